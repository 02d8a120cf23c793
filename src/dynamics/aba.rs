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
//!
//! Passes 2 and 3 are written once over the number type ([`Real`]): `f64` here, one body, and
//! [`F4`](super::lanes::F4) in [`super::aba_lanes`], [`LANES`](super::lanes::LANES) bodies at
//! once; each width's operations are its own, so each keeps its bits. They are held against
//! the book's `FDab`, written plainly over 6×6 matrices, in the tests (`aba_book.rs`).

use super::axis_rotation::{CoordAxis, JointAxes};
use super::data::Data;
use super::joint::JointType;
use super::kinematics::{base_acceleration, kinematics};
use super::model::{Model, ModelError};
use super::real::{
    ColumnsOps, ForceOps, InertiaOps, Mat3Ops, MotionOps, Real, TransformOps, Vec3Ops,
};
use super::spatial::{ArticulatedInertia, ForceVec};
use super::width::{Accelerations, JointForces};
use std::marker::PhantomData;

/// Forward dynamics: returns `q̈` (size nv, in `data.qdd`) for configuration `q` (nq), velocity
/// `v` (nv), joint forces `tau` (nv; N·m, or the free root's `[n; f]` in body coordinates) and
/// external forces `f_ext` on each body (body coordinates). A vector or `data` of another size
/// than the model's is a [`ModelError::SizeMismatch`].
pub fn aba<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    f_ext: &[ForceVec],
) -> Result<&'d [f64], ModelError> {
    model.check_data(data)?;
    model.check_state(q, v)?;
    model.check_forces(tau, f_ext)?;
    kinematics(model, data, q, v);
    aba_passes(model, data, tau, f_ext, None, &[]);
    Ok(&data.qdd)
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
    debug_assert_eq!(tau.len(), model.nv);
    debug_assert!(armature.is_none_or(|a| a.len() == model.nv));
    pass1_bias_forces(model, data, f_ext);
    if !implicit.is_empty() {
        implicit_inertias(model, data, implicit);
    }
    let n = model.nbodies();
    let mut bodies = Bodies::<f64> {
        xup: &data.xup[..n],
        rotation: &data.xup_rotation[..n],
        s: &data.s[..n],
        c: &data.c[..n],
        a: &mut data.a[..n],
        ia: &mut data.ia[..n],
        pa: &mut data.pa[..n],
        u: &mut data.u[..n],
        dinv: &mut data.dinv[..n],
        uu: &mut data.uu[..n],
    };
    let forces = (tau, armature);
    pass2_articulated_inertias(model, &mut bodies, &forces);
    pass3_accelerations(
        model,
        &mut bodies,
        &forces,
        base_acceleration(model),
        &mut data.qdd[..],
    );
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

/// The ABA's per-body quantities at width `S`, each a slice of length n (one entry per body):
/// the kinematics (`Xup`, its rotation's factors, `S`, `c`) and what passes 2 and 3 write.
pub(super) struct Bodies<'a, S: Real> {
    /// `Xup`.
    pub xup: &'a [S::Transform],
    /// `Xup`'s rotation in factored form.
    pub rotation: &'a [S::Rotation],
    /// The joints' motion-subspace columns.
    pub s: &'a [S::Columns],
    /// Velocity products `c`.
    pub c: &'a [S::Motion],
    /// Accelerations `a`.
    pub a: &'a mut [S::Motion],
    /// Articulated inertias `I^A` (rigid inertias in, pass 2 leaves `I^a`).
    pub ia: &'a mut [S::Inertia],
    /// Bias forces `p^A`.
    pub pa: &'a mut [S::Force],
    /// `U` per joint DOF.
    pub u: &'a mut [[S::Force; 3]],
    /// `D⁻¹`.
    pub dinv: &'a mut [S::M3],
    /// `u`.
    pub uu: &'a mut [S::V3],
}

