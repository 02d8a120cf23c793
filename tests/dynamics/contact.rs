//! Floor contact and the joint model on small bodies: a box settles with its weight carried by
//! the corner springs; on an inclined floor it sticks below the friction angle and slides at
//! `g(sin α − μ cos α)` above it; a joint limit holds a lever under load.

use glam::{DQuat, DVec3};
use marionette::dynamics::forces::contact::LinkBox;
use marionette::dynamics::forces::contact::{
    ContactGains, ContactModel, ContactParams, ContactSample, ContactState,
};
use marionette::dynamics::forces::limits::{JointLimitParams, joint_torque};
use marionette::dynamics::integrate;
use marionette::dynamics::{
    Body, Data, Dynamics, ForceVec, Inertia, Integrator, IntegratorWorkspace, JointType, Model,
    SpatialTransform, aba, kinematics,
};
use std::convert::Infallible;

struct BoxOnFloor {
    model: Model,
    data: Data,
    contact: ContactModel,
    state: ContactState,
    f_ext: Vec<ForceVec>,
    normal: Vec<f64>,
    tau: Vec<f64>,
}

impl Dynamics for BoxOnFloor {
    type Error = Infallible;
    fn acceleration(
        &mut self,
        _t: f64,
        q: &[f64],
        v: &[f64],
        _i: Option<f64>,
        qdd: &mut [f64],
    ) -> Result<(), Infallible> {
        kinematics(&self.model, &mut self.data, q, v);
        self.f_ext[0] = ForceVec::ZERO;
        self.contact
            .apply(&self.data, &self.state, &mut self.f_ext, &mut self.normal);
        aba(&self.model, &mut self.data, q, v, &self.tau, &self.f_ext).unwrap();
        qdd.copy_from_slice(&self.data.qdd);
        Ok(())
    }
}

const SIZE: DVec3 = DVec3::new(0.4, 0.2, 0.3);
/// The box's normal stiffness per kilogram (N/m/kg) for its whole face, and its damping.
const K_PER_KG: f64 = 4.8e5;
const C_PER_KG: f64 = 160.0;

fn box_world(params: ContactParams) -> BoxOnFloor {
    let m = 2.0;
    let inertia = Inertia::solid_box(m, DVec3::ZERO, SIZE);
    let model = Model::new(
        vec![Body {
            name: "box".into(),
            joint_name: "free".into(),
            parent: None,
            joint: JointType::Free,
            x_tree: SpatialTransform::IDENTITY,
            inertia,
        }],
        DVec3::new(0.0, -9.81, 0.0),
    )
    .unwrap();
    let lb = LinkBox {
        center: DVec3::ZERO,
        half: SIZE * 0.5,
    };
    BoxOnFloor {
        data: Data::new(&model),
        contact: ContactModel::new(
            &[lb],
            &[m],
            &[ContactGains::per_kg(m, K_PER_KG, C_PER_KG)],
            params,
        ),
        state: ContactState::new(1),
        f_ext: vec![ForceVec::ZERO],
        normal: vec![0.0],
        tau: vec![0.0; 6],
        model,
    }
}

/// Runs `seconds` with one anchor update per step; returns the box position after each second
/// fraction `samples`.
fn run(w: &mut BoxOnFloor, q: &mut [f64], v: &mut [f64], seconds: f64) {
    let h = 2e-4;
    let mut ws = IntegratorWorkspace::new(&w.model);
    let n = (seconds / h).round() as usize;
    for k in 0..n {
        kinematics(&w.model, &mut w.data, q, v);
        let mut f = [ForceVec::ZERO];
        let mut sample = ContactSample::new(1);
        w.contact
            .update_and_apply(&w.data, &mut w.state, &mut f, &mut sample);
        let scheme = Integrator::SemiImplicitEuler {
            implicit_damping: false,
        };
        integrate(
            scheme,
            &w.model.clone(),
            &mut ws,
            w,
            k as f64 * h,
            h,
            (q, v),
        )
        .unwrap();
    }
}

#[test]
fn a_box_settles_with_its_weight_on_the_springs() {
    let params = ContactParams::default();
    let mut w = box_world(params);
    let mut q = w.model.neutral();
    q[1] = 0.1 + 0.05; // dropped from 5 cm
    let mut v = vec![0.0; 6];
    run(&mut w, &mut q, &mut v, 2.0);
    kinematics(&w.model, &mut w.data, &q, &v);
    w.f_ext[0] = ForceVec::ZERO;
    let pen = w
        .contact
        .apply(&w.data, &w.state, &mut w.f_ext, &mut w.normal);
    let weight = 2.0 * 9.81;
    assert!(
        (w.normal[0] - weight).abs() < 1e-3 * weight,
        "springs carry {} N of {weight} N",
        w.normal[0]
    );
    // Four corners share the weight, each with a quarter of the face's stiffness: sink = g / k̂.
    let sink = 9.81 / K_PER_KG;
    assert!((pen - sink).abs() < 1e-3 * sink, "sink {pen} vs {sink}");
    assert!(v.iter().all(|x| x.abs() < 1e-6), "still moving: {v:?}");
}

