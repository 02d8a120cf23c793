//! The articulated-body algorithm for [`LANES`] bodies of one model at once: passes 2 and 3 of
//! [`aba_passes`] (Featherstone 2008, §7.3) with every quantity a lane of [`super::lanes`], so
//! one vector instruction advances every body. Each lane's `q̈` has the bits of
//! [`aba_passes`] on that body alone: the same operations in the same order, the branches
//! taken on the model's structure (joint types and axes), which every lane shares.

use super::aba::aba_passes;
use super::axis_rotation::{CoordAxis, JointAxes};
use super::data::Data;
use super::joint::JointType;
use super::kinematics::base_acceleration;
use super::lanes::{
    F4, Force4, Inertia4, LANES, M3, Motion4, Rotation4, Transform4, V3, rigid_apply,
};
use super::model::Model;
use super::spatial::ForceVec;

/// Lane buffers of [`aba_passes_lanes`], sized once from a model, and the bodies that fill
/// the lanes a call leaves empty.
#[derive(Clone, Debug)]
pub struct LaneData {
    buf: LaneBuffers,
    /// Kinematics of the model's neutral configuration, one per lane that can be empty.
    pad: Vec<Data>,
    /// Zero joint forces (nv).
    pad_tau: Vec<f64>,
    /// Zero external forces (one per body).
    pad_f_ext: Vec<ForceVec>,
}

impl LaneData {
    /// Buffers for `model`.
    pub fn new(model: &Model) -> Self {
        let (q, v) = (model.neutral(), vec![0.0; model.nv]);
        let pad = (1..LANES)
            .map(|_| {
                let mut d = Data::new(model);
                super::kinematics::kinematics(model, &mut d, &q, &v);
                d
            })
            .collect();
        Self {
            buf: LaneBuffers::new(model),
            pad,
            pad_tau: vec![0.0; model.nv],
            pad_f_ext: vec![ForceVec::ZERO; model.nbodies()],
        }
    }
}

/// One body of a lane call: its kinematics (in `data`, which receives `q̈`), joint forces
/// (nv), external forces (per body, body coordinates) and optional armature (nv).
#[derive(Debug)]
pub struct LaneInput<'a> {
    /// Kinematics in, `q̈` out.
    pub data: &'a mut Data,
    /// Joint forces.
    pub tau: &'a [f64],
    /// External forces per body.
    pub f_ext: &'a [ForceVec],
    /// Armature added to each joint's `D`.
    pub armature: Option<&'a [f64]>,
}

#[derive(Clone, Debug)]
struct LaneBuffers {
    xup: Vec<Transform4>,
    rotation: Vec<Rotation4>,
    s: Vec<[V3; 3]>,
    c: Vec<Motion4>,
    a: Vec<Motion4>,
    ia: Vec<Inertia4>,
    pa: Vec<Force4>,
    u: Vec<[Force4; 3]>,
    dinv: Vec<M3>,
    uu: Vec<V3>,
}

impl LaneBuffers {
    fn new(model: &Model) -> Self {
        let n = model.nbodies();
        Self {
            xup: vec![
                Transform4 {
                    rot: M3::ZERO,
                    trans: V3::ZERO,
                };
                n
            ],
            rotation: vec![Rotation4::General; n],
            s: vec![[V3::ZERO; 3]; n],
            c: vec![Motion4::ZERO; n],
            a: vec![Motion4::ZERO; n],
            ia: vec![Inertia4::splat(&super::spatial::ArticulatedInertia::ZERO); n],
            pa: vec![Force4::ZERO; n],
            u: vec![[Force4::ZERO; 3]; n],
            dinv: vec![M3::ZERO; n],
            uu: vec![V3::ZERO; n],
        }
    }
}

/// Passes 2 and 3 of the ABA for the bodies of `bodies` (all of `model`, kinematics in their
/// `data`), [`LANES`] at a time in the lanes of one vector computation, as [`aba_passes`] with
/// no implicit inertias: writes each body's `q̈` into its `data.qdd` with the bits
/// [`aba_passes`] gives it alone. The other ABA buffers of `data` are not written. Lanes a
/// call leaves empty compute a body at rest, whose result is dropped.
///
/// On an x86-64 processor with AVX2 this runs in a copy compiled for it (four `f64` per
/// instruction; [`crate::cpu::has_avx2`]).
pub fn aba_passes_lanes(model: &Model, lanes: &mut LaneData, bodies: &mut [LaneInput]) {
    #[cfg(target_arch = "x86_64")]
    if crate::cpu::has_avx2() {
        // SAFETY: the processor supports AVX2 (detected at run time just above).
        return unsafe { lanes_avx2(model, lanes, bodies) };
    }
    lanes_inline(model, lanes, reborrow(bodies))
}

