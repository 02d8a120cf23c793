//! The components of every character, kinematic or simulated: name, skeleton, joint state
//! (local and global transforms), clip playback and the recorder of drawable points.

use std::sync::Arc;

use bevy_ecs::prelude::*;
use glam::{DQuat, DVec3};

use crate::skeleton::{Clip, Skeleton, Transform};

/// Marks a character entity and names it.
#[derive(Component, Clone, Debug)]
pub struct Character {
    /// Name, used in outputs.
    pub name: String,
}

/// The character's skeleton, shared between worlds and characters.
#[derive(Component, Clone, Debug)]
pub struct SkeletonRef(pub Arc<Skeleton>);

/// The current pose: local translations and rotations per joint, and their global transforms
/// (filled by forward kinematics).
#[derive(Component, Clone, Debug)]
pub struct JointState {
    /// Local translation per joint, metres.
    pub translations: Vec<DVec3>,
    /// Local rotation per joint.
    pub rotations: Vec<DQuat>,
    /// Global transform per joint.
    pub globals: Vec<Transform>,
}

impl JointState {
    /// A rest state for `n` joints.
    pub fn new(n: usize) -> Self {
        JointState {
            translations: vec![DVec3::ZERO; n],
            rotations: vec![DQuat::IDENTITY; n],
            globals: vec![Transform::IDENTITY; n],
        }
    }
}

/// Plays a clip: the clip time advances by `speed × dt` each step; the pose between two frames
/// is interpolated (lerp of translations, slerp of rotations).
#[derive(Component, Clone, Debug)]
pub struct ClipPlayback {
    /// The clip.
    pub clip: Arc<Clip>,
    /// Current time in the clip, seconds.
    pub time: f64,
    /// Playback speed (1 = real time).
    pub speed: f64,
    /// Wrap around at the end instead of holding the last frame.
    pub looping: bool,
}

/// Records the drawable points (joints, then End Sites) of every step.
#[derive(Component, Clone, Debug, Default)]
pub struct Recorder {
    /// One entry per recorded step.
    pub frames: Vec<Vec<DVec3>>,
}
