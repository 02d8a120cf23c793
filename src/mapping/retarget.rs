//! Retargeting a clip onto a model by landmarks: segment frames from landmark positions, then
//! each joint's DOFs from its parent's achieved frame, root to leaves.
//!
//! For every model link a target orientation is built from the source's landmark positions: a
//! *primary* direction matched exactly (the bone to its child, or the hip line for the pelvis)
//! and a *hint* direction matched as well as the primary allows (the shin's bend for the thigh,
//! the forearm's bend for the upper arm, the shoulder line for the chest, …). Joints are then
//! visited parents first: the local target `L = G_parent⁻¹·T` is projected onto the joint's DOFs
//! ([`project_rotation`]) and the achieved frame `G = G_parent·R(θ)` is passed on, so what a
//! joint cannot do (e.g. waist twist) is taken up by the 3-DOF joints below it rather than
//! accumulating. Bone lengths and structural offsets (pelvis→hip, chest→shoulder) are the
//! median of the source's landmark geometry over the clip, so nothing depends on the source's
//! rest pose or joint-frame conventions.

use glam::{DMat3, DQuat, DVec3};

use super::{Landmark, Mapping, MappingError};
use crate::humanoid::FigureClip;
use crate::humanoid::{Figure, JointKind, local_rotation, project_rotation};
use crate::skeleton::Clip;

/// Which landmark an End Site of a model joint stands for.
fn end_landmark(joint: &str) -> Option<String> {
    let (side, role) = split_side(joint);
    match role {
        "neck" => Some("head".into()),
        "wrist" => Some(format!("{side}hand")),
        "ankle" => Some(format!("{side}toe")),
        _ => None,
    }
}

fn split_side(name: &str) -> (&str, &str) {
    for p in ["left_", "right_"] {
        if let Some(r) = name.strip_prefix(p) {
            return (p, r);
        }
    }
    ("", name)
}

/// Landmark positions of one frame, by landmark name.
struct Points<'a> {
    names: &'a [String],
    pos: &'a [DVec3],
}

impl Points<'_> {
    fn get(&self, name: &str) -> DVec3 {
        let i = self
            .names
            .iter()
            .position(|n| n == name)
            .expect("landmark resolved");
        self.pos[i]
    }
}

/// Orthonormal basis (a, b⊥a, a×b⊥) as matrix columns; `None` if a or b⊥ is degenerate.
fn basis(a: DVec3, b: DVec3) -> Option<DMat3> {
    let a = a.try_normalize()?;
    let b = (b - a * a.dot(b)).try_normalize()?;
    Some(DMat3::from_cols(a, b, a.cross(b)))
}

/// Rotation taking `rest_primary` onto `primary` exactly and `rest_hint` as near `hint` as that
/// allows; falls back to `fallback_hint` when `hint` is parallel to `primary`, and to `None` when
/// `primary` is degenerate.
fn frame_from(
    primary: DVec3,
    hint: DVec3,
    fallback_hint: DVec3,
    rest_primary: DVec3,
    rest_hint: DVec3,
) -> Option<DQuat> {
    let rest = basis(rest_primary, rest_hint)?;
    let now = basis(primary, hint).or_else(|| basis(primary, fallback_hint))?;
    Some(DQuat::from_mat3(&(now * rest.transpose())).normalize())
}

/// Perpendicular part of `v` to unit `axis`, normalised (zero if degenerate).
fn perp(v: DVec3, axis: DVec3) -> DVec3 {
    (v - axis * axis.dot(v)).normalize_or_zero()
}

/// Target global orientation of model joint `j`'s link at one frame, or `None` when the source
/// gives no direction for it (then the link keeps its parent's orientation).
fn target_frame(
    model: &Figure,
    j: usize,
    p: &Points,
    targets: &[Option<DQuat>],
    rest_dirs: &[DVec3],
) -> Option<DQuat> {
    let joint = &model.joints[j];
    let (side, role) = split_side(&joint.name);
    let link = Link {
        p,
        side,
        parent: joint
            .parent
            .and_then(|q| targets[q])
            .unwrap_or(DQuat::IDENTITY),
        rest_dir: rest_dirs[j],
    };
    match role {
        "pelvis" | "waist" | "neck" => torso_frame(role, &link),
        "clavicle" | "shoulder" | "elbow" | "wrist" => arm_frame(role, &link, model, targets),
        "hip" | "knee" | "ankle" => leg_frame(role, &link),
        _ => None,
    }
}

