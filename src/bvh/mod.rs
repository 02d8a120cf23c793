//! BVH (Biovision Hierarchy) motion files: reading and writing, for any skeleton.
//!
//! A [`Bvh`] is the file's content as data: the joint hierarchy in file order (each parent
//! before its children), each joint's OFFSET, CHANNELS and optional End Site, and the MOTION
//! block as one flat `frames × channel_count` array of the values as written (file units,
//! degrees). Turning that into rotations and positions is [`crate::skeleton`]'s job.

// mod parse; (reader: being written)
// mod write; (writer: being written)

use glam::DVec3;

/// One channel of a joint, in the order the CHANNELS line lists them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Channel {
    Xposition,
    Yposition,
    Zposition,
    Xrotation,
    Yrotation,
    Zrotation,
}

impl Channel {
    /// The channel's name as written in a BVH file.
    pub fn name(self) -> &'static str {
        match self {
            Channel::Xposition => "Xposition",
            Channel::Yposition => "Yposition",
            Channel::Zposition => "Zposition",
            Channel::Xrotation => "Xrotation",
            Channel::Yrotation => "Yrotation",
            Channel::Zrotation => "Zrotation",
        }
    }

    /// True for the three rotation channels.
    pub fn is_rotation(self) -> bool {
        matches!(
            self,
            Channel::Xrotation | Channel::Yrotation | Channel::Zrotation
        )
    }

    /// The axis index 0 (X), 1 (Y) or 2 (Z).
    pub fn axis(self) -> usize {
        match self {
            Channel::Xposition | Channel::Xrotation => 0,
            Channel::Yposition | Channel::Yrotation => 1,
            Channel::Zposition | Channel::Zrotation => 2,
        }
    }
}

/// One joint of the hierarchy (ROOT or JOINT), in file units.
#[derive(Clone, Debug, PartialEq)]
pub struct BvhJoint {
    /// The name after ROOT/JOINT.
    pub name: String,
    /// Index of the parent joint in [`Bvh::joints`]; `None` for a root.
    pub parent: Option<usize>,
    /// OFFSET from the parent joint, file units.
    pub offset: DVec3,
    /// The CHANNELS in file order (0, 3 or 6 of them, or any other count the file gives).
    pub channels: Vec<Channel>,
    /// Index of this joint's first value in a motion frame.
    pub first_channel: usize,
    /// OFFSET of the End Site, if the joint has one.
    pub end_site: Option<DVec3>,
}

/// A whole BVH file: hierarchy and motion.
#[derive(Clone, Debug, PartialEq)]
pub struct Bvh {
    /// Joints in file order; every parent comes before its children.
    pub joints: Vec<BvhJoint>,
    /// Seconds per frame (the `Frame Time:` line).
    pub frame_time: f64,
    /// Number of values in one frame (sum of all joints' channel counts).
    pub channel_count: usize,
    /// The motion values, frame after frame: `frames × channel_count`, as written in the file.
    pub motion: Vec<f64>,
}

impl Bvh {
    /// Number of frames of motion.
    pub fn frame_count(&self) -> usize {
        self.motion
            .len()
            .checked_div(self.channel_count)
            .unwrap_or(0)
    }

    /// The values of frame `f`.
    pub fn frame(&self, f: usize) -> &[f64] {
        &self.motion[f * self.channel_count..(f + 1) * self.channel_count]
    }

    /// Frames per second (1 / frame time).
    pub fn fps(&self) -> f64 {
        1.0 / self.frame_time
    }

    /// Duration in seconds (frames × frame time).
    pub fn duration(&self) -> f64 {
        self.frame_count() as f64 * self.frame_time
    }

    /// Index of the joint with this name.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }
}
