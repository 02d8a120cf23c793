//! The root assistance ("hand of god"): a PD on the pose of a body's free root with strength
//! `s ∈ [0, 1]` (1 = fully assisted, 0 = not at all), applied as a world-frame wrench at the
//! root origin:
//!
//! `F = s (F_ff + M (ω_a² (p_d − p) + 2ζ_a ω_a (ṗ_d − ṗ)))`,
//! `T = s (T_ff + I (ω_a² log(R_d Rᵀ) + 2ζ_a ω_a (ω_d − ω)))`,
//!
//! with `M` the body's mass, `I` a rotational inertia scale (e.g. the mean composite rotational
//! inertia about the root, [`super::gains::root_rotational_inertia`]) and `(F_ff, T_ff)` the
//! root's share of the desired motion's inverse dynamics ([`super::feedforward::root_share`]),
//! or zero.

use glam::{DQuat, DVec3};

use crate::dynamics::joint::quat_log;

/// A world-frame wrench about a body's origin: a force (N) and a torque (N·m).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Wrench {
    /// Force (N, world frame).
    pub force: DVec3,
    /// Torque (N·m, world frame).
    pub torque: DVec3,
}

impl Wrench {
    /// No force, no torque.
    pub const ZERO: Wrench = Wrench {
        force: DVec3::ZERO,
        torque: DVec3::ZERO,
    };
}

/// The gains of the root assistance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RootAssistGains {
    /// Strength `s` (1 fully assisted, 0 not at all; values in between partly).
    pub strength: f64,
    /// Natural frequency `ω_a` (rad/s).
    pub omega: f64,
    /// Damping ratio `ζ_a`.
    pub zeta: f64,
    /// Body mass `M` (kg).
    pub mass_kg: f64,
    /// Rotational inertia scale `I` (kg·m²).
    pub inertia_kg_m2: f64,
}

/// Where the assistance pulls the root: its desired pose and velocity, world frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RootTarget {
    /// Desired position `p_d` of the root origin (m).
    pub position: DVec3,
    /// Desired velocity `ṗ_d` of the root origin (m/s).
    pub velocity: DVec3,
    /// Desired orientation `R_d`.
    pub rotation: DQuat,
    /// Desired angular velocity `ω_d` (rad/s).
    pub angular_velocity: DVec3,
}

/// The assistance's wrench (see the module doc) on a body whose free root is at `q[0..7]`
/// (position, then the unit quaternion `x, y, z, w`) with velocity `v[0..6]` (angular, then
/// linear, root coordinates), pulled toward `target`, with the feedforward `feedforward`;
/// exactly zero at strength 0.
pub fn root_assist_wrench(
    gains: &RootAssistGains,
    feedforward: Wrench,
    q: &[f64],
    v: &[f64],
    target: &RootTarget,
) -> Wrench {
    if gains.strength == 0.0 {
        return Wrench::ZERO;
    }
    let p = DVec3::new(q[0], q[1], q[2]);
    let rot = DQuat::from_xyzw(q[3], q[4], q[5], q[6]);
    let w_world = rot * DVec3::new(v[0], v[1], v[2]);
    let v_world = rot * DVec3::new(v[3], v[4], v[5]);
    let (om, z, s) = (gains.omega, gains.zeta, gains.strength);
    let (kp, kd) = (om * om, 2.0 * z * om);
    let (m, i) = (gains.mass_kg, gains.inertia_kg_m2);
    let dp = kp * (target.position - p) + kd * (target.velocity - v_world);
    let force = s * (feedforward.force + m * dp);
    let e = quat_log(target.rotation * rot.inverse());
    let torque = s * (feedforward.torque + i * (kp * e + kd * (target.angular_velocity - w_world)));
    Wrench { force, torque }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GAINS: RootAssistGains = RootAssistGains {
        strength: 0.5,
        omega: 10.0,
        zeta: 1.0,
        mass_kg: 60.0,
        inertia_kg_m2: 2.0,
    };

    fn at_rest(position: DVec3) -> RootTarget {
        RootTarget {
            position,
            velocity: DVec3::ZERO,
            rotation: DQuat::IDENTITY,
            angular_velocity: DVec3::ZERO,
        }
    }

    #[test]
    fn a_root_below_its_target_is_pulled_up() {
        let q = [0.0, 0.9, 0.0, 0.0, 0.0, 0.0, 1.0];
        let w = root_assist_wrench(&GAINS, Wrench::ZERO, &q, &[0.0; 6], &at_rest(DVec3::Y));
        // s M ω² Δp = 0.5 · 60 · 100 · 0.1 = 300 N up.
        assert!((w.force - DVec3::new(0.0, 300.0, 0.0)).length() < 1e-9);
        assert_eq!(w.torque, DVec3::ZERO);
    }

    #[test]
    fn no_strength_no_wrench() {
        let gains = RootAssistGains {
            strength: 0.0,
            ..GAINS
        };
        let q = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
        let ff = Wrench {
            force: DVec3::Y,
            torque: DVec3::X,
        };
        let w = root_assist_wrench(&gains, ff, &q, &[1.0; 6], &at_rest(DVec3::Y));
        assert_eq!(w, Wrench::ZERO);
    }
}
