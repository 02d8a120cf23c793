//! Harmony between beats: a chroma vector per interval and the harmonic change at each boundary.
//!
//! The chroma of an interval [tᵢ, tᵢ₊₁) is the power spectrum of one Hann window of `window_s`
//! (rounded up to a power of two samples) centred in the interval, folded onto the 12 pitch
//! classes (each FFT bin from `low_hz` to `high_hz` goes to the pitch class nearest its
//! frequency, p = round(69 + 12 log₂(f / 440 Hz)) mod 12), log-compressed as
//! c(p) = ln(1 + γ P(p) / P_max) with P_max the loudest class of the song (the same compression
//! as the onset envelope's, so the gain of the song does not matter) and scaled to unit length.
//!
//! The harmonic change at boundary i over `w` intervals is the cosine distance between the summed
//! chroma of the w intervals before it and of the w intervals after it,
//! h_i = 1 − ⟨a, b⟩ / (|a| |b|): 0 where the harmony goes on, towards 1 where the chord changes.
//! In songs with chords, chords change on beats, and most often on the bar's first beat (Goto
//! 2001, "An audio-based real-time beat tracking system for music with or without drum-sounds").
//!
//! The bass line is followed apart: from the same spectrum, the bins from `bass_low_hz` to
//! `bass_high_hz` (30 to 260 Hz, below middle C, where the bass instruments and the pianist's
//! left hand play) are folded, compressed (with P_max the loudest class of this register) and
//! scaled the same way into a second chroma, the bass's ([`register_chroma`]), whose harmonic
//! change is measured likewise. The bass takes a new note most often on the bar's first beat,
//! and it says so apart from the upper voices, whose chroma a melody and passing notes blur.
//! The default window (0.37 s at 22.05 or 44.1 kHz) has bins 2.7 Hz apart, finer than a
//! semitone from about G1 (49 Hz) up; below that the bass's harmonics carry its pitch class.
//!
//! Harmony means something only where there is pitch: the tonality of a song is the mean over
//! its intervals of the cosine distance of their chroma from the flat profile (1/√12 each),
//! near 0 for noise and drums (0.01 to 0.05 for five synthesized drum tracks of 68 to 150 BPM)
//! and 0.26 to 0.45 for the first 12 of the 40 shared POP909 piano arrangements. Below
//! `min_tonality` the harmony is not used.

use std::sync::Arc;

use rayon::prelude::*;
use realfft::{RealFftPlanner, RealToComplex};
use serde::{Deserialize, Serialize};

/// Parameters of [`interval_chroma`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ChromaParams {
    /// Analysis window (s), rounded up to a power of two samples: long enough to resolve a
    /// semitone at `low_hz`.
    pub window_s: f64,
    /// Lowest frequency folded onto the pitch classes (Hz).
    pub low_hz: f64,
    /// Highest frequency folded onto the pitch classes (Hz).
    pub high_hz: f64,
    /// Lowest frequency of the bass register (Hz; module docs).
    pub bass_low_hz: f64,
    /// Highest frequency of the bass register (Hz).
    pub bass_high_hz: f64,
    /// γ of the log compression, as 10 log₁₀ γ (dB).
    pub compression_db: f64,
    /// Least tonality (module docs) at which the harmony is used.
    pub min_tonality: f64,
}

impl Default for ChromaParams {
    fn default() -> Self {
        ChromaParams {
            window_s: 0.186,
            low_hz: 100.0,
            high_hz: 2000.0,
            bass_low_hz: 30.0,
            bass_high_hz: 260.0,
            compression_db: 30.0,
            min_tonality: 0.1,
        }
    }
}

/// A 12-bin pitch-class profile (C, C♯, …, B), unit length or zero.
pub type Chroma = [f64; 12];

/// The chroma of each interval between successive `times_s` (one fewer than the times; see the
/// module docs), of mono `samples` at `sample_rate` Hz, over `low_hz` to `high_hz`.
pub fn interval_chroma(
    samples: &[f32],
    sample_rate: u32,
    times_s: &[f64],
    params: &ChromaParams,
) -> Vec<Chroma> {
    let register = [(params.low_hz, params.high_hz)];
    register_chroma(samples, sample_rate, times_s, params, &register)
        .pop()
        .unwrap_or_default()
}

