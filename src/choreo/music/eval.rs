//! The standard beat-tracking evaluation (MIREX, as `mir_eval.beat` computes it): beat
//! F-measure, the continuity scores CMLc/CMLt/AMLc/AMLt, tempo accuracy Acc1/Acc2 and the
//! downbeat F-measure, scoring estimated beat times against annotated ones (seconds).
//!
//! - F-measure: an estimate within ±`tolerance_s` (70 ms) of a reference beat matches it, each
//!   reference at most once; F = 2PR/(P + R).
//! - Continuity (Hainsworth; Klapuri et al. 2006): estimate m is correct when its distance to the
//!   nearest unused reference beat is below 17.5 % of the reference interval (phase) and its own
//!   interval is within 17.5 % of that reference interval (period). CMLt is the fraction of
//!   correct beats, CMLc the longest run of them, both over max(#reference, #estimated); AMLc
//!   and AMLt are the best of the same over the reference and four variations of it (off-beat,
//!   double, and half on the odd or even beats).
//! - Acc1: the estimated tempo within 4 % of the reference tempo (60 over the median reference
//!   interval); Acc2 the same allowing a factor of 2, ½, 3 or ⅓.
//!
//! [`trim`] drops the beats of the first 5 s, as the MIREX evaluation does before the beat and
//! downbeat scores. [`read_annotations`] reads annotated beats from a text file.

use std::path::Path;

use super::MusicError;

/// Annotated beats of a song.
#[derive(Debug, Clone, PartialEq)]
pub struct Annotations {
    /// Beat times (s), increasing.
    pub beats_s: Vec<f64>,
    /// The beats that are downbeats (s), increasing.
    pub downbeats_s: Vec<f64>,
}

/// Reads annotated beats: one beat a line, its time in seconds in the first column, further
/// numeric columns after whitespace or commas; blank lines and lines starting with `#` are
/// skipped. A beat is a downbeat when column `downbeat.0` (0-based) holds `downbeat.1`: the
/// `.beats` convention (beat position in the bar) is `(1, 1.0)`, POP909's `beat_midi.txt`
/// `(2, 1.0)`. Errors: the file unreadable, a line without a finite time, times not increasing,
/// a line without the downbeat column.
pub fn read_annotations(path: &Path, downbeat: (usize, f64)) -> Result<Annotations, MusicError> {
    let text = std::fs::read_to_string(path).map_err(|reason| MusicError::Io {
        path: path.to_path_buf(),
        reason,
    })?;
    let bad = |line: usize, message: String| MusicError::Annotation {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut out = Annotations {
        beats_s: vec![],
        downbeats_s: vec![],
    };
    for (k, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let cols: Vec<&str> = line
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|c| !c.is_empty())
            .collect();
        let num = |i: usize| -> Result<f64, MusicError> {
            let c = cols.get(i).ok_or_else(|| {
                bad(
                    k + 1,
                    format!("expected at least {} columns, found {}", i + 1, cols.len()),
                )
            })?;
            c.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    bad(
                        k + 1,
                        format!("column {}: {c:?} is not a finite number", i + 1),
                    )
                })
        };
        let t = num(0)?;
        if t < 0.0 {
            return Err(bad(k + 1, format!("beat time {t} s is negative")));
        }
        if let Some(&prev) = out.beats_s.last()
            && t <= prev
        {
            return Err(bad(
                k + 1,
                format!("beat time {t} s does not follow the previous beat at {prev} s"),
            ));
        }
        out.beats_s.push(t);
        if num(downbeat.0)? == downbeat.1 {
            out.downbeats_s.push(t);
        }
    }
    if out.beats_s.len() < 2 {
        return Err(bad(
            text.lines().count(),
            format!("expected at least 2 beats, found {}", out.beats_s.len()),
        ));
    }
    Ok(out)
}

