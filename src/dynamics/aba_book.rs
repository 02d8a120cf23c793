//! The articulated-body algorithm as the book writes it (Featherstone, *Rigid Body Dynamics
//! Algorithms*, 2008, Table 7.1, `FDab`): three loops over plain 6×6 spatial matrices with the
//! book's names `Xup, S, vJ, cJ, v, c, IA, pA, U, D, u, a`, and its own `jcalc`. Nothing here
//! uses the engine's spatial types or its kinematics, so that [`aba`](super::aba()) and the lane
//! ABA ([`aba_passes_lanes`](super::aba_lanes::aba_passes_lanes)), with their coordinate-axis
//! shortcuts and 3×3 blocks, are held against it on random trees (the tests below).
//!
//! Conventions of the engine it follows: spatial vectors `[angular; linear]`, external forces in
//! body coordinates (`pA = v ×* I v − f_ext`), the free root's `τ = [n; f]` and `q̈ = [ω̇; v̇]` in
//! body coordinates (a joint with `S = 1₆`), and `armature` added to the diagonal of `D`.

use super::joint::JointType;
use super::model::Model;
use super::spatial::{ForceVec, Inertia, SpatialTransform};
use glam::{DMat3, DQuat, DVec3};

/// A spatial vector `[angular; linear]`.
type V6 = [f64; 6];
/// A spatial matrix, rows of [`V6`].
type M6 = [[f64; 6]; 6];

fn zeros() -> M6 {
    [[0.0; 6]; 6]
}

fn mat_vec(a: &M6, x: &V6) -> V6 {
    std::array::from_fn(|r| (0..6).map(|k| a[r][k] * x[k]).sum())
}

fn mat_mul(a: &M6, b: &M6) -> M6 {
    std::array::from_fn(|r| std::array::from_fn(|c| (0..6).map(|k| a[r][k] * b[k][c]).sum()))
}

fn transpose(a: &M6) -> M6 {
    std::array::from_fn(|r| std::array::from_fn(|c| a[c][r]))
}

fn dot(a: &V6, b: &V6) -> f64 {
    (0..6).map(|k| a[k] * b[k]).sum()
}

fn add(a: &V6, b: &V6) -> V6 {
    std::array::from_fn(|k| a[k] + b[k])
}

fn sub(a: &V6, b: &V6) -> V6 {
    std::array::from_fn(|k| a[k] - b[k])
}

/// The 3×3 block `m` (by rows) placed at block row `br`, column `bc` of `a`.
fn put_block(a: &mut M6, br: usize, bc: usize, m: DMat3) {
    for r in 0..3 {
        for c in 0..3 {
            a[3 * br + r][3 * bc + c] = m.col(c)[r];
        }
    }
}

fn skew(r: DVec3) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(0.0, r.z, -r.y),
        DVec3::new(-r.z, 0.0, r.x),
        DVec3::new(r.y, -r.x, 0.0),
    )
}

/// The Plücker transform `rot(E) xlt(r) = [E 0; −E r× E]` (book eq. 2.24).
fn plux(e: DMat3, r: DVec3) -> M6 {
    let mut x = zeros();
    put_block(&mut x, 0, 0, e);
    put_block(&mut x, 1, 0, -(e * skew(r)));
    put_block(&mut x, 1, 1, e);
    x
}

fn x_of(t: &SpatialTransform) -> M6 {
    plux(t.rot, t.trans)
}

/// `crm(v)`, the motion cross product `v ×` (book eq. 2.31).
fn crm(v: &V6) -> M6 {
    let (w, vl) = (DVec3::new(v[0], v[1], v[2]), DVec3::new(v[3], v[4], v[5]));
    let mut m = zeros();
    put_block(&mut m, 0, 0, skew(w));
    put_block(&mut m, 1, 0, skew(vl));
    put_block(&mut m, 1, 1, skew(w));
    m
}

/// `crf(v) = −crm(v)ᵀ`, the force cross product `v ×*`.
fn crf(v: &V6) -> M6 {
    let t = transpose(&crm(v));
    std::array::from_fn(|r| std::array::from_fn(|c| -t[r][c]))
}

/// `mcI(m, c, I_c) = [I_c + m c× c×ᵀ, m c×; m c×ᵀ, m 1]` (book eq. 2.63).
fn mci(i: &Inertia) -> M6 {
    let cx = skew(i.com);
    let mut m = zeros();
    put_block(&mut m, 0, 0, i.inertia_com + cx * cx.transpose() * i.mass);
    put_block(&mut m, 0, 1, cx * i.mass);
    put_block(&mut m, 1, 0, cx.transpose() * i.mass);
    put_block(&mut m, 1, 1, DMat3::IDENTITY * i.mass);
    m
}

