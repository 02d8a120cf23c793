//! Beat tracking by dynamic programming (Ellis 2007, "Beat tracking by dynamic programming"):
//! beats fall on strong onsets and are spaced close to the tempo's period.
//!
//! The local score is the onset envelope divided by its standard deviation and smoothed by a
//! Gaussian of σ = period/32 frames. The cumulative score is
//! C(t) = local(t) + max_{τ ∈ [t − 2p, t − p/2]} [C(τ) − α (ln((t − τ)/p))²],
//! with p the period (frames) and α the tightness; the best predecessor of each frame is kept.
//! The last beat is the best C in the final period; the beats are read back along the
//! predecessors. Beats at the start and end whose local score is below `trim` × the RMS local
//! score at the beats (lead-in, fade-out, silence) are dropped. Each beat frame is refined to a
//! fraction of a frame by a parabola through the local score.

use serde::{Deserialize, Serialize};

use super::{MusicError, OnsetEnvelope};

/// Parameters of [`track_beats`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BeatParams {
    /// α: how strongly the spacing of beats is held to the period.
    pub tightness: f64,
    /// Leading and trailing beats weaker than this × the RMS beat strength are dropped.
    pub trim: f64,
    /// The beats are tracked again twice as fast when the onsets halfway between them are on
    /// average at least this strong relative to the onsets on them ([`midpoint_ratio`]): such
    /// a level groups two beats, as kick on 1 and 3 with the snare's backbeat on 2 and 4 does.
    pub midpoint_ratio: f64,
    /// The beats are also tracked again twice as fast when the harmony changes more halfway
    /// between them than on them, by at least this factor
    /// ([`super::chroma::midpoint_harmony_ratio`]): chords change on beats, so such beats are
    /// every second beat of the song, or off the beat.
    pub midpoint_harmony: f64,
}

impl Default for BeatParams {
    fn default() -> Self {
        BeatParams {
            tightness: 100.0,
            trim: 0.5,
            midpoint_ratio: 0.8,
            midpoint_harmony: 1.0,
        }
    }
}

/// Beat positions (fractional envelope frames, increasing) in `env` for a beat period of
/// `period` frames (see the module docs). Errors: a period or parameter out of range.
pub fn track_beats(
    env: &OnsetEnvelope,
    period: f64,
    params: &BeatParams,
) -> Result<Vec<f64>, MusicError> {
    check_params(env.values.len(), period, params)?;
    let local = local_score(&env.values, period);
    let (cum, back) = cumulative_score(&local, period, params.tightness);
    let frames = read_back(&cum, &back, period);
    let frames = trim_weak_ends(&frames, &local, params.trim);
    Ok(frames.iter().map(|&f| refine(&local, f)).collect())
}

/// Checks the period (2 frames to the envelope's length `n`) and the parameters.
fn check_params(n: usize, period: f64, params: &BeatParams) -> Result<(), MusicError> {
    if !(period.is_finite() && period >= 2.0 && period < n as f64) {
        return Err(MusicError::Parameter {
            name: "period",
            value: period,
            expected: "2 frames to the envelope's length",
        });
    }
    if !(params.tightness.is_finite() && params.tightness >= 0.0) {
        return Err(MusicError::Parameter {
            name: "tightness",
            value: params.tightness,
            expected: "a non-negative number",
        });
    }
    for (name, value) in [
        ("midpoint_ratio", params.midpoint_ratio),
        ("midpoint_harmony", params.midpoint_harmony),
    ] {
        if value.is_nan() || value < 0.0 {
            return Err(MusicError::Parameter {
                name,
                value,
                expected: "a non-negative number (inf: never)",
            });
        }
    }
    if !(0.0..=1.0).contains(&params.trim) {
        return Err(MusicError::Parameter {
            name: "trim",
            value: params.trim,
            expected: "0 to 1",
        });
    }
    Ok(())
}

/// The cumulative score C(t) of every frame and its best predecessor (module docs), with
/// predecessors from half to twice the period before.
fn cumulative_score(local: &[f64], period: f64, tightness: f64) -> (Vec<f64>, Vec<Option<usize>>) {
    let n = local.len();
    let lo = (period / 2.0).round() as usize;
    let hi = (2.0 * period).round() as usize;
    // Penalty per distance d = t − τ in lo..=hi.
    let penalty: Vec<f64> = (0..=hi)
        .map(|d| {
            if d < lo.max(1) {
                f64::INFINITY
            } else {
                tightness * ((d as f64 / period).ln()).powi(2)
            }
        })
        .collect();
    let mut cum = vec![0.0; n];
    let mut back: Vec<Option<usize>> = vec![None; n];
    for t in 0..n {
        let mut best: Option<(usize, f64)> = None;
        for (d, pen) in penalty
            .iter()
            .enumerate()
            .take(hi.min(t) + 1)
            .skip(lo.max(1))
        {
            let tau = t - d;
            let s = cum[tau] - pen;
            if best.is_none_or(|(_, b)| s > b) {
                best = Some((tau, s));
            }
        }
        match best {
            Some((tau, s)) if s > 0.0 => {
                cum[t] = local[t] + s;
                back[t] = Some(tau);
            }
            _ => cum[t] = local[t],
        }
    }
    (cum, back)
}