fn reborrow<'s>(bodies: &'s mut [LaneInput]) -> impl Iterator<Item = LaneInput<'s>> {
    bodies.iter_mut().map(|b| LaneInput {
        data: &mut *b.data,
        tau: b.tau,
        f_ext: b.f_ext,
        armature: b.armature,
    })
}

/// [`aba_passes_lanes`] over the bodies `bodies` yields, inlined into its caller (the step's
/// AVX2 copy inlines it there).
#[inline(always)]
pub fn lanes_inline<'a>(
    model: &Model,
    lanes: &mut LaneData,
    bodies: impl IntoIterator<Item = LaneInput<'a>>,
) {
    let LaneData {
        buf,
        pad,
        pad_tau,
        pad_f_ext,
    } = lanes;
    let mut bodies = bodies.into_iter().peekable();
    while bodies.peek().is_some() {
        let mut spare = pad.iter_mut();
        let mut tau = [&pad_tau[..]; LANES];
        let mut f_ext = [&pad_f_ext[..]; LANES];
        let mut armature = [None; LANES];
        let data: [&mut Data; LANES] = std::array::from_fn(|l| match bodies.next() {
            Some(b) => {
                (tau[l], f_ext[l], armature[l]) = (b.tau, b.f_ext, b.armature);
                b.data
            }
            // Lane 0 always holds a body: at most LANES - 1 are empty.
            None => spare.next().expect("LANES - 1 spare bodies"),
        });
        passes(model, buf, data, tau, f_ext, armature);
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn lanes_avx2(model: &Model, lanes: &mut LaneData, bodies: &mut [LaneInput]) {
    lanes_inline(model, lanes, reborrow(bodies))
}

/// Passes 2 and 3 for exactly [`LANES`] bodies.
#[inline(always)]
fn passes(
    model: &Model,
    lanes: &mut LaneBuffers,
    data: [&mut Data; LANES],
    tau: [&[f64]; LANES],
    f_ext: [&[ForceVec]; LANES],
    armature: [Option<&[f64]>; LANES],
) {
    // Lanes whose joint structure differs (not bodies of one model) are each taken alone.
    if !gather_rotations(model, lanes, &data) {
        for (l, d) in data.into_iter().enumerate() {
            aba_passes(model, d, tau[l], f_ext[l], armature[l], &[]);
        }
        return;
    }
    pass1_bias_forces(model, lanes, &data, f_ext);
    pass2_articulated_inertias(model, lanes, &tau, &armature);
    pass3_accelerations(model, lanes, data, &tau);
}

/// The joint forces and armature of one body's joint in every lane, whose first DOF is `iv`.
#[derive(Clone, Copy)]
struct JointInputs<'a> {
    tau: &'a [&'a [f64]; LANES],
    armature: &'a [Option<&'a [f64]>; LANES],
    iv: usize,
}

impl JointInputs<'_> {
    /// `τ` of the joint's DOF `k`.
    #[inline(always)]
    fn tau(&self, k: usize) -> F4 {
        F4::from_fn(|l| self.tau[l][self.iv + k])
    }

    /// The armature of the joint's DOF `k` (0 without armature).
    #[inline(always)]
    fn arm(&self, k: usize) -> F4 {
        F4::from_fn(|l| self.armature[l].map_or(0.0, |a| a[self.iv + k]))
    }
}

/// Where pass 2 leaves one body's `U`, `D⁻¹` and `u` for pass 3 (only the joint's DOFs are
/// written).
struct JointSlots<'a> {
    u: &'a mut [Force4; 3],
    dinv: &'a mut M3,
    uu: &'a mut V3,
}

/// Gathers each body's joint rotation from the lanes; false if the lanes' rotations differ
/// in structure (and the lanes must be taken alone).
#[inline(always)]
fn gather_rotations(model: &Model, lanes: &mut LaneBuffers, data: &[&mut Data; LANES]) -> bool {
    let n = model.nbodies();
    // (A loop, not `all`: an iterator adaptor left out of line would run without AVX2.)
    for (i, rot) in lanes.rotation[..n].iter_mut().enumerate() {
        match Rotation4::gather(std::array::from_fn(|l| &data[l].xup_rotation[i])) {
            Some(r) => *rot = r,
            None => return false,
        }
    }
    true
}

