//! The results page (`index.html` in every scene's output folder, and `marionette view`'s page)
//! in a real browser: `marionette run` of the fall, a short evolution
//! (`scenes/evolve_fall_quick.ron`), the high jump and the dance, each page opened from its
//! `file://` URL in headless Chromium by `tests/browser/results.mjs` — no console error and
//! nothing fetched, every motion of the scene listed, play advancing the frame, the plots'
//! cursor on the playhead, a frame step, and each figure standing on the floor in the first
//! frame (its lowest drawn body point at the floor, its highest a person's height above it, its
//! contact with the floor marked). Then `marionette view` on a real BVH of the
//! shared data and on a skeleton made up here (Z up, centimetres, names of no known rig, half a
//! metre below its floor). Screenshots go to `target/results-page/`. Needs Chromium, Node and
//! `tests/browser/node_modules`: ignored with that reason when absent (`cfg(tool_browser)`).

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("marionette-page-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn shots() -> PathBuf {
    let d = root().join("target/results-page");
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs the command; its standard output (panics with its error output when it fails).
fn marionette(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(args)
        .current_dir(root())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "marionette {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Drives the page in Chromium; what it showed.
fn drive(page: &Path, shot: &Path, chromium: &Path) -> serde_json::Value {
    let url = format!("file://{}", page.canonicalize().unwrap().display());
    let out = Command::new("node")
        .arg("results.mjs")
        .arg(&url)
        .arg(shot)
        .env("CHROMIUM", chromium)
        .current_dir(root().join("tests/browser"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "results.mjs on {url}: {stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_str(stdout.trim().lines().last().unwrap()).unwrap()
}

/// A list of frame numbers.
fn frames_of(v: &serde_json::Value) -> Vec<u64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_u64().unwrap())
        .collect()
}

/// What every page must show: no error, the motions listed as `expected` (each label holding
/// its text), play advancing the frame, the cursors on the playhead, a frame step, and every
/// figure standing on the floor at the first frame, something of it marked touching the floor.
fn check_page(what: &str, v: &serde_json::Value, expected: &[&str]) {
    assert_eq!(v["errors"], serde_json::json!([]), "{what}: {v}");
    let listed: Vec<&str> = v["listed"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l.as_str().unwrap())
        .collect();
    assert_eq!(listed.len(), expected.len(), "{what}: listed {listed:?}");
    for (l, e) in listed.iter().zip(expected) {
        assert!(
            l.contains(e),
            "{what}: '{l}' should name '{e}' ({listed:?})"
        );
    }
    assert!(v["views"].as_u64().unwrap() >= 1, "{what}: no 3-D view");
    // Play for 0.7 s: the playhead and at least one motion's frame advance.
    let (t0, t1) = (
        v["before"]["t"].as_f64().unwrap(),
        v["after"]["t"].as_f64().unwrap(),
    );
    assert!(t1 > t0 + 0.2, "{what}: played from {t0} to {t1} s");
    let (f0, f1) = (
        frames_of(&v["before"]["frames"]),
        frames_of(&v["after"]["frames"]),
    );
    assert!(
        f0.iter().zip(&f1).any(|(a, b)| b > a),
        "{what}: frames {f0:?} → {f1:?}"
    );
    assert_eq!(v["after"]["playing"], false, "{what}: pause did not stop");
    // Scrubbed to a quarter and three quarters: each timed plot's cursor at the playhead,
    // moving right.
    let c = v["cursors"].as_array().unwrap();
    let plots = c[0]["plots"].as_array().unwrap();
    assert!(!plots.is_empty(), "{what}: no plot with a cursor");
    for s in c {
        let t = s["t"].as_f64().unwrap();
        for p in s["plots"].as_array().unwrap() {
            let pt = p["t"].as_f64().unwrap();
            assert!(
                (pt - t).abs() < 1e-3,
                "{what}: cursor at {pt} s, playhead {t} s"
            );
        }
    }
    for (a, b) in plots.iter().zip(c[1]["plots"].as_array().unwrap()) {
        assert!(
            b["x"].as_f64().unwrap() > a["x"].as_f64().unwrap() + 5.0,
            "{what}: the cursor did not follow the playhead: {a} → {b}"
        );
    }
    // One frame step from the middle: the finest motion one frame on, none more.
    let (f0, f1) = (frames_of(&v["unstepped"]), frames_of(&v["stepped"]));
    let steps: Vec<i64> = f0
        .iter()
        .zip(&f1)
        .map(|(a, b)| *b as i64 - *a as i64)
        .collect();
    assert!(
        steps.contains(&1) && steps.iter().all(|s| (0..=1).contains(s)),
        "{what}: one frame step gave {f0:?} → {f1:?}"
    );
    // At the first frame every figure stands: its lowest drawn body point (a capsule's or a
    // box's surface) at the floor, its highest a standing person's height above.
    for s in v["stats"].as_array().unwrap() {
        let (lo, hi) = (
            s["lowest"].as_f64().unwrap(),
            s["highest"].as_f64().unwrap(),
        );
        assert!(
            (-0.07..=0.05).contains(&lo),
            "{what}: {} lowest at {lo} m, not on the floor",
            s["motion"]
        );
        assert!(
            hi - lo > 1.3,
            "{what}: {} is {:.2} m tall, not standing",
            s["motion"],
            hi - lo
        );
        // Standing, it touches the floor (its feet): some box or end segment is marked red.
        let touching: Vec<&str> = s["touching"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t.as_str().unwrap())
            .collect();
        assert!(
            !touching.is_empty(),
            "{what}: {} stands but nothing is marked touching the floor",
            s["motion"]
        );
    }
    assert!(
        v["lit"].as_f64().unwrap() > 0.002,
        "{what}: the first view shows almost no body: {}",
        v["lit"]
    );
}

#[test]
#[cfg_attr(
    not(tool_browser),
    ignore = "needs Chromium, Node and tests/browser/node_modules (installed by .ci/run)"
)]
fn every_scene_writes_a_page_that_plays_in_chromium() {
    let Some(chromium) = common::browser() else {
        return;
    };
    let d = scratch("scenes");
    let cases: [(&str, &[&str], &[&str], usize); 4] = [
        ("fall", &[], &["(elderly)", "(adult)"], 5_000_000),
        (
            "evolve_fall_quick",
            &["render.gif=false"],
            &[
                "elderly before",
                "elderly evolved",
                "adult before",
                "adult evolved",
            ],
            10_000_000,
        ),
        ("high_jump", &[], &["low", "normal", "high"], 5_000_000),
        ("dance", &[], &["16 bars"], 5_000_000),
    ];
    for (scene, set, expected, limit) in cases {
        let out = d.join(scene);
        let mut args = vec![
            "run".to_string(),
            format!("scenes/{scene}.ron"),
            "--out".into(),
            out.display().to_string(),
        ];
        for s in set {
            args.extend(["--set".to_string(), s.to_string()]);
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let printed = marionette(&args);
        let page = out.join("index.html");
        assert_eq!(
            printed.trim_end().lines().last().unwrap(),
            format!("page: {}", page.display()),
            "{scene}: run's last line"
        );
        let bytes = std::fs::metadata(&page).unwrap().len() as usize;
        eprintln!("{scene}: index.html {bytes} bytes");
        assert!(bytes < limit, "{scene}: the page is {bytes} bytes");
        let html = std::fs::read_to_string(&page).unwrap();
        assert!(
            !html.contains("src=\"http") && !html.contains("href=\"http"),
            "{scene}: the page refers to the network"
        );
        let v = drive(&page, &shots().join(format!("{scene}.png")), &chromium);
        check_page(scene, &v, expected);
        if scene == "dance" {
            assert!(html.contains("data:audio/wav;base64,") || html.contains("\"wav\":\""));
        }
        if scene.contains("fall") {
            assert!(html.contains("\"boxes\":\""), "{scene}: no contact boxes");
            assert!(
                html.contains("head lowest"),
                "{scene}: the head's lowest not marked"
            );
        }
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// A BVH no rig of the project's resembles: Z up, centimetres, French joint names, standing
/// half a metre below its floor, swaying its arms for 40 frames.
fn made_up_bvh() -> String {
    let mut s = String::from(
        "HIERARCHY\nROOT bassin\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n",
    );
    let joint = |name: &str, off: (f64, f64, f64), inner: &str, depth: usize| {
        let pad = "  ".repeat(depth);
        format!(
            "{pad}JOINT {name}\n{pad}{{\n{pad}  OFFSET {} {} {}\n{pad}  CHANNELS 3 Zrotation Xrotation Yrotation\n{inner}{pad}}}\n",
            off.0, off.1, off.2
        )
    };
    let end = |off: (f64, f64, f64), depth: usize| {
        let pad = "  ".repeat(depth);
        format!(
            "{pad}End Site\n{pad}{{\n{pad}  OFFSET {} {} {}\n{pad}}}\n",
            off.0, off.1, off.2
        )
    };
    let leg = |side: &str, x: f64| {
        joint(
            &format!("cuisse_{side}"),
            (x, 0.0, -8.0),
            &joint(
                &format!("jambe_{side}"),
                (0.0, 0.0, -42.0),
                &joint(
                    &format!("pied_{side}"),
                    (0.0, 0.0, -40.0),
                    &end((0.0, -14.0, -5.0), 4),
                    3,
                ),
                2,
            ),
            1,
        )
    };
    let arm = |side: &str, x: f64| {
        joint(
            &format!("epaule_{side}"),
            (x, 0.0, 0.0),
            &joint(
                &format!("bras_{side}"),
                (x.signum() * 12.0, 0.0, 0.0),
                &joint(
                    &format!("coude_{side}"),
                    (x.signum() * 28.0, 0.0, 0.0),
                    &end((x.signum() * 25.0, 0.0, 0.0), 5),
                    4,
                ),
                3,
            ),
            2,
        )
    };
    let chest = joint(
        "poitrine",
        (0.0, 0.0, 25.0),
        &format!(
            "{}{}{}",
            joint("tete", (0.0, 0.0, 18.0), &end((0.0, 0.0, 22.0), 3), 2),
            arm("g", 10.0),
            arm("d", -10.0)
        ),
        1,
    );
    s.push_str(&leg("g", 9.0));
    s.push_str(&leg("d", -9.0));
    s.push_str(&chest);
    s.push_str("}\nMOTION\nFrames: 40\nFrame Time: 0.033333\n");
    for f in 0..40 {
        // 6 root channels, then 3 per joint in the order written: the upper arms (bras_g,
        // bras_d) are joints 9 and 12 counted from 0, their Z rotation (about up) sways.
        let sway = 20.0 * (f as f64 * 0.2).sin();
        let mut row = vec![0.0; 6 + 3 * 14];
        // The root half a metre below the floor: its toes at −50 cm.
        row[2] = 45.0;
        row[6 + 3 * 9] = sway;
        row[6 + 3 * 12] = -sway;
        let row: Vec<String> = row.iter().map(|v| format!("{v:.3}")).collect();
        s.push_str(&row.join(" "));
        s.push('\n');
    }
    s
}

/// `marionette view BVH --unit-scale 0.01 --out PAGE` on the made-up centimetre skeleton: it
/// prints the page's path and nothing else; the page's text.
fn view_made_up(bvh: &Path, page: &Path) -> String {
    let printed = marionette(&[
        "view",
        &bvh.display().to_string(),
        "--unit-scale",
        "0.01",
        "--out",
        &page.display().to_string(),
    ]);
    assert_eq!(printed.trim(), page.display().to_string());
    std::fs::read_to_string(page).unwrap()
}

#[test]
#[cfg_attr(
    not(tool_browser),
    ignore = "needs Chromium, Node and tests/browser/node_modules (installed by .ci/run)"
)]
fn view_stands_any_bvh_upright_on_its_floor() {
    let Some(chromium) = common::browser() else {
        return;
    };
    let d = scratch("view");
    // A skeleton the project has never seen.
    let bvh = d.join("inconnu.bvh");
    std::fs::write(&bvh, made_up_bvh()).unwrap();
    let page = d.join("inconnu.html");
    let html = view_made_up(&bvh, &page);
    assert!(
        html.contains("up axis (+Z) is up") && html.contains("moved up"),
        "the page does not say how it stood the figure up"
    );
    let v = drive(&page, &shots().join("view_made_up.png"), &chromium);
    check_page("made-up skeleton", &v, &["inconnu"]);
    if let Some(real) = common::data_path("cmu/cmu_01_01_forward_jumps.bvh") {
        let page = d.join("cmu.html");
        marionette(&[
            "view",
            &real.display().to_string(),
            "--out",
            &page.display().to_string(),
        ]);
        let v = drive(&page, &shots().join("view_cmu.png"), &chromium);
        check_page("CMU 01_01", &v, &["cmu_01_01_forward_jumps"]);
        // On a model: the same capture mapped onto humanoid24.
        let page = d.join("cmu_h24.html");
        marionette(&[
            "view",
            &real.display().to_string(),
            "--model",
            "humanoid24",
            "--out",
            &page.display().to_string(),
        ]);
        let v = drive(&page, &shots().join("view_cmu_h24.png"), &chromium);
        check_page("CMU 01_01 on humanoid24", &v, &["on humanoid24"]);
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// Runs the command expecting it to fail; its error output.
fn marionette_fails(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(args)
        .current_dir(root())
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(1),
        "marionette {args:?} should fail"
    );
    assert!(out.stdout.is_empty(), "marionette {args:?} printed a page");
    String::from_utf8(out.stderr).unwrap()
}

#[test]
fn view_refuses_bad_input_naming_the_file_and_what_was_expected() {
    let d = scratch("bad");
    let missing = d.join("absent.bvh");
    let err = marionette_fails(&["view", &missing.display().to_string()]);
    assert!(err.contains("absent.bvh"), "{err}");
    let garbage = d.join("garbage.bvh");
    std::fs::write(&garbage, "not a motion\n").unwrap();
    let err = marionette_fails(&["view", &garbage.display().to_string()]);
    assert!(
        err.contains("garbage.bvh") && err.contains("line 1") && err.contains("HIERARCHY"),
        "{err}"
    );
    let empty = d.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let err = marionette_fails(&["view", &empty.display().to_string()]);
    assert!(
        err.contains("empty") && err.contains("no .bvh file"),
        "{err}"
    );
    let bvh = d.join("inconnu.bvh");
    std::fs::write(&bvh, made_up_bvh()).unwrap();
    let err = marionette_fails(&[
        "view",
        &bvh.display().to_string(),
        "--unit-scale",
        "0.01",
        "--model",
        "humanoid99",
    ]);
    assert!(
        err.contains("humanoid99") && err.contains("humanoid24"),
        "{err}"
    );
    // Without a browser: the page is written, names the motion and says how it stood it up.
    let page = d.join("inconnu.html");
    let html = view_made_up(&bvh, &page);
    assert!(
        html.contains("\"label\":\"inconnu\""),
        "the motion is not in the page"
    );
    assert!(
        html.contains("up axis (+Z) is up"),
        "no word on standing it up"
    );
    std::fs::remove_dir_all(&d).unwrap();
}
