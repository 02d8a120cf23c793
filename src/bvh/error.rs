//! What can go wrong reading or writing a BVH file, and the non-fatal notes a reader leaves.
//!
//! Every error raised while reading names the 1-based line (and the 1-based byte column where
//! one token is at fault), what was expected and what was found. Errors raised while reading a
//! file are wrapped in [`BvhError::InFile`], which also names the file.

use std::path::PathBuf;

/// Something in a BVH file that was tolerated and ignored, with the 1-based line it is on.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BvhWarning {
    /// 1-based line number.
    pub line: usize,
    /// What was found and what the reader did about it.
    pub message: String,
}

impl std::fmt::Display for BvhWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

/// A BVH file that cannot be read or written. Lines and columns are 1-based; columns count bytes.
#[derive(Debug, thiserror::Error)]
pub enum BvhError {
    /// The file has no content at all (or only whitespace).
    #[error("line {line}: the file is empty, expected HIERARCHY")]
    Empty {
        /// Line where the input ends.
        line: usize,
    },
    /// A byte sequence that is not UTF-8 text.
    #[error("line {line}, column {column}: invalid UTF-8 byte, expected plain text")]
    InvalidUtf8 {
        /// Line of the first invalid byte.
        line: usize,
        /// Byte column of the first invalid byte.
        column: usize,
    },
    /// A token other than the one the grammar needs here.
    #[error("line {line}, column {column}: expected {expected}, found {found}")]
    Expected {
        /// Line of the offending token.
        line: usize,
        /// Byte column of the offending token.
        column: usize,
        /// What the reader needed.
        expected: String,
        /// What it found (quoted token).
        found: String,
    },
    /// The input ends where more was needed.
    #[error("line {line}: the file ends, expected {expected}")]
    UnexpectedEnd {
        /// The last line of the input.
        line: usize,
        /// What the reader needed.
        expected: String,
    },
    /// A CHANNELS entry that is not one of the six channel names.
    #[error(
        "line {line}, column {column}: unknown channel name `{found}`, expected one of \
         Xposition, Yposition, Zposition, Xrotation, Yrotation, Zrotation"
    )]
    UnknownChannel {
        /// Line of the CHANNELS entry.
        line: usize,
        /// Byte column of the entry.
        column: usize,
        /// The name found.
        found: String,
    },
    /// A number beyond the limit for its kind ([`super::MAX_LENGTH_UNITS`],
    /// [`super::MAX_ANGLE_DEG`]).
    #[error("line {line}, column {column}: {what} is `{found}`, beyond the limit of ±{limit}")]
    OutOfRange {
        /// Line of the number.
        line: usize,
        /// Byte column of the number.
        column: usize,
        /// Which value this is (e.g. "value 4 of frame 12, a rotation in degrees").
        what: String,
        /// The text of the number.
        found: String,
        /// The limit.
        limit: f64,
    },
    /// A hierarchy deeper or larger than [`super::MAX_DEPTH`] / [`super::MAX_JOINTS`].
    #[error("line {line}: {what}")]
    TooLarge {
        /// Line of the joint past the limit.
        line: usize,
        /// What limit was passed.
        what: String,
    },
    /// Two joints with one name (tools such as Blender cannot read such a file).
    #[error(
        "line {line}: joint `{name}` is already defined on line {first_line}; joint names must be unique"
    )]
    DuplicateJoint {
        /// Line of the second joint.
        line: usize,
        /// The name.
        name: String,
        /// Line of the first.
        first_line: usize,
    },
    /// A number that parses but is NaN or infinite.
    #[error("line {line}, column {column}: {what} is `{found}`, expected a finite number")]
    NonFinite {
        /// Line of the number.
        line: usize,
        /// Byte column of the number.
        column: usize,
        /// Which value this is (e.g. "value 4 of frame 12").
        what: String,
        /// The text of the number.
        found: String,
    },
    /// A joint closed or continued before its OFFSET or CHANNELS line, or with a second one.
    #[error("line {line}: joint `{joint}` {problem}")]
    JointItem {
        /// Line where the problem shows.
        line: usize,
        /// The joint's name.
        joint: String,
        /// What is missing or duplicated, and what was found instead.
        problem: String,
    },
    /// A joint whose `{` has no matching `}` before MOTION or the end of the file.
    #[error(
        "line {line}: expected `}}` closing joint `{joint}` (opened on line {opened}), found {found}"
    )]
    Unclosed {
        /// Line where the closing brace was needed.
        line: usize,
        /// The joint left open.
        joint: String,
        /// Line of its `{`.
        opened: usize,
        /// What came instead.
        found: String,
    },
    /// A `}` with no open joint.
    #[error("line {line}, column {column}: `}}` without a matching `{{`")]
    UnmatchedClose {
        /// Line of the brace.
        line: usize,
        /// Byte column of the brace.
        column: usize,
    },
    /// A hierarchy that is not followed by a MOTION section.
    #[error("line {line}: the file ends after the hierarchy, expected MOTION")]
    MissingMotion {
        /// The last line of the input.
        line: usize,
    },
    /// A motion line with more or fewer values than the hierarchy has channels.
    #[error(
        "line {line}: expected {expected} numbers in frame {frame}, found {found} \
         (a BVH frame is exactly one line of values)"
    )]
    FrameValueCount {
        /// Line of the frame.
        line: usize,
        /// 1-based frame number.
        frame: usize,
        /// Channel count of the hierarchy.
        expected: usize,
        /// Values on the line.
        found: usize,
    },
    /// Fewer motion lines than `Frames:` declares.
    #[error(
        "line {line}: the file ends after {found} of the {declared} frames declared on line \
         {declared_line} (`Frames: {declared}`)"
    )]
    MissingFrames {
        /// Line where the next frame was expected.
        line: usize,
        /// Frames read.
        found: usize,
        /// Frames declared.
        declared: usize,
        /// Line of the `Frames:` declaration.
        declared_line: usize,
    },
    /// A `Frame Time:` that is zero, negative or not finite.
    #[error("line {line}: Frame Time is `{found}`, expected a positive finite number of seconds")]
    FrameTime {
        /// Line of `Frame Time:`.
        line: usize,
        /// The value as written.
        found: String,
    },
    /// Frames declared for a hierarchy without any channel.
    #[error("line {line}: `Frames: {frames}` but the hierarchy declares no channels")]
    NoChannels {
        /// Line of `Frames:`.
        line: usize,
        /// Frames declared.
        frames: usize,
    },
    /// A `Bvh` value that cannot be written as a valid file (see [`crate::bvh::Bvh::validate`]).
    #[error("invalid BVH data: {message}")]
    Invalid {
        /// What is inconsistent.
        message: String,
    },
    /// The file could not be read or written.
    #[error("{}: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        error: std::io::Error,
    },
    /// An error in the content of a named file.
    #[error("{}: {error}", path.display())]
    InFile {
        /// The file.
        path: PathBuf,
        /// What is wrong in it.
        error: Box<BvhError>,
    },
}

