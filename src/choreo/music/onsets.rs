//! The onset-strength envelope: spectral flux on a log-magnitude spectrogram.
//!
//! The song is cut into Hann-windowed frames of `window_s` (rounded up to a power of two
//! samples), centred every `hop_s`; each frame's power spectrum (`realfft`) is summed into bands
//! a sixth of an octave wide from 30 Hz up to 11 kHz (or the Nyquist frequency), and taken in dB
//! log-compressed relative to the loudest band of the song, L = ln(1 + γ P / P_max), so that the
//! envelope does not depend on the song's gain and soft sounds (γ P / P_max ≪ 1) count less than
//! in a pure log (a hi-hat weighs less than a kick drum). The flux of frame t is the mean over bands of the half-wave
//! rectified rise, o(t) = (1/K) Σ_k max(0, L_t(k) − L_{t−1}(k)) (L_{−1} = 0: silence before the
//! song); a moving mean over
//! `detrend_s` is subtracted (and the result rectified again) so that a noise floor or a
//! sustained sound does not count as onsets. A second envelope, over the bands below
//! `low_hz`, carries the bass and kick drum for the downbeat phase.

use std::sync::Arc;

use rayon::prelude::*;
use realfft::{RealFftPlanner, RealToComplex};
use serde::{Deserialize, Serialize};

use super::MusicError;

/// Parameters of [`onset_envelope`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OnsetParams {
    /// Analysis window (s), rounded up to a power of two samples.
    pub window_s: f64,
    /// Hop between frames (s), rounded to whole samples.
    pub hop_s: f64,
    /// γ of the log compression L = ln(1 + γ P / P_max), as 10 log₁₀ γ (dB): band powers this
    /// far below the song's loudest band count about half as much as in a pure log.
    pub compression_db: f64,
    /// Width of the moving mean subtracted from the flux (s).
    pub detrend_s: f64,
    /// Upper edge of the low-band envelope (Hz).
    pub low_hz: f64,
}

impl Default for OnsetParams {
    fn default() -> Self {
        OnsetParams {
            window_s: 0.046,
            hop_s: 0.01,
            compression_db: 30.0,
            detrend_s: 1.0,
            low_hz: 200.0,
        }
    }
}

/// An onset-strength envelope: one value per analysis frame, frame t centred on sample t·hop.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OnsetEnvelope {
    /// Sample rate of the song (Hz).
    pub sample_rate: u32,
    /// Samples between frames.
    pub hop: usize,
    /// Window length (samples).
    pub window: usize,
    /// Onset strength per frame over all bands (mean dB rise per band, detrended, ≥ 0).
    pub values: Vec<f64>,
    /// Onset strength per frame over the bands below `low_hz` (same units).
    pub low: Vec<f64>,
}

impl OnsetEnvelope {
    /// Frames per second.
    pub fn frame_rate(&self) -> f64 {
        self.sample_rate as f64 / self.hop as f64
    }

    /// An envelope of `values` at 100 frames per second (both bands the same), for tests.
    #[cfg(test)]
    pub(crate) fn at_100_hz(values: Vec<f64>) -> OnsetEnvelope {
        OnsetEnvelope {
            sample_rate: 100,
            hop: 1,
            window: 4,
            low: values.clone(),
            values,
        }
    }

    /// Time (s) of frame `frame` (fractional frames allowed): its window's centre.
    pub fn time_of(&self, frame: f64) -> f64 {
        frame * self.hop as f64 / self.sample_rate as f64
    }
}

/// Band edges as FFT bin indices: sixth-octave bands from 30 Hz to min(11 kHz, Nyquist), each
/// at least one bin wide.
fn band_edges(n_fft: usize, sample_rate: u32) -> Vec<usize> {
    let bin_hz = sample_rate as f64 / n_fft as f64;
    let top = (11_000.0f64).min(sample_rate as f64 / 2.0);
    let n_bins = n_fft / 2 + 1;
    let mut edges = vec![((30.0 / bin_hz).round() as usize).max(1)];
    let mut f = 30.0f64;
    while f < top {
        f = (f * 2f64.powf(1.0 / 6.0)).min(top);
        let b = ((f / bin_hz).round() as usize).min(n_bins);
        let last = *edges.last().unwrap_or(&1);
        if b > last {
            edges.push(b);
        }
    }
    edges
}

