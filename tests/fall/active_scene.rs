//! The active jumping knee kick as a scene: the physical character tracks the animated motion
//! until the push, the assistance is released after the scene's delay and the character falls;
//! the report says when, and every output is written. Bad values are refused before running.

use std::path::PathBuf;

use marionette::scene::{Scene, apply_overrides, run};

fn scene_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/active_knee_kick.ron")
}

#[test]
fn the_pushed_active_character_falls_and_the_report_says_when() {
    let path = scene_path();
    let scene = Scene::load(&path).unwrap();
    let out = std::env::temp_dir().join(format!("marionette-test-{}-active", std::process::id()));
    let r = run(&scene, path.parent().unwrap(), &out).unwrap();
    for f in [
        "report.json",
        "filmstrip.png",
        "motion.gif",
        "active_knee_kick.bvh",
        "pelvis_height.png",
        "pelvis_height.csv",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let push = r["push"]["start_s"].as_f64().unwrap();
    let release = r["release_s"].as_f64().unwrap();
    let fall = r["fall_s"].as_f64().unwrap();
    let rms = r["tracking"]["joint_rms_deg"].as_f64().unwrap();
    println!(
        "push {push} s, release {release} s, fallen {fall} s, tracking RMS {rms:.3}°, damage {} N",
        r["damage"]["total_n"]
    );
    assert!((release - push - 0.1).abs() < 1e-3);
    assert!(fall > release);
    assert!(rms < 6.0);
    assert!(r["pelvis_height_m"]["end"].as_f64().unwrap() < 0.35);
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn bad_values_are_refused_before_anything_runs() {
    let path = scene_path();
    let scene = Scene::load(&path).unwrap();
    for (set, expect) in [
        ("character.assist=1.5", "character.assist"),
        ("push.link=wing", "not a humanoid24 link"),
        ("dt_s=0", "dt_s"),
        ("push.start_s=9", "push.start_s"),
    ] {
        let s = apply_overrides(&scene, &[set.to_string()]).unwrap();
        let e = marionette::scene::validate(&s).unwrap_err().to_string();
        assert!(e.contains(expect), "{set}: {e}");
    }
}

#[test]
fn the_key_pose_scene_switches_at_the_release_and_falls() {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/active_knee_kick_key_pose.ron");
    let scene = Scene::load(&path).unwrap();
    let out =
        std::env::temp_dir().join(format!("marionette-test-{}-active-key", std::process::id()));
    let r = run(&scene, path.parent().unwrap(), &out).unwrap();
    assert_eq!(r["key_pose_deg"]["left_knee"].as_f64(), Some(90.0));
    let release = r["release_s"].as_f64().unwrap();
    let fall = r["fall_s"].as_f64().unwrap();
    println!(
        "key pose scene: release {release} s, fallen {fall} s, damage {} N",
        r["damage"]["total_n"]
    );
    assert!(fall > release);
    let bad =
        marionette::scene::apply_overrides(&scene, &["key_pose_deg={\"tail\": 1.0}".to_string()])
            .unwrap();
    let e = run(&bad, path.parent().unwrap(), &out)
        .unwrap_err()
        .to_string();
    assert!(e.contains("'tail' is not a DOF of humanoid24"), "{e}");
    std::fs::remove_dir_all(&out).ok();
}

/// Under `--set` of the push and the release delay the report gives the push as set and
/// releases the assistance that long after it.
#[test]
fn the_report_follows_the_push_and_release_under_set() {
    let path = scene_path();
    let scene = Scene::load(&path).unwrap();
    let sets: Vec<String> = [
        "push.force_n=450",
        "push.start_s=1.3",
        "push.duration_s=0.15",
        "release_delay_s=0.25",
    ]
    .map(String::from)
    .to_vec();
    let scene = apply_overrides(&scene, &sets).unwrap();
    let out =
        std::env::temp_dir().join(format!("marionette-test-{}-active-set", std::process::id()));
    let r = run(&scene, path.parent().unwrap(), &out).unwrap();
    assert_eq!(r["push"]["force_n"].as_f64(), Some(450.0), "{}", r["push"]);
    assert_eq!(
        r["push"]["duration_s"].as_f64(),
        Some(0.15),
        "{}",
        r["push"]
    );
    let push = r["push"]["start_s"].as_f64().unwrap();
    let release = r["release_s"].as_f64().unwrap();
    // To the tick (dt 0.5 ms).
    assert!((push - 1.3).abs() < 1e-3, "push at {push} s");
    assert!(
        (release - push - 0.25).abs() < 1e-3,
        "release at {release} s"
    );
    std::fs::remove_dir_all(&out).ok();
}
