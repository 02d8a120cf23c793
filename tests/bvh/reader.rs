//! Whole-feature tests of the BVH reader: the public data files, every tolerated variation of
//! the format, and every malformed input (each must name its line and say what was expected).

use glam::DVec3;
use marionette::bvh::{self, Bvh, BvhError, Channel};

use crate::common::data_dir;

/// A small valid file; line numbers are referred to by the malformed-input tests.
const BASE: &[&str] = &[
    "HIERARCHY",                                                                // 1
    "ROOT Hips",                                                                // 2
    "{",                                                                        // 3
    "\tOFFSET 0 0 0",                                                           // 4
    "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation", // 5
    "\tJOINT Chest",                                                            // 6
    "\t{",                                                                      // 7
    "\t\tOFFSET 0 10 0",                                                        // 8
    "\t\tCHANNELS 3 Zrotation Xrotation Yrotation",                             // 9
    "\t\tEnd Site",                                                             // 10
    "\t\t{",                                                                    // 11
    "\t\t\tOFFSET 0 5 0",                                                       // 12
    "\t\t}",                                                                    // 13
    "\t}",                                                                      // 14
    "}",                                                                        // 15
    "MOTION",                                                                   // 16
    "Frames: 3",                                                                // 17
    "Frame Time: 0.0333333",                                                    // 18
    "1 2 3 4 5 6 7 8 9",                                                        // 19
    "10 20 30 40 50 60 70 80 90",                                               // 20
    "-1 -2 -3 -4 -5 -6 -7 -8 -9",                                               // 21
];

fn base() -> String {
    BASE.join("\n") + "\n"
}

/// BASE with 1-based line `n` replaced by `text`.
fn with_line(n: usize, text: &str) -> String {
    let mut lines: Vec<&str> = BASE.to_vec();
    lines[n - 1] = text;
    lines.join("\n") + "\n"
}

/// BASE without 1-based line `n`.
fn without_line(n: usize) -> String {
    let mut lines: Vec<&str> = BASE.to_vec();
    lines.remove(n - 1);
    lines.join("\n") + "\n"
}

/// BASE cut after its first `n` lines.
fn first_lines(n: usize) -> String {
    BASE[..n].join("\n") + "\n"
}

/// Parses `text`, expecting an error on `line` whose message contains every one of `parts`.
#[track_caller]
fn fails(text: impl AsRef<[u8]>, line: usize, parts: &[&str]) -> BvhError {
    let err = match bvh::parse(text.as_ref()) {
        Ok(_) => panic!("expected an error on line {line}, but the input parsed"),
        Err(e) => e,
    };
    let msg = err.to_string();
    assert_eq!(err.line(), Some(line), "wrong line in: {msg}");
    assert!(
        msg.starts_with(&format!("line {line}")),
        "message does not lead with its line: {msg}"
    );
    for p in parts {
        assert!(msg.contains(p), "message {msg:?} lacks {p:?}");
    }
    err
}

fn ok(text: impl AsRef<[u8]>) -> Bvh {
    let (bvh, warnings) = bvh::parse(text.as_ref()).expect("parses");
    assert!(warnings.is_empty(), "unexpected warnings {warnings:?}");
    bvh
}

// ---------------------------------------------------------------- the public data files

struct Known {
    file: &'static str,
    frames: usize,
    joints: usize,
    end_sites: usize,
    channels: usize,
    frame_time: f64,
    /// First and last value of the first and of the last frame.
    first: (f64, f64),
    last: (f64, f64),
}

