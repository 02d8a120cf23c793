//! A dance assembled from one segment per bar at the song's bar timing (paper §3.2.2): every
//! segment time-resized to its bar, the root carried on from segment to segment, and the frames
//! around every seam rewritten by cubic interpolation.
//!
//! - **Timing.** The dance spans the bars, from the first bar's start (frame 0) to the last
//!   bar's end: F = round(span · fps) frames of frame_time = span / F, so that F × frame_time is
//!   the bars' span (the rate differs from `fps` by less than half a frame over the dance). Bar
//!   k holds the frames [round(start_k / frame_time), round(end_k / frame_time)) (times from the
//!   dance start); a frame at phase u ∈ [0, 1) of its bar samples its segment at u × (segment
//!   frames) (the segment's frames lie at phases i / frames): angles and root position on the
//!   natural cubic spline through the segment's frames (linear interpolation would put a kink,
//!   a spike of jerk, at every segment frame), root orientation by slerp; a whole frame exactly.
//! - **Beats on the music** ([`DanceParams::beat_warp`], [`super::warp`]). With the warp on, the
//!   phase u is first mapped to the segment phase w(u) of the bar's warp, a monotone cubic
//!   through (0, 0), (song beat phase, segment beat phase) …, (1, 1) with slope 1 at both ends:
//!   the segment's own beats (its speed minima near counts 2, 3 and 4, found from its frames by
//!   forward kinematics, [`super::warp::count_minima`]) fall on the song's beats inside the bar
//!   (the beats of `beats_s` strictly between its start and end, as phases), and the bar lines
//!   keep the uniform resize's rate, so the seams stay C¹. A bar whose song beats inside are not
//!   [`BEATS_PER_BAR`] − 1 (a song in another metre, beats not tracked) is resized uniformly,
//!   and so is a count whose minimum is not clear or whose knot would break the warp's rate
//!   bound. With the warp off, every bar is the paper's uniform resize, w(u) = u.
//! - **Root carried on.** The first segment keeps its root. Every later segment is turned about
//!   the vertical (Y) axis and shifted horizontally so that its first frame's pelvis stands where
//!   the previous segment, extrapolated by one of its frames to phase 1, ends, with that heading
//!   (heading = the yaw of the pelvis forward axis): the dancer neither teleports nor spins. The
//!   pelvis height stays the segment's own.
//! - **Angles unwrapped.** A DOF whose first value in a bar is more than π from the last of the
//!   bar before is shifted by the multiple of 2π that brings it nearest (the same pose).
//! - **Seams** ([`DanceParams::seam`]). The last w = `seam_frames` frames before a seam and the
//!   first w after it are rewritten, one of two ways.
//!   - [`Seam::Spline`], the paper's: the natural cubic spline through the [`SEAM_KNOTS`] frames
//!     on each side of the window (frames s − w − 4 … s − w − 1 and s + w … s + w + 3 for a seam
//!     at frame s), per DOF angle and per root coordinate: the spline interpolates the frames
//!     kept, so the motion enters and leaves the window with its own velocity and (nearly) its
//!     own acceleration, which a Hermite curve between the two frames next to the window would
//!     break (a jump of acceleration, a spike of jerk, at both ends of every seam). The jump
//!     between the segments is crossed at the bar line itself, so the seam's fastest moment is
//!     the bar line, where both segments were at a beat (their slowest), and the speed minima
//!     move to the window's ends, off the beat.
//!   - [`Seam::Offset`], the default: each side keeps its own motion plus half the jump of
//!     position, velocity and acceleration at the bar line, faded out across its w frames by
//!     quintic curves that leave the window's ends untouched to the second derivative
//!     (`offset_seam`). Both sides meet at the bar line with the mean of their positions,
//!     velocities and accelerations, so the bar line stays a speed minimum on the beat. Crossing
//!     the jump in half the time costs jerk: on the shared clips (issue 34, five dances of 16
//!     bars on three songs) the beat alignment rose in all five (0.37 → 0.44 held out, 0.34 →
//!     0.40 salsa, 0.93 → 0.96 the authored dance), and the mean seam jerk fell to 0.76× on two
//!     and rose to 2.4× on two and 3.4× on the authored dance, whose seams were nearly smooth.
//!
//!   The root orientation takes the same treatment of the rotation vectors log(q_a⁻¹ q)
//!   relative to the frame before the window (q = q_a exp(r), each on q_a's hemisphere):
//!   continuous, no flip. Every bar needs 2w + 2·4 frames so that a window's knots are never
//!   rewritten by the next seam.

