//! The articulated-body algorithm (Featherstone 2008, §7.3, `FDab`): forward dynamics
//! `q̈ = FD(q, q̇, τ, f_ext)` in O(n).
//!
//! Pass 1 ([`kinematics`], then `pass1_bias_forces`): `Xup, S, v, c`, `I^A = I`,
//! `p^A = v ×* I v − f_ext`. Pass 2 (`pass2_articulated_inertias`, leaves → root):
//! `U = I^A S`, `D = Sᵀ U`, `u = τ − Sᵀ p^A`, and for a body with a parent
//! `I^a = I^A − U D⁻¹ Uᵀ`, `p^a = p^A + I^a c + U D⁻¹ u`, accumulated into the parent as
//! `Xupᵀ I^a Xup` and `Xupᵀ p^a`. Pass 3 (`pass3_accelerations`, root → leaves):
//! `a' = Xup a_λ + c`, `q̈ = D⁻¹(u − Uᵀ a')`, `a = a' + S q̈`. A free root has `S = 1₆`, so
//! its acceleration is `a = (I^A)⁻¹(τ − p^A)` (Featherstone's floating-base variant, `FDfb`).

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
    pass1_bias_forces(model, data, f_ext);
    if !implicit.is_empty() {
        implicit_inertias(model, data, implicit);
    }
    pass2_articulated_inertias(model, data, tau, armature);
    pass3_accelerations(model, data, tau);
}

/// The joint forces and armature of one body's joint, whose first DOF is `iv`.
#[derive(Clone, Copy)]
struct JointInputs<'a> {
    tau: &'a [f64],
    armature: Option<&'a [f64]>,
    iv: usize,
}

impl JointInputs<'_> {
    /// `τ` of the joint's DOF `k`.
    #[inline(always)]
    fn tau(&self, k: usize) -> f64 {
        self.tau[self.iv + k]
    }

    /// The armature of the joint's DOF `k` (0 without armature).
    #[inline(always)]
    fn arm(&self, k: usize) -> f64 {
        self.armature.map_or(0.0, |a| a[self.iv + k])
    }
}

/// Where pass 2 leaves one body's `U`, `D⁻¹` and `u` for pass 3 (only the joint's DOFs are
/// written).
struct JointSlots<'a> {
    u: &'a mut [ForceVec; 3],
    dinv: &'a mut DMat3,
    uu: &'a mut DVec3,
}

/// The end of pass 1 (root → leaves; `Xup, S, v, c` are already in `data` from
/// [`kinematics`]): each body's articulated inertia and bias force start as its own,
/// `I^A = I` and `p^A = v ×* I v − f_ext` (Featherstone 2008, Table 7.1).
#[inline(always)]
fn pass1_bias_forces(model: &Model, data: &mut Data, f_ext: &[ForceVec]) {
    let n = model.nbodies();
    debug_assert_eq!(f_ext.len(), n);
    // Every per-body buffer as a slice of length n (the compiler then knows each body index
    // is in bounds).
    let (vs, ias, pas) = (&data.v[..n], &mut data.ia[..n], &mut data.pa[..n]);
    let f_ext = &f_ext[..n];
    ias.copy_from_slice(&model.inertia_blocks);
    for i in 0..n {
        let inertia = &model.bodies[i].inertia;
        let vi = vs[i];
        pas[i] = vi.cross_force(inertia.apply(vi)) - f_ext[i];
    }
}