const KNOWN: [Known; 6] = [
    Known {
        file: "cmu/cmu_01_01_forward_jumps.bvh",
        frames: 2752,
        joints: 31,
        end_sites: 7,
        channels: 96,
        frame_time: 0.0083333,
        first: (9.3722, 0.0),
        last: (8.8787, -0.9244),
    },
    Known {
        file: "cmu/acrnn_martial_04.bvh",
        frames: 1317,
        joints: 43,
        end_sites: 14,
        channels: 132,
        frame_time: 0.00833333,
        first: (-13.2422, -0.0537329),
        last: (-23.3735, 17.0514),
    },
    Known {
        file: "cmu/acrnn_salsa_05.bvh",
        frames: 1679,
        joints: 43,
        end_sites: 14,
        channels: 132,
        frame_time: 0.00833333,
        first: (-79.1929, -0.130519),
        last: (-45.7221, -17.6896),
    },
    Known {
        file: "cmu/acrnn_indian_13.bvh",
        frames: 1996,
        joints: 43,
        end_sites: 14,
        channels: 132,
        frame_time: 0.00833333,
        first: (70.1286, -0.0788737),
        last: (-14.067, -28.9732),
    },
    Known {
        file: "bandai/bandai1_kick_normal_001.bvh",
        frames: 358,
        joints: 22,
        end_sites: 5,
        channels: 132,
        frame_time: 0.0333333,
        first: (0.0, -16.7759),
        last: (0.0, -16.7771),
    },
    Known {
        file: "bandai/bandai1_punch_normal_001.bvh",
        frames: 224,
        joints: 22,
        end_sites: 5,
        channels: 132,
        frame_time: 0.0333333,
        first: (0.0, -22.8224),
        last: (0.0, -16.7438),
    },
];

#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn all_data_files_parse_with_their_known_shape_and_round_trip_exactly() {
    let Some(dir) = data_dir() else { return };
    for k in &KNOWN {
        let path = dir.join(k.file);
        let (b, warnings) = bvh::parse_file(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(warnings.is_empty(), "{}: {warnings:?}", k.file);
        assert_eq!(b.frame_count(), k.frames, "{}", k.file);
        assert_eq!(b.joints.len(), k.joints, "{}", k.file);
        let ends = b.joints.iter().filter(|j| j.end_site.is_some()).count();
        assert_eq!(ends, k.end_sites, "{}", k.file);
        assert_eq!(b.channel_count, k.channels, "{}", k.file);
        assert_eq!(b.frame_time, k.frame_time, "{}", k.file);
        assert_eq!(b.motion.len(), k.frames * k.channels);
        let f0 = b.frame(0);
        let fl = b.frame(k.frames - 1);
        assert_eq!((f0[0], f0[k.channels - 1]), k.first, "{}", k.file);
        assert_eq!((fl[0], fl[k.channels - 1]), k.last, "{}", k.file);
        b.validate().unwrap();

        let text = bvh::to_string(&b);
        let (again, w2) = bvh::parse(text.as_bytes()).unwrap();
        assert!(w2.is_empty());
        assert_eq!(again, b, "{} does not round-trip", k.file);
    }
}

#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn jumps_file_has_the_cmu_skeleton() {
    let Some(dir) = data_dir() else { return };
    let (b, _) = bvh::parse_file(&dir.join("cmu/cmu_01_01_forward_jumps.bvh")).unwrap();
    assert_eq!(b.frame_count(), 2752);
    assert_eq!(b.joints.len(), 31);
    assert_eq!(b.frame_time, 0.0083333);
    assert_eq!(b.joints[0].name, "Hips");
    assert_eq!(b.joints[0].parent, None);
    assert_eq!(b.joints[1].name, "LHipJoint");
    assert_eq!(b.joints[1].parent, Some(0));
    assert_eq!(b.joints[2].offset, DVec3::new(1.36306, -1.79463, 0.83929));
    use Channel::*;
    assert_eq!(
        b.joints[0].channels,
        [
            Xposition, Yposition, Zposition, Zrotation, Yrotation, Xrotation
        ]
    );
    assert_eq!(b.joints[1].channels, [Zrotation, Yrotation, Xrotation]);
    assert_eq!(b.joints[1].first_channel, 6);
    assert!((b.duration() - 2752.0 * 0.0083333).abs() < 1e-12);
}

#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn bandai_files_have_six_channels_on_every_joint() {
    let Some(dir) = data_dir() else { return };
    let (b, _) = bvh::parse_file(&dir.join("bandai/bandai1_kick_normal_001.bvh")).unwrap();
    use Channel::*;
    for (i, j) in b.joints.iter().enumerate() {
        assert_eq!(
            j.channels,
            [
                Xposition, Yposition, Zposition, Zrotation, Xrotation, Yrotation
            ],
            "{}",
            j.name
        );
        assert_eq!(j.first_channel, 6 * i);
    }
}

// ---------------------------------------------------------------- tolerated variations

