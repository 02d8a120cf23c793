//! A drum track with exact ground truth, for testing the music kernel and as the project's own
//! demo song: kick on every beat (loudest on the downbeat, with a bass note), snare on the
//! even beats, hi-hat on every eighth (the off-beat eighth delayed by the swing), white noise at
//! a given signal-to-noise ratio and a little random timing jitter. Each bar's hits are scaled
//! so that on their own they have the bar's given level as RMS over the bar; the ground truth
//! [`SynthTrack::bar_rms_db`] is the RMS actually in the samples of each bar (the given level
//! plus the noise and the tails of the bar before).

use std::f64::consts::PI;

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use serde::{Deserialize, Serialize};

use super::MusicError;

/// What to synthesize.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SynthSong {
    /// Tempo (BPM), any positive real.
    pub bpm: f64,
    /// Number of bars.
    pub bars: usize,
    /// Beats per bar.
    pub beats_per_bar: usize,
    /// Where the off-beat eighth falls, as a fraction of the beat (0.5 straight, 2/3 triplet
    /// swing).
    pub swing: f64,
    /// Level of each bar (dB re an RMS of 1), cycled when there are fewer levels than bars.
    pub bar_levels_db: Vec<f64>,
    /// Signal-to-noise ratio of the white noise added to each bar (dB); `None` for none.
    pub snr_db: Option<f64>,
    /// Standard deviation of the random timing of each drum hit (s).
    pub jitter_s: f64,
    /// Silence (with noise) before the first downbeat (s).
    pub lead_in_s: f64,
    /// Sound after the last bar (decays and noise) (s).
    pub tail_s: f64,
    /// Sample rate (Hz).
    pub sample_rate: u32,
    /// Seed of the noise and jitter.
    pub seed: u64,
}

impl Default for SynthSong {
    fn default() -> Self {
        SynthSong {
            bpm: 120.0,
            bars: 16,
            beats_per_bar: 4,
            swing: 0.5,
            bar_levels_db: vec![-20.0, -15.0, -21.0, -17.0],
            snr_db: Some(20.0),
            jitter_s: 0.003,
            lead_in_s: 0.5,
            tail_s: 0.5,
            sample_rate: 22_050,
            seed: 1,
        }
    }
}

/// A synthesized song and its ground truth.
#[derive(Debug, Clone, PartialEq)]
pub struct SynthTrack {
    /// Mono samples.
    pub samples: Vec<f32>,
    /// Sample rate (Hz).
    pub sample_rate: u32,
    /// The beat times (s): the nominal grid, without jitter.
    pub beats_s: Vec<f64>,
    /// The bars' spans (s), from downbeat to downbeat.
    pub bars_s: Vec<(f64, f64)>,
    /// Each bar's RMS level (dB re 1) as in the samples, over [start, end) of `bars_s`.
    pub bar_rms_db: Vec<f64>,
}

/// Most samples [`synthesize`] makes (one hour at 48 kHz).
const MAX_SAMPLES: f64 = 3600.0 * 48_000.0;

/// Adds one drum sound starting at time `t0` (s) with amplitude `a` into `x`.
fn hit(x: &mut [f64], sr: f64, t0: f64, a: f64, kind: Drum, rng: &mut Pcg64) {
    let len = (kind.length_s() * sr) as usize;
    let start = (t0 * sr).round();
    if start < 0.0 {
        return;
    }
    let start = start as usize;
    let mut prev = 0.0;
    for k in 0..len {
        let Some(s) = x.get_mut(start + k) else { break };
        let t = k as f64 / sr;
        let v = match kind {
            Drum::Kick => {
                let tau = 0.03;
                let phase = 2.0 * PI * (50.0 * t + 100.0 * tau * (1.0 - (-t / tau).exp()));
                (-t / 0.12).exp() * phase.sin()
            }
            Drum::Snare => {
                let n: f64 = rng.random_range(-1.0..1.0);
                (-t / 0.07).exp() * (0.6 * n + 0.4 * (2.0 * PI * 185.0 * t).sin())
            }
            Drum::Hat => {
                let n: f64 = rng.random_range(-1.0..1.0);
                let hp = n - prev;
                prev = n;
                0.5 * (-t / 0.025).exp() * hp
            }
            Drum::Bass => (-t / 0.6).exp() * (2.0 * PI * 55.0 * t).sin(),
        };
        *s += a * v;
    }
}

