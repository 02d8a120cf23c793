//! Falls per second against MuJoCo in the same run: 64 pushed falls of 3 s (the workload of
//! `falls_parallel`: both age groups alternating, pushes of 800–1115 N), 2 threads, three
//! alternating rounds of MuJoCo 4 `rollout` with `implicitfast` at 2 ms on the fall21 MJCF
//! (`tools/bench_vs_mujoco.py`, run with `.venv/bin/python` or `MARIONETTE_PYTHON`) and of the
//! engine — its linearly implicit steps at 2 ms and, for reference, the explicit step at the
//! fall scene's former 0.5 ms. Prints each side's falls/s per round, their medians and the
//! ratios. The engine's falls include building and settling each body (MuJoCo's start from the
//! settled state the engine gives it), so the ratio is conservative for the engine.
//! Run: `cargo bench --bench falls_vs_mujoco`.

mod common;

use common::mujoco::{FALLS, THREADS, configs, filtered_out, median, mujoco_round, setup};
use marionette::dynamics::Integrator;
use marionette::experiments::fall::FallConfig;
use marionette::experiments::fall::run_parallel;
use std::time::Instant;

const ROUNDS: usize = 3;

/// One engine round on the pool: falls per second, and every fall must succeed.
fn engine_round(pool: &rayon::ThreadPool, configs: &[FallConfig]) -> f64 {
    let start = Instant::now();
    let r = pool.install(|| run_parallel(configs));
    let s = start.elapsed().as_secs_f64();
    let failed: Vec<String> = r
        .iter()
        .filter_map(|x| x.as_ref().err().map(|e| e.to_string()))
        .collect();
    assert!(failed.is_empty(), "falls failed: {failed:?}");
    configs.len() as f64 / s
}

fn main() {
    if filtered_out("falls_vs_mujoco") {
        return;
    }
    let (py, dir, xml, work, pool) = setup("falls_vs_mujoco");
    let refine = |c: &[FallConfig]| -> Vec<FallConfig> {
        c.iter()
            .map(|c| FallConfig {
                reaction_window_s: 0.1,
                reaction_substeps: 4,
                ..c.clone()
            })
            .collect()
    };
    let midpoint = configs(Integrator::LinearlyImplicitMidpoint, 2e-3);
    // The engine's sides: the schemes at 2 ms, the GA's stepping (the midpoint with the
    // reaction's first 100 ms in 4 sub-steps) and the explicit step at 0.5 ms.
    let sides: [(&str, Vec<FallConfig>); 4] = [
        ("linearly implicit midpoint 2 ms", midpoint.clone()),
        (
            "the same, reaction's first 100 ms in 4 sub-steps (the GA's)",
            refine(&midpoint),
        ),
        (
            "linearly implicit Euler 2 ms",
            configs(Integrator::LinearlyImplicitEuler, 2e-3),
        ),
        (
            "explicit 0.5 ms",
            configs(
                Integrator::SemiImplicitEuler {
                    implicit_damping: true,
                },
                5e-4,
            ),
        ),
    ];
    // Warm-up of the engine (the shared body, caches).
    engine_round(&pool, &midpoint[..THREADS]);
    let mut mj = Vec::new();
    let mut eng = vec![Vec::new(); sides.len()];
    for round in 1..=ROUNDS {
        let m = mujoco_round(&py, &xml, &work);
        println!(
            "round {round}: MuJoCo {} implicitfast 2 ms {:.1} falls/s ({:.0} steps/s, {} \
             diverged, pelvis at {:.2} m at the end)",
            m.version, m.falls_per_s, m.steps_per_s, m.diverged, m.pelvis_end_m
        );
        mj.push(m.falls_per_s);
        for (k, (name, c)) in sides.iter().enumerate() {
            let e = engine_round(&pool, c);
            println!("round {round}: engine {name} {e:.1} falls/s");
            eng[k].push(e);
        }
    }
    let mj = median(mj);
    println!(
        "falls_vs_mujoco ({FALLS} pushed 3-s falls, {THREADS} threads, median of {ROUNDS} \
         rounds): MuJoCo implicitfast 2 ms {mj:.1} falls/s"
    );
    for ((name, _), e) in sides.iter().zip(eng) {
        let e = median(e);
        println!("  engine {name}: {e:.1} falls/s = {:.2}x MuJoCo", e / mj);
    }
    std::fs::remove_dir_all(&dir).ok();
}
