//! A segment database from dance clips generated in code: moves of sinusoidal DOF swings at a
//! beat, changing bar by bar with smooth blends, the root bouncing, turning and travelling; for
//! the experiments, tests and benchmarks that run without the shared data.

use std::f64::consts::TAU;

use glam::{DQuat, DVec3};
use rand::{Rng, RngExt, SeedableRng};

use super::database::{BuildParams, DATABASE_VERSION, Database, Source};
use super::eros::eros_weights;
use super::segments::{Beat, SegmentError, TempoSource, cut_segments};
use crate::humanoid::{FigureClip, humanoid24};

/// One move of a generated dance: per DOF an offset, an amplitude, a phase and a frequency (½
/// or ¼ per beat: one or two swings a bar); a turn rate and a travel speed of the root.
#[derive(Debug, Clone)]
struct Move {
    swings: Vec<(usize, f64, f64, f64, f64)>,
    turn_rad_s: f64,
    travel_m_s: f64,
}

/// The DOFs a generated move swings, with the largest amplitude of each, degrees.
const SWING_DOFS: [(&str, f64); 12] = [
    ("left_knee", 35.0),
    ("right_knee", 35.0),
    ("left_hip_flexion", 30.0),
    ("right_hip_flexion", 30.0),
    ("left_shoulder_abduction", 70.0),
    ("right_shoulder_abduction", 70.0),
    ("left_shoulder_flexion", 60.0),
    ("right_shoulder_flexion", 60.0),
    ("left_elbow_flexion", 60.0),
    ("right_elbow_flexion", 60.0),
    ("waist_flexion", 15.0),
    ("waist_lateral", 15.0),
];

/// A generated dance clip on humanoid24 at `fps`: `bars` bars of 4 beats at `bpm`, each a move
/// drawn from `moves` (blended over ±0.1 bar at the bar lines, so the clip is smooth).
fn generated_clip(
    rng: &mut impl Rng,
    moves: &[Move],
    bpm: f64,
    bars: usize,
    fps: f64,
) -> FigureClip {
    let model = humanoid24();
    let d = model.dofs.len();
    let beat = 60.0 / bpm;
    let bar = 4.0 * beat;
    let order: Vec<usize> = (0..bars + 1)
        .map(|_| rng.random_range(0..moves.len()))
        .collect();
    let frames = (bars as f64 * bar * fps).round() as usize;
    let pose = |m: &Move, t: f64, out: &mut [f64]| {
        for &(j, off, amp, ph, freq) in &m.swings {
            out[j] += off + amp * (TAU * freq * t / beat + ph).sin();
        }
    };
    let mut clip = FigureClip {
        model,
        frame_time: 1.0 / fps,
        root_translation: Vec::with_capacity(frames),
        root_rotation: Vec::with_capacity(frames),
        angles: vec![0.0; frames * d],
    };
    let (mut yaw, mut pos) = (rng.random_range(0.0..TAU), DVec3::ZERO);
    for f in 0..frames {
        let t = f as f64 / fps;
        let k = ((t / bar) as usize).min(bars - 1);
        let u = t / bar - k as f64;
        // Blend weights of this bar's move and its neighbours' near the bar lines.
        let smooth = |x: f64| {
            let x = x.clamp(0.0, 1.0);
            x * x * (3.0 - 2.0 * x)
        };
        let mut parts = vec![(order[k], 1.0)];
        if u > 0.9 {
            let w = 0.5 * smooth((u - 0.9) / 0.1);
            parts = vec![(order[k], 1.0 - w), (order[k + 1], w)];
        } else if u < 0.1 && k > 0 {
            let w = 0.5 * smooth((0.1 - u) / 0.1);
            parts = vec![(order[k], 1.0 - w), (order[k - 1], w)];
        }
        let row = &mut clip.angles[f * d..(f + 1) * d];
        let mut tmp = vec![0.0; d];
        let (mut turn, mut travel) = (0.0, 0.0);
        for &(m, w) in &parts {
            tmp.fill(0.0);
            pose(&moves[m], t, &mut tmp);
            for (r, x) in row.iter_mut().zip(&tmp) {
                *r += w * x;
            }
            turn += w * moves[m].turn_rad_s;
            travel += w * moves[m].travel_m_s;
        }
        yaw += turn / fps;
        pos += DQuat::from_rotation_y(yaw) * DVec3::Z * travel / fps;
        let bounce = 0.03 * (TAU * t / beat).cos();
        clip.root_translation
            .push(DVec3::new(pos.x, 0.93 + bounce, pos.z));
        clip.root_rotation.push(DQuat::from_rotation_y(yaw));
    }
    clip
}

/// A database of `clips` generated dance clips of `bars_per_clip` bars each (module docs),
/// tempo 96–128 BPM, from a vocabulary of 8 moves; seeded.
pub fn generated_database(
    seed: u64,
    clips: usize,
    bars_per_clip: usize,
) -> Result<Database, SegmentError> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let model = humanoid24();
    let moves: Vec<Move> = (0..8)
        .map(|_| Move {
            swings: SWING_DOFS
                .iter()
                .filter_map(|&(name, max)| {
                    let j = model.dof_index(name)?;
                    let amp = rng.random_range(0.2..1.0) * max.to_radians();
                    let off = rng.random_range(-0.5..0.5) * max.to_radians();
                    let freq = if rng.random_bool(0.5) { 0.25 } else { 0.5 };
                    Some((j, off, amp, rng.random_range(0.0..TAU), freq))
                })
                .collect(),
            turn_rad_s: rng.random_range(-0.6..0.6),
            travel_m_s: rng.random_range(0.0..0.4),
        })
        .collect();
    let params = BuildParams::default();
    let (mut sources, mut segments) = (vec![], vec![]);
    for c in 0..clips {
        let bpm = rng.random_range(96.0..128.0);
        let clip = generated_clip(&mut rng, &moves, bpm, bars_per_clip, 60.0);
        let beat = Beat {
            tempo_bpm: bpm,
            first_beat_s: 0.0,
            source: TempoSource::Manifest,
        };
        let name = format!("generated_{c}");
        let cut = cut_segments(&clip, &name, c, &beat, &params)?;
        sources.push(Source {
            file: name,
            frames: clip.frame_count(),
            fps: 60.0,
            window: None,
            beat,
            segments: cut.len(),
        });
        segments.extend(cut);
    }
    let pcas: Vec<_> = segments.iter().map(|s| &s.eros).collect();
    let eros_weights = eros_weights(&pcas);
    Ok(Database {
        format_version: DATABASE_VERSION,
        model: "humanoid24".into(),
        params,
        sources,
        skipped: vec![],
        segments,
        eros_weights,
    })
}
