//! PD control toward a key pose (the paper's eq. 4.1): `τ = k_p(θ_d − θ) + k_v(θ̇_d − θ̇)` per DOF.

/// Per-DOF PD settings: targets θ_d (rad), target velocities θ̇_d (rad/s), gains k_p
/// (N·m/rad) and k_v (N·m·s/rad), one entry per actuated DOF.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct PdTargets {
    /// Target angle θ_d per DOF (rad).
    pub target: Vec<f64>,
    /// Target velocity θ̇_d per DOF (rad/s).
    pub target_velocity: Vec<f64>,
    /// Proportional gain k_p per DOF (N·m/rad).
    pub kp: Vec<f64>,
    /// Derivative gain k_v per DOF (N·m·s/rad).
    pub kv: Vec<f64>,
}

impl PdTargets {
    /// Targets `target` held still (θ̇_d = 0) with gains `kp`, `kv`.
    pub fn hold(target: Vec<f64>, kp: Vec<f64>, kv: Vec<f64>) -> Self {
        let n = target.len();
        Self {
            target,
            target_velocity: vec![0.0; n],
            kp,
            kv,
        }
    }

    /// The torque (N·m) and velocity coefficient on DOF `d` at angle `theta`, rate `theta_dot`.
    #[inline]
    pub fn torque(&self, d: usize, theta: f64, theta_dot: f64) -> (f64, f64) {
        pd_torque(
            self.kp[d],
            self.kv[d],
            self.target[d],
            self.target_velocity[d],
            theta,
            theta_dot,
        )
    }
}

/// The PD torque (N·m) and its velocity coefficient `k_v` for one DOF.
#[inline]
pub fn pd_torque(
    kp: f64,
    kv: f64,
    theta_d: f64,
    theta_dot_d: f64,
    theta: f64,
    theta_dot: f64,
) -> (f64, f64) {
    (kp * (theta_d - theta) + kv * (theta_dot_d - theta_dot), kv)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pd_pulls_toward_the_target_and_damps() {
        assert!((pd_torque(100.0, 10.0, 0.5, 0.0, 0.3, 0.0).0 - 20.0).abs() < 1e-12);
        assert!((pd_torque(100.0, 10.0, 0.0, 0.0, 0.0, 1.0).0 + 10.0).abs() < 1e-12);
    }
}
