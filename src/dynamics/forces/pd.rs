//! PD control toward a key pose (the paper's eq. 4.1): `τ = k_p(θ_d − θ) + k_v(θ̇_d − θ̇)` per DOF,
//! plus an optional feedforward torque `τ_ff` (computed-torque control: the inverse dynamics of
//! the desired motion), saturated at the DOF's strength: `τ ← clamp(τ, τ_min, τ_max)` (a muscle cannot give more than
//! its maximal voluntary torque; see [`crate::humanoid::strength`]). A saturated torque no
//! longer depends on θ̇, so its velocity coefficient is 0.

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
    /// Strength per DOF: the torque range `(τ_min, τ_max)` (N·m, `τ_min ≤ 0 ≤ τ_max`) the PD
    /// torque is clamped to; empty = unbounded.
    pub torque_limits: Vec<(f64, f64)>,
    /// Feedforward torque `τ_ff` per DOF (N·m) added before the clamp; empty = none.
    pub feedforward: Vec<f64>,
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
            torque_limits: Vec::new(),
            feedforward: Vec::new(),
        }
    }

    /// The same targets with the PD torque of each DOF clamped to `limits` (N·m).
    pub fn with_torque_limits(mut self, limits: Vec<(f64, f64)>) -> Self {
        self.torque_limits = limits;
        self
    }

    /// True if the PD torque `tau` (N·m) of DOF `d` lies at or past its strength limit.
    #[inline]
    pub fn saturates(&self, d: usize, tau: f64) -> bool {
        self.torque_limits
            .get(d)
            .is_some_and(|&(lo, hi)| tau <= lo || tau >= hi)
    }

    /// The torque (N·m) and velocity coefficient on DOF `d` at angle `theta`, rate `theta_dot`.
    #[inline(always)]
    pub fn torque(&self, d: usize, theta: f64, theta_dot: f64) -> (f64, f64) {
        let (mut tau, kv) = pd_torque(
            self.kp[d],
            self.kv[d],
            self.target[d],
            self.target_velocity[d],
            theta,
            theta_dot,
        );
        if let Some(ff) = self.feedforward.get(d) {
            tau += ff;
        }
        match self.torque_limits.get(d) {
            Some(&(_, hi)) if tau > hi => (hi, 0.0),
            Some(&(lo, _)) if tau < lo => (lo, 0.0),
            _ => (tau, kv),
        }
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

    #[test]
    fn strength_clamps_the_torque_and_drops_its_velocity_term() {
        let pd = PdTargets::hold(vec![1.0], vec![100.0], vec![10.0])
            .with_torque_limits(vec![(-30.0, 50.0)]);
        assert_eq!(pd.torque(0, 0.0, 0.0), (50.0, 0.0));
        assert_eq!(pd.torque(0, 2.0, 0.0), (-30.0, 0.0));
        let (tau, kv) = pd.torque(0, 0.9, 0.0);
        assert!((tau - 10.0).abs() < 1e-9 && kv == 10.0);
        assert!(pd.saturates(0, 50.0) && !pd.saturates(0, 10.0));
    }
}
