//! Dance segments of the dance-editing paper: a dance clip on humanoid24 cut into bars of 4
//! counts (one bar of 4/4), each resampled to a common number of frames per bar, with its
//! motion intensity, its Eros features and its boundary link directions and velocities.
//!
//! Dance capture has no music, so when no manifest gives a clip's tempo and first beat they are
//! found from the motion itself (the kinematic beat, [`kinematic_beat`]):
//!
//! - the speed curve v(f) = Σ_i |ẋ_i(f)| over every joint ([`speed_curve`]), made steady
//!   ([`steady_speed`]): pose jumps (a rest pose in the first frame, a glitch) clipped to
//!   median + [`GLITCH_MADS`] robust deviations, and the trend, its Gaussian mean over one bar at
//!   the slowest tempo, taken off so that a dance that speeds up or slows down keeps its beat;
//! - its autocorrelation r(ℓ) = Σ_f v(f) v(f+ℓ) / ((n − ℓ) σ²) searched for the motion's period
//!   between [`MAX_BPM`] and half [`MIN_BPM`] (two beats of the slowest tempo: a dance whose
//!   clearest repeat is a step every other beat keeps its beat): the highest positive local peak
//!   of r(ℓ) weighted by a log-normal tempo prior, σ one octave, centred on the song's tempo when
//!   the database is built for one and else on [`PRIOR_BPM`] (so that the beat wins over the
//!   two-beat period whose r is as high); refined by a parabola through its neighbours;
//! - the octave level of that period within [`LEVEL_BPM`] nearest the song's tempo, or without a
//!   song the period itself, doubled when slower than [`MIN_BPM`] ([`kinematic_tempo`]);
//! - the first beat, the phase φ ∈ [0, T) whose beats φ + kT fall on the lowest mean steady
//!   speed (dancers mark the count with the minima of their speed).

use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};

use super::eros::{Pca, pca};
pub use super::error::SegmentError;
use super::features::{joint_speeds, mean_motion_intensity, pose_rows};
use crate::humanoid::FigureClip;
use crate::signal::{gaussian_smooth, median};

/// Counts (beats) per segment: one bar of 4/4.
pub const BEATS_PER_BAR: usize = 4;

/// The tempi a clip's beat or a song may have (BPM, both ends included): a tempo given in a
/// manifest, a song's tempo (`--music-bpm`) or a scene's. Outside it a bar is shorter than
/// 0.6 s or longer than 12 s, no dance a database is built for.
pub const TEMPO_RANGE_BPM: (f64, f64) = (20.0, 400.0);

/// The frames every bar may be resampled to ([`BuildParams::bar_frames`], both ends included):
/// at least 2 (a first and a last frame), at most 1024 (32 times the default, a bar of 3 s at
/// 340 fps; each segment's size grows with it).
pub const BAR_FRAMES_RANGE: (usize, usize) = (2, 1024);

/// `Ok` when `bpm` is a tempo within [`TEMPO_RANGE_BPM`], else what is wrong with `what` (the
/// option or field that gave it).
pub fn check_tempo(what: &str, bpm: f64) -> Result<(), String> {
    let (lo, hi) = TEMPO_RANGE_BPM;
    if bpm.is_finite() && (lo..=hi).contains(&bpm) {
        Ok(())
    } else {
        Err(format!(
            "{what} is {bpm} BPM, outside the accepted range {lo} to {hi} BPM"
        ))
    }
}

/// Slowest tempo the kinematic beat looks for, beats per minute (a beat of 1.5 s: slow dances
/// and ballads mark a count this long).
pub const MIN_BPM: f64 = 40.0;

/// Fastest tempo the kinematic beat looks for, beats per minute.
pub const MAX_BPM: f64 = 200.0;

/// The tempi between which a song may take the octave level of a clip's beat, BPM: the beat
/// search's own range.
pub const LEVEL_BPM: (f64, f64) = (MIN_BPM, MAX_BPM);

