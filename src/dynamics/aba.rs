//! The articulated-body algorithm (Featherstone 2008, §7.3, `FDab`): forward dynamics
//! `q̈ = FD(q, q̇, τ, f_ext)` in O(n).
//!
//! Pass 1 ([`kinematics`]): `Xup, S, v, c`. Pass 2 (leaves → root):
//! `U = I^A S`, `D = Sᵀ U`, `u = τ − Sᵀ p^A`, and for a body with a parent
//! `I^a = I^A − U D⁻¹ Uᵀ`, `p^a = p^A + I^a c + U D⁻¹ u`, accumulated into the parent as
//! `Xupᵀ I^a Xup` and `Xupᵀ p^a`. Pass 3 (root → leaves): `a' = Xup a_λ + c`,
//! `q̈ = D⁻¹(u − Uᵀ a')`, `a = a' + S q̈`. A free root has `S = 1₆`, so its acceleration is
//! `a = (I^A)⁻¹(τ − p^A)` (Featherstone's floating-base variant, `FDfb`).

use super::axis_rotation::{CoordAxis, JointAxes};
use super::data::Data;
use super::joint::JointType;
use super::kinematics::{base_acceleration, kinematics};
use super::model::Model;
use super::spatial::{ArticulatedInertia, ForceVec, MotionVec};
use glam::{DMat3, DVec3};

/// Forward dynamics: returns `q̈` (size nv, in `data.qdd`) for configuration `q` (nq), velocity
/// `v` (nv), joint forces `tau` (nv; N·m, or the free root's `[n; f]` in body coordinates) and
/// external forces `f_ext` on each body (body coordinates).
pub fn aba<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    f_ext: &[ForceVec],
) -> &'d [f64] {
    kinematics(model, data, q, v);
    aba_passes(model, data, tau, f_ext, None, &[]);
    &data.qdd
}