impl BvhError {
    /// The 1-based line the error points at, if it points at one (looks inside [`BvhError::InFile`]).
    pub fn line(&self) -> Option<usize> {
        use BvhError::*;
        match self {
            Empty { line }
            | InvalidUtf8 { line, .. }
            | Expected { line, .. }
            | UnexpectedEnd { line, .. }
            | UnknownChannel { line, .. }
            | NonFinite { line, .. }
            | OutOfRange { line, .. }
            | TooLarge { line, .. }
            | DuplicateJoint { line, .. }
            | JointItem { line, .. }
            | Unclosed { line, .. }
            | UnmatchedClose { line, .. }
            | MissingMotion { line }
            | FrameValueCount { line, .. }
            | MissingFrames { line, .. }
            | FrameTime { line, .. }
            | NoChannels { line, .. } => Some(*line),
            InFile { error, .. } => error.line(),
            Invalid { .. } | Io { .. } => None,
        }
    }

    /// The 1-based byte column the error points at, if it points at one token.
    pub fn column(&self) -> Option<usize> {
        use BvhError::*;
        match self {
            InvalidUtf8 { column, .. }
            | Expected { column, .. }
            | UnknownChannel { column, .. }
            | NonFinite { column, .. }
            | OutOfRange { column, .. }
            | UnmatchedClose { column, .. } => Some(*column),
            InFile { error, .. } => error.column(),
            _ => None,
        }
    }
}