fn angular(w: DVec3) -> V6 {
    [w.x, w.y, w.z, 0.0, 0.0, 0.0]
}

/// `jcalc`: the joint transform `XJ`, the motion subspace `S` (its columns) and the velocity
/// product `cJ = Ṡ q̇` of joint `joint` at `q`, `qd`.
fn jcalc(joint: &JointType, q: &[f64], qd: &[f64]) -> (M6, Vec<V6>, V6) {
    match joint {
        JointType::Pin { axis } => {
            let r = DMat3::from_axis_angle(*axis, q[0]);
            (
                plux(r.transpose(), DVec3::ZERO),
                vec![angular(*axis)],
                [0.0; 6],
            )
        }
        JointType::Universal { axis1, axis2 } => {
            // R = R₁(q₀) R₂(q₁); in child coordinates the first axis is b = R₂ᵀ a₁, whose
            // rate is db/dq₁ q̇₁ = (b × a₂) q̇₁, so cJ = (b × a₂) q̇₀ q̇₁.
            let (r1, r2) = (
                DMat3::from_axis_angle(*axis1, q[0]),
                DMat3::from_axis_angle(*axis2, q[1]),
            );
            let b = r2.transpose() * *axis1;
            let s = vec![angular(b), angular(*axis2)];
            let cj = angular(b.cross(*axis2) * (qd[0] * qd[1]));
            (plux((r1 * r2).transpose(), DVec3::ZERO), s, cj)
        }
        JointType::Ball { axes } => {
            let r = DMat3::from_quat(DQuat::from_xyzw(q[0], q[1], q[2], q[3]));
            let s = vec![
                angular(axes.x_axis),
                angular(axes.y_axis),
                angular(axes.z_axis),
            ];
            (plux(r.transpose(), DVec3::ZERO), s, [0.0; 6])
        }
        JointType::Free => {
            let r = DMat3::from_quat(DQuat::from_xyzw(q[3], q[4], q[5], q[6]));
            let s = (0..6)
                .map(|k| std::array::from_fn(|r| if r == k { 1.0 } else { 0.0 }))
                .collect();
            (
                plux(r.transpose(), DVec3::new(q[0], q[1], q[2])),
                s,
                [0.0; 6],
            )
        }
        JointType::Fixed => (plux(DMat3::IDENTITY, DVec3::ZERO), Vec::new(), [0.0; 6]),
    }
}

/// `A⁻¹ b` for a small square `A` (n ≤ 6) by Gauss–Jordan elimination with partial pivoting.
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for col in 0..n {
        let piv = (col..n)
            .max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))
            .expect("a column");
        a.swap(col, piv);
        b.swap(col, piv);
        for r in 0..n {
            if r != col {
                let f = a[r][col] / a[col][col];
                for c in col..n {
                    a[r][c] -= f * a[col][c];
                }
                b[r] -= f * b[col];
            }
        }
    }
    (0..n).map(|k| b[k] / a[k][k]).collect()
}