/// The chroma of each interval between successive `times_s` in each register (lowest, highest
/// frequency in Hz) of `registers`, all from one spectrum per interval (module docs): one list
/// of chroma per register. Intervals run in parallel, each with its own buffers, so the result
/// does not depend on the threads.
pub fn register_chroma(
    samples: &[f32],
    sample_rate: u32,
    times_s: &[f64],
    params: &ChromaParams,
    registers: &[(f64, f64)],
) -> Vec<Vec<Chroma>> {
    let sr = sample_rate as f64;
    let n_fft = ((params.window_s * sr).ceil() as usize)
        .next_power_of_two()
        .max(16);
    let window = super::onsets::hann(n_fft);
    let bin_hz = sr / n_fft as f64;
    // (bin, register, pitch class) of every bin folded.
    let bins: Vec<(usize, usize, usize)> = (1..n_fft / 2)
        .flat_map(|k| {
            let f = k as f64 * bin_hz;
            let class = ((69.0 + 12.0 * (f / 440.0).log2()).round() as i64).rem_euclid(12);
            registers
                .iter()
                .enumerate()
                .filter(move |(_, (lo, hi))| (*lo..=*hi).contains(&f))
                .map(move |(r, _)| (k, r, class as usize))
        })
        .collect();
    let fft: Arc<dyn RealToComplex<f32>> = RealFftPlanner::<f32>::new().plan_fft_forward(n_fft);
    let half = (n_fft / 2) as f64;
    let power: Vec<Vec<[f64; 12]>> = times_s
        .par_windows(2)
        .map_init(
            || {
                (
                    fft.make_input_vec(),
                    fft.make_output_vec(),
                    fft.make_scratch_vec(),
                )
            },
            |(input, spectrum, scratch), w| {
                let start = (0.5 * (w[0] + w[1]) * sr - half).round() as i64;
                super::onsets::windowed(samples, start, &window, input);
                // The lengths come from the same plan, so processing cannot fail.
                let _ = fft.process_with_scratch(input, spectrum, scratch);
                let mut p = vec![[0.0; 12]; registers.len()];
                for &(k, r, class) in &bins {
                    p[r][class] += spectrum[k].norm_sqr() as f64;
                }
                p
            },
        )
        .collect();
    (0..registers.len())
        .map(|r| compress(power.iter().map(|p| p[r]), params.compression_db))
        .collect()
}

/// Chroma from pitch-class powers: c(p) = ln(1 + γ P(p) / P_max) with P_max the largest power
/// of all, each scaled to unit length (module docs).
fn compress(power: impl Iterator<Item = [f64; 12]> + Clone, compression_db: f64) -> Vec<Chroma> {
    let max = power.clone().flatten().fold(0f64, |m, p| m.max(p));
    let gamma = 10f64.powf(compression_db / 10.0) / max.max(f64::MIN_POSITIVE);
    power
        .map(|p| {
            let mut c = p.map(|v| (gamma * v).ln_1p());
            let norm = c.iter().map(|v| v * v).sum::<f64>().sqrt();
            if norm > 0.0 {
                c.iter_mut().for_each(|v| *v /= norm);
            }
            c
        })
        .collect()
}

/// The tonality of a song from the chroma of its intervals (module docs): 0 for a flat
/// profile, towards 1 − 1/√12 for a single pitch class; 0 for no intervals.
pub fn tonality(chroma: &[Chroma]) -> f64 {
    let flat = [12f64.sqrt().recip(); 12];
    let sum: f64 = chroma.iter().map(|c| cosine_distance(c, &flat)).sum();
    if chroma.is_empty() {
        0.0
    } else {
        sum / chroma.len() as f64
    }
}