#[test]
fn base_fixture_parses_to_the_expected_values() {
    let b = ok(base());
    assert_eq!(b.joints.len(), 2);
    assert_eq!(b.joints[1].name, "Chest");
    assert_eq!(b.joints[1].parent, Some(0));
    assert_eq!(b.joints[1].offset, DVec3::new(0.0, 10.0, 0.0));
    assert_eq!(b.joints[1].end_site, Some(DVec3::new(0.0, 5.0, 0.0)));
    assert_eq!(b.joints[0].end_site, None);
    assert_eq!(b.frame_time, 0.0333333);
    assert_eq!(b.frame_count(), 3);
    assert_eq!(
        b.frame(2),
        [-1.0, -2.0, -3.0, -4.0, -5.0, -6.0, -7.0, -8.0, -9.0]
    );
}

#[test]
fn crlf_tabs_spaces_and_mixed_line_ends_read_the_same() {
    let want = ok(base());
    assert_eq!(ok(base().replace('\n', "\r\n")), want);
    assert_eq!(ok(base().replace('\t', "    ")), want);
    assert_eq!(ok(base().replace('\t', " \t ").replace(' ', "  ")), want);
    // Mixed, as in the acrnn files: LF in the first lines, CRLF afterwards.
    let lines: Vec<&str> = BASE.to_vec();
    let mixed = lines[..4].join("\n") + "\n" + &lines[4..].join("\r\n") + "\r\n";
    assert_eq!(ok(mixed), want);
    // No final line feed, trailing blank lines, a UTF-8 byte order mark.
    assert_eq!(ok(base().trim_end()), want);
    assert_eq!(ok(base() + "\n\n  \r\n"), want);
    assert_eq!(ok(format!("\u{feff}{}", base())), want);
}

#[test]
fn keywords_in_any_case_and_joined_forms() {
    let want = ok(base());
    let text = base()
        .replace("HIERARCHY", "hierarchy")
        .replace("End Site", "END SITE")
        .replace("OFFSET", "Offset")
        .replace("Zrotation", "ZROTATION")
        .replace("Frames: 3", "FRAMES:3")
        .replace("Frame Time: 0.0333333", "frame time:0.0333333");
    assert_eq!(ok(text), want);
}

#[test]
fn numbers_as_written_in_the_wild() {
    let text = with_line(18, "Frame Time: .0083333")
        .replace(
            "1 2 3 4 5 6 7 8 9",
            "-0 .5 1e-06 -1.5E+2 +3 7. 0.0000 -2.19456e-16 98765",
        )
        .replace("OFFSET 0 10 0", "OFFSET -0.24384 7.07133 1.2192");
    let b = ok(text);
    assert_eq!(b.frame_time, 0.0083333);
    let f = b.frame(0);
    assert_eq!(
        f,
        [
            -0.0,
            0.5,
            1e-6,
            -150.0,
            3.0,
            7.0,
            0.0,
            -2.19456e-16,
            98765.0
        ]
    );
    assert!(f[0].is_sign_negative());
    assert_eq!(b.joints[1].offset, DVec3::new(-0.24384, 7.07133, 1.2192));
}

#[test]
fn numbers_beyond_the_stated_limits_are_errors() {
    // A rotation of 1e300° (the limit is ±1e5°), with its line and column.
    let text =
        with_line(18, "Frame Time: .0083333").replace("1 2 3 4 5 6 7 8 9", "1 2 3 4 5 6 7 8 1e300");
    fails(
        text,
        19,
        &["value 9 of frame 1", "rotation", "1e300", "±100000"],
    );
    // An OFFSET of 1e308 file units (the limit is ±1e6).
    let text = with_line(18, "Frame Time: .0083333").replace("OFFSET 0 10 0", "OFFSET 0 1e308 0");
    let line = text.lines().position(|l| l.contains("1e308")).unwrap() + 1;
    fails(text, line, &["y of the OFFSET", "±1000000"]);
}

#[test]
fn joint_names_keep_inner_spaces() {
    let b = ok(with_line(6, "\tJOINT  Left Up Leg  "));
    assert_eq!(b.joints[1].name, "Left Up Leg");
    assert_eq!(b.joint_index("Left Up Leg"), Some(1));
}

