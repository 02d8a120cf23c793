//! The engine's humanoid models ([`Figure`]s): joint trees whose joints carry named, anatomical
//! degrees of freedom (DOFs).
//!
//! Frame: Y up, the figure faces +Z, its left is +X, metres. In the rest pose (every DOF zero) the
//! figure stands straight with arms hanging at its sides, palms facing the thighs, feet forward,
//! and every joint frame is aligned with the world, so a DOF axis is one vector valid in the
//! parent's and the child's frame. Each axis is oriented so that a positive angle is the named
//! anatomical motion (flexion, abduction, external rotation, …); the left side uses the mirrored
//! axis `(a.x, −a.y, −a.z)` so that the same number means the same motion on both sides.
//!
//! - [`humanoid24`]: the 24-DOF model of the motor-primitive paper (SPEC §1).
//! - [`FigureClip`]: a motion on a model (DOF angles plus root motion).
//! - [`leg_ik`]: two-bone inverse kinematics of a leg (the ankle put at a point).
//! - [`fall21`]: the 21-DOF, 15-link model of the falling paper (SPEC §3), with age-dependent
//!   joint ranges ([`RangeTable`], [`AgeGroup`]): data a user can edit, for fall21
//!   (`src/humanoid/data/fall21_elderly.ron`, `src/humanoid/data/fall21_adult.ron`) and adult for
//!   humanoid24 (`src/humanoid/data/humanoid24_adult.ron`; its sources are named there).
//! - [`HumanBody`]: a figure as an articulated body to simulate (de Leva's segment parameters,
//!   [`fall21_body`], [`human_body`]), written as robot files by [`to_urdf`] and [`to_mjcf`].
//!
//! Four files are namespaces of their own: the two-bone leg IK ([`leg_ik`], whose functions read
//! as `leg_ik::reach`), and three sourced tables whose module docs cite them: [`anthropometry`]
//! (de Leva 1996), [`strength`] (maximal joint torques by age group) and [`tissue`] (the floor
//! contact stiffness of the body's regions). The others are private, their items re-exported here
//! (`marionette::humanoid::HumanBody`).
//!
//! **Robot files** ([`to_urdf`], [`to_mjcf`]). The fall21 body as standard robot files: URDF (for
//! Pinocchio and ROS tools) and MJCF (for MuJoCo). Both keep the engine's frame (Y up, the figure facing +Z, its left +X, metres,
//! radians), so a loader must set gravity to `(0, −g, 0)`; both carry per link the mass, centre
//! of mass and inertia about it, and the contact box; per DOF the axis, range and (URDF) the
//! strength of the age group as `effort`.
//!
//! Joints: the pelvis is the floating base (URDF: the root link, to be loaded with a free-flyer
//! root joint; MJCF: a `freejoint`). Each fall21 DOF is one revolute joint named like the DOF:
//! a universal joint `R(a₁,θ₁)R(a₂,θ₂)` is two revolutes in series through a massless link
//! (`<joint>_1`), exactly the engine's joint. The neck's ball joint is a quaternion joint in the
//! engine: MJCF writes it as a `ball` joint (same quaternion, local angular velocity; its
//! components along the engine's axes X, Z, Y are the engine's velocity coordinates); URDF has no
//! ball joint, so it writes three revolutes about X, Z, Y in series (`neck_flexion`,
//! `neck_lateral`, `neck_rotation`), which equal the engine's joint at the identity and differ
//! elsewhere (Euler angles against a rotation vector). URDF `velocity` limits are not modelled
//! by the engine and are written as 20 rad/s.

pub mod anthropometry;
mod body;
mod definition;
mod export;
mod figure_clip;
mod joint_angles;
pub mod leg_ik;
mod ranges;
pub mod strength;
pub mod tissue;

pub use body::{
    CLAVICLE_SHARE, HumanBody, HumanError, fall21_body, human_body, humanoid24_body,
    shared_fall21_body,
};
pub use definition::{fall21, humanoid24};
pub use export::{to_mjcf, to_urdf};
pub use figure_clip::{FigureClip, ROOT_CHANNELS};
pub use joint_angles::{local_rotation, project_rotation, rotation_vector_near, unwrap_near};
pub use ranges::{AgeGroup, FORMAT_VERSION as RANGES_FORMAT_VERSION, RangeError, RangeTable};

use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};

use crate::skeleton::{Joint, Skeleton};

/// Farthest a foot's lowest point may be from its floor (above it, or through it) to count as
/// down, metres: the tolerance of a planted foot in the jumps and in the active character's
/// feet check.
pub const FOOT_DOWN_M: f64 = 0.01;

/// How a model joint moves relative to its parent.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum JointKind {
    /// The floating base: 3 translations and an orientation (a quaternion), not model DOFs.
    Free,
    /// Spherical joint, 3 DOFs: the angles are the rotation-vector components along its three
    /// orthonormal axes, `q = exp((θ₁a₁ + θ₂a₂ + θ₃a₃)/2)`; no gimbal lock.
    Ball,
    /// Universal joint, 2 DOFs: `R = R(a₁, θ₁)·R(a₂, θ₂)`, `a₁` the parent-side axis.
    Universal,
    /// Revolute (pin) joint, 1 DOF: `R = R(a, θ)`.
    Pin,
    /// Rigidly attached: no DOF.
    Fixed,
}