/// Robust deviations (1.4826 × the median absolute deviation) above the median at which the
/// speed curve is clipped before the beat is searched: a pose jump (a rest pose in a clip's
/// first frame, a marker swap) moves every joint at once and reads tens of times the median
/// speed, while the fastest dance moves stay within a few deviations; one such frame would
/// otherwise carry most of the curve's variance and flatten its autocorrelation.
pub const GLITCH_MADS: f64 = 6.0;

/// Centre of the log-normal tempo prior of the kinematic beat when no song is given, BPM (σ one
/// octave).
pub const PRIOR_BPM: f64 = 120.0;

/// How a clip's tempo and first beat were found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum TempoSource {
    /// Given in the manifest.
    Manifest,
    /// Estimated from the motion (the kinematic beat, module docs), its octave level chosen by
    /// the tempo prior.
    Kinematic,
    /// Estimated from the motion, its octave level the one nearest the song's tempo
    /// ([`BuildParams::music_bpm`]) ([`kinematic_tempo`]).
    KinematicMatched,
}

/// A clip's beat: tempo and the time of its first beat.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Beat {
    /// Tempo, beats per minute.
    pub tempo_bpm: f64,
    /// Time of the first beat from the clip's start, seconds.
    pub first_beat_s: f64,
    /// How they were found.
    pub source: TempoSource,
}

impl Beat {
    /// The bar length, seconds: [`BEATS_PER_BAR`] × 60 / tempo.
    pub fn bar_s(&self) -> f64 {
        BEATS_PER_BAR as f64 * 60.0 / self.tempo_bpm
    }
}

/// The speed curve of a motion, v(f) = Σ_i |ẋ_i(f)| over every point (m/s).
pub fn speed_curve(positions: &[Vec<DVec3>], fps: f64) -> Vec<f64> {
    joint_speeds(positions, fps)
        .iter()
        .map(|s| s.iter().sum())
        .collect()
}

/// The speed curve made steady for the beat search (module docs): each value clipped to
/// median + [`GLITCH_MADS`] × 1.4826 MAD (not at all when the MAD is 0), then its trend taken off, the Gaussian-weighted mean
/// m(f) = Σ_g w(f − g) v(g) / Σ_g w(f − g) with σ one bar of [`BEATS_PER_BAR`] counts at
/// [`MIN_BPM`] (6 s; [`gaussian_smooth`]: the weights cut at ±4σ and renormalised at the curve's
/// ends): it takes off drifts
/// slower than about 30 s (half power at 0.03 Hz) and leaves every beat of the search range
/// whole. Units as `speed`.
pub fn steady_speed(speed: &[f64], fps: f64) -> Vec<f64> {
    if speed.is_empty() {
        return vec![];
    }
    let med = median(speed);
    let mad = median(&speed.iter().map(|v| (v - med).abs()).collect::<Vec<_>>());
    // More than half the frames at one speed (a keyframed clip holding its poses): no spread to
    // tell a glitch from a move by, so nothing is clipped.
    let ceiling = if mad > 0.0 {
        med + GLITCH_MADS * 1.4826 * mad
    } else {
        f64::INFINITY
    };
    let clipped: Vec<f64> = speed.iter().map(|&v| v.min(ceiling)).collect();
    let sigma = BEATS_PER_BAR as f64 * 60.0 / MIN_BPM * fps;
    let trend = gaussian_smooth(&clipped, sigma);
    clipped.iter().zip(&trend).map(|(v, m)| v - m).collect()
}

