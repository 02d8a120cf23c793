//! The `marionette` command as a user runs it: outputs on good input, a non-zero exit and one
//! clear line on bad input.

use std::path::PathBuf;
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_marionette"))
}

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("marionette-cli-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

/// The project's normal jump written as a BVH file.
fn jump_bvh(name: &str) -> PathBuf {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let clip = marionette::clips::KeyframeClip::load(&root.join("scenes/clips/normal_jump.ron"))
        .unwrap()
        .to_model_clip();
    let p = temp(name);
    marionette::bvh::write_file(&clip.to_clip().to_bvh(), &p).unwrap();
    p
}

#[test]
fn inspect_reports_the_flight_of_the_jump() {
    let out = bin()
        .arg("inspect")
        .arg(jump_bvh("inspect.bvh"))
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("frames      240"), "{text}");
    assert!(text.contains("flights     1"), "{text}");
}

#[test]
fn export_positions_and_angles_have_the_documented_headers() {
    let bvh = jump_bvh("export.bvh");
    let pos = temp("p.csv");
    assert!(
        bin()
            .args(["export"])
            .arg(&bvh)
            .arg("--positions")
            .arg(&pos)
            .status()
            .unwrap()
            .success()
    );
    let text = std::fs::read_to_string(&pos).unwrap();
    let header = text.lines().next().unwrap();
    assert!(
        header.starts_with("frame,time_s,pelvis.x,pelvis.y,pelvis.z,waist.x"),
        "{header}"
    );
    assert_eq!(text.lines().count(), 241);
    let ang = temp("a.csv");
    assert!(
        bin()
            .args(["export"])
            .arg(&bvh)
            .args(["--angles", "humanoid24"])
            .arg(&ang)
            .status()
            .unwrap()
            .success()
    );
    let text = std::fs::read_to_string(&ang).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    assert_eq!(header.len(), 2 + 24);
    let knee = header.iter().position(|h| *h == "left_knee").unwrap();
    let peak = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(knee).unwrap().parse::<f64>().unwrap())
        .fold(0.0, f64::max);
    assert!((peak - 110.0).abs() < 1.0, "left knee peak {peak}");
    let back = temp("fall21.bvh");
    let out = bin()
        .args(["export"])
        .arg(&bvh)
        .arg("--bvh")
        .arg(&back)
        .args(["--model", "fall21"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        std::fs::read_to_string(&back)
            .unwrap()
            .contains("JOINT left_ankle")
    );
}

#[test]
fn bad_input_fails_with_one_line_naming_the_line() {
    let bad = temp("bad.bvh");
    std::fs::write(&bad, "HIERARCHY\nROOT a\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Xposition Yposition Zposition\n}\nMOTION\nFrames: 2\nFrame Time: 0.1\n1 2 3\n1 2\n").unwrap();
    let out = bin().arg("inspect").arg(&bad).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("line 11"), "{err}");
    let out = bin().args(["run", "scenes/nope.ron"]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let out = bin()
        .args(["render"])
        .arg(jump_bvh("render.bvh"))
        .args(["--out", "x.jpg"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8(out.stderr)
            .unwrap()
            .contains("expected a .png")
    );
}

#[test]
fn every_command_has_help() {
    for cmd in ["inspect", "export", "render", "run"] {
        let out = bin().args([cmd, "--help"]).output().unwrap();
        assert!(out.status.success() && !out.stdout.is_empty(), "{cmd}");
    }
}
