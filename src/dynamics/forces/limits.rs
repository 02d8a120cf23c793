//! The joint model of the paper (eqs. 3.4, 3.5), per DOF: viscous friction `τ = −k_v θ̇` inside
//! the range `[θ_lo, θ_hi]`; past a limit the restoring torque `τ = −k_p(θ − θ_lim) − k_v θ̇`.
//!
//! The limit gains are either shared by every DOF (`limit_kp`, `limit_kv`) or tuned per DOF to
//! one natural frequency `f` and damping ratio `ζ` ([`JointLimitParams::limit_frequency_hz`]):
//! with `w = (H⁻¹)_jj` the DOF's inverse effective inertia, `k_p = (2πf)²/w` and
//! `k_v = 2ζ(2πf)/w`, so a hand and a trunk stop equally hard for their inertia (a shared spring
//! soft enough for the wrist lets the trunk sink tens of degrees past its range) and every limit
//! has the same stability margin.

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
    /// When set, the natural frequency (Hz) every DOF's limit spring is tuned to, replacing
    /// `limit_kp` and `limit_kv` ([`limit_gains`]).
    #[serde(default)]
    pub limit_frequency_hz: Option<f64>,
    /// Damping ratio of the tuned limits (1 = critical: no bounce off a limit).
    #[serde(default = "critical")]
    pub limit_damping_ratio: f64,
}

fn critical() -> f64 {
    1.0
}

/// The limit spring and damper `(k_p, k_v)` of a DOF whose inverse effective inertia is `w`
/// (1/(kg·m²)) tuned to frequency `hz` with damping ratio `zeta`: `k_p = (2π hz)²/w`,
/// `k_v = 2 zeta (2π hz)/w`.
pub fn limit_gains(hz: f64, zeta: f64, w: f64) -> (f64, f64) {
    let omega = 2.0 * std::f64::consts::PI * hz;
    (omega * omega / w, 2.0 * zeta * omega / w)
}

impl Default for JointLimitParams {
    fn default() -> Self {
        Self {
            friction_kv: 0.5,
            limit_kp: 300.0,
            limit_kv: 10.0,
            limit_frequency_hz: None,
            limit_damping_ratio: 1.0,
        }
    }
}

/// The joint model of a body: one range `(θ_lo, θ_hi)` per actuated DOF (rad), the shared
/// gains and, when tuned, the limit gains of each DOF.
#[derive(Clone, Debug, PartialEq)]
pub struct JointRanges {
    /// `(lo, hi)` per DOF (rad).
    pub ranges: Vec<(f64, f64)>,
    /// Gains.
    pub params: JointLimitParams,
    /// Limit `(k_p, k_v)` per DOF (N·m/rad, N·m·s/rad); empty = `params.limit_kp`,
    /// `params.limit_kv` for all.
    pub limit_gains: Vec<(f64, f64)>,
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
        let gains = self.limit(d);
        joint_torque_with(
            self.params.friction_kv,
            gains,
            self.ranges[d],
            theta,
            theta_dot,
        )
    }

    /// The limit spring and damper `(k_p, k_v)` of DOF `d`.
    #[inline]
    pub fn limit(&self, d: usize) -> (f64, f64) {
        self.limit_gains
            .get(d)
            .copied()
            .unwrap_or((self.params.limit_kp, self.params.limit_kv))
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
    joint_torque_with(
        p.friction_kv,
        (p.limit_kp, p.limit_kv),
        (lo, hi),
        theta,
        theta_dot,
    )
}

/// [`joint_torque`] with friction `friction_kv` and the limit spring and damper `(kp, kv)`.
#[inline]
pub fn joint_torque_with(
    friction_kv: f64,
    (kp, kv): (f64, f64),
    (lo, hi): (f64, f64),
    theta: f64,
    theta_dot: f64,
) -> (f64, f64) {
    if theta > hi {
        (-kp * (theta - hi) - kv * theta_dot, kv)
    } else if theta < lo {
        (-kp * (theta - lo) - kv * theta_dot, kv)
    } else {
        (-friction_kv * theta_dot, friction_kv)
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

    #[test]
    fn tuned_gains_give_the_frequency_and_damping_ratio() {
        // ẍ = −(k/I)x − (c/I)ẋ with I = 1/w: ω² = k w, 2ζω = c w.
        let (w, hz, zeta) = (40.0, 50.0, 0.7);
        let (k, c) = limit_gains(hz, zeta, w);
        let omega = 2.0 * std::f64::consts::PI * hz;
        assert!((k * w - omega * omega).abs() < 1e-6 * omega * omega);
        assert!((c * w / (2.0 * omega) - zeta).abs() < 1e-12);
        let j = JointRanges {
            ranges: vec![(0.0, 1.0), (0.0, 1.0)],
            params: JointLimitParams::default(),
            limit_gains: vec![(k, c), (2.0 * k, c)],
        };
        assert_eq!(j.torque(1, 1.1, 0.0).0, 2.0 * j.torque(0, 1.1, 0.0).0);
        assert!((j.torque(0, 1.1, 0.0).0 + 0.1 * k).abs() < 1e-9 * k);
    }
}
