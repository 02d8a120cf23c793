//! A dance assembled from one segment per bar at the song's bar timing (paper §3.2.2): every
//! segment time-resized to its bar, the root carried on from segment to segment, and the frames
//! around every seam rewritten by cubic interpolation.
//!
//! - **Timing.** The dance spans the bars, from the first bar's start (frame 0) to the last
//!   bar's end: F = round(span · fps) frames of frame_time = span / F, so that F × frame_time is
//!   the bars' span (the rate differs from `fps` by less than half a frame over the dance). Bar
//!   k holds the frames [round(start_k / frame_time), round(end_k / frame_time)) (times from the
//!   dance start); a frame at phase u ∈ [0, 1) of its bar samples its segment at u × (segment
//!   frames) (angles and root position linearly, root orientation by slerp, as
//!   [`super::segments::resample`], a whole frame exactly; the segment's frames lie at phases
//!   i / frames).
//! - **Root carried on.** The first segment keeps its root. Every later segment is turned about
//!   the vertical (Y) axis and shifted horizontally so that its first frame's pelvis stands where
//!   the previous segment, extrapolated by one of its frames to phase 1, ends, with that heading
//!   (heading = the yaw of the pelvis forward axis): the dancer neither teleports nor spins. The
//!   pelvis height stays the segment's own.
//! - **Angles unwrapped.** A DOF whose first value in a bar is more than π from the last of the
//!   bar before is shifted by the multiple of 2π that brings it nearest (the same pose).
//! - **Seams.** The last `seam_frames` frames before a seam and the first `seam_frames` after it
//!   are replaced by a cubic Hermite curve between the frames just outside (a = seam − w − 1,
//!   b = seam + w) with the motion's own velocities there (one-sided differences away from the
//!   seam, a − 1 → a and b → b + 1): positions and velocities continuous at both ends. Per DOF
//!   angle and per root coordinate; the root orientation as the same Hermite curve in the tangent
//!   space of q_a (q = q_a exp(v(t)), v from 0 to log(q_a⁻¹ q_b), end rates log(q_{a−1}⁻¹ q_a) and
//!   log(q_b⁻¹ q_{b+1}), q_b taken on q_a's hemisphere), continuous with no flip.
//!   Every bar needs 2w + 2 frames so that the windows and their outside frames do not overlap.

use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};

use super::database::Database;
use super::music::Bar;
use super::segments::Segment;
use crate::humanoid::{ModelClip, humanoid24};

/// Slowest frame rate of a dance, frames per second.
pub const MIN_FPS: f64 = 1.0;

/// Fastest frame rate of a dance, frames per second.
pub const MAX_FPS: f64 = 1000.0;

/// Most frames a dance has (about 9 hours at 30 fps).
pub const MAX_FRAMES: usize = 1_000_000;

/// How a dance is assembled.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DanceParams {
    /// Frames per second of the dance ([`MIN_FPS`] to [`MAX_FPS`]).
    pub fps: f64,
    /// Frames rewritten on each side of a seam (the paper's 5).
    pub seam_frames: usize,
}

impl Default for DanceParams {
    /// 30 fps, 5 frames on each side of a seam.
    fn default() -> DanceParams {
        DanceParams {
            fps: 30.0,
            seam_frames: 5,
        }
    }
}

/// An assembled dance.
#[derive(Debug, Clone, PartialEq)]
pub struct Dance {
    /// The whole dance on humanoid24; frame 0 at the first bar's start.
    pub clip: ModelClip,
    /// The song time of frame 0 (the first bar's start), seconds.
    pub start_s: f64,
    /// The time of every seam (the start of bars 1, 2, …) from frame 0, seconds.
    pub seams_s: Vec<f64>,
    /// Every bar's frames, [first, end).
    pub bar_frames: Vec<(usize, usize)>,
    /// The segment of every bar.
    pub segments: Vec<usize>,
    /// Frames rewritten on each side of a seam.
    pub seam_frames: usize,
}

