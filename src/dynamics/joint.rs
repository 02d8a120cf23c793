//! Joint models (Featherstone's `jcalc`): the joint transform `X_J(q)`, the motion subspace `S`
//! (in the successor body's coordinates), the velocity product `c_J = Ṡ q̇`, and configuration
//! integration on the manifold (quaternions stay unit; no gimbal lock).
//!
//! Velocity conventions: a pin or universal joint's velocities are its angle rates; a ball joint's
//! three velocities are the child's angular velocity relative to the parent, in child coordinates,
//! projected on the joint's orthonormal DOF axes (`ω = A v`); a free joint's six velocities are the
//! body's spatial velocity `[ω; v]` in body coordinates. Quaternions are stored `x, y, z, w`; a
//! free joint's configuration is `[p; Q]` (world position of the body origin, then orientation).
//! The motion-subspace columns of pin, universal and ball joints are pure rotations `[a; 0]`
//! (the joint frame's origin is the rotation centre); the articulated-body algorithm relies on it.

use super::axis_rotation::{AxisRotation, JointAxes, JointRotation};
use super::spatial::{MotionVec, SpatialTransform};
use glam::{DMat3, DQuat, DVec3};

/// A joint type with its axes (unit vectors in the joint frame, equal to the parent's frame at `q=0`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum JointType {
    /// Revolute joint about `axis`: `R = R(a, θ)`. nq = nv = 1.
    Pin {
        /// Rotation axis (unit).
        axis: DVec3,
    },
    /// Universal joint `R = R(a₁, θ₁)·R(a₂, θ₂)` (`a₁` the parent-side axis). nq = nv = 2.
    Universal {
        /// Outer (parent-side) axis.
        axis1: DVec3,
        /// Inner (child-side) axis.
        axis2: DVec3,
    },
    /// Spherical joint, unit quaternion; its DOF axes are the columns of `axes` (orthonormal).
    /// nq = 4, nv = 3.
    Ball {
        /// The three DOF axes as columns.
        axes: DMat3,
    },
    /// Floating base: position and unit quaternion. nq = 7, nv = 6. Root only.
    Free,
    /// Rigid attachment (a welded joint): `R = 1`, `S` empty. nq = nv = 0; the body moves with
    /// its parent and its inertia reaches the parent's articulated inertia whole.
    Fixed,
}

/// Exact inverse of the right-trivialised exponential differential on SO(3):
/// `u̇ = ω + ½ u×ω + β u×(u×ω)`, `β = (1 − (θ/2)cot(θ/2))/θ²`, `θ = |u|`, so that
/// `R = R₀ exp(u)` moves with body angular velocity `ω`.
#[inline]
pub fn dexp_inv(u: DVec3, w: DVec3) -> DVec3 {
    let t2 = u.length_squared();
    let beta = if t2 < 1e-6 {
        1.0 / 12.0 + t2 / 720.0
    } else {
        let t = t2.sqrt();
        let h = 0.5 * t;
        (1.0 - h * h.cos() / h.sin()) / t2
    };
    let uw = u.cross(w);
    w + 0.5 * uw + beta * u.cross(uw)
}

/// The right-trivialised exponential differential on SO(3), the inverse of [`dexp_inv`]:
/// `ω = u̇ − ((1 − cos θ)/θ²) u×u̇ + ((θ − sin θ)/θ³) u×(u×u̇)`, `θ = |u|`: the body angular
/// velocity of `R = R₀ exp(u)` when the rotation vector moves at `u̇`.
#[inline]
pub fn dexp(u: DVec3, u_dot: DVec3) -> DVec3 {
    let t2 = u.length_squared();
    let (a, b) = if t2 < 1e-6 {
        (0.5 - t2 / 24.0, 1.0 / 6.0 - t2 / 120.0)
    } else {
        let t = t2.sqrt();
        ((1.0 - t.cos()) / t2, (t - t.sin()) / (t2 * t))
    };
    let uw = u.cross(u_dot);
    u_dot - a * uw + b * u.cross(uw)
}

