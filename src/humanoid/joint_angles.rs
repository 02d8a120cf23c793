//! Joint rotations from DOF angles and back: the one place where a joint's kind decides how its
//! angles compose (see [`JointKind`]).

use std::f64::consts::{PI, TAU};

use glam::{DMat3, DQuat, DVec3};

use super::JointKind;

/// Local rotation of a joint of `kind` with DOF `axes` at `angles` (radians):
/// Pin `R(a,θ)`, Universal `R(a₁,θ₁)R(a₂,θ₂)`, Ball `exp(Σθₖaₖ)`, Free/Fixed identity.
pub fn local_rotation(kind: JointKind, axes: &[DVec3], angles: &[f64]) -> DQuat {
    match kind {
        JointKind::Free | JointKind::Fixed => DQuat::IDENTITY,
        JointKind::Pin => DQuat::from_axis_angle(axes[0], angles[0]),
        JointKind::Universal => {
            DQuat::from_axis_angle(axes[0], angles[0]) * DQuat::from_axis_angle(axes[1], angles[1])
        }
        JointKind::Ball => {
            let v = axes[0] * angles[0] + axes[1] * angles[1] + axes[2] * angles[2];
            DQuat::from_scaled_axis(v)
        }
    }
}

/// The angle `a + 2πk` closest to `reference` (angle unwrapping).
pub fn unwrap_near(a: f64, reference: f64) -> f64 {
    a - TAU * ((a - reference) / TAU).round()
}

/// The rotation vector of `q` (axis × angle, radians) nearest `previous`: of the
/// representatives `v + 2πk·v̂` of the same rotation, the one closest to the previous frame's,
/// so a rotation growing through π does not flip to the opposite side.
pub fn rotation_vector_near(q: DQuat, previous: Option<DVec3>) -> DVec3 {
    let q = if q.w < 0.0 { -q } else { q };
    let v = q.to_scaled_axis();
    let Some(prev) = previous else { return v };
    let angle = v.length();
    if angle > 1e-9 {
        let dir = v / angle;
        let k = ((prev.dot(dir) - angle) / TAU).round();
        let alt = dir * (angle + TAU * k);
        if (alt - prev).length() < (v - prev).length() {
            alt
        } else {
            v
        }
    } else if prev.length() > PI {
        prev.normalize() * TAU * (prev.length() / TAU).round()
    } else {
        v
    }
}