impl Dance {
    /// The first frame of every bar after the first: the frames where seams fall.
    pub fn seam_frame_indices(&self) -> Vec<usize> {
        self.bar_frames.iter().skip(1).map(|b| b.0).collect()
    }
}

/// Why a dance could not be assembled.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DanceError {
    /// A database without segments.
    #[error("the dance database has no segments")]
    EmptyDatabase,
    /// No bars.
    #[error("no bars to dance to")]
    NoBars,
    /// Not one segment per bar.
    #[error("{segments} segments for {bars} bars: a dance takes one segment per bar")]
    Count {
        /// Segments given.
        segments: usize,
        /// Bars given.
        bars: usize,
    },
    /// A segment index past the database.
    #[error("bar {bar}: segment {segment} does not exist (the database has {segments})")]
    NoSuchSegment {
        /// The bar.
        bar: usize,
        /// The segment asked for.
        segment: usize,
        /// The database's segment count.
        segments: usize,
    },
    /// A segment whose frames are missing or inconsistent.
    #[error(
        "segment {segment}: {frames} frames with {angles} angles (humanoid24 has {dofs} DOFs, a \
         segment needs at least 2 frames)"
    )]
    BadSegment {
        /// The segment.
        segment: usize,
        /// Its frame count.
        frames: usize,
        /// Its angle count.
        angles: usize,
        /// DOFs expected per frame.
        dofs: usize,
    },
    /// A bar of zero or negative length, or not a finite time.
    #[error("bar {bar}: from {start_s} s to {end_s} s is not a bar (it must end after it starts)")]
    BadBar {
        /// The bar.
        bar: usize,
        /// Its start, seconds.
        start_s: f64,
        /// Its end, seconds.
        end_s: f64,
    },
    /// A bar that does not start where the one before ends.
    #[error("bar {bar} starts at {start_s} s but bar {} ends at {previous_end_s} s: bars must follow each other", bar - 1)]
    Gap {
        /// The bar.
        bar: usize,
        /// Its start, seconds.
        start_s: f64,
        /// The previous bar's end, seconds.
        previous_end_s: f64,
    },
    /// A frame rate outside [`MIN_FPS`]..=[`MAX_FPS`].
    #[error("frame rate {fps} fps: a dance takes {MIN_FPS} to {MAX_FPS} fps")]
    Fps {
        /// The frame rate asked for.
        fps: f64,
    },
    /// More frames than [`MAX_FRAMES`].
    #[error("{frames} frames are more than the {MAX_FRAMES} a dance takes")]
    TooLong {
        /// The frame count.
        frames: usize,
    },
    /// A bar too short for the seam windows at this frame rate.
    #[error(
        "bar {bar} has {frames} frames at this frame rate, fewer than the {needed} that seams of \
         {seam_frames} frames on each side need (raise fps or lower seam_frames)"
    )]
    BarTooShort {
        /// The bar.
        bar: usize,
        /// Its frames.
        frames: usize,
        /// Frames needed.
        needed: usize,
        /// The seam window.
        seam_frames: usize,
    },
}

/// The heading (yaw about Y) of a pelvis orientation: of its forward (Z) axis, radians.
pub fn heading(q: DQuat) -> f64 {
    let f = q * DVec3::Z;
    f.x.atan2(f.z)
}

