//! The MuJoCo side of the benches that run MuJoCo alongside the engine
//! (`falls_vs_mujoco`, `evolve_vs_mujoco`): the workload the tool reads (the fall21 MJCF, the
//! elderly figure's settled start, stance PD, strength, joint friction, pushes) and one round of
//! `tools/bench_vs_mujoco.py` (MuJoCo 4 `rollout`, `implicitfast` at 2 ms), run with
//! `.venv/bin/python` or `MARIONETTE_PYTHON`.

use marionette::dynamics::{Integrator, JointType};
use marionette::experiments::fall::{FallConfig, simulate_fall};
use marionette::humanoid::fall21_body;
use marionette::humanoid::to_mjcf;
use marionette::humanoid::{AgeGroup, RangeTable};
use serde_json::json;
use std::path::{Path, PathBuf};

/// Falls of the workload.
pub const FALLS: usize = 64;
/// Threads on both sides.
pub const THREADS: usize = 2;

/// The 64 pushed falls of `falls_parallel` (both age groups alternating, pushes of 800–1115 N),
/// stepped as the paper's fall is.
pub fn pushed_falls() -> Vec<FallConfig> {
    (0..FALLS)
        .map(|i| {
            let mut cfg = FallConfig::paper(if i % 2 == 0 {
                AgeGroup::Elderly
            } else {
                AgeGroup::Adult
            });
            cfg.push.force_n = 800.0 + 5.0 * i as f64;
            cfg
        })
        .collect()
}

/// [`pushed_falls`] with `integrator` at `dt` (s).
pub fn configs(integrator: Integrator, dt: f64) -> Vec<FallConfig> {
    pushed_falls()
        .into_iter()
        .map(|cfg| FallConfig {
            integrator,
            dt_s: dt,
            ..cfg
        })
        .collect()
}

/// True when `cargo bench` was given a filter that does not name the bench `name` (it passes
/// `--bench` and any filter as arguments): the bench then skips its run.
pub fn filtered_out(name: &str) -> bool {
    std::env::args()
        .skip(1)
        .any(|a| !a.starts_with("--") && !name.contains(&a))
}

/// The side-by-side setup: the Python with MuJoCo, the workload written into a fresh
/// temporary folder named after `name` (its path, the MJCF and the workload file), and a rayon
/// pool of [`THREADS`] threads for the engine.
pub fn setup(name: &str) -> (PathBuf, PathBuf, PathBuf, PathBuf, rayon::ThreadPool) {
    let dir = std::env::temp_dir().join(format!("marionette-{name}-{}", std::process::id()));
    let (xml, work) = write_workload(&dir);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(THREADS)
        .build()
        .expect("pool");
    (python(), dir, xml, work, pool)
}

/// The Python that has MuJoCo: `MARIONETTE_PYTHON`, else the project's `.venv`.
pub fn python() -> PathBuf {
    std::env::var_os("MARIONETTE_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(".venv/bin/python"))
}

/// A MuJoCo round's figures.
pub struct MujocoRound {
    /// MuJoCo's version.
    pub version: String,
    /// Falls per second.
    pub falls_per_s: f64,
    /// Steps per second over all falls (falls × steps / seconds).
    pub steps_per_s: f64,
    /// Falls whose state went non-finite.
    pub diverged: u64,
    /// Mean pelvis height at the end (m).
    pub pelvis_end_m: f64,
}

/// Writes the MJCF body and the MuJoCo workload (the elderly figure's settled start, stance PD,
/// strength, joint friction, pushes) into `dir`; returns their paths.
pub fn write_workload(dir: &Path) -> (PathBuf, PathBuf) {
    let cfg = FallConfig::paper(AgeGroup::Elderly);
    let body = fall21_body(cfg.height_m, cfg.mass_kg, cfg.gravity).expect("fall21");
    let ranges = RangeTable::builtin(AgeGroup::Elderly)
        .for_figure(&body.figure)
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
        body.model.bodies()[neck].joint,
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
pub fn mujoco_round(py: &Path, xml: &Path, work: &Path) -> MujocoRound {
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
    let m: serde_json::Value = serde_json::from_slice(&out.stdout).expect("the tool's JSON line");
    let num = |k: &str| m[k].as_f64().unwrap_or_else(|| panic!("{k} in {m}"));
    MujocoRound {
        version: m["mujoco"].as_str().unwrap_or("?").to_string(),
        falls_per_s: num("falls_per_s"),
        steps_per_s: num("falls") * num("steps") / num("seconds"),
        diverged: m["diverged"].as_u64().unwrap_or(0),
        pelvis_end_m: m["pelvis_end_m"].as_f64().unwrap_or(f64::NAN),
    }
}

/// The median.
pub fn median(mut x: Vec<f64>) -> f64 {
    x.sort_by(f64::total_cmp);
    x[x.len() / 2]
}
