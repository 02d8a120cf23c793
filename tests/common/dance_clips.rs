//! Dance clips generated on humanoid24 for the search tests and benches: six moves (step-touch,
//! knee bounce, side lunge, kicks, arm circles, a twisting groove), each clip morphing from one
//! move to the next and back over three bars at its own tempo, written as BVH and built into a
//! database through a manifest (as a user's clips would be).
//!
//! Shared by `tests/choreo/search.rs` and `benches/choreo_search.rs` (through `#[path]`).

#![allow(dead_code)] // each user takes some of these

use std::path::PathBuf;

use glam::{DQuat, DVec3};
use marionette::choreo::{BuildParams, Database, Manifest, ManifestClip, OnRefusal};
use marionette::humanoid::{FigureClip, humanoid24};

/// A fresh scratch folder.
pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("marionette-search-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Moves: (DOF, amplitude in degrees, cycles per bar, phase in cycles).
const MOVES: [&[(&str, f64, f64, f64)]; 6] = [
    // Step-touch with the left arm waving.
    &[
        ("left_hip_abduction", 20.0, 2.0, 0.0),
        ("right_knee", 25.0, 4.0, 0.25),
        ("left_shoulder_abduction", 70.0, 2.0, 0.0),
        ("left_elbow_flexion", 40.0, 4.0, 0.1),
    ],
    // Knee bounce with both arms pumping forward.
    &[
        ("left_knee", 35.0, 4.0, 0.0),
        ("right_knee", 35.0, 4.0, 0.0),
        ("left_shoulder_flexion", 60.0, 4.0, 0.5),
        ("right_shoulder_flexion", 60.0, 4.0, 0.0),
    ],
    // A side lunge to the right, the waist bending with it.
    &[
        ("right_hip_abduction", 30.0, 1.0, 0.0),
        ("left_knee", 40.0, 1.0, 0.5),
        ("waist_lateral", 20.0, 1.0, 0.0),
        ("right_shoulder_abduction", 80.0, 1.0, 0.25),
    ],
    // Kicks: hip flexion on alternate beats.
    &[
        ("left_hip_flexion", 45.0, 2.0, 0.0),
        ("right_hip_flexion", 45.0, 2.0, 0.5),
        ("waist_flexion", 15.0, 4.0, 0.0),
    ],
    // Arm circles over the head.
    &[
        ("left_shoulder_flexion", 90.0, 1.0, 0.0),
        ("right_shoulder_flexion", 90.0, 1.0, 0.25),
        ("left_shoulder_abduction", 50.0, 1.0, 0.25),
        ("right_shoulder_abduction", 50.0, 1.0, 0.5),
        ("right_knee", 15.0, 4.0, 0.0),
    ],
    // A twisting groove: shoulder rotation and clavicles.
    &[
        ("left_shoulder_rotation", 50.0, 2.0, 0.0),
        ("right_shoulder_rotation", 50.0, 2.0, 0.0),
        ("left_clavicle_elevation", 15.0, 4.0, 0.0),
        ("left_hip_rotation", 20.0, 2.0, 0.25),
        ("right_knee", 20.0, 2.0, 0.0),
    ],
];

/// Clip `c` on humanoid24: `bars` bars at `bpm`, morphing from move c to move c + 1 and back
/// over three bars, a bounce on every beat and a slow turn; 60 fps.
pub fn generated_clip(c: usize, bars: usize, bpm: f64) -> FigureClip {
    let model = humanoid24();
    let d = model.dofs.len();
    let fps = 60.0;
    let bar_s = 240.0 / bpm;
    let n = ((bars as f64 * bar_s + 0.1) * fps).round() as usize;
    let (a, b) = (MOVES[c % 6], MOVES[(c + 1) % 6]);
    let mut angles = vec![0.0; n * d];
    let tau = std::f64::consts::TAU;
    for f in 0..n {
        let t = f as f64 / fps;
        let mix = 0.5 - 0.5 * (tau * t / (3.0 * bar_s)).cos();
        for (move_, w) in [(a, 1.0 - mix), (b, mix)] {
            for &(name, amp, cycles, phase) in move_ {
                let i = model.dof_index(name).unwrap();
                let x = (tau * (cycles * t / bar_s + phase)).sin();
                angles[f * d + i] += w * amp.to_radians() * (0.6 + 0.4 * x);
            }
        }
    }
    let turn = 0.3 * (c as f64 - 2.5);
    FigureClip {
        model,
        frame_time: 1.0 / fps,
        root_translation: (0..n)
            .map(|f| {
                let t = f as f64 / fps;
                let beat = t * bpm / 60.0;
                DVec3::new(
                    0.1 * (tau * beat / 4.0).sin(),
                    0.93 + 0.02 * (tau * beat).cos(),
                    0.05 * t,
                )
            })
            .collect(),
        root_rotation: (0..n)
            .map(|f| DQuat::from_rotation_y(turn * f as f64 / fps))
            .collect(),
        angles,
    }
}

/// The tempo of generated clip `c`, BPM.
pub fn tempo(c: usize) -> f64 {
    100.0 + 6.0 * c as f64
}

/// A database built from `clips` generated clips of 8 bars each, written as BVH and listed in
/// a manifest with their tempo; the folder is returned too.
pub fn generated_database(name: &str, clips: usize) -> (Database, PathBuf) {
    let dir = scratch(name);
    let mut list = vec![];
    for c in 0..clips {
        let clip = generated_clip(c, 8, tempo(c));
        let file = dir.join(format!("gen_{c}.bvh"));
        marionette::bvh::write_file(&clip.to_clip().to_bvh(), &file).unwrap();
        list.push(ManifestClip {
            file,
            tempo_bpm: Some(tempo(c)),
            first_beat_s: Some(0.0),
            window: None,
            mapping: None,
        });
    }
    let m = Manifest {
        format_version: 1,
        clips: list,
    };
    (
        Database::build(&m, &BuildParams::default(), OnRefusal::Fail, |_, _| {}).unwrap(),
        dir,
    )
}
