//! The scratch workspace of the dynamics algorithms (Pinocchio's `Data`): every buffer is sized
//! once from a [`Model`], so the algorithms never allocate.

use super::axis_rotation::JointRotation;
use super::model::Model;
use super::spatial::{ArticulatedInertia, ForceVec, MotionVec, SpatialTransform};
use glam::{DMat3, DVec3};

/// Per-body and per-DOF buffers filled by [`kinematics`](super::kinematics::kinematics),
/// [`aba`](super::aba::aba), [`rnea`](super::rnea::rnea) and [`crba`](super::crba::crba).
#[derive(Clone, Debug)]
pub struct Data {
    /// `Xup[i]`: parent frame → body `i` frame (world → body for a root).
    pub xup: Vec<SpatialTransform>,
    /// The joint rotation of each `Xup` as its coordinate-axis factors, where the model's
    /// `JointAxes` has them.
    pub xup_rotation: Vec<JointRotation>,
    /// Motion-subspace columns `S` of each joint, body coordinates (first `nv` used; free: none).
    pub s: Vec<[MotionVec; 3]>,
    /// Body spatial velocity, body coordinates.
    pub v: Vec<MotionVec>,
    /// Velocity-product acceleration `c = c_J + v ×m v_J`, body coordinates.
    pub c: Vec<MotionVec>,
    /// Body spatial acceleration (including the fictitious `−g` base acceleration), body coordinates.
    pub a: Vec<MotionVec>,
    /// Articulated-body inertia `I^A`; after the ABA's second pass, for a body with a parent,
    /// the inertia `I^a = I^A − U D⁻¹ Uᵀ` it passed on (updated in place).
    pub ia: Vec<ArticulatedInertia>,
    /// Articulated bias force `p^A`.
    pub pa: Vec<ForceVec>,
    /// `U = I^A S` per joint column.
    pub u: Vec<[ForceVec; 3]>,
    /// `D⁻¹ = (Sᵀ U)⁻¹` (a 1×1, 2×2 or 3×3 block).
    pub dinv: Vec<DMat3>,
    /// `u = τ − Sᵀ p^A` per joint column.
    pub uu: Vec<DVec3>,
    /// Body forces of the recursive Newton–Euler algorithm, body coordinates.
    pub f: Vec<ForceVec>,
    /// Composite inertias of the composite-rigid-body algorithm.
    pub ic: Vec<ArticulatedInertia>,
    /// `sin q` and `cos q` entry by entry (size nq), filled by
    /// [`kinematics`](super::kinematics::kinematics) at the model's `axis_angles` only.
    pub q_sin_cos: (Vec<f64>, Vec<f64>),
    /// World orientation of each body (body → world rotation).
    pub rot: Vec<DMat3>,
    /// World position of each body origin (m).
    pub pos: Vec<DVec3>,
    /// Joint accelerations `q̈` (size nv).
    pub qdd: Vec<f64>,
    /// Joint forces `τ` (size nv), output of RNEA.
    pub tau: Vec<f64>,
    /// Joint-space inertia matrix `H` (nv × nv, row-major), output of CRBA; factored in place.
    pub h: Vec<f64>,
    /// Scratch vector of size nv.
    pub scratch: Vec<f64>,
    /// A zero vector of size nv.
    pub zeros: Vec<f64>,
}

impl Data {
    /// Allocates a workspace for `model`.
    pub fn new(model: &Model) -> Self {
        let n = model.nbodies();
        let nv = model.nv;
        Self {
            xup: vec![SpatialTransform::IDENTITY; n],
            xup_rotation: vec![JointRotation::General; n],
            s: vec![[MotionVec::ZERO; 3]; n],
            v: vec![MotionVec::ZERO; n],
            c: vec![MotionVec::ZERO; n],
            a: vec![MotionVec::ZERO; n],
            ia: vec![ArticulatedInertia::ZERO; n],
            pa: vec![ForceVec::ZERO; n],
            u: vec![[ForceVec::ZERO; 3]; n],
            dinv: vec![DMat3::IDENTITY; n],
            uu: vec![DVec3::ZERO; n],
            f: vec![ForceVec::ZERO; n],
            ic: vec![ArticulatedInertia::ZERO; n],
            q_sin_cos: (vec![0.0; model.nq], vec![0.0; model.nq]),
            rot: vec![DMat3::IDENTITY; n],
            pos: vec![DVec3::ZERO; n],
            qdd: vec![0.0; nv],
            tau: vec![0.0; nv],
            h: vec![0.0; nv * nv],
            scratch: vec![0.0; nv],
            zeros: vec![0.0; nv],
        }
    }
}
