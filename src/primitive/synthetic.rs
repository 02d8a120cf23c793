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
