//! Music analysis for choreography: from a mono sample buffer to the song's tempo, its beats, its
//! bars of 4 beats and each bar's intensity (RMS), as the dance-editing paper needs them.
//!
//! One algorithm per file, each a kernel over plain numbers:
//!
//! - [`onsets`]: the onset-strength envelope (spectral flux on a log-magnitude spectrogram);
//! - [`tempo`]: the tempo (autocorrelation of the envelope weighted by a log-normal tempo prior);
//! - [`beats`]: beat placement by dynamic programming on the envelope (Ellis 2007);
//! - [`chroma`]: the harmony between beats and the bass line (pitch-class profiles) and where
//!   they change;
//! - [`bars`]: bars of 4 beats from downbeats tracked on the bass onsets, the onsets, the chord
//!   changes and the bass line's changes (a shorter bar where the song inserts one), or from a
//!   given first downbeat;
//! - [`eval`]: the standard beat, continuity, tempo and downbeat scores against annotations;
//! - [`intensity`]: each bar's RMS and its level in dB;
//! - [`synth`]: a drum track with exact ground truth (tempo, beats, bar loudness) for tests and
//!   the project's own demo song;
//! - [`wav`]: a buffer written as a 16-bit PCM WAV file;
//! - `decode` (feature `audio`): WAV, OGG/Vorbis and MP3 to mono samples with symphonia;
//!
//! [`analyze`] runs them in order.

pub(crate) mod bars;
pub(crate) mod beats;
pub(crate) mod chroma;
#[cfg(feature = "audio")]
pub(crate) mod decode;
pub mod eval;
pub(crate) mod intensity;
pub(crate) mod onsets;
pub(crate) mod synth;
pub(crate) mod tempo;
pub(crate) mod wav;

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

pub use bars::{Bar, bars_from_downbeats, downbeat_evidence, track_downbeats};
pub use beats::{BeatParams, track_beats};
pub use chroma::{Chroma, ChromaParams, half_beat_chroma, harmonic_change, interval_chroma};
#[cfg(feature = "audio")]
pub use decode::{Audio, decode_file};
pub use intensity::{bar_intensity, rms_db};
pub use onsets::{OnsetEnvelope, OnsetParams, onset_envelope};
pub use synth::{SynthSong, synthesize};
pub use tempo::{TempoEstimate, TempoPrior, estimate_tempo};
pub use wav::wav_bytes;

/// Errors of music decoding and analysis.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MusicError {
    /// The song file could not be opened or read.
    #[error("{path}: cannot read the song: {reason}")]
    Io {
        /// The song file.
        path: PathBuf,
        /// The operating system's reason (in the message, so not repeated as a source).
        reason: std::io::Error,
    },
    /// The file is not audio symphonia can read (format, codec or a corrupt stream).
    #[error("{path}: cannot decode the song: {message}")]
    Decode {
        /// The song file.
        path: PathBuf,
        /// What the decoder said.
        message: String,
    },
    /// The sample rate is zero or absurd.
    #[error("sample rate {0} Hz: expected 4000 to 384000 Hz")]
    SampleRate(u32),
    /// A sample is NaN or infinite.
    #[error("sample {index} is not finite: {value}")]
    NonFinite {
        /// Index of the sample.
        index: usize,
        /// Its value.
        value: f32,
    },
    /// The song is silent: no onsets to find beats in.
    #[error("the song is silent (peak level {peak_db:.1} dB): no beats to find")]
    Silent {
        /// Peak absolute sample in dB (−inf for all zeros).
        peak_db: f64,
    },
    /// The song is shorter than the analysis needs.
    #[error("the song lasts {duration_s:.3} s: at least {needed_s:.3} s ({what}) are needed")]
    TooShort {
        /// Its duration (s).
        duration_s: f64,
        /// The least duration needed (s).
        needed_s: f64,
        /// What it is needed for.
        what: &'static str,
    },
    /// Fewer beats than one bar were found.
    #[error("found {beats} beats: a bar needs {needed} (is the song rhythmic?)")]
    TooFewBeats {
        /// Beats found.
        beats: usize,
        /// Beats needed.
        needed: usize,
    },
    /// The onset envelope has no beat structure: its autocorrelation at the best beat period is
    /// below [`MusicParams::min_beat_strength`] (noise, or a song without a pulse).
    #[error(
        "no beat structure found: the onsets repeat at the best beat period ({bpm:.1} BPM) with \
         strength {strength:.3}, below {threshold} (pure noise gives under 0.06, the project's \
         real songs 0.55 to 0.87); the song is refused rather than danced to random beats \
         (set music.min_beat_strength lower to analyse it anyway)"
    )]
    NoBeat {
        /// Normalised autocorrelation of the onset envelope at the period found.
        strength: f64,
        /// The tempo of that period (BPM).
        bpm: f64,
        /// The least strength accepted.
        threshold: f64,
    },
    /// An annotation file is malformed.
    #[error("{path}: line {line}: {message}")]
    Annotation {
        /// The annotation file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// What was expected.
        message: String,
    },
    /// A parameter is out of its range.
    #[error("music parameter {name} = {value}: expected {expected}")]
    Parameter {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: f64,
        /// Its valid range.
        expected: &'static str,
    },
}