/// Moving mean of `x` over a centred window of `w` values (shorter at the ends).
pub(crate) fn moving_mean(x: &[f64], w: usize) -> Vec<f64> {
    let half = w / 2;
    let mut prefix = Vec::with_capacity(x.len() + 1);
    prefix.push(0.0);
    for v in x {
        prefix.push(prefix.last().unwrap_or(&0.0) + v);
    }
    (0..x.len())
        .map(|i| {
            let lo = i.saturating_sub(half);
            let hi = (i + half + 1).min(x.len());
            (prefix[hi] - prefix[lo]) / (hi - lo) as f64
        })
        .collect()
}

/// Subtracts the moving mean over `w` frames and rectifies.
fn detrend(x: &[f64], w: usize) -> Vec<f64> {
    let m = moving_mean(x, w);
    x.iter().zip(m).map(|(v, m)| (v - m).max(0.0)).collect()
}

/// The onset-strength envelope of mono `samples` at `sample_rate` Hz (see the module docs).
/// Errors: parameters out of range.
pub fn onset_envelope(
    samples: &[f32],
    sample_rate: u32,
    params: &OnsetParams,
) -> Result<OnsetEnvelope, MusicError> {
    params.check()?;
    let sr = sample_rate as f64;
    let n_fft = ((params.window_s * sr).ceil() as usize)
        .next_power_of_two()
        .max(16);
    let hop = ((params.hop_s * sr).round() as usize).max(1);
    let frames = samples.len().div_ceil(hop).max(1);
    let edges = band_edges(n_fft, sample_rate);
    let bands = edges.len() - 1;
    let bin_hz = sr / n_fft as f64;
    let low_bands = edges[1..]
        .iter()
        .take_while(|&&e| e as f64 * bin_hz <= params.low_hz)
        .count()
        .max(1);
    let power = band_power(samples, n_fft, hop, &edges);
    let max = power.iter().fold(0f32, |m, &p| m.max(p)) as f64;
    let gamma = 10f64.powf(params.compression_db / 10.0) / max.max(f64::MIN_POSITIVE);
    // Element by element on the rayon pool: the same values whatever the threads.
    let level: Vec<f64> = power
        .par_iter()
        .map(|&p| (gamma * p as f64).ln_1p())
        .collect();
    // Before the song is silence (L = 0), so a song that starts on a hit has an onset at 0.
    let flux = |t: usize, range: std::ops::Range<usize>| -> f64 {
        let n = range.len() as f64;
        range
            .map(|b| {
                let prev = if t == 0 {
                    0.0
                } else {
                    level[(t - 1) * bands + b]
                };
                (level[t * bands + b] - prev).max(0.0)
            })
            .sum::<f64>()
            / n
    };
    let full: Vec<f64> = (0..frames)
        .into_par_iter()
        .map(|t| flux(t, 0..bands))
        .collect();
    let low: Vec<f64> = (0..frames)
        .into_par_iter()
        .map(|t| flux(t, 0..low_bands))
        .collect();
    let w = ((params.detrend_s * sr / hop as f64).round() as usize).max(1);
    Ok(OnsetEnvelope {
        sample_rate,
        hop,
        window: n_fft,
        values: detrend(&full, w),
        low: detrend(&low, w),
    })
}

/// The power of each band between `edges` (FFT bins) in each Hann-windowed frame of `n_fft`
/// samples centred every `hop` samples, frame-major.
fn band_power(samples: &[f32], n_fft: usize, hop: usize, edges: &[usize]) -> Vec<f32> {
    let frames = samples.len().div_ceil(hop).max(1);
    let bands = edges.len() - 1;
    let window = hann(n_fft);
    let mut planner = RealFftPlanner::<f32>::new();
    let fft: Arc<dyn RealToComplex<f32>> = planner.plan_fft_forward(n_fft);
    // Band power per frame, frame-major. Frames are independent: chunks of them run on the
    // rayon pool, each with its own buffers, so the result does not depend on the threads.
    let mut power = vec![0f32; frames * bands];
    let half = n_fft / 2;
    const CHUNK: usize = 256;
    power
        .par_chunks_mut(CHUNK * bands)
        .enumerate()
        .for_each(|(c, rows)| {
            let mut input = fft.make_input_vec();
            let mut spectrum = fft.make_output_vec();
            let mut scratch = fft.make_scratch_vec();
            for (j, row) in rows.chunks_mut(bands).enumerate() {
                let centre = (c * CHUNK + j) * hop;
                windowed(samples, centre as i64 - half as i64, &window, &mut input);
                // The lengths come from the same plan, so processing cannot fail.
                let _ = fft.process_with_scratch(&mut input, &mut spectrum, &mut scratch);
                for (b, p) in row.iter_mut().enumerate() {
                    *p = spectrum[edges[b]..edges[b + 1]]
                        .iter()
                        .map(|c| c.norm_sqr())
                        .sum();
                }
            }
        });
    power
}

