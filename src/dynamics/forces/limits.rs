//! The joint model of the paper (eqs. 3.4, 3.5), per DOF: viscous friction `τ = −k_v θ̇` inside
//! the range `[θ_lo, θ_hi]`; past a limit the restoring torque `τ = −k_p(θ − θ_lim) − k_v θ̇`.

use serde::{Deserialize, Serialize};

/// Gains of the joint model, shared by every DOF (the range is per DOF).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointLimitParams {
    /// Viscous friction inside the range `k_v` (N·m·s/rad).
    pub friction_kv: f64,
    /// Limit spring `k_p` past a limit (N·m/rad).
    pub limit_kp: f64,
    /// Limit damper `k_v` past a limit (N·m·s/rad).
    pub limit_kv: f64,
}

impl Default for JointLimitParams {
    fn default() -> Self {
        Self {
            friction_kv: 0.5,
            limit_kp: 300.0,
            limit_kv: 10.0,
        }
    }
}

/// The joint model of a body: one range `(θ_lo, θ_hi)` per actuated DOF (rad) and the shared
/// gains.
#[derive(Clone, Debug, PartialEq)]
pub struct JointRanges {
    /// `(lo, hi)` per DOF (rad).
    pub ranges: Vec<(f64, f64)>,
    /// Gains.
    pub params: JointLimitParams,
}

impl JointRanges {
    /// How far angle `theta` (rad) of DOF `d` lies outside its range (rad, ≥ 0).
    #[inline]
    pub fn excursion(&self, d: usize, theta: f64) -> f64 {
        let (lo, hi) = self.ranges[d];
        (lo - theta).max(theta - hi).max(0.0)
    }

    /// The joint-model torque (N·m) and velocity coefficient on DOF `d`.
    #[inline]
    pub fn torque(&self, d: usize, theta: f64, theta_dot: f64) -> (f64, f64) {
        joint_torque(&self.params, self.ranges[d], theta, theta_dot)
    }
}

/// The joint torque `τ` (N·m) and its velocity coefficient `d = −∂τ/∂θ̇` (N·m·s/rad) for angle
/// `theta` and rate `theta_dot` with range `(lo, hi)` (rad).
#[inline]
pub fn joint_torque(
    p: &JointLimitParams,
    (lo, hi): (f64, f64),
    theta: f64,
    theta_dot: f64,
) -> (f64, f64) {
    if theta > hi {
        let d = p.limit_kv;
        (-p.limit_kp * (theta - hi) - d * theta_dot, d)
    } else if theta < lo {
        let d = p.limit_kv;
        (-p.limit_kp * (theta - lo) - d * theta_dot, d)
    } else {
        (-p.friction_kv * theta_dot, p.friction_kv)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn torque_restores_past_either_limit_and_only_damps_inside() {
        let p = JointLimitParams::default();
        let r = (-0.5, 1.0);
        assert_eq!(joint_torque(&p, r, 0.2, 0.0).0, 0.0);
        assert!(joint_torque(&p, r, 1.1, 0.0).0 < 0.0);
        assert!(joint_torque(&p, r, -0.6, 0.0).0 > 0.0);
        assert!((joint_torque(&p, r, 1.1, 0.0).0 + p.limit_kp * 0.1).abs() < 1e-12);
        assert!((joint_torque(&p, r, 0.0, 2.0).0 + 2.0 * p.friction_kv).abs() < 1e-12);
    }
}