use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};

use super::database::Database;
use super::music::Bar;
use super::segments::{BEATS_PER_BAR, Segment, speed_curve};
use super::warp::{Warp, count_minima};
use crate::humanoid::{FigureClip, humanoid24};

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
    /// Whether each bar's time is warped so that the segment's own beats (its speed minima near
    /// the counts) fall on the song's beats (module docs; true when a scene does not say);
    /// false: the paper's uniform resize of every segment to its bar.
    #[serde(default = "beat_warp_default")]
    pub beat_warp: bool,
    /// How the frames around a seam are rewritten (module docs; [`Seam::Offset`] when a scene
    /// does not say; [`Seam::Spline`] is the paper's).
    #[serde(default)]
    pub seam: Seam,
}

/// How the 2w frames around a seam are rewritten (module docs).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Seam {
    /// The paper's: the natural cubic spline through the frames on each side of the window.
    Spline,
    /// Each side keeps its own motion plus half the jump of position and of velocity at the
    /// bar line, faded out across its half of the window: the bar line, where both segments
    /// are at a beat, stays the slowest moment of the seam.
    #[default]
    Offset,
}

/// A scene that does not say warps its bars' beats onto the music.
fn beat_warp_default() -> bool {
    true
}

impl Default for DanceParams {
    /// 30 fps, 5 frames on each side of a seam, beats warped onto the music.
    fn default() -> DanceParams {
        DanceParams {
            fps: 30.0,
            seam_frames: 5,
            beat_warp: true,
            seam: Seam::Offset,
        }
    }
}