#[test]
fn six_channels_on_every_joint() {
    let b = ok(with_line(
        9,
        "\t\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
    )
    .replace("Frames: 3", "Frames: 1")
    .replace("1 2 3 4 5 6 7 8 9\n", "1 2 3 4 5 6 7 8 9 10 11 12\n")
    .replace(
        "10 20 30 40 50 60 70 80 90\n-1 -2 -3 -4 -5 -6 -7 -8 -9\n",
        "",
    ));
    assert_eq!(b.channel_count, 12);
    assert_eq!(b.joints[1].channels.len(), 6);
    assert_eq!(b.joints[1].first_channel, 6);
    assert_eq!(&b.frame(0)[6..], [7.0, 8.0, 9.0, 10.0, 11.0, 12.0]);
}

#[test]
fn every_rotation_order_and_channel_arrangement_is_kept() {
    use Channel::*;
    let rots = [Xrotation, Yrotation, Zrotation];
    let orders = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    for order in orders {
        let chest: Vec<Channel> = order.iter().map(|&k| rots[k]).collect();
        // Root: rotations first, then positions, in reverse axis order.
        let root: Vec<Channel> = chest
            .iter()
            .copied()
            .chain([Zposition, Yposition, Xposition])
            .collect();
        let names = |cs: &[Channel]| cs.iter().map(|c| c.name()).collect::<Vec<_>>().join(" ");
        let text = with_line(5, &format!("\tCHANNELS 6 {}", names(&root))).replace(
            "CHANNELS 3 Zrotation Xrotation Yrotation",
            &format!("CHANNELS 3 {}", names(&chest)),
        );
        let b = ok(text);
        assert_eq!(b.joints[0].channels, root);
        assert_eq!(b.joints[1].channels, chest);
        // Values stay in file order: the Chest's first channel is the 7th value.
        assert_eq!(b.frame(1)[b.joints[1].first_channel], 70.0);
        let again = bvh::parse(bvh::to_string(&b).as_bytes()).unwrap().0;
        assert_eq!(again, b);
    }
}

#[test]
fn any_count_of_channels_including_none() {
    let b = ok(with_line(9, "\t\tCHANNELS 0")
        .replace("1 2 3 4 5 6 7 8 9", "1 2 3 4 5 6")
        .replace("10 20 30 40 50 60 70 80 90", "1 2 3 4 5 6")
        .replace("-1 -2 -3 -4 -5 -6 -7 -8 -9", "1 2 3 4 5 6"));
    assert!(b.joints[1].channels.is_empty());
    assert_eq!(b.channel_count, 6);
    let b = ok(with_line(9, "\t\tCHANNELS 1 Yrotation")
        .replace("7 8 9", "7")
        .replace("70 80 90", "70")
        .replace("-7 -8 -9", "-7"));
    assert_eq!(b.joints[1].channels, [Channel::Yrotation]);
    assert_eq!(b.frame(1)[6], 70.0);
}

#[test]
fn several_roots_are_read_in_order() {
    let mut lines: Vec<&str> = BASE[..15].to_vec();
    lines.extend([
        "ROOT Prop",
        "{",
        "OFFSET 1 2 3",
        "CHANNELS 1 Xposition",
        "}",
    ]);
    lines.extend([
        "MOTION",
        "Frames: 1",
        "Frame Time: 0.01",
        "1 2 3 4 5 6 7 8 9 10",
    ]);
    let b = ok(lines.join("\n"));
    assert_eq!(b.joints.len(), 3);
    assert_eq!(b.joints[2].parent, None);
    assert_eq!(b.joints[2].first_channel, 9);
    assert_eq!(b.frame(0)[9], 10.0);
}

#[test]
fn zero_frames_is_a_valid_file() {
    let b = ok(first_lines(18).replace("Frames: 3", "Frames: 0"));
    assert_eq!(b.frame_count(), 0);
    assert!(b.motion.is_empty());
}

#[test]
fn motion_lines_beyond_frames_are_ignored_with_a_warning() {
    let (b, warnings) = bvh::parse(with_line(17, "Frames: 1").as_bytes()).unwrap();
    assert_eq!(b.frame_count(), 1);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert_eq!(warnings[0].line, 20);
    assert!(
        warnings[0].message.contains("2 line(s) after the 1 frames"),
        "{}",
        warnings[0]
    );
}

#[test]
fn blank_lines_inside_the_motion_are_skipped_with_a_warning() {
    let (b, warnings) =
        bvh::parse(with_line(20, "10 20 30 40 50 60 70 80 90\n\n").as_bytes()).unwrap();
    assert_eq!(b, ok(base()));
    assert_eq!(warnings.len(), 1);
    assert_eq!(warnings[0].line, 21);
}

