//! The articulated-body algorithm held against the recursive Newton–Euler algorithm and against
//! CRBA + Cholesky on random trees mixing every joint type (pin, universal, ball, fixed, free
//! root), and on the human bodies built from the engine's models (fall21 and humanoid24).

use glam::{DMat3, DQuat, DVec3};
use marionette::dynamics::forward_dynamics_crba;
use marionette::dynamics::{
    Body, Data, ForceVec, Inertia, JointType, Model, SpatialTransform, aba, rnea,
};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;

fn unit(rng: &mut Pcg64) -> DVec3 {
    loop {
        let v = DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let l = v.length();
        if l > 0.1 && l <= 1.0 {
            return v / l;
        }
    }
}

fn random_rotation(rng: &mut Pcg64) -> DMat3 {
    DMat3::from_axis_angle(unit(rng), rng.random_range(-3.0..3.0))
}

fn random_joint(rng: &mut Pcg64) -> JointType {
    match rng.random_range(0..4) {
        0 => JointType::Pin { axis: unit(rng) },
        3 => JointType::Fixed,
        1 => JointType::Universal {
            axis1: unit(rng),
            axis2: unit(rng),
        },
        _ => JointType::Ball {
            axes: random_rotation(rng),
        },
    }
}

fn random_model(rng: &mut Pcg64, n: usize, free_root: bool) -> Model {
    let mut bodies = Vec::new();
    for i in 0..n {
        let joint = if i == 0 && free_root {
            JointType::Free
        } else {
            random_joint(rng)
        };
        let parent = if i == 0 {
            None
        } else {
            Some(rng.random_range(0..i))
        };
        let x_tree = if i == 0 && free_root {
            SpatialTransform::IDENTITY
        } else {
            SpatialTransform {
                rot: random_rotation(rng),
                trans: unit(rng) * rng.random_range(0.05..0.5),
            }
        };
        let d = DVec3::new(
            rng.random_range(0.5..1.5),
            rng.random_range(0.5..1.5),
            rng.random_range(0.5..1.5),
        );
        // Principal moments satisfying the triangle inequality: from a box.
        let mass = rng.random_range(0.3..10.0);
        let r = random_rotation(rng);
        let ibox = Inertia::solid_box(mass, DVec3::ZERO, d * 0.3).inertia_com;
        let inertia = Inertia::new(mass, unit(rng) * 0.2, r * ibox * r.transpose());
        bodies.push(Body {
            name: format!("b{i}"),
            joint_name: format!("j{i}"),
            parent,
            joint,
            x_tree,
            inertia,
        });
    }
    Model::new(bodies, DVec3::new(0.0, -9.81, 0.0)).expect("valid random model")
}

fn random_state(rng: &mut Pcg64, m: &Model) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<ForceVec>) {
    let mut q = vec![0.0; m.nq()];
    for (i, b) in m.bodies().iter().enumerate() {
        let qi = &mut q[m.q_offset(i)..m.q_offset(i) + b.joint.nq()];
        match b.joint {
            JointType::Ball { .. } => {
                let qq = DQuat::from_axis_angle(unit(rng), rng.random_range(-3.0..3.0));
                qi.copy_from_slice(&[qq.x, qq.y, qq.z, qq.w]);
            }
            JointType::Free => {
                let qq = DQuat::from_axis_angle(unit(rng), rng.random_range(-3.0..3.0));
                let p = unit(rng);
                qi.copy_from_slice(&[p.x, p.y, p.z, qq.x, qq.y, qq.z, qq.w]);
            }
            _ => qi.iter_mut().for_each(|x| *x = rng.random_range(-3.0..3.0)),
        }
    }
    let v = (0..m.nv()).map(|_| rng.random_range(-2.0..2.0)).collect();
    let tau = (0..m.nv()).map(|_| rng.random_range(-5.0..5.0)).collect();
    let f_ext = (0..m.nbodies())
        .map(|_| ForceVec::new(unit(rng) * 2.0, unit(rng) * 3.0))
        .collect();
    (q, v, tau, f_ext)
}