/// The end of pass 1: gathers the lanes' kinematics (`Xup, S, c`) and starts each body's
/// articulated inertia and bias force as its own, `I^A = I` and `p^A = v ×* I v − f_ext`
/// (Featherstone 2008, Table 7.1).
#[inline(always)]
fn pass1_bias_forces(
    model: &Model,
    lanes: &mut LaneBuffers,
    data: &[&mut Data; LANES],
    f_ext: [&[ForceVec]; LANES],
) {
    let n = model.nbodies();
    let (xups, ss, cs) = (&mut lanes.xup[..n], &mut lanes.s[..n], &mut lanes.c[..n]);
    let (ias, pas) = (&mut lanes.ia[..n], &mut lanes.pa[..n]);
    for i in 0..n {
        let body = &model.bodies[i];
        xups[i] = Transform4::gather(std::array::from_fn(|l| &data[l].xup[i]));
        if !matches!(body.joint, JointType::Free | JointType::Fixed) {
            for k in 0..body.joint.nv() {
                ss[i][k] = V3::from_fn(|l| data[l].s[i][k].ang);
            }
        }
        cs[i] = Motion4::from_fn(|l| data[l].c[i]);
        let vi = Motion4::from_fn(|l| data[l].v[i]);
        pas[i] = vi.cross_force(rigid_apply(&body.inertia, vi)) - Force4::from_fn(|l| f_ext[l][i]);
        ias[i] = Inertia4::splat(&model.inertia_blocks[i]);
    }
}

