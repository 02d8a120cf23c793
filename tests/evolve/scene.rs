//! The evolution scene from the command line: a short run writes every output, and a run cut
//! short and resumed ends with the same logbooks and report figures as a run straight through.

use std::path::{Path, PathBuf};
use std::process::Command;

use marionette::evolve::checkpoint;
use marionette::scene::GaStep;

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
    assert_eq!(fall["dt_s"].as_f64(), Some(GaStep::midpoint_2ms().dt_s));
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
        .args(["--set", &file, "--set", "fall.dt_s=0.001"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    let evolved_at = format!("dt_s = {} s", GaStep::midpoint_2ms().dt_s);
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
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("seeds: the checkpoint has [1,2], the scene asks [7]"),
        "{err}"
    );
    for d in [a, b, ck_a, ck_b] {
        std::fs::remove_dir_all(d).ok();
    }
}

/// `marionette args…`, whatever its exit.
fn marionette_any(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap()
}

/// A quick run of the adult group over `seeds` to `generations`, its checkpoint in `ck`, with
/// `more` overrides; returns what it printed.
fn quick_run(
    out: &Path,
    ck: &Path,
    seeds: &str,
    generations: u64,
    resume: bool,
    more: &[&str],
) -> std::process::Output {
    let (out, ck) = (out.display().to_string(), ck.display().to_string());
    let (seeds, generations) = (
        format!("seeds={seeds}"),
        format!("ga.generations={generations}"),
    );
    let ck_set = format!("checkpoint_dir=\"{ck}\"");
    let mut args = vec!["run", "scenes/evolve_fall.ron", "--out", &out];
    args.extend(["--set", "groups=[adult]", "--set", "ga.population=6"]);
    args.extend([
        "--set",
        "render.gif=false",
        "--set",
        &seeds,
        "--set",
        &generations,
    ]);
    if resume {
        args.extend(["--resume", &ck]);
    } else {
        args.extend(["--set", &ck_set]);
    }
    args.extend(more);
    marionette_any(&args)
}

/// Edits the runs of the checkpoint in `ck` as another writer could: the file stays well
/// formed and, if `reseal`, its checksum is that of the edited content.
fn edit_checkpoint(ck: &Path, reseal: bool, edit: impl FnOnce(&mut serde_json::Value)) {
    let file = ck.join(checkpoint::FILE);
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    edit(&mut v["content"]);
    let text = if reseal {
        checkpoint::encode(&v["content"]).unwrap()
    } else {
        serde_json::to_string(&v).unwrap()
    };
    std::fs::write(&file, text).unwrap();
}

/// A change to one run of a checkpoint.
type Edit = fn(&mut serde_json::Value);

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn a_resume_refuses_another_experiment_or_a_broken_checkpoint_saying_what() {
    let (out, ck, saved) = (tmp("other"), tmp("other_ck"), tmp("other_saved"));
    let made = quick_run(&out, &ck, "[3,4]", 1, false, &[]);
    assert!(made.status.success(), "{}", stderr(&made));
    std::fs::create_dir_all(&saved).unwrap();
    std::fs::copy(ck.join("checkpoint.json"), saved.join("checkpoint.json")).unwrap();
    let restore = || {
        std::fs::copy(saved.join("checkpoint.json"), ck.join("checkpoint.json")).unwrap();
    };
    // Other seeds: refused, naming the setting and both values.
    let o = quick_run(&out, &ck, "[1,2]", 2, true, &[]);
    let err = stderr(&o);
    assert!(!o.status.success(), "resumed seeds [3, 4] as [1, 2]: {err}");
    assert!(
        err.contains("seeds") && err.contains("[3,4]") && err.contains("[1,2]"),
        "{err}"
    );
    // Another GA setting: named with both values.
    let o = quick_run(
        &out,
        &ck,
        "[3,4]",
        2,
        true,
        &["--set", "ga.mutation_eta=30.0"],
    );
    let err = stderr(&o);
    assert!(!o.status.success());
    assert!(
        err.contains("ga.mutation_eta") && err.contains("20") && err.contains("30"),
        "{err}"
    );
    // Fewer generations than the checkpoint already holds: named as such.
    let longer = quick_run(&out, &ck, "[3,4]", 2, true, &[]);
    assert!(longer.status.success(), "{}", stderr(&longer));
    let o = quick_run(&out, &ck, "[3,4]", 1, true, &[]);
    let err = stderr(&o);
    assert!(!o.status.success());
    assert!(
        err.contains("ga.generations") && err.contains("generation 2"),
        "{err}"
    );
    // Lists cut by one entry or emptied: refused, never a panic, naming the file, the run and
    // the list.
    let cuts: [(&str, Edit); 4] = [
        ("fitness", |r| {
            drop(r["state"]["fitness"].as_array_mut().unwrap().pop())
        }),
        ("population", |r| {
            drop(r["state"]["population"].as_array_mut().unwrap().pop())
        }),
        ("bounds", |r| {
            drop(r["state"]["bounds"]["hi"].as_array_mut().unwrap().pop())
        }),
        ("population", |r| {
            for k in ["population", "fitness", "checked"] {
                r["state"][k] = serde_json::json!([]);
            }
        }),
    ];
    for (what, cut) in cuts {
        restore();
        edit_checkpoint(&ck, true, |runs| cut(&mut runs[1]));
        let o = quick_run(&out, &ck, "[3,4]", 2, true, &[]);
        let err = stderr(&o);
        assert_ne!(o.status.code(), Some(101), "{what}: panicked: {err}");
        assert!(!o.status.success(), "{what}: accepted");
        assert!(
            err.contains("checkpoint.json") && err.contains("adult seed 4") && err.contains(what),
            "{what}: {err}"
        );
    }
    // Edited values: refused for the checksum unless it was updated, and then for what is
    // wrong in them.
    let edits: [(&str, Edit); 4] = [
        ("seeds: the checkpoint has [3,9]", |r| {
            r["state"]["config"]["seed"] = serde_json::json!(9)
        }),
        ("generation", |r| {
            r["state"]["generation"] = serde_json::json!(0)
        }),
        ("fitness of individual 2 is -1", |r| {
            r["state"]["fitness"][2] = serde_json::json!(-1.0)
        }),
        ("outside its bounds", |r| {
            r["state"]["population"][1][0] = serde_json::json!(1e308)
        }),
    ];
    for (what, edit) in edits {
        for reseal in [false, true] {
            restore();
            edit_checkpoint(&ck, reseal, |runs| edit(&mut runs[1]));
            let o = quick_run(&out, &ck, "[3,4]", 2, true, &[]);
            let err = stderr(&o);
            assert!(!o.status.success(), "{what}: accepted");
            let said = if reseal { what } else { "checksum" };
            assert!(
                err.contains("checkpoint") && err.contains(said),
                "{what}: {err}"
            );
        }
    }
    for d in [out, ck, saved] {
        std::fs::remove_dir_all(d).ok();
    }
}