/// The joint forces and armature of one body's joint, whose first DOF is `iv`.
struct JointInputs<'a, S, F> {
    forces: &'a F,
    iv: usize,
    width: PhantomData<S>,
}

impl<S, F: JointForces<S>> JointInputs<'_, S, F> {
    /// `τ` of the joint's DOF `k`.
    #[inline(always)]
    fn tau(&self, k: usize) -> S {
        self.forces.tau(self.iv + k)
    }

    /// The armature of the joint's DOF `k` (0 without armature).
    #[inline(always)]
    fn arm(&self, k: usize) -> S {
        self.forces.armature(self.iv + k)
    }
}

/// Where pass 2 leaves one body's `U`, `D⁻¹` and `u` for pass 3 (only the joint's DOFs are
/// written).
struct JointSlots<'a, S: Real> {
    u: &'a mut [S::Force; 3],
    dinv: &'a mut S::M3,
    uu: &'a mut S::V3,
}

/// Pass 2 (leaves → root): each joint's `U = I^A S`, `D = Sᵀ U` (+ armature) and
/// `u = τ − Sᵀ p^A`; a body with a parent passes on `I^a = I^A − U D⁻¹ Uᵀ` and
/// `p^a = p^A + I^a c + U D⁻¹ u`, accumulated into the parent as `Xupᵀ I^a Xup` and
/// `Xupᵀ p^a` (Featherstone 2008, Table 7.1).
#[inline(always)]
pub(super) fn pass2_articulated_inertias<S: Real>(
    model: &Model,
    bodies: &mut Bodies<S>,
    forces: &impl JointForces<S>,
) {
    let n = model.nbodies();
    let (xups, rots) = (&bodies.xup[..n], &bodies.rotation[..n]);
    let (ss, cs) = (&bodies.s[..n], &bodies.c[..n]);
    let (ias, pas) = (&mut bodies.ia[..n], &mut bodies.pa[..n]);
    let (us, dinvs, uus) = (
        &mut bodies.u[..n],
        &mut bodies.dinv[..n],
        &mut bodies.uu[..n],
    );
    for i in (0..n).rev() {
        let body = &model.bodies[i];
        let joint = JointInputs {
            forces,
            iv: model.v_idx[i],
            width: PhantomData,
        };
        // Parents come before their children: the parent's entries lie below `i`, and the
        // body's own articulated inertia is updated in place to `I^a` (no copies).
        let (ia_head, ia_tail) = ias.split_at_mut(i);
        let ia = &mut ia_tail[0];
        let pa = pas[i];
        let out = JointSlots::<S> {
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
fn pin_pass2<S: Real>(
    ia: &mut S::Inertia,
    pa: S::Force,
    (s, axes): (&S::Columns, JointAxes),
    joint: JointInputs<S, impl JointForces<S>>,
    out: JointSlots<S>,
    has_parent: bool,
) -> S::Force {
    // Revolute columns are pure rotations: S = [a; 0]; about a coordinate axis `a = ±e_k`,
    // `U` is ± column k of `[M; Hᵀ]` and `D = M_kk` (the same bits as the products, whose
    // other terms are zeros).
    let (u, d, uu) = match axes {
        JointAxes::One(ax) => coordinate_column::<S>(ia, ax, joint.tau(0), pa),
        _ => {
            let a = s.axis(0);
            let u = ia.apply_angular(a);
            (u, a.dot(u.ang()), joint.tau(0) - a.dot(pa.ang()))
        }
    };
    let d = d + joint.arm(0);
    let dinv = S::splat(1.0) / d;
    out.u[0] = u;
    out.dinv.col_mut(0).set(0, dinv);
    out.uu.set(0, uu);
    if !has_parent {
        return pa;
    }
    ia.sub_outer(u, dinv);
    pa + u * (dinv * uu)
}

/// Pass 2 for a universal joint whose second axis `a2` is a coordinate axis (`D` is 2×2,
/// inverted in closed form): as [`pin_pass2`].
#[inline(always)]
fn universal_pass2<S: Real>(
    ia: &mut S::Inertia,
    pa: S::Force,
    (s, a2): (&S::Columns, CoordAxis),
    joint: JointInputs<S, impl JointForces<S>>,
    out: JointSlots<S>,
    has_parent: bool,
) -> S::Force {
    // The second column is the coordinate axis `a2` itself (taken as in a pin), the first
    // `R₂ᵀ a₁` (from the kinematics).
    let b = s.axis(0);
    let u0 = ia.apply_angular(b);
    let (u1, d11, uu1) = coordinate_column::<S>(ia, a2, joint.tau(1), pa);
    let d00 = b.dot(u0.ang()) + joint.arm(0);
    let d11 = d11 + joint.arm(1);
    let (d01, d10) = (b.dot(u1.ang()), S::splat(a2.sign) * u0.ang().get(a2.k));
    let uu0 = joint.tau(0) - b.dot(pa.ang());
    let inv_det = S::splat(1.0) / (d00 * d11 - d01 * d10);
    let zero = S::splat(0.0);
    let dinv = S::M3::from_cols(
        S::V3::new(d11 * inv_det, -d10 * inv_det, zero),
        S::V3::new(-d01 * inv_det, d00 * inv_det, zero),
        S::V3::new(zero, zero, S::splat(1.0)),
    );
    let u = [u0, u1];
    out.u[0] = u0;
    out.u[1] = u1;
    *out.dinv = dinv;
    *out.uu = S::V3::new(uu0, uu1, zero);
    if !has_parent {
        return pa;
    }
    let (c0, c1) = (dinv.col(0), dinv.col(1));
    let w = [
        u0 * c0.get(0) + u1 * c0.get(1),
        u0 * c1.get(0) + u1 * c1.get(1),
    ];
    ia.sub_products(&w, &u);
    pa + u0 * (c0.get(0) * uu0 + c1.get(0) * uu1) + u1 * (c0.get(1) * uu0 + c1.get(1) * uu1)
}

/// Pass 2 for a joint of `nv` (2 or 3) rotational DOFs about general axes (ball, universal):
/// `D` (`nv`×`nv`) inverted as a 3×3 with ones beyond `nv`; as [`pin_pass2`].
#[inline(always)]
fn rotational_pass2<S: Real>(
    ia: &mut S::Inertia,
    pa: S::Force,
    (s, nv): (&S::Columns, usize),
    joint: JointInputs<S, impl JointForces<S>>,
    out: JointSlots<S>,
    has_parent: bool,
) -> S::Force {
    let mut u = [S::Force::ZERO; 3];
    let mut d = S::M3::IDENTITY;
    let mut uu = S::V3::ZERO;
    for k in 0..nv {
        let a = s.axis(k);
        u[k] = ia.apply_angular(a);
        uu.set(k, joint.tau(k) - a.dot(pa.ang()));
    }
    for r in 0..nv {
        for k in 0..nv {
            let mut e = s.axis(r).dot(u[k].ang());
            if r == k {
                e += joint.arm(k);
            }
            d.col_mut(k).set(r, e);
        }
    }
    let dinv = d.inverse();
    *out.u = u;
    *out.dinv = dinv;
    *out.uu = uu;
    if !has_parent {
        return pa;
    }
    if nv == 2 {
        ia.sub_u_dinv_ut(&[u[0], u[1]], &dinv);
    } else {
        ia.sub_u_dinv_ut(&u, &dinv);
    }
    let w = dinv.mul_vec3(uu);
    let mut pa_a = pa;
    for k in 0..nv {
        pa_a += u[k] * w.get(k);
    }
    pa_a
}

/// Pass 3 (root → leaves): `a' = Xup a_λ + c`, `q̈ = D⁻¹(u − Uᵀ a')`, `a = a' + S q̈`
/// (Featherstone 2008, Table 7.1), from the base's `a0` (gravity, [`base_acceleration`]); a
/// free root's `a = (I^A)⁻¹(τ − p^A)` (`FDfb`). Writes `q̈` into `qdd`.
#[inline(always)]
pub(super) fn pass3_accelerations<S: Real>(
    model: &Model,
    bodies: &mut Bodies<S>,
    forces: &impl JointForces<S>,
    a0: S::Motion,
    qdd: &mut (impl Accelerations<S> + ?Sized),
) {
    let n = model.nbodies();
    let (xups, ss, cs) = (&bodies.xup[..n], &bodies.s[..n], &bodies.c[..n]);
    let (accs, ias, pas) = (&mut bodies.a[..n], &bodies.ia[..n], &bodies.pa[..n]);
    let (us, dinvs, uus) = (&bodies.u[..n], &bodies.dinv[..n], &bodies.uu[..n]);
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
                let x = dinvs[i].col(0).get(0) * (uus[i].get(0) - a_prime.dot(us[i][0]));
                qdd.put(iv, x);
                let mut a = a_prime;
                *a.ang_mut() += ss[i].axis(0) * x;
                accs[i] = a;
            }
            JointType::Universal { .. } => {
                accs[i] = multi_dof_acceleration::<S, 2>(
                    (&us[i], &dinvs[i], uus[i]),
                    &ss[i],
                    a_prime,
                    iv,
                    qdd,
                )
            }
            JointType::Ball { .. } => {
                accs[i] = multi_dof_acceleration::<S, 3>(
                    (&us[i], &dinvs[i], uus[i]),
                    &ss[i],
                    a_prime,
                    iv,
                    qdd,
                )
            }
            JointType::Fixed => accs[i] = a_prime,
            JointType::Free => {
                let t = |k: usize| forces.tau(iv + k);
                let f = S::Force::new(S::V3::new(t(0), t(1), t(2)), S::V3::new(t(3), t(4), t(5)))
                    - pas[i];
                let a = ias[i].solve(f);
                let x = a - a_prime;
                for k in 0..3 {
                    qdd.put(iv + k, x.ang().get(k));
                }
                for k in 0..3 {
                    qdd.put(iv + 3 + k, x.lin().get(k));
                }
                accs[i] = a;
            }
        }
    }
}

