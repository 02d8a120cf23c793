//! The Ray path, for real: the GA evaluates its generations through `tools/ray_eval.py` on a
//! local Ray (actors each holding a `marionette eval --stdin` worker) and ends with the same
//! bits as the in-process run.

use crate::common;

use std::path::PathBuf;
use std::process::Command;

use marionette::evolve::{GaConfig, GaState, InProcess, JsonLines};
use marionette::experiments::evolve_fall::FallProblem;
use marionette::humanoid::AgeGroup;

#[test]
#[cfg_attr(
    not(tool_python),
    ignore = "needs the Python environment .venv (made by .ci/run) or MARIONETTE_PYTHON"
)]
fn a_run_on_a_local_ray_cluster_matches_the_in_process_run_bit_for_bit() {
    let Some(python) = common::python_with(&["ray"]) else {
        return;
    };
    let mut p = FallProblem::paper(AgeGroup::Adult);
    p.fall.duration_s = 1.0;
    let cfg = GaConfig {
        population: 8,
        generations: 2,
        seed: 4,
        ..GaConfig::default()
    };
    let bounds = p.bounds().unwrap();
    let mut local = InProcess {
        batch: |g: &[Vec<f64>], refine: u32| p.evaluate(g, refine),
    };
    let mut a = GaState::initial(cfg.clone(), bounds.clone(), &mut local).unwrap();
    while !a.done() {
        a.step(&mut local).unwrap();
    }
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tools/ray_eval.py");
    let mut cmd = Command::new(python);
    cmd.arg(script)
        .args(["--actors", "2", "--cpus-per-actor", "1", "--worker"])
        .arg(env!("CARGO_BIN_EXE_marionette"));
    let mut ray = JsonLines::start(cmd, &p).unwrap();
    let mut b = GaState::initial(cfg, bounds, &mut ray).unwrap();
    while !b.done() {
        b.step(&mut ray).unwrap();
    }
    assert_eq!(
        serde_json::to_string(&a).unwrap(),
        serde_json::to_string(&b).unwrap()
    );
    assert_eq!(b.evaluations + b.inherited, 8 + 2 * 6);
    assert!(b.evaluations > 8, "the children went through Ray");
    // The elite check's refined evaluations went through Ray too.
    assert!(b.check_evaluations > 0);
}