/// The inertias `I_c` taken implicitly (see [`aba_passes`]): `I^A_b += I_c` and
/// `p^A_b −= I_c ā_b`, with `ā = Xup ā_λ + c` the accelerations at `q̈ = 0`.
#[inline(always)]
fn implicit_inertias(model: &Model, data: &mut Data, implicit: &[(usize, ArticulatedInertia)]) {
    let n = model.nbodies();
    let (xups, cs, accs) = (&data.xup[..n], &data.c[..n], &mut data.a[..n]);
    let (ias, pas) = (&mut data.ia[..n], &mut data.pa[..n]);
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

/// Pass 2 (leaves → root): each joint's `U = I^A S`, `D = Sᵀ U` (+ armature) and
/// `u = τ − Sᵀ p^A`; a body with a parent passes on `I^a = I^A − U D⁻¹ Uᵀ` and
/// `p^a = p^A + I^a c + U D⁻¹ u`, accumulated into the parent as `Xupᵀ I^a Xup` and
/// `Xupᵀ p^a` (Featherstone 2008, Table 7.1).
#[inline(always)]
fn pass2_articulated_inertias(
    model: &Model,
    data: &mut Data,
    tau: &[f64],
    armature: Option<&[f64]>,
) {
    let n = model.nbodies();
    let (xups, rots) = (&data.xup[..n], &data.xup_rotation[..n]);
    let (ss, cs) = (&data.s[..n], &data.c[..n]);
    let (ias, pas) = (&mut data.ia[..n], &mut data.pa[..n]);
    let (us, dinvs, uus) = (&mut data.u[..n], &mut data.dinv[..n], &mut data.uu[..n]);
    for i in (0..n).rev() {
        let body = &model.bodies[i];
        let joint = JointInputs {
            tau,
            armature,
            iv: model.v_idx[i],
        };
        // Parents come before their children: the parent's entries lie below `i`, and the
        // body's own articulated inertia is updated in place to `I^a` (no copies).
        let (ia_head, ia_tail) = ias.split_at_mut(i);
        let ia = &mut ia_tail[0];
        let pa = pas[i];
        let out = JointSlots {
            u: &mut us[i],
            dinv: &mut dinvs[i],
            uu: &mut uus[i],
        };
        let has_parent = body.parent.is_some();
        // `p^a − I^a c`: the bias force the body passes on (before the inertia's product; a
        // root passes nothing on).
        let pa_a = match (&body.joint, model.joint_axes[i]) {
            (JointType::Pin { .. }, axes) => {
                pin_pass2(ia, pa, (&ss[i], axes), joint, out, has_parent)
            }
            (JointType::Universal { .. }, JointAxes::Two(_, a2)) => {
                universal_pass2(ia, pa, (&ss[i], a2), joint, out, has_parent)
            }
            (JointType::Universal { .. } | JointType::Ball { .. }, _) => {
                rotational_pass2(ia, pa, (&ss[i], body.joint.nv()), joint, out, has_parent)
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
}

/// Pass 2 for a revolute joint (`D` is 1×1): with a parent, `I^a = I^A − U D⁻¹ Uᵀ` in place
/// and returns `p^A + U D⁻¹ u` (a root's `p^A` as it is).
#[inline(always)]
fn pin_pass2(
    ia: &mut ArticulatedInertia,
    pa: ForceVec,
    (s, axes): (&[MotionVec; 3], JointAxes),
    joint: JointInputs,
    out: JointSlots,
    has_parent: bool,
) -> ForceVec {
    // Revolute columns are pure rotations: S = [a; 0]; about a coordinate axis `a = ±e_k`,
    // `U` is ± column k of `[M; Hᵀ]` and `D = M_kk` (the same bits as the products, whose
    // other terms are zeros).
    let (u, d, uu) = match axes {
        JointAxes::One(ax) => coordinate_column(ia, ax, joint.tau(0), pa),
        _ => {
            let a = s[0].ang;
            let u = ia.apply_angular(a);
            (u, a.dot(u.ang), joint.tau(0) - a.dot(pa.ang))
        }
    };
    let d = d + joint.arm(0);
    let dinv = 1.0 / d;
    out.u[0] = u;
    out.dinv.x_axis.x = dinv;
    out.uu.x = uu;
    if !has_parent {
        return pa;
    }
    ia.sub_outer(u, dinv);
    pa + u * (dinv * uu)
}

/// Pass 2 for a universal joint whose second axis `a2` is a coordinate axis (`D` is 2×2,
/// inverted in closed form): as [`pin_pass2`].
#[inline(always)]
fn universal_pass2(
    ia: &mut ArticulatedInertia,
    pa: ForceVec,
    (s, a2): (&[MotionVec; 3], CoordAxis),
    joint: JointInputs,
    out: JointSlots,
    has_parent: bool,
) -> ForceVec {
    // The second column is the coordinate axis `a2` itself (taken as in a pin), the first
    // `R₂ᵀ a₁` (from the kinematics).
    let b = s[0].ang;
    let u0 = ia.apply_angular(b);
    let (u1, d11, uu1) = coordinate_column(ia, a2, joint.tau(1), pa);
    let d00 = b.dot(u0.ang) + joint.arm(0);
    let d11 = d11 + joint.arm(1);
    let (d01, d10) = (b.dot(u1.ang), a2.sign * u0.ang[a2.k]);
    let uu0 = joint.tau(0) - b.dot(pa.ang);
    let inv_det = 1.0 / (d00 * d11 - d01 * d10);
    let dinv = DMat3::from_cols(
        DVec3::new(d11 * inv_det, -d10 * inv_det, 0.0),
        DVec3::new(-d01 * inv_det, d00 * inv_det, 0.0),
        DVec3::Z,
    );
    let u = [u0, u1];
    out.u[0] = u0;
    out.u[1] = u1;
    *out.dinv = dinv;
    *out.uu = DVec3::new(uu0, uu1, 0.0);
    if !has_parent {
        return pa;
    }
    let w = [
        u0 * dinv.x_axis.x + u1 * dinv.x_axis.y,
        u0 * dinv.y_axis.x + u1 * dinv.y_axis.y,
    ];
    ia.sub_products(&w, &u);
    pa + u0 * (dinv.x_axis.x * uu0 + dinv.y_axis.x * uu1)
        + u1 * (dinv.x_axis.y * uu0 + dinv.y_axis.y * uu1)
}

/// Pass 2 for a joint of `nv` rotational DOFs about general axes (ball, universal): `D`
/// (`nv`×`nv`) inverted as a 3×3 with ones beyond `nv`; as [`pin_pass2`].
#[inline(always)]
fn rotational_pass2(
    ia: &mut ArticulatedInertia,
    pa: ForceVec,
    (s, nv): (&[MotionVec; 3], usize),
    joint: JointInputs,
    out: JointSlots,
    has_parent: bool,
) -> ForceVec {
    let mut u = [ForceVec::ZERO; 3];
    let mut d = DMat3::IDENTITY;
    let mut uu = DVec3::ZERO;
    for k in 0..nv {
        let a = s[k].ang;
        u[k] = ia.apply_angular(a);
        uu[k] = joint.tau(k) - a.dot(pa.ang);
    }
    for r in 0..nv {
        for k in 0..nv {
            let mut e = s[r].ang.dot(u[k].ang);
            if r == k {
                e += joint.arm(k);
            }
            d.col_mut(k)[r] = e;
        }
    }
    let dinv = d.inverse();
    *out.u = u;
    *out.dinv = dinv;
    *out.uu = uu;
    if !has_parent {
        return pa;
    }
    ia.sub_u_dinv_ut(&u[..nv], &dinv);
    let w = dinv * uu;
    let mut pa_a = pa;
    for k in 0..nv {
        pa_a += u[k] * w[k];
    }
    pa_a
}

/// Pass 3 (root → leaves): `a' = Xup a_λ + c`, `q̈ = D⁻¹(u − Uᵀ a')`, `a = a' + S q̈`
/// (Featherstone 2008, Table 7.1); a free root's `a = (I^A)⁻¹(τ − p^A)` (`FDfb`).
#[inline(always)]
fn pass3_accelerations(model: &Model, data: &mut Data, tau: &[f64]) {
    let n = model.nbodies();
    let (xups, ss, cs) = (&data.xup[..n], &data.s[..n], &data.c[..n]);
    let (accs, ias, pas) = (&mut data.a[..n], &data.ia[..n], &data.pa[..n]);
    let (us, dinvs, uus) = (&data.u[..n], &data.dinv[..n], &data.uu[..n]);
    let qdds = &mut data.qdd[..];
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