/// The rotation vector (axis·angle, |angle| ≤ π) of a unit quaternion.
#[inline]
pub fn quat_log(q: DQuat) -> DVec3 {
    let q = if q.w < 0.0 { -q } else { q };
    let s = DVec3::new(q.x, q.y, q.z);
    let sn = s.length();
    if sn < 1e-12 {
        return 2.0 * s;
    }
    let angle = 2.0 * sn.atan2(q.w);
    s * (angle / sn)
}

#[inline]
fn quat_at(q: &[f64]) -> DQuat {
    DQuat::from_xyzw(q[0], q[1], q[2], q[3])
}

#[inline]
fn put_quat(q: DQuat, out: &mut [f64]) {
    let q = q.normalize();
    out[0] = q.x;
    out[1] = q.y;
    out[2] = q.z;
    out[3] = q.w;
}

impl JointType {
    /// Configuration size.
    #[inline]
    pub const fn nq(&self) -> usize {
        match self {
            JointType::Pin { .. } => 1,
            JointType::Universal { .. } => 2,
            JointType::Ball { .. } => 4,
            JointType::Free => 7,
            JointType::Fixed => 0,
        }
    }

    /// Velocity size (degrees of freedom).
    #[inline]
    pub const fn nv(&self) -> usize {
        match self {
            JointType::Pin { .. } => 1,
            JointType::Universal { .. } => 2,
            JointType::Ball { .. } => 3,
            JointType::Free => 6,
            JointType::Fixed => 0,
        }
    }

    /// The DOFs of a joint whose coordinates are its angles (pin 1, universal 2; `None` for
    /// the others): its retraction is `θ + z`, its chart rate `v` and its angles `θ`, DOF by DOF
    /// (what [`crate::dynamics::model::Model`]'s per-joint loops take inline).
    #[inline(always)]
    pub const fn angle_dofs(&self) -> Option<usize> {
        match self {
            JointType::Pin { .. } => Some(1),
            JointType::Universal { .. } => Some(2),
            _ => None,
        }
    }

    /// True if every axis is unit length and a ball's axes are orthonormal.
    pub fn axes_valid(&self) -> bool {
        let unit = |a: DVec3| a.is_finite() && (a.length() - 1.0).abs() < 1e-9;
        match self {
            JointType::Pin { axis } => unit(*axis),
            JointType::Universal { axis1, axis2 } => unit(*axis1) && unit(*axis2),
            JointType::Ball { axes } => {
                let g = axes.transpose() * *axes;
                (g - DMat3::IDENTITY)
                    .to_cols_array()
                    .iter()
                    .all(|e| e.abs() < 1e-9)
            }
            JointType::Free | JointType::Fixed => true,
        }
    }

    /// Writes the neutral configuration (zero angles, identity rotation).
    pub fn neutral(&self, q: &mut [f64]) {
        q.fill(0.0);
        match self {
            JointType::Ball { .. } => q[3] = 1.0,
            JointType::Free => q[6] = 1.0,
            _ => {}
        }
    }

    /// The child's orientation relative to the joint frame, `R(q)` (child → parent coordinates).
    #[inline]
    pub fn rotation(&self, q: &[f64]) -> DMat3 {
        match self {
            JointType::Pin { axis } => DMat3::from_axis_angle(*axis, q[0]),
            JointType::Universal { axis1, axis2 } => {
                DMat3::from_axis_angle(*axis1, q[0]) * DMat3::from_axis_angle(*axis2, q[1])
            }
            JointType::Ball { .. } => DMat3::from_quat(quat_at(q)),
            JointType::Free => DMat3::from_quat(quat_at(&q[3..7])),
            JointType::Fixed => DMat3::IDENTITY,
        }
    }

