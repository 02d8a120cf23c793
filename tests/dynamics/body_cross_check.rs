//! The body as standard files, cross-checked by independent engines: the URDF loaded in
//! Pinocchio gives the engine's RNEA and ABA to 1e-9 on random states (`tools/pinocchio_check.py`);
//! the MJCF loaded in MuJoCo, driven by the same joint torques and push, follows the pushed fall's
//! head height until the first link other than the feet touches the floor
//! (`tools/mujoco_check.py`; within 3 cm: MuJoCo's own contact holds the feet).
//! The Python side runs with the virtual environment `.ci/run` creates (`.venv/`, with `pin`);
//! when it is missing the tests are ignored with that reason (`cfg(tool_python)`, `build.rs`),
//! and when it lacks a module they print a SKIPPED line; under CI both fail instead.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;

use glam::DQuat;
use marionette::dynamics::{Data, ForceVec, JointType, aba, rnea};
use marionette::humanoid::fall21_body;
use marionette::humanoid::strength::torque_limits;
use marionette::humanoid::to_urdf;
use marionette::humanoid::{AgeGroup, RangeTable};
use rand::{RngExt, SeedableRng};
use serde_json::json;

/// Runs `tools/<script>` with `args` under `py`, prints its output; returns success and output.
fn run_tool(py: &Path, script: &str, args: &[&dyn AsRef<std::ffi::OsStr>]) -> (bool, String) {
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tools")
        .join(script);
    let mut cmd = Command::new(py);
    cmd.arg(&script);
    for a in args {
        cmd.arg(a.as_ref());
    }
    let out = cmd.output().expect("python runs");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    println!("{text}");
    (out.status.success(), text)
}