/// Cosine distance 1 − ⟨a, b⟩ / (|a| |b|); 0 when either is zero.
fn cosine_distance(a: &Chroma, b: &Chroma) -> f64 {
    let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    let na = a.iter().map(|v| v * v).sum::<f64>().sqrt();
    let nb = b.iter().map(|v| v * v).sum::<f64>().sqrt();
    if na * nb > 0.0 {
        1.0 - dot / (na * nb)
    } else {
        0.0
    }
}

/// The harmonic change h_i at the start of each interval i of `chroma` over `w` intervals on
/// each side (module docs; fewer at the ends).
pub fn harmonic_change(chroma: &[Chroma], w: usize) -> Vec<f64> {
    let sum = |range: std::ops::Range<usize>| {
        let mut s = [0.0; 12];
        for c in &chroma[range] {
            s.iter_mut().zip(c).for_each(|(s, v)| *s += v);
        }
        s
    };
    (0..chroma.len())
        .map(|i| {
            let before = sum(i.saturating_sub(w)..i);
            let after = sum(i..(i + w).min(chroma.len()));
            cosine_distance(&before, &after)
        })
        .collect()
}

/// The chroma of each half beat of `beats_s` (two intervals a beat, the last beat's one
/// fitted period long): 2n chroma for n beats, empty for fewer than two beats.
pub fn half_beat_chroma(
    samples: &[f32],
    sample_rate: u32,
    beats_s: &[f64],
    params: &ChromaParams,
) -> Vec<Chroma> {
    interval_chroma(samples, sample_rate, &half_beat_times(beats_s), params)
}

/// The chroma of each half beat of `beats_s` as [`half_beat_chroma`], and from the same
/// spectra the bass's (`bass_low_hz` to `bass_high_hz`, module docs): (chords, bass).
pub fn half_beat_chroma_and_bass(
    samples: &[f32],
    sample_rate: u32,
    beats_s: &[f64],
    params: &ChromaParams,
) -> (Vec<Chroma>, Vec<Chroma>) {
    let registers = [
        (params.low_hz, params.high_hz),
        (params.bass_low_hz, params.bass_high_hz),
    ];
    let mut c = register_chroma(
        samples,
        sample_rate,
        &half_beat_times(beats_s),
        params,
        &registers,
    );
    let bass = c.pop().unwrap_or_default();
    (c.pop().unwrap_or_default(), bass)
}

/// The bounds of every half beat of `beats_s`, the last beat one fitted period long; none for
/// fewer than two beats.
fn half_beat_times(beats_s: &[f64]) -> Vec<f64> {
    if beats_s.len() < 2 {
        return vec![];
    }
    let mut beats = beats_s.to_vec();
    beats.extend(
        beats_s
            .last()
            .map(|t| t + super::beats::fitted_period(beats_s)),
    );
    let mut halves: Vec<f64> = beats
        .windows(2)
        .flat_map(|w| [w[0], 0.5 * (w[0] + w[1])])
        .collect();
    halves.extend(beats.last());
    halves
}

/// The chroma of each beat from those of its halves ([`half_beat_chroma`]): that of its first
/// half, where a chord struck on the beat sounds before the passing notes of the beat's second
/// half.
pub fn beat_chroma(halves: &[Chroma]) -> Vec<Chroma> {
    halves.iter().step_by(2).copied().collect()
}