/// The MIREX beat tolerance (s).
pub const F_TOLERANCE_S: f64 = 0.07;
/// The continuity tolerance on phase and period, a fraction of the reference interval.
pub const CONTINUITY_TOLERANCE: f64 = 0.175;
/// The tempo tolerance of Acc1 and Acc2 (relative).
pub const TEMPO_TOLERANCE: f64 = 0.04;
/// Beats before this time (s) are left out of the scores ([`trim`]).
pub const TRIM_S: f64 = 5.0;

/// The beats of `beats_s` at or after [`TRIM_S`].
pub fn trim(beats_s: &[f64]) -> Vec<f64> {
    beats_s.iter().copied().filter(|&t| t >= TRIM_S).collect()
}

/// The F-measure of `estimated` beat times against `reference` ones (s) at ±`tolerance_s`: each
/// reference beat matches the nearest unmatched estimate within the tolerance.
pub fn f_measure(estimated: &[f64], reference: &[f64], tolerance_s: f64) -> f64 {
    if estimated.is_empty() || reference.is_empty() {
        return 0.0;
    }
    let mut used = vec![false; estimated.len()];
    let mut hits = 0usize;
    for r in reference {
        let m = estimated
            .iter()
            .enumerate()
            .filter(|&(i, e)| !used[i] && (e - r).abs() <= tolerance_s)
            .min_by(|a, b| (a.1 - r).abs().total_cmp(&(b.1 - r).abs()));
        if let Some((i, _)) = m {
            used[i] = true;
            hits += 1;
        }
    }
    let p = hits as f64 / estimated.len() as f64;
    let r = hits as f64 / reference.len() as f64;
    if p + r == 0.0 {
        0.0
    } else {
        2.0 * p * r / (p + r)
    }
}

/// The continuity scores of `estimated` against `reference` beat times (s).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Continuity {
    /// Correct metrical level, longest continuous run.
    pub cml_c: f64,
    /// Correct metrical level, all correct beats.
    pub cml_t: f64,
    /// Any metrical level, longest continuous run.
    pub aml_c: f64,
    /// Any metrical level, all correct beats.
    pub aml_t: f64,
}

/// (longest run, total) of correct estimates against one reference variation.
fn continuity_against(estimated: &[f64], reference: &[f64]) -> (f64, f64) {
    let n = reference.len().max(estimated.len());
    let mut used = vec![false; reference.len()];
    let mut success = vec![false; estimated.len()];
    for (m, &e) in estimated.iter().enumerate() {
        let (nearest, diff) = reference
            .iter()
            .enumerate()
            .map(|(i, r)| (i, (e - r).abs()))
            .fold((0, f64::INFINITY), |b, c| if c.1 < b.1 { c } else { b });
        if used[nearest] {
            continue;
        }
        let (ref_iv, est_iv) = if m == 0 || nearest == 0 {
            let ref_iv = if nearest + 1 < reference.len() {
                reference[nearest + 1] - reference[nearest]
            } else {
                reference[nearest] - reference[nearest - 1]
            };
            let est_iv = if m + 1 < estimated.len() {
                estimated[m + 1] - e
            } else {
                e - estimated[m - 1]
            };
            (ref_iv, est_iv)
        } else {
            (
                reference[nearest] - reference[nearest - 1],
                e - estimated[m - 1],
            )
        };
        let phase = if ref_iv == 0.0 {
            if diff == 0.0 { 1.0 } else { f64::INFINITY }
        } else {
            (diff / ref_iv).abs()
        };
        let period = if ref_iv == 0.0 {
            if est_iv == 0.0 { 0.0 } else { f64::INFINITY }
        } else {
            (1.0 - est_iv / ref_iv).abs()
        };
        if phase < CONTINUITY_TOLERANCE && period < CONTINUITY_TOLERANCE {
            used[nearest] = true;
            success[m] = true;
        }
    }
    let (mut longest, mut run) = (0usize, 0usize);
    for &s in &success {
        run = if s { run + 1 } else { 0 };
        longest = longest.max(run);
    }
    let total = success.iter().filter(|&&s| s).count();
    (longest as f64 / n as f64, total as f64 / n as f64)
}

