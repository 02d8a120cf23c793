//! Euler angles in any channel order (BVH rotation channels) to quaternions and back.

#[cfg(test)]
use glam::DVec3;
use glam::{DMat3, DQuat};

fn axis_quat(axis: usize, angle: f64) -> DQuat {
    match axis {
        0 => DQuat::from_rotation_x(angle),
        1 => DQuat::from_rotation_y(angle),
        _ => DQuat::from_rotation_z(angle),
    }
}

/// Rotation of BVH rotation channels: `R = R_{a₀}(θ₀)·R_{a₁}(θ₁)·R_{a₂}(θ₂)` in the order the
/// channels are listed (intrinsic rotations), angles in radians; `axes[k]` is 0 (X), 1 (Y), 2 (Z).
/// Any count of channels (0–3, repeated axes included) is composed in order.
#[inline]
pub fn euler_to_quat(axes: &[usize], angles: &[f64]) -> DQuat {
    let mut q = DQuat::IDENTITY;
    for (&a, &t) in axes.iter().zip(angles) {
        q *= axis_quat(a, t);
    }
    q
}

/// Angles (radians) for three distinct channel axes `axes` such that
/// `euler_to_quat(axes, angles) == q` (a Tait–Bryan decomposition in any of the six orders).
pub fn quat_to_euler(axes: [usize; 3], q: DQuat) -> [f64; 3] {
    let [i, j, k] = axes;
    // Parity of the permutation (i, j, k): +1 for XYZ-like cyclic orders, −1 otherwise.
    let sign = if (j + 3 - i) % 3 == 1 { 1.0 } else { -1.0 };
    let m = DMat3::from_quat(q);
    let e = |r: usize, c: usize| m.col(c)[r];
    // For R = R_i(a) R_j(b) R_k(c): e(i,k) = sign·sin b.
    let sb = (sign * e(i, k)).clamp(-1.0, 1.0);
    let b = sb.asin();
    let (a, c);
    if sb.abs() < 1.0 - 1e-12 {
        a = (-sign * e(j, k)).atan2(e(k, k));
        c = (-sign * e(i, j)).atan2(e(i, i));
    } else {
        // Gimbal lock: put the whole remaining rotation into the first angle.
        c = 0.0;
        a = (sign * e(k, j)).atan2(e(j, j));
    }
    [a, b, c]
}

#[cfg(test)]
mod tests {
    use super::*;

    const ORDERS: [[usize; 3]; 6] = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];

    #[test]
    fn every_order_round_trips() {
        let angles = [0.3, -0.7, 1.1];
        for order in ORDERS {
            let q = euler_to_quat(&order, &angles);
            let back = quat_to_euler(order, q);
            for k in 0..3 {
                assert!((back[k] - angles[k]).abs() < 1e-12, "{order:?}: {back:?}");
            }
        }
    }

    #[test]
    fn orders_differ() {
        // A wrong Euler order gives a different rotation: ZXY ≠ XYZ for the same angles.
        let a = euler_to_quat(&[2, 0, 1], &[0.5, 0.4, 0.3]);
        let b = euler_to_quat(&[0, 1, 2], &[0.3, 0.5, 0.4]);
        assert!(a.angle_between(b) > 0.05);
    }

    #[test]
    fn intrinsic_order_is_left_to_right() {
        // "Zrotation Xrotation": R = Rz·Rx, so a vector is rotated about x first.
        let q = euler_to_quat(
            &[2, 0],
            &[std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2],
        );
        let v = q * DVec3::Y; // Rx(90°)·y = z; Rz(90°)·z = z
        assert!((v - DVec3::Z).length() < 1e-12, "{v}");
    }
}
