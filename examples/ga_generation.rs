//! One GA evaluation for profiling: the first `N` genomes (default 8) of an age group's initial
//! population (seed 1), in the parallel Worlds of the fall pool (up to four falls at a time in each)
//! on the current rayon pool; prints each fall's
//! damage, steps, rest time, worst range excursion and penetration so a change can be checked
//! for identical bits. Deterministic instruction counts:
//! `MARIONETTE_PORTABLE=1 RAYON_NUM_THREADS=1 valgrind --tool=callgrind target/release/examples/ga_generation 8`
//! (the portable copy of the step: valgrind cannot decode some instructions of the AVX2 copy).
//! Optional environment: `GROUP=adult`, `DT=<s>` (time step), `SEED=<k>` (the GA seed), and
//! to find what makes the age groups' first generations differ, the other group's joint
//! ranges (`RANGES=adult|elderly`: θ_d bounds and the simulated ranges) or strength
//! (`STRENGTH=adult|elderly`: torque limits and k_p bounds, the step re-derived from them).
//! `RANGE_KEYS=knee,hip_flexion` takes only those side-less DOFs' ranges from `RANGES`;
//! `RANGES_FOR=genes|sim` applies them only to the θ_d bounds or only to the simulated ranges.
//! `IMPLICIT_CONTACT_DAMPING=1` takes the floor's normal damping implicitly and re-derives the
//! step without its bound (before `DT`).
//! `KEY=stance` replaces every θ_d gene by the stance pose (random k_p only: the fall of a
//! body that holds its stance). `GENOMES_FROM=<dir>` takes the genomes from the population of
//! the run of `GROUP` and `SEED` in that folder's `checkpoint.json` (an evolved population,
//! whose falls last longer than the initial one's) instead of the initial population. Besides each fall, it prints the mean damage share per link over the falls and the link
//! that carries the most damage in the best one.

