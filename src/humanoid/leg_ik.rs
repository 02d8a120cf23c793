//! Two-bone inverse kinematics of a leg: the hip and knee angles that put the ankle at a target
//! point, the pelvis held where it is.
//!
//! With the hip H, the knee's offset k in the thigh frame, the ankle's offset e in the shin
//! frame and the knee's pin axis u, the hip–ankle distance at knee angle θ is
//!
//! ```text
//! |p(θ)|² = |k|² + |e|² + 2 k·R(u, θ) e = C + A cos θ + B sin θ
//! C = |k|² + |e|² + 2 k·(u u·e),   A = 2 k·(e − u u·e),   B = 2 k·(u × e)
//! ```
//!
//! so the knee angle that gives the distance d = |T − H| to the target T is
//! θ = φ ± acos((d² − C) / R), R = √(A² + B²), φ = atan2(B, A), the one of the two nearer the
//! current angle (the knee keeps bending the way it bends). The thigh is then swung by the
//! shortest rotation that takes the hip→ankle direction onto H→T, so the plane of the knee turns
//! as little as it can, and the new hip rotation is projected onto the hip's DOFs
//! ([`project_rotation`]). A target out of reach (d outside the range of |p(θ)|) is met as
//! nearly as the leg allows: the knee at its straightest or most bent, the leg pointing at it;
//! near full reach the distance is softened ([`soft_distance`]) so the knee never snaps.

use glam::{DQuat, DVec3};

use super::{Figure, JointKind, project_rotation};
use crate::skeleton::Transform;
#[cfg(doc)]
use crate::skeleton::forward_kinematics;

/// A leg of a model: its hip (3 or 2 DOFs), knee (1 DOF, a pin) and ankle joints.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Leg {
    /// The hip joint.
    pub hip: usize,
    /// The knee joint (a pin).
    pub knee: usize,
    /// The ankle joint.
    pub ankle: usize,
}

impl Leg {
    /// The leg of a side (`"left"` or `"right"`): joints `{side}_hip`, `{side}_knee` (a pin,
    /// child of the hip) and `{side}_ankle` (child of the knee); `None` when the model has no
    /// such chain or the hip carries no DOF.
    pub fn of(model: &Figure, side: &str) -> Option<Leg> {
        let hip = model.joint_index(&format!("{side}_hip"))?;
        let knee = model.joint_index(&format!("{side}_knee"))?;
        let ankle = model.joint_index(&format!("{side}_ankle"))?;
        let ok = model.joints[knee].parent == Some(hip)
            && model.joints[ankle].parent == Some(knee)
            && model.joints[knee].kind == JointKind::Pin
            && matches!(
                model.joints[hip].kind,
                JointKind::Ball | JointKind::Universal
            )
            && model.joints[hip].parent.is_some();
        ok.then_some(Leg { hip, knee, ankle })
    }
}

/// Fraction of the leg's full reach from which the reach is softened ([`soft_distance`]).
pub const SOFT_REACH: f64 = 0.97;

/// The hip–ankle distance the knee is set for when the target is `d` from the hip and the leg
/// reaches `full` at most ("soft IK"): d itself up to s = [`SOFT_REACH`]·full, beyond it
/// s + (full − s)(1 − exp(−(d − s)/(full − s))), which rises smoothly to the full reach and
/// never quite gets there. Near a straight knee dθ/dd grows without bound (θ is an arccosine of
/// d²), so a target a millimetre further would snap the knee; softened, the knee straightens
/// smoothly and the ankle stops short of the target by at most (1 − s)·full/e there.
pub fn soft_distance(d: f64, full: f64) -> f64 {
    let s = SOFT_REACH * full;
    if d <= s || full <= s {
        d
    } else {
        s + (full - s) * (1.0 - (-(d - s) / (full - s)).exp())
    }
}

/// Global transforms of every joint of `model` at one frame: the root at `root_t`, `root_q`,
/// the DOF `angles` (radians, model order); written to `out`.
pub fn frame_globals(
    model: &Figure,
    root_t: DVec3,
    root_q: DQuat,
    angles: &[f64],
    out: &mut Vec<Transform>,
) {
    let n = model.joints.len();
    let mut rot = vec![DQuat::IDENTITY; n];
    model.local_rotations(angles, &mut rot);
    out.resize(n, Transform::IDENTITY);
    for (j, joint) in model.joints.iter().enumerate() {
        // Parents come first, so out[p] is final here (as in [`forward_kinematics`]).
        out[j] = match joint.parent {
            Some(p) => out[p].compose(rot[j], joint.offset),
            None => Transform {
                rotation: root_q,
                translation: root_t,
            },
        };
    }
}

