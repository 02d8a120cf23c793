//! BVH (Biovision Hierarchy) motion files: reading and writing, for any skeleton.
//!
//! A [`Bvh`] is the file's content as data: the joint hierarchy in file order (each parent
//! before its children), each joint's OFFSET, CHANNELS and optional End Site, and the MOTION
//! block as one flat `frames × channel_count` array of the values as written (file units,
//! degrees). Turning that into rotations and positions is [`crate::skeleton`]'s job.
//!
//! [`parse`] / [`parse_file`] read any skeleton (any channel order and count, End Sites,
//! several roots, LF or CRLF); malformed input gives a [`BvhError`] naming the line, never a
//! panic. [`to_string`] / [`write_file`] write text that reads back to identical values.
//!
//! ```
//! use marionette::bvh;
//! let text = "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0 0\n\tCHANNELS 3 Zrotation Xrotation Yrotation\n\
//!             \tEnd Site\n\t{\n\t\tOFFSET 0 1 0\n\t}\n}\nMOTION\nFrames: 1\nFrame Time: .0083333\n\
//!             10 -0 1e-06\n";
//! let (b, warnings) = bvh::parse(text.as_bytes())?;
//! assert!(warnings.is_empty());
//! assert_eq!((b.frame_count(), b.channel_count, b.frame(0)[0]), (1, 3, 10.0));
//! assert_eq!(bvh::parse(bvh::to_string(&b).as_bytes())?.0, b);
//! # Ok::<(), bvh::BvhError>(())
//! ```

mod error;
mod parse;
mod write;

pub use error::{BvhError, BvhWarning};

/// Deepest joint nesting read or written (a human skeleton is about 10 levels deep).
pub const MAX_DEPTH: usize = 64;
/// Most joints in a hierarchy.
pub const MAX_JOINTS: usize = 1024;
/// Largest OFFSET component or position channel value, file units (a kilometre in
/// millimetres): beyond it a figure's size is not a number a unit scale can make human.
pub const MAX_LENGTH_UNITS: f64 = 1e6;
/// Largest rotation channel value, degrees (about 278 turns, room for unwrapped angles).
pub const MAX_ANGLE_DEG: f64 = 1e5;
pub use parse::{parse, parse_file};
pub use write::{to_string, to_string_with_precision, write_file};

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

    /// Checks that this value describes a well-formed BVH file, the invariants the reader
    /// guarantees and the writer relies on:
    ///
    /// - at least one joint; every name non-empty, without a line feed or surrounding spaces;
    /// - joints in depth-first file order: each joint's parent is on the path from a root to
    ///   the joint before it (so the parent also comes first);
    /// - `first_channel` of each joint is the sum of the channel counts before it, and
    ///   `channel_count` the sum over all joints;
    /// - `motion.len()` a multiple of `channel_count` (empty when there are no channels);
    /// - `frame_time` positive and finite; every offset and motion value finite.
    pub fn validate(&self) -> Result<(), BvhError> {
        let invalid = |message: String| Err(BvhError::Invalid { message });
        if self.joints.is_empty() {
            return invalid("no joints".into());
        }
        if self.joints.len() > MAX_JOINTS {
            return invalid(format!(
                "{} joints, more than the {MAX_JOINTS} allowed",
                self.joints.len()
            ));
        }
        let next_channel = self.check_joints()?;
        if self.channel_count != next_channel {
            return invalid(format!(
                "channel_count is {}, but the joints have {next_channel} channels",
                self.channel_count
            ));
        }
        let frames_ok = if self.channel_count == 0 {
            self.motion.is_empty()
        } else {
            self.motion.len().is_multiple_of(self.channel_count)
        };
        if !frames_ok {
            return invalid(format!(
                "motion has {} values, not a whole number of frames of {} channels",
                self.motion.len(),
                self.channel_count
            ));
        }
        if !(self.frame_time.is_finite() && self.frame_time > 0.0) {
            return invalid(format!("frame_time is {}, expected > 0", self.frame_time));
        }
        if let Some(k) = self.motion.iter().position(|v| !v.is_finite()) {
            return invalid(format!("motion value {k} is {}", self.motion[k]));
        }
        Ok(())
    }

    /// [`Bvh::validate`]'s checks of each joint: its name, its parent on the depth-first path,
    /// its depth, its channels following the ones before, its finite offsets. Returns the
    /// joints' channel count.
    fn check_joints(&self) -> Result<usize, BvhError> {
        let invalid = |message: String| Err(BvhError::Invalid { message });
        let mut seen = std::collections::HashMap::new();
        let mut path: Vec<usize> = Vec::new();
        let mut next_channel = 0usize;
        for (i, j) in self.joints.iter().enumerate() {
            let n = &j.name;
            let spaces: &[char] = &[' ', '\t', '\r', '\x0b', '\x0c'];
            if n.is_empty() || n.trim_matches(spaces) != n || n.contains('\n') {
                return invalid(format!(
                    "joint {i} name {n:?} is empty, has surrounding spaces or a line feed"
                ));
            }
            while let Some(&top) = path.last() {
                if j.parent == Some(top) {
                    break;
                }
                path.pop();
            }
            if let Some(p) = j.parent
                && path.last() != Some(&p)
            {
                return invalid(format!(
                    "joint {i} `{n}` has parent {p}, which is not on the depth-first path to it \
                     (joints must be in file order)"
                ));
            }
            path.push(i);
            if path.len() > MAX_DEPTH {
                return invalid(format!(
                    "joint {i} `{n}` is nested {} deep, deeper than the {MAX_DEPTH} allowed",
                    path.len()
                ));
            }
            if let Some(first) = seen.insert(n.as_str(), i) {
                return invalid(format!(
                    "joints {first} and {i} are both named `{n}`; joint names must be unique"
                ));
            }
            if j.first_channel != next_channel {
                return invalid(format!(
                    "joint {i} `{n}` has first_channel {}, expected {next_channel}",
                    j.first_channel
                ));
            }
            next_channel += j.channels.len();
            let end = j.end_site.unwrap_or(DVec3::ZERO);
            if !j.offset.is_finite() || !end.is_finite() {
                return invalid(format!("joint {i} `{n}` has a non-finite offset"));
            }
        }
        Ok(next_channel)
    }
}