/// Passes 2 and 3 of the ABA on kinematics already in `data`. `armature` (size nv, N·m·s²)
/// is added to each joint's `D`, so that the algorithm solves `(H + diag(armature)) q̈ = τ − C`;
/// the integrator uses it to take joint damping implicitly (armature = `dt·k_v`).
///
/// `implicit` lists bodies `b` with an inertia `I_c` (body coordinates) through which a force
/// `−I_c (a_b − ā_b)` acts, `ā_b` the body's acceleration at `q̈ = 0` (gravity and velocity
/// products): the linearisation of a force taken implicitly, `J q̈ = a_b − ā_b` being the
/// body's acceleration due to `q̈`. It enters as `I^A_b += I_c`, `p^A_b −= I_c ā_b`
/// ([`ContactParams::implicit_damping`](super::forces::contact::ContactParams::implicit_damping)).
#[inline(always)]
pub fn aba_passes(
    model: &Model,
    data: &mut Data,
    tau: &[f64],
    f_ext: &[ForceVec],
    armature: Option<&[f64]>,
    implicit: &[(usize, ArticulatedInertia)],
) {
    let n = model.nbodies();
    debug_assert_eq!(f_ext.len(), n);
    // Every per-body buffer as a slice of length n (the compiler then knows each body index
    // is in bounds).
    let Data {
        xup,
        xup_rotation,
        s,
        v,
        c,
        a,
        ia,
        pa,
        u,
        dinv,
        uu,
        qdd,
        ..
    } = data;
    let (xups, rots, ss, vs, cs) = (&xup[..n], &xup_rotation[..n], &s[..n], &v[..n], &c[..n]);
    let (accs, ias, pas) = (&mut a[..n], &mut ia[..n], &mut pa[..n]);
    let (us, dinvs, uus, qdds) = (&mut u[..n], &mut dinv[..n], &mut uu[..n], &mut qdd[..]);
    let f_ext = &f_ext[..n];
    ias.copy_from_slice(&model.inertia_blocks);
    for i in 0..n {
        let inertia = &model.bodies[i].inertia;
        let vi = vs[i];
        pas[i] = vi.cross_force(inertia.apply(vi)) - f_ext[i];
    }
    if !implicit.is_empty() {
        // ā: the accelerations at q̈ = 0, parents first (pass 3 overwrites `a`).
        let a0 = base_acceleration(model);
        for i in 0..n {
            let a_parent = model.bodies[i].parent.map_or(a0, |p| accs[p]);
            accs[i] = xups[i].apply_motion(a_parent) + cs[i];
        }
        for (b, ic) in implicit {
            ias[*b] += *ic;
            pas[*b] -= ic.apply(accs[*b]);
        }
    }
    for i in (0..n).rev() {
        let body = &model.bodies[i];
        let iv = model.v_idx[i];
        // Parents come before their children: the parent's entries lie below `i`, and the
        // body's own articulated inertia is updated in place to `I^a` (no copies).
        let (ia_head, ia_tail) = ias.split_at_mut(i);
        let ia = &mut ia_tail[0];
        let pa = pas[i];
        let arm = |k: usize| armature.map_or(0.0, |a| a[iv + k]);
        let has_parent = body.parent.is_some();
        // `p^a − I^a c`: the bias force the body passes on (before the inertia's product).
        let pa_a = match (&body.joint, model.joint_axes[i]) {
            (JointType::Pin { .. }, axes) => {
                // Revolute columns are pure rotations: S = [a; 0]; about a coordinate axis
                // `a = ±e_k`, `U` is ± column k of `[M; Hᵀ]` and `D = M_kk` (the same bits as
                // the products, whose other terms are zeros).
                let (u, d, uu) = match axes {
                    JointAxes::One(ax) => coordinate_column(ia, ax, tau[iv], pa),
                    _ => {
                        let a = ss[i][0].ang;
                        let u = ia.apply_angular(a);
                        (u, a.dot(u.ang), tau[iv] - a.dot(pa.ang))
                    }
                };
                let d = d + arm(0);
                let dinv = 1.0 / d;
                us[i][0] = u;
                dinvs[i].x_axis.x = dinv;
                uus[i].x = uu;
                if !has_parent {
                    continue;
                }
                ia.sub_outer(u, dinv);
                pa + u * (dinv * uu)
            }
            (JointType::Universal { .. }, JointAxes::Two(_, a2)) => {
                // The second column is the coordinate axis `a2` itself (taken as in a pin),
                // the first `R₂ᵀ a₁` (from the kinematics); `D` is 2×2.
                let b = ss[i][0].ang;
                let u0 = ia.apply_angular(b);
                let (u1, d11, uu1) = coordinate_column(ia, a2, tau[iv + 1], pa);
                let d00 = b.dot(u0.ang) + arm(0);
                let d11 = d11 + arm(1);
                let (d01, d10) = (b.dot(u1.ang), a2.sign * u0.ang[a2.k]);
                let uu0 = tau[iv] - b.dot(pa.ang);
                let inv_det = 1.0 / (d00 * d11 - d01 * d10);
                let dinv = DMat3::from_cols(
                    DVec3::new(d11 * inv_det, -d10 * inv_det, 0.0),
                    DVec3::new(-d01 * inv_det, d00 * inv_det, 0.0),
                    DVec3::Z,
                );
                let u = [u0, u1];
                us[i][0] = u0;
                us[i][1] = u1;
                dinvs[i] = dinv;
                uus[i] = DVec3::new(uu0, uu1, 0.0);
                if !has_parent {
                    continue;
                }
                let w = [
                    u0 * dinv.x_axis.x + u1 * dinv.x_axis.y,
                    u0 * dinv.y_axis.x + u1 * dinv.y_axis.y,
                ];
                ia.sub_products(&w, &u);
                pa + u0 * (dinv.x_axis.x * uu0 + dinv.y_axis.x * uu1)
                    + u1 * (dinv.x_axis.y * uu0 + dinv.y_axis.y * uu1)
            }
            (JointType::Universal { .. } | JointType::Ball { .. }, _) => {
                let nv = body.joint.nv();
                let mut u = [ForceVec::ZERO; 3];
                let mut d = DMat3::IDENTITY;
                let mut uu = DVec3::ZERO;
                for k in 0..nv {
                    let a = ss[i][k].ang;
                    u[k] = ia.apply_angular(a);
                    uu[k] = tau[iv + k] - a.dot(pa.ang);
                }
                for r in 0..nv {
                    for k in 0..nv {
                        let mut e = ss[i][r].ang.dot(u[k].ang);
                        if r == k {
                            e += arm(k);
                        }
                        d.col_mut(k)[r] = e;
                    }
                }
                let dinv = d.inverse();
                us[i] = u;
                dinvs[i] = dinv;
                uus[i] = uu;
                if !has_parent {
                    continue;
                }
                ia.sub_u_dinv_ut(&u[..nv], &dinv);
                let w = dinv * uu;
                let mut pa_a = pa;
                for k in 0..nv {
                    pa_a += u[k] * w[k];
                }
                pa_a
            }
            // No DOF: the whole articulated inertia and bias force reach the parent.
            (JointType::Fixed, _) => pa,
            (JointType::Free, _) => continue,
        };
        if let Some(p) = body.parent {
            let pa_a = pa_a + ia.apply(cs[i]);
            let x = &xups[i];
            ia_head[p] += ia.transform_to_parent_with(x, &rots[i]);
            pas[p] += x.inv_apply_force(pa_a);
        }
    }
    let a0 = base_acceleration(model);
    for i in 0..n {
        let body = &model.bodies[i];
        let iv = model.v_idx[i];
        let a_parent = match body.parent {
            Some(p) => accs[p],
            None => a0,
        };
        let a_prime = xups[i].apply_motion(a_parent) + cs[i];
        match body.joint {
            JointType::Pin { .. } => {
                let qdd = dinvs[i].x_axis.x * (uus[i].x - us[i][0].dot_motion(a_prime));
                qdds[iv] = qdd;
                let mut a = a_prime;
                a.ang += ss[i][0].ang * qdd;
                accs[i] = a;
            }
            JointType::Universal { .. } => {
                accs[i] = multi_dof_acceleration::<2>(
                    (&us[i], &dinvs[i], uus[i], &ss[i]),
                    a_prime,
                    &mut qdds[iv..iv + 2],
                )
            }
            JointType::Ball { .. } => {
                accs[i] = multi_dof_acceleration::<3>(
                    (&us[i], &dinvs[i], uus[i], &ss[i]),
                    a_prime,
                    &mut qdds[iv..iv + 3],
                )
            }
            JointType::Fixed => accs[i] = a_prime,
            JointType::Free => {
                let f = ForceVec::new(
                    DVec3::new(tau[iv], tau[iv + 1], tau[iv + 2]),
                    DVec3::new(tau[iv + 3], tau[iv + 4], tau[iv + 5]),
                ) - pas[i];
                let a = ias[i].solve(f);
                let qdd = a - a_prime;
                qdds[iv..iv + 3].copy_from_slice(&qdd.ang.to_array());
                qdds[iv + 3..iv + 6].copy_from_slice(&qdd.lin.to_array());
                accs[i] = a;
            }
        }
    }
}