/// What a link's target frame is built from: the frame's landmarks, the link's side, its
/// parent's target frame and its rest direction.
struct Link<'a> {
    p: &'a Points<'a>,
    /// "left_", "right_" or "".
    side: &'a str,
    parent: DQuat,
    rest_dir: DVec3,
}

impl Link<'_> {
    /// The landmark `name` on the link's side.
    fn l(&self, name: &str) -> DVec3 {
        self.p.get(&format!("{}{name}", self.side))
    }
}

/// The target frame of the pelvis (the hip line, the waist above), the waist (up to the neck,
/// the shoulder line) or the neck (up to the head).
fn torso_frame(role: &str, link: &Link) -> Option<DQuat> {
    let (p, parent_frame) = (link.p, link.parent);
    match role {
        "pelvis" => frame_from(
            p.get("left_hip") - p.get("right_hip"),
            p.get("waist") - p.get("pelvis"),
            DVec3::Y,
            DVec3::X,
            DVec3::Y,
        ),
        "waist" => frame_from(
            p.get("neck") - p.get("waist"),
            p.get("left_shoulder") - p.get("right_shoulder"),
            parent_frame * DVec3::X,
            DVec3::Y,
            DVec3::X,
        ),
        _ => frame_from(
            p.get("head") - link.l("neck"),
            parent_frame * DVec3::X,
            parent_frame * DVec3::Z,
            DVec3::Y,
            DVec3::X,
        ),
    }
}

/// The target frame of an arm's clavicle, upper arm (shoulder), forearm (elbow) or hand
/// (wrist).
fn arm_frame(role: &str, link: &Link, model: &Figure, targets: &[Option<DQuat>]) -> Option<DQuat> {
    let l = |name: &str| link.l(name);
    let parent_frame = link.parent;
    match role {
        "clavicle" => frame_from(
            l("shoulder") - l("clavicle"),
            parent_frame * DVec3::Z,
            parent_frame * DVec3::Y,
            link.rest_dir,
            DVec3::Z,
        ),
        "shoulder" => {
            let upper = l("elbow") - l("shoulder");
            let u = upper.normalize_or_zero();
            // The forearm's bend says where the upper arm's front is; when the elbow is straight
            // the chest's front decides.
            let chest = targets[model.joint_index("waist")?].unwrap_or(DQuat::IDENTITY);
            let hint = perp(l("wrist") - l("elbow"), u) + 0.2 * perp(chest * DVec3::Z, u);
            frame_from(upper, hint, chest * DVec3::Y, DVec3::NEG_Y, DVec3::Z)
        }
        // A hinge's hint is its own axis in the parent (lateral): valid at any bend, even past 90°.
        "elbow" => frame_from(
            l("wrist") - l("elbow"),
            parent_frame * DVec3::X,
            parent_frame * DVec3::Z,
            DVec3::NEG_Y,
            DVec3::X,
        ),
        _ => frame_from(
            l("hand") - l("wrist"),
            parent_frame * DVec3::Z,
            parent_frame * DVec3::X,
            link.rest_dir,
            DVec3::Z,
        ),
    }
}

/// The target frame of a leg's thigh (hip), shin (knee) or foot (ankle).
fn leg_frame(role: &str, link: &Link) -> Option<DQuat> {
    let l = |name: &str| link.l(name);
    let parent_frame = link.parent;
    match role {
        "hip" => {
            let thigh = l("knee") - l("hip");
            let t = thigh.normalize_or_zero();
            // Knee flexion moves the shin backward; with a straight knee the foot points forward.
            let hint = -perp(l("ankle") - l("knee"), t) + 0.1 * perp(l("toe") - l("ankle"), t);
            frame_from(thigh, hint, parent_frame * DVec3::Z, DVec3::NEG_Y, DVec3::Z)
        }
        "knee" => frame_from(
            l("ankle") - l("knee"),
            parent_frame * DVec3::X,
            parent_frame * DVec3::Z,
            DVec3::NEG_Y,
            DVec3::X,
        ),
        _ => frame_from(
            l("toe") - l("ankle"),
            parent_frame * DVec3::X,
            parent_frame * DVec3::Y,
            link.rest_dir,
            DVec3::X,
        ),
    }
}