/// The period of a steady speed curve ([`steady_speed`]) sampled at `fps`, in BPM: the
/// highest positive peak of the normalised autocorrelation between [`MAX_BPM`] and half
/// [`MIN_BPM`], weighted by the log-normal prior centred on `prior_bpm` (module docs; a curve
/// shorter than two of the slowest periods is searched down to the slowest it holds twice);
/// `None` when the curve is constant, holds no two periods of the fastest tempo, or has no
/// positive peak.
fn beat_tempo(steady: &[f64], fps: f64, prior_bpm: f64) -> Option<f64> {
    let n = steady.len();
    let min_lag = (fps * 60.0 / MAX_BPM).floor().max(2.0) as usize;
    let max_lag = ((fps * 120.0 / MIN_BPM).ceil() as usize).min(n.saturating_sub(2) / 2);
    if max_lag < min_lag + 1 {
        return None;
    }
    let mean = steady.iter().sum::<f64>() / n as f64;
    let c: Vec<f64> = steady.iter().map(|v| v - mean).collect();
    let var = c.iter().map(|x| x * x).sum::<f64>() / n as f64;
    if var <= 1e-12 {
        return None;
    }
    let r = |lag: usize| -> f64 {
        let s: f64 = (0..n - lag).map(|f| c[f] * c[f + lag]).sum();
        s / ((n - lag) as f64 * var)
    };
    let rs: Vec<f64> = (min_lag - 1..=max_lag + 1).map(r).collect();
    // The highest local maximum inside the range, weighted by the tempo prior.
    let prior = |k: usize| -> f64 {
        let bpm = 60.0 * fps / (min_lag - 1 + k) as f64;
        (-0.5 * (bpm / prior_bpm).log2().powi(2)).exp()
    };
    let mut best: Option<(usize, f64)> = None;
    for k in 1..rs.len() - 1 {
        let score = rs[k] * prior(k);
        if rs[k] > 0.0
            && rs[k] >= rs[k - 1]
            && rs[k] >= rs[k + 1]
            && best.is_none_or(|(_, b)| score > b)
        {
            best = Some((k, score));
        }
    }
    let (k, _) = best?;
    let (a, b, cc) = (rs[k - 1], rs[k], rs[k + 1]);
    let denom = a - 2.0 * b + cc;
    let offset = if denom.abs() > 1e-15 {
        (0.5 * (a - cc) / denom).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    let lag = (min_lag - 1 + k) as f64 + offset;
    Some(60.0 * fps / lag)
}

/// The kinematic tempo of a speed curve sampled at `fps`, in BPM: the period of its steady curve
/// ([`steady_speed`], [`beat_tempo`], the prior centred on the song's tempo `music_bpm` when
/// given, else on [`PRIOR_BPM`]); with the song, the octave level of it (the period × 2^k)
/// nearest the song's tempo in log scale (|log2(tempo / music_bpm)| least) between
/// [`LEVEL_BPM`]; without, the period, doubled when slower than [`MIN_BPM`]. A motion that
/// repeats every beat repeats every two beats, and a beat halved still has the motion's own
/// beats on every other count, so every level is a metrical level of the motion; the one
/// nearest the song's makes its bars as long as the song's, so it is danced at its own speed
/// (a bar of 5.9 s danced in 2 s would be three times as fast). `None` as [`beat_tempo`].
pub fn kinematic_tempo(speed: &[f64], fps: f64, music_bpm: Option<f64>) -> Option<f64> {
    let music = music_bpm.filter(|m| m.is_finite() && *m > 0.0);
    let period = beat_tempo(&steady_speed(speed, fps), fps, music.unwrap_or(PRIOR_BPM))?;
    let beat = if period < MIN_BPM {
        2.0 * period
    } else {
        period
    };
    let Some(music) = music else {
        return Some(beat);
    };
    let level = (-3..=3)
        .map(|k| beat * 2f64.powi(k))
        .filter(|t| (LEVEL_BPM.0..=LEVEL_BPM.1).contains(t))
        .min_by(|a, b| {
            let d = |t: f64| (t / music).log2().abs();
            d(*a).total_cmp(&d(*b))
        });
    Some(level.unwrap_or(beat))
}

/// The first beat of a speed curve at a known tempo: the phase φ ∈ [0, T) (T = 60/tempo s)
/// whose beats φ + kT have the lowest mean speed (linear interpolation between frames), seconds.
pub fn kinematic_first_beat(speed: &[f64], fps: f64, tempo_bpm: f64) -> f64 {
    let period = 60.0 / tempo_bpm * fps;
    let at = |x: f64| -> f64 {
        let i = x.floor() as usize;
        let t = x - i as f64;
        if i + 1 >= speed.len() {
            speed[speed.len() - 1]
        } else {
            speed[i] * (1.0 - t) + speed[i + 1] * t
        }
    };
    let steps = period.ceil().max(1.0) as usize * 4;
    let mut best = (0.0, f64::INFINITY);
    for s in 0..steps {
        let phase = period * s as f64 / steps as f64;
        let (mut sum, mut count) = (0.0, 0usize);
        let mut x = phase;
        while x <= (speed.len() - 1) as f64 {
            sum += at(x);
            count += 1;
            x += period;
        }
        if count > 0 && sum / (count as f64) < best.1 {
            best = (phase, sum / count as f64);
        }
    }
    best.0 / fps
}

/// The kinematic beat of a motion (tempo by autocorrelation, first beat by the minima of the
/// steady speed, module docs); with
/// the song's tempo `music_bpm`, the octave level nearest it ([`kinematic_tempo`]).
pub fn kinematic_beat(
    clip: &FigureClip,
    name: &str,
    music_bpm: Option<f64>,
) -> Result<Beat, SegmentError> {
    let fps = 1.0 / clip.frame_time;
    let speed = speed_curve(&clip.to_clip().point_frames(), fps);
    let tempo_bpm = kinematic_tempo(&speed, fps, music_bpm).ok_or_else(|| SegmentError::Tempo {
        clip: name.to_string(),
        message: format!(
            "no kinematic tempo between {MIN_BPM} and {MAX_BPM} BPM: the autocorrelation of the \
             speed curve has no positive peak there (no regular speed minima), or the motion is \
             still or shorter than {:.1} s, two beats at {MAX_BPM} BPM ({} frames at {:.1} fps); \
             give tempo_bpm and first_beat_s in a manifest",
            2.0 * 60.0 / MAX_BPM,
            speed.len(),
            fps
        ),
    })?;
    Ok(Beat {
        tempo_bpm,
        first_beat_s: kinematic_first_beat(&steady_speed(&speed, fps), fps, tempo_bpm),
        source: if music_bpm.is_some() {
            TempoSource::KinematicMatched
        } else {
            TempoSource::Kinematic
        },
    })
}

/// How a database is built.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BuildParams {
    /// Frames every segment is resampled to (one bar).
    pub bar_frames: usize,
    /// The weights α_i of the motion intensity, one per drawable point of humanoid24 (joints
    /// then End Sites); missing weights count 1.
    pub alpha: Vec<f64>,
    /// Principal axes kept per segment for Eros (the leading ones; at most the pose rows'
    /// dimension). On the shared dance clips the 16 leading axes of humanoid24's 66 carry 99.9 %
    /// of the database's Eros weight, and the file is 2.4 times smaller (3.0 MB, not 7.1 MB).
    pub eros_axes: usize,
    /// The tempo of the song the database is built for, BPM, when known: each kinematic tempo
    /// takes the octave level nearest it ([`kinematic_tempo`]). A scene sets it to its song's
    /// tempo when it builds from clips.
    #[serde(default)]
    pub music_bpm: Option<f64>,
}

