//! Speed of the pictures: a 2000-frame (120 Hz, 16.7 s) walking clip as a 25 fps GIF, one pose
//! PNG, a 6-column filmstrip and a two-series plot.
//!
//! Run: `cargo bench --bench render`.

use std::f64::consts::PI;
use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;
use marionette::render::{
    Plot, Series, StickFigure, Track, animation_gif, filmstrip_png, plot, pose_png,
};

/// A 16-point walker at 120 Hz: legs and arms swing at 1 Hz, the body advances 1.2 m/s along +Z.
fn walker(frames: usize) -> (StickFigure, Vec<Vec<DVec3>>) {
    let names = [
        "Hips",
        "Spine",
        "Neck",
        "Head",
        "LeftShoulder",
        "LeftElbow",
        "LeftHand",
        "RightShoulder",
        "RightElbow",
        "RightHand",
        "LeftHip",
        "LeftKnee",
        "LeftFoot",
        "RightHip",
        "RightKnee",
        "RightFoot",
    ];
    let parents = vec![
        None,
        Some(0),
        Some(1),
        Some(2),
        Some(2),
        Some(4),
        Some(5),
        Some(2),
        Some(7),
        Some(8),
        Some(0),
        Some(10),
        Some(11),
        Some(0),
        Some(13),
        Some(14),
    ];
    let fig = StickFigure {
        names: names.map(String::from).to_vec(),
        parents,
    };
    let clip = (0..frames)
        .map(|k| {
            let t = k as f64 / 120.0;
            let ph = 2.0 * PI * t;
            let hips = DVec3::new(0.0, 0.95 + 0.02 * (2.0 * ph).cos(), 1.2 * t);
            let spine = hips + DVec3::new(0.0, 0.3, 0.0);
            let neck = spine + DVec3::new(0.0, 0.25, 0.0);
            let mut v = vec![hips, spine, neck, neck + DVec3::new(0.0, 0.2, 0.03)];
            for s in [1.0, -1.0] {
                let sh = neck + DVec3::new(0.18 * s, -0.03, 0.0);
                let a = -0.4 * s * ph.sin();
                let el = sh + DVec3::new(0.03 * s, -0.28 * a.cos(), 0.28 * a.sin());
                let b = a + 0.3;
                v.extend([
                    sh,
                    el,
                    el + DVec3::new(0.0, -0.25 * b.cos(), 0.25 * b.sin()),
                ]);
            }
            for s in [1.0, -1.0] {
                let hip = hips + DVec3::new(0.1 * s, -0.05, 0.0);
                let a = 0.45 * s * ph.sin();
                let kn = hip + DVec3::new(0.0, -0.42 * a.cos(), 0.42 * a.sin());
                let b = a - 0.3;
                v.extend([
                    hip,
                    kn,
                    kn + DVec3::new(0.0, -0.42 * b.cos(), 0.42 * b.sin()),
                ]);
            }
            v
        })
        .collect();
    (fig, clip)
}

fn bench(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("marionette-bench-render-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (fig, frames) = walker(2000);
    let track = Track {
        figure: &fig,
        frames: &frames,
        label: "walker".into(),
        frame_time: 1.0 / 120.0,
    };
    let tracks = [track.clone()];
    let mut g = c.benchmark_group("render");
    g.sample_size(10);
    g.bench_function("gif_2000_frames_at_25fps", |b| {
        b.iter(|| animation_gif(black_box(&tracks), 25.0, &dir.join("walk.gif")).unwrap())
    });
    g.bench_function("pose_png", |b| {
        b.iter(|| pose_png(black_box(&track), 500, &dir.join("pose.png")).unwrap())
    });
    g.bench_function("filmstrip_png_6", |b| {
        b.iter(|| filmstrip_png(black_box(&tracks), 6, &dir.join("strip.png")).unwrap())
    });
    let p = Plot {
        title: "bench".into(),
        x_label: "time (s)".into(),
        y_label: "angle (°)".into(),
        series: (0..2)
            .map(|i| Series {
                name: format!("s{i}"),
                points: (0..2000)
                    .map(|k| (k as f64 / 120.0, (k as f64 / 40.0 + i as f64).sin()))
                    .collect(),
            })
            .collect(),
        markers: vec![(3.0, "event".into())],
    };
    g.bench_function("plot_png_2x2000", |b| {
        b.iter(|| plot(black_box(&p), &dir.join("plot.png")).unwrap())
    });
    g.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, bench);
criterion_main!(benches);