/// Assembles `segments` (one per bar, database indices) at the timing of `bars` (module docs).
pub fn assemble(
    db: &Database,
    segments: &[usize],
    bars: &[Bar],
    p: &DanceParams,
) -> Result<Dance, DanceError> {
    let model = humanoid24();
    let dofs = model.dofs.len();
    if db.segments.is_empty() {
        return Err(DanceError::EmptyDatabase);
    }
    if bars.is_empty() {
        return Err(DanceError::NoBars);
    }
    if segments.len() != bars.len() {
        return Err(DanceError::Count {
            segments: segments.len(),
            bars: bars.len(),
        });
    }
    if !(p.fps.is_finite() && (MIN_FPS..=MAX_FPS).contains(&p.fps)) {
        return Err(DanceError::Fps { fps: p.fps });
    }
    for (bar, &s) in segments.iter().enumerate() {
        let seg = db.segments.get(s).ok_or(DanceError::NoSuchSegment {
            bar,
            segment: s,
            segments: db.segments.len(),
        })?;
        let frames = seg.frame_count();
        if frames < 2 || seg.root_rotation.len() != frames || seg.angles.len() != frames * dofs {
            return Err(DanceError::BadSegment {
                segment: s,
                frames,
                angles: seg.angles.len(),
                dofs,
            });
        }
    }
    for (k, b) in bars.iter().enumerate() {
        if !(b.start_s.is_finite() && b.end_s.is_finite() && b.end_s > b.start_s) {
            return Err(DanceError::BadBar {
                bar: k,
                start_s: b.start_s,
                end_s: b.end_s,
            });
        }
        if k > 0 {
            let prev = bars[k - 1].end_s;
            if (b.start_s - prev).abs() > 1e-6 * prev.abs().max(1.0) {
                return Err(DanceError::Gap {
                    bar: k,
                    start_s: b.start_s,
                    previous_end_s: prev,
                });
            }
        }
    }
    let start_s = bars[0].start_s;
    let span = bars[bars.len() - 1].end_s - start_s;
    let frames_f = (span * p.fps).round();
    if frames_f > MAX_FRAMES as f64 {
        return Err(DanceError::TooLong {
            frames: frames_f as usize,
        });
    }
    let frames = (frames_f as usize).max(1);
    let dt = span / frames as f64;
    let at = |t: f64| (((t - start_s) / dt).round().max(0.0) as usize).min(frames);
    let bar_frames: Vec<(usize, usize)> = bars
        .iter()
        .enumerate()
        .map(|(k, b)| {
            let first = if k == 0 { 0 } else { at(b.start_s) };
            let end = if k + 1 == bars.len() {
                frames
            } else {
                at(b.end_s)
            };
            (first, end)
        })
        .collect();
    let w = p.seam_frames;
    let needed = if bars.len() > 1 { 2 * w + 2 } else { 1 };
    for (k, &(a, b)) in bar_frames.iter().enumerate() {
        if b - a < needed.max(1) {
            return Err(DanceError::BarTooShort {
                bar: k,
                frames: b - a,
                needed: needed.max(1),
                seam_frames: w,
            });
        }
    }

    let mut clip = ModelClip {
        model: model.clone(),
        frame_time: dt,
        root_translation: Vec::with_capacity(frames),
        root_rotation: Vec::with_capacity(frames),
        angles: Vec::with_capacity(frames * dofs),
    };
    // The carry-on of the previous bar: its rotation about Y and horizontal offset, and where
    // its segment ends (extrapolated to phase 1) in the dance.
    let mut end: Option<(DVec3, f64)> = None;
    for (k, (&s, bar)) in segments.iter().zip(bars).enumerate() {
        let seg = &db.segments[s];
        let m = seg.frame_count();
        let (first, stop) = bar_frames[k];
        let length = bar.end_s - bar.start_s;
        let part = sample(
            seg,
            dofs,
            (first..stop).map(|f| (f as f64 * dt - (bar.start_s - start_s)) / length * m as f64),
        );
        // The rigid carry-on: yaw ψ and horizontal offset o, world = R_ψ p + o.
        let (turn, offset) = match end {
            None => (DQuat::IDENTITY, DVec3::ZERO),
            Some((e, yaw)) => {
                let turn = DQuat::from_rotation_y(yaw - heading(seg.root_rotation[0]));
                let p0 = turn * seg.root_translation[0];
                (turn, DVec3::new(e.x - p0.x, 0.0, e.z - p0.z))
            }
        };
        for (t, q) in part.root_translation.iter().zip(&part.root_rotation) {
            clip.root_translation.push(turn * *t + offset);
            clip.root_rotation.push((turn * *q).normalize());
        }
        // Angles, each DOF unwrapped against the previous bar's last frame.
        let base = clip.angles.len();
        clip.angles.extend_from_slice(&part.angles);
        if k > 0 {
            for d in 0..dofs {
                let prev = clip.angles[base - dofs + d];
                let diff = clip.angles[base + d] - prev;
                let turns = (diff / std::f64::consts::TAU).round();
                if diff.abs() > std::f64::consts::PI && turns != 0.0 {
                    let shift = turns * std::f64::consts::TAU;
                    for f in 0..stop - first {
                        clip.angles[base + f * dofs + d] -= shift;
                    }
                }
            }
        }
        // Where this segment ends at phase 1: one of its frames past its last.
        let (pl, pm) = (seg.root_translation[m - 1], seg.root_translation[m - 2]);
        let (ql, qm) = (seg.root_rotation[m - 1], seg.root_rotation[m - 2]);
        let e = turn * (pl + (pl - pm)) + offset;
        let qe = turn * (ql * (qm.inverse() * ql));
        end = Some((e, heading(qe)));
    }

    if w > 0 {
        let original = clip.clone();
        for &(s, _) in bar_frames.iter().skip(1) {
            rewrite_seam(&original, &mut clip, s, w);
        }
    }
    Ok(Dance {
        clip,
        start_s,
        seams_s: bar_frames.iter().skip(1).map(|b| b.0 as f64 * dt).collect(),
        bar_frames,
        segments: segments.to_vec(),
        seam_frames: w,
    })
}