impl BuildParams {
    /// `Ok` when every parameter is within its bounds ([`BAR_FRAMES_RANGE`], a song tempo
    /// within [`TEMPO_RANGE_BPM`], finite weights), else an error naming the parameter, its
    /// value and the accepted range. Checked before any clip is read.
    pub fn check(&self) -> Result<(), SegmentError> {
        let bad = |message: String| SegmentError::Manifest {
            path: "build parameters".into(),
            message,
        };
        let (lo, hi) = BAR_FRAMES_RANGE;
        if !(lo..=hi).contains(&self.bar_frames) {
            return Err(bad(format!(
                "bar_frames is {}, outside the accepted range {lo} to {hi}",
                self.bar_frames
            )));
        }
        if let Some(m) = self.music_bpm {
            check_tempo("music_bpm", m).map_err(bad)?;
        }
        if let Some((i, a)) = self.alpha.iter().enumerate().find(|(_, a)| !a.is_finite()) {
            return Err(bad(format!("alpha[{i}] is {a}, not a finite weight")));
        }
        Ok(())
    }
}

impl Default for BuildParams {
    /// 32 frames per bar, unit weights, 16 Eros axes, no song tempo.
    fn default() -> BuildParams {
        BuildParams {
            bar_frames: 32,
            alpha: vec![],
            eros_axes: 16,
            music_bpm: None,
        }
    }
}

