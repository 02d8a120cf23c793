//! Integrators against closed forms: a pendulum's period (elliptic integral), energy of a passive
//! chain under RK4, free fall of a spinning body, and implicit damping staying stable.

use glam::{DMat3, DQuat, DVec3};
use marionette::dynamics::integrate;
use marionette::dynamics::mechanical_energy;
use marionette::dynamics::{
    Body, Data, Dynamics, ForceVec, Inertia, Integrator, IntegratorWorkspace, JointType, Model,
    SpatialTransform, aba, aba_passes, kinematics,
};
use std::convert::Infallible;

/// Passive dynamics with optional viscous joint damping `τ = −d v`.
struct Passive<'m> {
    model: &'m Model,
    data: Data,
    damping: Vec<f64>,
    tau: Vec<f64>,
    f_ext: Vec<ForceVec>,
}

impl<'m> Passive<'m> {
    fn new(model: &'m Model, damping: f64) -> Self {
        let mut damping = vec![damping; model.nv()];
        if matches!(model.bodies()[0].joint, JointType::Free) {
            damping[..6].fill(0.0);
        }
        Self {
            model,
            data: Data::new(model),
            damping,
            tau: vec![0.0; model.nv()],
            f_ext: vec![ForceVec::ZERO; model.nbodies()],
        }
    }
}

impl Dynamics for Passive<'_> {
    type Error = Infallible;
    fn acceleration(
        &mut self,
        _t: f64,
        q: &[f64],
        v: &[f64],
        implicit_dt: Option<f64>,
        qdd: &mut [f64],
    ) -> Result<(), Infallible> {
        for ((t, d), x) in self.tau.iter_mut().zip(&self.damping).zip(v) {
            *t = -d * x;
        }
        match implicit_dt {
            None => {
                aba(self.model, &mut self.data, q, v, &self.tau, &self.f_ext).unwrap();
            }
            Some(h) => {
                let arm: Vec<f64> = self.damping.iter().map(|d| d * h).collect();
                kinematics(self.model, &mut self.data, q, v);
                aba_passes(
                    self.model,
                    &mut self.data,
                    &self.tau,
                    &self.f_ext,
                    Some(&arm),
                    &[],
                );
            }
        }
        qdd.copy_from_slice(&self.data.qdd);
        Ok(())
    }
}

fn body(name: &str, parent: Option<usize>, joint: JointType, offset: DVec3, i: Inertia) -> Body {
    Body {
        name: name.into(),
        joint_name: name.into(),
        parent,
        joint,
        x_tree: SpatialTransform::translation(offset),
        inertia: i,
    }
}

/// Complete elliptic integral of the first kind by the arithmetic–geometric mean.
fn ellip_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    for _ in 0..30 {
        let an = 0.5 * (a + b);
        b = (a * b).sqrt();
        a = an;
    }
    std::f64::consts::PI / (2.0 * a)
}

#[test]
fn pendulum_period_matches_the_elliptic_integral() {
    // A rod-like body hanging from a pin: I_pivot = I_c + m d².
    let (m, d) = (2.0, 0.6);
    let inertia = Inertia::solid_box(m, DVec3::new(0.0, -d, 0.0), DVec3::new(0.05, 1.2, 0.05));
    let model = Model::new(
        vec![body(
            "rod",
            None,
            JointType::Pin { axis: DVec3::X },
            DVec3::ZERO,
            inertia,
        )],
        DVec3::new(0.0, -9.81, 0.0),
    )
    .unwrap();
    let i_pivot = inertia.inertia_com.x_axis.x + m * d * d;
    let theta0: f64 = 1.2;
    let t_exact = 4.0 * (i_pivot / (m * 9.81 * d)).sqrt() * ellip_k((theta0 / 2.0).sin());
    let mut dynm = Passive::new(&model, 0.0);
    let mut ws = IntegratorWorkspace::new(&model);
    let (mut q, mut v) = (vec![theta0], vec![0.0]);
    let h = 1e-3;
    let mut t = 0.0;
    let mut crossings = Vec::new();
    let mut prev = v[0];
    while crossings.len() < 3 {
        integrate(
            Integrator::Rk4,
            &model,
            &mut ws,
            &mut dynm,
            t,
            h,
            (&mut q, &mut v),
        )
        .unwrap();
        t += h;
        // θ̇ crosses zero downward at each θ = +θ0 turning point (period apart).
        if prev > 0.0 && v[0] <= 0.0 {
            crossings.push(t - h * v[0] / (v[0] - prev));
        }
        prev = v[0];
    }
    let period = (crossings[2] - crossings[0]) / 2.0;
    let rel = (period - t_exact).abs() / t_exact;
    println!("pendulum period {period} s, elliptic {t_exact} s, relative error {rel:e}");
    assert!(
        rel < 1e-6,
        "period {period} vs exact {t_exact} (rel {rel:e})"
    );
}