/// The column of a joint DOF about the coordinate axis `ax` (`S = [±e_k; 0]`): `U = I^A S`
/// (± column k of `[M; Hᵀ]`), `Sᵀ U = M_kk` and `τ − Sᵀ p^A`.
#[inline(always)]
fn coordinate_column<S: Real>(
    ia: &S::Inertia,
    ax: CoordAxis,
    tau: S,
    pa: S::Force,
) -> (S::Force, S, S) {
    let sign = S::splat(ax.sign);
    (
        S::Force::new(ia.m().col(ax.k) * sign, ia.h().row(ax.k) * sign),
        ia.m().col(ax.k).get(ax.k),
        tau - sign * pa.ang().get(ax.k),
    )
}

/// Pass 3 for a joint of `N` rotational DOFs: `q̈ = D⁻¹(u − Uᵀ a')`, `a = a' + S q̈`.
#[inline(always)]
fn multi_dof_acceleration<S: Real, const N: usize>(
    (u, dinv, uu): (&[S::Force; 3], &S::M3, S::V3),
    s: &S::Columns,
    a_prime: S::Motion,
    iv: usize,
    qdd: &mut (impl Accelerations<S> + ?Sized),
) -> S::Motion {
    let mut r = S::V3::ZERO;
    for k in 0..N {
        r.set(k, uu.get(k) - a_prime.dot(u[k]));
    }
    let x = dinv.mul_vec3(r);
    let mut a = a_prime;
    for k in 0..N {
        qdd.put(iv + k, x.get(k));
        *a.ang_mut() += s.axis(k) * x.get(k);
    }
    a
}
