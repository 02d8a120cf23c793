//! BVH writer: [`Bvh`] → text that [`super::parse`] reads back to the same values.
//!
//! Layout: tabs for indentation, one `OFFSET` and one `CHANNELS n …` line per joint (the
//! channels as stored), `End Site` blocks after a joint's children, then `MOTION`,
//! `Frames: N`, `Frame Time: t` and one line of space-separated values per frame.
//!
//! Numbers use Rust's shortest round-trip formatting of `f64` (the fewest digits that read back
//! to the identical value), in scientific notation only outside 1e-5 ≤ |v| < 1e16 so that tiny
//! values such as `1.17755e-14` stay short.

use std::fmt::Write as _;
use std::path::Path;

use super::{Bvh, BvhError, BvhJoint};

/// The file text of `bvh`, every number written so that reading it back gives the identical
/// `f64`. For a `bvh` that fails [`Bvh::validate`] the text is still produced (no panic) but
/// may not read back to the same data.
pub fn to_string(bvh: &Bvh) -> String {
    write_bvh(bvh, push_shortest)
}

/// Like [`to_string`] but motion values with exactly `decimals` digits after the point (the
/// hierarchy's offsets and the frame time keep their exact shortest form). Smaller files,
/// values rounded to `10^-decimals`.
pub fn to_string_with_precision(bvh: &Bvh, decimals: usize) -> String {
    write_bvh(bvh, |out, v| {
        let _ = write!(out, "{v:.decimals$}");
    })
}

/// Writes `bvh` to `path` atomically (whole file or nothing) after checking it with
/// [`Bvh::validate`] and that it has at least one frame (a file without frames holds no motion
/// and many readers refuse it).
pub fn write_file(bvh: &Bvh, path: &Path) -> Result<(), BvhError> {
    bvh.validate()?;
    if bvh.frame_count() == 0 {
        return Err(BvhError::Invalid {
            message: format!(
                "{}: the motion has no frames; nothing to write",
                path.display()
            ),
        });
    }
    crate::io::write_atomic(path, to_string(bvh).as_bytes()).map_err(|error| BvhError::Io {
        path: path.to_path_buf(),
        error,
    })
}

/// Appends the shortest decimal text of `v` that parses back to exactly `v`.
#[inline]
fn push_shortest(out: &mut String, v: f64) {
    let a = v.abs();
    let _ = if a != 0.0 && !(1e-5..1e16).contains(&a) {
        write!(out, "{v:e}")
    } else {
        write!(out, "{v}")
    };
}

fn write_bvh(bvh: &Bvh, mut value: impl FnMut(&mut String, f64)) -> String {
    // About 10 bytes per value in typical files.
    let mut out = String::with_capacity(bvh.joints.len() * 120 + bvh.motion.len() * 10 + 64);
    out.push_str("HIERARCHY\n");
    // Joints are in file (depth-first) order: the stack holds the path from the root to the
    // joint last opened; a joint closes when the next joint is not its descendant.
    let mut stack: Vec<usize> = Vec::new();
    for (i, joint) in bvh.joints.iter().enumerate() {
        while let Some(&top) = stack.last() {
            if joint.parent == Some(top) {
                break;
            }
            stack.pop();
            close_joint(&mut out, &bvh.joints[top], stack.len());
        }
        let depth = stack.len();
        indent(&mut out, depth);
        out.push_str(if depth == 0 { "ROOT " } else { "JOINT " });
        out.push_str(&joint.name);
        out.push('\n');
        indent(&mut out, depth);
        out.push_str("{\n");
        indent(&mut out, depth + 1);
        push_offset(&mut out, joint.offset.to_array());
        indent(&mut out, depth + 1);
        let _ = write!(out, "CHANNELS {}", joint.channels.len());
        for c in &joint.channels {
            out.push(' ');
            out.push_str(c.name());
        }
        out.push('\n');
        stack.push(i);
    }
    while let Some(top) = stack.pop() {
        close_joint(&mut out, &bvh.joints[top], stack.len());
    }
    let frames = bvh.frame_count();
    out.push_str("MOTION\n");
    let _ = writeln!(out, "Frames: {frames}");
    out.push_str("Frame Time: ");
    push_shortest(&mut out, bvh.frame_time);
    out.push('\n');
    if bvh.channel_count > 0 {
        for row in bvh.motion.chunks(bvh.channel_count) {
            for (k, &v) in row.iter().enumerate() {
                if k > 0 {
                    out.push(' ');
                }
                value(&mut out, v);
            }
            out.push('\n');
        }
    }
    out
}

/// Writes the joint's End Site (if any) and its closing brace at nesting `depth`.
fn close_joint(out: &mut String, joint: &BvhJoint, depth: usize) {
    if let Some(end) = joint.end_site {
        indent(out, depth + 1);
        out.push_str("End Site\n");
        indent(out, depth + 1);
        out.push_str("{\n");
        indent(out, depth + 2);
        push_offset(out, end.to_array());
        indent(out, depth + 1);
        out.push_str("}\n");
    }
    indent(out, depth);
    out.push_str("}\n");
}

fn push_offset(out: &mut String, v: [f64; 3]) {
    out.push_str("OFFSET");
    for x in v {
        out.push(' ');
        push_shortest(out, x);
    }
    out.push('\n');
}

/// Tabs for `depth`, at most [`super::MAX_DEPTH`] (a hierarchy the reader accepts is never
/// deeper; one built in code that is keeps its lines short).
fn indent(out: &mut String, depth: usize) {
    for _ in 0..depth.min(super::MAX_DEPTH) {
        out.push('\t');
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shortest(v: f64) -> String {
        let mut s = String::new();
        push_shortest(&mut s, v);
        s
    }

    #[test]
    fn shortest_round_trips_and_stays_short() {
        assert_eq!(shortest(0.0), "0");
        assert_eq!(shortest(-0.0), "-0");
        assert_eq!(shortest(0.0083333), "0.0083333");
        assert_eq!(shortest(1.17755e-14), "1.17755e-14");
        assert_eq!(shortest(1e20), "1e20");
        for v in [
            0.1,
            1.0 / 3.0,
            -2.0e-5,
            9.999999e-6,
            f64::MIN_POSITIVE,
            f64::MAX,
            5e-324,
            123456789.125,
        ] {
            assert_eq!(shortest(v).parse::<f64>().unwrap(), v, "{v}");
        }
    }
}
