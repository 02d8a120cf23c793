//! Bar intensity: the RMS of the song's samples in each bar, and its level in dB.

use super::Bar;

/// 20 log₁₀ `rms` (dB re an RMS of 1); −200 dB for silence.
pub fn rms_db(rms: f64) -> f64 {
    20.0 * rms.max(1e-10).log10()
}

/// The RMS of `samples` (a mono buffer at `sample_rate` Hz) over each span (start, end) in
/// seconds, as bars: rms = √((1/n) Σ x²) over the samples with start ≤ i/rate < end.
pub fn bar_intensity(samples: &[f32], sample_rate: u32, spans: &[(f64, f64)]) -> Vec<Bar> {
    let sr = sample_rate as f64;
    spans
        .iter()
        .map(|&(start_s, end_s)| {
            let a = ((start_s * sr).ceil().max(0.0) as usize).min(samples.len());
            let b = ((end_s * sr).ceil().max(0.0) as usize).clamp(a, samples.len());
            let sum: f64 = samples[a..b].iter().map(|&x| (x as f64) * (x as f64)).sum();
            let rms = if b > a {
                (sum / (b - a) as f64).sqrt()
            } else {
                0.0
            };
            Bar {
                start_s,
                end_s,
                rms,
                rms_db: rms_db(rms),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sine_bar_has_rms_amplitude_over_root_two() {
        let sr = 8000;
        let x: Vec<f32> = (0..16_000)
            .map(|i| {
                let a = if i < 8000 { 0.5 } else { 0.05 };
                a * (2.0 * std::f32::consts::PI * 100.0 * i as f32 / sr as f32).sin()
            })
            .collect();
        let bars = bar_intensity(&x, sr, &[(0.0, 1.0), (1.0, 2.0)]);
        assert!((bars[0].rms - 0.5 / 2f64.sqrt()).abs() < 1e-4);
        assert!((bars[0].rms_db - bars[1].rms_db - 20.0).abs() < 1e-3);
        assert_eq!(rms_db(0.0), -200.0);
    }
}