/// Maps `clip` onto `model` through `mapping`: DOF angle trajectories (radians, unwrapped over
/// time), root translation (the pelvis landmark, metres) and root orientation, on a copy of the
/// model whose offsets are the source's (median landmark geometry).
pub fn retarget(
    clip: &Clip,
    mapping: &Mapping,
    model: &Figure,
) -> Result<FigureClip, MappingError> {
    let names = needed_landmarks(model);
    let resolved: Vec<Landmark> = names
        .iter()
        .map(|n| mapping.resolve(&clip.skeleton, n))
        .collect::<Result<_, _>>()?;
    let lm = LandmarkTracks {
        positions: landmark_positions(clip, &resolved),
        names,
        frames: clip.frame_count(),
    };

    // Rest directions of the links (the clavicle's, hand's and foot's are not straight down).
    let n = model.joints.len();
    let rest_dirs: Vec<DVec3> = (0..n).map(|j| model.link_direction(j)).collect();

    // Target frames per frame and link.
    let (frames, k) = (lm.frames, lm.names.len());
    let mut targets = vec![None; frames * n];
    let mut row = vec![None; n];
    for f in 0..frames {
        let p = Points {
            names: &lm.names,
            pos: &lm.positions[f * k..(f + 1) * k],
        };
        for j in 0..n {
            let t = target_frame(model, j, &p, &row, &rest_dirs);
            row[j] = t;
        }
        targets[f * n..(f + 1) * n].copy_from_slice(&row);
    }

    let mapped_figure = mapped_figure(model, &lm, &targets);
    let pelvis_lm = lm.index(&model.joints[0].name);
    let (angles, root_rotation) = dof_angles(model, &targets, &rest_dirs, frames);
    let root_translation = (0..frames)
        .map(|f| lm.positions[f * k + pelvis_lm])
        .collect();
    Ok(FigureClip {
        model: mapped_figure,
        frame_time: clip.frame_time,
        root_translation,
        root_rotation,
        angles,
    })
}

/// The landmarks `model` needs: one per joint, plus those of End Sites, plus the hints'.
fn needed_landmarks(model: &Figure) -> Vec<String> {
    let mut names: Vec<String> = vec![];
    let mut need = |n: String| {
        if !names.contains(&n) {
            names.push(n);
        }
    };
    for j in &model.joints {
        need(j.name.clone());
        if let Some(e) = end_landmark(&j.name) {
            need(e);
        }
    }
    for n in [
        "left_hip",
        "right_hip",
        "waist",
        "neck",
        "head",
        "left_shoulder",
        "right_shoulder",
    ] {
        need(n.into());
    }
    for side in ["left_", "right_"] {
        for n in ["elbow", "wrist", "hand", "knee", "ankle", "toe"] {
            need(format!("{side}{n}"));
        }
    }
    names
}

/// The positions of the `resolved` landmarks in every frame of `clip`, frame by frame.
fn landmark_positions(clip: &Clip, resolved: &[Landmark]) -> Vec<DVec3> {
    let mut positions = Vec::with_capacity(clip.frame_count() * resolved.len());
    let mut g = vec![];
    for f in 0..clip.frame_count() {
        clip.globals(f, &mut g);
        for lm in resolved {
            let t = g[lm.joint];
            let e = if lm.end_site {
                clip.skeleton.joints[lm.joint].end_site.unwrap_or_default()
            } else {
                DVec3::ZERO
            };
            positions.push(t.translation + t.rotation * e);
        }
    }
    positions
}

/// The landmarks' positions over the clip: `positions[f * names.len() + i]` is landmark
/// `names[i]` at frame `f`.
struct LandmarkTracks {
    names: Vec<String>,
    positions: Vec<DVec3>,
    frames: usize,
}

impl LandmarkTracks {
    /// The index of landmark `name`.
    fn index(&self, name: &str) -> usize {
        self.names
            .iter()
            .position(|x| x == name)
            .expect("needed above")
    }
}

