//! The `marionette` command as a user runs it: outputs on good input, a non-zero exit and one
//! clear line on bad input.

use crate::common;

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
        .to_figure_clip();
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

/// Runs the command, returning (exit code, stdout, stderr).
fn run_cli(args: &[&std::ffi::OsStr]) -> (Option<i32>, String, String) {
    let out = bin().args(args).output().unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).to_string(),
        String::from_utf8_lossy(&out.stderr).to_string(),
    )
}

/// A BVH file of two joints: `offset` is the child's OFFSET line, `frame` the one motion line.
fn tiny_bvh(name: &str, root: &str, child: &str, offset: &str, frame: &str) -> PathBuf {
    let p = temp(name);
    std::fs::write(
        &p,
        format!(
            "HIERARCHY\nROOT {root}\n{{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n  JOINT {child}\n  {{\n    OFFSET {offset}\n    CHANNELS 3 Zrotation Xrotation Yrotation\n    End Site\n    {{\n      OFFSET 0 -80 0\n    }}\n  }}\n}}\nMOTION\nFrames: 1\nFrame Time: 0.01\n{frame}\n"
        ),
    )
    .unwrap();
    p
}

/// The error line of a failing `inspect`, after checking it failed with one line.
fn inspect_error(file: &std::path::Path) -> String {
    let (code, _, err) = run_cli(&["inspect".as_ref(), file.as_os_str()]);
    assert_eq!(code, Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    err
}

#[test]
fn garbage_numbers_and_names_are_errors_with_their_line() {
    let f = tiny_bvh("huge.bvh", "a", "b", "0 1e308 0", "0 90 0 0 0 0 0 0 0");
    let e = inspect_error(&f);
    assert!(
        e.contains("line 8") && e.contains("beyond the limit"),
        "{e}"
    );
    let f = tiny_bvh("angle.bvh", "a", "b", "0 -10 0", "0 90 0 1e300 0 0 0 0 0");
    let e = inspect_error(&f);
    assert!(e.contains("line 19") && e.contains("rotation"), "{e}");
    let f = tiny_bvh("dup.bvh", "a", "a", "0 -10 0", "0 90 0 0 0 0 0 0 0");
    let e = inspect_error(&f);
    assert!(
        e.contains("line 6") && e.contains("already defined on line 2"),
        "{e}"
    );
    // A 26 km figure: a unit scale that makes no human.
    let f = jump_bvh("scale.bvh");
    let (code, _, e) = run_cli(&[
        "inspect".as_ref(),
        f.as_os_str(),
        "--unit-scale".as_ref(),
        "1000".as_ref(),
    ]);
    assert_eq!(code, Some(1));
    assert!(e.contains("human range 0.3..3 m"), "{e}");
}

#[test]
fn a_deep_hierarchy_is_refused_at_the_stated_depth() {
    let mut s = String::from(
        "HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n",
    );
    for i in 1..10_000 {
        s.push_str(&format!(
            "JOINT j{i}\n{{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
        ));
    }
    let p = temp("deep.bvh");
    std::fs::write(&p, s).unwrap();
    let e = inspect_error(&p);
    assert!(e.contains("deeper than 64"), "{e}");
}

#[test]
fn os_errors_are_said_once() {
    let (code, _, e) = run_cli(&["inspect".as_ref(), "/nonexistent/x.bvh".as_ref()]);
    assert_eq!(code, Some(1));
    assert_eq!(e.matches("No such file").count(), 1, "{e}");
    let (code, _, e) = run_cli(&["run".as_ref(), "/nonexistent/s.ron".as_ref()]);
    assert_eq!(code, Some(1));
    assert_eq!(e.matches("No such file").count(), 1, "{e}");
}

#[test]
fn a_bvh_without_frames_is_not_written() {
    let p = temp("zero.bvh");
    std::fs::write(&p, "HIERARCHY\nROOT a\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n}\nMOTION\nFrames: 0\nFrame Time: 0.1\n").unwrap();
    let out = temp("zero_out.bvh");
    let (code, _, e) = run_cli(&[
        "export".as_ref(),
        p.as_os_str(),
        "--bvh".as_ref(),
        out.as_os_str(),
    ]);
    assert_eq!(code, Some(1), "{e}");
    assert!(e.contains("no frames"), "{e}");
    assert!(!out.exists());
}

#[test]
fn render_draws_any_skeleton_as_it_is_and_takes_a_window() {
    // A skeleton no built-in mapping knows.
    let f = tiny_bvh(
        "odd.bvh",
        "thing",
        "limb",
        "0 -90 0",
        "0 170 0 0 0 0 10 0 0",
    );
    let png = temp("odd.png");
    let (code, _, e) = run_cli(&[
        "render".as_ref(),
        f.as_os_str(),
        "--out".as_ref(),
        png.as_os_str(),
    ]);
    assert_eq!(code, Some(0), "{e}");
    assert!(png.exists());
    // --mapping needs --model; with --model it is taken.
    let (code, _, _) = run_cli(&[
        "render".as_ref(),
        f.as_os_str(),
        "--out".as_ref(),
        png.as_os_str(),
        "--mapping".as_ref(),
        "m.ron".as_ref(),
    ]);
    assert_eq!(code, Some(2));
    let jump = jump_bvh("window.bvh");
    let png = temp("window.png");
    let (code, _, e) = run_cli(&[
        "render".as_ref(),
        jump.as_os_str(),
        "--out".as_ref(),
        png.as_os_str(),
        "--start".as_ref(),
        "0.5".as_ref(),
        "--end".as_ref(),
        "1.5".as_ref(),
        "--model".as_ref(),
        "humanoid24".as_ref(),
        "--mapping".as_ref(),
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/src/mapping/builtin/marionette_humanoid24.ron"
        )
        .as_ref(),
    ]);
    assert_eq!(code, Some(0), "{e}");
    // A window reaching past the clip (2 s) names the clip's span.
    let (code, _, e) = run_cli(&[
        "render".as_ref(),
        jump.as_os_str(),
        "--out".as_ref(),
        png.as_os_str(),
        "--end".as_ref(),
        "9".as_ref(),
    ]);
    assert_eq!(code, Some(1));
    assert!(e.contains("spans 0..2.000 s"), "{e}");
}