// ---------------------------------------------------------------- malformed input

#[test]
fn empty_and_blank_files() {
    fails("", 1, &["empty", "expected HIERARCHY"]);
    fails("  \n\t\n", 3, &["empty"]);
}

#[test]
fn something_else_than_hierarchy() {
    fails(
        "HIERARCH\nROOT a\n",
        1,
        &["expected HIERARCHY", "`HIERARCH`"],
    );
    fails(with_line(2, "JOINT Hips"), 2, &["expected ROOT", "`JOINT`"]);
}

#[test]
fn truncated_files() {
    fails("HIERARCHY\n", 2, &["the file ends", "expected ROOT"]);
    fails(
        first_lines(2),
        3,
        &["the file ends", "`{` opening joint `Hips`"],
    );
    fails(
        first_lines(9),
        10,
        &[
            "`}` closing joint `Chest` (opened on line 7)",
            "end of the file",
        ],
    );
    fails(
        first_lines(11),
        12,
        &["the file ends", "`OFFSET` of the End Site of joint `Chest`"],
    );
    fails(first_lines(15), 16, &["expected MOTION"]);
    fails(first_lines(16), 17, &["the file ends", "`Frames:`"]);
    fails(first_lines(17), 18, &["the file ends", "`Frame Time:`"]);
    fails(
        first_lines(18),
        19,
        &["ends after 0 of the 3 frames declared on line 17"],
    );
    fails(
        first_lines(20),
        21,
        &["ends after 2 of the 3 frames declared on line 17"],
    );
    // Cut inside the last frame's line.
    let cut = base();
    fails(
        &cut[..cut.len() - 7],
        21,
        &["expected 9 numbers in frame 3, found 7"],
    );
    // Cut inside an OFFSET.
    fails(
        &first_lines(8)[..first_lines(8).len() - 3],
        8,
        &["the file ends", "z of the OFFSET of joint `Chest`"],
    );
}

#[test]
fn frame_count_larger_than_the_lines_present() {
    let e = fails(
        with_line(17, "Frames: 5"),
        22,
        &["ends after 3 of the 5 frames declared on line 17 (`Frames: 5`)"],
    );
    assert!(matches!(
        e,
        BvhError::MissingFrames {
            found: 3,
            declared: 5,
            ..
        }
    ));
}

#[test]
fn wrong_value_counts_per_frame() {
    fails(
        with_line(19, "1 2 3 4 5 6 7 8"),
        19,
        &["expected 9 numbers in frame 1, found 8", "one line"],
    );
    fails(
        with_line(20, "10 20 30 40 50 60 70 80 90 100"),
        20,
        &["expected 9 numbers in frame 2, found 10"],
    );
    // Two frames joined on one line.
    fails(
        with_line(19, "1 2 3 4 5 6 7 8 9 10 20 30 40 50 60 70 80 90"),
        19,
        &[
            "expected 9 numbers in frame 1, found 18",
            "exactly one line",
        ],
    );
    // One frame split over two lines.
    fails(
        with_line(19, "1 2 3 4 5\n6 7 8 9"),
        19,
        &["expected 9 numbers in frame 1, found 5"],
    );
}

#[test]
fn non_numbers_in_the_motion() {
    let e = fails(
        with_line(20, "10 20 abc 40 50 60 70 80 90"),
        20,
        &[
            "column 7",
            "expected a number (value 3 of frame 2)",
            "found `abc`",
        ],
    );
    assert_eq!(e.column(), Some(7));
    fails(
        with_line(19, "1 2 3 4 5 6 7 8 9,"),
        19,
        &["value 9 of frame 1", "`9,`"],
    );
    fails(with_line(19, "1 2 3 4 5 6 7 8 1.2.3"), 19, &["`1.2.3`"]);
    fails(
        with_line(19, "1 2 3 4 5 6 7 8 \u{0}"),
        19,
        &["value 9", "`\\0`"],
    );
}

#[test]
fn nan_and_infinity_are_rejected() {
    for bad in ["nan", "NaN", "inf", "-inf", "infinity", "1e400"] {
        let line = format!("1 {bad} 3 4 5 6 7 8 9");
        fails(
            with_line(19, &line),
            19,
            &["value 2 of frame 1", bad, "expected a finite number"],
        );
    }
    fails(
        with_line(8, "\t\tOFFSET 0 NaN 0"),
        8,
        &["y of the OFFSET of joint `Chest`", "finite"],
    );
    fails(
        with_line(12, "\t\t\tOFFSET inf 5 0"),
        12,
        &["x of the OFFSET of the End Site of joint `Chest`"],
    );
}