#[derive(Clone, Copy)]
enum Drum {
    Kick,
    Snare,
    Hat,
    Bass,
}

impl Drum {
    fn length_s(self) -> f64 {
        match self {
            Drum::Kick => 0.5,
            Drum::Snare => 0.4,
            Drum::Hat => 0.15,
            Drum::Bass => 2.0,
        }
    }
}

/// Synthesizes `song` (see the module docs). Errors: parameters out of range or a song longer
/// than an hour at 48 kHz.
pub fn synthesize(song: &SynthSong) -> Result<SynthTrack, MusicError> {
    check_song(song)?;
    let sr = song.sample_rate as f64;
    let beat = 60.0 / song.bpm;
    let bar = beat * song.beats_per_bar as f64;
    let duration = song.lead_in_s + song.bars as f64 * bar + song.tail_s;
    if duration * sr > MAX_SAMPLES {
        return Err(MusicError::Parameter {
            name: "duration",
            value: duration,
            expected: "at most an hour at 48 kHz",
        });
    }
    let n = (duration * sr).ceil() as usize;
    let mut rng = Pcg64::seed_from_u64(song.seed);
    let (beats_s, bars_s, hits) = drum_hits(song, &mut rng);
    let span = |(a, b): (f64, f64)| {
        let lo = ((a * sr).ceil() as usize).min(n);
        let hi = ((b * sr).ceil() as usize).clamp(lo, n);
        lo..hi
    };
    let regions: Vec<std::ops::Range<usize>> = bars_s.iter().map(|&s| span(s)).collect();
    let noise_seed = song.seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let gains = bar_gains(song, &hits, &regions, n, noise_seed);
    // The song: every hit at its bar's gain, then white noise at the SNR of each bar's level
    // (the lead-in takes the first bar's, the tail the last's).
    let mut x = vec![0.0f64; n];
    let mut hr = Pcg64::seed_from_u64(noise_seed);
    for &(b, t, a, d) in &hits {
        hit(&mut x, sr, t, a * gains[b], d, &mut hr);
    }
    if let Some(snr) = song.snr_db {
        for (i, v) in x.iter_mut().enumerate() {
            let b = regions.partition_point(|r| r.end <= i).min(song.bars - 1);
            let level = song.bar_levels_db[b % song.bar_levels_db.len()];
            let a = 10f64.powf((level - snr) / 20.0) * 3f64.sqrt();
            let u: f64 = rng.random_range(-1.0..1.0);
            *v += a * u;
        }
    }
    let bar_rms_db = regions
        .iter()
        .map(|r| 20.0 * rms(&x[r.clone()]).max(1e-12).log10())
        .collect();
    Ok(SynthTrack {
        samples: x.iter().map(|&s| s as f32).collect(),
        sample_rate: song.sample_rate,
        beats_s,
        bars_s,
        bar_rms_db,
    })
}

/// Errors unless every parameter of `song` is in its range.
fn check_song(song: &SynthSong) -> Result<(), MusicError> {
    let bad = |name, value, expected| MusicError::Parameter {
        name,
        value,
        expected,
    };
    if !(song.bpm.is_finite() && (20.0..=400.0).contains(&song.bpm)) {
        return Err(bad("bpm", song.bpm, "20 to 400"));
    }
    if song.bars == 0 || !(1..=16).contains(&song.beats_per_bar) {
        return Err(bad("bars", song.bars as f64, "≥ 1 bar of 1 to 16 beats"));
    }
    if !(0.25..=0.8).contains(&song.swing) {
        return Err(bad("swing", song.swing, "0.25 to 0.8 of a beat"));
    }
    if song.bar_levels_db.is_empty()
        || song
            .bar_levels_db
            .iter()
            .any(|l| !(-100.0..=0.0).contains(l))
    {
        return Err(bad(
            "bar_levels_db",
            f64::NAN,
            "at least one level, −100 to 0 dB",
        ));
    }
    if !(0.0..=0.05).contains(&song.jitter_s) {
        return Err(bad("jitter_s", song.jitter_s, "0 to 0.05 s"));
    }
    if !(song.lead_in_s >= 0.0 && song.tail_s >= 0.0) {
        return Err(bad(
            "lead_in_s/tail_s",
            song.lead_in_s.min(song.tail_s),
            "≥ 0 s",
        ));
    }
    if !(super::MIN_SAMPLE_RATE..=super::MAX_SAMPLE_RATE).contains(&song.sample_rate) {
        return Err(MusicError::SampleRate(song.sample_rate));
    }
    Ok(())
}