/// A segment's root positions, orientations and angles at frame positions `xs` (fractional
/// frames, clamped to [0, frames − 1]): a whole frame exactly, between frames angles and position
/// linearly and orientation by slerp (as [`super::segments::resample`]).
fn sample(seg: &Segment, dofs: usize, xs: impl Iterator<Item = f64>) -> ModelClip {
    let m = seg.frame_count();
    let mut out = ModelClip {
        model: humanoid24(),
        frame_time: 1.0,
        root_translation: vec![],
        root_rotation: vec![],
        angles: vec![],
    };
    for x in xs {
        let mut x = x.clamp(0.0, (m - 1) as f64);
        if (x - x.round()).abs() < 1e-9 {
            x = x.round();
        }
        let i = (x.floor() as usize).min(m - 1);
        let a = x - i as f64;
        let p = &seg.angles[i * dofs..(i + 1) * dofs];
        if a == 0.0 {
            out.root_translation.push(seg.root_translation[i]);
            out.root_rotation.push(seg.root_rotation[i]);
            out.angles.extend_from_slice(p);
        } else {
            let q = &seg.angles[(i + 1) * dofs..(i + 2) * dofs];
            out.root_translation
                .push(seg.root_translation[i].lerp(seg.root_translation[i + 1], a));
            out.root_rotation
                .push(seg.root_rotation[i].slerp(seg.root_rotation[i + 1], a));
            out.angles
                .extend(p.iter().zip(q).map(|(u, v)| u + (v - u) * a));
        }
    }
    out
}

/// The cubic Hermite basis at t ∈ [0, 1]: (h00, h10, h01, h11).
fn hermite(t: f64) -> (f64, f64, f64, f64) {
    let (t2, t3) = (t * t, t * t * t);
    (
        2.0 * t3 - 3.0 * t2 + 1.0,
        t3 - 2.0 * t2 + t,
        -2.0 * t3 + 3.0 * t2,
        t3 - t2,
    )
}

/// The rotation vector of `q` on the hemisphere w ≥ 0 (angle ≤ π), radians.
fn log(q: DQuat) -> DVec3 {
    let q = if q.w < 0.0 { -q } else { q };
    q.to_scaled_axis()
}

