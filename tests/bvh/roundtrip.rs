//! Property tests: random hierarchies and motions survive write → read exactly, and damaged
//! text never makes the reader panic (it errors with a line inside the file, or reads data
//! that itself round-trips).

use glam::DVec3;
use marionette::bvh::{self, Bvh, BvhJoint, Channel};
use proptest::prelude::*;

const CHANNELS: [Channel; 6] = [
    Channel::Xposition,
    Channel::Yposition,
    Channel::Zposition,
    Channel::Xrotation,
    Channel::Yrotation,
    Channel::Zrotation,
];

/// Any f64 the reader accepts (within ±[`bvh::MAX_ANGLE_DEG`], the smaller of its limits):
/// ordinary magnitudes, every bit pattern brought into range, the limits, subnormals, signed
/// zeros.
fn finite() -> impl Strategy<Value = f64> {
    let max = marionette::bvh::MAX_ANGLE_DEG;
    prop_oneof![
        -1000.0..1000.0f64,
        (-1000.0..1000.0f64).prop_map(|v| (v * 1e4).round() / 1e4),
        any::<f64>().prop_map(move |v| if v.is_finite() { v % max } else { -0.0 }),
        Just(0.0),
        Just(-0.0),
        Just(5e-324),
        Just(max),
        Just(-max),
    ]
}

fn vec3() -> impl Strategy<Value = DVec3> {
    (finite(), finite(), finite()).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

/// One joint's random parts: how far to climb back up the depth-first path before attaching
/// (climbing past the top starts a new root), name, offset, channels, End Site.
type JointParts = (usize, String, DVec3, Vec<Channel>, Option<DVec3>);

fn joint_parts() -> impl Strategy<Value = JointParts> {
    (
        0usize..4,
        "[A-Za-z_]([A-Za-z0-9_ .:-]{0,10}[A-Za-z0-9])?",
        vec3(),
        prop::collection::vec(prop::sample::select(&CHANNELS[..]), 0..8),
        prop::option::of(vec3()),
    )
}

/// A random valid `Bvh`: joints in depth-first order, any channel lists, 0–5 frames.
fn any_bvh() -> impl Strategy<Value = Bvh> {
    (
        prop::collection::vec(joint_parts(), 1..12),
        prop_oneof![1e-4..1.0f64, any::<f64>().prop_map(|v| v.abs().max(1e-300))],
        0usize..6,
    )
        .prop_flat_map(|(parts, frame_time, frames)| {
            let mut joints = Vec::new();
            let mut path: Vec<usize> = Vec::new();
            let mut first = 0;
            for (i, (climb, name, offset, channels, end_site)) in parts.into_iter().enumerate() {
                if i > 0 {
                    for _ in 0..climb.min(path.len()) {
                        path.pop();
                    }
                }
                let parent = if i == 0 { None } else { path.last().copied() };
                let n = channels.len();
                joints.push(BvhJoint {
                    // Joint names are unique in a valid file.
                    name: format!("{name}_{i}"),
                    parent,
                    offset,
                    channels,
                    first_channel: first,
                    end_site,
                });
                first += n;
                path.push(i);
            }
            let frames = if first == 0 { 0 } else { frames };
            let frame_time = if frame_time.is_finite() {
                frame_time
            } else {
                0.01
            };
            prop::collection::vec(finite(), frames * first).prop_map(move |motion| Bvh {
                joints: joints.clone(),
                frame_time,
                channel_count: first,
                motion,
            })
        })
}

proptest! {
    #[test]
    fn random_bvh_round_trips_exactly(b in any_bvh()) {
        prop_assert!(b.validate().is_ok(), "{:?}", b.validate());
        let text = bvh::to_string(&b);
        let (again, warnings) = bvh::parse(text.as_bytes())
            .map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert!(warnings.is_empty());
        prop_assert_eq!(&again, &b);
        for (x, y) in b.motion.iter().zip(&again.motion) {
            prop_assert_eq!(x.to_bits(), y.to_bits());
        }
        // CRLF line ends read the same.
        let crlf = text.replace('\n', "\r\n");
        prop_assert_eq!(bvh::parse(crlf.as_bytes()).unwrap().0, b);
    }

    #[test]
    fn damaged_text_errors_with_a_line_inside_the_file(
        b in any_bvh(),
        edits in prop::collection::vec((any::<prop::sample::Index>(), 0u8..3, any::<u8>(), 1usize..6), 1..4),
    ) {
        let mut bytes = bvh::to_string(&b).into_bytes();
        for (at, op, byte, len) in edits {
            let i = at.index(bytes.len() + 1);
            match op {
                0 => { bytes.drain(i..(i + len).min(bytes.len())); }
                1 => { bytes.splice(i..i, std::iter::repeat_n(byte, len)); }
                _ => if i < bytes.len() { bytes[i] = byte },
            }
        }
        let lines = bytes.split(|&c| c == b'\n').count();
        match bvh::parse(&bytes) {
            Err(e) => {
                let line = e.line().expect("a parse error names a line");
                prop_assert!(line >= 1 && line <= lines + 1, "line {} of {}: {}", line, lines, e);
                let lead = format!("line {line}");
                prop_assert!(e.to_string().starts_with(&lead), "{}", e);
            }
            Ok((parsed, _)) => {
                prop_assert!(parsed.validate().is_ok());
                let again = bvh::parse(bvh::to_string(&parsed).as_bytes()).unwrap().0;
                prop_assert_eq!(again, parsed);
            }
        }
    }
}
