//! Bars: groups of beats starting on a downbeat, `beats_per_bar` of them unless the music
//! inserts a shorter bar.
//!
//! Each beat i gets a downbeat evidence e_i: the rank among the beats of its onset strength in
//! the low band (bass and kick drum come in on the downbeat), plus half that of its full-band
//! onset strength, plus that of the harmonic change at the beat (chords change most often on
//! the bar's first beat; [`super::chroma::harmonic_change`] over two beats each side), plus
//! that of the bass line's harmonic change at the beat (the bass takes a new note most often
//! on the bar's first beat, also where the chords above it change on every second beat; the
//! same change over two beats each side, of the bass register's chroma,
//! [`super::chroma::half_beat_chroma_and_bass`], a beat's being its first half's):
//!
//! e_i = r(low_i) + ½ r(full_i) + r(h_i) + r(b_i), each rank r in (0, 1),
//!
//! and z_i is e_i standardised over the song. A song without tonality has neither harmonic
//! term. The downbeats are the bar positions (0 .. B − 1, B = beats per bar) that maximise
//! Σ_{i: position 0} z_i by dynamic programming (Viterbi) over the beats: the position advances
//! by one each beat and wraps from B − 1 to 0, and a bar may end early (a bar of fewer beats,
//! as when a song inserts a 2/4 bar) at a cost of `rephase_sd` (in units of z: the downbeat
//! evidence of the bars after it must make up for it). The first beat may sit anywhere in its
//! bar (a pickup). With a given downbeat, or an infinite cost, every bar has B beats.
//!
//! A bar spans from its downbeat to the next; the last bar, whose closing downbeat was not
//! tracked, ends one bar's fitted length after its start if the song lasts that long.

use serde::{Deserialize, Serialize};

use super::OnsetEnvelope;
use super::beats::{at, fitted_period};

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

/// The standardised downbeat evidence z_i of each beat (module docs) from the onsets at each
/// beat and the harmonic changes at each beat (`harmony`: the chords' and the bass line's, each
/// one per beat and of weight 1; one of any other length, as the empty one of a song without
/// tonality, is left out): each feature enters as its rank among the beats (0 to 1), so that
/// one outlier, as the first onset of a song, does not outweigh the rest.
pub fn downbeat_evidence(env: &OnsetEnvelope, beat_frames: &[f64], harmony: &[&[f64]]) -> Vec<f64> {
    let n = beat_frames.len();
    let mut e = vec![0.0; n];
    let low: Vec<f64> = beat_frames.iter().map(|&f| at(&env.low, f)).collect();
    let full: Vec<f64> = beat_frames.iter().map(|&f| at(&env.values, f)).collect();
    let mut features = vec![(low, 1.0), (full, 0.5)];
    for h in harmony.iter().filter(|h| h.len() == n) {
        features.push((h.to_vec(), 1.0));
    }
    for (s, weight) in features {
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| s[a].total_cmp(&s[b]).then(a.cmp(&b)));
        for (rank, &i) in order.iter().enumerate() {
            e[i] += weight * (rank as f64 + 0.5) / n as f64;
        }
    }
    let mean = e.iter().sum::<f64>() / n.max(1) as f64;
    let sd = (e.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n.max(1) as f64).sqrt();
    e.iter()
        .map(|v| if sd > 0.0 { (v - mean) / sd } else { 0.0 })
        .collect()
}

