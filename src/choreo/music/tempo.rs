//! Tempo estimation: a metrical comb over the autocorrelation of the onset envelopes, weighted
//! by a log-normal tempo prior.
//!
//! With x the mean-removed envelope, the unbiased autocorrelation is
//! r(l) = (1/(N − l)) Σ_t x_t x_{t+l} / r(0). A beat period l is scored by the periodicity of the
//! whole metrical grid it implies: the mean of r at its multiples k l within a span of T seconds
//! (`comb_span_s`, 3 s, about the span over which a listener takes in a beat), taken on the
//! full-band and the low-band envelope:
//! S(l) = w(l) · (1/2K) Σ_{k=1..K} [r̂_full(k l) + r̂_low(k l)], K = max(1, ⌊T / l⌋),
//! where r̂(k l) is the largest r within ±⌈k/2⌉ frames of k l (the multiple's rounding). Every
//! candidate is scored over the same span, so that no level is credited with periodicity at
//! longer lags than another. The prior is w(l) = exp(−½ (log₂(bpm(l)/centre_bpm) / octaves)²).
//!
//! The comb is what settles the metrical level. A period twice too short (eighth notes taken
//! for beats) has its odd multiples between the true beats, where a song with any accent on its
//! beats correlates less; a period twice too long keeps only every other beat's support but
//! loses nothing, so the comb leans slow, and the prior balances it. The prior is centred on
//! 100 BPM, the spontaneous tapping tempo of about 600 ms (Fraisse 1982), and is wide (1.5
//! octaves), so that it tips only what the comb leaves even. Chosen on the 24 development songs
//! of the POP909 evaluation (`benches/music_real_songs.rs`): the tempo levels there are those of
//! the written quarter notes, which the ear often taps at twice the rate in a slow ballad. The period is the best S over the range, refined to a fraction of a frame by a
//! parabola through the full-band r.

use realfft::RealFftPlanner;
use realfft::num_complex::Complex;
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
    /// The span of lags the comb averages over (s).
    pub comb_span_s: f64,
}

impl Default for TempoPrior {
    fn default() -> Self {
        TempoPrior {
            centre_bpm: 100.0,
            octaves: 1.5,
            min_bpm: 40.0,
            max_bpm: 240.0,
            comb_span_s: 3.0,
        }
    }
}