/// ABA, RNEA(ABA) and CRBA + Cholesky at random states of `m`; the worst relative
/// disagreements `(RNEA(ABA) vs τ, ABA vs CRBA)`.
fn worst_disagreement(m: &Model, rng: &mut Pcg64, states: usize) -> (f64, f64) {
    let mut data = Data::new(m);
    let (mut worst_rnea, mut worst_crba) = (0.0f64, 0.0f64);
    for _ in 0..states {
        let (q, v, tau, f_ext) = random_state(rng, m);
        let qdd = aba(m, &mut data, &q, &v, &tau, &f_ext).unwrap().to_vec();
        assert!(qdd.iter().all(|x| x.is_finite()));
        let tau2 = rnea(m, &mut data, &q, &v, &qdd, &f_ext).unwrap().to_vec();
        let scale = 1.0 + tau.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        worst_rnea = worst_rnea.max(max_abs_diff(&tau, &tau2) / scale);
        let qdd2 = forward_dynamics_crba(m, &mut data, &q, &v, &tau, &f_ext)
            .unwrap()
            .to_vec();
        let qscale = 1.0 + qdd.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        worst_crba = worst_crba.max(max_abs_diff(&qdd, &qdd2) / qscale);
    }
    (worst_rnea, worst_crba)
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn aba_agrees_with_rnea_and_crba_on_random_trees() {
    let mut rng = Pcg64::seed_from_u64(20260411);
    let (mut worst_rnea, mut worst_crba) = (0.0f64, 0.0f64);
    for trial in 0..60 {
        let n = rng.random_range(2..16);
        let m = random_model(&mut rng, n, trial % 2 == 0);
        let mut data = Data::new(&m);
        for _ in 0..3 {
            let (q, v, tau, f_ext) = random_state(&mut rng, &m);
            let qdd = aba(&m, &mut data, &q, &v, &tau, &f_ext).unwrap().to_vec();
            assert!(qdd.iter().all(|x| x.is_finite()));
            let tau2 = rnea(&m, &mut data, &q, &v, &qdd, &f_ext).unwrap().to_vec();
            let scale = 1.0 + tau.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            let e1 = max_abs_diff(&tau, &tau2) / scale;
            assert!(e1 < 1e-9, "trial {trial}: RNEA(ABA) − τ = {e1:e}");
            worst_rnea = worst_rnea.max(e1);
            let qdd2 = forward_dynamics_crba(&m, &mut data, &q, &v, &tau, &f_ext)
                .unwrap()
                .to_vec();
            let qscale = 1.0 + qdd.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            let e2 = max_abs_diff(&qdd, &qdd2) / qscale;
            assert!(e2 < 1e-9, "trial {trial}: ABA − CRBA = {e2:e}");
            worst_crba = worst_crba.max(e2);
        }
    }
    println!(
        "worst relative disagreement: RNEA(ABA) vs τ {worst_rnea:e}, ABA vs CRBA {worst_crba:e}"
    );
}

#[test]
fn crba_matrix_is_symmetric_positive_definite_and_matches_rnea_columns() {
    // H e_k = RNEA(q, 0, e_k) − RNEA(q, 0, 0) with gravity off.
    let mut rng = Pcg64::seed_from_u64(7);
    let m = random_model(&mut rng, 9, true).with_gravity(DVec3::ZERO);
    let mut data = Data::new(&m);
    let (q, _, _, _) = random_state(&mut rng, &m);
    let nv = m.nv();
    let h = marionette::dynamics::crba(&m, &mut data, &q)
        .unwrap()
        .to_vec();
    let zero_f = vec![ForceVec::ZERO; m.nbodies()];
    let zeros = vec![0.0; nv];
    for k in 0..nv {
        let mut e = vec![0.0; nv];
        e[k] = 1.0;
        let col = rnea(&m, &mut data, &q, &zeros, &e, &zero_f)
            .unwrap()
            .to_vec();
        for r in 0..nv {
            assert!((col[r] - h[r * nv + k]).abs() < 1e-10);
            assert!((h[r * nv + k] - h[k * nv + r]).abs() < 1e-12);
        }
    }
}

#[test]
fn aba_agrees_with_rnea_and_crba_on_the_human_bodies() {
    use marionette::humanoid::{fall21_body, humanoid24_body};
    let mut rng = Pcg64::seed_from_u64(24);
    for (name, body) in [
        ("fall21", fall21_body(1.70, 65.0, 9.81).unwrap()),
        ("humanoid24", humanoid24_body(1.70, 65.0, 9.81).unwrap()),
    ] {
        let (e1, e2) = worst_disagreement(&body.model, &mut rng, 50);
        println!("{name}: RNEA(ABA) vs τ {e1:e}, ABA vs CRBA {e2:e} (relative, 50 random states)");
        assert!(e1 < 1e-9 && e2 < 1e-9, "{name}: {e1:e} {e2:e}");
    }
}

#[test]
fn arguments_of_the_wrong_size_are_errors_that_name_both_sizes() {
    use marionette::dynamics::ModelError;
    use marionette::dynamics::mechanical_energy;
    let mut rng = Pcg64::seed_from_u64(11);
    let m = random_model(&mut rng, 5, true);
    let (q, v, tau, f_ext) = random_state(&mut rng, &m);
    let (nq, nv, nb) = (m.nq(), m.nv(), m.nbodies());
    let mut data = Data::new(&m);
    let short = |x: &[f64]| x[..x.len() - 1].to_vec();
    let mismatch = |e: ModelError, what: &'static str, expected: usize, found: usize| {
        let msg = e.to_string();
        assert_eq!(
            e,
            ModelError::SizeMismatch {
                what,
                expected,
                found
            }
        );
        assert_eq!(
            msg,
            format!("{what} has {found} entries, the model needs {expected}")
        );
    };
    let e = aba(&m, &mut data, &short(&q), &v, &tau, &f_ext).unwrap_err();
    mismatch(e, "q", nq, nq - 1);
    let e = aba(&m, &mut data, &q, &short(&v), &tau, &f_ext).unwrap_err();
    mismatch(e, "v", nv, nv - 1);
    let e = aba(&m, &mut data, &q, &v, &short(&tau), &f_ext).unwrap_err();
    mismatch(e, "tau", nv, nv - 1);
    let e = aba(&m, &mut data, &q, &v, &tau, &f_ext[1..]).unwrap_err();
    mismatch(e, "f_ext", nb, nb - 1);
    let e = rnea(&m, &mut data, &q, &v, &short(&tau), &f_ext).unwrap_err();
    mismatch(e, "qdd", nv, nv - 1);
    let e = marionette::dynamics::crba(&m, &mut data, &short(&q)).unwrap_err();
    mismatch(e, "q", nq, nq - 1);
    let e = forward_dynamics_crba(&m, &mut data, &q, &v, &short(&tau), &f_ext).unwrap_err();
    mismatch(e, "tau", nv, nv - 1);
    let e = mechanical_energy(&m, &mut data, &q, &short(&v)).unwrap_err();
    mismatch(e, "v", nv, nv - 1);
    // A workspace of another model.
    let other = random_model(&mut rng, 3, true);
    let mut small = Data::new(&other);
    let e = aba(&m, &mut small, &q, &v, &tau, &f_ext).unwrap_err();
    mismatch(e, "data (bodies)", nb, other.nbodies());
    // The right sizes still work.
    assert!(aba(&m, &mut data, &q, &v, &tau, &f_ext).is_ok());
}