fn on_incline(angle_deg: f64, mu: f64, seconds: f64) -> (f64, f64) {
    let a = angle_deg.to_radians();
    let n = DVec3::new(0.0, a.cos(), a.sin());
    let params = ContactParams {
        friction: mu,
        floor_normal: n,
        ..ContactParams::default()
    };
    let mut w = box_world(params);
    let mut q = w.model.neutral();
    let sink = 9.81 * a.cos() / K_PER_KG;
    let p0 = n * (SIZE.y * 0.5 - sink);
    let r = DQuat::from_rotation_x(a);
    q[..3].copy_from_slice(&p0.to_array());
    q[3..7].copy_from_slice(&[r.x, r.y, r.z, r.w]);
    let mut v = vec![0.0; 6];
    let down = DVec3::new(0.0, -a.sin(), a.cos());
    run(&mut w, &mut q, &mut v, seconds * 0.5);
    let half = (DVec3::new(q[0], q[1], q[2]) - p0).dot(down);
    run(&mut w, &mut q, &mut v, seconds * 0.5);
    let full = (DVec3::new(q[0], q[1], q[2]) - p0).dot(down);
    (half, full)
}

#[test]
fn a_box_sticks_below_the_friction_angle() {
    // μ = 0.5: friction angle 26.6°.
    let (half, full) = on_incline(20.0, 0.5, 1.0);
    assert!(full.abs() < 1e-3, "slid {full} m");
    assert!((full - half).abs() < 1e-6, "creeps: {half} → {full}");
}

#[test]
fn a_box_slides_above_the_friction_angle_at_the_coulomb_rate() {
    let (a, mu): (f64, f64) = (35.0, 0.5);
    let (_, full) = on_incline(a, mu, 1.0);
    let acc = 9.81 * (a.to_radians().sin() - mu * a.to_radians().cos());
    let expect = 0.5 * acc * 1.0;
    assert!(
        (full - expect).abs() < 0.03 * expect,
        "slid {full} m, Coulomb predicts {expect} m"
    );
}

struct Lever {
    model: Model,
    data: Data,
    params: JointLimitParams,
    range: (f64, f64),
}

impl Dynamics for Lever {
    type Error = Infallible;
    fn acceleration(
        &mut self,
        _t: f64,
        q: &[f64],
        v: &[f64],
        _i: Option<f64>,
        qdd: &mut [f64],
    ) -> Result<(), Infallible> {
        let (tau, _) = joint_torque(&self.params, self.range, q[0], v[0]);
        aba(&self.model, &mut self.data, q, v, &[tau], &[ForceVec::ZERO]).unwrap();
        qdd[0] = self.data.qdd[0];
        Ok(())
    }
}

#[test]
fn a_joint_limit_holds_a_lever_under_load() {
    // A 3 kg lever, centre of mass 0.4 m out along +Z, pin about X: a positive θ turns +Z toward
    // −Y, so gravity drives θ up; the range stops it at +0.2 rad.
    let (m, d) = (3.0, 0.4);
    let inertia = Inertia::solid_box(m, DVec3::new(0.0, 0.0, d), DVec3::new(0.05, 0.05, 0.8));
    let model = Model::new(
        vec![Body {
            name: "lever".into(),
            joint_name: "pin".into(),
            parent: None,
            joint: JointType::Pin { axis: DVec3::X },
            x_tree: SpatialTransform::IDENTITY,
            inertia,
        }],
        DVec3::new(0.0, -9.81, 0.0),
    )
    .unwrap();
    let params = JointLimitParams::default();
    let mut lever = Lever {
        data: Data::new(&model),
        model: model.clone(),
        params,
        range: (-1.0, 0.2),
    };
    let (mut q, mut v) = (vec![-0.5], vec![0.0]);
    let mut ws = IntegratorWorkspace::new(&model);
    let mut highest: f64 = -0.5;
    let h = 1e-3;
    for k in 0..5000 {
        integrate(
            Integrator::Rk4,
            &model,
            &mut ws,
            &mut lever,
            k as f64 * h,
            h,
            (&mut q, &mut v),
        )
        .unwrap();
        highest = highest.max(q[0]);
    }
    // Static balance past the limit: k_p (θ_lim − θ) = m g d cos θ.
    let theta = q[0];
    let load = m * 9.81 * d * theta.cos();
    let expect = 0.2 + load / params.limit_kp;
    assert!(
        (theta - expect).abs() < 1e-4,
        "rests at {theta}, balance predicts {expect}"
    );
    // The swing onto the stop overshoots no more than its energy allows against the limit
    // spring: ½ k_p δ² ≤ m g d (sin 0.2 + sin 0.5) (plus the static offset); free, it would
    // swing past π/2.
    let e = m * 9.81 * d * (0.2f64.sin() + 0.5f64.sin());
    let bound = 0.2 + (2.0 * e / params.limit_kp).sqrt() + load / params.limit_kp;
    assert!(
        highest < bound && highest < 1.0,
        "overshoot to {highest} (bound {bound})"
    );
}
