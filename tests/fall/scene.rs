//! The falling paper's scene end to end: the pushed figure falls backward, comes to rest, never
//! compresses its soft tissue more than the published stiffnesses imply, reports each link's
//! impact and the pelvis beside real falls, and `--set` reaches the time step, integrator, age group
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
    assert!(r["max_penetration_m"].as_f64().unwrap() < 0.09);
    // The impact of every link and the pelvis beside the published older-adult values.
    assert_eq!(r["impacts"].as_array().unwrap().len(), 15);
    let pelvis = &r["pelvis"];
    assert!(pelvis["impact_velocity_m_s"].as_f64().unwrap() > 0.5);
    assert!(pelvis["descent_time_s"].as_f64().unwrap() > 0.1);
    assert_eq!(
        pelvis["published_older_adults"]["impact_velocity_m_s"]["mean"],
        2.1
    );
    let standing = &r["standing_start"];
    assert!(standing["weight_n"].as_f64().unwrap() > 600.0);
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
        "fall.dt_s=0.00025",
        "fall.push.force_n=1200",
        "render.gif=false",
    ]);
    assert_eq!(r["age_group"], "adult");
    assert_eq!(r["dt_s"].as_f64().unwrap(), 0.00025);
    assert_eq!(r["steps"].as_u64().unwrap(), 12000);
    let rk4 = run_fall(&[
        "fall.integrator=Rk4",
        "fall.dt_s=0.00025",
        "render.gif=false",
    ]);
    assert_eq!(rk4["came_to_rest"], serde_json::Value::Bool(true));
}

#[test]
fn set_reaches_a_single_field_of_every_block() {
    // The fall's contact and push blocks, and its single fields, take one field without
    // restating the others.
    let r = run_fall(&[
        "fall.contact.stiffness_scale=1.2",
        "fall.mass_kg=70",
        "fall.push.start_s=0.12",
        "compare_with=null",
        "render.gif=false",
    ]);
    let w = r["standing_start"]["weight_n"].as_f64().unwrap();
    assert!((w - 70.0 * 9.81).abs() < 1e-9, "weight {w}");
    // The old per-kilogram contact field is named as unknown, with the fields there.
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/fall.ron");
    let scene = Scene::load(&path).unwrap();
    let e = apply_overrides(&scene, &["fall.contact.stiffness_per_kg=1".to_string()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("stiffness_scale"), "{e}");
}

#[test]
fn impossible_runs_are_refused_up_front() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/fall.ron");
    let scene = Scene::load(&path).unwrap();
    let out = std::env::temp_dir().join(format!("marionette-fall-refused-{}", std::process::id()));
    for (sets, expect) in [
        (vec!["fall.duration_s=1e9"], "duration_s"),
        (vec!["fall.dt_s=1e-9"], "duration_s"),
        (vec!["fall.push.start_s=5"], "push.start_s"),
        (
            vec!["controller.dt_s=0.0009", "fall.dt_s=0.0005"],
            "evolved at, dt_s = 0.0009 s",
        ),
    ] {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        let s = apply_overrides(&scene, &sets).unwrap();
        let e = run(&s, path.parent().unwrap(), &out)
            .unwrap_err()
            .to_string();
        assert!(e.contains(expect), "{sets:?}: {e}");
    }
    std::fs::remove_dir_all(&out).ok();
}

/// Under `--set` of the damage weights and the age groups, the report's damage is
/// `D = Σ w_i f_i` of the weights it lists (those given, the rest the defaults) and its peak
/// forces, for the first figure and the compared one, and each names its own age group.
#[test]
fn the_report_follows_damage_weights_and_age_groups_under_set() {
    let r = run_fall(&[
        "fall.damage_weights.head=3.0",
        "fall.damage_weights.pelvis=0.5",
        "age_group=adult",
        "compare_with=elderly",
        "render.gif=false",
    ]);
    assert_eq!(r["age_group"], "adult");
    assert_eq!(r["compared"]["age_group"], "elderly");
    let w = &r["damage_weights"];
    assert_eq!(w["head"].as_f64(), Some(3.0), "{w}");
    assert_eq!(w["pelvis"].as_f64(), Some(0.5), "{w}");
    for (who, rep) in [("adult", &r), ("elderly", &r["compared"])] {
        let forces = rep["peak_vertical_force_n"].as_object().unwrap();
        let d: f64 = forces
            .iter()
            .map(|(link, f)| w[link].as_f64().unwrap_or(0.0) * f.as_f64().unwrap())
            .sum();
        let reported = rep["damage"].as_f64().unwrap();
        assert!(
            (d - reported).abs() <= 1e-9 * reported.abs().max(1.0),
            "{who}: damage {reported} vs Σ w·f {d}"
        );
        assert!(reported > 0.0, "{who}: no damage");
    }
}
