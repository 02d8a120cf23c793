//! Dance segments of the dance-editing paper: a dance clip on humanoid24 cut into bars of 4
//! counts (one bar of 4/4), each resampled to a common number of frames per bar, with its
//! motion intensity, its Eros features and its boundary link directions and velocities.
//!
//! Dance capture has no music, so when no manifest gives a clip's tempo and first beat they are
//! found from the motion itself (the kinematic beat): the speed curve v(f) = Σ_i |ẋ_i(f)| over
//! every joint, less its slow trend ([`detrend`]: a dancer travelling or slowing down), its
//! autocorrelation r(ℓ) = Σ_f (v(f) − v̄)(v(f+ℓ) − v̄) / ((n − ℓ) σ²) searched for the beat
//! period between [`MIN_BPM`] and [`MAX_BPM`] ([`kinematic_tempo`]: the highest local peak of
//! r(ℓ) weighted by a log-normal tempo prior, centre [`PRIOR_BPM`], σ one octave, then its
//! fundamental, and, when the database is built for a song, the octave level the motion
//! supports nearest the song's tempo; refined by a parabola through its neighbours), and the
//! first beat the phase φ ∈ [0, T) whose beats φ + kT fall on the lowest mean speed (dancers
//! mark the count with the minima of their speed).

use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};

use super::eros::{Pca, pca};
use super::features::{joint_speeds, mean_motion_intensity, pose_rows};
use crate::humanoid::ModelClip;

/// Counts (beats) per segment: one bar of 4/4.
pub const BEATS_PER_BAR: usize = 4;

/// Slowest tempo the kinematic beat looks for, beats per minute.
pub const MIN_BPM: f64 = 40.0;

/// Fastest tempo the kinematic beat looks for, beats per minute.
pub const MAX_BPM: f64 = 200.0;

/// Centre of the log-normal tempo prior of the kinematic beat, BPM (σ one octave).
pub const PRIOR_BPM: f64 = 120.0;

/// Why a clip could not be cut into segments or a database built.
#[derive(Debug, thiserror::Error)]
pub enum SegmentError {
    /// A clip shorter than one bar after its first beat.
    #[error(
        "{clip}: the clip lasts {duration_s:.3} s after its first beat at {first_beat_s:.3} s, \
         shorter than one bar of {BEATS_PER_BAR} counts ({bar_s:.3} s at {tempo_bpm:.2} BPM)"
    )]
    TooShort {
        /// The clip.
        clip: String,
        /// Its duration, seconds.
        duration_s: f64,
        /// Its first beat, seconds.
        first_beat_s: f64,
        /// The bar length, seconds.
        bar_s: f64,
        /// The tempo, BPM.
        tempo_bpm: f64,
    },
    /// A tempo or first beat that is not usable (given in a manifest, or not found in the motion).
    #[error("{clip}: {message}")]
    Tempo {
        /// The clip.
        clip: String,
        /// What was wrong.
        message: String,
    },
    /// A folder with no clip in it.
    #[error("{path}: no dance clip in the folder (expected .bvh or keyframed .ron clips)")]
    EmptyFolder {
        /// The folder.
        path: String,
    },
    /// A clip or manifest that could not be read, parsed or mapped onto humanoid24 (the file
    /// named once: the reason's own text when it names it already).
    #[error("{}", name_once(path, source))]
    Load {
        /// The file.
        path: String,
        /// Why.
        #[source]
        source: Box<crate::Error>,
    },
    /// A manifest whose content is inconsistent.
    #[error("{path}: {message}")]
    Manifest {
        /// The manifest.
        path: String,
        /// What was wrong.
        message: String,
    },
    /// A folder or manifest none of whose clips could be used: each clip and why.
    #[error(
        "no clip could be used ({} refused):{}",
        skipped.len(),
        skipped.iter().map(|s| format!("\n  {}", s.reason)).collect::<String>()
    )]
    NoUsableClip {
        /// Every clip and why it was refused.
        skipped: Vec<super::database::Skipped>,
    },
    /// A database file that could not be read or is not a database.
    #[error("{path}: not a dance database: {message}")]
    Database {
        /// The file.
        path: String,
        /// What was wrong (with line and column for JSON errors).
        message: String,
    },
}

