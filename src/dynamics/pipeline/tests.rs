use super::*;
use crate::dynamics::forces::contact::{ContactGains, ContactParams, LinkBox};
use crate::dynamics::joint::JointType;
use crate::dynamics::model::Body;
use crate::dynamics::spatial::{Inertia, SpatialTransform};
use glam::DVec3;

const SIZE: DVec3 = DVec3::new(0.4, 0.2, 0.3);

/// No force at all.
const NO_FORCES: Forces<'static> = Forces {
    dofs: &[],
    pd: None,
    limits: None,
    contact: None,
    external: &[],
};

/// Semi-implicit Euler, damping explicit, steps of 1 ms.
const EULER_1MS: StepSettings = StepSettings {
    integrator: Integrator::SemiImplicitEuler {
        implicit_damping: false,
    },
    dt: 1e-3,
};

fn free_box() -> Model {
    Model::new(
        vec![Body {
            name: "box".into(),
            joint_name: "free".into(),
            parent: None,
            joint: JointType::Free,
            x_tree: SpatialTransform::IDENTITY,
            inertia: Inertia::solid_box(2.0, DVec3::ZERO, SIZE),
        }],
        DVec3::new(0.0, -9.81, 0.0),
    )
    .unwrap()
}

fn run(model: &Model, forces: &Forces, steps: usize) -> (State, StepMonitor) {
    let mut q = model.neutral();
    q[1] = 0.5;
    let mut state = State::new(q, vec![0.0; model.nv], 1);
    let mut ws = StepWorkspace::new(model);
    let mut monitor = StepMonitor::new(1, 0);
    let settings = EULER_1MS;
    for _ in 0..steps {
        step(model, settings, forces, &mut state, &mut ws, &mut monitor).unwrap();
    }
    (state, monitor)
}

#[test]
fn a_force_that_is_absent_is_not_felt() {
    let model = free_box();
    let none = NO_FORCES;
    // Free fall, semi-implicit Euler's closed form: y_n = y_0 − g h² n(n+1)/2.
    let n = 1000;
    let (s, m) = run(&model, &none, n);
    let expected = 0.5 - 9.81 * 1e-6 * (n * (n + 1)) as f64 / 2.0;
    assert!(
        (s.q[1] - expected).abs() < 1e-9,
        "y = {} vs {expected}",
        s.q[1]
    );
    assert_eq!(s.steps, n as u64);
    assert!((s.time_s - 1.0).abs() < 1e-12);
    assert_eq!(m.contact.peak[0], 0.0);
    // With the floor it rests on it, carrying its weight.
    let cm = ContactModel::new(
        &[LinkBox {
            center: DVec3::ZERO,
            half: SIZE * 0.5,
        }],
        &[2.0],
        &[ContactGains::per_kg(2.0, 1.2e5 * 4.0, 160.0)],
        ContactParams::default(),
    );
    let floor = Forces {
        contact: Some(&cm),
        ..none
    };
    let (s, m) = run(&model, &floor, 3000);
    assert!(s.q[1] > 0.09 && s.q[1] < 0.1, "y = {}", s.q[1]);
    assert!((m.sample.normal[0] - 2.0 * 9.81).abs() < 0.05 * 2.0 * 9.81);
    assert!(m.contact.peak[0] > 2.0 * 9.81);
    // An upward external force equal to the weight holds it in the air.
    let lift = [ExternalForce {
        body: 0,
        point: DVec3::ZERO,
        force: DVec3::new(0.0, 2.0 * 9.81, 0.0),
        torque: DVec3::ZERO,
        start_s: 0.0,
        duration_s: f64::INFINITY,
    }];
    let held = Forces {
        external: &lift,
        ..none
    };
    let (s, _) = run(&model, &held, 1000);
    assert!((s.q[1] - 0.5).abs() < 1e-9, "y = {}", s.q[1]);
}