/// A copy of `model` with the source's offsets and End Sites: the median of the landmark
/// geometry in the parent's target frame (the model's own where the source gives none).
fn mapped_figure(model: &Figure, lm: &LandmarkTracks, targets: &[Option<DQuat>]) -> Figure {
    let (n, k, frames) = (model.joints.len(), lm.names.len(), lm.frames);
    let positions = &lm.positions;
    let mut mapped_figure = model.clone();
    for j in 0..n {
        let me = lm.index(&model.joints[j].name);
        if let Some(pj) = model.joints[j].parent {
            let parent = lm.index(&model.joints[pj].name);
            mapped_figure.joints[j].offset = median_local(frames, |f| {
                let q = targets[f * n + pj]?;
                Some(q.inverse() * (positions[f * k + me] - positions[f * k + parent]))
            })
            .unwrap_or(model.joints[j].offset);
        }
        if let Some(e) = end_landmark(&model.joints[j].name) {
            let end = lm.index(&e);
            mapped_figure.joints[j].end_site = median_local(frames, |f| {
                let q = targets[f * n + j]?;
                Some(q.inverse() * (positions[f * k + end] - positions[f * k + me]))
            })
            .or(model.joints[j].end_site);
        }
    }
    mapped_figure.height = height_of(&mapped_figure);
    mapped_figure
}

/// The DOF angles of every frame (`frames` × DOFs) and the root's rotation, parents first,
/// each joint's from its parent's achieved frame and the link's target (`targets`, frame by
/// frame), unwrapped against the frame before.
fn dof_angles(
    model: &Figure,
    targets: &[Option<DQuat>],
    rest_dirs: &[DVec3],
    frames: usize,
) -> (Vec<f64>, Vec<DQuat>) {
    let n = model.joints.len();
    let dofs = model.dofs.len();
    let mut angles = vec![0.0; frames * dofs];
    let mut root_rotation = Vec::with_capacity(frames);
    let mut achieved = vec![DQuat::IDENTITY; n];
    let joint_axes: Vec<Vec<DVec3>> = (0..n).map(|j| model.joint_axes(j)).collect();
    for f in 0..frames {
        for j in 0..n {
            let joint = &model.joints[j];
            let parent = joint.parent.map_or(DQuat::IDENTITY, |p| achieved[p]);
            let target = targets[f * n + j].unwrap_or(parent);
            if joint.kind == JointKind::Free {
                achieved[j] = target;
                continue;
            }
            let axes = &joint_axes[j];
            let local = parent.inverse() * target;
            let m = joint.dofs.len();
            let mut out = [0.0; 3];
            if m > 0 {
                let first = joint.dofs[0];
                let mut prev = [0.0; 3];
                if f > 0 {
                    let row = (f - 1) * dofs + first;
                    prev[..m].copy_from_slice(&angles[row..row + m]);
                }
                project_rotation(
                    joint.kind,
                    axes,
                    rest_dirs[j],
                    local,
                    (f > 0).then_some(&prev[..m]),
                    &mut out[..m],
                );
                angles[f * dofs + first..f * dofs + first + m].copy_from_slice(&out[..m]);
            }
            achieved[j] = parent * local_rotation(joint.kind, axes, &out[..m]);
        }
        root_rotation.push(achieved[0]);
    }
    (angles, root_rotation)
}

/// Componentwise median of the vectors `sample(f)` over frames (skipping `None`).
fn median_local(frames: usize, sample: impl Fn(usize) -> Option<DVec3>) -> Option<DVec3> {
    let v: Vec<DVec3> = (0..frames).filter_map(sample).collect();
    if v.is_empty() {
        return None;
    }
    let med = |c: usize| {
        let mut x: Vec<f64> = v.iter().map(|p| p[c]).collect();
        x.sort_by(f64::total_cmp);
        x[x.len() / 2]
    };
    Some(DVec3::new(med(0), med(1), med(2)))
}

/// Standing height of a model in its rest pose (top point minus lowest point), metres.
fn height_of(model: &Figure) -> f64 {
    let pts = model.skeleton().rest_points();
    let hi = pts.iter().map(|p| p.y).fold(f64::MIN, f64::max);
    let lo = pts.iter().map(|p| p.y).fold(f64::MAX, f64::min);
    hi - lo
}