/// `source`'s text, preceded by `path` unless it names it already.
fn name_once(path: &str, source: &crate::Error) -> String {
    let s = source.to_string();
    if s.contains(path) {
        s
    } else {
        format!("{path}: {s}")
    }
}

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

/// The speed curve less its slow trend: v(f) − v̄_W(f), v̄_W the centred moving average over
/// W = 60 / [`MIN_BPM`] s (one period of the slowest beat, so that a box of that width has its
/// zeros on every multiple of [`MIN_BPM`] and passes every beat in range with a gain between
/// 0.78 and 1.22, while a trend slower than one cycle in 10 s keeps less than 4 % of itself:
/// a dancer travelling, slowing down or speeding up does not swamp the beat). Only the frames
/// whose whole window lies inside the curve are kept (the first and last W/2 are dropped).
pub fn detrend(speed: &[f64], fps: f64) -> Vec<f64> {
    let h = (0.5 * fps * 60.0 / MIN_BPM).round().max(1.0) as usize;
    let n = speed.len();
    if n < 2 * h + 1 {
        return vec![];
    }
    let mut prefix = Vec::with_capacity(n + 1);
    prefix.push(0.0);
    for v in speed {
        prefix.push(prefix[prefix.len() - 1] + v);
    }
    let w = (2 * h + 1) as f64;
    (h..n - h)
        .map(|f| speed[f] - (prefix[f + h + 1] - prefix[f - h]) / w)
        .collect()
}

/// The normalised autocorrelation r(ℓ) of a detrended curve: tabulated over the lags of the
/// tempo range, computed where asked beyond it.
struct Autocorrelation {
    /// The curve less its mean.
    c: Vec<f64>,
    /// Its variance σ².
    var: f64,
    /// The first tabulated lag, frames.
    lag0: usize,
    /// r(lag0 + k).
    table: Vec<f64>,
}

impl Autocorrelation {
    /// r(ℓ) = Σ_f c(f) c(f+ℓ) / ((n − ℓ) σ²) of `c` (mean removed here), tabulated for ℓ in
    /// `lags`; `None` when `c` is constant or shorter than the last lag.
    fn of(c: &[f64], lags: std::ops::RangeInclusive<usize>) -> Option<Autocorrelation> {
        let n = c.len();
        if n <= *lags.end() {
            return None;
        }
        let mean = c.iter().sum::<f64>() / n as f64;
        let c: Vec<f64> = c.iter().map(|v| v - mean).collect();
        let var = c.iter().map(|x| x * x).sum::<f64>() / n as f64;
        if var <= 1e-12 {
            return None;
        }
        let mut acf = Autocorrelation {
            c,
            var,
            lag0: *lags.start(),
            table: vec![],
        };
        acf.table = lags.map(|lag| acf.at(lag)).collect();
        Some(acf)
    }

    /// r(`lag`), from the table when it holds it (`lag` < n).
    fn at(&self, lag: usize) -> f64 {
        if let Some(r) = lag.checked_sub(self.lag0).and_then(|k| self.table.get(k)) {
            return *r;
        }
        let n = self.c.len();
        let s: f64 = (0..n - lag).map(|f| self.c[f] * self.c[f + lag]).sum();
        s / ((n - lag) as f64 * self.var)
    }

    /// r at a fractional lag, linear between the integer lags around it.
    fn interpolated(&self, lag: f64) -> f64 {
        let i = lag.floor() as usize;
        let t = lag - i as f64;
        self.at(i) * (1.0 - t) + self.at(i + 1) * t
    }

    /// Whether the motion comes back after `lag` frames as a level of a beat of `beat_lag`
    /// frames: r at `lag` above r at lag ± w, w = min(lag, beat_lag)/4, half-way to the
    /// troughs of the shorter period (so r peaks within about w/2 of `lag`).
    fn supports(&self, lag: f64, beat_lag: f64) -> bool {
        let w = 0.25 * lag.min(beat_lag);
        if lag - w < 1.0 || lag + w + 1.0 > self.max_lag() as f64 {
            return false;
        }
        let r = self.interpolated(lag);
        r > self.interpolated(lag - w) && r > self.interpolated(lag + w)
    }

    /// The longest lag r is looked at: half the curve, so that at least half of its frames
    /// enter every r(ℓ).
    fn max_lag(&self) -> usize {
        self.c.len() / 2
    }