    /// `jcalc`: returns `(X_J, v_J, c_J)` and writes the motion-subspace columns into `s`
    /// (unused for a free joint, whose `S` is the 6×6 identity).
    #[inline(always)]
    pub fn jcalc(
        &self,
        q: &[f64],
        qd: &[f64],
        s: &mut [MotionVec; 3],
    ) -> (SpatialTransform, MotionVec, MotionVec) {
        match self {
            JointType::Pin { axis } => {
                let r = DMat3::from_axis_angle(*axis, q[0]);
                s[0] = MotionVec::new(*axis, DVec3::ZERO);
                (
                    SpatialTransform::rotation(r.transpose()),
                    s[0] * qd[0],
                    MotionVec::ZERO,
                )
            }
            JointType::Universal { axis1, axis2 } => {
                let r1 = DMat3::from_axis_angle(*axis1, q[0]);
                let r2 = DMat3::from_axis_angle(*axis2, q[1]);
                let b = r2.transpose() * *axis1;
                s[0] = MotionVec::new(b, DVec3::ZERO);
                s[1] = MotionVec::new(*axis2, DVec3::ZERO);
                let vj = MotionVec::new(b * qd[0] + *axis2 * qd[1], DVec3::ZERO);
                let cj = MotionVec::new(b.cross(*axis2) * (qd[0] * qd[1]), DVec3::ZERO);
                (SpatialTransform::rotation((r1 * r2).transpose()), vj, cj)
            }
            JointType::Ball { axes } => {
                let r = DMat3::from_quat(quat_at(q));
                s[0] = MotionVec::new(axes.x_axis, DVec3::ZERO);
                s[1] = MotionVec::new(axes.y_axis, DVec3::ZERO);
                s[2] = MotionVec::new(axes.z_axis, DVec3::ZERO);
                let w = *axes * DVec3::new(qd[0], qd[1], qd[2]);
                (
                    SpatialTransform::rotation(r.transpose()),
                    MotionVec::new(w, DVec3::ZERO),
                    MotionVec::ZERO,
                )
            }
            JointType::Free => {
                let r = DMat3::from_quat(quat_at(&q[3..7]));
                let x = SpatialTransform {
                    rot: r.transpose(),
                    trans: DVec3::new(q[0], q[1], q[2]),
                };
                let vj = MotionVec::new(
                    DVec3::new(qd[0], qd[1], qd[2]),
                    DVec3::new(qd[3], qd[4], qd[5]),
                );
                (x, vj, MotionVec::ZERO)
            }
            JointType::Fixed => (SpatialTransform::IDENTITY, MotionVec::ZERO, MotionVec::ZERO),
        }
    }

    /// [`JointType::jcalc`] for a joint whose rotation factors into rotations about coordinate
    /// axes (`axes`, from the model): the same `X_J`, `v_J`, `c_J` and `S` from the factors'
    /// sines and cosines (`sin_q`, `cos_q`: those of the joint's `q`, from
    /// `trig::sin_cos_at`), without general 3×3 products, and the
    /// factors themselves. Joints without that structure (`JointAxes::General`) take
    /// [`JointType::jcalc`].
    #[inline(always)]
    pub fn jcalc_axes(
        &self,
        axes: JointAxes,
        (q, sin_q, cos_q): (&[f64], &[f64], &[f64]),
        qd: &[f64],
        s: &mut [MotionVec; 3],
    ) -> (SpatialTransform, MotionVec, MotionVec, JointRotation) {
        match (self, axes) {
            (JointType::Pin { axis }, JointAxes::One(a)) => {
                let r = AxisRotation::from_sin_cos(a, sin_q[0], cos_q[0]);
                s[0] = MotionVec::new(*axis, DVec3::ZERO);
                let e = r.matrix().transpose();
                (
                    SpatialTransform::rotation(e),
                    s[0] * qd[0],
                    MotionVec::ZERO,
                    JointRotation::One(r),
                )
            }
            (JointType::Universal { axis1, axis2 }, JointAxes::Two(a1, a2)) => {
                let r1 = AxisRotation::from_sin_cos(a1, sin_q[0], cos_q[0]);
                let r2 = AxisRotation::from_sin_cos(a2, sin_q[1], cos_q[1]);
                let b = r2.apply_transpose(*axis1);
                s[0] = MotionVec::new(b, DVec3::ZERO);
                s[1] = MotionVec::new(*axis2, DVec3::ZERO);
                let vj = MotionVec::new(b * qd[0] + *axis2 * qd[1], DVec3::ZERO);
                let cj = MotionVec::new(b.cross(*axis2) * (qd[0] * qd[1]), DVec3::ZERO);
                let r = r2.mul_right(&r1.matrix());
                (
                    SpatialTransform::rotation(r.transpose()),
                    vj,
                    cj,
                    JointRotation::Two(r1, r2),
                )
            }
            _ => {
                let (x, vj, cj) = self.jcalc(q, qd, s);
                (x, vj, cj, JointRotation::General)
            }
        }
    }