/// One bar of dance on humanoid24, resampled to a common number of frames.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Segment {
    /// Index of the clip it was cut from in the database's sources.
    pub clip: usize,
    /// Bar number within the clip (0-based).
    pub bar: usize,
    /// Start of the bar in the clip, seconds.
    pub start_s: f64,
    /// End of the bar in the clip, seconds.
    pub end_s: f64,
    /// Pelvis position per resampled frame, metres.
    pub root_translation: Vec<DVec3>,
    /// Pelvis orientation per resampled frame.
    pub root_rotation: Vec<DQuat>,
    /// DOF angles, `frames × dofs`, radians.
    pub angles: Vec<f64>,
    /// The paper's motion intensity of the bar, the time average of W(f) = Σ_i α_i |ẋ_i| at the
    /// clip's real timing (m/s with unit weights).
    pub intensity: f64,
    /// Eros features: the leading principal axes ([`BuildParams::eros_axes`]) of the pose rows
    /// (points relative to the pelvis).
    pub eros: Pca,
    /// Unit direction of every link (parent point → point, pelvis excluded) at the first frame,
    /// in the pelvis heading frame (the vertical-axis rotation removed).
    pub first_directions: Vec<DVec3>,
    /// The same at the last frame.
    pub last_directions: Vec<DVec3>,
    /// Velocity of every point at the first frame relative to the pelvis heading, m/s.
    pub first_velocities: Vec<DVec3>,
    /// The same at the last frame.
    pub last_velocities: Vec<DVec3>,
}

impl Segment {
    /// Number of resampled frames.
    pub fn frame_count(&self) -> usize {
        self.root_translation.len()
    }

    /// The segment's motion as a clip on `model` (humanoid24) at its real timing: the bar's
    /// length spread over its resampled frames.
    pub fn clip(&self, model: &crate::humanoid::Figure) -> FigureClip {
        let n = self.frame_count().max(1);
        FigureClip {
            model: model.clone(),
            frame_time: (self.end_s - self.start_s) / n as f64,
            root_translation: self.root_translation.clone(),
            root_rotation: self.root_rotation.clone(),
            angles: self.angles.clone(),
        }
    }
}

/// `clip` resampled at the times `times` (seconds): angles and pelvis position interpolated
/// linearly, pelvis orientation by slerp; times are clamped to the clip.
pub fn resample(clip: &FigureClip, times: &[f64]) -> FigureClip {
    let n = clip.frame_count();
    let d = clip.dof_count();
    let mut out = FigureClip {
        model: clip.model.clone(),
        frame_time: if times.len() > 1 {
            times[1] - times[0]
        } else {
            clip.frame_time
        },
        root_translation: Vec::with_capacity(times.len()),
        root_rotation: Vec::with_capacity(times.len()),
        angles: Vec::with_capacity(times.len() * d),
    };
    for &t in times {
        let x = (t / clip.frame_time).clamp(0.0, (n - 1) as f64);
        let i = (x.floor() as usize).min(n.saturating_sub(2));
        let j = (i + 1).min(n - 1);
        let a = x - i as f64;
        out.root_translation
            .push(clip.root_translation[i].lerp(clip.root_translation[j], a));
        out.root_rotation
            .push(clip.root_rotation[i].slerp(clip.root_rotation[j], a));
        let (p, q) = (clip.frame_angles(i), clip.frame_angles(j));
        out.angles
            .extend(p.iter().zip(q).map(|(u, v)| u + (v - u) * a));
    }
    out
}

/// The rotation about the vertical (Y) axis that undoes the pelvis heading `q`.
fn unheading(q: DQuat) -> DQuat {
    let f = q * DVec3::Z;
    let yaw = f.x.atan2(f.z);
    DQuat::from_rotation_y(-yaw)
}