/// An assembled dance.
#[derive(Debug, Clone, PartialEq)]
pub struct Dance {
    /// The whole dance on humanoid24; frame 0 at the first bar's start.
    pub clip: FigureClip,
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
    /// Per bar, how many of the segment's beats the warp moved onto the song's (0 for a bar
    /// resized uniformly; at most [`BEATS_PER_BAR`] − 1).
    pub warped_beats: Vec<usize>,
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

/// Assembles `segments` (one per bar, database indices) at the timing of `bars`, each
/// segment's beats warped onto the song's beats `beats_s` (song time, seconds, increasing) when
/// `p.beat_warp` (module docs).
pub fn assemble(
    db: &Database,
    segments: &[usize],
    bars: &[Bar],
    beats_s: &[f64],
    p: &DanceParams,
) -> Result<Dance, DanceError> {
    let model = humanoid24();
    let dofs = model.dofs.len();
    check_inputs(db, segments, bars, p, dofs)?;
    let start_s = bars[0].start_s;
    let (frames, dt) = frame_count(bars, p.fps)?;
    let bar_frames = bar_frames(bars, p, frames, dt)?;
    let w = p.seam_frames;

    // Each segment's beats (phases of counts 2, 3, 4), found once per segment, and each bar's
    // warp and samples: independent, so found in parallel.
    use rayon::prelude::*;
    let beats_of: std::collections::BTreeMap<usize, Vec<Option<f64>>> = if p.beat_warp {
        let unique: std::collections::BTreeSet<usize> = segments.iter().copied().collect();
        let unique: Vec<usize> = unique.into_iter().collect();
        unique
            .par_iter()
            .map(|&s| (s, segment_beats(&db.segments[s], &model)))
            .collect::<Vec<_>>()
            .into_iter()
            .collect()
    } else {
        Default::default()
    };
    let parts: Vec<(usize, FigureClip)> = segments
        .par_iter()
        .zip(bars)
        .enumerate()
        .map(|(k, (&s, bar))| {
            let seg = &db.segments[s];
            let m = seg.frame_count();
            let (first, stop) = bar_frames[k];
            let length = bar.end_s - bar.start_s;
            let warp = match beats_of.get(&s) {
                Some(own) => bar_warp(bar, beats_s, own),
                None => Warp::identity(),
            };
            let x = |f: usize| warp.at((f as f64 * dt - (bar.start_s - start_s)) / length);
            let part = sample(seg, dofs, (first..stop).map(|f| x(f) * m as f64));
            (warp.knots().len() - 2, part)
        })
        .collect();

    let mut clip = FigureClip::with_capacity(model.clone(), dt, frames);
    // The carry-on of the previous bar: its rotation about Y and horizontal offset, and where
    // its segment ends (extrapolated to phase 1) in the dance.
    let mut end: Option<(DVec3, f64)> = None;
    let mut warped_beats = Vec::with_capacity(bars.len());
    for (k, (&s, (warped, part))) in segments.iter().zip(parts).enumerate() {
        let seg = &db.segments[s];
        warped_beats.push(warped);
        let (turn, offset) = carry_on(seg, end);
        for (t, q) in part.root_translation.iter().zip(&part.root_rotation) {
            clip.root_translation.push(turn * *t + offset);
            clip.root_rotation.push((turn * *q).normalize());
        }
        // Angles, each DOF unwrapped against the previous bar's last frame.
        let base = clip.angles.len();
        clip.angles.extend_from_slice(&part.angles);
        if k > 0 {
            unwrap_against_previous(&mut clip.angles[base - dofs..], dofs);
        }
        end = Some(phase_one_end(seg, turn, offset));
    }

    rewrite_seams(&mut clip, &bar_frames, w, p.seam);
    Ok(Dance {
        clip,
        start_s,
        seams_s: bar_frames.iter().skip(1).map(|b| b.0 as f64 * dt).collect(),
        bar_frames,
        segments: segments.to_vec(),
        seam_frames: w,
        warped_beats,
    })
}

/// The rigid carry-on of `seg` after a bar that ended at `end` (its root's place and heading
/// at phase 1, [`phase_one_end`]): the yaw ψ and horizontal offset o that put the segment's
/// first root frame there, world = R_ψ p + o; none for the first bar.
fn carry_on(seg: &Segment, end: Option<(DVec3, f64)>) -> (DQuat, DVec3) {
    match end {
        None => (DQuat::IDENTITY, DVec3::ZERO),
        Some((e, yaw)) => {
            let turn = DQuat::from_rotation_y(yaw - heading(seg.root_rotation[0]));
            let p0 = turn * seg.root_translation[0];
            (turn, DVec3::new(e.x - p0.x, 0.0, e.z - p0.z))
        }
    }
}

/// Where `seg`, carried on by `turn` and `offset`, ends at phase 1 (one of its frames past its
/// last, extrapolated): its root's place and heading (rad).
fn phase_one_end(seg: &Segment, turn: DQuat, offset: DVec3) -> (DVec3, f64) {
    let m = seg.frame_count();
    let (pl, pm) = (seg.root_translation[m - 1], seg.root_translation[m - 2]);
    let (ql, qm) = (seg.root_rotation[m - 1], seg.root_rotation[m - 2]);
    let e = turn * (pl + (pl - pm)) + offset;
    let qe = turn * (ql * (qm.inverse() * ql));
    (e, heading(qe))
}

/// Every seam of `clip` (at the first frame of each bar of `bar_frames` after the first)
/// rewritten over `w` frames on each side as `seam` says; nothing when `w` is 0.
fn rewrite_seams(clip: &mut FigureClip, bar_frames: &[(usize, usize)], w: usize, seam: Seam) {
    if w == 0 {
        return;
    }
    let original = clip.clone();
    for &(s, _) in bar_frames.iter().skip(1) {
        match seam {
            Seam::Spline => rewrite_seam(&original, clip, s, w),
            Seam::Offset => offset_seam(&original, clip, s, w),
        }
    }
}

/// The dance's frame count over `bars` at `fps` (at least 1, at most [`MAX_FRAMES`]) and its
/// frame time (s), which fits the bars' span exactly.
fn frame_count(bars: &[Bar], fps: f64) -> Result<(usize, f64), DanceError> {
    let span = bars[bars.len() - 1].end_s - bars[0].start_s;
    let frames_f = (span * fps).round();
    if frames_f > MAX_FRAMES as f64 {
        return Err(DanceError::TooLong {
            frames: frames_f as usize,
        });
    }
    let frames = (frames_f as usize).max(1);
    Ok((frames, span / frames as f64))
}

/// Refuses what [`assemble`] cannot dance: an empty database, no bars, a segment count that is
/// not the bar count, a frame rate outside [`MIN_FPS`, `MAX_FPS`], a segment index out of range
/// or a segment of the wrong size (`dofs` angles a frame), a bar that is not a finite, positive
/// span, or bars that do not meet.
fn check_inputs(
    db: &Database,
    segments: &[usize],
    bars: &[Bar],
    p: &DanceParams,
    dofs: usize,
) -> Result<(), DanceError> {
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
    Ok(())
}

/// The dance's frames `[first, end)` of every bar: `frames` frames of `dt` s from the first
/// bar's start, each bar from the frame nearest its start (the first from 0, the last to the
/// end); refused when a bar has fewer frames than its two seams need ([`SEAM_KNOTS`] knots
/// and `p.seam_frames` frames on each side).
fn bar_frames(
    bars: &[Bar],
    p: &DanceParams,
    frames: usize,
    dt: f64,
) -> Result<Vec<(usize, usize)>, DanceError> {
    let start_s = bars[0].start_s;
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
    let needed = if bars.len() > 1 && w > 0 {
        2 * w + 2 * SEAM_KNOTS
    } else {
        1
    };
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

    Ok(bar_frames)
}

/// Unwraps each of the `dofs` angles of the frame after `angles`' first (one frame of `dofs`
/// angles, then the new bar's frames) against that first frame, shifting the whole new bar by
/// whole turns where its first value is more than π away: a DOF's angle stays continuous
/// across the seam.
fn unwrap_against_previous(angles: &mut [f64], dofs: usize) {
    let count = angles.len() / dofs - 1;
    for d in 0..dofs {
        let diff = angles[dofs + d] - angles[d];
        let turns = (diff / std::f64::consts::TAU).round();
        if diff.abs() > std::f64::consts::PI && turns != 0.0 {
            let shift = turns * std::f64::consts::TAU;
            for f in 1..=count {
                angles[f * dofs + d] -= shift;
            }
        }
    }
}

/// Speed-curve samples per segment frame that [`segment_beats`] looks for minima in.
pub const BEAT_SUBSAMPLES: usize = 4;

/// A segment's own beats: the phases of the speed minima near its counts 2 … [`BEATS_PER_BAR`]
/// ([`count_minima`] of the speed curve, by forward kinematics, of the motion the dance plays:
/// the segment on the spline [`assemble`] samples it by, [`BEAT_SUBSAMPLES`] samples a frame: a
/// bar of 32 frames at 85 BPM has a frame every 88 ms, too coarse for beats judged within
/// σ = 50 ms). The speed is taken at one frame per unit time: a bar's length scales the curve,
/// not where its minima are.
pub fn segment_beats(seg: &Segment, model: &crate::humanoid::Figure) -> Vec<Option<f64>> {
    let n = seg.frame_count() * BEAT_SUBSAMPLES;
    let step = 1.0 / BEAT_SUBSAMPLES as f64;
    let mut clip = sample(seg, model.dofs.len(), (0..n).map(|i| i as f64 * step));
    clip.frame_time = step;
    let speed = speed_curve(&clip.to_clip().point_frames(), 1.0 / step);
    count_minima(&speed, BEATS_PER_BAR)
}

/// The warp of `bar` that moves the segment's beats `own` (phases of counts 2, 3, …) onto the
/// song's beats inside the bar; the identity unless the song has exactly `own.len()` beats
/// strictly inside it (module docs).
fn bar_warp(bar: &Bar, beats_s: &[f64], own: &[Option<f64>]) -> Warp {
    let length = bar.end_s - bar.start_s;
    let tol = 1e-6 * length;
    let song: Vec<f64> = beats_s
        .iter()
        .filter(|&&t| t > bar.start_s + tol && t < bar.end_s - tol)
        .map(|&t| (t - bar.start_s) / length)
        .collect();
    if song.len() != own.len() {
        return Warp::identity();
    }
    let pairs: Vec<(f64, f64)> = song
        .iter()
        .zip(own)
        .filter_map(|(&u, w)| w.map(|w| (u, w)))
        .collect();
    Warp::through(&pairs)
}

/// A segment's root positions, orientations and angles at frame positions `xs` (fractional
/// frames from 0 to below frames): angles and root position by the natural cubic spline through
/// the segment's frames (C², so that the time-resized motion has no kinks at the frames; past
/// the last frame its last piece continues), the root orientation by slerp between frames (held
/// past the last); a whole frame is that frame exactly.
fn sample(seg: &Segment, dofs: usize, xs: impl Iterator<Item = f64>) -> FigureClip {
    let m = seg.frame_count();
    let channels = dofs + 3;
    // Channel-major values and the spline's second derivatives.
    let value = |c: usize, i: usize| -> f64 {
        if c < dofs {
            seg.angles[i * dofs + c]
        } else {
            seg.root_translation[i][c - dofs]
        }
    };
    let y: Vec<Vec<f64>> = (0..channels)
        .map(|c| (0..m).map(|i| value(c, i)).collect())
        .collect();
    let second: Vec<Vec<f64>> = y.iter().map(|v| natural_spline(v)).collect();
    let mut out = FigureClip {
        model: humanoid24(),
        frame_time: 1.0,
        root_translation: vec![],
        root_rotation: vec![],
        angles: vec![],
    };
    let mut row = vec![0.0; channels];
    for x in xs {
        let mut x = x.clamp(0.0, m as f64);
        if (x - x.round()).abs() < 1e-9 {
            x = x.round();
        }
        // The spline piece [i, i + 1] (the last one past the last frame), t from its start.
        let i = (x.floor() as usize).min(m.saturating_sub(2));
        let t = x - i as f64;
        let j = (i + 1).min(m - 1);
        for (c, r) in row.iter_mut().enumerate() {
            let (yi, yj, mi, mj) = (y[c][i], y[c][j], second[c][i], second[c][j]);
            let u = 1.0 - t;
            *r = u * yi + t * yj + ((u * u * u - u) * mi + (t * t * t - t) * mj) / 6.0;
        }
        out.angles.extend_from_slice(&row[..dofs]);
        out.root_translation
            .push(DVec3::new(row[dofs], row[dofs + 1], row[dofs + 2]));
        let a = (x - i as f64).min(1.0);
        out.root_rotation.push(if a == 0.0 {
            seg.root_rotation[i]
        } else if a == 1.0 {
            seg.root_rotation[j]
        } else {
            seg.root_rotation[i].slerp(seg.root_rotation[j], a)
        });
    }
    out
}

/// The second derivatives of the natural cubic spline through `y` at unit spacing: M_0 =
/// M_{n−1} = 0, M_{i−1} + 4 M_i + M_{i+1} = 6 (y_{i+1} − 2 y_i + y_{i−1}) (Thomas algorithm).
fn natural_spline(y: &[f64]) -> Vec<f64> {
    let n = y.len();
    let mut m = vec![0.0; n];
    if n < 3 {
        return m;
    }
    // Forward sweep over the interior unknowns 1 ..= n − 2.
    let k = n - 2;
    let mut c = vec![0.0; k];
    let mut d = vec![0.0; k];
    for r in 0..k {
        let i = r + 1;
        let rhs = 6.0 * (y[i + 1] - 2.0 * y[i] + y[i - 1]);
        let (cp, dp) = if r == 0 {
            (0.0, 0.0)
        } else {
            (c[r - 1], d[r - 1])
        };
        let denom = 4.0 - cp;
        c[r] = 1.0 / denom;
        d[r] = (rhs - dp) / denom;
    }
    for r in (0..k).rev() {
        let next = if r + 1 < k { m[r + 2] } else { 0.0 };
        m[r + 1] = d[r] - c[r] * next;
    }
    m
}

/// Frames on each side of a seam window the interpolating spline passes through.
pub const SEAM_KNOTS: usize = 4;

/// The natural cubic spline through the points (`x`, `y`) (x increasing) evaluated at `at`:
/// second derivatives M with M_0 = M_{n−1} = 0 and h_{i−1} M_{i−1} + 2(h_{i−1} + h_i) M_i +
/// h_i M_{i+1} = 6((y_{i+1} − y_i)/h_i − (y_i − y_{i−1})/h_{i−1}) (Thomas algorithm).
fn spline_at(x: &[f64], y: &[f64], at: &[f64]) -> Vec<f64> {
    let n = x.len();
    let mut m = vec![0.0; n];
    if n >= 3 {
        let (mut c, mut d) = (vec![0.0; n], vec![0.0; n]);
        for i in 1..n - 1 {
            let (h0, h1) = (x[i] - x[i - 1], x[i + 1] - x[i]);
            let rhs = 6.0 * ((y[i + 1] - y[i]) / h1 - (y[i] - y[i - 1]) / h0);
            let diag = 2.0 * (h0 + h1) - h0 * c[i - 1];
            c[i] = h1 / diag;
            d[i] = (rhs - h0 * d[i - 1]) / diag;
        }
        for i in (1..n - 1).rev() {
            m[i] = d[i] - c[i] * m[i + 1];
        }
    }
    at.iter()
        .map(|&t| {
            let i = (0..n - 1).rfind(|&i| x[i] <= t).unwrap_or(0);
            let h = x[i + 1] - x[i];
            let (l, r) = (x[i + 1] - t, t - x[i]);
            m[i] * l * l * l / (6.0 * h)
                + m[i + 1] * r * r * r / (6.0 * h)
                + (y[i] / h - m[i] * h / 6.0) * l
                + (y[i + 1] / h - m[i + 1] * h / 6.0) * r
        })
        .collect()
}

/// The rotation vector of `q` on the hemisphere w ≥ 0 (angle ≤ π), radians.
fn log(q: DQuat) -> DVec3 {
    let q = if q.w < 0.0 { -q } else { q };
    q.to_scaled_axis()
}

/// Rewrites frames [s − w, s + w) of `out` by the natural cubic spline through the
/// [`SEAM_KNOTS`] frames of `src` on each side of the window (module docs).
fn rewrite_seam(src: &FigureClip, out: &mut FigureClip, s: usize, w: usize) {
    let knots: Vec<usize> = (s - w - SEAM_KNOTS..s - w)
        .chain(s + w..s + w + SEAM_KNOTS)
        .collect();
    let x: Vec<f64> = knots.iter().map(|&f| f as f64).collect();
    let at: Vec<f64> = (s - w..s + w).map(|f| f as f64).collect();
    let mut y = vec![0.0; knots.len()];
    let channel = |value: Values| -> Vec<f64> {
        for (v, &f) in y.iter_mut().zip(&knots) {
            *v = value(f);
        }
        spline_at(&x, &y, &at)
    };
    rewrite_window(src, out, s - w..s + w, channel);
}

/// One channel's value at any frame of the source clip.
type Values<'a> = &'a dyn Fn(usize) -> f64;

/// Rewrites the frames `window` of `out` channel by channel: every DOF angle, every root
/// coordinate, and the root orientation as the rotation vectors log(q_a⁻¹ q) relative to the
/// frame q_a before the window (q = q_a exp(r), each on q_a's hemisphere), each channel's new
/// values over the window given by `channel` from its values in `src` at any frame.
fn rewrite_window(
    src: &FigureClip,
    out: &mut FigureClip,
    window: std::ops::Range<usize>,
    mut channel: impl FnMut(Values) -> Vec<f64>,
) {
    let d = src.dof_count();
    for j in 0..d {
        let v = channel(&|f| src.angles[f * d + j]);
        for (k, f) in window.clone().enumerate() {
            out.angles[f * d + j] = v[k];
        }
    }
    for c in 0..3 {
        let v = channel(&|f| src.root_translation[f][c]);
        for (k, f) in window.clone().enumerate() {
            out.root_translation[f][c] = v[k];
        }
    }
    let qa = src.root_rotation[window.start - 1];
    let rel = |f: usize| log(qa.inverse() * src.root_rotation[f]);
    let r: Vec<Vec<f64>> = (0..3).map(|c| channel(&|f| rel(f)[c])).collect();
    for (k, f) in window.enumerate() {
        let v = DVec3::new(r[0][k], r[1][k], r[2][k]);
        out.root_rotation[f] = (qa * DQuat::from_scaled_axis(v)).normalize();
    }
}

/// The fade of the position jump across a half window, b(τ) = 1 − 10|τ|³ + 15|τ|⁴ − 6|τ|⁵ for
/// τ ∈ [−1, 1]: 1 at the bar line with b′ = b″ = 0 there, 0 at the window's ends with b′ = b″
/// = 0 (the quintic smootherstep, mirrored).
fn offset_fade(tau: f64) -> f64 {
    let a = tau.abs().min(1.0);
    1.0 - a * a * a * (10.0 - 15.0 * a + 6.0 * a * a)
}

/// The fade of the velocity jump across a half window, c(τ) = τ (1 − |τ|)³: c(0) = 0, c′(0) = 1,
/// c″(0±) = ±6 (which the opposite signs of the two sides turn into one acceleration), 0 at the
/// window's ends with c′ = c″ = 0.
fn velocity_fade(tau: f64) -> f64 {
    let a = tau.abs().min(1.0);
    tau.signum() * a * (1.0 - a).powi(3)
}

/// The fade of the acceleration jump across a half window, e(τ) = ½ τ² (1 − |τ|)³: e(0) = e′(0)
/// = 0, e″(0) = 1, 0 at the window's ends with e′ = e″ = 0.
fn acceleration_fade(tau: f64) -> f64 {
    let a = tau.abs().min(1.0);
    0.5 * a * a * (1.0 - a).powi(3)
}

/// Rewrites frames [s − w, s + w) of `out` ([`Seam::Offset`]) as each side's own motion in
/// `src` plus its half of the jump at the bar line s (module docs). The previous segment is
/// extrapolated to s by the parabola through its last three frames (value p̂, velocity v̂ and
/// acceleration â per frame); the next one has the value x_s and the one-sided velocity
/// v_s = (−3x_s + 4x_{s+1} − x_{s+2}) / 2 and acceleration a_s = x_s − 2x_{s+1} + x_{s+2}.
/// With J = x_s − p̂, V = v_s − v̂ and A = a_s − â, the frames before s get the offset
/// ½ (J b(τ) + V w c(τ) + A w² e(τ)) and those from s on its negative, τ = (f − s) / w
/// ([`offset_fade`], [`velocity_fade`], [`acceleration_fade`]). Both sides then meet at s with
/// the mean of their positions, velocities and accelerations, and the window's
/// ends keep their frames' position, velocity and acceleration.
fn offset_seam(src: &FigureClip, out: &mut FigureClip, s: usize, w: usize) {
    let half = w as f64;
    let shift = |value: Values| -> Vec<f64> {
        let (p1, p2, p3) = (value(s - 1), value(s - 2), value(s - 3));
        let ahead = 3.0 * p1 - 3.0 * p2 + p3;
        let v_before = 0.5 * (5.0 * p1 - 8.0 * p2 + 3.0 * p3);
        let a_before = p1 - 2.0 * p2 + p3;
        let (x0, x1, x2) = (value(s), value(s + 1), value(s + 2));
        let v_after = 0.5 * (-3.0 * x0 + 4.0 * x1 - x2);
        let a_after = x0 - 2.0 * x1 + x2;
        let (jump, dv, da) = (x0 - ahead, v_after - v_before, a_after - a_before);
        (s - w..s + w)
            .map(|f| {
                let side = if f < s { 1.0 } else { -1.0 };
                let tau = (f as f64 - s as f64) / half;
                value(f)
                    + side
                        * 0.5
                        * (jump * offset_fade(tau)
                            + dv * half * velocity_fade(tau)
                            + da * half * half * acceleration_fade(tau))
            })
            .collect()
    };
    rewrite_window(src, out, s - w..s + w, shift);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::choreo::generated::generated_database;

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

    /// Beats at the quarters of every bar.
    fn quarters(bars: &[Bar]) -> Vec<f64> {
        bars.iter()
            .flat_map(|b| (0..4).map(move |c| b.start_s + 0.25 * c as f64 * (b.end_s - b.start_s)))
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
            beat_warp: false,
            seam: Seam::Spline,
        };
        let d = assemble(&db, &segs, &b, &[], &p).unwrap();
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
        let b = bars(6, 1.9, 0.0);
        let d = assemble(&db, &segs, &b, &quarters(&b), &DanceParams::default()).unwrap();
        assert!(
            d.warped_beats.iter().sum::<usize>() > 0,
            "{:?}",
            d.warped_beats
        );
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
            assemble(&empty, &[0, 0], &b, &[], &p),
            Err(DanceError::EmptyDatabase)
        );
        assert_eq!(assemble(&db, &[], &[], &[], &p), Err(DanceError::NoBars));
        assert!(matches!(
            assemble(&db, &[0], &b, &[], &p),
            Err(DanceError::Count { .. })
        ));
        assert!(matches!(
            assemble(&db, &[0, 99], &b, &[], &p),
            Err(DanceError::NoSuchSegment {
                bar: 1,
                segment: 99,
                ..
            })
        ));
        let mut z = b.clone();
        z[1].end_s = z[1].start_s;
        assert!(matches!(
            assemble(&db, &[0, 1], &z, &[], &p),
            Err(DanceError::BadBar { bar: 1, .. })
        ));
        let mut g = b.clone();
        g[1].start_s += 0.5;
        assert!(matches!(
            assemble(&db, &[0, 1], &g, &[], &p),
            Err(DanceError::Gap { bar: 1, .. })
        ));
        for fps in [0.0, -3.0, f64::NAN, 5000.0] {
            let q = DanceParams {
                fps,
                ..DanceParams::default()
            };
            assert!(matches!(
                assemble(&db, &[0, 1], &b, &[], &q),
                Err(DanceError::Fps { .. })
            ));
        }
        let q = DanceParams {
            fps: 5.0,
            ..DanceParams::default()
        };
        let e = assemble(&db, &[0, 1], &b, &[], &q).unwrap_err();
        assert!(
            matches!(
                e,
                DanceError::BarTooShort {
                    frames: 10,
                    needed: 18,
                    ..
                }
            ),
            "{e}"
        );
    }
}

