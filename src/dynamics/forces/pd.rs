//! PD control toward a key pose (the paper's eq. 4.1): `τ = k_p(θ_d − θ) + k_v(θ̇_d − θ̇)` per DOF.

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