#[test]
fn an_interrupted_run_leaves_the_old_outputs_or_the_whole_new_set() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let dir = temp("interrupt");
    let out = dir.join("jump");
    let run = |extra: &[&str]| {
        let mut c = bin();
        c.arg("run")
            .arg(root.join("scenes/show_normal_jump.ron"))
            .arg("--out")
            .arg(&out)
            .args(extra);
        c
    };
    assert!(
        run(&["--set", "render.gif=false"])
            .status()
            .unwrap()
            .success()
    );
    let old = std::fs::read(out.join("report.json")).unwrap();
    // The second run (with a GIF) interrupted part-way with SIGINT.
    let mut child = run(&[]).spawn().unwrap();
    std::thread::sleep(std::time::Duration::from_millis(150));
    let _ = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status();
    let status = child.wait().unwrap();
    let report = std::fs::read(out.join("report.json")).unwrap();
    let gif = out.join("motion.gif").exists();
    // Interrupted before its outputs were put in place: the old set as it was, nothing of the
    // new one; after (while it printed its summary), or finished: the whole new set.
    let whole_new = gif && report != old;
    let old_kept = !gif && report == old;
    assert!(
        whole_new || old_kept,
        "exit {status}: a GIF {gif}, the report changed {}",
        report != old
    );
    if status.success() {
        assert!(whole_new, "a successful run left the old outputs");
    }
    // The next run removes what the interrupted one left and succeeds.
    assert!(run(&[]).status().unwrap().success());
    let left: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    assert_eq!(left, ["jump"], "{left:?}");
}