/// Parameters of [`analyze`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MusicParams {
    /// The onset envelope.
    pub onsets: OnsetParams,
    /// The tempo prior.
    pub prior: TempoPrior,
    /// The beat tracker.
    pub beats: BeatParams,
    /// The chroma of the harmony between beats (the beat level's check and the downbeats).
    pub chroma: ChromaParams,
    /// Beats per bar (4 for 4/4).
    pub beats_per_bar: usize,
    /// Index of the first downbeat among the beats (0 .. beats_per_bar); every bar then has
    /// `beats_per_bar` beats. Tracked from the signal when `None`.
    pub downbeat: Option<usize>,
    /// The cost of a bar shorter than `beats_per_bar` in the downbeat tracking, in standard
    /// deviations of the downbeat evidence ([`bars`]); `inf` for bars all of the same length.
    pub rephase_sd: f64,
    /// Least beat strength (the onset envelope's normalised autocorrelation at the beat period,
    /// 0 to 1) of a song analysed; below it the song is refused ([`MusicError::NoBeat`]).
    /// Default 0.15: 32 s of white noise measures 0.005 to 0.053, a synthesized song at
    /// −10 dB SNR 0.26 to 0.43, the project's real songs 0.55 to 0.87. 0 accepts any song.
    pub min_beat_strength: f64,
}

impl Default for MusicParams {
    fn default() -> Self {
        MusicParams {
            onsets: OnsetParams::default(),
            prior: TempoPrior::default(),
            beats: BeatParams::default(),
            chroma: ChromaParams::default(),
            beats_per_bar: 4,
            downbeat: None,
            rephase_sd: 8.0,
            min_beat_strength: 0.15,
        }
    }
}

/// The analysis of one song: tempo, beats, bars and their intensity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MusicAnalysis {
    /// Sample rate of the analysed buffer (Hz).
    pub sample_rate: u32,
    /// Duration of the song (s).
    pub duration_s: f64,
    /// Tempo (beats per minute): 60 over the least-squares beat period of the tracked beats.
    pub tempo_bpm: f64,
    /// The tempo the metrical comb found before tracking (BPM).
    pub tempo_prior_bpm: f64,
    /// Every beat time (s), increasing.
    pub beats_s: Vec<f64>,
    /// Beats per bar.
    pub beats_per_bar: usize,
    /// Index in `beats_s` of the first downbeat.
    pub downbeat: usize,
    /// Indices in `beats_s` of every downbeat (the beats that start bars), increasing.
    pub downbeats: Vec<usize>,
    /// Whether `downbeat` was given (true) or chosen from the signal (false).
    pub downbeat_given: bool,
    /// The bars of `beats_per_bar` beats with their RMS.
    pub bars: Vec<Bar>,
    /// The onset-strength envelope the beats were placed on.
    pub onsets: OnsetEnvelope,
}

impl MusicAnalysis {
    /// The number of beats in each bar (its downbeat to the next; the last bar counts its
    /// beats up to its end).
    pub fn bar_beats(&self) -> Vec<usize> {
        self.bars
            .iter()
            .map(|b| {
                let eps = 1e-9;
                self.beats_s
                    .iter()
                    .filter(|&&t| t >= b.start_s - eps && t < b.end_s - eps)
                    .count()
                    .max(1)
            })
            .collect()
    }