/// The indices of the beats that start bars, from the evidence `z` of each beat (see
/// [`downbeat_evidence`]), `beats_per_bar` and the cost of a short bar (module docs).
pub fn track_downbeats(z: &[f64], beats_per_bar: usize, rephase_sd: f64) -> Vec<usize> {
    let (n, b) = (z.len(), beats_per_bar.max(1));
    if n == 0 {
        return vec![];
    }
    let gain = |i: usize, k: usize| if k == 0 { z[i] } else { 0.0 };
    let mut score: Vec<f64> = (0..b).map(|k| gain(0, k)).collect();
    // back[i * b + k]: the position of beat i − 1 on the best path to position k at beat i.
    let mut back = vec![0usize; n * b];
    for i in 1..n {
        let mut next = vec![f64::NEG_INFINITY; b];
        for k in 0..b {
            let (from, s) = if k == 0 {
                // From the bar's last position, or a short bar ending early.
                (0..b)
                    .map(|j| {
                        let cost = if j == b - 1 { 0.0 } else { rephase_sd };
                        (j, score[j] - cost)
                    })
                    .fold(
                        (b - 1, f64::NEG_INFINITY),
                        |m, c| if c.1 > m.1 { c } else { m },
                    )
            } else {
                (k - 1, score[k - 1])
            };
            next[k] = s + gain(i, k);
            back[i * b + k] = from;
        }
        score = next;
    }
    let mut k = (0..b)
        .max_by(|&x, &y| score[x].total_cmp(&score[y]))
        .unwrap_or(0);
    let mut positions = vec![0; n];
    for i in (0..n).rev() {
        positions[i] = k;
        k = back[i * b + k];
    }
    (0..n).filter(|&i| positions[i] == 0).collect()
}

/// Every `beats_per_bar`-th beat of `n` from index `first`.
pub fn regular_downbeats(first: usize, beats_per_bar: usize, n: usize) -> Vec<usize> {
    (first..n).step_by(beats_per_bar.max(1)).collect()
}