/// The flights `inspect` prints: (start, end) seconds.
fn inspect_flights(file: &std::path::Path) -> Vec<(f64, f64)> {
    let (code, text, err) = run_cli(&["inspect".as_ref(), file.as_os_str()]);
    assert_eq!(code, Some(0), "{err}");
    let start = text.find("flights ").expect("a flights line");
    text[start..]
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l
                .split_whitespace()
                .filter_map(|w| w.parse().ok())
                .collect();
            (v[1], v[2])
        })
        .collect()
}

#[test]
fn lying_after_the_project_s_fall_is_not_flight() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let out = temp("fall_out");
    let (code, _, err) = run_cli(&[
        "run".as_ref(),
        root.join("scenes/fall.ron").as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
        "--set".as_ref(),
        "render.gif=false".as_ref(),
    ]);
    assert_eq!(code, Some(0), "{err}");
    let (_, text, _) = run_cli(&["inspect".as_ref(), out.join("fall.bvh").as_os_str()]);
    assert!(text.contains("flights     0"), "{text}");
    // It lies on the floor at the end: the body touches.
    assert!(!text.contains("body        0 spans"), "{text}");
}

#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn the_cmu_forward_jumps_have_exactly_their_ten_flights() {
    let Some(file) = common::data_path("cmu/cmu_01_01_forward_jumps.bvh") else {
        return;
    };
    let flights = inspect_flights(&file);
    assert_eq!(flights.len(), 10, "{flights:?}");
    // None while standing still at the start (0–1.3 s), each as long as a jump's flight.
    assert!(flights[0].0 > 1.3, "{flights:?}");
    for (a, b) in &flights {
        assert!((0.2..0.6).contains(&(b - a)), "{flights:?}");
    }
}

/// Runs `scenes/<scene>.ron` without its GIF into the temporary folder `out`: the folder and
/// the report.
fn run_scene_without_gif(scene: &str, out: &str) -> (PathBuf, serde_json::Value) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let out = temp(out);
    let (code, _, err) = run_cli(&[
        "run".as_ref(),
        root.join(format!("scenes/{scene}.ron")).as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
        "--set".as_ref(),
        "render.gif=false".as_ref(),
    ]);
    assert_eq!(code, Some(0), "{err}");
    let report =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    (out, report)
}

#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn the_mapped_cmu_jumps_keep_the_source_s_two_flights() {
    let Some(_) = common::data_dir() else {
        return;
    };
    let (_, report) = run_scene_without_gif("show_cmu_jumps", "cmu_jumps");
    let flights = report["flights"].as_array().unwrap();
    assert_eq!(flights.len(), 2, "{}", report["flights"]);
    // The source's flights in 0–5 s: 1.9–2.3 s and 3.6–3.9 s.
    for (f, (a, b)) in flights.iter().zip([(1.93, 2.25), (3.61, 3.89)]) {
        let (s, e) = (f["start_s"].as_f64().unwrap(), f["end_s"].as_f64().unwrap());
        assert!(
            (s - a).abs() < 0.12 && (e - b).abs() < 0.12,
            "{f} against {a}..{b}"
        );
    }
}

/// `inspect` on the primitive scenes' own BVH outputs finds exactly the one flight of each jump,
/// none while standing, the one the report gives as `own_contacts_flight`.
#[test]
fn inspect_finds_the_primitive_scenes_flights_in_their_outputs() {
    for (scene, files) in [
        (
            "high_jump",
            vec![
                ("low_jump.bvh", "low"),
                ("normal_jump.bvh", "normal"),
                ("high_jump.bvh", "high"),
            ],
        ),
        (
            "jumping_knee_kick",
            vec![("jumping_knee_kick.bvh", "jumping_knee_kick")],
        ),
    ] {
        let (out, report) = run_scene_without_gif(scene, &format!("{scene}_out"));
        for (file, key) in files {
            let flights = inspect_flights(&out.join(file));
            assert_eq!(flights.len(), 1, "{scene}/{file}: {flights:?}");
            let (a, b) = flights[0];
            assert!(
                a > 0.5,
                "{scene}/{file}: a flight while standing: {flights:?}"
            );
            let figures = if scene == "high_jump" {
                &report["jumps"][key]
            } else {
                &report[key]
            };
            let own = &figures["own_contacts_flight"];
            let (s, e) = (
                own["start_s"].as_f64().unwrap(),
                own["end_s"].as_f64().unwrap(),
            );
            // inspect prints milliseconds.
            assert!(
                (a - s).abs() < 1e-3 && (b - e).abs() < 1e-3,
                "{scene}/{file}: inspect {a}..{b} s, report {own}"
            );
        }
    }
}