/// The beat frames read back along the predecessors from the best score in the final period.
fn read_back(cum: &[f64], back: &[Option<usize>], period: f64) -> Vec<usize> {
    let n = cum.len();
    let tail_from = n.saturating_sub(period.ceil() as usize);
    let mut t = (tail_from..n)
        .max_by(|&a, &b| cum[a].total_cmp(&cum[b]))
        .unwrap_or(n - 1);
    let mut frames = vec![t];
    while let Some(p) = back[t] {
        frames.push(p);
        t = p;
    }
    frames.reverse();
    frames
}

/// The beats without the leading and trailing ones whose local score is below `trim` × the
/// RMS local score at the beats.
fn trim_weak_ends<'a>(frames: &'a [usize], local: &[f64], trim: f64) -> &'a [usize] {
    let rms =
        (frames.iter().map(|&f| local[f] * local[f]).sum::<f64>() / frames.len() as f64).sqrt();
    let thresh = trim * rms;
    let first = frames.iter().position(|&f| local[f] >= thresh);
    let last = frames.iter().rposition(|&f| local[f] >= thresh);
    match (first, last) {
        (Some(a), Some(b)) => &frames[a..=b],
        _ => &frames[..0],
    }
}

/// Frame `f` refined to a fraction of a frame by a parabola through the local score.
fn refine(local: &[f64], f: usize) -> f64 {
    if f == 0 || f + 1 >= local.len() {
        return f as f64;
    }
    let (a, b, c) = (local[f - 1], local[f], local[f + 1]);
    let d = a - 2.0 * b + c;
    if d < 0.0 {
        f as f64 + (0.5 * (a - c) / d).clamp(-0.5, 0.5)
    } else {
        f as f64
    }
}

/// The envelope over its standard deviation, smoothed by a Gaussian of σ = period/32 frames.
fn local_score(values: &[f64], period: f64) -> Vec<f64> {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    let sd = var.sqrt().max(f64::MIN_POSITIVE);
    let sigma = (period / 32.0).max(0.5);
    let half = (3.0 * sigma).ceil() as isize;
    let kernel: Vec<f64> = (-half..=half)
        .map(|k| (-0.5 * (k as f64 / sigma).powi(2)).exp())
        .collect();
    let ksum: f64 = kernel.iter().sum();
    (0..values.len() as isize)
        .map(|i| {
            let mut s = 0.0;
            for (j, w) in kernel.iter().enumerate() {
                let k = i + j as isize - half;
                if k >= 0 && (k as usize) < values.len() {
                    s += w * values[k as usize];
                }
            }
            s / ksum / sd
        })
        .collect()
}

/// The mean onset strength (full band plus low band, the largest within ±2 frames) halfway
/// between consecutive beats over the mean at the beats: near 0 when the beats carry the onsets
/// and the midpoints do not, near 1 or above when the midpoints are beats too. 0 for fewer than
/// two beats.
pub fn midpoint_ratio(env: &OnsetEnvelope, frames: &[f64]) -> f64 {
    let at = |f: f64| at(&env.values, f) + at(&env.low, f);
    if frames.len() < 2 {
        return 0.0;
    }
    let on: f64 = frames.iter().map(|&f| at(f)).sum::<f64>() / frames.len() as f64;
    let mid: f64 = frames
        .windows(2)
        .map(|w| at(0.5 * (w[0] + w[1])))
        .sum::<f64>()
        / (frames.len() - 1) as f64;
    if on > 0.0 { mid / on } else { 0.0 }
}

/// The least-squares beat period (s) of beat times `beats_s`: the slope of time against beat
/// index. Needs at least two beats (returns NaN otherwise).
pub fn fitted_period(beats_s: &[f64]) -> f64 {
    let n = beats_s.len() as f64;
    if beats_s.len() < 2 {
        return f64::NAN;
    }
    let mi = (n - 1.0) / 2.0;
    let mt = beats_s.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (i, t) in beats_s.iter().enumerate() {
        let di = i as f64 - mi;
        sxy += di * (t - mt);
        sxx += di * di;
    }
    sxy / sxx
}

/// Strength of `x` at beat frame `f`: its maximum within ±2 frames.
pub(super) fn at(x: &[f64], f: f64) -> f64 {
    let c = f.round() as usize;
    let lo = c.saturating_sub(2);
    let hi = (c + 3).min(x.len());
    x[lo.min(hi)..hi].iter().fold(0.0, |m, &v| m.max(v))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::choreo::music::eval::f_measure;

    #[test]
    fn beats_follow_a_pulse_train_and_skip_the_silent_lead_in() {
        let n = 2000;
        let period = 47.3;
        let mut values = vec![0.0; n];
        let mut truth = Vec::new();
        let mut t = 300.0;
        while t < (n - 5) as f64 {
            values[t.round() as usize] = 1.0;
            truth.push(t.round());
            t += period;
        }
        let env = OnsetEnvelope::at_100_hz(values);
        let beats = track_beats(&env, period, &BeatParams::default()).unwrap();
        assert_eq!(beats.len(), truth.len(), "{beats:?}");
        for (b, r) in beats.iter().zip(&truth) {
            assert!((b - r).abs() <= 1.0, "{b} vs {r}");
        }
        let f = f_measure(&beats, &truth, 1.0);
        assert!((f - 1.0).abs() < 1e-12);
    }

    #[test]
    fn fitted_period_by_hand() {
        assert!((fitted_period(&[1.0, 1.5, 2.0, 2.5]) - 0.5).abs() < 1e-12);
    }
}
