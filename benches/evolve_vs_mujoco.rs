//! The paper's GA for one age group against what MuJoCo would need for the same falls, in the
//! same run: `scenes/evolve_fall.ron`'s elderly problem with its stepping (the linearly
//! implicit midpoint step at 2 ms), seed 1, 30 chromosomes × 500 generations with the elite
//! checks at half the step, evaluated in process on 2 threads as the scene does. Every fall the
//! GA used (its evaluations and its checks, not the look-ahead it threw away) is simulated
//! again afterwards, untimed, for its length from the reaction start to its end. MuJoCo's time
//! for those falls is their steps (at the GA's step: 2 ms, the checks 1 ms) over MuJoCo's
//! rate, measured by `tools/bench_vs_mujoco.py` (64 pushed falls of the same body, `rollout`
//! with `implicitfast`, 2 threads) once before and once after the GA; MuJoCo starts each fall
//! at the reaction from a given state, the engine builds its start itself. Prints both sides'
//! seconds and the ratio. Takes about 5–10 minutes.
//! Run: `cargo bench --bench evolve_vs_mujoco`.

mod common;

use common::mujoco::{filtered_out, mujoco_round, setup};
use marionette::evolve::{Evaluation, Evaluator, EvolveError, GaConfig, GaState, Genome};
use marionette::experiments::evolve_fall::{FallProblem, InProcessFalls};
use marionette::experiments::fall::run_parallel;
use marionette::humanoid::AgeGroup;
use marionette::scene::Scene;
use std::path::Path;
use std::time::Instant;

/// Passes every call to the scene's evaluator and keeps the genomes whose falls the GA used,
/// with their refinement.
struct Recorded {
    inner: InProcessFalls,
    used: Vec<(Genome, u32)>,
}

impl Evaluator for Recorded {
    fn evaluate(
        &mut self,
        generation: u64,
        genomes: &[Genome],
        refine: u32,
    ) -> Result<Vec<Evaluation>, EvolveError> {
        self.used
            .extend(genomes.iter().map(|g| (g.clone(), refine)));
        self.inner.evaluate(generation, genomes, refine)
    }

    fn evaluate_checks(
        &mut self,
        generation: u64,
        checks: &[Genome],
        refine: u32,
        ahead: &dyn Fn() -> Vec<Genome>,
        wanted: &(dyn Fn(&[Evaluation]) -> bool + Sync),
    ) -> Result<Vec<Evaluation>, EvolveError> {
        self.used.extend(checks.iter().map(|g| (g.clone(), refine)));
        self.inner
            .evaluate_checks(generation, checks, refine, ahead, wanted)
    }
}

/// The scene's elderly problem and GA settings with seed 1.
fn scene_problem() -> (FallProblem, GaConfig) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/evolve_fall.ron");
    let Scene::EvolveFall(scene) = Scene::load(&path).expect("scenes/evolve_fall.ron") else {
        panic!("scenes/evolve_fall.ron is not an EvolveFall scene");
    };
    let config = scene.config().expect("the scene's problems");
    let problem = config
        .problems
        .into_iter()
        .find(|p| p.age_group == AgeGroup::Elderly)
        .expect("an elderly problem");
    let ga = GaConfig {
        seed: 1,
        ..config.ga
    };
    (problem, ga)
}

/// MuJoCo's steps for the falls the GA used: each fall's length from the reaction start to its
/// end (simulated again, untimed) over the step it was evaluated at.
fn mujoco_steps(problem: &FallProblem, used: &[(Genome, u32)]) -> f64 {
    let reaction = problem.fall.control_start_s;
    let mut steps = 0.0;
    for chunk in used.chunks(256) {
        let configs: Vec<_> = chunk
            .iter()
            .map(|(g, refine)| {
                let mut c = problem.config(g);
                c.dt_s /= f64::from(*refine);
                c
            })
            .collect();
        for (c, r) in configs.iter().zip(run_parallel(&configs)) {
            let r = r.expect("a fall the GA used runs again");
            // The fall's time is its step count times its step (sub-steps count as one).
            let end = r.steps as f64 * r.dt_s;
            steps += ((end - reaction).max(0.0) / c.dt_s).round();
        }
    }
    steps
}

fn main() {
    if filtered_out("evolve_vs_mujoco") {
        return;
    }
    let (py, dir, xml, work, pool) = setup("evolve_vs_mujoco");
    let (problem, ga) = scene_problem();
    let before = mujoco_round(&py, &xml, &work);
    println!(
        "MuJoCo {} implicitfast 2 ms before the GA: {:.0} steps/s ({:.1} falls/s)",
        before.version, before.steps_per_s, before.falls_per_s
    );
    let mut e = Recorded {
        inner: InProcessFalls::new(problem.clone()),
        used: Vec::new(),
    };
    let start = Instant::now();
    let s = pool.install(|| {
        let mut s = GaState::initial(ga, problem.bounds().expect("bounds"), &mut e).expect("GA");
        while !s.done() {
            s.step(&mut e).expect("GA step");
        }
        s
    });
    let engine_s = start.elapsed().as_secs_f64();
    let after = mujoco_round(&py, &xml, &work);
    println!(
        "MuJoCo implicitfast 2 ms after the GA: {:.0} steps/s ({:.1} falls/s)",
        after.steps_per_s, after.falls_per_s
    );
    let rate = 0.5 * (before.steps_per_s + after.steps_per_s);
    let steps = pool.install(|| mujoco_steps(&problem, &e.used));
    let mujoco_s = steps / rate;
    println!(
        "engine GA ({} × {}, {:?} at {} ms, {} falls used, {} of them checks, {} answered from \
         the look-ahead): {engine_s:.1} s, best damage {:.0} N",
        s.config.population,
        s.config.generations,
        problem.fall.integrator,
        problem.fall.dt_s * 1e3,
        e.used.len(),
        s.check_evaluations,
        e.inner.answered_ahead,
        s.best.as_ref().map_or(f64::NAN, |b| b.1)
    );
    println!(
        "evolve_vs_mujoco: MuJoCo would need {steps:.0} steps at {rate:.0} steps/s = \
         {mujoco_s:.1} s; engine {engine_s:.1} s = {:.2}x MuJoCo",
        mujoco_s / engine_s
    );
    std::fs::remove_dir_all(&dir).ok();
}