#[cfg(test)]
mod spline_tests {
    #[test]
    fn the_natural_spline_of_a_line_is_flat_and_of_a_cubic_close() {
        let m = super::natural_spline(&[1.0, 2.0, 3.0, 4.0, 5.0]);
        assert!(m.iter().all(|v| v.abs() < 1e-12));
        // y = x² has y'' = 2 inside (the natural ends pull the ends to 0).
        let y: Vec<f64> = (0..40).map(|i| (i as f64).powi(2)).collect();
        let m = super::natural_spline(&y);
        assert!((m[20] - 2.0).abs() < 1e-6, "{}", m[20]);
    }
}

#[cfg(test)]
mod offset_seam_tests {
    use super::*;

    /// A humanoid24 clip of `n` frames whose every angle and root coordinate follows
    /// `value(frame)`, and its heading a tenth of it.
    fn clip(n: usize, value: impl Fn(usize) -> f64) -> FigureClip {
        let model = humanoid24();
        let d = model.dofs.len();
        FigureClip {
            model,
            frame_time: 1.0 / 30.0,
            root_translation: (0..n).map(|f| DVec3::splat(value(f))).collect(),
            root_rotation: (0..n)
                .map(|f| DQuat::from_rotation_y(0.1 * value(f)))
                .collect(),
            angles: (0..n).flat_map(|f| vec![value(f); d]).collect(),
        }
    }

