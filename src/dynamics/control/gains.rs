//! PD gains of equal bandwidth: every DOF `k` tracks like a mass–spring–damper of natural
//! frequency `ω` and damping ratio `ζ` whose mass is its joint-space inertia `H_kk` (the CRBA
//! diagonal at a pose): `k_p = ω² H_kk`, `k_v = 2ζω H_kk`.

/// The gains `(k_p, k_v)` of the DOFs whose velocity indices are `dofs`, from the joint-space
/// inertia `h` (row-major `nv × nv`, kg·m² for a hinge) with bandwidth `omega` (rad/s) and
/// damping ratio `zeta`: `k_p = ω² H_kk` (N·m/rad), `k_v = 2ζω H_kk` (N·m·s/rad).
pub fn inertia_scaled_gains(
    h: &[f64],
    nv: usize,
    dofs: &[usize],
    omega: f64,
    zeta: f64,
) -> (Vec<f64>, Vec<f64>) {
    let hkk: Vec<f64> = dofs.iter().map(|&k| h[k * nv + k]).collect();
    let (w, z) = (omega, zeta);
    let kp = hkk.iter().map(|i| w * w * i).collect();
    let kv = hkk.iter().map(|i| 2.0 * z * w * i).collect();
    (kp, kv)
}

/// The rotational inertia scale of a free root (kg·m²): the mean of the first three diagonal
/// entries of the joint-space inertia `h` (row-major `nv × nv`), the composite rotational
/// inertia of the whole body about the root's axes, `(H_00 + H_11 + H_22) / 3`.
pub fn root_rotational_inertia(h: &[f64], nv: usize) -> f64 {
    (h[0] + h[nv + 1] + h[2 * nv + 2]) / 3.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gains_scale_with_the_diagonal() {
        // H = diag(1, 2, 3, 4) (nv = 4); DOFs 3 and 1.
        let mut h = vec![0.0; 16];
        for k in 0..4 {
            h[k * 4 + k] = (k + 1) as f64;
        }
        let (kp, kv) = inertia_scaled_gains(&h, 4, &[3, 1], 10.0, 0.5);
        assert_eq!(kp, vec![400.0, 200.0]);
        assert_eq!(kv, vec![40.0, 20.0]);
        assert_eq!(root_rotational_inertia(&h, 4), 2.0);
    }
}