/// Rewrites frames [s − w, s + w) of `out` by cubic Hermite interpolation between frames a =
/// s − w − 1 and b = s + w of `src` (module docs).
fn rewrite_seam(src: &ModelClip, out: &mut ModelClip, s: usize, w: usize) {
    let d = src.dof_count();
    let (a, b) = (s - w - 1, s + w);
    let span = (b - a) as f64;
    // Angles and root position.
    let ang = |f: usize, j: usize| src.angles[f * d + j];
    let tr = |f: usize| src.root_translation[f];
    let (qa, qb0) = (src.root_rotation[a], src.root_rotation[b]);
    let qb = if qa.dot(qb0) < 0.0 { -qb0 } else { qb0 };
    let vb = log(qa.inverse() * qb);
    let ma = log(src.root_rotation[a - 1].inverse() * qa);
    let mb = log(qb0.inverse() * src.root_rotation[b + 1]);
    for f in a + 1..b {
        let (h00, h10, h01, h11) = hermite((f - a) as f64 / span);
        for j in 0..d {
            let (xa, xb) = (ang(a, j), ang(b, j));
            let (va, vb) = (xa - ang(a - 1, j), ang(b + 1, j) - xb);
            out.angles[f * d + j] = h00 * xa + h10 * span * va + h01 * xb + h11 * span * vb;
        }
        let (pa, pb) = (tr(a), tr(b));
        let (va, vbt) = (pa - tr(a - 1), tr(b + 1) - pb);
        out.root_translation[f] = h00 * pa + h10 * span * va + h01 * pb + h11 * span * vbt;
        let v = h10 * span * ma + h01 * vb + h11 * span * mb;
        out.root_rotation[f] = (qa * DQuat::from_scaled_axis(v)).normalize();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::dance_fill::generated_database;

    fn bars(n: usize, bar_s: f64, start: f64) -> Vec<Bar> {
        (0..n)
            .map(|k| Bar {
                start_s: start + k as f64 * bar_s,
                end_s: start + (k + 1) as f64 * bar_s,
                rms: 0.1,
                rms_db: -20.0,
            })
            .collect()
    }

    #[test]
    fn frames_outside_the_seams_are_the_segments_and_the_dance_lasts_its_bars() {
        let db = generated_database(3, 3, 4).unwrap();
        let segs = [0, 5, 2, 9];
        // 32 frames per segment over a 2 s bar: 16 fps puts every dance frame on a segment frame.
        let b = bars(4, 2.0, 1.25);
        let p = DanceParams {
            fps: 16.0,
            seam_frames: 5,
        };
        let d = assemble(&db, &segs, &b, &p).unwrap();
        let dofs = d.clip.dof_count();
        assert_eq!(d.clip.frame_count(), 128);
        assert_eq!(d.clip.frame_count() as f64 * d.clip.frame_time, 8.0);
        assert_eq!(d.start_s, 1.25);
        assert_eq!(d.seams_s, vec![2.0, 4.0, 6.0]);
        for (k, &s) in segs.iter().enumerate() {
            let (first, end) = d.bar_frames[k];
            assert_eq!((first, end), (32 * k, 32 * (k + 1)));
            let seg = &db.segments[s];
            let lo = if k == 0 { 0 } else { 5 };
            let hi = if k == 3 { 32 } else { 27 };
            for i in lo..hi {
                assert_eq!(
                    d.clip.frame_angles(first + i),
                    &seg.angles[i * dofs..(i + 1) * dofs],
                    "bar {k} frame {i}"
                );
            }
            // The root moved rigidly: same height, same displacement lengths, same turn.
            for i in lo + 1..hi {
                let (a, b) = (
                    d.clip.root_translation[first + i - 1],
                    d.clip.root_translation[first + i],
                );
                let (sa, sb) = (seg.root_translation[i - 1], seg.root_translation[i]);
                assert!((b.y - sb.y).abs() < 1e-12);
                assert!(((b - a).length() - (sb - sa).length()).abs() < 1e-12);
                let turn = d.clip.root_rotation[first + i - 1]
                    .angle_between(d.clip.root_rotation[first + i]);
                assert!(
                    (turn - seg.root_rotation[i - 1].angle_between(seg.root_rotation[i])).abs()
                        < 1e-9
                );
            }
        }
        // Inside the windows the frames changed (a seam between unrelated segments).
        assert_ne!(d.clip.frame_angles(32), &db.segments[5].angles[..dofs]);
    }

    #[test]
    fn the_root_carries_on_across_seams() {
        let db = generated_database(5, 4, 4).unwrap();
        let segs = [1, 7, 3, 12, 0, 9];
        let d = assemble(&db, &segs, &bars(6, 1.9, 0.0), &DanceParams::default()).unwrap();
        let t = &d.clip.root_translation;
        let step = |f: usize| {
            let v = t[f + 1] - t[f];
            DVec3::new(v.x, 0.0, v.z).length()
        };
        let steps: Vec<f64> = (0..t.len() - 1).map(step).collect();
        let inside = steps.iter().copied().fold(0.0, f64::max);
        for &s in &d.seam_frame_indices() {
            // No teleport: the horizontal step over the seam is no larger than the dance's steps.
            assert!(step(s - 1) <= inside + 1e-12);
            // No spin: the heading changes at the seam as little as one frame's turn.
            let turn = (heading(d.clip.root_rotation[s]) - heading(d.clip.root_rotation[s - 1]))
                .rem_euclid(std::f64::consts::TAU);
            let turn = turn.min(std::f64::consts::TAU - turn);
            assert!(turn < 0.05, "seam at {s}: turn {turn}");
        }
        // Without carry-on the seams would jump: the segments stand where their clips were.
        let raw =
            (db.segments[7].root_translation[0] - db.segments[1].root_translation[31]).length();
        eprintln!("uncarried jump at the first seam: {raw:.3} m, largest step {inside:.4} m");
    }

    #[test]
    fn every_bad_input_has_its_error() {
        let db = generated_database(1, 1, 3).unwrap();
        let p = DanceParams::default();
        let b = bars(2, 2.0, 0.0);
        let empty = Database {
            segments: vec![],
            ..db.clone()
        };
        assert_eq!(
            assemble(&empty, &[0, 0], &b, &p),
            Err(DanceError::EmptyDatabase)
        );
        assert_eq!(assemble(&db, &[], &[], &p), Err(DanceError::NoBars));
        assert!(matches!(
            assemble(&db, &[0], &b, &p),
            Err(DanceError::Count { .. })
        ));
        assert!(matches!(
            assemble(&db, &[0, 99], &b, &p),
            Err(DanceError::NoSuchSegment {
                bar: 1,
                segment: 99,
                ..
            })
        ));
        let mut z = b.clone();
        z[1].end_s = z[1].start_s;
        assert!(matches!(
            assemble(&db, &[0, 1], &z, &p),
            Err(DanceError::BadBar { bar: 1, .. })
        ));
        let mut g = b.clone();
        g[1].start_s += 0.5;
        assert!(matches!(
            assemble(&db, &[0, 1], &g, &p),
            Err(DanceError::Gap { bar: 1, .. })
        ));
        for fps in [0.0, -3.0, f64::NAN, 5000.0] {
            let q = DanceParams {
                fps,
                seam_frames: 5,
            };
            assert!(matches!(
                assemble(&db, &[0, 1], &b, &q),
                Err(DanceError::Fps { .. })
            ));
        }
        let q = DanceParams {
            fps: 5.0,
            seam_frames: 5,
        };
        let e = assemble(&db, &[0, 1], &b, &q).unwrap_err();
        assert!(
            matches!(
                e,
                DanceError::BarTooShort {
                    frames: 10,
                    needed: 12,
                    ..
                }
            ),
            "{e}"
        );
    }
}
