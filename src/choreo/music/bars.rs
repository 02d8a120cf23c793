//! Bars: groups of `beats_per_bar` beats starting on a downbeat.
//!
//! The downbeat phase φ (which of the first `beats_per_bar` beats starts a bar) is chosen from
//! the signal: bars start where the bass and kick drum come in, so φ maximises the mean
//! low-band onset strength at the beats i ≡ φ (mod beats_per_bar), each band's strength
//! normalised by its mean over all beats, plus half the same for the full-band envelope. Or
//! it is given. Bar k spans beats φ + k·B to φ + (k+1)·B; the last bar, whose closing downbeat
//! was not tracked, ends one bar's fitted length after its start if the song lasts that long.

use serde::{Deserialize, Serialize};

use super::OnsetEnvelope;
use super::beats::fitted_period;

/// One bar: its span and its intensity (the RMS of the song's samples in it).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Bar {
    /// Start (s): its downbeat.
    pub start_s: f64,
    /// End (s): the next downbeat.
    pub end_s: f64,
    /// RMS of the samples in [start_s, end_s) (full scale = 1).
    pub rms: f64,
    /// The RMS in dB: 20 log₁₀ rms (0 dB = an RMS of 1, a full-scale square wave).
    pub rms_db: f64,
}

/// Strength of `x` at beat frame `f`: its maximum within ±2 frames.
fn at(x: &[f64], f: f64) -> f64 {
    let c = f.round() as usize;
    let lo = c.saturating_sub(2);
    let hi = (c + 3).min(x.len());
    x[lo.min(hi)..hi].iter().fold(0.0, |m, &v| m.max(v))
}

/// The downbeat phase (0 .. beats_per_bar) of `beat_frames` on `env` (see the module docs).
pub fn downbeat_phase(env: &OnsetEnvelope, beat_frames: &[f64], beats_per_bar: usize) -> usize {
    let score = |x: &[f64]| -> Vec<f64> {
        let s: Vec<f64> = beat_frames.iter().map(|&f| at(x, f)).collect();
        let mean = s.iter().sum::<f64>() / s.len().max(1) as f64;
        (0..beats_per_bar)
            .map(|phi| {
                let v: Vec<f64> = s.iter().skip(phi).step_by(beats_per_bar).copied().collect();
                let m = v.iter().sum::<f64>() / v.len().max(1) as f64;
                if mean > 0.0 { m / mean } else { 0.0 }
            })
            .collect()
    };
    let low = score(&env.low);
    let full = score(&env.values);
    (0..beats_per_bar)
        .max_by(|&a, &b| (low[a] + 0.5 * full[a]).total_cmp(&(low[b] + 0.5 * full[b])))
        .unwrap_or(0)
}

/// Bar spans (start, end) in seconds from beat times, the index of the first downbeat, beats
/// per bar and the song's duration (see the module docs).
pub fn bars_from_beats(
    beats_s: &[f64],
    downbeat: usize,
    beats_per_bar: usize,
    duration_s: f64,
) -> Vec<(f64, f64)> {
    let period = fitted_period(beats_s);
    let mut out = Vec::new();
    let mut i = downbeat;
    while i + beats_per_bar - 1 < beats_s.len() {
        let start = beats_s[i];
        let end = match beats_s.get(i + beats_per_bar) {
            Some(&e) => e,
            None => start + beats_per_bar as f64 * period,
        };
        if end > duration_s + 1e-9 || !end.is_finite() {
            break;
        }
        out.push((start, end));
        i += beats_per_bar;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bars_group_beats_from_the_downbeat_and_the_last_is_extrapolated() {
        let beats: Vec<f64> = (0..11).map(|i| 0.5 * i as f64).collect();
        let bars = bars_from_beats(&beats, 1, 4, 10.0);
        assert_eq!(bars, vec![(0.5, 2.5), (2.5, 4.5)]);
        // Nine beats after the phase: the third bar's end 5.0 + 2.0 is past a 6.8 s song.
        assert_eq!(bars_from_beats(&beats, 1, 4, 6.8).len(), 2);
        let bars = bars_from_beats(&beats[..10], 2, 4, 10.0);
        assert_eq!(bars, vec![(1.0, 3.0), (3.0, 5.0)]);
    }

    #[test]
    fn the_accented_beat_is_the_downbeat() {
        let n = 1000;
        let frames: Vec<f64> = (0..19).map(|i| 20.0 + 50.0 * i as f64).collect();
        let mut low = vec![0.0; n];
        let mut values = vec![0.0; n];
        for (i, &f) in frames.iter().enumerate() {
            values[f as usize] = 1.0;
            low[f as usize] = if i % 4 == 3 { 2.0 } else { 0.5 };
        }
        let env = OnsetEnvelope {
            sample_rate: 100,
            hop: 1,
            window: 4,
            values,
            low,
        };
        assert_eq!(downbeat_phase(&env, &frames, 4), 3);
    }
}