    #[test]
    fn a_motion_without_a_jump_passes_through_unchanged() {
        // A parabola is what the extrapolations assume: no jump of position, velocity or
        // acceleration at the bar line, so nothing to fade.
        let src = clip(40, |f| 0.3 + 0.02 * f as f64 - 0.001 * (f as f64).powi(2));
        let mut out = src.clone();
        offset_seam(&src, &mut out, 20, 5);
        for (a, b) in out.angles.iter().zip(&src.angles) {
            assert!((a - b).abs() < 1e-12);
        }
        for (a, b) in out.root_rotation.iter().zip(&src.root_rotation) {
            assert!((*a - *b).length() < 1e-12, "{a} {b}");
        }
    }

    #[test]
    fn a_jump_is_crossed_away_from_the_bar_line_and_only_inside_the_window() {
        // Two still segments at 0 and 1: the spline crosses the jump fastest at the bar line
        // s = 20; the offset seam crosses it in the middle of each half window and is slowest
        // at the bar line.
        let (s, w) = (20, 5);
        let src = clip(40, |f| if f < s { 0.0 } else { 1.0 });
        let mut offset = src.clone();
        offset_seam(&src, &mut offset, s, w);
        let mut spline = src.clone();
        rewrite_seam(&src, &mut spline, s, w);
        let d = src.dof_count();
        let track = |c: &FigureClip| -> Vec<f64> { (0..40).map(|f| c.angles[f * d]).collect() };
        let (o, p) = (track(&offset), track(&spline));
        let step = |x: &[f64], f: usize| (x[f + 1] - x[f]).abs();
        // Outside the window nothing moves.
        for f in (0..s - w).chain(s + w..40) {
            assert_eq!(o[f], track(&src)[f], "frame {f}");
        }
        // Monotone from 0 to 1, meeting at the mean.
        assert!(o.windows(2).all(|x| x[1] >= x[0]));
        assert!((o[s] - 0.5).abs() < 1e-12);
        // The bar line is a speed minimum of the offset seam (the steps on each side of it
        // are smaller than the next ones out) and the speed maximum of the spline.
        assert!(step(&o, s - 1) < step(&o, s - 2) && step(&o, s) < step(&o, s + 1));
        let inner = s - w..s + w - 1;
        let fastest = inner.max_by(|&a, &b| step(&p, a).total_cmp(&step(&p, b)));
        assert!(
            fastest == Some(s - 1) || fastest == Some(s),
            "spline fastest at {fastest:?}"
        );
    }

    #[test]
    fn a_velocity_jump_meets_at_the_mean_velocity() {
        // Still before the bar line, moving at 0.06 a frame after it.
        let (s, w) = (20, 5);
        let src = clip(40, |f| if f < s { 0.0 } else { 0.06 * (f - s) as f64 });
        let mut out = src.clone();
        offset_seam(&src, &mut out, s, w);
        let d = src.dof_count();
        let x: Vec<f64> = (0..40).map(|f| out.angles[f * d]).collect();
        // Central difference at the bar line: the mean of 0 and 0.06, to the fade's curvature.
        let v = 0.5 * (x[s + 1] - x[s - 1]);
        assert!((v - 0.03).abs() < 0.006, "velocity {v}");
        for f in (0..s - w).chain(s + w..40) {
            assert_eq!(x[f], src.angles[f * d], "frame {f}");
        }
    }
}