    /// The highest point of r over the integer lags of [lo, hi] (within 1 ..= [`Self::max_lag`])
    /// when it lies strictly inside that window (higher than r at both ends): its lag refined by
    /// a parabola through its neighbours, and its height. `None` when r rises to an end of the
    /// window.
    fn peak_in(&self, lo: f64, hi: f64) -> Option<Peak> {
        let a = lo.ceil().max(1.0) as usize;
        let b = hi.floor().min(self.max_lag() as f64).max(0.0) as usize;
        if b < a + 2 {
            return None;
        }
        let (k, _) = (a..=b)
            .map(|l| (l, self.at(l)))
            .fold((a, f64::NEG_INFINITY), |m, x| if x.1 > m.1 { x } else { m });
        if k == a || k == b {
            return None;
        }
        Some(self.refined(k))
    }

    /// The peak at lag `k` (a local maximum) refined by a parabola through its neighbours.
    fn refined(&self, k: usize) -> Peak {
        let (a, b, c) = (self.at(k - 1), self.at(k), self.at(k + 1));
        let denom = a - 2.0 * b + c;
        let offset = if denom.abs() > 1e-15 {
            (0.5 * (a - c) / denom).clamp(-0.5, 0.5)
        } else {
            0.0
        };
        let correction = -0.25 * (a - c) * offset;
        Peak {
            lag: k as f64 + offset,
            r: b + correction,
            correction: correction.abs(),
        }
    }

    /// Every positive local maximum of r inside the table.
    fn peaks(&self) -> impl Iterator<Item = Peak> + '_ {
        let r = &self.table;
        (1..r.len() - 1)
            .filter(|&k| r[k] > 0.0 && r[k] >= r[k - 1] && r[k] >= r[k + 1])
            .map(|k| self.refined(self.lag0 + k))
    }
}

/// A peak of the autocorrelation: its lag (frames, refined) and height, and how much the
/// parabola moved the height from the highest sampled lag (the resolution of the height).
#[derive(Debug, Clone, Copy)]
struct Peak {
    lag: f64,
    r: f64,
    correction: f64,
}

/// The log-normal tempo prior of the kinematic beat at `bpm`: exp(−½ log2(bpm / 120)²).
fn tempo_prior(bpm: f64) -> f64 {
    (-0.5 * (bpm / PRIOR_BPM).log2().powi(2)).exp()
}

/// The peak of the octave level `lag` (frames) of a beat of `beat_lag` frames: the highest
/// point of r strictly inside lag ± p/4, p the shorter of the two periods (a motion that
/// repeats every p frames has its troughs of r at lag ± p/2: the window reaches half-way to
/// them). `None` when r has no peak there: nothing in the motion comes back after `lag`
/// more than around it. (r need not be positive at the peak: for a speed curve
/// v(t) = cos ωt + a cos 2ωt, r ∝ cos ωℓ + a² cos 2ωℓ has a peak at ℓ = π/ω, the half
/// period, as soon as a > ½, while r(π/ω) > 0 only for a > 1.)
fn level_peak(acf: &Autocorrelation, lag: f64, beat_lag: f64) -> Option<Peak> {
    let half = 0.25 * lag.min(beat_lag);
    acf.peak_in(lag - half, lag + half)
}

/// The period (frames) of the level whose peak is `p`, measured on its farthest repetition:
/// a peak's refined lag is within half a frame of the true one, so the period measured on the
/// k-th repetition is within 1/(2k) frame, and r's peak at the 2k-th repetition is predicted
/// within a frame, plus half a frame of its own. While r has a peak ([`level_peak`]) there,
/// that close, the period becomes its lag over 2k (each doubling halves the error); up to
/// [`Autocorrelation::max_lag`]. A motion whose tempo drifts stops early, on its own peak.
fn farthest_period(acf: &Autocorrelation, p: Peak) -> f64 {
    let (mut period, mut k) = (p.lag, 1.0);
    while let Some(q) = level_peak(acf, 2.0 * k * period, period) {
        if (q.lag - 2.0 * k * period).abs() > 1.5 {
            break;
        }
        k *= 2.0;
        period = q.lag / k;
    }
    period
}

