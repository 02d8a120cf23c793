//! Falls per second against MuJoCo in the same run: 64 pushed falls of 3 s (the workload of
//! `falls_parallel`: both age groups alternating, pushes of 800–1115 N), 2 threads, three
//! alternating rounds of MuJoCo 4 `rollout` with `implicitfast` at 2 ms on the fall21 MJCF
//! (`tools/bench_vs_mujoco.py`, run with `.venv/bin/python` or `MARIONETTE_PYTHON`) and of the
//! engine — its linearly implicit step at 2 ms and, for reference, the explicit step at the
//! fall scene's 0.5 ms. Prints each side's falls/s per round, their medians and the ratios.
//! The engine's falls include building and settling each body (MuJoCo's start from the settled
//! state the engine gives it), so the ratio is conservative for the engine.
//! Run: `cargo bench --bench falls_vs_mujoco`.

use marionette::dynamics::{Integrator, JointType};
use marionette::experiments::fall::ecs::run_parallel;
use marionette::experiments::fall::{FallConfig, simulate_fall};
use marionette::humanoid::body::fall21_body;
use marionette::humanoid::export::to_mjcf;
use marionette::humanoid::ranges::{AgeGroup, RangeTable};
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

const FALLS: usize = 64;
const THREADS: usize = 2;
const ROUNDS: usize = 3;

/// The 64 falls of `falls_parallel` with `integrator` at `dt` (s).
fn configs(integrator: Integrator, dt: f64) -> Vec<FallConfig> {
    (0..FALLS)
        .map(|i| {
            let mut cfg = FallConfig::paper(if i % 2 == 0 {
                AgeGroup::Elderly
            } else {
                AgeGroup::Adult
            });
            cfg.push.force_n = 800.0 + 5.0 * i as f64;
            cfg.integrator = integrator;
            cfg.dt_s = dt;
            cfg
        })
        .collect()
}

/// Writes the MJCF body and the MuJoCo workload (the elderly figure's settled start, stance PD,
/// strength, joint friction, pushes) into `dir`; returns their paths.
fn write_workload(dir: &std::path::Path) -> (PathBuf, PathBuf) {
    let cfg = FallConfig::paper(AgeGroup::Elderly);
    let body = fall21_body(cfg.height_m, cfg.mass_kg, cfg.gravity).expect("fall21");
    let ranges = RangeTable::builtin(AgeGroup::Elderly)
        .for_model(&body.figure)
        .expect("ranges");
    let limits = cfg.torque_limits_nm.clone().expect("strength");
    let dofs: Vec<_> = body
        .figure
        .dofs
        .iter()
        .enumerate()
        .map(|(d, dof)| {
            json!({
                "name": dof.name, "target": cfg.stance_pose_deg[d].to_radians(),
                "kp": cfg.stance_kp[d], "kv": cfg.stance_kv[d],
                "torque_min": limits[d].0, "torque_max": limits[d].1,
            })
        })
        .collect();
    let neck = body.link_index("head").expect("head");
    assert!(matches!(
        body.model.bodies[neck].joint,
        JointType::Ball { .. }
    ));
    let start = simulate_fall(&cfg).expect("the paper's fall").frames[0].clone();
    let forces: Vec<f64> = configs(Integrator::LinearlyImplicitEuler, 2e-3)
        .iter()
        .map(|c| c.push.force_n)
        .collect();
    let work = json!({
        "dt_s": 2e-3, "duration_s": cfg.duration_s, "dofs": dofs,
        "friction_kv": cfg.limits.friction_kv,
        "start": {
            "root_position": start.root_position.to_array(),
            "root_orientation": start.root_orientation.to_array(),
            "angles": start.angles,
        },
        "push": cfg.push, "push_forces_n": forces,
    });
    std::fs::create_dir_all(dir).expect("bench directory");
    let (xml, path) = (dir.join("fall21.xml"), dir.join("workload.json"));
    std::fs::write(&xml, to_mjcf(&body, &ranges, cfg.gravity)).expect("MJCF");
    std::fs::write(&path, work.to_string()).expect("workload");
    (xml, path)
}

/// One MuJoCo round: the tool's report.
fn mujoco_round(py: &PathBuf, xml: &PathBuf, work: &PathBuf) -> serde_json::Value {
    let tool = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tools/bench_vs_mujoco.py");
    let out = std::process::Command::new(py)
        .arg(&tool)
        .arg(xml)
        .arg(work)
        .arg(THREADS.to_string())
        .output()
        .expect("python runs");
    assert!(
        out.status.success(),
        "bench_vs_mujoco.py failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("the tool's JSON line")
}

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

fn median(mut x: Vec<f64>) -> f64 {
    x.sort_by(f64::total_cmp);
    x[x.len() / 2]
}

fn main() {
    // `cargo bench` passes `--bench`; a filter that is not ours skips the run.
    if std::env::args()
        .skip(1)
        .any(|a| !a.starts_with("--") && !"falls_vs_mujoco".contains(&a))
    {
        return;
    }
    let py = std::env::var_os("MARIONETTE_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(".venv/bin/python"));
    let dir = std::env::temp_dir().join(format!("marionette-vs-mujoco-{}", std::process::id()));
    let (xml, work) = write_workload(&dir);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(THREADS)
        .build()
        .expect("pool");
    let implicit = configs(Integrator::LinearlyImplicitEuler, 2e-3);
    let explicit = configs(
        Integrator::SemiImplicitEuler {
            implicit_damping: true,
        },
        5e-4,
    );
    // The same with the reaction's first 100 ms in 4 sub-steps (the setting that holds the
    // halving test's genomes within 10 %, tests/dynamics/implicit.rs).
    let refined: Vec<FallConfig> = implicit
        .iter()
        .map(|c| FallConfig {
            reaction_window_s: 0.1,
            reaction_substeps: 4,
            ..c.clone()
        })
        .collect();
    // Warm-up of the engine (the shared body, caches).
    engine_round(&pool, &implicit[..THREADS]);
    let (mut mj, mut eng, mut old, mut fine) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for round in 1..=ROUNDS {
        let m = mujoco_round(&py, &xml, &work);
        let rate = m["falls_per_s"].as_f64().expect("falls_per_s");
        let e = engine_round(&pool, &implicit);
        let o = engine_round(&pool, &explicit);
        let r = engine_round(&pool, &refined);
        println!(
            "round {round}: MuJoCo {} implicitfast 2 ms {rate:.1} falls/s ({} diverged, pelvis \
             at {:.2} m at the end); engine linearly implicit 2 ms {e:.1} falls/s (reaction \
             refined {r:.1}); engine explicit 0.5 ms {o:.1} falls/s",
            m["mujoco"].as_str().unwrap_or("?"),
            m["diverged"],
            m["pelvis_end_m"].as_f64().unwrap_or(f64::NAN)
        );
        mj.push(rate);
        eng.push(e);
        old.push(o);
        fine.push(r);
    }
    let (mj, eng, old, fine) = (median(mj), median(eng), median(old), median(fine));
    println!(
        "falls_vs_mujoco ({FALLS} pushed 3-s falls, {THREADS} threads, median of {ROUNDS} \
         rounds): MuJoCo implicitfast 2 ms {mj:.1} falls/s; engine linearly implicit 2 ms \
         {eng:.1} falls/s = {:.2}x MuJoCo, its reaction's first 100 ms in 4 sub-steps {fine:.1} \
         falls/s = {:.2}x; engine explicit 0.5 ms {old:.1} falls/s = {:.2}x",
        eng / mj,
        fine / mj,
        old / mj
    );
    std::fs::remove_dir_all(&dir).ok();
}
