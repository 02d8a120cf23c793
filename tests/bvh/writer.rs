//! Whole-feature tests of the BVH writer: the layout it produces, exact round trips, atomic
//! file writing and the checks on data that cannot be written.

use glam::DVec3;
use marionette::bvh::{self, Bvh, BvhError, BvhJoint, Channel};

/// Hips (6 channels) → Chest (3, End Site), and Hips → Leg (3, End Site), 2 frames.
fn sample() -> Bvh {
    use Channel::*;
    let joint = |name: &str, parent, first, channels: Vec<Channel>, end: Option<DVec3>| BvhJoint {
        name: name.into(),
        parent,
        offset: DVec3::new(0.1, 2.0 / 3.0, -1e-7),
        channels,
        first_channel: first,
        end_site: end,
    };
    Bvh {
        joints: vec![
            joint(
                "Hips",
                None,
                0,
                vec![
                    Xposition, Yposition, Zposition, Zrotation, Yrotation, Xrotation,
                ],
                None,
            ),
            joint(
                "Chest",
                Some(0),
                6,
                vec![Zrotation, Xrotation, Yrotation],
                Some(DVec3::new(0.0, 5.0, 0.0)),
            ),
            joint(
                "Left Leg",
                Some(0),
                9,
                vec![Yrotation, Xrotation, Zrotation],
                Some(DVec3::new(0.0, -40.0, 1.5)),
            ),
        ],
        frame_time: 1.0 / 120.0,
        channel_count: 12,
        motion: (0..24)
            .map(|i| (i as f64 - 11.5) * std::f64::consts::PI * 10f64.powi(i % 8 - 4))
            .collect(),
    }
}

#[test]
fn layout_uses_tabs_end_sites_and_the_motion_header() {
    let b = sample();
    let text = bvh::to_string(&b);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "HIERARCHY");
    assert_eq!(lines[1], "ROOT Hips");
    assert_eq!(lines[2], "{");
    assert!(
        lines[3].starts_with("\tOFFSET 0.1 0.6666666666666666 -1e-7"),
        "{}",
        lines[3]
    );
    assert_eq!(
        lines[4],
        "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation"
    );
    assert_eq!(lines[5], "\tJOINT Chest");
    assert_eq!(lines[8], "\t\tCHANNELS 3 Zrotation Xrotation Yrotation");
    assert_eq!(lines[9], "\t\tEnd Site");
    assert_eq!(lines[11], "\t\t\tOFFSET 0 5 0");
    assert_eq!(lines[13], "\t}");
    assert_eq!(lines[14], "\tJOINT Left Leg");
    let motion_at = lines.iter().position(|l| *l == "MOTION").unwrap();
    assert_eq!(lines[motion_at - 1], "}");
    assert_eq!(lines[motion_at + 1], "Frames: 2");
    assert_eq!(lines[motion_at + 2], "Frame Time: 0.008333333333333333");
    assert_eq!(lines.len(), motion_at + 5);
    for row in &lines[motion_at + 3..] {
        assert_eq!(row.split(' ').count(), 12, "{row}");
    }
    // No spaces used for indentation.
    assert!(lines.iter().all(|l| !l.starts_with(' ')));
}

#[test]
fn written_text_reads_back_to_identical_values() {
    let b = sample();
    let (again, warnings) = bvh::parse(bvh::to_string(&b).as_bytes()).unwrap();
    assert!(warnings.is_empty());
    assert_eq!(again, b);
    // Bit-identical, not just equal within a tolerance (and -0 stays -0).
    let mut b = sample();
    b.motion[3] = -0.0;
    b.motion[4] = f64::MIN_POSITIVE;
    b.motion[5] = 5e-324;
    b.motion[6] = marionette::bvh::MAX_ANGLE_DEG.next_down();
    let again = bvh::parse(bvh::to_string(&b).as_bytes()).unwrap().0;
    for (x, y) in b.motion.iter().zip(&again.motion) {
        assert_eq!(x.to_bits(), y.to_bits());
    }
}

#[test]
fn writing_is_stable_after_one_round_trip() {
    let text = bvh::to_string(&sample());
    let again = bvh::parse(text.as_bytes()).unwrap().0;
    assert_eq!(bvh::to_string(&again), text);
}

#[test]
fn fixed_precision_rounds_motion_only() {
    let b = sample();
    for decimals in [0, 2, 6] {
        let text = bvh::to_string_with_precision(&b, decimals);
        let (again, _) = bvh::parse(text.as_bytes()).unwrap();
        assert_eq!(again.joints, b.joints, "offsets stay exact");
        assert_eq!(again.frame_time, b.frame_time, "frame time stays exact");
        let half_step = 0.5 * 10f64.powi(-(decimals as i32));
        for (x, y) in b.motion.iter().zip(&again.motion) {
            assert!((x - y).abs() <= half_step * (1.0 + 1e-9), "{x} → {y}");
        }
        let row = text.lines().last().unwrap();
        for v in row.split(' ') {
            let frac = v.split('.').nth(1).map_or(0, str::len);
            assert_eq!(frac, decimals, "{v}");
        }
    }
}

#[test]
fn write_file_writes_whole_files_that_read_back() {
    let dir = std::env::temp_dir().join(format!("marionette-bvh-writer-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("out.bvh");
    let b = sample();
    bvh::write_file(&b, &path).unwrap();
    let (again, _) = bvh::parse_file(&path).unwrap();
    assert_eq!(again, b);
    // Overwrite, and leave no temporary files behind.
    let mut shorter = sample();
    shorter.motion.truncate(12);
    bvh::write_file(&shorter, &path).unwrap();
    assert_eq!(bvh::parse_file(&path).unwrap().0.frame_count(), 1);
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    // A folder that does not exist: an I/O error naming the path.
    let e = bvh::write_file(&b, &dir.join("no/such/dir/x.bvh")).unwrap_err();
    assert!(matches!(e, BvhError::Io { .. }), "{e}");
    assert!(e.to_string().contains("no/such/dir/x.bvh"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn write_file_refuses_data_that_would_not_read_back() {
    let dir = std::env::temp_dir().join(format!("marionette-bvh-invalid-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.bvh");
    type Break = fn(&mut Bvh);
    let cases: [(Break, &str); 9] = [
        (|b| b.joints.clear(), "no joints"),
        (|b| b.motion.push(1.0), "not a whole number of frames"),
        (|b| b.motion[7] = f64::NAN, "motion value 7 is NaN"),
        (|b| b.frame_time = 0.0, "frame_time is 0"),
        (|b| b.channel_count = 11, "channel_count is 11"),
        (
            |b| b.joints[2].first_channel = 6,
            "first_channel 6, expected 9",
        ),
        (|b| b.joints[1].name = " Chest".into(), "surrounding spaces"),
        (
            |b| b.joints[1].offset.x = f64::INFINITY,
            "non-finite offset",
        ),
        // A parent listed after its child.
        (
            |b| b.joints[1].parent = Some(2),
            "not on the depth-first path",
        ),
    ];
    for (brk, expect) in cases {
        let mut b = sample();
        brk(&mut b);
        let e = bvh::write_file(&b, &path).unwrap_err();
        assert!(matches!(e, BvhError::Invalid { .. }), "{e}");
        assert!(e.to_string().contains(expect), "{e} lacks {expect:?}");
        assert!(!path.exists(), "an invalid Bvh was written");
        // to_string still returns text rather than panicking.
        let _ = bvh::to_string(&b);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn sample_is_valid() {
    sample().validate().unwrap();
}
