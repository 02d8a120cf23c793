//! Synthetic demonstrations made in code (no motion-capture files needed): a smooth 24-DOF
//! clip of the paper's humanoid, a knee-flexion curve of a vertical jump, and a jump's root
//! height. Used by tests, benches and demo scenes.

use super::error::Result;
use super::trajectory::Trajectory;

/// The 24 joint DOFs of the paper's humanoid (waist 2, each clavicle 2, each shoulder 3, each
/// elbow 2, each hip 3, each knee 1), named as in the engine's `humanoid24` model.
pub const HUMANOID24_DOF_NAMES: [&str; 24] = [
    "waist_flexion",
    "waist_lateral",
    "right_clavicle_elevation",
    "right_clavicle_protraction",
    "right_shoulder_flexion",
    "right_shoulder_abduction",
    "right_shoulder_rotation",
    "right_elbow_flexion",
    "right_elbow_pronation",
    "left_clavicle_elevation",
    "left_clavicle_protraction",
    "left_shoulder_flexion",
    "left_shoulder_abduction",
    "left_shoulder_rotation",
    "left_elbow_flexion",
    "left_elbow_pronation",
    "right_hip_flexion",
    "right_hip_abduction",
    "right_hip_rotation",
    "right_knee",
    "left_hip_flexion",
    "left_hip_abduction",
    "left_hip_rotation",
    "left_knee",
];

/// SplitMix64: a tiny deterministic generator for the synthetic parameters.
fn splitmix(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// A smooth demonstration of the 24 humanoid DOFs: each DOF is an offset plus three sinusoids
/// (0.15–0.9 Hz, amplitudes 5°–30° in total, random phases, so the clip starts mid-motion),
/// `frames` frames at `fps`. Deterministic in `seed`.
pub fn smooth_humanoid24(frames: usize, fps: f64, seed: u64) -> Result<Trajectory> {
    let mut st = seed;
    let names: Vec<String> = HUMANOID24_DOF_NAMES.iter().map(|s| s.to_string()).collect();
    let deg = std::f64::consts::PI / 180.0;
    let columns: Vec<Vec<f64>> = names
        .iter()
        .map(|_| {
            let offset = (splitmix(&mut st) - 0.5) * 40.0 * deg;
            let comps: Vec<(f64, f64, f64)> = (0..3)
                .map(|_| {
                    let a = (2.0 + 8.0 * splitmix(&mut st)) * deg;
                    let f = 0.15 + 0.75 * splitmix(&mut st);
                    let ph = std::f64::consts::TAU * splitmix(&mut st);
                    (a, f, ph)
                })
                .collect();
            (0..frames)
                .map(|k| {
                    let t = k as f64 / fps;
                    offset
                        + comps
                            .iter()
                            .map(|(a, f, ph)| a * (std::f64::consts::TAU * f * t + ph).sin())
                            .sum::<f64>()
                })
                .collect()
        })
        .collect();
    Trajectory::from_columns(1.0 / fps, names, &columns)
}

/// Knee flexion (radians) of a standing vertical jump lasting `duration` s, sampled at `fps`:
/// 5° standing, a crouch to `peak_flexion` at 30 % of the clip, extension at take-off, a landing
/// flexion of 40 % of the peak at 78 %, standing again at the end (starts and ends at rest).
pub fn knee_jump(peak_flexion: f64, duration: f64, fps: f64) -> Vec<f64> {
    let n = (duration * fps).round() as usize + 1;
    let stand = 5f64.to_radians();
    (0..n)
        .map(|k| {
            let x = k as f64 / (n - 1) as f64;
            let bump = |c: f64, w: f64| (-((x - c) / w).powi(2)).exp();
            // Window that is 0 with zero slope at both ends keeps start and end at rest.
            let win = (std::f64::consts::PI * x).sin().powi(2);
            stand + win * (peak_flexion * bump(0.3, 0.1) + 0.4 * peak_flexion * bump(0.78, 0.07))
        })
        .collect()
}

/// A synthetic standing vertical jump sampled at `fps`: root height (m) and the lowest foot
/// height (m) per frame, with the true event times.
///
/// Standing at 0.95 m until 0.5 s; a cosine crouch to 0.70 m at 0.9 s (Bend); a push (cubic
/// Hermite) to take-off at 1.2 s at 1.00 m moving up at 2.5 m/s; a ballistic flight (g = 9.81)
/// peaking at 1.2 + 2.5/g s (Leap) and landing at 1.0 m at 1.2 + 5/g s (Land); absorption to
/// 0.80 m in 0.25 s, a rise back to 0.95 m in 0.5 s, standing until 3 s. Feet are at 0.08 m except
/// in flight, where they rise with the root.
pub fn jump_root_height(fps: f64) -> (Vec<f64>, Vec<f64>, super::events::JumpEvents) {
    const G: f64 = 9.81;
    let (stand, low, to_h, v0) = (0.95, 0.70, 1.00, 2.5);
    let t_bend = 0.9;
    let t_to = 1.2;
    let t_flight = 2.0 * v0 / G;
    let t_land = t_to + t_flight;
    let hermite = |s: f64, p0: f64, m0: f64, p1: f64, m1: f64| {
        let (s2, s3) = (s * s, s * s * s);
        (2.0 * s3 - 3.0 * s2 + 1.0) * p0
            + (s3 - 2.0 * s2 + s) * m0
            + (-2.0 * s3 + 3.0 * s2) * p1
            + (s3 - s2) * m1
    };
    let n = (3.0 * fps).round() as usize + 1;
    let mut root = Vec::with_capacity(n);
    let mut foot = Vec::with_capacity(n);
    for k in 0..n {
        let t = k as f64 / fps;
        let y = if t < 0.5 {
            stand
        } else if t < t_bend {
            let s = (t - 0.5) / (t_bend - 0.5);
            stand - (stand - low) * 0.5 * (1.0 - (std::f64::consts::PI * s).cos())
        } else if t < t_to {
            let d = t_to - t_bend;
            hermite((t - t_bend) / d, low, 0.0, to_h, v0 * d)
        } else if t < t_land {
            let u = t - t_to;
            to_h + v0 * u - 0.5 * G * u * u
        } else if t < t_land + 0.25 {
            hermite((t - t_land) / 0.25, to_h, -v0 * 0.25, 0.80, 0.0)
        } else if t < t_land + 0.75 {
            let s = (t - t_land - 0.25) / 0.5;
            0.80 + (stand - 0.80) * 0.5 * (1.0 - (std::f64::consts::PI * s).cos())
        } else {
            stand
        };
        root.push(y);
        foot.push(if t >= t_to && t < t_land {
            0.08 + (y - to_h)
        } else {
            0.08
        });
    }
    let truth = super::events::JumpEvents {
        start: 0.5,
        bend: t_bend,
        take_off: t_to,
        leap: t_to + v0 / G,
        land: t_land,
    };
    (root, foot, truth)
}