/// The continuity scores (module docs). Zero when either list has fewer than two beats.
pub fn continuity(estimated: &[f64], reference: &[f64]) -> Continuity {
    if estimated.len() < 2 || reference.len() < 2 {
        return Continuity {
            cml_c: 0.0,
            cml_t: 0.0,
            aml_c: 0.0,
            aml_t: 0.0,
        };
    }
    // The reference at twice the rate: the beats and the midpoints between them.
    let double: Vec<f64> = reference
        .windows(2)
        .flat_map(|w| [w[0], 0.5 * (w[0] + w[1])])
        .chain(reference.last().copied())
        .collect();
    let offbeat: Vec<f64> = double.iter().skip(1).step_by(2).copied().collect();
    let odd: Vec<f64> = reference.iter().step_by(2).copied().collect();
    let even: Vec<f64> = reference.iter().skip(1).step_by(2).copied().collect();
    let (cml_c, cml_t) = continuity_against(estimated, reference);
    let (mut aml_c, mut aml_t) = (cml_c, cml_t);
    for v in [&offbeat, &double, &odd, &even] {
        if v.len() < 2 {
            continue;
        }
        let (c, t) = continuity_against(estimated, v);
        aml_c = aml_c.max(c);
        aml_t = aml_t.max(t);
    }
    Continuity {
        cml_c,
        cml_t,
        aml_c,
        aml_t,
    }
}

/// The median of `xs` (NaN when empty).
pub fn median(xs: &[f64]) -> f64 {
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    let k = v.len();
    match k {
        0 => f64::NAN,
        _ if k % 2 == 1 => v[k / 2],
        _ => 0.5 * (v[k / 2 - 1] + v[k / 2]),
    }
}

/// The tempo (BPM) of annotated beats: 60 over their median interval (NaN for fewer than two).
pub fn reference_tempo(reference: &[f64]) -> f64 {
    let iv: Vec<f64> = reference.windows(2).map(|w| w[1] - w[0]).collect();
    60.0 / median(&iv)
}

/// Acc1: `estimated_bpm` within [`TEMPO_TOLERANCE`] of `reference_bpm`.
pub fn acc1(estimated_bpm: f64, reference_bpm: f64) -> bool {
    (estimated_bpm / reference_bpm - 1.0).abs() <= TEMPO_TOLERANCE
}

/// Acc2: [`acc1`] allowing the estimate to be off by a factor of 2, ½, 3 or ⅓.
pub fn acc2(estimated_bpm: f64, reference_bpm: f64) -> bool {
    [1.0, 2.0, 0.5, 3.0, 1.0 / 3.0]
        .iter()
        .any(|k| acc1(estimated_bpm * k, reference_bpm))
}

/// The scores of one song's analysis against its annotations.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct BeatScores {
    /// Beat F-measure at ±70 ms.
    pub f_measure: f64,
    /// The continuity scores.
    pub continuity: Continuity,
    /// The reference tempo (BPM).
    pub reference_bpm: f64,
    /// The estimated tempo (BPM).
    pub estimated_bpm: f64,
    /// Acc1.
    pub acc1: bool,
    /// Acc2.
    pub acc2: bool,
    /// Downbeat F-measure at ±70 ms (NaN when either side has no downbeats).
    pub downbeat_f: f64,
}