/// One drum hit: (bar, time in s, amplitude, drum).
type Hit = (usize, f64, f64, Drum);

/// The beat times, the bars' (start, end) times and every drum hit of `song`: a kick on every
/// beat (louder on the first, with the bass), a snare on the off beats, a hat on every beat and
/// its swung half, each jittered by `rng`.
fn drum_hits(song: &SynthSong, rng: &mut Pcg64) -> (Vec<f64>, Vec<(f64, f64)>, Vec<Hit>) {
    let beat = 60.0 / song.bpm;
    let bar = beat * song.beats_per_bar as f64;
    let mut beats_s = Vec::new();
    let mut bars_s = Vec::new();
    let mut hits: Vec<Hit> = Vec::new();
    for b in 0..song.bars {
        let t_bar = song.lead_in_s + b as f64 * bar;
        bars_s.push((t_bar, t_bar + bar));
        for i in 0..song.beats_per_bar {
            let t = t_bar + i as f64 * beat;
            beats_s.push(t);
            let mut j = || {
                let g: f64 = rng.random_range(-1.0..1.0);
                g * song.jitter_s * 3f64.sqrt()
            };
            let (jk, js, jh, jo) = (j(), j(), j(), j());
            hits.push((b, t + jk, if i == 0 { 1.0 } else { 0.6 }, Drum::Kick));
            if i == 0 {
                hits.push((b, t + jk, 0.5, Drum::Bass));
            }
            if i % 2 == 1 {
                hits.push((b, t + js, 0.7, Drum::Snare));
            }
            hits.push((b, t + jh, 0.35, Drum::Hat));
            hits.push((b, t + song.swing * beat + jo, 0.25, Drum::Hat));
        }
    }
    (beats_s, bars_s, hits)
}

/// Root mean square of `v` (0 when empty).
fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|s| s * s).sum::<f64>() / v.len().max(1) as f64).sqrt()
}

/// Each bar's gain: its own hits at unit gain, alone in `n` samples, scaled to its level over
/// its samples `regions[bar]`.
fn bar_gains(
    song: &SynthSong,
    hits: &[Hit],
    regions: &[std::ops::Range<usize>],
    n: usize,
    noise_seed: u64,
) -> Vec<f64> {
    let sr = song.sample_rate as f64;
    let mut gains = Vec::with_capacity(song.bars);
    let mut own = vec![0.0f64; n];
    for (b, r) in regions.iter().enumerate() {
        let mut hr = Pcg64::seed_from_u64(noise_seed);
        own.iter_mut().for_each(|v| *v = 0.0);
        for &(_, t, a, d) in hits.iter().filter(|h| h.0 == b) {
            hit(&mut own, sr, t, a, d, &mut hr);
        }
        let level = song.bar_levels_db[b % song.bar_levels_db.len()];
        gains.push(10f64.powf(level / 20.0) / rms(&own[r.clone()]).max(1e-12));
    }
    gains
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bars_have_their_levels_and_the_grid_its_tempo() {
        let song = SynthSong {
            bpm: 97.3,
            bars: 5,
            ..SynthSong::default()
        };
        let t = synthesize(&song).unwrap();
        assert_eq!(t.beats_s.len(), 20);
        assert!((t.beats_s[1] - t.beats_s[0] - 60.0 / 97.3).abs() < 1e-12);
        // The given level, plus 20 dB SNR noise (+0.04 dB) and the tails of the bar before.
        for (b, l) in t.bar_rms_db.iter().enumerate() {
            assert!((l - song.bar_levels_db[b % 4]).abs() < 0.6, "{b}: {l}");
        }
        let again = synthesize(&song).unwrap();
        assert_eq!(t, again);
    }

    #[test]
    fn bad_parameters_are_refused() {
        for s in [
            SynthSong {
                bpm: 0.0,
                ..SynthSong::default()
            },
            SynthSong {
                bars: 0,
                ..SynthSong::default()
            },
            SynthSong {
                bar_levels_db: vec![],
                ..SynthSong::default()
            },
        ] {
            assert!(synthesize(&s).is_err());
        }
    }
}
