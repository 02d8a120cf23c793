//! Tempo estimation: the autocorrelation of the onset envelope weighted by a log-normal tempo
//! prior, with a metrical-level check.
//!
//! With x the mean-removed envelope, the unbiased autocorrelation is
//! r(l) = (1/(N − l)) Σ_t x_t x_{t+l} / r(0), for lags l between 60/max_bpm and 60/min_bpm
//! seconds. The prior is w(l) = exp(−½ (log₂(bpm(l)/centre_bpm) / octaves)²) (as in the standard
//! trackers); the period is the local maximum of w·r, refined to a fraction of a frame by a
//! parabola through r. A periodic envelope correlates as well at twice its period as at its
//! period, so the prior alone may pick the slower level: when r at half the period is at least
//! `octave_ratio` of r at the period (a beat half as long is as well supported) and that tempo is
//! within range, the faster level is taken.

use serde::{Deserialize, Serialize};

use super::{MusicError, OnsetEnvelope};

/// The tempo prior and range of [`estimate_tempo`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TempoPrior {
    /// Centre of the log-normal prior (BPM).
    pub centre_bpm: f64,
    /// Its standard deviation (octaves).
    pub octaves: f64,
    /// Slowest tempo considered (BPM).
    pub min_bpm: f64,
    /// Fastest tempo considered (BPM).
    pub max_bpm: f64,
    /// Take the faster metrical level when r(period/2) ≥ this × r(period).
    pub octave_ratio: f64,
}

impl Default for TempoPrior {
    fn default() -> Self {
        TempoPrior {
            centre_bpm: 120.0,
            octaves: 1.0,
            min_bpm: 40.0,
            max_bpm: 240.0,
            octave_ratio: 0.8,
        }
    }
}

/// The tempo found by [`estimate_tempo`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TempoEstimate {
    /// Tempo (BPM).
    pub bpm: f64,
    /// Beat period in envelope frames (fractional).
    pub period_frames: f64,
    /// Normalised autocorrelation r at the period (1 for a perfectly periodic envelope).
    pub strength: f64,
}

/// Normalised unbiased autocorrelation r(l) of `x` (mean removed) for l in 0..=max_lag.
fn autocorrelation(x: &[f64], max_lag: usize) -> Vec<f64> {
    let n = x.len();
    let mean = x.iter().sum::<f64>() / n as f64;
    let y: Vec<f64> = x.iter().map(|v| v - mean).collect();
    let mut r: Vec<f64> = (0..=max_lag.min(n - 1))
        .map(|l| {
            let s: f64 = y[..n - l].iter().zip(&y[l..]).map(|(a, b)| a * b).sum();
            s / (n - l) as f64
        })
        .collect();
    let r0 = r[0];
    if r0 > 0.0 {
        r.iter_mut().for_each(|v| *v /= r0);
    }
    r
}

/// The vertex of the parabola through r(l−1), r(l), r(l+1): (lag, value).
fn parabolic(r: &[f64], l: usize) -> (f64, f64) {
    if l == 0 || l + 1 >= r.len() {
        return (l as f64, r[l]);
    }
    let (a, b, c) = (r[l - 1], r[l], r[l + 1]);
    let d = a - 2.0 * b + c;
    if d >= 0.0 {
        return (l as f64, b);
    }
    let off = (0.5 * (a - c) / d).clamp(-0.5, 0.5);
    (l as f64 + off, b - 0.25 * (a - c) * off)
}