/// `FDab`: the joint accelerations `q̈` (size nv) of `model` at configuration `q` (nq), velocity
/// `qd` (nv), joint forces `tau` (nv), external forces `f_ext` (per body, body coordinates) and
/// `armature` (nv, added to each `D`).
pub(crate) fn fd_ab(
    model: &Model,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    f_ext: &[ForceVec],
    armature: &[f64],
) -> Vec<f64> {
    let nb = model.nbodies();
    let a_grav = [
        0.0,
        0.0,
        0.0,
        model.gravity.x,
        model.gravity.y,
        model.gravity.z,
    ];
    let (mut xup, mut s, mut v, mut c) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut ia, mut pa) = (Vec::new(), Vec::new());
    // Loop 1, root → leaves: velocities, velocity products, rigid inertias and bias forces.
    for i in 0..nb {
        let body = &model.bodies[i];
        let (iq, iv) = (model.q_idx[i], model.v_idx[i]);
        let (nq, nv) = (body.joint.nq(), body.joint.nv());
        let (xj, si, cj) = jcalc(&body.joint, &q[iq..iq + nq], &qd[iv..iv + nv]);
        let vj = (0..nv).fold([0.0; 6], |acc, k| add(&acc, &si[k].map(|x| x * qd[iv + k])));
        let x = mat_mul(&xj, &x_of(&body.x_tree));
        let v_parent = body.parent.map_or([0.0; 6], |p: usize| v[p]);
        let vi = add(&mat_vec(&x, &v_parent), &vj);
        c.push(add(&cj, &mat_vec(&crm(&vi), &vj)));
        let inertia = mci(&body.inertia);
        let fe = f_ext[i];
        let fe = [fe.ang.x, fe.ang.y, fe.ang.z, fe.lin.x, fe.lin.y, fe.lin.z];
        pa.push(sub(&mat_vec(&crf(&vi), &mat_vec(&inertia, &vi)), &fe));
        ia.push(inertia);
        v.push(vi);
        xup.push(x);
        s.push(si);
    }
    // Loop 2, leaves → root: U, D, u, and the articulated inertia and bias force passed on.
    let (mut uu, mut dd, mut u) = (
        vec![Vec::new(); nb],
        vec![Vec::new(); nb],
        vec![Vec::new(); nb],
    );
    for i in (0..nb).rev() {
        let iv = model.v_idx[i];
        let n = s[i].len();
        uu[i] = s[i]
            .iter()
            .map(|sk| mat_vec(&ia[i], sk))
            .collect::<Vec<V6>>();
        dd[i] = (0..n)
            .map(|r| {
                (0..n)
                    .map(|k| dot(&s[i][r], &uu[i][k]) + if r == k { armature[iv + k] } else { 0.0 })
                    .collect::<Vec<f64>>()
            })
            .collect::<Vec<_>>();
        u[i] = (0..n)
            .map(|k| tau[iv + k] - dot(&s[i][k], &pa[i]))
            .collect::<Vec<f64>>();
        if let Some(p) = model.bodies[i].parent {
            // Ia = IA − U D⁻¹ Uᵀ, pa = pA + Ia c + U D⁻¹ u.
            let mut ia_a = ia[i];
            for col in 0..6 {
                let e = (0..n).map(|k| uu[i][k][col]).collect();
                let dinv_ut = solve(dd[i].clone(), e);
                for r in 0..6 {
                    ia_a[r][col] -= (0..n).map(|k| uu[i][k][r] * dinv_ut[k]).sum::<f64>();
                }
            }
            let dinv_u = solve(dd[i].clone(), u[i].clone());
            let u_dinv_u = (0..n).fold([0.0; 6], |acc, k| {
                add(&acc, &uu[i][k].map(|x| x * dinv_u[k]))
            });
            let pa_a = add(&add(&pa[i], &mat_vec(&ia_a, &c[i])), &u_dinv_u);
            let xt = transpose(&xup[i]);
            let passed = mat_mul(&xt, &mat_mul(&ia_a, &xup[i]));
            for r in 0..6 {
                for col in 0..6 {
                    ia[p][r][col] += passed[r][col];
                }
            }
            pa[p] = add(&pa[p], &mat_vec(&xt, &pa_a));
        }
    }
    // Loop 3, root → leaves: accelerations.
    let mut a: Vec<V6> = Vec::with_capacity(nb);
    let mut qdd = vec![0.0; model.nv];
    for i in 0..nb {
        let iv = model.v_idx[i];
        let n = s[i].len();
        let a_parent = model.bodies[i].parent.map_or(a_grav.map(|x| -x), |p| a[p]);
        let mut ai = add(&mat_vec(&xup[i], &a_parent), &c[i]);
        let rhs = (0..n).map(|k| u[i][k] - dot(&uu[i][k], &ai)).collect();
        let qdd_i = solve(dd[i].clone(), rhs);
        for k in 0..n {
            qdd[iv + k] = qdd_i[k];
            ai = add(&ai, &s[i][k].map(|x| x * qdd_i[k]));
        }
        a.push(ai);
    }
    qdd
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::aba_lanes::{LaneData, LaneInput, aba_passes_lanes};
    use crate::dynamics::data::Data;
    use crate::dynamics::kinematics::kinematics;
    use crate::dynamics::model::Body;
    use crate::dynamics::{aba, aba_passes};
    use rand::{Rng, RngExt, SeedableRng};
    use rand_pcg::Pcg64;

    fn unit(rng: &mut impl Rng) -> DVec3 {
        loop {
            let v = DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            if (0.1..=1.0).contains(&v.length()) {
                return v.normalize();
            }
        }
    }

    fn coordinate_axis(rng: &mut impl Rng) -> DVec3 {
        let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
        [DVec3::X, DVec3::Y, DVec3::Z][rng.random_range(0..3)] * sign
    }

    /// A random tree of `n` bodies: every joint kind, half of the pins and universals about
    /// coordinate axes with an unrotated `Xtree` (the engine's shortcuts), a free root or not.
    fn random_model(rng: &mut impl Rng, n: usize, free_root: bool) -> Model {
        let bodies = (0..n)
            .map(|i| {
                let coordinate = rng.random_bool(0.5);
                let axis = |rng: &mut _| {
                    if coordinate {
                        coordinate_axis(rng)
                    } else {
                        unit(rng)
                    }
                };
                let joint = match (i, free_root, rng.random_range(0..5)) {
                    (0, true, _) => JointType::Free,
                    (_, _, 0 | 1) => JointType::Pin { axis: axis(rng) },
                    (_, _, 2) => JointType::Universal {
                        axis1: axis(rng),
                        axis2: axis(rng),
                    },
                    (_, _, 3) => JointType::Ball {
                        axes: DMat3::from_axis_angle(unit(rng), rng.random_range(-3.0..3.0)),
                    },
                    _ => JointType::Fixed,
                };
                let rot = if coordinate {
                    DMat3::IDENTITY
                } else {
                    DMat3::from_axis_angle(unit(rng), rng.random_range(-3.0..3.0))
                };
                let half = DVec3::new(
                    rng.random_range(0.05..0.4),
                    rng.random_range(0.05..0.4),
                    rng.random_range(0.05..0.4),
                );
                let box_inertia = Inertia::solid_box(rng.random_range(0.5..8.0), DVec3::ZERO, half);
                let r = DMat3::from_axis_angle(unit(rng), rng.random_range(-3.0..3.0));
                Body {
                    name: format!("b{i}"),
                    joint_name: format!("j{i}"),
                    parent: (i > 0).then(|| rng.random_range(0..i)),
                    joint,
                    x_tree: SpatialTransform {
                        rot,
                        trans: unit(rng) * rng.random_range(0.0..0.4),
                    },
                    inertia: Inertia::new(
                        box_inertia.mass,
                        unit(rng) * 0.1,
                        r * box_inertia.inertia_com * r.transpose(),
                    ),
                }
            })
            .collect();
        Model::new(bodies, DVec3::new(0.0, -9.81, 0.0)).expect("a valid random model")
    }

    /// A random state of `model`: `(q, q̇, τ, f_ext, armature)`.
    type State = (Vec<f64>, Vec<f64>, Vec<f64>, Vec<ForceVec>, Vec<f64>);

    fn random_state(rng: &mut impl Rng, model: &Model) -> State {
        let mut q = vec![0.0; model.nq];
        for (i, b) in model.bodies.iter().enumerate() {
            let qi = &mut q[model.q_idx[i]..model.q_idx[i] + b.joint.nq()];
            let quat = DQuat::from_axis_angle(unit(rng), rng.random_range(-3.0..3.0));
            match b.joint {
                JointType::Ball { .. } => qi.copy_from_slice(&quat.to_array()),
                JointType::Free => {
                    qi[..3].copy_from_slice(&(unit(rng) * 0.7).to_array());
                    qi[3..].copy_from_slice(&quat.to_array());
                }
                _ => qi.fill_with(|| rng.random_range(-3.0..3.0)),
            }
        }
        let mut vector = |len: usize, r: f64| -> Vec<f64> {
            (0..len).map(|_| rng.random_range(-r..r)).collect()
        };
        let (v, tau) = (vector(model.nv, 3.0), vector(model.nv, 20.0));
        // Armature on the joints' DOFs, none on a free root's (the engine's ABA adds none there).
        let mut armature: Vec<f64> = vector(model.nv, 0.05).iter().map(|x| x.abs()).collect();
        if matches!(model.bodies[0].joint, JointType::Free) {
            armature[..6].fill(0.0);
        }
        let f_ext = (0..model.nbodies())
            .map(|_| ForceVec::new(unit(rng) * 5.0, unit(rng) * 30.0))
            .collect();
        (q, v, tau, f_ext, armature)
    }

    /// `max |x − y| / (1 + max |y|)`.
    fn relative_error(x: &[f64], y: &[f64]) -> f64 {
        let scale = 1.0 + y.iter().fold(0.0f64, |m, e| m.max(e.abs()));
        x.iter()
            .zip(y)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
            / scale
    }

    #[test]
    fn the_book_algorithm_solves_the_equation_of_motion_of_one_body() {
        // One free body: `I a = f − v ×* I v` with gravity in `a`, which FDab must return.
        let inertia = Inertia::new(
            2.0,
            DVec3::new(0.1, -0.2, 0.05),
            DMat3::from_diagonal(DVec3::new(0.3, 0.2, 0.1)),
        );
        let body = Body {
            name: "b".into(),
            joint_name: "j".into(),
            parent: None,
            joint: JointType::Free,
            x_tree: SpatialTransform::IDENTITY,
            inertia,
        };
        let model = Model::new(vec![body], DVec3::new(0.0, -9.81, 0.0)).unwrap();
        let mut q = vec![0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
        let quat = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 2.0) / 3.0, 0.7);
        q[3..].copy_from_slice(&quat.to_array());
        let v = [0.4, -0.3, 0.2, 1.0, 0.5, -0.7];
        let tau = [0.5, 0.1, -0.2, 3.0, 1.0, 2.0];
        let qdd = fd_ab(&model, &q, &v, &tau, &[ForceVec::ZERO], &[0.0; 6]);
        // I (q̈ + Eg·(0; −g)) = τ − v ×* I v, with E the body's rotation of world vectors.
        let e = DMat3::from_quat(quat).transpose();
        let g = e * DVec3::new(0.0, 9.81, 0.0);
        let a: V6 = [
            qdd[0],
            qdd[1],
            qdd[2],
            qdd[3] + g.x,
            qdd[4] + g.y,
            qdd[5] + g.z,
        ];
        let i6 = mci(&inertia);
        let lhs = add(&mat_vec(&i6, &a), &mat_vec(&crf(&v), &mat_vec(&i6, &v)));
        assert!(relative_error(&lhs, &tau) < 1e-13, "{lhs:?} vs {tau:?}");
    }

    #[test]
    fn aba_and_the_lane_aba_agree_with_the_book_algorithm_on_random_trees() {
        let mut rng = Pcg64::seed_from_u64(37);
        let (mut worst_aba, mut worst_lanes) = (0.0f64, 0.0f64);
        for trial in 0..80 {
            let n = rng.random_range(1..14);
            let model = random_model(&mut rng, n, trial % 2 == 0);
            let states: Vec<State> = (0..4).map(|_| random_state(&mut rng, &model)).collect();
            let book: Vec<Vec<f64>> = states
                .iter()
                .map(|(q, v, tau, f, arm)| fd_ab(&model, q, v, tau, f, arm))
                .collect();
            // The scalar ABA, without and with armature.
            let mut data = Data::new(&model);
            for ((q, v, tau, f, arm), book) in states.iter().zip(&book) {
                let zero = vec![0.0; model.nv];
                let plain = aba(&model, &mut data, q, v, tau, f).unwrap().to_vec();
                let e = relative_error(&plain, &fd_ab(&model, q, v, tau, f, &zero));
                assert!(e < 1e-10, "trial {trial}: aba vs FDab {e:e}");
                kinematics(&model, &mut data, q, v);
                aba_passes(&model, &mut data, tau, f, Some(arm), &[]);
                let e_arm = relative_error(&data.qdd, book);
                assert!(
                    e_arm < 1e-10,
                    "trial {trial}: aba with armature vs FDab {e_arm:e}"
                );
                worst_aba = worst_aba.max(e).max(e_arm);
            }
            // The lane ABA, four states in the lanes of one call.
            let mut datas: Vec<Data> = states
                .iter()
                .map(|(q, v, ..)| {
                    let mut d = Data::new(&model);
                    kinematics(&model, &mut d, q, v);
                    d
                })
                .collect();
            let mut lanes = LaneData::new(&model);
            let mut bodies: Vec<LaneInput> = datas
                .iter_mut()
                .zip(&states)
                .map(|(data, (_, _, tau, f_ext, arm))| LaneInput {
                    data,
                    tau,
                    f_ext,
                    armature: Some(arm),
                })
                .collect();
            aba_passes_lanes(&model, &mut lanes, &mut bodies);
            for (d, book) in datas.iter().zip(&book) {
                let e = relative_error(&d.qdd, book);
                assert!(e < 1e-10, "trial {trial}: lane aba vs FDab {e:e}");
                worst_lanes = worst_lanes.max(e);
            }
        }
        println!("worst relative error vs FDab: aba {worst_aba:e}, lanes {worst_lanes:e}");
    }
}
