//! The automatic mapping through the command line: a skeleton no built-in file fits (the
//! project's jump with every joint renamed to a meaningless name) is inspected, written as a
//! mapping file, exported onto a model with its feet where the source has them; a hand-written
//! mapping given with --mapping wins; a non-humanoid is refused in one line.

use std::path::PathBuf;
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_marionette"))
}

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("marionette-mapcli-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

/// The project's normal jump as BVH text with the joints renamed `bone<k>`.
fn renamed_jump() -> PathBuf {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let clip = marionette::clips::KeyframeClip::load(&root.join("scenes/clips/normal_jump.ron"))
        .unwrap()
        .to_figure_clip();
    let text = marionette::bvh::to_string(&clip.to_clip().to_bvh());
    let mut k = 0;
    let renamed: Vec<String> = text
        .lines()
        .map(|l| {
            let t = l.trim_start();
            if t.starts_with("ROOT ") || t.starts_with("JOINT ") {
                k += 1;
                let indent = &l[..l.len() - t.len()];
                let word = t.split_whitespace().next().unwrap();
                format!("{indent}{word} bone{:02}", (k * 7) % 23)
            } else {
                l.to_string()
            }
        })
        .collect();
    let p = temp("renamed_jump.bvh");
    std::fs::write(&p, renamed.join("\n") + "\n").unwrap();
    p
}

fn run(args: &[&str]) -> (bool, String, String) {
    let o = bin().args(args).output().unwrap();
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stdout).to_string(),
        String::from_utf8_lossy(&o.stderr).to_string(),
    )
}

/// Worst foot distance (mm) in the end-effector report of `export --bvh --model`.
fn worst_foot_mm(report: &str) -> f64 {
    report
        .lines()
        .filter(|l| {
            l.trim_start().starts_with("left_foot") || l.trim_start().starts_with("right_foot")
        })
        .map(|l| {
            let worst = l.split('/').nth(1).unwrap();
            worst
                .trim()
                .trim_end_matches("mm")
                .trim()
                .parse::<f64>()
                .unwrap()
        })
        .fold(0.0, f64::max)
}

#[test]
fn an_unseen_skeleton_is_inspected_written_and_exported_and_a_given_mapping_wins() {
    let bvh = renamed_jump();
    let b = bvh.to_str().unwrap();
    let (ok, out, err) = run(&["inspect", b]);
    assert!(ok, "{err}");
    assert!(out.contains("mapping     automatic"), "{out}");
    assert!(
        out.contains("left_knee") && out.contains("structure"),
        "{out}"
    );

    let ron = temp("found.ron");
    let (ok, out, err) = run(&["mapping", b, "--out", ron.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(out.starts_with("wrote "), "{out}");
    let m = marionette::mapping::Mapping::load(&ron).unwrap();
    assert_eq!(m.landmarks.len(), 22);

    let (ok, out, err) = run(&[
        "export",
        b,
        "--bvh",
        temp("auto.bvh").to_str().unwrap(),
        "--model",
        "humanoid24",
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("mapping automatic"), "{out}");
    let auto_mm = worst_foot_mm(&out);
    assert!(auto_mm < 50.0, "feet {auto_mm} mm off:\n{out}");

    // A hand-written mapping wins: the written file, renamed and with the hands moved to the
    // wrists, is what export uses.
    let text = std::fs::read_to_string(&ron).unwrap();
    let wrist = m.landmarks["left_wrist"].clone();
    let edited = text
        .replace("name: \"automatic\"", "name: \"my_rig\"")
        .replace(
            &format!("\"left_hand\": {:?}", m.landmarks["left_hand"]),
            &format!("\"left_hand\": {wrist:?}"),
        );
    assert_ne!(edited, text);
    let edited_ron = temp("edited.ron");
    std::fs::write(&edited_ron, edited).unwrap();
    let (ok, out, err) = run(&[
        "export",
        b,
        "--bvh",
        temp("edited.bvh").to_str().unwrap(),
        "--model",
        "humanoid24",
        "--mapping",
        edited_ron.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("mapping my_rig"), "{out}");
}

#[test]
fn a_non_humanoid_is_refused_in_one_line() {
    let p = temp("chain.bvh");
    std::fs::write(
        &p,
        "HIERARCHY\nROOT a\n{\n  OFFSET 0 100 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n  JOINT b\n  {\n    OFFSET 0 -30 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n    JOINT c\n    {\n      OFFSET 0 -30 0\n      CHANNELS 3 Zrotation Xrotation Yrotation\n      End Site\n      {\n        OFFSET 0 -30 0\n      }\n    }\n  }\n}\nMOTION\nFrames: 1\nFrame Time: 0.033333\n0 100 0 0 0 0 0 0 0 0 0 0\n",
    )
    .unwrap();
    let (ok, _, err) = run(&[
        "export",
        p.to_str().unwrap(),
        "--angles",
        "humanoid24",
        temp("x.csv").to_str().unwrap(),
    ]);
    assert!(!ok);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("no mapping for this skeleton") && err.contains("limb end"),
        "{err}"
    );
}