/// Scores estimated beats and downbeats (s) and tempo (BPM) against reference ones, the beats
/// and downbeats of the first [`TRIM_S`] left out.
pub fn score(
    beats_s: &[f64],
    downbeats_s: &[f64],
    tempo_bpm: f64,
    reference_beats_s: &[f64],
    reference_downbeats_s: &[f64],
) -> BeatScores {
    let (est, reference) = (trim(beats_s), trim(reference_beats_s));
    let reference_bpm = reference_tempo(reference_beats_s);
    let (ed, rd) = (trim(downbeats_s), trim(reference_downbeats_s));
    BeatScores {
        f_measure: f_measure(&est, &reference, F_TOLERANCE_S),
        continuity: continuity(&est, &reference),
        reference_bpm,
        estimated_bpm: tempo_bpm,
        acc1: acc1(tempo_bpm, reference_bpm),
        acc2: acc2(tempo_bpm, reference_bpm),
        downbeat_f: if rd.is_empty() {
            f64::NAN
        } else {
            f_measure(&ed, &rd, F_TOLERANCE_S)
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f_measure_by_hand() {
        // Two of three estimates hit two of four references: P = 2/3, R = 1/2.
        let f = f_measure(&[0.0, 1.02, 5.0], &[0.0, 1.0, 2.0, 3.0], 0.07);
        assert!((f - 2.0 * (2.0 / 3.0) * 0.5 / (2.0 / 3.0 + 0.5)).abs() < 1e-12);
    }

    #[test]
    fn continuity_levels() {
        let reference: Vec<f64> = (0..40).map(|i| 0.5 * i as f64).collect();
        let c = continuity(&reference, &reference);
        assert_eq!((c.cml_c, c.cml_t, c.aml_c, c.aml_t), (1.0, 1.0, 1.0, 1.0));
        // Double tempo: wrong metrical level, right at another.
        let double: Vec<f64> = (0..79).map(|i| 0.25 * i as f64).collect();
        let c = continuity(&double, &reference);
        assert_eq!(c.cml_t, 0.0);
        assert!((c.aml_t - 1.0).abs() < 1e-12, "{c:?}");
        // Off-beat: AML only.
        let off: Vec<f64> = reference.iter().map(|t| t + 0.25).collect();
        let c = continuity(&off, &reference);
        assert_eq!(c.cml_t, 0.0);
        assert!(c.aml_t > 0.95, "{c:?}");
        // A gap in the middle: CMLc is the longer run, CMLt counts both.
        let gap: Vec<f64> = reference
            .iter()
            .enumerate()
            .map(|(i, t)| if i == 10 { t + 0.2 } else { *t })
            .collect();
        let c = continuity(&gap, &reference);
        assert!((c.cml_t - 38.0 / 40.0).abs() < 1e-12, "{c:?}");
        assert!((c.cml_c - 28.0 / 40.0).abs() < 1e-12, "{c:?}");
    }

    #[test]
    fn annotations_read_and_refuse_clearly() {
        let dir = std::env::temp_dir().join(format!("marionette-eval-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("song.beats.txt");
        std::fs::write(
            &path,
            "# pop909\n0.5 1.0 1.0\n1.0 0 0\n\n1.5,1,0\n2.0 0 1\n",
        )
        .unwrap();
        let a = read_annotations(&path, (2, 1.0)).unwrap();
        assert_eq!(a.beats_s, vec![0.5, 1.0, 1.5, 2.0]);
        assert_eq!(a.downbeats_s, vec![0.5, 2.0]);
        std::fs::write(&path, "0.5 1\n0.4 2\n").unwrap();
        let e = read_annotations(&path, (1, 1.0)).unwrap_err().to_string();
        assert!(
            e.contains("song.beats.txt") && e.contains("line 2") && e.contains("0.4"),
            "{e}"
        );
        std::fs::write(&path, "0.5 1\nabc 2\n").unwrap();
        let e = read_annotations(&path, (1, 1.0)).unwrap_err().to_string();
        assert!(e.contains("line 2") && e.contains("\"abc\""), "{e}");
        std::fs::write(&path, "0.5\n1.0\n").unwrap();
        let e = read_annotations(&path, (1, 1.0)).unwrap_err().to_string();
        assert!(
            e.contains("line 1") && e.contains("at least 2 columns"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn tempo_accuracy() {
        assert!(acc1(81.0, 80.0) && !acc1(84.0, 80.0));
        assert!(!acc1(160.0, 80.0) && acc2(160.0, 80.0) && acc2(27.0, 80.0));
        assert!((reference_tempo(&[0.0, 0.5, 1.0, 1.6]) - 120.0).abs() < 1e-12);
    }
}