    /// "N bars of B beats", or "N bars (K of B beats, M shorter)" when the song inserts shorter
    /// bars.
    pub fn bars_label(&self) -> String {
        let counts = self.bar_beats();
        let full = counts.iter().filter(|&&c| c >= self.beats_per_bar).count();
        let n = self.bars.len();
        if full == n {
            format!("{n} bars of {} beats", self.beats_per_bar)
        } else {
            format!(
                "{n} bars ({full} of {} beats, {} shorter)",
                self.beats_per_bar,
                n - full
            )
        }
    }

    /// Checks that the song has at least `n` bars (a dance needs one per segment). Error:
    /// [`MusicError::TooShort`] with the song's duration and the length of `n` bars.
    pub fn require_bars(&self, n: usize) -> Result<(), MusicError> {
        if self.bars.len() >= n {
            return Ok(());
        }
        let bar_s = self.beats_per_bar as f64 * 60.0 / self.tempo_bpm;
        Err(MusicError::TooShort {
            duration_s: self.duration_s,
            needed_s: n as f64 * bar_s,
            what: "whole bars from its first downbeat",
        })
    }
}

/// Least samples per second [`analyze`] accepts.
pub const MIN_SAMPLE_RATE: u32 = 4_000;
/// Most samples per second [`analyze`] accepts.
pub const MAX_SAMPLE_RATE: u32 = 384_000;

/// Checks the sample rate and that every sample is finite.
pub fn check_samples(samples: &[f32], sample_rate: u32) -> Result<(), MusicError> {
    if !(MIN_SAMPLE_RATE..=MAX_SAMPLE_RATE).contains(&sample_rate) {
        return Err(MusicError::SampleRate(sample_rate));
    }
    if let Some(index) = samples.iter().position(|s| !s.is_finite()) {
        return Err(MusicError::NonFinite {
            index,
            value: samples[index],
        });
    }
    Ok(())
}

/// Analyses a mono song `samples` at `sample_rate` Hz: onset envelope, tempo, beats, bars and
/// bar RMS. A song with beats but less than a whole bar gets no bars (see
/// [`MusicAnalysis::require_bars`]). Errors: a bad rate, sample or parameter, a silent song, a
/// song shorter than four beats at the fastest tempo considered, fewer than two beats.
pub fn analyze(
    samples: &[f32],
    sample_rate: u32,
    params: &MusicParams,
) -> Result<MusicAnalysis, MusicError> {
    check_samples(samples, sample_rate)?;
    params.check()?;
    let bpb = params.beats_per_bar;
    let duration_s = samples.len() as f64 / sample_rate as f64;
    let env = audible_envelope(samples, sample_rate, params)?;
    let tempo = estimate_tempo(&env, &params.prior)?;
    if tempo.strength < params.min_beat_strength {
        return Err(MusicError::NoBeat {
            strength: tempo.strength,
            bpm: tempo.bpm,
            threshold: params.min_beat_strength,
        });
    }
    let (beat_frames, halves) = beat_level(samples, sample_rate, &env, &tempo, params)?;
    let beats_s = times_of(&env, &beat_frames);
    if beats_s.len() < 2 {
        return Err(MusicError::TooFewBeats {
            beats: beats_s.len(),
            needed: 2,
        });
    }
    let tempo_bpm = 60.0 / beats::fitted_period(&beats_s);
    let (downbeats, downbeat_given) = match params.downbeat {
        Some(d) => (bars::regular_downbeats(d, bpb, beats_s.len()), true),
        None => {
            let (halves, bass_halves) = halves
                .unwrap_or_else(|| tonal_halves(samples, sample_rate, &beats_s, &params.chroma));
            let harmony = harmonic_change(&chroma::beat_chroma(&halves), 2);
            let bass = harmonic_change(&chroma::beat_chroma(&bass_halves), 2);
            let z = downbeat_evidence(&env, &beat_frames, &[&harmony, &bass]);
            (track_downbeats(&z, bpb, params.rephase_sd), false)
        }
    };
    let downbeat = downbeats.first().copied().unwrap_or(0);
    let spans = bars_from_downbeats(&beats_s, &downbeats, bpb, duration_s);
    let bars = bar_intensity(samples, sample_rate, &spans);
    Ok(MusicAnalysis {
        sample_rate,
        duration_s,
        tempo_bpm,
        tempo_prior_bpm: tempo.bpm,
        beats_s,
        beats_per_bar: bpb,
        downbeat,
        downbeats,
        downbeat_given,
        bars,
        onsets: env,
    })
}