/// Drops the box from 0.3 m onto a floor with a heavily damped contact (ζ ≈ 3 flat) for
/// `seconds` at step `dt`; the final state, or the step error.
fn drop_on_damped_floor(implicit_damping: bool, dt: f64, seconds: f64) -> Result<State, StepError> {
    let model = free_box();
    let cm = ContactModel::new(
        &[LinkBox {
            center: DVec3::ZERO,
            half: SIZE * 0.5,
        }],
        &[2.0],
        &[ContactGains::per_kg(2.0, 1.0e5, 2000.0)],
        ContactParams {
            implicit_damping,
            ..ContactParams::default()
        },
    );
    let forces = Forces {
        dofs: &[],
        pd: None,
        limits: None,
        contact: Some(&cm),
        external: &[],
    };
    let mut q = model.neutral();
    q[1] = 0.3;
    let mut state = State::new(q, vec![0.0; model.nv], 1);
    let mut ws = StepWorkspace::new(&model);
    let mut monitor = StepMonitor::new(1, 0);
    let settings = StepSettings {
        integrator: Integrator::SemiImplicitEuler {
            implicit_damping: true,
        },
        dt,
    };
    for _ in 0..(seconds / dt).round() as usize {
        step(&model, settings, &forces, &mut state, &mut ws, &mut monitor)?;
    }
    Ok(state)
}

#[test]
fn implicit_contact_damping_lifts_the_damped_bound_and_agrees_at_small_steps() {
    // Flat on four corners ω = √(k/m) ≈ 316 rad/s, ζ = c/(2mω) ≈ 3.2: the explicit damper
    // bounds semi-implicit Euler at 2(√(1+ζ²) − ζ)/ω ≈ 1 ms (less on an edge), the
    // undamped spring at 2/ω ≈ 6 ms.
    let coarse = 2e-3;
    // Explicit at 2 ms the damper pumps energy in: the box leaves the floor higher than it
    // was dropped from (the force never pulls, so it flies instead of diverging).
    let e = drop_on_damped_floor(false, coarse, 1.0).expect("explicit at 2 ms");
    assert!(e.q[1] > 0.3, "explicit damping at 2 ms: y = {}", e.q[1]);
    let s = drop_on_damped_floor(true, coarse, 1.0).expect("implicit damping at 2 ms");
    // At rest on the floor: the box centre at half its height less the static sink.
    let sink = 2.0 * 9.81 / 1.0e5;
    assert!((s.q[1] - (0.1 - sink)).abs() < 1e-4, "y = {}", s.q[1]);
    assert!(s.v.iter().all(|v| v.abs() < 1e-3), "v = {:?}", s.v);
    // At a step far inside both bounds the two treatments are the same motion to first
    // order in h.
    let fine = 5e-5;
    let a = drop_on_damped_floor(false, fine, 0.3).unwrap();
    let b = drop_on_damped_floor(true, fine, 0.3).unwrap();
    for (x, y) in a.q.iter().zip(&b.q) {
        assert!((x - y).abs() < 1e-4, "{:?} vs {:?}", a.q, b.q);
    }
}

#[test]
fn pd_follows_a_moving_target_through_its_velocity_term() {
    // τ = k_p(θ_d − θ) + k_v(θ̇_d − θ̇): at θ = θ_d the torque is k_v(θ̇_d − θ̇).
    let pd = PdTargets {
        target: vec![0.3],
        target_velocity: vec![2.0],
        kp: vec![100.0],
        kv: vec![10.0],
        torque_limits: Vec::new(),
        feedforward: Vec::new(),
    };
    let (tau, d) = pd.torque(0, 0.3, 0.5);
    assert!((tau - 15.0).abs() < 1e-12);
    assert_eq!(d, 10.0);
}

#[test]
fn a_state_of_the_wrong_size_is_an_error_and_is_left_as_it_was() {
    let model = free_box();
    let none = NO_FORCES;
    let settings = EULER_1MS;
    let mut ws = StepWorkspace::new(&model);
    let mut monitor = StepMonitor::new(1, 0);
    let mut state = State::new(model.neutral(), vec![0.0; model.nv - 1], 1);
    let before = state.clone();
    let e = step(&model, settings, &none, &mut state, &mut ws, &mut monitor).unwrap_err();
    assert_eq!(
        e,
        StepError::Size(ModelError::SizeMismatch {
            what: "v",
            expected: 6,
            found: 5
        })
    );
    assert_eq!(e.to_string(), "v has 5 entries, the model needs 6");
    assert_eq!(state, before);
    let mut state = State::new(vec![0.0; 3], vec![0.0; 6], 1);
    let e = step_refined(
        &model,
        settings,
        4,
        &none,
        &mut state,
        &mut ws,
        &mut monitor,
    );
    assert_eq!(
        e.unwrap_err().to_string(),
        "q has 3 entries, the model needs 7"
    );
    let state = State::new(model.neutral(), vec![0.0; 6], 1);
    let mut qdd = vec![0.0; 5];
    let e = acceleration(&model, &none, &state, &mut ws, &mut qdd).unwrap_err();
    assert_eq!(e.to_string(), "qdd has 5 entries, the model needs 6");
}
