//! The bodies stepped in the lanes of one vector computation, and the processor-specific copy
//! of the step, on the pushed fall21 figure (free root, pins, universals, the ball neck, PD, the
//! joint model, floor contact on every link, the push): each gives the bits of the plain scalar
//! path.

use std::process::Command;

use glam::{DQuat, DVec3};
use marionette::dynamics::LANES;
use marionette::dynamics::forces::pd::PdTargets;
use marionette::dynamics::pipeline::{LaneBody, step, step_lanes};
use marionette::dynamics::{
    Data, ForceVec, Forces, Integrator, State, StepMonitor, StepSettings, StepWorkspace,
    aba_passes, kinematics,
};
use marionette::dynamics::{LaneData, LaneInput, aba_passes_lanes};
use marionette::experiments::fall::{FallConfig, build_fall};
use marionette::humanoid::AgeGroup;
use marionette::humanoid::fall21_body;

/// The bits of every state of the pushed elderly fall stepped 2400 times by [`step`] (1.2 s),
/// one line per step, then the final monitor; panics unless some link other than the feet
/// touched the floor (the fall happened).
fn fall_steps() -> Vec<String> {
    let ch = build_fall(&FallConfig::paper(AgeGroup::Elderly)).expect("the paper's fall builds");
    let body = &ch.human.0;
    let forces = Forces {
        dofs: &body.dof_v,
        pd: Some(&ch.pd.0),
        limits: Some(&ch.limits.0),
        contact: Some(&*ch.contact.0),
        external: ch.external.all(),
    };
    let settings = StepSettings {
        integrator: ch.physics.body.integrator,
        dt: 5e-4,
    };
    let model = &body.model;
    let mut state = ch.physics.state.0.clone();
    let mut ws = StepWorkspace::new(model);
    let mut monitor = StepMonitor::new(body.link_names.len(), body.dof_v.len());
    let mut lines = Vec::new();
    for _ in 0..2400 {
        step(model, settings, &forces, &mut state, &mut ws, &mut monitor).unwrap();
        let bits: Vec<String> = state
            .q
            .iter()
            .chain(&state.v)
            .map(|x| format!("{:x}", x.to_bits()))
            .collect();
        lines.push(bits.join(" "));
    }
    let touched = (0..body.link_names.len())
        .filter(|&l| !body.link_names[l].ends_with("_foot") && monitor.contact.peak[l] > 0.0)
        .count();
    assert!(
        touched > 0,
        "no link but the feet touched the floor in 1.2 s"
    );
    lines.push(format!("{monitor:?}"));
    lines
}

/// Set in the child process of
/// [`the_processor_specific_step_gives_the_portable_steps_bits`]: it prints its steps.
const CHILD: &str = "MARIONETTE_TEST_PRINT_STEPS";

/// `step` takes the AVX2 copy of the stages where the processor has it and the portable copy
/// under `MARIONETTE_PORTABLE` (decided once per process): this process's steps against those of
/// a child process of this test run portable, the same bits at every step.
#[test]
fn the_processor_specific_step_gives_the_portable_steps_bits() {
    // The test's full name in this binary: its module path without the crate.
    let module = module_path!().split_once("::").map_or("", |(_, m)| m);
    let name = format!("{module}::the_processor_specific_step_gives_the_portable_steps_bits");
    let here = fall_steps();
    if std::env::var_os(CHILD).is_some() {
        // A line of its own first: the test harness's "test NAME ... " is not ended by a
        // newline before the test's own output.
        println!();
        for l in &here {
            println!("step {l}");
        }
        return;
    }
    let out = Command::new(std::env::current_exe().unwrap())
        .args([name.as_str(), "--exact", "--nocapture", "--test-threads=1"])
        .env(CHILD, "1")
        .env("MARIONETTE_PORTABLE", "1")
        .output()
        .expect("the test runs itself");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let portable: Vec<&str> = text
        .lines()
        .filter_map(|l| l.strip_prefix("step "))
        .collect();
    assert_eq!(portable.len(), here.len(), "{text}");
    for (n, (a, b)) in here.iter().zip(&portable).enumerate() {
        assert_eq!(a, b, "step {n}");
    }
}