impl MusicParams {
    /// Checks the bar's parameters, the rephase cost and the least beat strength.
    fn check(&self) -> Result<(), MusicError> {
        let bpb = self.beats_per_bar;
        if !(1..=16).contains(&bpb) {
            return Err(MusicError::Parameter {
                name: "beats_per_bar",
                value: bpb as f64,
                expected: "1 to 16",
            });
        }
        if let Some(d) = self.downbeat
            && d >= bpb
        {
            return Err(MusicError::Parameter {
                name: "downbeat",
                value: d as f64,
                expected: "0 to beats_per_bar − 1",
            });
        }
        if self.rephase_sd.is_nan() || self.rephase_sd < 0.0 {
            return Err(MusicError::Parameter {
                name: "rephase_sd",
                value: self.rephase_sd,
                expected: "a non-negative number or inf",
            });
        }
        if !(0.0..=1.0).contains(&self.min_beat_strength) {
            return Err(MusicError::Parameter {
                name: "min_beat_strength",
                value: self.min_beat_strength,
                expected: "0 to 1",
            });
        }
        Ok(())
    }
}

/// The onset envelope of a song long enough for four beats at the fastest tempo considered and
/// not silent (peak above −90 dB, some onset).
fn audible_envelope(
    samples: &[f32],
    sample_rate: u32,
    params: &MusicParams,
) -> Result<OnsetEnvelope, MusicError> {
    let duration_s = samples.len() as f64 / sample_rate as f64;
    let needed_s = 4.0 * 60.0 / params.prior.max_bpm;
    if duration_s < needed_s {
        return Err(MusicError::TooShort {
            duration_s,
            needed_s,
            what: "four beats at the fastest tempo considered",
        });
    }
    let peak = samples.iter().fold(0f32, |m, s| m.max(s.abs()));
    let peak_db = 20.0 * (peak as f64).log10();
    if peak_db < -90.0 {
        return Err(MusicError::Silent { peak_db });
    }
    let env = onset_envelope(samples, sample_rate, &params.onsets)?;
    if env.values.iter().all(|&v| v <= 0.0) {
        return Err(MusicError::Silent { peak_db });
    }
    Ok(env)
}

/// The beats at the comb's level, or tracked again twice as fast when that level's midpoints
/// are as strong as its beats (a backbeat) or its chords change between its beats (every second
/// beat, or off the beat); with the half-beat chroma and bass chroma of the returned beats when
/// they were taken.
fn beat_level(
    samples: &[f32],
    sample_rate: u32,
    env: &OnsetEnvelope,
    tempo: &TempoEstimate,
    params: &MusicParams,
) -> Result<(Vec<f64>, Option<Halves>), MusicError> {
    let beat_frames = track_beats(env, tempo.period_frames, &params.beats)?;
    let fastest = 60.0 * env.frame_rate() / params.prior.max_bpm;
    if tempo.period_frames / 2.0 < fastest {
        return Ok((beat_frames, None));
    }
    let faster = || track_beats(env, tempo.period_frames / 2.0, &params.beats);
    if beats::midpoint_ratio(env, &beat_frames) >= params.beats.midpoint_ratio {
        return Ok((faster()?, None));
    }
    let times = times_of(env, &beat_frames);
    let halves = tonal_halves(samples, sample_rate, &times, &params.chroma);
    if chroma::midpoint_harmony_ratio(&halves.0) >= params.beats.midpoint_harmony {
        return Ok((faster()?, None));
    }
    Ok((beat_frames, Some(halves)))
}

/// Times (s) of envelope frames.
fn times_of(env: &OnsetEnvelope, frames: &[f64]) -> Vec<f64> {
    frames.iter().map(|&f| env.time_of(f)).collect()
}

/// The chroma and the bass chroma of each half beat of a song's beats.
type Halves = (Vec<Chroma>, Vec<Chroma>);

/// The chroma and the bass chroma of each half beat of `beats_s`
/// ([`chroma::half_beat_chroma_and_bass`]); both empty for a song less tonal than
/// `p.min_tonality` (drums, noise), whose harmony is not used.
fn tonal_halves(samples: &[f32], sample_rate: u32, beats_s: &[f64], p: &ChromaParams) -> Halves {
    let (halves, bass) = chroma::half_beat_chroma_and_bass(samples, sample_rate, beats_s, p);
    if chroma::tonality(&halves) < p.min_tonality {
        return (vec![], vec![]);
    }
    (halves, bass)
}
