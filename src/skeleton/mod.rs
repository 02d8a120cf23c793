//! Skeletons, poses and forward kinematics (glam f64, Y up, metres).
//!
//! A [`Skeleton`] is a joint tree (parents first) with rest offsets; a [`Clip`] is a skeleton
//! with one local translation and one local rotation per joint per frame; [`forward_kinematics`]
//! turns a frame into the global position and orientation of every joint.

mod clip;
mod euler;
mod fk;
mod side;

pub use clip::{Clip, ClipError, FIGURE_SIZE_M, MAX_FRAME_JOINTS, estimate_unit_scale};
pub use euler::{euler_to_quat, quat_to_euler};
pub use fk::{Transform, forward_kinematics};
pub use side::{Side, side_from_name};

use glam::{DQuat, DVec3};

/// One joint: a name, its parent and its rest offset from the parent (metres).
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// Joint name.
    pub name: String,
    /// Parent index; `None` for the root.
    pub parent: Option<usize>,
    /// Rest offset from the parent joint, metres.
    pub offset: DVec3,
    /// End Site offset from this joint, metres, if it has one.
    pub end_site: Option<DVec3>,
}

/// A joint tree with each parent before its children.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Skeleton {
    /// The joints, parents first.
    pub joints: Vec<Joint>,
}

impl Skeleton {
    /// Index of the joint with this name.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// Parent indices, one per joint.
    pub fn parents(&self) -> Vec<Option<usize>> {
        self.joints.iter().map(|j| j.parent).collect()
    }

    /// Names of the drawable points: every joint, then every End Site (named `<joint>_end`).
    pub fn point_names(&self) -> Vec<String> {
        let mut names: Vec<String> = self.joints.iter().map(|j| j.name.clone()).collect();
        names.extend(
            self.joints
                .iter()
                .filter(|j| j.end_site.is_some())
                .map(|j| format!("{}_end", j.name)),
        );
        names
    }

    /// Parent of each drawable point (see [`Skeleton::point_names`]).
    pub fn point_parents(&self) -> Vec<Option<usize>> {
        let mut p = self.parents();
        p.extend(
            self.joints
                .iter()
                .enumerate()
                .filter(|(_, j)| j.end_site.is_some())
                .map(|(i, _)| Some(i)),
        );
        p
    }

    /// Drawable points (joints, then End Sites) from global joint transforms.
    pub fn points(&self, globals: &[Transform], out: &mut Vec<DVec3>) {
        out.clear();
        out.extend(globals.iter().map(|t| t.translation));
        for (j, g) in self.joints.iter().zip(globals) {
            if let Some(e) = j.end_site {
                out.push(g.translation + g.rotation * e);
            }
        }
    }

    /// Points of the rest pose (all rotations identity, root at its offset).
    pub fn rest_points(&self) -> Vec<DVec3> {
        let n = self.joints.len();
        let translations: Vec<DVec3> = self.joints.iter().map(|j| j.offset).collect();
        let mut g = vec![Transform::IDENTITY; n];
        forward_kinematics(self, &translations, &vec![DQuat::IDENTITY; n], &mut g);
        let mut pts = vec![];
        self.points(&g, &mut pts);
        pts
    }

    /// The root when it is a ground proxy rather than a part of the body: a root with a single
    /// child joint that is farther from it than a quarter of the rest figure's height (e.g.
    /// Bandai's `joint_Root` on the floor under `Hips`). Contact analysis ignores it and
    /// pictures do not draw its bone (it would look like a third leg).
    pub fn ground_proxy_root(&self) -> Option<usize> {
        let children: Vec<usize> = (0..self.joints.len())
            .filter(|&i| self.joints[i].parent == Some(0))
            .collect();
        let [child] = children[..] else {
            return None;
        };
        let pts = self.rest_points();
        let (lo, hi) = pts
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(p.y), b.max(p.y))
            });
        let height = hi - lo;
        (height > 0.0 && self.joints[child].offset.length() > 0.25 * height).then_some(0)
    }
}