#[test]
fn bodies_stepped_in_lanes_have_the_bits_of_bodies_stepped_alone() {
    // Five pushed fall21 figures with different PD targets and gains (a group of four
    // lanes and one body with three empty lanes), stepped by `step_lanes` and each alone by
    // `step`: the same states at every step and the same monitors; with joint damping
    // taken implicitly (the fall's scheme) and explicitly.
    let ch = build_fall(&FallConfig::paper(AgeGroup::Elderly)).expect("the paper's fall builds");
    let body = &ch.human.0;
    let model = &body.model;
    let nd = body.dof_v.len();
    let pds: Vec<PdTargets> = (0..5)
        .map(|b| {
            let mut pd = ch.pd.0.clone();
            for d in 0..nd {
                let x = (b * nd + d) as f64;
                pd.target[d] += 0.3 * (0.7 * x).sin();
                pd.kp[d] *= 0.5 + 0.25 * b as f64;
            }
            pd
        })
        .collect();
    let forces_of = |pd| Forces {
        dofs: &body.dof_v,
        pd: Some(pd),
        limits: Some(&ch.limits.0),
        contact: Some(&*ch.contact.0),
        external: ch.external.all(),
    };
    for implicit_damping in [true, false] {
        let settings = StepSettings {
            integrator: Integrator::SemiImplicitEuler { implicit_damping },
            dt: 5e-4,
        };
        let fresh = || {
            (0..5)
                .map(|_| {
                    (
                        ch.physics.state.0.clone(),
                        StepWorkspace::new(model),
                        StepMonitor::new(body.link_names.len(), nd),
                    )
                })
                .collect::<Vec<_>>()
        };
        let (mut alone, mut laned) = (fresh(), fresh());
        let mut lanes = LaneData::new(model);
        for n in 0..2400 {
            for (b, (state, ws, monitor)) in alone.iter_mut().enumerate() {
                step(model, settings, &forces_of(&pds[b]), state, ws, monitor).unwrap();
            }
            let mut bodies: Vec<LaneBody> = laned
                .iter_mut()
                .zip(&pds)
                .map(|((state, ws, monitor), pd)| LaneBody {
                    forces: forces_of(pd),
                    state,
                    ws,
                    monitor,
                    result: Ok(()),
                })
                .collect();
            step_lanes(model, settings, &mut bodies, &mut lanes);
            assert!(bodies.iter().all(|b| b.result.is_ok()), "step {n}");
            drop(bodies);
            let bits =
                |s: &State| -> Vec<u64> { s.q.iter().chain(&s.v).map(|x| x.to_bits()).collect() };
            for b in 0..5 {
                assert_eq!(bits(&alone[b].0), bits(&laned[b].0), "body {b}, step {n}");
            }
        }
        for b in 0..5 {
            assert_eq!(alone[b].0, laned[b].0);
            assert_eq!(alone[b].2, laned[b].2, "monitor of body {b}");
        }
        // The bodies fell differently.
        assert_ne!(alone[0].0.q, alone[4].0.q);
    }
}

#[test]
fn every_lane_has_the_bits_of_the_scalar_aba() {
    // Four different states, joint forces, external forces and armatures of the fall21
    // body (free root, pins, universals, the ball neck): each lane's q̈ is the scalar
    // ABA's to the bit, with and without armature.
    let body = fall21_body(1.70, 65.0, 9.81).expect("fall21 body");
    let model = &body.model;
    let lane_inputs = |l: usize| {
        let x = l as f64 + 1.0;
        let angles: Vec<f64> = (0..21)
            .map(|k| 0.4 * ((k as f64) * 0.7 * x).sin())
            .collect();
        let q = body.configuration(
            &angles,
            DVec3::new(0.1 * x, 0.9, -0.2),
            DQuat::from_axis_angle(DVec3::new(0.2, 1.0, 0.1 * x).normalize(), 0.4 * x),
        );
        let v: Vec<f64> = (0..model.nv())
            .map(|k| 0.5 * ((k as f64) * 1.3 + x).cos())
            .collect();
        let tau: Vec<f64> = (0..model.nv())
            .map(|k| {
                if k < 6 {
                    0.0
                } else {
                    10.0 * ((k as f64) * 0.9 * x).sin()
                }
            })
            .collect();
        let f_ext: Vec<ForceVec> = (0..model.nbodies())
            .map(|i| {
                ForceVec::new(
                    DVec3::new(0.1, -0.3 * x, 0.2) * i as f64,
                    DVec3::new(x, 50.0 * x, 3.0),
                )
            })
            .collect();
        let arm: Vec<f64> = (0..model.nv()).map(|k| 1e-3 * (k as f64 + x)).collect();
        (q, v, tau, f_ext, arm)
    };
    let inputs: Vec<_> = (0..LANES + 1).map(lane_inputs).collect();
    for with_armature in [false, true] {
        let mut scalar: Vec<Data> = (0..=LANES).map(|_| Data::new(model)).collect();
        let mut lane: Vec<Data> = (0..=LANES).map(|_| Data::new(model)).collect();
        for l in 0..=LANES {
            let (q, v, tau, f_ext, arm) = &inputs[l];
            kinematics(model, &mut scalar[l], q, v);
            kinematics(model, &mut lane[l], q, v);
            let arm = with_armature.then_some(&arm[..]);
            aba_passes(model, &mut scalar[l], tau, f_ext, arm, &[]);
        }
        let mut ld = LaneData::new(model);
        let mut bodies: Vec<LaneInput> = lane
            .iter_mut()
            .zip(&inputs)
            .map(|(data, (_, _, tau, f_ext, arm))| LaneInput {
                data,
                tau,
                f_ext,
                armature: with_armature.then_some(&arm[..]),
            })
            .collect();
        // Five bodies: a full group of four and one alone with three empty lanes.
        aba_passes_lanes(model, &mut ld, &mut bodies);
        for l in 0..=LANES {
            let bits = |d: &Data| d.qdd.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(
                bits(&lane[l]),
                bits(&scalar[l]),
                "lane {l}, armature {with_armature}"
            );
            assert!(scalar[l].qdd.iter().any(|x| x.abs() > 1e-3));
        }
        // The lanes differ from each other (the inputs do).
        assert_ne!(lane[0].qdd, lane[1].qdd);
    }
}