/// `joints` with every ancestor of each, in model order (parents before children): the joints
/// whose global transforms [`chain_globals`] needs to place `joints`.
pub fn with_ancestors(model: &Figure, joints: &[usize]) -> Vec<usize> {
    let mut inside = vec![false; model.joints.len()];
    for &j in joints {
        let mut at = Some(j);
        while let Some(i) = at.filter(|&i| !inside[i]) {
            inside[i] = true;
            at = model.joints[i].parent;
        }
    }
    (0..inside.len()).filter(|&i| inside[i]).collect()
}

/// [`frame_globals`] of the joints `chain` only (closed under parents and in model order, as
/// [`with_ancestors`] gives): the same transforms, bit for bit, at the cost of the chain; the
/// other entries of `out` are left as they were.
pub fn chain_globals(
    model: &Figure,
    chain: &[usize],
    root_t: DVec3,
    root_q: DQuat,
    angles: &[f64],
    out: &mut Vec<Transform>,
) {
    out.resize(model.joints.len(), Transform::IDENTITY);
    for &j in chain {
        let joint = &model.joints[j];
        out[j] = match joint.parent {
            Some(p) => out[p].compose(model.local_rotation_of(j, angles), joint.offset),
            None => Transform {
                rotation: root_q,
                translation: root_t,
            },
        };
    }
}

/// Moves the ankle of `leg` towards the global point `target` (module docs): rewrites the hip's
/// and knee's DOF angles in `angles` (one frame, radians, model order), the root at `root_t`,
/// `root_q`. Returns the distance left between the ankle and the target, metres (0 up to
/// rounding when the target is within reach and the hip has 3 DOFs).
pub fn reach(
    model: &Figure,
    leg: Leg,
    root_t: DVec3,
    root_q: DQuat,
    angles: &mut [f64],
    target: DVec3,
) -> f64 {
    let chain = with_ancestors(model, &[leg.ankle]);
    let mut g = Vec::new();
    chain_globals(model, &chain, root_t, root_q, angles, &mut g);
    reach_along(model, leg, &chain, &mut g, (root_t, root_q), angles, target)
}