/// Leg length of a model at rest, metres: the mean over the sides that have them of the height
/// of the `…_hip` joint above the lowest point at or below its `…_ankle` joint (the ankle, its
/// End Site, any joint under it); `None` for a model without hips and ankles.
pub fn leg_length(model: &Figure) -> Option<f64> {
    let skeleton = model.skeleton();
    let pts = skeleton.rest_points();
    let parents = skeleton.point_parents();
    let mut lengths = vec![];
    for side in ["left_", "right_"] {
        let (Some(hip), Some(ankle)) = (
            model.joint_index(&format!("{side}hip")),
            model.joint_index(&format!("{side}ankle")),
        ) else {
            continue;
        };
        // Points at or below the ankle: parents come before children, so one pass marks them.
        let mut below = vec![false; pts.len()];
        for p in 0..pts.len() {
            below[p] = p == ankle || parents[p].is_some_and(|q| below[q]);
        }
        let lowest = (0..pts.len())
            .filter(|&p| below[p])
            .map(|p| pts[p].y)
            .fold(f64::INFINITY, f64::min);
        lengths.push(pts[hip].y - lowest);
    }
    (!lengths.is_empty()).then(|| lengths.iter().sum::<f64>() / lengths.len() as f64)
}

/// `clip` played on `target`, a model with the same joints and DOFs as `clip.model` (e.g. the
/// source-proportioned copy [`retarget`] returns, played on the model itself): the DOF angles
/// and the root orientation as they are, the root translation scaled by s = L_target / L_clip,
/// the ratio of the two models' leg lengths at rest ([`leg_length`]): t' = s·t. A dancer 1.53 m
/// tall put on legs of a 1.65 m figure keeps her pelvis at her own height and so stands in the
/// floor; scaled, the pelvis rides as high above the feet, and the steps are as long, in
/// proportion to the legs. Without legs on either model the translation is kept (s = 1).
pub fn onto_figure(clip: &FigureClip, target: &Figure) -> FigureClip {
    let s = match (leg_length(target), leg_length(&clip.model)) {
        (Some(t), Some(c)) if t > 0.0 && c > 0.0 => t / c,
        _ => 1.0,
    };
    FigureClip {
        model: target.clone(),
        frame_time: clip.frame_time,
        root_translation: clip.root_translation.iter().map(|t| *t * s).collect(),
        root_rotation: clip.root_rotation.clone(),
        angles: clip.angles.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::humanoid::humanoid24;

    #[test]
    fn leg_length_of_humanoid24_is_its_hip_height_and_scales_with_it() {
        let m = humanoid24();
        let l = leg_length(&m).unwrap();
        // Hip centre at 0.530 H above the sole (the toe End Site is at the floor at rest).
        assert!((l / m.height - 0.530).abs() < 0.01, "{l} of {}", m.height);
        let small = m.scaled_to_height(1.53);
        assert!((leg_length(&small).unwrap() / l - 1.53 / m.height).abs() < 1e-12);
    }

    #[test]
    fn onto_a_taller_model_the_root_path_scales_with_the_legs() {
        let target = humanoid24();
        let source = target.scaled_to_height(1.53);
        let d = target.dofs.len();
        let n = 10;
        let clip = FigureClip {
            model: source.clone(),
            frame_time: 0.1,
            root_translation: (0..n)
                .map(|f| DVec3::new(0.1 * f as f64, 0.8, -0.05 * f as f64))
                .collect(),
            root_rotation: vec![DQuat::IDENTITY; n],
            angles: (0..n * d).map(|i| 0.01 * i as f64).collect(),
        };
        let out = onto_figure(&clip, &target);
        let s = target.height / 1.53;
        for (a, b) in clip.root_translation.iter().zip(&out.root_translation) {
            assert!((*b - *a * s).length() < 1e-12);
        }
        assert_eq!(out.angles, clip.angles);
        assert_eq!(out.model, target);
        // Standing straight with its sole on the floor on the source, so it does on the target.
        let stand = |m: &Figure| {
            leg_length(m).unwrap()
                + (m.skeleton().rest_points()[0].y
                    - m.skeleton().rest_points()[m.joint_index("left_hip").unwrap()].y)
        };
        let still = FigureClip {
            root_translation: vec![DVec3::new(0.0, stand(&source), 0.0)],
            root_rotation: vec![DQuat::IDENTITY],
            angles: vec![0.0; d],
            ..clip
        };
        let on = onto_figure(&still, &target);
        let sole = on.foot_heights()[0][0];
        assert!(sole.abs() < 1e-9, "sole at {sole} m");
    }
}