/// The headline lines of every report under `dir` (one folder a scene), by scene name.
fn headlines(dir: &std::path::Path) -> Vec<(String, Vec<String>)> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path().join("report.json");
        if !path.is_file() {
            continue; // the evolution's checkpoint folder
        }
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let lines = report["headline"]
            .as_array()
            .unwrap_or_else(|| panic!("{}: no headline", path.display()))
            .iter()
            .map(|l| l.as_str().unwrap().to_string())
            .collect();
        out.push((report["scene"].as_str().unwrap().to_string(), lines));
    }
    out
}

#[test]
fn run_sums_up_each_scene_in_a_few_lines_from_its_report() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let scene = |name: &str| root.join(format!("scenes/{name}.ron"));
    // The README's main command: three scenes in one run, one folder each under --out.
    let tour = temp("tour");
    let out = bin()
        .arg("run")
        .args(["jumping_knee_kick", "dance", "evolve_fall_quick"].map(scene))
        .arg("--out")
        .arg(&tour)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.lines().count() <= 40, "{text}");
    assert_eq!(text.matches("done in").count(), 3, "{text}");
    // Each scene's block names its results page; the last line is the run's page linking them.
    let index = tour.join("index.html");
    assert_eq!(
        text.trim_end().lines().last().unwrap(),
        format!("page: {}", index.display()),
        "{text}"
    );
    let linked = std::fs::read_to_string(&index).unwrap();
    for name in ["jumping_knee_kick", "dance", "evolve_fall_quick"] {
        let page = tour.join(name).join("index.html");
        assert!(
            text.contains(&format!("  page: {}\n", page.display())),
            "{name}: its page not named\n{text}"
        );
        assert!(page.is_file(), "{}", page.display());
        assert!(
            linked.contains(&format!("href=\"{name}/index.html\"")),
            "{name}: not linked from {}",
            index.display()
        );
    }
    // The other scene kinds, and --set refused with several scenes.
    let rest = temp("rest");
    let (code, _, err) = run_cli(&[
        "run".as_ref(),
        scene("fall").as_os_str(),
        scene("high_jump").as_os_str(),
        "--set".as_ref(),
        "render.gif=false".as_ref(),
    ]);
    assert_eq!(code, Some(1));
    assert!(err.contains("apply to one scene"), "{err}");
    let out = bin()
        .arg("run")
        .args(["show_normal_jump", "high_jump", "fall", "active_knee_kick"].map(scene))
        .arg("--out")
        .arg(&rest)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let printed = headlines(&tour);
    for (name, lines) in &printed {
        for line in lines {
            assert!(
                text.contains(&format!("  {line}\n")),
                "{name}: {line} not printed"
            );
        }
    }
    let mut all = printed;
    all.extend(headlines(&rest));
    assert_eq!(all.len(), 7);
    for (name, lines) in &all {
        assert!(!lines.is_empty(), "{name}");
        for line in lines {
            // Every figure named is in the report (a renamed field would show as "(no …)").
            assert!(!line.contains("in the report)"), "{name}: {line}");
        }
    }
    // The evolution's lines carry its own numbers: the best damage fell in both groups.
    let evolve = &all
        .iter()
        .find(|(n, _)| n == "evolve_fall_quick")
        .unwrap()
        .1;
    for group in ["elderly", "adult"] {
        let line = evolve
            .iter()
            .find(|l| l.starts_with(&format!("{group}: best damage")))
            .unwrap_or_else(|| panic!("{evolve:?}"));
        let n: Vec<f64> = line.split(' ').filter_map(|w| w.parse().ok()).collect();
        assert!(n[1] < n[0], "{line}");
    }
}