/// The column of a joint DOF about the coordinate axis `ax` (`S = [±e_k; 0]`): `U = I^A S`
/// (± column k of `[M; Hᵀ]`), `Sᵀ U = M_kk` and `τ − Sᵀ p^A`.
#[inline(always)]
fn coordinate_column(
    ia: &ArticulatedInertia,
    ax: CoordAxis,
    tau: f64,
    pa: ForceVec,
) -> (ForceVec, f64, f64) {
    (
        ForceVec::new(ia.m.col(ax.k) * ax.sign, ia.h.row(ax.k) * ax.sign),
        ia.m.col(ax.k)[ax.k],
        tau - ax.sign * pa.ang[ax.k],
    )
}

/// Pass 3 for a joint of `N` rotational DOFs: `q̈ = D⁻¹(u − Uᵀ a')`, `a = a' + S q̈`.
#[inline(always)]
fn multi_dof_acceleration<const N: usize>(
    (u, dinv, uu, s): (&[ForceVec; 3], &DMat3, DVec3, &[MotionVec; 3]),
    a_prime: MotionVec,
    qdd: &mut [f64],
) -> MotionVec {
    let mut r = DVec3::ZERO;
    for k in 0..N {
        r[k] = uu[k] - u[k].dot_motion(a_prime);
    }
    let qdd_n = *dinv * r;
    let mut a = a_prime;
    for k in 0..N {
        qdd[k] = qdd_n[k];
        a.ang += s[k].ang * qdd_n[k];
    }
    a
}