/// Estimates the tempo of an onset envelope (see the module docs). Errors: a prior out of
/// range, an envelope too short for two beats at the slowest tempo considered, an envelope
/// without any positive autocorrelation peak in the range.
pub fn estimate_tempo(
    env: &OnsetEnvelope,
    prior: &TempoPrior,
) -> Result<TempoEstimate, MusicError> {
    let bad = |name, value, expected| MusicError::Parameter {
        name,
        value,
        expected,
    };
    if !(prior.min_bpm >= 10.0 && prior.min_bpm < prior.max_bpm && prior.max_bpm <= 600.0) {
        return Err(bad(
            "min_bpm/max_bpm",
            prior.min_bpm,
            "10 ≤ min_bpm < max_bpm ≤ 600",
        ));
    }
    if !(prior.centre_bpm > 0.0 && prior.centre_bpm.is_finite()) {
        return Err(bad("centre_bpm", prior.centre_bpm, "a positive tempo"));
    }
    if !(prior.octaves > 0.0 && prior.octaves.is_finite()) {
        return Err(bad("octaves", prior.octaves, "a positive width"));
    }
    if !(0.0..=1.0).contains(&prior.octave_ratio) {
        return Err(bad("octave_ratio", prior.octave_ratio, "0 to 1"));
    }
    let fps = env.frame_rate();
    let n = env.values.len();
    let lag_of = |bpm: f64| 60.0 * fps / bpm;
    let min_lag = (lag_of(prior.max_bpm).floor() as usize).max(2);
    let max_lag = (lag_of(prior.min_bpm).ceil() as usize).min(n / 2);
    if max_lag <= min_lag + 1 {
        return Err(MusicError::TooShort {
            duration_s: env.time_of(n as f64),
            needed_s: 2.0 * 60.0 / prior.min_bpm,
            what: "two beats at the slowest tempo considered",
        });
    }
    let r = autocorrelation(&env.values, max_lag + 1);
    let weight = |l: f64| {
        let z = (60.0 * fps / l / prior.centre_bpm).log2() / prior.octaves;
        (-0.5 * z * z).exp()
    };
    let mut best: Option<(usize, f64)> = None;
    for l in min_lag.max(1)..=max_lag.min(r.len() - 2) {
        if r[l] >= r[l - 1] && r[l] >= r[l + 1] && r[l] > 0.0 {
            let s = r[l] * weight(l as f64);
            if best.is_none_or(|(_, b)| s > b) {
                best = Some((l, s));
            }
        }
    }
    let Some((l, _)) = best else {
        return Err(MusicError::TooFewBeats {
            beats: 0,
            needed: 2,
        });
    };
    let (mut lag, mut strength) = parabolic(&r, l);
    // The metrical-level check: halve the period while the half is as well supported.
    loop {
        let h = lag / 2.0;
        if h < min_lag as f64 {
            break;
        }
        let c = h.round() as usize;
        let k = (c.saturating_sub(1)..=c + 1)
            .filter(|&k| k >= 1 && k + 1 < r.len())
            .max_by(|&a, &b| r[a].total_cmp(&r[b]));
        let Some(k) = k else { break };
        let (hl, hv) = parabolic(&r, k);
        if hv >= prior.octave_ratio * strength {
            lag = hl;
            strength = hv;
        } else {
            break;
        }
    }
    Ok(TempoEstimate {
        bpm: 60.0 * fps / lag,
        period_frames: lag,
        strength,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pulses(period: f64, n: usize) -> OnsetEnvelope {
        let mut values = vec![0.0; n];
        let mut t: f64 = 5.0;
        while (t as usize) < n {
            let i = t.floor() as usize;
            let f = t - i as f64;
            values[i] += 1.0 - f;
            if i + 1 < n {
                values[i + 1] += f;
            }
            t += period;
        }
        OnsetEnvelope::at_100_hz(values)
    }

    #[test]
    fn pulse_trains_give_their_tempo_at_every_level() {
        for bpm in [60.0, 97.3, 120.0, 150.0, 180.0] {
            let env = pulses(6000.0 / bpm, 3000);
            let t = estimate_tempo(&env, &TempoPrior::default()).unwrap();
            assert!((t.bpm / bpm - 1.0).abs() < 0.01, "{bpm}: {}", t.bpm);
        }
    }

    #[test]
    fn noise_without_pulse_is_weak() {
        let mut s = 7u64;
        let values: Vec<f64> = (0..3000)
            .map(|_| {
                s = s.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
                (s >> 11) as f64 / (1u64 << 53) as f64
            })
            .collect();
        let env = OnsetEnvelope::at_100_hz(values);
        if let Ok(t) = estimate_tempo(&env, &TempoPrior::default()) {
            assert!(t.strength < 0.2, "{}", t.strength);
        }
    }
}