#[test]
fn non_numbers_in_the_hierarchy() {
    fails(
        with_line(8, "\t\tOFFSET 0 ten 0"),
        8,
        &[
            "column 12",
            "a number (y of the OFFSET of joint `Chest`)",
            "`ten`",
        ],
    );
    fails(
        with_line(8, "\t\tOFFSET 0 10"),
        9,
        &["z of the OFFSET of joint `Chest`", "`CHANNELS`"],
    );
    fails(
        with_line(9, "\t\tCHANNELS three Zrotation"),
        9,
        &["the channel count of joint `Chest`", "`three`"],
    );
    fails(
        with_line(5, "\tCHANNELS"),
        5,
        &["channel count of joint `Hips`", "end of the line"],
    );
}

#[test]
fn hierarchy_without_motion() {
    fails(
        first_lines(15),
        16,
        &["after the hierarchy, expected MOTION"],
    );
    fails(
        with_line(16, "MOTON"),
        16,
        &["expected ROOT or MOTION", "`MOTON`"],
    );
    fails(
        with_line(16, "MOTION").replace("Frames: 3", "Frame: 3"),
        17,
        &["expected `Frames:` after MOTION", "`Frame:`"],
    );
}

#[test]
fn unbalanced_braces() {
    // A missing `}`: MOTION arrives while Hips is still open.
    fails(
        without_line(14),
        15,
        &[
            "expected `}` closing joint `Hips` (opened on line 3)",
            "`MOTION`",
        ],
    );
    // One `}` too many.
    let e = fails(with_line(15, "}\n}"), 16, &["`}` without a matching `{`"]);
    assert_eq!(e.column(), Some(1));
    // A missing `{`.
    fails(
        without_line(7),
        7,
        &["expected `{` opening joint `Chest`", "`OFFSET`"],
    );
    // End Site not closed: its `}` is taken from Chest, so Hips is left open.
    fails(
        without_line(13),
        15,
        &["expected `}` closing joint `Hips`", "`MOTION`"],
    );
    // End Site followed by something else than `}`.
    fails(
        with_line(13, "\t\tOFFSET 1 1 1"),
        13,
        &["`}` closing the End Site of joint `Chest`", "`OFFSET`"],
    );
}

#[test]
fn missing_offset_or_channels() {
    fails(
        without_line(8),
        9,
        &[
            "joint `Chest` has no OFFSET",
            "expected OFFSET before `End`",
        ],
    );
    fails(
        without_line(5),
        5,
        &["joint `Hips` has no CHANNELS", "before `JOINT`"],
    );
    fails(
        without_line(12),
        12,
        &["expected `OFFSET` of the End Site of joint `Chest`", "`}`"],
    );
    // A leaf joint without CHANNELS, closed straight away.
    let leaf = with_line(10, "\t\tJOINT Head\n\t\t{\n\t\t\tOFFSET 0 1 0\n\t\t}");
    fails(leaf, 13, &["joint `Head` has no CHANNELS", "before `}`"]);
    // Duplicates.
    fails(
        with_line(9, "\t\tOFFSET 1 1 1"),
        9,
        &["joint `Chest` has a second OFFSET"],
    );
    fails(
        with_line(4, "\tCHANNELS 1 Xrotation"),
        5,
        &["joint `Hips` has a second CHANNELS line"],
    );
}

#[test]
fn unknown_channel_names_and_wrong_channel_counts() {
    let e = fails(
        with_line(9, "\t\tCHANNELS 3 Zrotation Xrotation Wrotation"),
        9,
        &["unknown channel name `Wrotation`", "Xposition, Yposition"],
    );
    assert_eq!(e.column(), Some(34));
    fails(
        with_line(9, "\t\tCHANNELS 3 Zrotation Xrotation"),
        9,
        &[
            "column 33: expected 3 channel names for joint `Chest` (2 given on the CHANNELS line)",
            "found the end of the line",
        ],
    );
    fails(
        with_line(9, "\t\tCHANNELS 2 Zrotation Xrotation Yrotation"),
        9,
        &[
            "end of the line after the 2 channels of joint `Chest`",
            "`Yrotation`",
        ],
    );
}