/// How much more the harmony changes halfway between beats than on them, from the chroma of
/// every half beat ([`half_beat_chroma`]): the mean harmonic change (over one half beat each
/// side) at the midpoints over that at the beats. Above 1 the chords change between the
/// tracked beats: they are off the beat, or every second beat of the song. 0 with fewer than
/// three beats or no change.
pub fn midpoint_harmony_ratio(halves: &[Chroma]) -> f64 {
    if halves.len() < 6 {
        return 0.0;
    }
    let h = harmonic_change(halves, 1);
    // Boundary 0 (the first beat) has nothing before it.
    let on: f64 = h.iter().skip(2).step_by(2).sum();
    let mid: f64 = h.iter().skip(1).step_by(2).sum();
    if on > 0.0 { mid / on } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chord of sines (Hz) for `s` seconds at 22.05 kHz.
    fn chord(freqs: &[f64], s: f64) -> Vec<f32> {
        let sr = 22_050.0;
        (0..(s * sr) as usize)
            .map(|i| {
                let t = i as f64 / sr;
                freqs
                    .iter()
                    .map(|f| (std::f64::consts::TAU * f * t).sin())
                    .sum::<f64>() as f32
                    * 0.2
            })
            .collect()
    }

    #[test]
    fn a_chord_s_pitch_classes_carry_its_chroma() {
        // C major (C4, E4, G4): classes 0, 4 and 7.
        let x = chord(&[261.63, 329.63, 392.0], 1.0);
        let c = interval_chroma(&x, 22_050, &[0.2, 0.8], &ChromaParams::default());
        assert_eq!(c.len(), 1);
        let mut order: Vec<usize> = (0..12).collect();
        order.sort_by(|&a, &b| c[0][b].total_cmp(&c[0][a]));
        let mut top = order[..3].to_vec();
        top.sort();
        assert_eq!(top, vec![0, 4, 7], "{:?}", c[0]);
        let norm: f64 = c[0].iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!((norm - 1.0).abs() < 1e-12);
    }

    #[test]
    fn noise_has_no_tonality_and_a_chord_has_much() {
        let mut seed = 1u32;
        let noise: Vec<f32> = (0..44_100)
            .map(|_| {
                seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (seed >> 8) as f32 / (1u32 << 24) as f32 - 0.5
            })
            .collect();
        let times: Vec<f64> = (0..8).map(|i| 0.25 * i as f64).collect();
        let p = ChromaParams::default();
        let t_noise = tonality(&interval_chroma(&noise, 22_050, &times, &p));
        let x = chord(&[261.63, 329.63, 392.0], 2.0);
        let t_chord = tonality(&interval_chroma(&x, 22_050, &times, &p));
        assert!(t_noise < 0.05, "noise {t_noise}");
        assert!(t_chord > 0.3, "chord {t_chord}");
        assert!(t_noise < p.min_tonality && t_chord > p.min_tonality);
    }

    #[test]
    fn the_change_is_where_the_chord_changes_and_the_ratio_finds_off_beats() {
        // C major for 2 s, then A minor (A3, C4, E4) for 2 s; beats every 0.5 s.
        let mut x = chord(&[261.63, 329.63, 392.0], 2.0);
        x.extend(chord(&[220.0, 261.63, 329.63], 2.0));
        let times: Vec<f64> = (0..9).map(|i| 0.5 * i as f64).collect();
        let p = ChromaParams::default();
        let h = harmonic_change(&interval_chroma(&x, 22_050, &times, &p), 1);
        let (best, _) = h
            .iter()
            .enumerate()
            .fold((0, 0.0), |b, (i, &v)| if v > b.1 { (i, v) } else { b });
        assert_eq!(best, 4, "{h:?}");
        // Chords changing every second, on beats every 0.5 s from 0: on the beats, ratio < 1;
        // the same beats shifted by a quarter second put every change halfway: ratio > 1.
        let mut x = Vec::new();
        for k in 0..6 {
            let f = if k % 2 == 0 {
                [261.63, 329.63, 392.0]
            } else {
                [220.0, 261.63, 329.63]
            };
            x.extend(chord(&f, 1.0));
        }
        let on: Vec<f64> = (0..11).map(|i| 0.5 * i as f64).collect();
        let off: Vec<f64> = on.iter().map(|t| t + 0.25).collect();
        let ratio =
            |beats: &[f64]| midpoint_harmony_ratio(&half_beat_chroma(&x, 22_050, beats, &p));
        assert!(ratio(&on) < 0.5, "{}", ratio(&on));
        assert!(ratio(&off) > 2.0, "{}", ratio(&off));
        // A beat's chroma is its first half's.
        let halves = half_beat_chroma(&x, 22_050, &on, &p);
        let beats = beat_chroma(&halves);
        assert_eq!((halves.len(), beats.len()), (2 * on.len(), on.len()));
        assert_eq!(beats[3], halves[6]);
    }
}