    /// Column `k` of the motion subspace for a free joint (`S = 1₆`).
    #[inline]
    pub fn free_column(k: usize) -> MotionVec {
        let mut a = [0.0; 6];
        a[k] = 1.0;
        MotionVec::new(DVec3::new(a[0], a[1], a[2]), DVec3::new(a[3], a[4], a[5]))
    }

    /// The retraction `q ⊞ z`: pin/universal `θ + z`; ball `Q·exp(A z)`; free
    /// `[p + z_lin; Q·exp(z_ang)]` (`z_lin` a world displacement, `z_ang` a body rotation vector).
    #[inline(always)]
    pub fn retract(&self, q: &[f64], z: &[f64], out: &mut [f64]) {
        match self {
            JointType::Pin { .. } => out[0] = q[0] + z[0],
            JointType::Universal { .. } => {
                out[0] = q[0] + z[0];
                out[1] = q[1] + z[1];
            }
            JointType::Ball { axes } => {
                let u = *axes * DVec3::new(z[0], z[1], z[2]);
                put_quat(quat_at(q) * DQuat::from_scaled_axis(u), out);
            }
            JointType::Free => {
                let u = DVec3::new(z[0], z[1], z[2]);
                out[0] = q[0] + z[3];
                out[1] = q[1] + z[4];
                out[2] = q[2] + z[5];
                put_quat(
                    quat_at(&q[3..7]) * DQuat::from_scaled_axis(u),
                    &mut out[3..7],
                );
            }
            JointType::Fixed => {}
        }
    }

    /// The rate `ż` of the chart coordinates `z` (with `q_stage = q₀ ⊞ z`) under velocity `v`:
    /// angles `ż = v`; ball `ż = Aᵀ dexp⁻¹(Az, Av)`; free `ż_ang = dexp⁻¹(z_ang, ω)`,
    /// `ż_lin = R(q_stage) v_lin`. Integrating `ż` in the chart keeps Runge–Kutta at full order.
    #[inline(always)]
    pub fn chart_rate(&self, q_stage: &[f64], z: &[f64], v: &[f64], zdot: &mut [f64]) {
        match self {
            JointType::Pin { .. } => zdot[0] = v[0],
            JointType::Universal { .. } => {
                zdot[0] = v[0];
                zdot[1] = v[1];
            }
            JointType::Ball { axes } => {
                let u = *axes * DVec3::new(z[0], z[1], z[2]);
                let w = *axes * DVec3::new(v[0], v[1], v[2]);
                let r = axes.transpose() * dexp_inv(u, w);
                zdot[..3].copy_from_slice(&r.to_array());
            }
            JointType::Free => {
                let u = DVec3::new(z[0], z[1], z[2]);
                let w = DVec3::new(v[0], v[1], v[2]);
                let r = dexp_inv(u, w);
                let pd = quat_at(&q_stage[3..7]) * DVec3::new(v[3], v[4], v[5]);
                zdot[..3].copy_from_slice(&r.to_array());
                zdot[3..6].copy_from_slice(&pd.to_array());
            }
            JointType::Fixed => {}
        }
    }