#[test]
fn a_generation_of_failed_falls_stops_the_run_and_its_resume_says_why() {
    let (out, ck) = (tmp("failing"), tmp("failing_ck"));
    // A step of 50 ms: every genome is refused by the stability check before it runs.
    let fall = ["--set", r#"fall={"dt_s":0.05}"#];
    let o = quick_run(&out, &ck, "[1]", 3, false, &fall);
    let err = stderr(&o);
    assert!(!o.status.success());
    assert!(
        err.contains("generation 0") && err.contains("6 of 6") && err.contains("stability"),
        "{err}"
    );
    assert!(!err.contains("not finite"), "{err}");
    let line = err
        .lines()
        .find(|l| l.contains("6 of 6"))
        .unwrap()
        .to_string();
    let o = quick_run(&out, &ck, "[1]", 3, true, &fall);
    let again = stderr(&o);
    assert!(!o.status.success());
    assert!(again.contains(&line), "first:\n{err}\nresumed:\n{again}");
    for d in [out, ck] {
        std::fs::remove_dir_all(d).ok();
    }
}

/// Point 6 of issue 38: a worker that never answered hung the run forever, with no line on the
/// terminal.
#[test]
fn a_silent_worker_stops_the_run_at_the_timeout_saying_who_and_what_it_said() {
    let (out, ck) = (tmp("silent"), tmp("silent_ck"));
    let silent = r#"evaluator={"Command":["sh","-c","echo starting >&2; cat > /dev/null"]}"#;
    let t0 = std::time::Instant::now();
    let o = quick_run(
        &out,
        &ck,
        "[1]",
        2,
        false,
        &["--set", silent, "--set", "worker_timeout_s=1.5"],
    );
    let err = stderr(&o);
    assert!(!o.status.success(), "{err}");
    assert!(t0.elapsed().as_secs() < 30, "{:?}", t0.elapsed());
    assert!(
        err.contains("waiting for the worker `sh -c echo starting"),
        "{err}"
    );
    assert!(
        err.contains("answered 0 of the 6 genomes of generation 0 in 1.5 s, the batch timeout"),
        "{err}"
    );
    assert!(err.contains("on stderr \"starting\""), "{err}");
    let o = quick_run(&out, &ck, "[1]", 2, false, &["--set", "worker_timeout_s=0"]);
    let err = stderr(&o);
    assert!(!o.status.success());
    assert!(
        err.contains("worker_timeout_s must be in (0, 604800] seconds, found 0"),
        "{err}"
    );
    for d in [out, ck] {
        std::fs::remove_dir_all(d).ok();
    }
}
