//! The body as standard files, cross-checked by independent engines: the URDF loaded in
//! Pinocchio gives the engine's RNEA and ABA to 1e-9 on random states (`tools/pinocchio_check.py`).
//! The Python side runs with the virtual environment `.ci/run` creates (`.venv/`, with `pin`);
//! when it is missing the test prints a SKIPPED line, except under CI, where it fails.

use std::io::Write;
use std::path::PathBuf;
use std::process::Command;

use glam::DQuat;
use marionette::dynamics::{Data, ForceVec, JointType, aba, rnea};
use marionette::humanoid::body::fall21_body;
use marionette::humanoid::export::to_urdf;
use marionette::humanoid::ranges::{AgeGroup, RangeTable};
use marionette::humanoid::strength::torque_limits;
use rand::{RngExt, SeedableRng};
use serde_json::json;

fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !matches!(v.trim(), "" | "0" | "false" | "FALSE"))
}

/// The virtual environment's python, or `None` after a SKIPPED line (a panic under CI).
fn venv_python() -> Option<PathBuf> {
    let py = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(".venv/bin/python");
    if py.is_file() {
        return Some(py);
    }
    if in_ci() {
        panic!(
            "{} not found and CI is set: .ci/run creates the virtual environment (pip install pin \
             mujoco) so the cross-checks run in CI",
            py.display()
        );
    }
    let _ = writeln!(
        std::io::stderr(),
        "SKIPPED: body cross-check: needs {} (run .ci/run once, or python3 -m venv .venv && \
         .venv/bin/pip install pin mujoco)",
        py.display()
    );
    None
}

#[test]
fn pinocchio_agrees_with_the_engines_rnea_and_aba_on_the_urdf() {
    let Some(py) = venv_python() else { return };
    let g = 9.81;
    let body = fall21_body(1.70, 65.0, g).unwrap();
    let group = AgeGroup::Elderly;
    let ranges = RangeTable::builtin(group).for_model(&body.figure).unwrap();
    let urdf = to_urdf(&body, &ranges, &torque_limits(group));
    let m = &body.model;
    // Per DOF: its velocity index and (not for the ball joint) its configuration index.
    let mut dofs = serde_json::Map::new();
    let mut neck_v = Vec::new();
    for (d, dof) in body.figure.dofs.iter().enumerate() {
        let b = dof.joint;
        let k = body.dof_v[d] - m.v_idx[b];
        let q = match m.bodies[b].joint {
            JointType::Ball { .. } => {
                neck_v.push(body.dof_v[d]);
                serde_json::Value::Null
            }
            _ => json!(m.q_idx[b] + k),
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
        let iq = m.q_idx[neck];
        q[iq..iq + 4].copy_from_slice(&[0.0, 0.0, 0.0, 1.0]);
        let mut v: Vec<f64> = (0..m.nv).map(|_| rng.random_range(-2.0..2.0)).collect();
        for &k in &neck_v {
            v[k] = 0.0;
        }
        let a: Vec<f64> = (0..m.nv).map(|_| rng.random_range(-5.0..5.0)).collect();
        let tau_in: Vec<f64> = (0..m.nv).map(|_| rng.random_range(-20.0..20.0)).collect();
        let tau_rnea = rnea(m, &mut data, &q, &v, &a, &zero).to_vec();
        let qdd_aba = aba(m, &mut data, &q, &v, &tau_in, &zero).to_vec();
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
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tools/pinocchio_check.py");
    let out = Command::new(&py)
        .arg(&script)
        .arg(&urdf_path)
        .arg(&states_path)
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    println!("{text}");
    std::fs::remove_dir_all(&dir).ok();
    assert!(out.status.success(), "pinocchio check failed: {text}");
}