    /// The joint's anatomical angles (rad), one per velocity DOF: pin/universal `θ`; ball the
    /// rotation vector's components on its DOF axes (`Aᵀ log Q`); free: zeros.
    #[inline(always)]
    pub fn angles(&self, q: &[f64], out: &mut [f64]) {
        match self {
            JointType::Pin { .. } => out[0] = q[0],
            JointType::Universal { .. } => {
                out[0] = q[0];
                out[1] = q[1];
            }
            JointType::Ball { axes } => {
                let a = axes.transpose() * quat_log(quat_at(q));
                out[..3].copy_from_slice(&a.to_array());
            }
            JointType::Free => out[..6].fill(0.0),
            JointType::Fixed => {}
        }
    }

    /// The joint's angles as [`JointType::angles`], but a ball's rotation vector `v` read as the
    /// representative of the same rotation nearest `reference` (`v` or `v − 2π v̂`): a rotation
    /// tracked through |θ| = π (an arm swung overhead) reads on without the principal branch's
    /// jump to the opposite side. The other joints read as [`JointType::angles`].
    #[inline(always)]
    pub fn angles_near(&self, q: &[f64], reference: &[f64], out: &mut [f64]) {
        self.angles(q, out);
        if matches!(self, JointType::Ball { .. }) {
            let v = DVec3::new(out[0], out[1], out[2]);
            let angle = v.length();
            if angle > 1e-9 {
                let r = DVec3::new(reference[0], reference[1], reference[2]);
                let alt = v * (1.0 - std::f64::consts::TAU / angle);
                // Distances are the same in the DOF coordinates and the joint frame (A is
                // orthonormal).
                if (alt - r).length_squared() < (v - r).length_squared() {
                    out[..3].copy_from_slice(&alt.to_array());
                }
            }
        }
    }

    /// The joint velocity (as `v`) of angles `angles` moving at rates `rates` (the DOFs' time
    /// derivatives): pin and universal `v = θ̇`; ball `v = Aᵀ dexp(Aθ, Aθ̇)` (the child's angular
    /// velocity in its own coordinates, see `dexp`); free and fixed unchanged (`out` is left
    /// as it is).
    #[inline]
    pub fn velocity_from_rates(&self, angles: &[f64], rates: &[f64], out: &mut [f64]) {
        match self {
            JointType::Pin { .. } => out[0] = rates[0],
            JointType::Universal { .. } => {
                out[0] = rates[0];
                out[1] = rates[1];
            }
            JointType::Ball { axes } => {
                let u = *axes * DVec3::new(angles[0], angles[1], angles[2]);
                let ud = *axes * DVec3::new(rates[0], rates[1], rates[2]);
                let w = axes.transpose() * dexp(u, ud);
                out[..3].copy_from_slice(&w.to_array());
            }
            JointType::Free | JointType::Fixed => {}
        }
    }