/// Best DOF angles (radians) for a joint of `kind` with DOF `axes` to reproduce the local
/// rotation `q`, written to `out`; `previous` (the same joint's angles one frame earlier) keeps
/// the result continuous over time (no ±2π jumps, no rotation-vector flips).
///
/// - Pin: the twist of `q` about the axis (swing–twist decomposition), `θ = 2·atan2(q⃗·a, q_w)`.
/// - Universal with the link's rest direction `bone` along a₂ (bend then twist, an elbow): θ₁
///   bends the link onto its current direction, θ₂ is the remaining twist about it.
/// - Universal with `bone` across both axes (waist, clavicle, a 2-DOF hip): the first two angles
///   of the Tait–Bryan decomposition `R = R(a₁,θ₁)R(a₂,θ₂)R(a₁×a₂,θ₃)`; θ₃, a twist about the
///   link the joint cannot make, is dropped, so the link's direction is matched exactly.
/// - Ball: the rotation vector `log(q)` along the three axes, taking of `v` and `v − 2π·v̂` the
///   one nearer `previous`.
pub fn project_rotation(
    kind: JointKind,
    axes: &[DVec3],
    bone: DVec3,
    q: DQuat,
    previous: Option<&[f64]>,
    out: &mut [f64],
) {
    match kind {
        JointKind::Free | JointKind::Fixed => {}
        JointKind::Pin => {
            let a = axes[0];
            let twist = 2.0 * q.xyz().dot(a).atan2(q.w);
            out[0] = match previous {
                Some(p) => unwrap_near(twist, p[0]),
                None => unwrap_near(twist, 0.0),
            };
        }
        JointKind::Universal => {
            let a1 = axes[0].normalize();
            let a2 = axes[1].normalize();
            let (p0, p1) = previous.map_or((0.0, 0.0), |p| (p[0], p[1]));
            let b0 = bone.normalize_or(DVec3::NEG_Y);
            if b0.dot(a2).abs() > 0.9 {
                // Bend, then twist about the link (an elbow): the bend is the angle about a₁ that
                // takes the link's rest direction to its current one, the twist what remains
                // about a₂. Exact for the link's direction at any twist.
                let d = q * b0;
                let d_perp = d - a1 * a1.dot(d);
                let b_perp = b0 - a1 * a1.dot(b0);
                let t1 = a1.dot(b_perp.cross(d_perp)).atan2(b_perp.dot(d_perp));
                let rest = DQuat::from_axis_angle(a1, t1).inverse() * q;
                let t2 = 2.0 * rest.xyz().dot(a2).atan2(rest.w);
                out[0] = unwrap_near(t1, p0);
                out[1] = unwrap_near(t2, p1);
                return;
            }
            let a3 = a1.cross(a2);
            let basis = DMat3::from_cols(a1, a2, a3);
            // R expressed in the joint's axis basis: R' = Bᵀ R B = Rx(θ1) Ry(θ2) Rz(θ3).
            let r = basis.transpose() * DMat3::from_quat(q) * basis;
            // Element (row i, column j) is r.col(j)[i].
            let t1 = (-r.z_axis.y).atan2(r.z_axis.z);
            let t2 = r.z_axis.x.clamp(-1.0, 1.0).asin();
            // Both decompositions (θ₁, θ₂) and (θ₁+π, π−θ₂) point a₃ the same way; take the one
            // nearer the previous frame so the angles stay continuous.
            let a = (unwrap_near(t1, p0), unwrap_near(t2, p1));
            let b = (unwrap_near(t1 + PI, p0), unwrap_near(PI - t2, p1));
            let dist = |x: (f64, f64)| (x.0 - p0).powi(2) + (x.1 - p1).powi(2);
            let best = if previous.is_some() && dist(b) < dist(a) {
                b
            } else {
                a
            };
            out[0] = best.0;
            out[1] = best.1;
        }
        JointKind::Ball => {
            let prev = previous.map(|p| axes[0] * p[0] + axes[1] * p[1] + axes[2] * p[2]);
            let v = rotation_vector_near(q, prev);
            for k in 0..3 {
                out[k] = v.dot(axes[k]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn roundtrip(kind: JointKind, axes: &[DVec3], angles: &[f64]) -> Vec<f64> {
        let q = local_rotation(kind, axes, angles);
        let mut out = vec![0.0; angles.len()];
        project_rotation(kind, axes, DVec3::NEG_Y, q, Some(angles), &mut out);
        out
    }

    #[test]
    fn pin_recovers_its_angle_and_unwraps() {
        let ax = [DVec3::X];
        for &a in &[0.0, 0.3, -1.2, 3.0, 4.0, -5.5] {
            let r = roundtrip(JointKind::Pin, &ax, &[a]);
            assert!((r[0] - a).abs() < 1e-12, "{a} -> {}", r[0]);
        }
    }

    #[test]
    fn universal_recovers_both_angles() {
        let axes = [DVec3::NEG_X, DVec3::NEG_Z];
        for &(a, b) in &[(0.2, -0.4), (1.3, 0.7), (-0.9, 1.2)] {
            let r = roundtrip(JointKind::Universal, &axes, &[a, b]);
            assert!(
                (r[0] - a).abs() < 1e-12 && (r[1] - b).abs() < 1e-12,
                "{a},{b} -> {r:?}"
            );
        }
    }

    #[test]
    fn universal_matches_bone_direction_when_a_third_rotation_is_added() {
        // Waist: flexion X, lateral Z, bone up; an added twist about the bone must not change
        // the recovered angles.
        let axes = [DVec3::X, DVec3::Z];
        let q =
            local_rotation(JointKind::Universal, &axes, &[0.4, -0.3]) * DQuat::from_rotation_y(0.8);
        let mut out = [0.0; 2];
        project_rotation(JointKind::Universal, &axes, DVec3::Y, q, None, &mut out);
        assert!(
            (out[0] - 0.4).abs() < 1e-12 && (out[1] + 0.3).abs() < 1e-12,
            "{out:?}"
        );
    }

    #[test]
    fn universal_with_a_large_second_angle_keeps_the_link_pointing_the_same_way() {
        // Elbow: flexion then pronation about the forearm; pronation past 90° must not be read
        // as the other branch with a 180° third rotation (which would flip the forearm).
        let axes = [DVec3::NEG_X, DVec3::Y];
        let q =
            local_rotation(JointKind::Universal, &axes, &[0.8, 2.4]) * DQuat::from_rotation_z(0.1);
        let bone = DVec3::NEG_Y;
        let mut out = [0.0; 2];
        project_rotation(JointKind::Universal, &axes, DVec3::NEG_Y, q, None, &mut out);
        let forearm = local_rotation(JointKind::Universal, &axes, &out) * DVec3::NEG_Y;
        assert!(forearm.angle_between(q * bone) < 0.101, "{out:?}");
    }

    #[test]
    fn ball_recovers_rotation_vector_and_stays_continuous_past_pi() {
        let axes = [DVec3::NEG_X, DVec3::NEG_Z, DVec3::NEG_Y];
        let r = roundtrip(JointKind::Ball, &axes, &[0.3, -0.2, 0.5]);
        assert!(
            (r[0] - 0.3).abs() < 1e-12 && (r[1] + 0.2).abs() < 1e-12 && (r[2] - 0.5).abs() < 1e-12
        );
        // A rotation growing through π about one axis: the representation must not flip.
        let mut prev = [0.0; 3];
        for i in 0..=80 {
            let a = i as f64 * 0.05; // up to 4 rad
            let q = local_rotation(JointKind::Ball, &axes, &[a, 0.0, 0.0]);
            let mut out = [0.0; 3];
            project_rotation(
                JointKind::Ball,
                &axes,
                DVec3::NEG_Y,
                q,
                Some(&prev),
                &mut out,
            );
            assert!((out[0] - a).abs() < 1e-9, "step {i}: {a} -> {out:?}");
            prev = out;
        }
    }
}
