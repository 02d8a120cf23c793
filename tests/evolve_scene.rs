//! The evolution scene from the command line: a short run writes every output, and a run cut
//! short and resumed ends with the same logbooks and report figures as a run straight through.

use std::path::{Path, PathBuf};
use std::process::Command;

use marionette::evolve::FallProblem;
use marionette::humanoid::ranges::AgeGroup;

fn marionette(args: &[&str]) -> std::process::Output {
    let out = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "marionette {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn tmp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("marionette-evolve-{}-{name}", std::process::id()))
}

fn report(dir: &Path) -> serde_json::Value {
    let mut r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    let o = r.as_object_mut().unwrap();
    for k in ["wall_time_s", "ga_wall_time_s", "checkpoint"] {
        o.remove(k);
    }
    r
}

const QUICK: [&str; 6] = [
    "--set",
    "seeds=[1,2]",
    "--set",
    "ga.population=6",
    "--set",
    "render.gif=false",
];

#[test]
fn a_resumed_evolution_ends_where_an_uninterrupted_one_does() {
    let (a, b, ck_a, ck_b) = (tmp("a"), tmp("b"), tmp("ck_a"), tmp("ck_b"));
    let s = |p: &Path| p.display().to_string();
    let ck = |p: &Path| format!("checkpoint_dir=\"{}\"", p.display());
    let mut straight = vec!["run", "scenes/evolve_fall.ron", "--out"];
    let (sa, sb, ca, cb) = (s(&a), s(&b), ck(&ck_a), ck(&ck_b));
    straight.extend([
        sa.as_str(),
        "--set",
        "ga.generations=3",
        "--set",
        ca.as_str(),
    ]);
    straight.extend(QUICK);
    marionette(&straight);
    for f in [
        "fitness.png",
        "head_height.png",
        "filmstrip.png",
        "fall_elderly_before.bvh",
        "fall_elderly_evolved.bvh",
        "fall_adult_before.bvh",
        "fall_adult_evolved.bvh",
        "best_elderly.controller.ron",
        "best_adult.controller.ron",
        "logbook_elderly_seed1.csv",
        "logbook_adult_seed2.jsonl",
    ] {
        assert!(a.join(f).is_file(), "{f} missing");
    }
    // One generation, then resumed to three.
    let mut first = vec!["run", "scenes/evolve_fall.ron", "--out"];
    first.extend([
        sb.as_str(),
        "--set",
        "ga.generations=1",
        "--set",
        cb.as_str(),
    ]);
    first.extend(QUICK);
    marionette(&first);
    let ckb = s(&ck_b);
    let mut resumed = vec!["run", "scenes/evolve_fall.ron", "--out"];
    resumed.extend([
        sb.as_str(),
        "--set",
        "ga.generations=3",
        "--resume",
        ckb.as_str(),
    ]);
    resumed.extend(QUICK);
    marionette(&resumed);
    assert_eq!(report(&a), report(&b));
    for f in ["logbook_elderly_seed1.csv", "logbook_adult_seed2.csv"] {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{f}"
        );
    }
    let r = report(&a);
    assert_eq!(r["generations"], 3);
    // The population and seeds given by --set are the ones reported.
    assert_eq!(r["population"], 6);
    let groups = r["groups"].as_array().unwrap();
    assert_eq!(groups.len(), 2);
    for g in groups {
        assert_eq!(g["seeds"], serde_json::json!([1, 2]), "{}", g["age_group"]);
        let initial = g["initial"]["mean"].as_f64().unwrap();
        let fin = g["final"]["mean"].as_f64().unwrap();
        assert!(fin <= initial, "best so far rose: {initial} → {fin}");
    }
    // The best controller replays in the Fall scene: the same damage as the evolution's replay.
    let replay = tmp("replay");
    let file = format!(
        "controller_file=\"{}\"",
        a.join("best_adult.controller.ron").display()
    );
    let replay_on = |group: &str| {
        marionette(&[
            "run",
            "scenes/fall.ron",
            "--out",
            &s(&replay),
            "--set",
            &format!("age_group={group}"),
            "--set",
            "compare_with=null",
            "--set",
            "render.gif=false",
            "--set",
            &file,
        ])
    };
    replay_on("adult");
    // The file carries the step it was evolved at; the Fall scene takes it. It names the
    // group it was evolved for, and the report says so.
    let fall = report(&replay);
    assert_eq!(fall["controller_evolved_for"], "adult");
    assert_eq!(fall["age_group"], "adult");
    assert_eq!(
        fall["dt_s"].as_f64(),
        Some(FallProblem::paper(AgeGroup::Adult).fall.dt_s)
    );
    let evolved = r["best_falls"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["fall"] == "adult evolved")
        .unwrap()["honesty"]["damage"]
        .as_f64()
        .unwrap();
    let replayed = fall["damage"].as_f64().unwrap();
    assert!(
        (replayed - evolved).abs() <= 1e-9 * evolved,
        "replayed {replayed} N vs evolved {evolved} N"
    );
    // Run on the other figure only, the fall says whose controller it is running.
    let other = replay_on("elderly");
    let note = String::from_utf8_lossy(&other.stderr);
    assert!(
        note.contains("evolved for the adult figure") && note.contains("--set age_group=adult"),
        "{note}"
    );
    assert_eq!(report(&replay)["controller_evolved_for"], "adult");
    std::fs::remove_dir_all(&replay).ok();
    // A scene step that contradicts the controller's is refused, naming the way out.
    let out = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["run", "scenes/fall.ron", "--out", &s(&replay)])
        .args(["--set", &file, "--set", "simulation.dt=0.0005"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    let evolved_at = format!("dt_s = {} s", FallProblem::paper(AgeGroup::Adult).fall.dt_s);
    assert!(
        err.contains("controller.dt_s") && err.contains(&evolved_at),
        "{err}"
    );
    std::fs::remove_dir_all(&replay).ok();
    // A resume from another experiment is refused.
    let out = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args([
            "run",
            "scenes/evolve_fall.ron",
            "--out",
            &sb,
            "--resume",
            &ckb,
        ])
        .args(["--set", "seeds=[7]"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("another scene"));
    for d in [a, b, ck_a, ck_b] {
        std::fs::remove_dir_all(d).ok();
    }
}