fn chain() -> Model {
    let g = DVec3::new(0.0, -9.81, 0.0);
    let seg =
        |m: f64| Inertia::solid_box(m, DVec3::new(0.0, -0.15, 0.0), DVec3::new(0.06, 0.3, 0.04));
    let bodies = vec![
        body(
            "a",
            None,
            JointType::Pin { axis: DVec3::Z },
            DVec3::ZERO,
            seg(1.5),
        ),
        body(
            "b",
            Some(0),
            JointType::Universal {
                axis1: DVec3::Z,
                axis2: DVec3::X,
            },
            DVec3::new(0.0, -0.3, 0.0),
            seg(1.0),
        ),
        body(
            "c",
            Some(1),
            JointType::Ball {
                axes: DMat3::from_cols(DVec3::X, DVec3::Z, DVec3::Y),
            },
            DVec3::new(0.0, -0.3, 0.0),
            seg(0.8),
        ),
        body(
            "d",
            Some(2),
            JointType::Pin { axis: DVec3::X },
            DVec3::new(0.0, -0.3, 0.0),
            seg(0.5),
        ),
    ];
    Model::new(bodies, g).unwrap()
}

#[test]
fn passive_chain_conserves_energy_under_rk4() {
    let model = chain();
    let mut data = Data::new(&model);
    let mut q = model.neutral();
    q[0] = 1.4; // pin a
    q[1] = -0.7; // universal b
    q[2] = 0.5;
    let axis = DVec3::new(0.3, 1.0, -0.2).normalize();
    let b = DQuat::from_axis_angle(axis, 1.0);
    q[3..7].copy_from_slice(&[b.x, b.y, b.z, b.w]);
    q[7] = 0.9;
    let mut v = vec![0.0; model.nv()];
    v[4] = 2.0; // spin the ball
    let (t0, v0) = mechanical_energy(&model, &mut data, &q, &v).unwrap();
    // Reference the potential to the hanging rest pose so that E0 is the energy in the motion.
    let rest = model.neutral();
    let (_, v_rest) = mechanical_energy(&model, &mut data, &rest, &vec![0.0; model.nv()]).unwrap();
    let e0 = t0 + v0 - v_rest;
    let mut dynm = Passive::new(&model, 0.0);
    let mut ws = IntegratorWorkspace::new(&model);
    let h = 5e-4;
    let mut max_rel: f64 = 0.0;
    for n in 0..20_000 {
        integrate(
            Integrator::Rk4,
            &model,
            &mut ws,
            &mut dynm,
            n as f64 * h,
            h,
            (&mut q, &mut v),
        )
        .unwrap();
        if n % 100 == 99 {
            let (t, p) = mechanical_energy(&model, &mut data, &q, &v).unwrap();
            max_rel = max_rel.max(((t + p - v_rest) - e0).abs() / e0);
        }
    }
    println!("passive chain, RK4 h = {h} s: max relative energy drift {max_rel:e} over 10 s");
    assert!(
        max_rel < 1e-6,
        "relative energy drift {max_rel:e} over 10 s"
    );
}

#[test]
fn free_fall_of_a_spinning_body_follows_the_parabola() {
    let inertia = Inertia::new(
        3.0,
        DVec3::new(0.1, 0.05, -0.02),
        DMat3::from_diagonal(DVec3::new(0.05, 0.02, 0.04)),
    );
    let model = Model::new(
        vec![body("box", None, JointType::Free, DVec3::ZERO, inertia)],
        DVec3::new(0.0, -9.81, 0.0),
    )
    .unwrap();
    let mut data = Data::new(&model);
    let mut q = model.neutral();
    q[1] = 2.0;
    // Body velocity [ω; v] in body coordinates.
    let mut v = vec![1.0, -2.0, 3.0, 0.5, 4.0, -1.0];
    kinematics(&model, &mut data, &q, &v);
    let com0 = data.pos[0] + data.rot[0] * inertia.com;
    let vcom0 = data.rot[0]
        * (DVec3::new(v[3], v[4], v[5]) + DVec3::new(v[0], v[1], v[2]).cross(inertia.com));
    let l0 = {
        let h = inertia.apply(data.v[0]);
        // angular momentum about the centre of mass, world frame
        data.rot[0] * (h.ang - inertia.com.cross(h.lin))
    };
    let mut dynm = Passive::new(&model, 0.0);
    let mut ws = IntegratorWorkspace::new(&model);
    let h = 1e-3;
    let n = 1500;
    for k in 0..n {
        integrate(
            Integrator::Rk4,
            &model,
            &mut ws,
            &mut dynm,
            k as f64 * h,
            h,
            (&mut q, &mut v),
        )
        .unwrap();
    }
    let t = n as f64 * h;
    kinematics(&model, &mut data, &q, &v);
    let com = data.pos[0] + data.rot[0] * inertia.com;
    let expect = com0 + vcom0 * t + 0.5 * model.gravity() * t * t;
    assert!((com - expect).length() < 1e-9, "com {com} vs {expect}");
    let hm = inertia.apply(data.v[0]);
    let l = data.rot[0] * (hm.ang - inertia.com.cross(hm.lin));
    assert!((l - l0).length() < 1e-8 * l0.length(), "L {l} vs {l0}");
    let qn = DQuat::from_xyzw(q[3], q[4], q[5], q[6]);
    assert!((qn.length() - 1.0).abs() < 1e-12);
}

