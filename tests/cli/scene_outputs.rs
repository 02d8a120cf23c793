//! A scene's outputs appear together or not at all: a run that fails (after parsing, or in
//! the middle) leaves the previous outputs as they were, a run that succeeds leaves nothing of
//! the previous run beside its files, and bad scene values are errors before any work.

use std::path::{Path, PathBuf};

use marionette::scene::{self, Scene};

fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("marionette-scene-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A Show scene of the project's normal jump, with `extra` fields.
fn show(name: &str, extra: &str) -> Scene {
    let clip = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/clips/normal_jump.ron");
    let text = format!(
        "Show(format_version: 1, name: {name:?}, clip: (file: {:?}), {extra})",
        clip.display().to_string()
    );
    Scene::parse(&text, "test.ron").unwrap()
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    v.sort();
    v
}

#[test]
fn failing_runs_leave_the_previous_outputs_and_no_partial_set() {
    let d = scratch("fail");
    let out = d.join("jump");
    let good = show(
        "jump",
        r#"model: "humanoid24", render: (gif: true, filmstrip_frames: 4)"#,
    );
    scene::run(&good, &d, &out).unwrap();
    let before = names(&out);
    assert!(before.contains(&"motion.gif".to_string()), "{before:?}");
    let report = std::fs::read(out.join("report.json")).unwrap();

    // A plotted DOF that does not exist, set after parsing: refused before any work.
    let bad = scene::apply_overrides(&good, &["render.plot=[\"left_knee\",\"left_kne\"]".into()])
        .unwrap();
    let e = scene::run(&bad, &d, &out).unwrap_err().to_string();
    assert!(e.contains("'left_kne' is not a DOF of humanoid24"), "{e}");
    assert_eq!(names(&out), before);
    assert_eq!(std::fs::read(out.join("report.json")).unwrap(), report);

    // An error in the middle of the run (the clip is on humanoid24, not fall21).
    let mid = scene::apply_overrides(&good, &["model=fall21".into()]).unwrap();
    let e = scene::run(&mid, &d, &out).unwrap_err().to_string();
    assert!(e.contains("not fall21"), "{e}");
    assert_eq!(names(&out), before);
    assert_eq!(std::fs::read(out.join("report.json")).unwrap(), report);
    // No temporary folder is left beside the outputs.
    assert_eq!(names(&d), ["jump"]);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_new_run_leaves_nothing_of_the_old_one_beside_its_files() {
    let d = scratch("replace");
    let out = d.join("jump");
    let with_gif = show(
        "jump",
        r#"model: "humanoid24", render: (gif: true, filmstrip_frames: 4)"#,
    );
    scene::run(&with_gif, &d, &out).unwrap();
    assert!(out.join("motion.gif").exists() && out.join("angles.png").exists());
    // On its own skeleton and without a GIF: no angles and no GIF of the old run remain.
    let plain = show("jump", "render: (gif: false, filmstrip_frames: 4)");
    scene::run(&plain, &d, &out).unwrap();
    let now = names(&out);
    assert!(!now.contains(&"motion.gif".to_string()), "{now:?}");
    assert!(!now.contains(&"angles.png".to_string()), "{now:?}");
    assert!(!now.contains(&"angles.csv".to_string()), "{now:?}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert!(report.get("model").is_none(), "{report}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_folder_that_is_not_a_scene_output_is_not_replaced() {
    let d = scratch("foreign");
    std::fs::write(d.join("notes.txt"), "mine").unwrap();
    let e = scene::run(&show("jump", ""), &d, &d)
        .unwrap_err()
        .to_string();
    assert!(e.contains("not a scene's output"), "{e}");
    assert_eq!(names(&d), ["notes.txt"]);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn names_that_write_elsewhere_are_refused() {
    for name in ["", "/tmp/x", "../up", "a/b", ".hidden"] {
        let e = scene::validate(&show(name, "")).unwrap_err().to_string();
        assert!(e.contains("plain folder name"), "{name:?}: {e}");
    }
    scene::validate(&show("fine_name-2", "")).unwrap();
}

#[test]
fn version_zero_and_huge_keyframed_clips_are_errors() {
    let clip = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/clips/normal_jump.ron");
    let text = format!(
        "Show(format_version: 0, name: \"v\", clip: (file: {:?}))",
        clip.display().to_string()
    );
    let e = Scene::parse(&text, "v.ron").unwrap_err().to_string();
    assert!(
        e.contains("format_version 0") && e.contains("start at 1"),
        "{e}"
    );

    let d = scratch("huge");
    let jump = std::fs::read_to_string(&clip).unwrap();
    let huge = jump.replace("duration: 2.0", "duration: 1e7");
    assert_ne!(huge, jump);
    std::fs::write(d.join("huge.ron"), huge).unwrap();
    let s = Scene::parse(
        r#"Show(format_version: 1, name: "huge", clip: (file: "huge.ron"))"#,
        "h.ron",
    )
    .unwrap();
    let e = scene::run(&s, &d, &d.join("out")).unwrap_err().to_string();
    assert!(e.contains("more than the 1000000"), "{e}");
    assert!(!d.join("out").exists());
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn windows_reaching_outside_the_clip_name_its_span() {
    let d = scratch("window");
    let s = scene::apply_overrides(
        &show("w", ""),
        &["clip.start_s=1.0".into(), "clip.end_s=3.0".into()],
    )
    .unwrap();
    let e = scene::run(&s, &d, &d.join("w")).unwrap_err().to_string();
    assert!(e.contains("spans 0..2.000 s"), "{e}");
    std::fs::remove_dir_all(&d).unwrap();
}

/// `--set clip.unit_scale=1000` on a BVH clip (a 1.7 km figure) is refused with the human
/// range before any output, as `inspect --unit-scale` refuses it.
#[test]
fn a_unit_scale_that_makes_no_human_is_refused_in_a_scene() {
    let d = scratch("unit");
    let clip = marionette::clips::KeyframeClip::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/clips/normal_jump.ron"),
    )
    .unwrap()
    .to_figure_clip();
    marionette::bvh::write_file(&clip.to_clip().to_bvh(), &d.join("jump.bvh")).unwrap();
    let s = Scene::parse(
        r#"Show(format_version: 1, name: "unit", clip: (file: "jump.bvh"))"#,
        "u.ron",
    )
    .unwrap();
    let s = scene::apply_overrides(&s, &["clip.unit_scale=1000".into()]).unwrap();
    let e = scene::run(&s, &d, &d.join("unit")).unwrap_err().to_string();
    assert!(e.contains("human range 0.3..3 m"), "{e}");
    assert!(!d.join("unit").exists());
    std::fs::remove_dir_all(&d).unwrap();
}
