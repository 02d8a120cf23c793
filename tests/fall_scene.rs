//! The falling paper's scene end to end: the pushed figure falls backward, comes to rest, never
//! sinks a centimetre into the floor, and `--set` reaches the time step, integrator, age group
//! and push.

use std::path::PathBuf;

use marionette::scene::{Scene, apply_overrides, run};

fn run_fall(sets: &[&str]) -> serde_json::Value {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/fall.ron");
    let scene = Scene::load(&path).unwrap();
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let scene = apply_overrides(&scene, &sets).unwrap();
    let out = std::env::temp_dir().join(format!(
        "marionette-fall-{}-{}",
        std::process::id(),
        sets.join("_").replace(['/', '='], "-")
    ));
    let report = run(&scene, path.parent().unwrap(), &out).unwrap();
    for f in [
        "fall.bvh",
        "filmstrip.png",
        "head_height.png",
        "report.json",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    std::fs::remove_dir_all(&out).ok();
    report
}

#[test]
fn pushed_from_the_front_the_figure_falls_backward_and_rests() {
    let r = run_fall(&["render.gif=false"]);
    let z = r["final_pelvis_position_m"][2].as_f64().unwrap();
    assert!(
        z < -0.3,
        "pelvis ended at z = {z} m: the push from the front must send it backward (−Z)"
    );
    assert_eq!(r["came_to_rest"], serde_json::Value::Bool(true));
    assert!(r["max_penetration_m"].as_f64().unwrap() < 0.01);
    assert!(
        r["final_head_height_m"].as_f64().unwrap() < 0.3,
        "the head ends near the floor"
    );
    let d = r["damage"].as_f64().unwrap();
    assert!(d.is_finite() && d > 0.0);
    // The adult figure took the same push in its own World beside it; before any evolution the
    // two groups' damage is about the same (the paper's starting point).
    assert_eq!(r["compared"]["age_group"], "adult");
    let d_adult = r["compared"]["damage"].as_f64().unwrap();
    assert!(
        (d_adult - d).abs() / d < 0.1,
        "elderly {d} vs adult {d_adult}"
    );
    for k in ["peak_vertical_force_n", "impulse_n_s"] {
        assert_eq!(r[k].as_object().unwrap().len(), 15, "{k} per link");
    }
}

#[test]
fn set_reaches_the_age_group_step_integrator_and_push() {
    let r = run_fall(&[
        "age_group=adult",
        "simulation.dt=0.00025",
        "push.force_n=1200",
        "render.gif=false",
    ]);
    assert_eq!(r["age_group"], "adult");
    assert_eq!(r["dt_s"].as_f64().unwrap(), 0.00025);
    assert_eq!(r["steps"].as_u64().unwrap(), 12000);
    let rk4 = run_fall(&[
        "simulation.integrator=Rk4",
        "simulation.dt=0.00025",
        "render.gif=false",
    ]);
    assert_eq!(rk4["came_to_rest"], serde_json::Value::Bool(true));
}