#[test]
fn implicit_damping_is_stable_where_explicit_euler_blows_up() {
    // Damping d with h·d/I ≫ 2: explicit Euler diverges, the implicit form decays.
    let model = chain();
    let mut q = model.neutral();
    q[0] = 0.5;
    let run = |implicit: bool, mut q: Vec<f64>| {
        let mut dynm = Passive::new(&model, 400.0);
        let mut ws = IntegratorWorkspace::new(&model);
        let mut v = vec![0.0; model.nv()];
        v[0] = 1.0;
        for k in 0..2000 {
            let scheme = Integrator::SemiImplicitEuler {
                implicit_damping: implicit,
            };
            integrate(
                scheme,
                &model,
                &mut ws,
                &mut dynm,
                k as f64 * 2e-3,
                2e-3,
                (&mut q, &mut v),
            )
            .unwrap();
        }
        // NaN-propagating max |v|: a diverged run reports NaN or a huge value.
        v.iter().fold(
            0.0f64,
            |a, x| if x.is_nan() { f64::NAN } else { a.max(x.abs()) },
        )
    };
    let implicit = run(true, q.clone());
    let explicit = run(false, q);
    // Heavily overdamped: the chain creeps toward rest, never faster than it started.
    assert!(
        implicit.is_finite() && implicit < 0.1,
        "implicit: {implicit}"
    );
    assert!(
        explicit.is_nan() || explicit > 1e3,
        "explicit Euler should diverge: {explicit}"
    );
}

#[test]
fn rk4_keeps_fourth_order_on_the_rotation_manifold() {
    // A torque-free asymmetric top (free joint, no gravity) spinning about all three axes: the
    // orientation error must fall ~16× when the step halves (order 4 on SO(3), thanks to the
    // exact dexp⁻¹ chart rate).
    let inertia = Inertia::new(
        1.0,
        DVec3::new(0.05, -0.02, 0.03),
        DMat3::from_diagonal(DVec3::new(0.3, 0.2, 0.1)),
    );
    let model = Model::new(
        vec![body("top", None, JointType::Free, DVec3::ZERO, inertia)],
        DVec3::ZERO,
    )
    .unwrap();
    let run = |h: f64| {
        let mut q = model.neutral();
        let mut v = vec![3.0, -2.0, 4.0, 0.3, 0.1, -0.2];
        let mut dynm = Passive::new(&model, 0.0);
        let mut ws = IntegratorWorkspace::new(&model);
        let n = (1.0 / h).round() as usize;
        for k in 0..n {
            integrate(
                Integrator::Rk4,
                &model,
                &mut ws,
                &mut dynm,
                k as f64 * h,
                h,
                (&mut q, &mut v),
            )
            .unwrap();
        }
        (
            DQuat::from_xyzw(q[3], q[4], q[5], q[6]),
            DVec3::new(q[0], q[1], q[2]),
        )
    };
    let (q_ref, p_ref) = run(1.0 / 1600.0);
    let err = |h: f64| {
        let (qh, ph) = run(h);
        qh.angle_between(q_ref) + (ph - p_ref).length()
    };
    let (e1, e2, e3) = (err(1.0 / 50.0), err(1.0 / 100.0), err(1.0 / 200.0));
    // Order p gives a ratio of 2^p: 4 for order 2, 8 for order 3, 16 for order 4.
    for (a, b) in [(e1, e2), (e2, e3)] {
        let ratio = a / b;
        assert!(
            ratio > 12.0 && ratio < 24.0,
            "error ratio {ratio} ({a:e} → {b:e})"
        );
    }
}