/// Boundary link directions and velocities at frame `f` of `points` (frames of every point):
/// the unit direction of every link (parent point → point) and the velocity of every point
/// relative to the pelvis, both in the pelvis heading frame (the fields of [`Segment`]).
pub fn boundary(
    points: &[Vec<DVec3>],
    parents: &[Option<usize>],
    root_rotation: DQuat,
    f: usize,
    fps: f64,
) -> (Vec<DVec3>, Vec<DVec3>) {
    let h = unheading(root_rotation);
    let p = &points[f];
    let dirs = parents
        .iter()
        .enumerate()
        .filter_map(|(i, par)| par.map(|q| h * (p[i] - p[q]).normalize_or_zero()))
        .collect();
    let speeds_at = |g: usize| -> Vec<DVec3> {
        let (a, b) = (g.saturating_sub(1), (g + 1).min(points.len() - 1));
        let dt = (b - a).max(1) as f64 / fps;
        (0..p.len())
            .map(|i| h * ((points[b][i] - points[b][0]) - (points[a][i] - points[a][0])) / dt)
            .collect()
    };
    (dirs, speeds_at(f))
}

/// Errors unless `beat` (of the clip `name`) has a tempo in range and a first beat at a time
/// ≥ 0 s.
fn check_beat(name: &str, beat: &Beat) -> Result<(), SegmentError> {
    check_tempo("the tempo", beat.tempo_bpm).map_err(|message| SegmentError::Tempo {
        clip: name.to_string(),
        message,
    })?;
    if !(beat.first_beat_s.is_finite() && beat.first_beat_s >= 0.0) {
        return Err(SegmentError::Tempo {
            clip: name.to_string(),
            message: format!(
                "the first beat must be a time ≥ 0 s, found {} s",
                beat.first_beat_s
            ),
        });
    }
    Ok(())
}

/// The motion intensity of the bar from `start_s` to `end_s` at the clip's own timing, over the
/// frames of the bar, the points weighted by `alpha` (1 past its end).
fn bar_intensity(clip: &FigureClip, start_s: f64, end_s: f64, alpha: &[f64]) -> f64 {
    let fps = 1.0 / clip.frame_time;
    let first = (start_s * fps).round() as usize;
    let last = ((end_s * fps).round() as usize).min(clip.frame_count() - 1);
    let real = clip
        .window(
            first as f64 * clip.frame_time,
            (last + 1) as f64 * clip.frame_time,
        )
        .map(|w| w.to_clip().point_frames())
        .unwrap_or_default();
    let ones: Vec<f64> = (0..real.first().map_or(0, |p| p.len()))
        .map(|i| alpha.get(i).copied().unwrap_or(1.0))
        .collect();
    mean_motion_intensity(&real, fps, &ones)
}