/// [`reach`] over the joints `chain` (the ankle's and its ancestors at least, in model order
/// as [`with_ancestors`] gives), whose global transforms for `angles` the scratch `g` holds
/// already ([`chain_globals`]), and leaves holding for the new angles: the same angles, bit for
/// bit, without an allocation or a second placing per call, for legs moved round after round.
pub fn reach_along(
    model: &Figure,
    leg: Leg,
    chain: &[usize],
    g: &mut Vec<Transform>,
    (root_t, root_q): (DVec3, DQuat),
    angles: &mut [f64],
    target: DVec3,
) -> f64 {
    let hip_pos = g[leg.hip].translation;
    let k = model.joints[leg.knee].offset;
    let e = model.joints[leg.ankle].offset;
    let knee_dof = model.joints[leg.knee].dofs[0];
    let u = model.dofs[knee_dof].axis.normalize();

    // Knee: the angle giving the distance to the target.
    let e_par = u * u.dot(e);
    let c = k.length_squared() + e.length_squared() + 2.0 * k.dot(e_par);
    let a = 2.0 * k.dot(e - e_par);
    let b = 2.0 * k.dot(u.cross(e));
    let r = a.hypot(b);
    let theta0 = angles[knee_dof];
    if r > 1e-12 {
        let d2 = soft_distance((target - hip_pos).length(), (c + r).sqrt()).powi(2);
        let phi = b.atan2(a);
        let x = ((d2 - c) / r).clamp(-1.0, 1.0).acos();
        // The two solutions φ ± x, each brought next to the current angle.
        let near = |t: f64| super::unwrap_near(t, theta0);
        let (t1, t2) = (near(phi + x), near(phi - x));
        angles[knee_dof] = if (t1 - theta0).abs() <= (t2 - theta0).abs() {
            t1
        } else {
            t2
        };
    }

    // Hip: swing the thigh so that the hip→ankle direction points at the target.
    let hip = &model.joints[leg.hip];
    let thigh = g[leg.hip].rotation;
    let shin = DQuat::from_axis_angle(u, angles[knee_dof]);
    let ankle_rel = thigh * (k + shin * e);
    let to_target = target - hip_pos;
    if let (Some(from), Some(to)) = (ankle_rel.try_normalize(), to_target.try_normalize()) {
        let swing = DQuat::from_rotation_arc(from, to);
        let parent = g[hip.parent.expect("Leg::of checks the hip has a parent")].rotation;
        let local = parent.inverse() * (swing * thigh);
        let axes = model.joint_axes(leg.hip);
        let first = hip.dofs[0];
        let m = hip.dofs.len();
        let previous: Vec<f64> = angles[first..first + m].to_vec();
        let bone = model.link_direction(leg.hip);
        project_rotation(
            hip.kind,
            &axes,
            bone,
            local.normalize(),
            Some(&previous),
            &mut angles[first..first + m],
        );
    }
    chain_globals(model, chain, root_t, root_q, angles, g);
    (g[leg.ankle].translation - target).length()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::humanoid::humanoid24;

    /// A frame of humanoid24 with every DOF at a pseudo-random angle of up to ±`amp` rad.
    fn pose(model: &Figure, seed: u64, amp: f64) -> Vec<f64> {
        let mut x = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (0..model.dofs.len())
            .map(|_| {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                amp * (((x >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0)
            })
            .collect()
    }

    #[test]
    fn the_ankle_reaches_any_target_within_the_leg_s_range() {
        let model = humanoid24();
        let root_q = DQuat::from_rotation_y(0.4) * DQuat::from_rotation_x(0.1);
        let root_t = DVec3::new(0.2, 0.9, -0.3);
        let mut g = vec![];
        for side in ["left", "right"] {
            let leg = Leg::of(&model, side).unwrap();
            for seed in 0..40 {
                let mut angles = pose(&model, seed, 0.6);
                frame_globals(&model, root_t, root_q, &angles, &mut g);
                let hip = g[leg.hip].translation;
                // A target 5–15 cm from where the ankle is, inside the leg's unsoftened reach.
                let ankle = g[leg.ankle].translation;
                let shift = DVec3::new(0.05, -0.1, 0.08) * (1.0 + (seed % 3) as f64 * 0.3);
                let mut target = ankle + if seed % 2 == 0 { shift } else { -shift };
                let reach_max = 0.95
                    * (model.joints[leg.knee].offset.length()
                        + model.joints[leg.ankle].offset.length());
                if (target - hip).length() > reach_max {
                    target = hip + (target - hip).normalize() * reach_max;
                }
                let before = angles.clone();
                let left = reach(&model, leg, root_t, root_q, &mut angles, target);
                assert!(left < 1e-9, "{side} seed {seed}: {left} m short");
                // Only this leg's hip and knee moved.
                let j = &model.joints;
                let moved: Vec<usize> = j[leg.hip]
                    .dofs
                    .iter()
                    .chain(&j[leg.knee].dofs)
                    .copied()
                    .collect();
                for (d, (a, b)) in before.iter().zip(&angles).enumerate() {
                    if !moved.contains(&d) {
                        assert_eq!(a, b, "DOF {d} moved");
                    }
                }
            }
        }
    }

    #[test]
    fn a_target_out_of_reach_straightens_the_leg_towards_it() {
        let model = humanoid24();
        let leg = Leg::of(&model, "left").unwrap();
        let mut angles = vec![0.0; model.dofs.len()];
        let knee = model.joints[leg.knee].dofs[0];
        angles[knee] = 0.8;
        let (t, q) = (DVec3::new(0.0, 0.9, 0.0), DQuat::IDENTITY);
        let mut g = vec![];
        frame_globals(&model, t, q, &angles, &mut g);
        let hip = g[leg.hip].translation;
        let target = hip + DVec3::new(0.0, -2.0, 0.3);
        let left = reach(&model, leg, t, q, &mut angles, target);
        assert!(angles[knee].abs() < 1e-6, "knee at {}", angles[knee]);
        let full = model.joints[leg.knee].offset.length() + model.joints[leg.ankle].offset.length();
        assert!((left - ((target - hip).length() - full)).abs() < 1e-9);
    }
}
