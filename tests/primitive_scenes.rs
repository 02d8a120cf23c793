//! The motor-primitive paper's experiments as scenes: the numbers the paper reports, on the
//! project's own keyframed clips and (when `MARIONETTE_DATA` is present) on the CMU capture.

use std::path::PathBuf;

use marionette::scene::{Scene, run};

mod common;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn run_scene(file: &str) -> serde_json::Value {
    let path = root().join("scenes").join(file);
    let scene = Scene::load(&path).unwrap();
    let out = std::env::temp_dir().join(format!(
        "marionette-test-{}-{}",
        std::process::id(),
        file.replace('.', "_")
    ));
    let report = run(&scene, path.parent().unwrap(), &out).unwrap();
    for f in ["report.json", "filmstrip.png", "motion.gif"] {
        assert!(out.join(f).is_file(), "{file}: {f} missing");
    }
    std::fs::remove_dir_all(&out).ok();
    report
}

/// Whether the CMU files the `_cmu` scenes read are present (else skipped, or failed under CI).
fn data_present() -> bool {
    [
        "cmu/cmu_01_01_forward_jumps.bvh",
        "cmu/acrnn_martial_04.bvh",
    ]
    .iter()
    .all(|f| common::data_path(f).is_some())
}

fn f(v: &serde_json::Value, path: &[&str]) -> f64 {
    let mut x = v;
    for p in path {
        x = &x[*p];
    }
    x.as_f64()
        .unwrap_or_else(|| panic!("{path:?} is not a number in {v}"))
}

fn check_high_jump(r: &serde_json::Value) {
    let (low, normal, high) = (
        f(r, &["peak_knee_flexion_deg", "low"]),
        f(r, &["peak_knee_flexion_deg", "normal"]),
        f(r, &["peak_knee_flexion_deg", "high"]),
    );
    let expected = 1.5 * normal - 0.5 * low;
    assert!(
        (high - expected).abs() < 2.0,
        "high {high:.2} vs 1.5·{normal:.2} − 0.5·{low:.2} = {expected:.2}"
    );
    assert!(f(r, &["fit_rmse_deg", "median"]) < 0.5);
}

#[test]
fn high_jump_on_the_projects_own_clips() {
    let r = run_scene("high_jump.ron");
    check_high_jump(&r);
    assert!((f(&r, &["peak_knee_flexion_deg", "low"]) - 70.0).abs() < 1.0);
    assert!((f(&r, &["peak_knee_flexion_deg", "normal"]) - 110.0).abs() < 1.0);
    assert!((f(&r, &["peak_knee_flexion_deg", "high"]) - 130.0).abs() < 2.0);
}

fn check_kick(r: &serde_json::Value) {
    let e = |k: &str| f(r, &["events_s", k]);
    assert!(
        e("start") < e("bend") && e("bend") < e("leap") && e("leap") < e("land"),
        "events out of order: {}",
        r["events_s"]
    );
    assert!(f(r, &["junction", "max_angle_jump_deg"]) < 1e-6);
    assert!(f(r, &["junction", "max_velocity_jump_deg_s"]) < 1e-6);
    assert!(
        f(r, &["posture_gap_deg", "jump_at_bend"]) < 2.0,
        "{}",
        r["posture_gap_deg"]
    );
    assert!(
        f(r, &["posture_gap_deg", "kick_at_leap"]) < 2.0,
        "{}",
        r["posture_gap_deg"]
    );
    assert_eq!(
        r["lands_with_both_feet"],
        serde_json::Value::Bool(true),
        "{}",
        r["feet_above_floor_after_landing_m"]
    );
    assert!(f(r, &["fit_rmse_deg", "median"]) < 0.5);
    // The same sequence played by a character in an ECS world lands on the kernel's motion.
    assert!(
        f(r, &["ecs_vs_kernel_max_m"]) < 1e-9,
        "ECS playback differs by {} m",
        r["ecs_vs_kernel_max_m"]
    );
}

#[test]
fn jumping_knee_kick_on_the_projects_own_clips() {
    check_kick(&run_scene("jumping_knee_kick.ron"));
}

#[test]
fn high_jump_on_the_cmu_jumps() {
    if data_present() {
        check_high_jump(&run_scene("high_jump_cmu.ron"));
    }
}

#[test]
fn jumping_knee_kick_on_cmu_capture() {
    if data_present() {
        check_kick(&run_scene("jumping_knee_kick_cmu.ron"));
    }
}