impl TempoPrior {
    /// Checks the range (10 ≤ min < max ≤ 600 BPM), the centre within it, a positive width and
    /// a comb span of 0 to 30 s.
    fn check(&self) -> Result<(), MusicError> {
        let prior = self;
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
        if !(prior.min_bpm..=prior.max_bpm).contains(&prior.centre_bpm) {
            return Err(bad(
                "centre_bpm",
                prior.centre_bpm,
                "a tempo within min_bpm to max_bpm",
            ));
        }
        if !(prior.octaves > 0.0 && prior.octaves.is_finite()) {
            return Err(bad("octaves", prior.octaves, "a positive width"));
        }
        if !(prior.comb_span_s > 0.0 && prior.comb_span_s <= 30.0) {
            return Err(bad("comb_span_s", prior.comb_span_s, "0 to 30 s"));
        }
        Ok(())
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

/// Normalised unbiased autocorrelation r(l) of `x` (mean removed) for l in 0..=max_lag, by the
/// Wiener–Khinchin theorem: the inverse FFT of the power spectrum of `x` padded with zeros to at
/// least twice its length (so that the circular correlation is the linear one), each lag over
/// its n − l products.
fn autocorrelation(x: &[f64], max_lag: usize) -> Vec<f64> {
    let n = x.len();
    let mean = x.iter().sum::<f64>() / n as f64;
    let size = (2 * n).next_power_of_two();
    let mut planner = RealFftPlanner::<f64>::new();
    let forward = planner.plan_fft_forward(size);
    let inverse = planner.plan_fft_inverse(size);
    let mut y = forward.make_input_vec();
    for (o, v) in y.iter_mut().zip(x) {
        *o = v - mean;
    }
    let mut spectrum = forward.make_output_vec();
    // The lengths come from the same plans, so processing cannot fail.
    let _ = forward.process(&mut y, &mut spectrum);
    for c in spectrum.iter_mut() {
        *c = Complex::new(c.norm_sqr(), 0.0);
    }
    let mut products = inverse.make_output_vec();
    let _ = inverse.process(&mut spectrum, &mut products);
    let mut r: Vec<f64> = (0..=max_lag.min(n - 1))
        .map(|l| products[l] / size as f64 / (n - l) as f64)
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

/// The largest r within ±`tol` frames of lag `x` (0 when out of range).
fn near(r: &[f64], x: f64, tol: usize) -> f64 {
    let c = x.round() as usize;
    let hi = (c + tol + 1).min(r.len());
    let lo = c.saturating_sub(tol).max(1);
    if lo >= hi {
        return 0.0;
    }
    r[lo..hi].iter().fold(f64::NEG_INFINITY, |m, &v| m.max(v))
}

/// Estimates the tempo of an onset envelope (see the module docs). Errors: a prior or comb span
/// out of range, an envelope too short for two beats at the slowest tempo considered, an
/// envelope without any positive periodicity in the range.
pub fn estimate_tempo(
    env: &OnsetEnvelope,
    prior: &TempoPrior,
) -> Result<TempoEstimate, MusicError> {
    prior.check()?;
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
    // Multiples past half the envelope are left out of the comb (too few products to trust).
    let span = (prior.comb_span_s * fps).round() as usize;
    let reach = (span.max(max_lag) + span / min_lag + 2)
        .min(n / 2)
        .max(max_lag + 1);
    let full = autocorrelation(&env.values, reach);
    let low = autocorrelation(&env.low, reach);
    let weight = |l: f64| {
        let z = (60.0 * fps / l / prior.centre_bpm).log2() / prior.octaves;
        (-0.5 * z * z).exp()
    };
    let mut best: Option<(usize, f64)> = None;
    for l in min_lag..=max_lag.min(full.len() - 2) {
        let mut sum = 0.0;
        let mut count = 0usize;
        for k in 1..=(span / l).max(1) {
            let x = (k * l) as f64;
            if x + 1.0 >= full.len() as f64 {
                break;
            }
            let tol = k.div_ceil(2);
            sum += near(&full, x, tol) + near(&low, x, tol);
            count += 2;
        }
        let s = weight(l as f64) * sum / count.max(1) as f64;
        if full[l] > 0.0 && best.is_none_or(|(_, b)| s > b) {
            best = Some((l, s));
        }
    }
    let Some((l, _)) = best else {
        return Err(MusicError::TooFewBeats {
            beats: 0,
            needed: 2,
        });
    };
    // The comb's lag, moved to the full-band peak within a frame and refined by a parabola.
    let l = (l.saturating_sub(1).max(1)..=(l + 1).min(full.len() - 2))
        .max_by(|&a, &b| full[a].total_cmp(&full[b]))
        .unwrap_or(l);
    let (lag, strength) = parabolic(&full, l);
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
    fn pulse_trains_give_a_metrical_level_of_their_tempo() {
        for bpm in [60.0, 97.3, 120.0, 150.0, 180.0] {
            let env = pulses(6000.0 / bpm, 3000);
            let t = estimate_tempo(&env, &TempoPrior::default()).unwrap();
            // An even pulse has no accent to tell its level, and every multiple of its period
            // is as periodic: the comb may group 2 or 3 pulses (the prior's choice; `analyze`
            // then tracks beats twice as fast where the midpoints are as strong as the beats).
            let level = [1.0, 0.5, 1.0 / 3.0]
                .into_iter()
                .find(|k| (t.bpm / (k * bpm) - 1.0).abs() < 0.01);
            assert!(level.is_some(), "{bpm}: {}", t.bpm);
        }
    }

    #[test]
    fn a_prior_centred_outside_the_tempi_considered_is_refused() {
        let env = pulses(50.0, 3000);
        for centre_bpm in [1e9, 300.0, 20.0, f64::NAN] {
            let prior = TempoPrior {
                centre_bpm,
                ..TempoPrior::default()
            };
            let e = estimate_tempo(&env, &prior).unwrap_err().to_string();
            assert!(e.contains("centre_bpm"), "{centre_bpm}: {e}");
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

    #[test]
    fn the_fft_autocorrelation_is_the_sum_of_products() {
        let x: Vec<f64> = (0..501)
            .map(|i| ((i * i) % 17) as f64 + (i as f64 * 0.3).sin())
            .collect();
        let r = autocorrelation(&x, 120);
        let n = x.len();
        let mean = x.iter().sum::<f64>() / n as f64;
        let y: Vec<f64> = x.iter().map(|v| v - mean).collect();
        let direct = |l: usize| {
            y[..n - l]
                .iter()
                .zip(&y[l..])
                .map(|(a, b)| a * b)
                .sum::<f64>()
                / (n - l) as f64
        };
        for l in [0, 1, 7, 60, 120] {
            assert!((r[l] - direct(l) / direct(0)).abs() < 1e-12, "lag {l}");
        }
    }
}
