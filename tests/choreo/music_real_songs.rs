//! The music analysis on real songs with annotated beats (the shared POP909 songs rendered with
//! FluidSynth, see `common/pop909.rs`), beside librosa in the same run, and the evaluation's own
//! scores against `mir_eval`, the reference implementation of the MIREX beat metrics.

use crate::common;
use crate::pop909;

use std::io::Write;

use marionette::choreo::music::eval::{F_TOLERANCE_S, continuity, f_measure};

/// The renderer, or `None` after a SKIPPED line; panics instead under CI.
fn renderer_or_skip() -> Option<()> {
    match pop909::renderer() {
        Ok(()) => Some(()),
        Err(why) if common::in_ci() => panic!("{why}: .ci/run installs it"),
        Err(why) => {
            let _ = writeln!(std::io::stderr(), "SKIPPED: POP909 songs: {why}");
            None
        }
    }
}

#[test]
#[cfg_attr(
    not(all(shared_data, tool_python, tool_fluidsynth)),
    ignore = "needs the shared data (MARIONETTE_DATA), the Python environment .venv and \
              fluidsynth with its soundfont (.ci/run makes and installs them)"
)]
fn held_out_songs_beats_tempo_and_bars_beside_librosa() {
    let Some(dir) = common::data_path("pop909") else {
        return;
    };
    let Some(()) = renderer_or_skip() else {
        return;
    };
    let Some(python) = common::python_with(&["librosa"]) else {
        return;
    };
    let songs = pop909::songs(&dir);
    assert_eq!(songs.len(), 40);
    let wavs = pop909::render_all(&songs);
    let ours: Vec<pop909::Tracked> = songs
        .iter()
        .zip(&wavs)
        .map(|(s, w)| pop909::ours(s, w))
        .collect();
    let held: Vec<usize> = (0..songs.len()).filter(|&i| songs[i].held_out).collect();
    let theirs = pop909::librosa(
        &python,
        &held.iter().map(|&i| &songs[i]).collect::<Vec<_>>(),
        &held.iter().map(|&i| wavs[i].as_path()).collect::<Vec<_>>(),
    );
    for (k, &i) in held.iter().enumerate() {
        let (o, t) = (&ours[i].scores, &theirs[k].scores);
        eprintln!(
            "{} reference {:6.1} BPM | ours {:6.1} F {:.3} downbeat F {:.3} | librosa {:6.1} F {:.3}",
            songs[i].id,
            o.reference_bpm,
            o.estimated_bpm,
            o.f_measure,
            o.downbeat_f,
            t.estimated_bpm,
            t.f_measure
        );
    }
    let dev: Vec<_> = (0..songs.len())
        .filter(|&i| !songs[i].held_out)
        .map(|i| ours[i].scores)
        .collect();
    let ours_held: Vec<_> = held.iter().map(|&i| ours[i].scores).collect();
    let theirs_held: Vec<_> = theirs.iter().map(|t| t.scores).collect();
    eprintln!("{}", pop909::line("marionette, 24 dev songs", &dev));
    eprintln!("{}", pop909::line("marionette, 16 held out", &ours_held));
    eprintln!("{}", pop909::line("librosa, 16 held out", &theirs_held));
    // Issue 35's aims on the held-out songs: F ≥ librosa's + 0.03 and Acc1 ≥ 80 %, met; downbeat
    // F ≥ 0.8, not met (0.782 when written, with the chord and bass-line changes: see
    // docs/choreography.md), held here at 0.76.
    let [f, _, aml_t, acc1, acc2, downbeat_f] = pop909::means(&ours_held);
    let [f_librosa, ..] = pop909::means(&theirs_held);
    assert!(
        f >= f_librosa + 0.03,
        "held-out beat F {f:.3} against librosa's {f_librosa:.3}"
    );
    assert!(acc1 >= 0.8, "held-out Acc1 {acc1:.3}");
    assert!(
        acc2 >= 0.9 && aml_t >= 0.85,
        "Acc2 {acc2:.3} AMLt {aml_t:.3}"
    );
    assert!(downbeat_f >= 0.76, "held-out downbeat F {downbeat_f:.3}");
    let [f_dev, _, _, acc1_dev, _, downbeat_dev] = pop909::means(&dev);
    assert!(
        f_dev >= 0.9 && acc1_dev >= 0.85 && downbeat_dev >= 0.69,
        "development songs: F {f_dev:.3} Acc1 {acc1_dev:.3} downbeat F {downbeat_dev:.3}"
    );
}

/// A deterministic generator for the cross-check's beat lists.
fn lcg(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    (*seed >> 11) as f64 / (1u64 << 53) as f64
}

#[test]
#[cfg_attr(
    not(tool_python),
    ignore = "needs the Python environment .venv (made by .ci/run) or MARIONETTE_PYTHON"
)]
fn the_scores_agree_with_mir_eval() {
    let Some(python) = common::python_with(&["mir_eval"]) else {
        return;
    };
    // References with a drifting tempo; estimates jittered, at double and half tempo, off the
    // beat, with gaps and extra beats.
    let mut seed = 7u64;
    let mut cases: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
    for c in 0..12 {
        let period = 0.4 + 0.05 * c as f64;
        let mut t = 5.2;
        let reference: Vec<f64> = (0..80)
            .map(|i| {
                t += period * (1.0 + 0.05 * (i as f64 * 0.1).sin());
                t
            })
            .collect();
        let jitter = 0.01 + 0.01 * (c % 4) as f64;
        let mut est: Vec<f64> = match c % 4 {
            0 => reference.clone(),
            1 => reference
                .windows(2)
                .flat_map(|w| [w[0], 0.5 * (w[0] + w[1])])
                .collect(),
            2 => reference.iter().step_by(2).copied().collect(),
            _ => reference.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect(),
        };
        for e in est.iter_mut() {
            *e += jitter * (2.0 * lcg(&mut seed) - 1.0);
        }
        if c % 3 == 0 {
            est.drain(20..26);
            est.push(est[est.len() - 1] + 0.13);
        }
        est.sort_by(f64::total_cmp);
        est.dedup();
        cases.push((reference, est));
    }
    let json = serde_json::to_string(&cases).unwrap();
    let script = "import json, sys, numpy as np, mir_eval\n\
        for ref, est in json.load(sys.stdin):\n\
        \x20   ref, est = np.array(ref), np.array(est)\n\
        \x20   f = mir_eval.beat.f_measure(ref, est)\n\
        \x20   c = mir_eval.beat.continuity(ref, est)\n\
        \x20   print(json.dumps([f, *c]))\n";
    let mut child = std::process::Command::new(&python)
        .args(["-c", script])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(json.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let theirs: Vec<[f64; 5]> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(theirs.len(), cases.len());
    for (k, ((reference, est), t)) in cases.iter().zip(&theirs).enumerate() {
        let c = continuity(est, reference);
        let ours = [
            f_measure(est, reference, F_TOLERANCE_S),
            c.cml_c,
            c.cml_t,
            c.aml_c,
            c.aml_t,
        ];
        for (name, (o, t)) in ["F", "CMLc", "CMLt", "AMLc", "AMLt"]
            .iter()
            .zip(ours.iter().zip(t))
        {
            assert!(
                (o - t).abs() < 1e-12,
                "case {k} {name}: ours {o} mir_eval {t}"
            );
        }
    }
}
