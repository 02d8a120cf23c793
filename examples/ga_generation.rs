//! One GA evaluation for profiling: the first `N` genomes (default 8) of an age group's initial
//! population (seed 1), each fall in its own World on the current rayon pool; prints each fall's
//! damage, steps, rest time, worst range excursion and penetration so a change can be checked
//! for identical bits. Deterministic instruction counts:
//! `RAYON_NUM_THREADS=1 valgrind --tool=callgrind target/release/examples/ga_generation 8`.
//! Optional environment: `GROUP=adult`, `DT=<s>` (time step), `SEED=<k>` (the GA seed), and
//! to find what makes the age groups' first generations differ, the other group's joint
//! ranges (`RANGES=adult|elderly`: θ_d bounds and the simulated ranges) or strength
//! (`STRENGTH=adult|elderly`: torque limits and k_p bounds, the step re-derived from them).

use marionette::evolve::fall_fitness::{stable_step_for, strength_kp_max};
use marionette::evolve::{FallProblem, GaConfig, GaState, InProcess};
use marionette::experiments::fall::Ranges;
use marionette::experiments::fall::{SettledStart, ecs::run_parallel_from};
use marionette::humanoid::ranges::AgeGroup;

fn env(name: &str) -> Option<f64> {
    std::env::var(name).ok().map(|v| v.parse().expect(name))
}

fn group_env(name: &str) -> Option<AgeGroup> {
    match std::env::var(name).as_deref() {
        Ok("adult") => Some(AgeGroup::Adult),
        Ok("elderly") => Some(AgeGroup::Elderly),
        Ok(other) => panic!("{name}={other}: adult or elderly"),
        Err(_) => None,
    }
}

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(8, |a| a.parse().expect("N: number of genomes"));
    let group = match std::env::var("GROUP").as_deref() {
        Ok("adult") => AgeGroup::Adult,
        _ => AgeGroup::Elderly,
    };
    let mut problem = FallProblem::paper(group);
    if let Some(g) = group_env("RANGES") {
        problem.fall.ranges = Ranges::Builtin(g);
    }
    if let Some(g) = group_env("STRENGTH") {
        problem.fall.torque_limits_nm = Some(marionette::humanoid::strength::torque_limits(g));
        problem.kp_max = strength_kp_max(g, 1.0);
        problem.fall.dt_s = stable_step_for(&problem.fall, &problem.kp_max).expect("step");
    }
    if let Some(dt) = env("DT") {
        problem.fall.dt_s = dt;
    }
    if let Some(k) = env("LIMIT_KP") {
        problem.fall.limits.limit_kp = k;
    }
    if let Some(k) = env("LIMIT_KV") {
        problem.fall.limits.limit_kv = k;
    }
    if let Some(hz) = env("LIMIT_HZ") {
        problem.fall.limits.limit_frequency_hz = Some(hz);
    }
    if let Some(z) = env("LIMIT_ZETA") {
        problem.fall.limits.limit_damping_ratio = z;
    }
    if let Some(h) = env("REST_HOLD") {
        problem.fall.rest_hold_s = h;
    }
    eprintln!("dt = {} s", problem.fall.dt_s);
    let bounds = problem.bounds().expect("bounds");
    let cfg = GaConfig {
        population: n.max(2),
        generations: 1,
        seed: env("SEED").map_or(1, |s| s as u64),
        ..GaConfig::default()
    };
    let mut free = InProcess {
        batch: |g: &[Vec<f64>]| g.iter().map(|_| Ok(0.0)).collect(),
    };
    let state = GaState::initial(cfg, bounds, &mut free).expect("GA");
    let edge = std::env::var("EDGE").is_ok();
    let configs: Vec<_> = state.population[..n]
        .iter()
        .map(|g| {
            let mut g = g.clone();
            if edge {
                // Every gene pushed to its nearer bound (the bang-bang genomes a GA drifts to).
                for (i, x) in g.iter_mut().enumerate() {
                    let (lo, hi) = (state.bounds.lo[i], state.bounds.hi[i]);
                    *x = if *x - lo < hi - *x { lo } else { hi };
                }
            }
            problem.config(&g)
        })
        .collect();
    let start = SettledStart::of(&problem.fall).ok();
    let t0 = std::time::Instant::now();
    let results = run_parallel_from(&configs, start.as_ref());
    let wall = t0.elapsed().as_secs_f64();
    let mut steps = 0;
    let mut best = f64::INFINITY;
    for (i, r) in results.iter().enumerate() {
        match r {
            Ok(f) => {
                steps += f.steps;
                best = best.min(f.damage);
                let (d, ex) = f
                    .max_limit_excursion_rad
                    .iter()
                    .enumerate()
                    .fold((0, 0.0), |b, (d, &x)| if x > b.1 { (d, x) } else { b });
                println!(
                    "{i} damage {:?} steps {} rest {:?} excursion {:.2} deg ({}) penetration {:.4} m",
                    f.damage,
                    f.steps,
                    f.rest_time_s,
                    ex.to_degrees(),
                    f.dof_names[d],
                    f.max_penetration_m
                );
            }
            Err(e) => println!("{i} error {e}"),
        }
    }
    eprintln!(
        "{n} falls, {steps} steps, {wall:.3} s wall, {:.1} falls/s",
        n as f64 / wall
    );
    println!("best damage {best}");
}