/// Cuts `clip` into bars of [`BEATS_PER_BAR`] counts from `beat`, each resampled to
/// `params.bar_frames` frames at the times start + k·bar/bar_frames; `params.alpha` weighs each
/// point in the motion intensity (missing weights count 1). A clip shorter than a bar is an
/// error.
pub fn cut_segments(
    clip: &FigureClip,
    name: &str,
    clip_index: usize,
    beat: &Beat,
    params: &BuildParams,
) -> Result<Vec<Segment>, SegmentError> {
    let (bar_frames, alpha) = (params.bar_frames, &params.alpha);
    params.check()?;
    check_beat(name, beat)?;
    let bar_s = beat.bar_s();
    // The clip spans frames × frame time (as [`crate::skeleton::Clip::duration`]); the last
    // resampled frame of a bar lies a bar/bar_frames before its end.
    let duration = clip.frame_count() as f64 * clip.frame_time;
    let bars = ((duration - beat.first_beat_s) / bar_s + 1e-9).floor();
    if bars < 1.0 || clip.frame_count() < 2 {
        return Err(SegmentError::TooShort {
            clip: name.to_string(),
            duration_s: (duration - beat.first_beat_s).max(0.0),
            first_beat_s: beat.first_beat_s,
            bar_s,
            counts: BEATS_PER_BAR,
            tempo_bpm: beat.tempo_bpm,
        });
    }
    let parents = clip.model.skeleton().point_parents();
    let mut segments = vec![];
    for bar in 0..bars as usize {
        let start_s = beat.first_beat_s + bar as f64 * bar_s;
        let end_s = start_s + bar_s;
        let intensity = bar_intensity(clip, start_s, end_s, alpha);

        let times: Vec<f64> = (0..bar_frames)
            .map(|k| start_s + bar_s * k as f64 / bar_frames as f64)
            .collect();
        let seg = resample(clip, &times);
        let points = seg.to_clip().point_frames();
        let seg_fps = bar_frames as f64 / bar_s;
        let lastf = points.len() - 1;
        let (first_directions, first_velocities) =
            boundary(&points, &parents, seg.root_rotation[0], 0, seg_fps);
        let (last_directions, last_velocities) =
            boundary(&points, &parents, seg.root_rotation[lastf], lastf, seg_fps);
        segments.push(Segment {
            clip: clip_index,
            bar,
            start_s,
            end_s,
            eros: leading_axes(pca(&pose_rows(&points, 0)), params.eros_axes),
            intensity,
            root_translation: seg.root_translation,
            root_rotation: seg.root_rotation,
            angles: seg.angles,
            first_directions,
            last_directions,
            first_velocities,
            last_velocities,
        });
    }
    Ok(segments)
}