#[test]
fn non_utf8_bytes_name_their_line() {
    let mut bytes = base().into_bytes();
    let at = base().find("Chest").unwrap() + 2;
    bytes[at] = 0xff;
    let e = fails(&bytes, 6, &["invalid UTF-8", "column 10"]);
    assert!(matches!(
        e,
        BvhError::InvalidUtf8 {
            line: 6,
            column: 10
        }
    ));
    let mut bytes = base().into_bytes();
    let at = base().find("-5").unwrap();
    bytes[at] = 0xc3; // a lead byte followed by ASCII
    fails(&bytes, 21, &["invalid UTF-8"]);
}

#[test]
fn frame_time_must_be_positive_and_finite() {
    for bad in ["0", "-0.0333", "nan", "inf", "-0"] {
        fails(
            with_line(18, &format!("Frame Time: {bad}")),
            18,
            &["Frame Time is", bad, "positive finite"],
        );
    }
    fails(
        with_line(18, "Frame Time: fast"),
        18,
        &["a number of seconds", "`fast`"],
    );
    fails(
        with_line(18, "Frame Time: 0.03 1 2"),
        18,
        &["end of the line after `Frame Time:`"],
    );
    fails(
        with_line(18, "Frame Tim: 0.03"),
        18,
        &["column 7: expected `Time:` after `Frame`, found `Tim:`"],
    );
    fails(
        with_line(18, "Frame"),
        18,
        &["expected `Time:` after `Frame`, found the end of the line"],
    );
    fails(
        with_line(18, "Frame: 0.03"),
        18,
        &["expected `Frame Time:`", "`Frame:`"],
    );
}

#[test]
fn frames_must_be_a_whole_number() {
    fails(
        with_line(17, "Frames: 2.5"),
        17,
        &["a whole number of frames", "`2.5`"],
    );
    fails(with_line(17, "Frames: -1"), 17, &["`-1`"]);
    fails(
        with_line(17, "Frames:"),
        17,
        &["the frame count after `Frames:`"],
    );
}

#[test]
fn frames_without_channels() {
    let text = "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 0\n}\nMOTION\nFrames: 2\nFrame Time: 0.1\n\n\n";
    fails(
        text,
        8,
        &["`Frames: 2` but the hierarchy declares no channels"],
    );
    let none =
        "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 0\n}\nMOTION\nFrames: 0\nFrame Time: 0.1\n";
    assert_eq!(ok(none).frame_count(), 0);
}

#[test]
fn a_huge_frame_count_is_an_error_not_an_allocation() {
    fails(
        with_line(17, &format!("Frames: {}", usize::MAX)),
        22,
        &["ends after 3 of the"],
    );
}

#[test]
fn parse_file_errors_name_the_file() {
    let dir = std::env::temp_dir().join(format!("marionette-bvh-reader-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.bvh");
    std::fs::write(&path, with_line(19, "1 2 3")).unwrap();
    let e = bvh::parse_file(&path).unwrap_err();
    let msg = e.to_string();
    assert!(msg.starts_with(&path.display().to_string()), "{msg}");
    assert!(
        msg.contains("line 19: expected 9 numbers in frame 1, found 3"),
        "{msg}"
    );
    assert_eq!(e.line(), Some(19));

    let missing = dir.join("missing.bvh");
    let e = bvh::parse_file(&missing).unwrap_err();
    assert!(matches!(e, BvhError::Io { .. }));
    assert!(e.to_string().contains("missing.bvh"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn a_value_or_a_frame_missing_from_the_jumps_file() {
    let Some(dir) = data_dir() else { return };
    let text = std::fs::read_to_string(dir.join("cmu/cmu_01_01_forward_jumps.bvh")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 2939);
    // Line 188 is frame 1; drop its last value.
    let mut short = lines.clone();
    short[187] = lines[187].trim_end().rsplit_once(' ').unwrap().0;
    let e = fails(short.join("\n"), 188, &[]);
    assert_eq!(
        e.to_string(),
        "line 188: expected 96 numbers in frame 1, found 95 (a BVH frame is exactly one line of values)"
    );
    // The last frame (line 2939) missing altogether.
    let cut = lines[..2938].join("\n") + "\n";
    fails(
        cut,
        2939,
        &["ends after 2751 of the 2752 frames declared on line 186"],
    );
}