/// The kinematic tempo of a speed curve sampled at `fps`, in BPM, between [`MIN_BPM`] and
/// [`MAX_BPM`], from the autocorrelation r(ℓ) of the detrended curve ([`detrend`]):
///
/// 1. the beat is the positive local maximum of r with the highest r(ℓ) · prior(ℓ), the
///    log-normal tempo prior (centre [`PRIOR_BPM`], σ one octave) that makes the beat win over
///    the two-beat period whose r is as high;
/// 2. its fundamental: while r has a peak at half the lag (a supported level, below) at least
///    as high (within the two heights' resolution: what the parabola added to each sampled
///    peak), the motion repeats
///    as well twice as often and the tempo doubles (a motion that repeats every beat also
///    repeats every two beats: the prior alone would halve a fast tempo);
/// 3. with the song's tempo `music_bpm`, the octave level (the tempo × 2^k, k = −2..2, in
///    range) nearest the song's tempo in log scale (|log2(tempo / music_bpm)| least), a finer
///    level (k > 0) always (it divides the motion's beat evenly, so the motion's beats stay on
///    its counts and its bars take the song's length: a 41 BPM salsa bar of 5.9 s would be
///    danced three times as fast in a 2 s bar of a 120 BPM song), a coarser one (k < 0) when
///    the motion supports it. A level of ℓ frames, for a beat of L, is supported
///    when r(ℓ) is above r(ℓ ± w), w = min(ℓ, L)/4 (half-way to the troughs of the shorter
///    period): r peaks within about w/2 of ℓ. r need not be positive there: for
///    v(t) = cos ωt + a cos 2ωt, r ∝ cos ωℓ + a² cos 2ωℓ supports the half period as soon as
///    a > 0.54, though r(π/ω) > 0 only for a > 1. Only octaves: a bar is four beats of 4/4,
///    and a 3:2 level would cut bars across the dance's own beats.
///
/// The tempo is the beat's period measured on its farthest repetition (while r peaks
/// within 1.5 frames of twice the last multiple found, the period is that peak's lag over its
/// multiple: half a frame of error on the first peak predicts the next within a frame, plus
/// half a frame of its own; up to half the curve's length), each peak's lag refined by a
/// parabola through its neighbours, times the octave the song chose, kept in range (the
/// refinement moves it by less than half a frame of lag). `None` when the curve is too short
/// for two periods of the slowest tempo (plus the detrending window), is constant after
/// detrending, or r has no positive peak in range.
pub fn kinematic_tempo(speed: &[f64], fps: f64, music_bpm: Option<f64>) -> Option<f64> {
    let min_lag = (fps * 60.0 / MAX_BPM).floor().max(2.0) as usize;
    let max_lag = (fps * 60.0 / MIN_BPM).ceil() as usize;
    let c = detrend(speed, fps);
    if c.len() < 2 * max_lag + 2 {
        return None;
    }
    let acf = Autocorrelation::of(&c, min_lag - 1..=max_lag + 1)?;
    let bpm = |lag: f64| 60.0 * fps / lag;
    let in_range = |p: &Peak| (MIN_BPM..=MAX_BPM).contains(&bpm(p.lag));
    let mut beat = acf
        .peaks()
        .filter(in_range)
        .map(|p| (p, p.r * tempo_prior(bpm(p.lag))))
        .fold(None::<(Peak, f64)>, |best, (p, s)| match best {
            Some((_, b)) if b >= s => best,
            _ => Some((p, s)),
        })?
        .0;
    loop {
        let half = 0.5 * beat.lag;
        let Some(h) = level_peak(&acf, half, beat.lag).filter(in_range) else {
            break;
        };
        if !acf.supports(half, beat.lag) || h.r + h.correction + beat.correction < beat.r {
            break;
        }
        beat = h;
    }
    let mut octave = 1.0;
    if let Some(music) = music_bpm.filter(|m| m.is_finite() && *m > 0.0) {
        let distance = |lag: f64| (bpm(lag) / music).log2().abs();
        for k in [-2, -1, 1, 2] {
            let m = 2f64.powi(k);
            let lag = beat.lag / m;
            // A finer level (k > 0) divides the beat evenly: the motion's own beats fall on
            // every 2^k-th count of it, whether or not it moves at the finer period too, and
            // its bars are as many beats of the song's length. A coarser level needs the
            // motion to come back there.
            let level =
                (MIN_BPM..=MAX_BPM).contains(&bpm(lag)) && (k > 0 || acf.supports(lag, beat.lag));
            if level && distance(lag) < distance(beat.lag / octave) {
                octave = m;
            }
        }
    }
    Some((octave * bpm(farthest_period(&acf, beat))).clamp(MIN_BPM, MAX_BPM))
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

/// The kinematic beat of a motion (tempo by autocorrelation, first beat by speed minima); with
/// the song's tempo `music_bpm`, the octave level nearest it ([`kinematic_tempo`]).
pub fn kinematic_beat(
    clip: &ModelClip,
    name: &str,
    music_bpm: Option<f64>,
) -> Result<Beat, SegmentError> {
    let fps = 1.0 / clip.frame_time;
    let speed = speed_curve(&clip.to_clip().point_frames(), fps);
    let tempo_bpm = kinematic_tempo(&speed, fps, music_bpm).ok_or_else(|| SegmentError::Tempo {
        clip: name.to_string(),
        message: format!(
            "no kinematic tempo between {MIN_BPM} and {MAX_BPM} BPM: the autocorrelation of the \
             detrended speed curve has no positive peak there (no regular speed minima), or the \
             motion is still or shorter than {:.1} s ({} frames at {:.1} fps); give tempo_bpm \
             and first_beat_s in a manifest",
            3.0 * 60.0 / MIN_BPM,
            speed.len(),
            fps
        ),
    })?;
    Ok(Beat {
        tempo_bpm,
        first_beat_s: kinematic_first_beat(&speed, fps, tempo_bpm),
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
    pub fn clip(&self, model: &crate::humanoid::Model) -> ModelClip {
        let n = self.frame_count().max(1);
        ModelClip {
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
pub fn resample(clip: &ModelClip, times: &[f64]) -> ModelClip {
    let n = clip.frame_count();
    let d = clip.dof_count();
    let mut out = ModelClip {
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

/// Cuts `clip` into bars of [`BEATS_PER_BAR`] counts from `beat`, each resampled to
/// `params.bar_frames` frames at the times start + k·bar/bar_frames; `params.alpha` weighs each
/// point in the motion intensity (missing weights count 1). A clip shorter than a bar is an
/// error.
pub fn cut_segments(
    clip: &ModelClip,
    name: &str,
    clip_index: usize,
    beat: &Beat,
    params: &BuildParams,
) -> Result<Vec<Segment>, SegmentError> {
    let (bar_frames, alpha) = (params.bar_frames, &params.alpha);
    let usable = beat.tempo_bpm.is_finite()
        && beat.tempo_bpm > 0.0
        && beat.first_beat_s.is_finite()
        && beat.first_beat_s >= 0.0;
    if !usable {
        return Err(SegmentError::Tempo {
            clip: name.to_string(),
            message: format!(
                "tempo must be a positive number of BPM and the first beat a time ≥ 0 s, found \
                 {} BPM and {} s",
                beat.tempo_bpm, beat.first_beat_s
            ),
        });
    }
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
            tempo_bpm: beat.tempo_bpm,
        });
    }
    let fps = 1.0 / clip.frame_time;
    let parents = clip.model.skeleton().point_parents();
    let mut segments = vec![];
    for bar in 0..bars as usize {
        let start_s = beat.first_beat_s + bar as f64 * bar_s;
        let end_s = start_s + bar_s;
        // Intensity at the clip's own timing, over the frames of the bar.
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
        let intensity = mean_motion_intensity(&real, fps, &ones);

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

    /// `curve` with a slow trend added: a ramp of `ramp` m/s over the curve and a sinusoid of
    /// amplitude `wave` m/s and period 12.7 s.
    fn with_trend(curve: &[f64], fps: f64, ramp: f64, wave: f64) -> Vec<f64> {
        let n = curve.len() as f64;
        curve
            .iter()
            .enumerate()
            .map(|(f, v)| {
                let t = f as f64 / fps;
                v + ramp * f as f64 / n + wave * (2.0 * std::f64::consts::PI * t / 12.7).sin()
            })
            .collect()
    }

    #[test]
    fn a_slow_trend_does_not_hide_the_beat_from_40_to_200_bpm() {
        // The beat's own swing is 2.3 m/s peak to peak; the trend's 6 m/s ramp and ±2 m/s
        // sinusoid are larger (a dancer who travels faster and faster, and slows).
        let mut bpm = MIN_BPM;
        while bpm <= MAX_BPM {
            for fps in [30.0, 120.0] {
                let s = with_trend(&beat_curve(bpm, 0.13, fps, 24.0), fps, 6.0, 2.0);
                let t = kinematic_tempo(&s, fps, None);
                assert!(
                    t.is_some_and(|t| (t / bpm - 1.0).abs() < 0.01),
                    "{bpm} BPM at {fps} fps: {t:?}"
                );
            }
            bpm *= 1.0721; // 24 tempi from 40 to 200 BPM, none on a round lag
        }
    }

    #[test]
    fn detrending_removes_a_ramp_and_keeps_the_beat() {
        let fps = 60.0;
        let ramp: Vec<f64> = (0..600).map(|f| 0.01 * f as f64).collect();
        let d = detrend(&ramp, fps);
        assert_eq!(d.len(), 600 - 2 * 45);
        assert!(d.iter().all(|x| x.abs() < 1e-9), "{d:?}");
        // A beat at 40 BPM (the box is exactly one period wide) passes whole.
        let beat: Vec<f64> = (0..600)
            .map(|f| (2.0 * std::f64::consts::PI * f as f64 / 90.0).cos())
            .collect();
        let d = detrend(&beat, fps);
        let peak = d.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!((peak - 1.0).abs() < 0.02, "{peak}");
    }

    /// A speed curve at `bpm` with a component twice as fast of amplitude `half` (the first's
    /// is 0.6 m/s): a dancer who marks every beat and, more strongly, every half beat.
    fn with_half_beats(bpm: f64, half: f64, fps: f64, seconds: f64) -> Vec<f64> {
        let w = 2.0 * std::f64::consts::PI * bpm / 60.0;
        (0..(seconds * fps) as usize)
            .map(|f| {
                let t = f as f64 / fps;
                2.0 - 0.6 * (w * t).cos() - half * (2.0 * w * t + 0.4).cos()
            })
            .collect()
    }

    #[test]
    fn the_octave_level_nearest_the_song_is_chosen() {
        let fps = 100.0;
        let near = |t: Option<f64>, bpm: f64| t.is_some_and(|t| (t / bpm - 1.0).abs() < 0.01);
        // 75 BPM with stronger half beats: alone, 75 (the prior and the full period); for a
        // song at 150 (or 140, or 170), the 150 BPM level; for a song at 75 or 70, 75.
        let s = with_half_beats(75.0, 1.0, fps, 30.0);
        let t = kinematic_tempo(&s, fps, None);
        assert!(near(t, 75.0), "{t:?}");
        for (music, want) in [(150.0, 150.0), (140.0, 150.0), (170.0, 150.0), (75.0, 75.0)] {
            let t = kinematic_tempo(&s, fps, Some(music));
            assert!(near(t, want), "song at {music}: {t:?}, want {want}");
        }
        let t = kinematic_tempo(&s, fps, Some(70.0));
        assert!(near(t, 75.0), "{t:?}");
        // Half beats weak or absent: the finer level divides the beat evenly all the same, and
        // a song at 150 takes it.
        for half in [0.45, 0.24, 0.0] {
            let s = with_half_beats(75.0, half, fps, 30.0);
            let t = kinematic_tempo(&s, fps, Some(150.0));
            assert!(near(t, 150.0), "half beats {half}: {t:?}");
        }
        // A coarser level needs the motion to come back there: 75 BPM with strong half beats
        // repeats every 75 BPM beat, and a song at 37.5 BPM (out of range) leaves it at 75;
        // a song at 40 takes 37.5 only in range, so the nearest level in range, 75, stays.
        let s = with_half_beats(75.0, 1.0, fps, 30.0);
        let t = kinematic_tempo(&s, fps, Some(40.0));
        assert!(near(t, 75.0), "{t:?}");
        // A motion at 160 BPM repeats every two beats too: for a song at 80, 80; alone, 160
        // (its fundamental, though the prior weighs 80 more).
        let s = beat_curve(160.0, 0.1, fps, 30.0);
        let t = kinematic_tempo(&s, fps, None);
        assert!(near(t, 160.0), "{t:?}");
        let t = kinematic_tempo(&s, fps, Some(82.0));
        assert!(near(t, 80.0), "{t:?}");
        // A song at 45 BPM takes a 180 BPM motion two octaves down (45, in range).
        let s = beat_curve(180.0, 0.1, fps, 30.0);
        let t = kinematic_tempo(&s, fps, Some(45.0));
        assert!(near(t, 45.0), "{t:?}");
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
    }
}
