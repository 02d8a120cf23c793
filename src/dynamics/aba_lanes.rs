//! The articulated-body algorithm for [`LANES`] bodies of one model at once: passes 2 and 3 of
//! [`aba_passes`] (Featherstone 2008, §7.3) with every quantity a lane of [`super::lanes`], so
//! one vector instruction advances every body. Passes 2 and 3 are the one source of
//! [`super::aba`] at the width [`F4`]; this file gathers the lanes' kinematics (pass 1) and
//! holds the lane buffers. Each lane's `q̈` has the bits of [`aba_passes`] on that body alone:
//! the same operations in the same order, the branches taken on the model's structure (joint
//! types and axes), which every lane shares.

use super::aba::{Bodies, aba_passes, pass2_articulated_inertias, pass3_accelerations};
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
    let n = model.nbodies();
    let mut bodies = Bodies::<F4> {
        xup: &lanes.xup[..n],
        rotation: &lanes.rotation[..n],
        s: &lanes.s[..n],
        c: &lanes.c[..n],
        a: &mut lanes.a[..n],
        ia: &mut lanes.ia[..n],
        pa: &mut lanes.pa[..n],
        u: &mut lanes.u[..n],
        dinv: &mut lanes.dinv[..n],
        uu: &mut lanes.uu[..n],
    };
    let forces = (&tau, &armature);
    pass2_articulated_inertias(model, &mut bodies, &forces);
    let a0 = base_acceleration(model);
    let a0 = Motion4::new(V3::splat(a0.ang), V3::splat(a0.lin));
    let mut qdd = data.map(|d| &mut d.qdd[..]);
    pass3_accelerations(model, &mut bodies, &forces, a0, &mut qdd);
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