    /// Sets the configuration from anatomical angles (inverse of [`JointType::angles`]); a free
    /// joint is left unchanged.
    pub fn set_angles(&self, angles: &[f64], q: &mut [f64]) {
        match self {
            JointType::Pin { .. } => q[0] = angles[0],
            JointType::Universal { .. } => {
                q[0] = angles[0];
                q[1] = angles[1];
            }
            JointType::Ball { axes } => {
                let u = *axes * DVec3::new(angles[0], angles[1], angles[2]);
                put_quat(DQuat::from_scaled_axis(u), q);
            }
            JointType::Free | JointType::Fixed => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dexp_inv_matches_finite_difference_of_the_exponential() {
        // R(t) = exp(u(t)); body rate ω = (Rᵀ Ṙ)^∨ must equal the ω fed to dexp_inv.
        let u0 = DVec3::new(0.4, -0.9, 0.3);
        let w = DVec3::new(0.7, 0.2, -1.1);
        let ud = dexp_inv(u0, w);
        let h = 1e-6;
        let r0 = DMat3::from_quat(DQuat::from_scaled_axis(u0));
        let r1 = DMat3::from_quat(DQuat::from_scaled_axis(u0 + ud * h));
        let wh = quat_log(DQuat::from_mat3(&(r0.transpose() * r1))) / h;
        assert!((wh - w).length() < 1e-5, "{wh} vs {w}");
    }

    #[test]
    fn dexp_inverts_dexp_inv_and_is_the_body_rate_of_exp() {
        for u in [
            DVec3::new(0.4, -0.9, 0.3),
            DVec3::new(3.0, 0.2, -0.1),
            DVec3::ZERO,
        ] {
            let w = DVec3::new(0.7, 0.2, -1.1);
            assert!((dexp(u, dexp_inv(u, w)) - w).length() < 1e-12, "{u}");
            let ud = DVec3::new(-0.3, 1.2, 0.5);
            let h = 1e-6;
            let r0 = DMat3::from_quat(DQuat::from_scaled_axis(u));
            let r1 = DMat3::from_quat(DQuat::from_scaled_axis(u + ud * h));
            let wh = quat_log(DQuat::from_mat3(&(r0.transpose() * r1))) / h;
            assert!(
                (wh - dexp(u, ud)).length() < 1e-5,
                "{wh} vs {}",
                dexp(u, ud)
            );
        }
    }

    #[test]
    fn ball_angles_near_a_reference_read_on_through_pi() {
        let axes = DMat3::from_cols(DVec3::NEG_X, DVec3::NEG_Z, DVec3::NEG_Y);
        let j = JointType::Ball { axes };
        let mut q = [0.0; 4];
        // An arm flexed 190° with 8° of abduction: the principal branch reads it as the
        // opposite rotation of 170°.
        let set = [190f64.to_radians(), 8f64.to_radians(), 0.0];
        j.set_angles(&set, &mut q);
        let (mut plain, mut near) = ([0.0; 3], [0.0; 3]);
        j.angles(&q, &mut plain);
        assert!(plain[0] < 0.0, "{plain:?}");
        j.angles_near(&q, &[3.2, 0.1, 0.0], &mut near);
        for k in 0..3 {
            assert!((near[k] - set[k]).abs() < 1e-9, "{near:?}");
        }
        // Near zero the reading is the principal one, bit for bit.
        j.set_angles(&[0.3, -0.2, 0.1], &mut q);
        j.angles(&q, &mut plain);
        j.angles_near(&q, &[0.0; 3], &mut near);
        assert_eq!(plain, near);
    }

    #[test]
    fn universal_cj_is_the_derivative_of_s() {
        let j = JointType::Universal {
            axis1: DVec3::X,
            axis2: DVec3::Y,
        };
        let (q, qd) = ([0.3, -0.5], [1.3, 0.8]);
        let mut s0 = [MotionVec::ZERO; 3];
        let (_, vj, cj) = j.jcalc(&q, &qd, &mut s0);
        let h = 1e-7;
        let q1 = [q[0] + h * qd[0], q[1] + h * qd[1]];
        let mut s1 = [MotionVec::ZERO; 3];
        let (_, vj1, _) = j.jcalc(&q1, &qd, &mut s1);
        let fd = (vj1 - vj) * (1.0 / h);
        assert!((fd - cj).ang.length() < 1e-6);
    }

    #[test]
    fn ball_angles_round_trip() {
        let axes = DMat3::from_cols(DVec3::X, DVec3::Z, DVec3::Y);
        let j = JointType::Ball { axes };
        let mut q = [0.0; 4];
        j.set_angles(&[0.2, -0.3, 0.5], &mut q);
        let mut a = [0.0; 3];
        j.angles(&q, &mut a);
        assert!((a[0] - 0.2).abs() < 1e-12 && (a[1] + 0.3).abs() < 1e-12);
        assert!((a[2] - 0.5).abs() < 1e-12);
    }
}
