//! Whole-feature tests of `marionette::render`: files are written and decode, the views put the
//! figure's sides where they belong, bad input is an error, plots write PNG and SVG.

use std::f64::consts::PI;
use std::path::PathBuf;

use glam::DVec3;
use marionette::render::{
    Plot, RenderError, Series, StickFigure, Track, View, animation_gif, filmstrip_png,
    filmstrip_view_png, plot, pose_png,
};

/// A fresh directory for one test's outputs.
fn out_dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("marionette-render-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A 5-point stick man: hips, chest, head, left hand, right hand (arms out along ±X).
fn stick_man() -> (StickFigure, Vec<DVec3>) {
    let fig = StickFigure {
        names: ["Hips", "Chest", "Head", "LeftHand", "RightHand"]
            .map(String::from)
            .to_vec(),
        parents: vec![None, Some(0), Some(1), Some(1), Some(1)],
    };
    let pose = vec![
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(0.0, 1.4, 0.0),
        DVec3::new(0.0, 1.7, 0.0),
        DVec3::new(0.7, 1.4, 0.0),
        DVec3::new(-0.7, 1.4, 0.0),
    ];
    (fig, pose)
}

/// A pendulum of length 1 m hanging from (0, 2, 0), swinging ±40° in the X–Y plane at 120 Hz.
fn pendulum(seconds: f64) -> (StickFigure, Vec<Vec<DVec3>>) {
    let fig = StickFigure {
        names: vec!["Pivot".into(), "Bob".into()],
        parents: vec![None, Some(0)],
    };
    let n = (seconds * 120.0).round() as usize + 1;
    let frames = (0..n)
        .map(|k| {
            let t = k as f64 / 120.0;
            let a = 40f64.to_radians() * (2.0 * PI * t / 2.0).cos();
            let pivot = DVec3::new(0.0, 2.0, 0.0);
            vec![pivot, pivot + DVec3::new(a.sin(), -a.cos(), 0.0)]
        })
        .collect();
    (fig, frames)
}

/// Logical screen size of a GIF.
fn dec_size(path: &std::path::Path) -> (u16, u16) {
    let d = gif::DecodeOptions::new()
        .read_info(std::fs::File::open(path).unwrap())
        .unwrap();
    (d.width(), d.height())
}

fn png_size(path: &std::path::Path) -> (u32, u32) {
    let p = tiny_skia::Pixmap::load_png(path).expect("a decodable PNG");
    (p.width(), p.height())
}

/// Mean x of the pixels in the limb colour of `side` at any shade (blue for the left,
/// vermillion for the right) in the top 80 % of the picture (above the footer with the colour
/// key), and their count.
fn mean_x_of_colour(path: &std::path::Path, side: [u8; 3]) -> (f64, usize) {
    let p = tiny_skia::Pixmap::load_png(path).unwrap();
    let w = p.width() as usize;
    let rows = p.height() as usize * 4 / 5;
    let (mut sum, mut n) = (0.0, 0usize);
    for (i, c) in p.pixels()[..rows * w].iter().enumerate() {
        let (r, g, b) = (c.red() as i32, c.green() as i32, c.blue() as i32);
        let hit = if side == LEFT {
            b > r + 50 && b > g
        } else {
            r > b + 80 && r > g + 40
        };
        if hit {
            sum += (i % w) as f64;
            n += 1;
        }
    }
    (sum / n.max(1) as f64, n)
}

const LEFT: [u8; 3] = [0, 114, 178];
const RIGHT: [u8; 3] = [213, 94, 0];

#[test]
fn front_view_shows_the_figures_left_on_the_viewers_right() {
    let (fig, pose) = stick_man();
    let frames = vec![pose];
    let t = Track {
        figure: &fig,
        frames: &frames,
        label: "stick man".into(),
        frame_time: 1.0 / 30.0,
    };
    let dir = out_dir("front");
    let path = dir.join("front.png");
    filmstrip_view_png(&[t], 1, View::Front, &path).unwrap();
    let (lx, ln) = mean_x_of_colour(&path, LEFT);
    let (rx, rn) = mean_x_of_colour(&path, RIGHT);
    assert!(
        ln > 50 && rn > 50,
        "both arms drawn: {ln} left, {rn} right pixels"
    );
    // Each arm reaches 0.7 m from the mid-line: the means are 0.7 m ≈ 79 px apart at this scale
    // (less the round ends and the thicker girdles near the middle).
    assert!(lx > rx + 50.0, "left arm at mean x {lx}, right arm at {rx}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn three_quarter_view_from_the_front_left_puts_a_forward_leg_on_screen_left() {
    // Legs in a stride: left foot forward (+Z), right foot back; the hips say where the figure
    // faces (+Z, its left +X). Without motion the filmstrip looks from 45° on the figure's left,
    // where forward is towards screen left (as in the side view it used before).
    let fig = StickFigure {
        names: ["Hips", "LeftHip", "LeftFoot", "RightHip", "RightFoot"]
            .map(String::from)
            .to_vec(),
        parents: vec![None, Some(0), Some(1), Some(0), Some(3)],
    };
    let frames = vec![vec![
        DVec3::new(0.0, 0.9, 0.0),
        DVec3::new(0.1, 0.9, 0.0),
        DVec3::new(0.1, 0.0, 0.45),
        DVec3::new(-0.1, 0.9, 0.0),
        DVec3::new(-0.1, 0.0, -0.45),
    ]];
    let t = Track {
        figure: &fig,
        frames: &frames,
        label: String::new(),
        frame_time: 0.01,
    };
    let dir = out_dir("side");
    let path = dir.join("side.png");
    filmstrip_png(&[t], 1, &path).unwrap();
    let (lx, _) = mean_x_of_colour(&path, LEFT);
    let (rx, _) = mean_x_of_colour(&path, RIGHT);
    assert!(
        lx + 20.0 < rx,
        "left (forward) leg at mean x {lx}, right at {rx}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn pose_filmstrip_and_gif_are_written_and_decode() {
    let (fig, frames) = pendulum(2.0);
    let (fig2, frames2) = pendulum(1.0);
    let tracks = [
        Track {
            figure: &fig,
            frames: &frames,
            label: "pendulum 2 s".into(),
            frame_time: 1.0 / 120.0,
        },
        Track {
            figure: &fig2,
            frames: &frames2,
            label: "pendulum 1 s".into(),
            frame_time: 1.0 / 120.0,
        },
    ];
    let dir = out_dir("files");

    let pose = dir.join("pose.png");
    pose_png(&tracks[0], 60, &pose).unwrap();
    let (w, h) = png_size(&pose);
    assert!(h >= 360 && w >= 3 * 198, "pose picture {w}×{h}");

    let strip = dir.join("strip.png");
    filmstrip_png(&tracks, 6, &strip).unwrap();
    let (sw, sh) = png_size(&strip);
    assert!(sw > 6 * 99 && sh > 2 * 220, "filmstrip {sw}×{sh}");

    let gif_path = dir.join("anim.gif");
    animation_gif(&tracks, 25.0, &gif_path).unwrap();
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::Indexed);
    let mut dec = opts
        .read_info(std::fs::File::open(&gif_path).unwrap())
        .unwrap();
    let palette = dec.global_palette().unwrap().to_vec();
    let mut count = 0;
    let mut delays = 0u32;
    let mut first_frame_colours = Vec::new();
    while let Some(f) = dec.read_next_frame().unwrap() {
        if count == 0 {
            // The first frame is the whole page.
            assert_eq!((f.width, f.height), (dec_size(&gif_path)));
            first_frame_colours = f
                .buffer
                .iter()
                .map(|&i| &palette[3 * i as usize..3 * i as usize + 3])
                .map(|c| [c[0], c[1], c[2]])
                .collect();
        }
        count += 1;
        delays += f.delay as u32;
    }
    // The palette keeps the drawing's colours: the white page, the black text, and the
    // pendulum's rod in at least three shades of grey between its shadow and its highlight.
    let has = |rgb: [u8; 3]| first_frame_colours.contains(&rgb);
    assert!(has([255, 255, 255]) && has([30, 30, 30]));
    let mut greys: Vec<u8> = first_frame_colours
        .iter()
        .filter(|c| c[0] == c[1] && c[1] == c[2] && (60..=190).contains(&c[0]))
        .map(|c| c[0])
        .collect();
    greys.sort_unstable();
    greys.dedup();
    assert!(greys.len() >= 3, "shades of grey: {greys:?}");
    // 2 s at 25 frames per second: t = 0, 0.04, …, 2.0.
    assert_eq!(count, 51);
    assert_eq!(delays, 204, "51 frames of 4 hundredths of a second");
    // One three-quarter panel per track, each at least 192 pixels wide.
    assert!(dec.width() as u32 > 2 * 192);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn non_finite_and_miscounted_input_is_an_error_and_writes_nothing() {
    let (fig, pose) = stick_man();
    let mut bad = pose.clone();
    bad[3].x = f64::NAN;
    let frames = vec![pose.clone(), bad];
    let t = Track {
        figure: &fig,
        frames: &frames,
        label: "nan".into(),
        frame_time: 0.1,
    };
    let dir = out_dir("bad");
    let path = dir.join("x.png");
    match pose_png(&t, 0, &path) {
        Err(RenderError::NonFinite {
            frame, point, name, ..
        }) => assert_eq!((frame, point, name.as_str()), (1, 3, "LeftHand")),
        other => panic!("expected NonFinite, got {other:?}"),
    }
    assert!(!path.exists());
    let gif_path = dir.join("x.gif");
    assert!(matches!(
        animation_gif(std::slice::from_ref(&t), 25.0, &gif_path),
        Err(RenderError::NonFinite { .. })
    ));

    let short = vec![pose.clone(), pose[..4].to_vec()];
    let t = Track {
        frames: &short,
        ..t
    };
    let err = filmstrip_png(std::slice::from_ref(&t), 3, &path).unwrap_err();
    assert!(matches!(
        err,
        RenderError::PointCount {
            frame: 1,
            got: 4,
            expected: 5,
            ..
        }
    ));
    assert!(err.to_string().contains("frame 1 has 4 points"), "{err}");

    assert!(matches!(
        filmstrip_png(&[], 3, &path),
        Err(RenderError::Empty(_))
    ));
    let ok = vec![pose];
    let t = Track { frames: &ok, ..t };
    assert!(matches!(
        pose_png(&t, 5, &path),
        Err(RenderError::FrameOutOfRange {
            frame: 5,
            len: 1,
            ..
        })
    ));
    assert!(matches!(
        pose_png(&t, 0, &dir.join("x.jpg")),
        Err(RenderError::UnsupportedExtension { .. })
    ));
    assert!(matches!(
        animation_gif(std::slice::from_ref(&t), 0.0, &gif_path),
        Err(RenderError::InvalidArgument(_))
    ));
    assert!(!path.exists() && !gif_path.exists());
    let nowhere = std::path::Path::new("/nonexistent-marionette-dir/x.png");
    assert!(matches!(
        pose_png(&t, 0, nowhere),
        Err(RenderError::Io { .. })
    ));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn extreme_but_finite_input_gives_a_picture_or_an_error_never_a_panic() {
    let (fig, pose) = stick_man();
    let mut far = pose.clone();
    far[3] = DVec3::new(1e12, 1.4, -1e12); // a hand a billion kilometres away
    let frames = vec![pose.clone(), far];
    let t = Track {
        figure: &fig,
        frames: &frames,
        label: "far".into(),
        frame_time: 1e-300,
    };
    let dir = out_dir("extreme");
    // The panel is capped, the far hand drawn off it: a picture of bounded size.
    pose_png(&t, 1, &dir.join("far.png")).unwrap();
    let (w, h) = png_size(&dir.join("far.png"));
    assert!(w <= 3 * 4096 + 100 && h < 1000, "{w}×{h}");
    animation_gif(std::slice::from_ref(&t), 25.0, &dir.join("far.gif")).unwrap();
    // Too many columns or too long a GIF are errors.
    assert!(matches!(
        filmstrip_png(std::slice::from_ref(&t), 1_000_000, &dir.join("wide.png")),
        Err(RenderError::InvalidArgument(_))
    ));
    let slow = Track {
        frame_time: 1e300,
        ..t
    };
    assert!(matches!(
        animation_gif(std::slice::from_ref(&slow), 25.0, &dir.join("long.gif")),
        Err(RenderError::InvalidArgument(_))
    ));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn plot_of_two_series_writes_png_and_svg() {
    let p = Plot {
        title: "Pendulum".into(),
        x_label: "time (s)".into(),
        y_label: "angle (°)".into(),
        series: vec![
            Series {
                name: "40° swing".into(),
                points: (0..200)
                    .map(|k| {
                        let t = k as f64 / 100.0;
                        (t, 40.0 * (PI * t).cos())
                    })
                    .collect(),
            },
            Series {
                name: "20° swing".into(),
                points: (0..200)
                    .map(|k| {
                        let t = k as f64 / 100.0;
                        (t, 20.0 * (PI * t).cos())
                    })
                    .collect(),
            },
        ],
        markers: vec![(0.5, "lowest".into()), (1.0, "turn".into())],
    };
    let dir = out_dir("plot");
    let png = dir.join("plot.png");
    plot(&p, &png).unwrap();
    assert_eq!(png_size(&png), (900, 540));
    let svg = dir.join("plot.SVG");
    plot(&p, &svg).unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg"), "{}", &text[..text.len().min(80)]);
    for needle in ["Pendulum", "time (s)", "40° swing", "20° swing", "turn"] {
        assert!(text.contains(needle), "SVG lacks {needle:?}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}