/// Bar spans (start, end) in seconds from beat times, the indices of the beats that start bars
/// (increasing), beats per bar and the song's duration (see the module docs).
pub fn bars_from_downbeats(
    beats_s: &[f64],
    downbeats: &[usize],
    beats_per_bar: usize,
    duration_s: f64,
) -> Vec<(f64, f64)> {
    let period = fitted_period(beats_s);
    let mut out = Vec::new();
    for (j, &i) in downbeats.iter().enumerate() {
        let Some(&start) = beats_s.get(i) else { break };
        let end = match downbeats.get(j + 1) {
            Some(&next) => beats_s[next],
            None => match beats_s.get(i + beats_per_bar) {
                Some(&e) => e,
                None => start + beats_per_bar as f64 * period,
            },
        };
        if end > duration_s + 1e-9 || !end.is_finite() {
            break;
        }
        out.push((start, end));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bars_group_beats_from_the_downbeat_and_the_last_is_extrapolated() {
        let beats: Vec<f64> = (0..11).map(|i| 0.5 * i as f64).collect();
        let downbeats = regular_downbeats(1, 4, beats.len());
        assert_eq!(downbeats, vec![1, 5, 9]);
        // The last bar, from beat 9 without its closing downbeat, is one fitted bar long.
        let bars = bars_from_downbeats(&beats, &downbeats, 4, 10.0);
        assert_eq!(bars, vec![(0.5, 2.5), (2.5, 4.5), (4.5, 6.5)]);
        // Its end 6.5 is past a 6.4 s song: it is left out.
        assert_eq!(bars_from_downbeats(&beats, &downbeats, 4, 6.4).len(), 2);
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
        let z = downbeat_evidence(&env, &frames, &[]);
        assert_eq!(track_downbeats(&z, 4, f64::INFINITY)[0], 3);
    }

    #[test]
    fn the_bass_line_s_change_marks_the_bar_where_the_chords_change_every_two_beats() {
        use crate::choreo::music::chroma::{
            ChromaParams, beat_chroma, half_beat_chroma_and_bass, harmonic_change,
        };
        use crate::choreo::music::{OnsetParams, onset_envelope};
        // Beats every 0.5 s from 0.25 s; one beat of pickup, then bars from beat 1. Every beat
        // strikes the same chord and bass note loudness; the chord changes on beats 1 and 3 of
        // each bar (C major, then F major), the bass note only on beat 1 (C2, A1, F1, G1, …).
        let (sr, beat_s, n) = (22_050u32, 0.5, 33usize);
        let chords = [[261.63, 329.63, 392.0], [349.23, 440.0, 523.25]];
        let roots = [65.41, 55.0, 43.65, 49.0];
        let mut x = vec![0f32; (sr as f64 * (0.25 + beat_s * n as f64 + 0.5)) as usize];
        for b in 0..n {
            let (bar, pos) = (b.div_ceil(4), (b + 3) % 4);
            let chord = chords[pos / 2];
            let root = roots[bar % 4];
            let start = (sr as f64 * (0.25 + beat_s * b as f64)) as usize;
            for k in 0..(sr as f64 * beat_s) as usize {
                let t = k as f64 / sr as f64;
                let decay = (-3.0 * t).exp();
                let upper: f64 = chord
                    .iter()
                    .map(|f| (std::f64::consts::TAU * f * t).sin())
                    .sum();
                let bass = 2.0 * (std::f64::consts::TAU * root * t).sin();
                x[start + k] += (0.1 * decay * (upper + bass)) as f32;
            }
        }
        let beats: Vec<f64> = (0..n).map(|b| 0.25 + beat_s * b as f64).collect();
        let (halves, bass_halves) =
            half_beat_chroma_and_bass(&x, sr, &beats, &ChromaParams::default());
        let bass_chroma = beat_chroma(&bass_halves);
        // Each beat's bass chroma peaks on its root's class, under the chords above 260 Hz.
        for (b, c) in bass_chroma.iter().enumerate() {
            let class = c
                .iter()
                .enumerate()
                .fold((0, 0.0), |m, (i, &v)| if v > m.1 { (i, v) } else { m })
                .0;
            let expected = [0, 9, 5, 7][b.div_ceil(4) % 4];
            assert_eq!(class, expected, "beat {b}: {c:?}");
        }
        // The bass line changes on each bar's first beat, hardly on its third.
        let bass = harmonic_change(&bass_chroma, 2);
        let mean = |pos: usize| {
            let v: Vec<f64> = (4..n - 2)
                .filter(|b| (b + 3) % 4 == pos)
                .map(|b| bass[b])
                .collect();
            v.iter().sum::<f64>() / v.len() as f64
        };
        assert!(mean(0) > 3.0 * mean(2), "{} vs {}", mean(0), mean(2));
        // With the onsets and the chords' change, the downbeats are the bar's first beats.
        let chords_change = harmonic_change(&beat_chroma(&halves), 2);
        let env = onset_envelope(&x, sr, &OnsetParams::default()).unwrap();
        let frames: Vec<f64> = beats.iter().map(|t| t * env.frame_rate()).collect();
        let z = downbeat_evidence(&env, &frames, &[&chords_change, &bass]);
        let downbeats = track_downbeats(&z, 4, f64::INFINITY);
        assert_eq!(downbeats[..3], [1, 5, 9], "{z:?}");
    }

    #[test]
    fn an_inserted_short_bar_is_followed_and_costs_what_it_says() {
        // Downbeats every 4 beats from beat 1, then a 2-beat bar at beat 21: from 23 on.
        let mut truth: Vec<usize> = (1..=21).step_by(4).collect();
        truth.extend((23..60).step_by(4));
        let z: Vec<f64> = (0..60)
            .map(|i| if truth.contains(&i) { 1.0 } else { -0.3 })
            .collect();
        assert_eq!(track_downbeats(&z, 4, 4.0), truth);
        // At an infinite cost every bar keeps its 4 beats: the longer stretch wins.
        let regular = track_downbeats(&z, 4, f64::INFINITY);
        assert!(regular.windows(2).all(|w| w[1] - w[0] == 4), "{regular:?}");
        assert_eq!(regular[0] % 4, 3, "{regular:?}");
        // A short bar after a single bar of evidence does not pay its cost.
        let mut z = vec![-0.3; 40];
        for i in (0..40).step_by(4) {
            z[i] = 1.0;
        }
        z[20] = -0.3;
        z[22] = 1.0;
        let d = track_downbeats(&z, 4, 4.0);
        assert!(d.windows(2).all(|w| w[1] - w[0] == 4), "{d:?}");
        let bars = bars_from_downbeats(&[0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0], &[0, 4, 6], 4, 10.0);
        assert_eq!(bars, vec![(0.0, 2.0), (2.0, 3.0), (3.0, 5.0)]);
    }
}