#[test]
#[cfg_attr(
    not(tool_python),
    ignore = "needs the Python environment .venv (made by .ci/run) or MARIONETTE_PYTHON"
)]
fn pinocchio_agrees_with_the_engines_rnea_and_aba_on_the_urdf() {
    let Some(py) = common::python_with(&["pinocchio", "mujoco"]) else {
        return;
    };
    let g = 9.81;
    let body = fall21_body(1.70, 65.0, g).unwrap();
    let group = AgeGroup::Elderly;
    let ranges = RangeTable::builtin(group).for_figure(&body.figure).unwrap();
    let urdf = to_urdf(&body, &ranges, &torque_limits(group));
    let m = &body.model;
    // Per DOF: its velocity index and (not for the ball joint) its configuration index.
    let mut dofs = serde_json::Map::new();
    let mut neck_v = Vec::new();
    for (d, dof) in body.figure.dofs.iter().enumerate() {
        let b = dof.joint;
        let k = body.dof_v[d] - m.v_offset(b);
        let q = match m.bodies()[b].joint {
            JointType::Ball { .. } => {
                neck_v.push(body.dof_v[d]);
                serde_json::Value::Null
            }
            _ => json!(m.q_offset(b) + k),
        };
        dofs.insert(dof.name.clone(), json!({"v": body.dof_v[d], "q": q}));
    }
    let mut rng = rand_pcg::Pcg64::seed_from_u64(9);
    let mut data = Data::new(m);
    let zero = vec![ForceVec::ZERO; m.nbodies()];
    let mut states = Vec::new();
    for _ in 0..25 {
        let angles: Vec<f64> = (0..body.dof_v.len())
            .map(|_| rng.random_range(-1.0..1.0))
            .collect();
        let rot = DQuat::from_scaled_axis(glam::DVec3::new(
            rng.random_range(-2.0..2.0),
            rng.random_range(-2.0..2.0),
            rng.random_range(-2.0..2.0),
        ));
        let pos = glam::DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(0.0..2.0),
            rng.random_range(-1.0..1.0),
        );
        let mut q = body.configuration(&angles, pos, rot);
        // The neck at the identity and at rest (URDF writes it as three revolutes).
        let neck = body.link_index("head").unwrap();
        let iq = m.q_offset(neck);
        q[iq..iq + 4].copy_from_slice(&[0.0, 0.0, 0.0, 1.0]);
        let mut v: Vec<f64> = (0..m.nv()).map(|_| rng.random_range(-2.0..2.0)).collect();
        for &k in &neck_v {
            v[k] = 0.0;
        }
        let a: Vec<f64> = (0..m.nv()).map(|_| rng.random_range(-5.0..5.0)).collect();
        let tau_in: Vec<f64> = (0..m.nv()).map(|_| rng.random_range(-20.0..20.0)).collect();
        let tau_rnea = rnea(m, &mut data, &q, &v, &a, &zero).unwrap().to_vec();
        let qdd_aba = aba(m, &mut data, &q, &v, &tau_in, &zero).unwrap().to_vec();
        states.push(json!({
            "q": q, "v": v, "a": a, "tau_rnea": tau_rnea, "tau_in": tau_in, "qdd_aba": qdd_aba,
        }));
    }
    let dir = std::env::temp_dir().join(format!("marionette-pinocchio-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (urdf_path, states_path) = (dir.join("fall21.urdf"), dir.join("states.json"));
    std::fs::write(&urdf_path, urdf).unwrap();
    std::fs::write(
        &states_path,
        serde_json::to_string(&json!({"gravity": g, "dofs": dofs, "states": states})).unwrap(),
    )
    .unwrap();
    let ok = run_tool(&py, "pinocchio_check.py", &[&urdf_path, &states_path]);
    std::fs::remove_dir_all(&dir).ok();
    assert!(ok.0, "pinocchio check failed: {}", ok.1);
}

#[test]
#[cfg_attr(
    not(tool_python),
    ignore = "needs the Python environment .venv (made by .ci/run) or MARIONETTE_PYTHON"
)]
fn mujoco_follows_the_pushed_fall_until_first_contact() {
    use marionette::experiments::fall::{FallConfig, simulate_fall};
    use marionette::humanoid::to_mjcf;
    let Some(py) = common::python_with(&["pinocchio", "mujoco"]) else {
        return;
    };
    let cfg = FallConfig::paper(AgeGroup::Elderly);
    let r = simulate_fall(&cfg).unwrap();
    let body = fall21_body(cfg.height_m, cfg.mass_kg, cfg.gravity).unwrap();
    let ranges = RangeTable::builtin(AgeGroup::Elderly)
        .for_figure(&body.figure)
        .unwrap();
    let mjcf = to_mjcf(&body, &ranges, cfg.gravity);
    // Until the first link other than the feet touches the floor.
    let until = r
        .impacts
        .iter()
        .filter(|i| !i.link.ends_with("_foot"))
        .filter_map(|i| i.touchdown_s)
        .fold(f64::INFINITY, f64::min);
    assert!(until.is_finite());
    let limits = cfg.torque_limits_nm.clone().unwrap();
    // The paper's controller holds one pose throughout (key pose = stance, same gains).
    assert_eq!(cfg.key_pose_deg, cfg.stance_pose_deg);
    assert_eq!(cfg.kp, cfg.stance_kp);
    let dofs: Vec<_> = body
        .figure
        .dofs
        .iter()
        .enumerate()
        .map(|(d, dof)| {
            json!({
                "name": dof.name, "target": cfg.stance_pose_deg[d].to_radians(),
                "kp": cfg.stance_kp[d], "kv": cfg.stance_kv[d],
                "torque_min": limits[d].0, "torque_max": limits[d].1,
                "range": [ranges[d].0, ranges[d].1],
            })
        })
        .collect();
    let neck = body.link_index("head").unwrap();
    let JointType::Ball { axes } = body.model.bodies()[neck].joint else {
        panic!("the neck is a ball joint")
    };
    let start = &r.frames[0];
    let head: Vec<[f64; 2]> = r
        .frames
        .iter()
        .take_while(|f| f.time_s < until)
        .map(|f| [f.time_s, f.head_height_m])
        .collect();
    let fall = json!({
        "dt_s": cfg.dt_s, "dofs": dofs, "until_s": until,
        "neck_axes": [
            [axes.x_axis.x, axes.y_axis.x, axes.z_axis.x],
            [axes.x_axis.y, axes.y_axis.y, axes.z_axis.y],
            [axes.x_axis.z, axes.y_axis.z, axes.z_axis.z],
        ],
        "start": {
            "root_position": start.root_position.to_array(),
            "root_orientation": start.root_orientation.to_array(),
            "angles": start.angles,
        },
        "push": cfg.push,
        "limits": cfg.limits,
        "head_height": head,
    });
    let dir = std::env::temp_dir().join(format!("marionette-mujoco-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (xml, fall_path) = (dir.join("fall21.xml"), dir.join("fall.json"));
    std::fs::write(&xml, mjcf).unwrap();
    std::fs::write(&fall_path, serde_json::to_string(&fall).unwrap()).unwrap();
    // MuJoCo's own soft contact holds the feet (not the engine's corner springs), so the two
    // falls part by about 2.6 cm of head height by the first non-foot touchdown (measured).
    let tol = std::ffi::OsString::from("0.03");
    let ok = run_tool(&py, "mujoco_check.py", &[&xml, &fall_path, &tol]);
    std::fs::remove_dir_all(&dir).ok();
    assert!(ok.0, "mujoco check failed: {}", ok.1);
}