/// The `k` leading principal axes of `p` (all when it has fewer; at least one).
pub fn leading_axes(mut p: Pca, k: usize) -> Pca {
    p.values.truncate(k.max(1));
    p.vectors.truncate(k.max(1));
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A speed curve with a minimum on every beat at `bpm`, starting at `phase_s`.
    fn beat_curve(bpm: f64, phase_s: f64, fps: f64, seconds: f64) -> Vec<f64> {
        let w = 2.0 * std::f64::consts::PI * bpm / 60.0;
        (0..(seconds * fps) as usize)
            .map(|f| {
                let t = f as f64 / fps - phase_s;
                1.5 - (w * t).cos() + 0.3 * (0.5 * w * t).sin().powi(2)
            })
            .collect()
    }

    #[test]
    fn autocorrelation_finds_a_non_integer_tempo() {
        for bpm in [72.5, 97.3, 121.0, 143.7] {
            let s = beat_curve(bpm, 0.21, 120.0, 20.0);
            let t = kinematic_tempo(&s, 120.0, None).unwrap();
            assert!((t / bpm - 1.0).abs() < 0.01, "{bpm}: {t}");
        }
    }

    #[test]
    fn slow_and_fast_dances_keep_their_beat() {
        // 42 and 48 BPM were below the former 60 BPM floor.
        for bpm in [42.0, 48.0] {
            let s = beat_curve(bpm, 0.13, 120.0, 30.0);
            let t = kinematic_tempo(&s, 120.0, None).unwrap();
            assert!((t / bpm - 1.0).abs() < 0.01, "{bpm}: {t}");
        }
        // 190 BPM, above the former 180 ceiling: with its accent on every other beat the prior
        // takes the two-beat level alone; a song near it takes the beat itself.
        let s = beat_curve(190.0, 0.13, 120.0, 30.0);
        let alone = kinematic_tempo(&s, 120.0, None).unwrap();
        assert!((alone / 95.0 - 1.0).abs() < 0.01, "{alone}");
        let matched = kinematic_tempo(&s, 120.0, Some(185.0)).unwrap();
        assert!((matched / 190.0 - 1.0).abs() < 0.01, "{matched}");
    }

    #[test]
    fn a_pose_jump_does_not_hide_the_beat() {
        // A rest pose in the first frame: every joint jumps at once, 400 times the median speed.
        let bpm = 97.3;
        let mut s = beat_curve(bpm, 0.3, 120.0, 20.0);
        s[0] = 600.0;
        s[1] = 250.0;
        let steady = steady_speed(&s, 120.0);
        assert!(steady[0] < 10.0, "clipped: {}", steady[0]);
        let t = kinematic_tempo(&s, 120.0, None).unwrap();
        assert!((t / bpm - 1.0).abs() < 0.01, "{t}");
        let f = kinematic_first_beat(&steady, 120.0, t);
        assert!((f - 0.3).abs() < 0.02, "{f}");
    }

    #[test]
    fn a_dance_that_speeds_up_keeps_its_beat() {
        // The beat's depth and the mean speed both triple over the clip.
        let (bpm, fps) = (71.0, 120.0);
        let s: Vec<f64> = beat_curve(bpm, 0.0, fps, 40.0)
            .iter()
            .enumerate()
            .map(|(f, v)| {
                let g = 1.0 + 2.0 * f as f64 / (40.0 * fps);
                v * g + 3.0 * g
            })
            .collect();
        let t = kinematic_tempo(&s, fps, None).unwrap();
        assert!((t / bpm - 1.0).abs() < 0.01, "{t}");
        // Taking off a linear drift leaves the beat whole: in the middle third, the steady curve
        // (more than 4σ from either end) is the beat less its mean to within 1 % of its swing.
        let beat = beat_curve(bpm, 0.0, fps, 80.0);
        let mean = beat.iter().sum::<f64>() / beat.len() as f64;
        let drifting: Vec<f64> = (0..beat.len()).map(|f| beat[f] + 0.01 * f as f64).collect();
        let steady = steady_speed(&drifting, fps);
        let n = beat.len();
        for f in n / 3..2 * n / 3 {
            assert!(
                (steady[f] - (beat[f] - mean)).abs() < 0.01 * 2.3,
                "frame {f}"
            );
        }
    }

    #[test]
    fn a_clip_of_a_few_beats_is_searched_at_the_tempi_it_holds() {
        // 2.5 s: two beats at 60 BPM or faster, not at 40.
        let s = beat_curve(150.0, 0.1, 120.0, 2.5);
        let t = kinematic_tempo(&s, 120.0, None).unwrap();
        assert!((t / 150.0 - 1.0).abs() < 0.02, "{t}");
    }

    #[test]
    fn a_song_takes_the_octave_level_of_the_beat_nearest_its_tempo() {
        let fps = 100.0;
        let near = |t: Option<f64>, bpm: f64| t.is_some_and(|t| (t / bpm - 1.0).abs() < 0.01);
        let s = beat_curve(82.0, 0.1, fps, 30.0);
        assert!(near(kinematic_tempo(&s, fps, None), 82.0));
        for (music, want) in [
            (82.0, 82.0),
            (136.0, 164.0),
            (120.0, 164.0),
            (110.0, 82.0),
            (50.0, 41.0),
            (300.0, 164.0),
        ] {
            let t = kinematic_tempo(&s, fps, Some(music));
            assert!(near(t, want), "song at {music}: {t:?}, want {want}");
        }
        // A song that is not a number is no song.
        assert!(near(kinematic_tempo(&s, fps, Some(f64::NAN)), 82.0));
    }

    #[test]
    fn first_beat_falls_on_the_speed_minimum() {
        let s = beat_curve(120.0, 0.21, 120.0, 10.0);
        let f = kinematic_first_beat(&s, 120.0, 120.0);
        assert!((f - 0.21).abs() < 0.01, "{f}");
    }

    #[test]
    fn a_still_motion_has_no_tempo() {
        assert_eq!(kinematic_tempo(&[1.0; 2000], 120.0, None), None);
        assert_eq!(kinematic_tempo(&[1.0, 2.0], 120.0, None), None);
        // Still more than half the time (a keyframed clip holding its poses): no glitch can be
        // told, nothing is clipped, and the moves keep their beat.
        let held: Vec<f64> = beat_curve(90.0, 0.0, 120.0, 20.0)
            .iter()
            .map(|v| (v - 1.8).max(0.0))
            .collect();
        assert!(held.iter().filter(|v| **v == 0.0).count() > held.len() / 2);
        let t = kinematic_tempo(&held, 120.0, None).unwrap();
        assert!((t / 90.0 - 1.0).abs() < 0.01, "{t}");
    }
}