/// `out[i] = samples[start + i] · window[i]`, a sample outside the song being 0: the frame of
/// `window.len()` samples from `start` (which may lie before the song's start), windowed.
pub(crate) fn windowed(samples: &[f32], start: i64, window: &[f32], out: &mut [f32]) {
    let inside = usize::try_from(start)
        .ok()
        .and_then(|a| samples.get(a..a + window.len()));
    match inside {
        // A frame inside the song: one straight pass the compiler vectorises.
        Some(frame) => {
            for ((x, s), w) in out.iter_mut().zip(frame).zip(window) {
                *x = s * w;
            }
        }
        // A frame over either end.
        None => {
            for (i, (x, w)) in out.iter_mut().zip(window).enumerate() {
                let s = usize::try_from(start + i as i64)
                    .ok()
                    .and_then(|k| samples.get(k));
                *x = s.map_or(0.0, |s| s * w);
            }
        }
    }
}

/// A Hann window of `n` samples, sin²(π i / n).
pub(crate) fn hann(n: usize) -> Vec<f32> {
    (0..n)
        .map(|i| {
            let x = std::f64::consts::PI * i as f64 / n as f64;
            (x.sin() * x.sin()) as f32
        })
        .collect()
}

impl OnsetParams {
    /// Checks each parameter against its range.
    fn check(&self) -> Result<(), MusicError> {
        let params = self;
        let check = |name, value: f64, lo: f64, hi: f64, expected| {
            if value.is_finite() && value >= lo && value <= hi {
                Ok(())
            } else {
                Err(MusicError::Parameter {
                    name,
                    value,
                    expected,
                })
            }
        };
        check("window_s", params.window_s, 0.005, 0.5, "0.005 to 0.5 s")?;
        check("hop_s", params.hop_s, 0.001, 0.1, "0.001 to 0.1 s")?;
        check(
            "compression_db",
            params.compression_db,
            0.0,
            120.0,
            "0 to 120 dB",
        )?;
        check("detrend_s", params.detrend_s, 0.05, 10.0, "0.05 to 10 s")?;
        check("low_hz", params.low_hz, 40.0, 2000.0, "40 to 2000 Hz")?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_rise_and_cover_the_range() {
        let e = band_edges(2048, 44_100);
        assert!(e.windows(2).all(|w| w[1] > w[0]));
        assert!(e.len() > 30, "{}", e.len());
        assert_eq!(
            *e.last().unwrap(),
            (11_000.0f64 / (44_100.0 / 2048.0)).round() as usize
        );
    }

    #[test]
    fn a_click_gives_one_peak_at_its_time_and_gain_does_not_matter() {
        let sr = 22_050;
        let mut x = vec![0f32; sr as usize * 2];
        let mut seed = 1u32;
        for s in x.iter_mut() {
            // Quiet noise so the spectrum has a floor.
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            *s = ((seed >> 8) as f32 / (1u32 << 24) as f32 - 0.5) * 1e-3;
        }
        let at = sr as usize; // 1 s
        for k in 0..2000 {
            x[at + k] += (0.99f32).powi(k as i32) * (k as f32 * 0.3).sin();
        }
        let p = OnsetParams::default();
        let e = onset_envelope(&x, sr, &p).unwrap();
        let (i, _) = e
            .values
            .iter()
            .enumerate()
            .fold((0, 0.0), |b, (i, &v)| if v > b.1 { (i, v) } else { b });
        let t = e.time_of(i as f64);
        assert!((t - 1.0).abs() < 0.03, "peak at {t} s");
        let louder: Vec<f32> = x.iter().map(|s| s * 10.0).collect();
        let e2 = onset_envelope(&louder, sr, &p).unwrap();
        for (a, b) in e.values.iter().zip(&e2.values) {
            assert!((a - b).abs() < 1e-3 * (1.0 + a.abs()), "{a} vs {b}");
        }
    }
}