impl JointKind {
    /// Number of model DOFs the joint carries (the floating base carries none: root motion is
    /// kept apart from the DOFs).
    pub fn dof_count(self) -> usize {
        match self {
            JointKind::Free | JointKind::Fixed => 0,
            JointKind::Pin => 1,
            JointKind::Universal => 2,
            JointKind::Ball => 3,
        }
    }
}

/// One degree of freedom: a named anatomical angle about an axis (radians inside).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Dof {
    /// Anatomical name, e.g. `left_knee`, `right_hip_flexion`.
    pub name: String,
    /// Index of the joint that carries it in [`Figure::joints`].
    pub joint: usize,
    /// Unit rotation axis in rest (world-aligned) coordinates; positive angle = the named motion.
    pub axis: DVec3,
}

/// One joint of a model, which also names the link (segment) that hangs from it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FigureJoint {
    /// Joint name, e.g. `left_knee`.
    pub name: String,
    /// Name of the link moved by this joint, e.g. `left_shin`.
    pub link: String,
    /// Parent joint index; `None` for the root (pelvis).
    pub parent: Option<usize>,
    /// How it moves.
    pub kind: JointKind,
    /// Position relative to the parent joint in the rest pose, metres.
    pub offset: DVec3,
    /// Indices of its DOFs in [`Figure::dofs`], in axis order.
    pub dofs: Vec<usize>,
    /// End point of a terminal link (head top, hand, toe), relative to the joint, metres.
    pub end_site: Option<DVec3>,
}

/// A humanoid figure (one of the engine's models): joints in depth-first order (each parent
/// before its children) and the DOFs they carry, in joint order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Figure {
    /// `humanoid24` or `fall21`.
    pub name: String,
    /// Standing height the offsets were made for, metres.
    pub height: f64,
    /// Joints, parents first.
    pub joints: Vec<FigureJoint>,
    /// DOFs in joint order.
    pub dofs: Vec<Dof>,
}

/// Errors about figures (the engine's models).
#[derive(Debug, thiserror::Error)]
pub enum FigureError {
    /// The name is not one of the engine's models.
    #[error("unknown model '{0}': expected one of humanoid24, fall21")]
    Unknown(String),
    /// A trajectory lacks a channel the model needs (a DOF or a root channel).
    #[error("the trajectory has no channel '{0}'")]
    MissingChannel(String),
}

impl Figure {
    /// The engine's model with this name (`humanoid24` or `fall21`), at the reference height.
    pub fn by_name(name: &str) -> Result<Figure, FigureError> {
        match name {
            "humanoid24" => Ok(humanoid24()),
            "fall21" => Ok(fall21()),
            other => Err(FigureError::Unknown(other.to_string())),
        }
    }

    /// Index of the DOF with this name.
    pub fn dof_index(&self, name: &str) -> Option<usize> {
        self.dofs.iter().position(|d| d.name == name)
    }

    /// Index of the joint with this name.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// DOF names in model order.
    pub fn dof_names(&self) -> Vec<String> {
        self.dofs.iter().map(|d| d.name.clone()).collect()
    }

    /// The axes of joint `j`'s DOFs, in order.
    pub fn joint_axes(&self, j: usize) -> Vec<DVec3> {
        self.joints[j]
            .dofs
            .iter()
            .map(|&d| self.dofs[d].axis)
            .collect()
    }

    /// Rest direction of joint `j`'s link: towards its first child, or its End Site; straight
    /// down for a link with neither.
    pub fn link_direction(&self, j: usize) -> DVec3 {
        let end = self.joints[j].end_site;
        let child = self
            .joints
            .iter()
            .find(|c| c.parent == Some(j))
            .map(|c| c.offset);
        child
            .or(end)
            .and_then(|v| v.try_normalize())
            .unwrap_or(DVec3::NEG_Y)
    }

    /// A copy with every offset and end site scaled so that the standing height is `height` m.
    pub fn scaled_to_height(&self, height: f64) -> Figure {
        let s = height / self.height;
        let mut m = self.clone();
        m.height = height;
        for j in &mut m.joints {
            j.offset *= s;
            j.end_site = j.end_site.map(|e| e * s);
        }
        m
    }

    /// The model as a plain skeleton (same joint names, parents, offsets and end sites), for
    /// forward kinematics, pictures and BVH output.
    pub fn skeleton(&self) -> Skeleton {
        Skeleton {
            joints: self
                .joints
                .iter()
                .map(|j| Joint {
                    name: j.name.clone(),
                    parent: j.parent,
                    offset: j.offset,
                    end_site: j.end_site,
                })
                .collect(),
        }
    }

    /// Local rotations of every joint (root's is identity) for the DOF angles `angles`
    /// (radians, model order); writes into `out` (one per joint).
    pub fn local_rotations(&self, angles: &[f64], out: &mut [DQuat]) {
        for (j, o) in out.iter_mut().enumerate().take(self.joints.len()) {
            *o = self.local_rotation_of(j, angles);
        }
    }

    /// The local rotation of joint `j` for the DOF angles `angles` (radians, model order).
    pub fn local_rotation_of(&self, j: usize, angles: &[f64]) -> DQuat {
        let joint = &self.joints[j];
        let n = joint.dofs.len();
        let mut axes = [DVec3::ZERO; 3];
        let mut a = [0.0; 3];
        for (k, &d) in joint.dofs.iter().enumerate() {
            axes[k] = self.dofs[d].axis;
            a[k] = angles[d];
        }
        local_rotation(joint.kind, &axes[..n], &a[..n])
    }
}
