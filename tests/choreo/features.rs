//! Segment features on the project's own keyframed dance (`scenes/clips/dance_bars.ron`, four
//! bars at 120 BPM on humanoid24): Eros finds a bar most similar to itself, the mirror image of
//! a lopsided bar less similar than itself (and a symmetric bar's the same), and the motion
//! intensity W(f) tells the bars apart.

use std::path::Path;

use glam::DVec3;
use marionette::choreo::{eros, eros_weights, pca};
use marionette::choreo::{mean_motion_intensity, mirror_motion, mirror_partners, pose_rows};
use marionette::clips::KeyframeClip;

/// The dance's joint positions per frame, its joint names and its frame rate.
fn dance() -> (Vec<Vec<DVec3>>, Vec<String>, f64) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/clips/dance_bars.ron");
    let clip = KeyframeClip::load(&path)
        .unwrap()
        .to_figure_clip()
        .to_clip();
    let mut g = Vec::new();
    let pos = (0..clip.frame_count())
        .map(|f| {
            clip.globals(f, &mut g);
            g.iter().map(|t| t.translation).collect()
        })
        .collect();
    let names = clip
        .skeleton
        .joints
        .iter()
        .map(|j| j.name.clone())
        .collect();
    (pos, names, 1.0 / clip.frame_time)
}

#[test]
fn a_bar_is_most_like_itself_and_less_like_its_mirror() {
    let (pos, names, fps) = dance();
    let bar = (2.0 * fps).round() as usize; // 120 BPM: a bar of 4 beats is 2 s
    let bars: Vec<&[Vec<DVec3>]> = pos.chunks_exact(bar).collect();
    assert_eq!(bars.len(), 4);
    let partners = mirror_partners(&names);
    assert!(
        partners.iter().enumerate().any(|(i, &p)| p != i),
        "no left/right pairs"
    );
    let pcas: Vec<_> = bars.iter().map(|b| pca(&pose_rows(b, 0))).collect();
    let mirrors: Vec<_> = bars
        .iter()
        .map(|b| pca(&pose_rows(&mirror_motion(b, &partners), 0)))
        .collect();
    let all: Vec<_> = pcas.iter().chain(&mirrors).collect();
    let w = eros_weights(&all);
    for (k, p) in pcas.iter().enumerate() {
        let own = eros(p, p, &w);
        assert!((own - 1.0).abs() < 1e-9, "bar {k}: {own}");
        let mirror = eros(p, &mirrors[k], &w);
        if k < 3 {
            // Bars 1–3 (step-touch with one arm up, arm waves, a turn) are lopsided.
            assert!(
                mirror < own - 1e-3,
                "bar {k}: mirror {mirror} vs self {own}"
            );
        } else {
            // Bar 4, the squat with both arms up, is its own mirror image.
            assert!(mirror > 1.0 - 1e-6, "bar {k}: mirror {mirror}");
        }
        for (j, q) in pcas.iter().enumerate().filter(|&(j, _)| j != k) {
            let other = eros(p, q, &w);
            assert!(other < own, "bar {k} vs bar {j}: {other}");
        }
    }
}

#[test]
fn motion_intensity_of_the_bars_is_positive_and_differs() {
    let (pos, names, fps) = dance();
    let bar = (2.0 * fps).round() as usize;
    let alpha = vec![1.0; names.len()];
    let w: Vec<f64> = pos
        .chunks_exact(bar)
        .map(|b| mean_motion_intensity(b, fps, &alpha))
        .collect();
    assert!(w.iter().all(|&x| x > 0.1), "{w:?}");
    let (lo, hi) = w
        .iter()
        .fold((f64::MAX, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
    assert!(hi > 1.2 * lo, "{w:?}");
    // A still dancer has none.
    let still: Vec<Vec<DVec3>> = vec![pos[0].clone(); 30];
    assert_eq!(mean_motion_intensity(&still, fps, &alpha), 0.0);
}