use marionette::evolve::{GaConfig, GaState, InProcess, checkpoint};
use marionette::experiments::evolve_fall::{
    EvolutionRun, FallProblem, STEP_MARGIN, stable_step_for, strength_kp_max,
};
use marionette::experiments::fall::Ranges;
use marionette::experiments::fall::SettledStart;
use marionette::experiments::fall::{ReactionStart, run_parallel_reacting};
use marionette::humanoid::{AgeGroup, RangeTable};

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
    let own = RangeTable::builtin(group);
    let mut sim_ranges = Ranges::Table(own.clone());
    if let Some(g) = group_env("RANGES") {
        let other = RangeTable::builtin(g);
        let mut table = own.clone();
        match std::env::var("RANGE_KEYS") {
            Ok(keys) => {
                for k in keys.split(',') {
                    let r = *other
                        .ranges
                        .get(k)
                        .unwrap_or_else(|| panic!("RANGE_KEYS: {k}"));
                    table.ranges.insert(k.to_string(), r);
                }
            }
            Err(_) => table = other,
        }
        let table = Ranges::Table(table);
        match std::env::var("RANGES_FOR").as_deref() {
            Ok("genes") => problem.fall.ranges = table,
            Ok("sim") => sim_ranges = table,
            Ok(other) => panic!("RANGES_FOR={other}: genes or sim"),
            Err(_) => {
                problem.fall.ranges = table.clone();
                sim_ranges = table;
            }
        }
    }
    if let Some(g) = group_env("STRENGTH") {
        problem.fall.torque_limits_nm = Some(marionette::humanoid::strength::torque_limits(g));
        problem.kp_max = strength_kp_max(g, 1.0);
        problem.fall.dt_s =
            stable_step_for(&problem.fall, &problem.kp_max, STEP_MARGIN).expect("step");
    }
    if std::env::var("IMPLICIT_CONTACT_DAMPING").is_ok() {
        // The floor's damping taken implicitly: the step re-derived without its bound.
        problem.fall.contact.implicit_damping = true;
        problem.fall.dt_s =
            stable_step_for(&problem.fall, &problem.kp_max, STEP_MARGIN).expect("step");
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
    // The θ_d bounds are taken; from here the fall simulates `sim_ranges`.
    if std::env::var("RANGES_FOR").is_ok() {
        problem.fall.ranges = sim_ranges;
    }
    let cfg = GaConfig {
        population: n.max(2),
        generations: 1,
        seed: env("SEED").map_or(1, |s| s as u64),
        ..GaConfig::default()
    };
    let mut free = InProcess {
        batch: |g: &[Vec<f64>], _: u32| g.iter().map(|_| Ok(0.0)).collect(),
    };
    let mut state = GaState::initial(cfg, bounds, &mut free).expect("GA");
    if let Ok(dir) = std::env::var("GENOMES_FROM") {
        let runs: Vec<EvolutionRun> =
            checkpoint::load(std::path::Path::new(&dir)).expect("GENOMES_FROM: a checkpoint");
        let seed = state.config.seed;
        let run = runs
            .into_iter()
            .find(|r| r.problem.age_group == group && r.state.config.seed == seed)
            .unwrap_or_else(|| panic!("GENOMES_FROM: no run of {group:?}, seed {seed}"));
        eprintln!("generation {} of {dir}", run.state.generation);
        state.population = run.state.population;
        assert!(n <= state.population.len(), "N: at most the population");
    }
    let edge = std::env::var("EDGE").is_ok();
    let stance_key = std::env::var("KEY").as_deref() == Ok("stance");
    let nd = problem.kp_max.len();
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
            if stance_key {
                for (x, s) in g[..nd].iter_mut().zip(&problem.fall.stance_pose_deg) {
                    *x = s.to_radians();
                }
            }
            problem.config(&g)
        })
        .collect();
    let start = SettledStart::of(&problem.fall).ok();
    // The stretch before the reaction, run once for all (as the GA does); NO_REACTION=1 runs
    // every fall from its settled start instead (the same results).
    let reaction = if std::env::var("NO_REACTION").is_ok() {
        None
    } else {
        ReactionStart::of(&problem.fall, start.as_ref()).ok()
    };
    let t0 = std::time::Instant::now();
    let results = run_parallel_reacting(&configs, start.as_ref(), reaction.as_ref());
    let wall = t0.elapsed().as_secs_f64();
    let mut steps = 0;
    let mut best = f64::INFINITY;
    let mut best_link = String::new();
    // Per link over the completed falls: damage share, damage (N), falls it touched in, summed
    // impact velocity (m/s).
    let mut share: Vec<(String, f64, f64, usize, f64)> = Vec::new();
    let mut completed = 0.0;
    for (i, r) in results.iter().enumerate() {
        match r {
            Ok(f) => {
                steps += f.steps;
                completed += 1.0;
                if share.is_empty() {
                    share = f
                        .impacts
                        .iter()
                        .map(|l| (l.link.clone(), 0.0, 0.0, 0, 0.0))
                        .collect();
                }
                for (s, l) in share.iter_mut().zip(&f.impacts) {
                    s.1 += l.damage_n / f.damage;
                    s.2 += l.damage_n;
                    if l.touchdown_s.is_some() {
                        s.3 += 1;
                        s.4 += l.impact_velocity_m_s;
                    }
                }
                if f.damage < best {
                    best = f.damage;
                    let top = f
                        .impacts
                        .iter()
                        .max_by(|a, b| a.damage_n.total_cmp(&b.damage_n));
                    best_link = top.map_or(String::new(), |l| {
                        format!(
                            "{} {:.0} N ({:.2} m/s)",
                            l.link, l.damage_n, l.impact_velocity_m_s
                        )
                    });
                }
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
    share.sort_by(|a, b| b.1.total_cmp(&a.1));
    let shares: Vec<String> = share
        .iter()
        .take(4)
        .map(|(l, x, d, k, v)| {
            format!(
                "{l} {:.0} % ({:.0} N; touched in {k}, at {:.2} m/s)",
                100.0 * x / completed,
                d / completed,
                v / (*k).max(1) as f64
            )
        })
        .collect();
    println!("mean damage share: {}", shares.join(", "));
    println!("best fall's largest share: {best_link}");
    let mut damages: Vec<f64> = results.iter().flatten().map(|f| f.damage).collect();
    damages.sort_by(f64::total_cmp);
    if let Some(median) = damages.get(damages.len() / 2) {
        println!(
            "population damage: mean {:.0} N, median {median:.0} N",
            damages.iter().sum::<f64>() / damages.len() as f64
        );
    }
    println!("best damage {best}");
}