/// Pass 2 (leaves → root): each joint's `U = I^A S`, `D = Sᵀ U` (+ armature) and
/// `u = τ − Sᵀ p^A`; a body with a parent passes on `I^a = I^A − U D⁻¹ Uᵀ` and
/// `p^a = p^A + I^a c + U D⁻¹ u`, accumulated into the parent as `Xupᵀ I^a Xup` and
/// `Xupᵀ p^a` (Featherstone 2008, Table 7.1).
#[inline(always)]
fn pass2_articulated_inertias(
    model: &Model,
    lanes: &mut LaneBuffers,
    tau: &[&[f64]; LANES],
    armature: &[Option<&[f64]>; LANES],
) {
    let n = model.nbodies();
    let (xups, rots) = (&lanes.xup[..n], &lanes.rotation[..n]);
    let (ss, cs) = (&lanes.s[..n], &lanes.c[..n]);
    let (ias, pas) = (&mut lanes.ia[..n], &mut lanes.pa[..n]);
    let (us, dinvs, uus) = (&mut lanes.u[..n], &mut lanes.dinv[..n], &mut lanes.uu[..n]);
    for i in (0..n).rev() {
        let body = &model.bodies[i];
        let joint = JointInputs {
            tau,
            armature,
            iv: model.v_idx[i],
        };
        let (ia_head, ia_tail) = ias.split_at_mut(i);
        let ia = &mut ia_tail[0];
        let pa = pas[i];
        let out = JointSlots {
            u: &mut us[i],
            dinv: &mut dinvs[i],
            uu: &mut uus[i],
        };
        let has_parent = body.parent.is_some();
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
    ia: &mut Inertia4,
    pa: Force4,
    (s, axes): (&[V3; 3], JointAxes),
    joint: JointInputs,
    out: JointSlots,
    has_parent: bool,
) -> Force4 {
    let (u, d, uu) = match axes {
        JointAxes::One(ax) => coordinate_column(ia, ax.k, ax.sign, joint.tau(0), pa),
        _ => {
            let a = s[0];
            let u = ia.apply_angular(a);
            (u, a.dot(u.ang), joint.tau(0) - a.dot(pa.ang))
        }
    };
    let d = d + joint.arm(0);
    let dinv = F4::splat(1.0) / d;
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
    ia: &mut Inertia4,
    pa: Force4,
    (s, a2): (&[V3; 3], CoordAxis),
    joint: JointInputs,
    out: JointSlots,
    has_parent: bool,
) -> Force4 {
    let b = s[0];
    let u0 = ia.apply_angular(b);
    let (u1, d11, uu1) = coordinate_column(ia, a2.k, a2.sign, joint.tau(1), pa);
    let d00 = b.dot(u0.ang) + joint.arm(0);
    let d11 = d11 + joint.arm(1);
    let (d01, d10) = (b.dot(u1.ang), u0.ang.get(a2.k) * a2.sign);
    let uu0 = joint.tau(0) - b.dot(pa.ang);
    let inv_det = F4::splat(1.0) / (d00 * d11 - d01 * d10);
    let dinv = M3::from_cols(
        V3::new(d11 * inv_det, -d10 * inv_det, F4::ZERO),
        V3::new(-d01 * inv_det, d00 * inv_det, F4::ZERO),
        V3::new(F4::ZERO, F4::ZERO, F4::splat(1.0)),
    );
    let u = [u0, u1];
    out.u[0] = u0;
    out.u[1] = u1;
    *out.dinv = dinv;
    *out.uu = V3::new(uu0, uu1, F4::ZERO);
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
    ia: &mut Inertia4,
    pa: Force4,
    (s, nv): (&[V3; 3], usize),
    joint: JointInputs,
    out: JointSlots,
    has_parent: bool,
) -> Force4 {
    let mut u = [Force4::ZERO; 3];
    let mut d = M3::splat(&glam::DMat3::IDENTITY);
    let mut uu = V3::ZERO;
    for k in 0..nv {
        let a = s[k];
        u[k] = ia.apply_angular(a);
        uu.set(k, joint.tau(k) - a.dot(pa.ang));
    }
    for r in 0..nv {
        for k in 0..nv {
            let mut e = s[r].dot(u[k].ang);
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
/// (Featherstone 2008, Table 7.1); a free root's `a = (I^A)⁻¹(τ − p^A)` (`FDfb`). Writes each
/// lane's `q̈` into its `data`.
#[inline(always)]
fn pass3_accelerations(
    model: &Model,
    lanes: &mut LaneBuffers,
    data: [&mut Data; LANES],
    tau: &[&[f64]; LANES],
) {
    let n = model.nbodies();
    let (xups, ss, cs) = (&lanes.xup[..n], &lanes.s[..n], &lanes.c[..n]);
    let (accs, ias, pas) = (&mut lanes.a[..n], &lanes.ia[..n], &lanes.pa[..n]);
    let (us, dinvs, uus) = (&lanes.u[..n], &lanes.dinv[..n], &lanes.uu[..n]);
    let tau_of = |k: usize| F4::from_fn(|l| tau[l][k]);
    let a0 = base_acceleration(model);
    let a0 = Motion4::new(V3::splat(a0.ang), V3::splat(a0.lin));
    let mut qdds = data.map(|d| &mut d.qdd[..]);
    let mut put = |k: usize, x: F4| {
        for (q, x) in qdds.iter_mut().zip(x.0) {
            q[k] = x;
        }
    };
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
                let qdd = dinvs[i].x_axis.x * (uus[i].x - a_prime.dot(us[i][0]));
                put(iv, qdd);
                let mut a = a_prime;
                a.ang += ss[i][0] * qdd;
                accs[i] = a;
            }
            JointType::Universal { .. } => {
                accs[i] = multi_dof_acceleration::<2>(
                    (&us[i], &dinvs[i], uus[i], &ss[i]),
                    a_prime,
                    iv,
                    &mut put,
                )
            }
            JointType::Ball { .. } => {
                accs[i] = multi_dof_acceleration::<3>(
                    (&us[i], &dinvs[i], uus[i], &ss[i]),
                    a_prime,
                    iv,
                    &mut put,
                )
            }
            JointType::Fixed => accs[i] = a_prime,
            JointType::Free => {
                let f = Force4::new(
                    V3::new(tau_of(iv), tau_of(iv + 1), tau_of(iv + 2)),
                    V3::new(tau_of(iv + 3), tau_of(iv + 4), tau_of(iv + 5)),
                ) - pas[i];
                let a = ias[i].solve(f);
                let qdd = a - a_prime;
                for (k, x) in [
                    qdd.ang.x, qdd.ang.y, qdd.ang.z, qdd.lin.x, qdd.lin.y, qdd.lin.z,
                ]
                .into_iter()
                .enumerate()
                {
                    put(iv + k, x);
                }
                accs[i] = a;
            }
        }
    }
}

/// The column of a DOF about coordinate axis `k` with sign `sign`: `U = I^A S`, `Sᵀ U` and
/// `τ − Sᵀ p^A` (the scalar `coordinate_column`).
#[inline(always)]
fn coordinate_column(ia: &Inertia4, k: usize, sign: f64, tau: F4, pa: Force4) -> (Force4, F4, F4) {
    (
        Force4::new(ia.m.col(k) * sign, ia.h.row(k) * sign),
        ia.m.col(k).get(k),
        tau - pa.ang.get(k) * sign,
    )
}

/// Pass 3 for a joint of `N` rotational DOFs: `q̈ = D⁻¹(u − Uᵀ a')`, `a = a' + S q̈`.
#[inline(always)]
fn multi_dof_acceleration<const N: usize>(
    (u, dinv, uu, s): (&[Force4; 3], &M3, V3, &[V3; 3]),
    a_prime: Motion4,
    iv: usize,
    put: &mut impl FnMut(usize, F4),
) -> Motion4 {
    let mut r = V3::ZERO;
    for k in 0..N {
        r.set(k, uu.get(k) - a_prime.dot(u[k]));
    }
    let qdd = dinv.mul_vec3(r);
    let mut a = a_prime;
    for k in 0..N {
        put(iv + k, qdd.get(k));
        a.ang += s[k] * qdd.get(k);
    }
    a
}
