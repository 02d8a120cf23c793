//! Beats, tempo and bars of the 40 shared POP909 songs (rendered with FluidSynth) against their
//! annotations, marionette beside librosa's `beat_track` in the same run: every song, then the
//! means over the 24 development songs and the 16 held out, then the speed ratio (median wall
//! time per song of decoding and analysis, each tracker on the same WAV files).
//!
//! `cargo bench --bench music_real_songs` (needs `$MARIONETTE_DATA/pop909`, `fluidsynth` with
//! the Fluid R3 GM soundfont, and `.venv` with librosa, all made by `.ci/run`).

#[path = "../tests/common/pop909.rs"]
mod pop909;

use std::path::PathBuf;

use marionette::choreo::music::eval::median;

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let dir = marionette::io::data_dir().join("pop909");
    if !dir.exists() {
        eprintln!(
            "skipping: {} not found (set MARIONETTE_DATA)",
            dir.display()
        );
        return;
    }
    if let Err(why) = pop909::renderer() {
        eprintln!("skipping: {why}");
        return;
    }
    let python = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(".venv/bin/python");
    let songs = pop909::songs(&dir);
    let wavs = pop909::render_all(&songs);
    let ours: Vec<_> = songs
        .iter()
        .zip(&wavs)
        .map(|(s, w)| pop909::ours(s, w))
        .collect();
    let theirs = pop909::librosa(
        &python,
        &songs.iter().collect::<Vec<_>>(),
        &wavs.iter().map(PathBuf::as_path).collect::<Vec<_>>(),
    );
    println!(
        "song  split  reference | marionette BPM  F      AMLt   downbeat F | librosa BPM  F      AMLt"
    );
    for ((s, o), t) in songs.iter().zip(&ours).zip(&theirs) {
        let (o, t) = (&o.scores, &t.scores);
        println!(
            "{}   {}  {:6.1}    | {:6.1}{} {:.3}  {:.3}  {:.3}      | {:6.1}{}  {:.3}  {:.3}",
            s.id,
            if s.held_out { "held" } else { "dev " },
            o.reference_bpm,
            o.estimated_bpm,
            if o.acc1 { ' ' } else { '*' },
            o.f_measure,
            o.continuity.aml_t,
            o.downbeat_f,
            t.estimated_bpm,
            if t.acc1 { ' ' } else { '*' },
            t.f_measure,
            t.continuity.aml_t,
        );
    }
    println!(
        "(* : tempo off by more than 4 %; librosa has no downbeats, its row reads every 4th beat)"
    );
    for (name, held) in [("24 development songs", false), ("16 held-out songs", true)] {
        let pick = |rows: &[pop909::Tracked]| -> Vec<_> {
            rows.iter()
                .zip(&songs)
                .filter(|(_, s)| s.held_out == held)
                .map(|(r, _)| r.scores)
                .collect()
        };
        println!("{name}:");
        println!("  {}", pop909::line("marionette", &pick(&ours)));
        println!("  {}", pop909::line("librosa", &pick(&theirs)));
    }
    let ours_s = median(&ours.iter().map(|t| t.seconds).collect::<Vec<_>>());
    let theirs_s = median(&theirs.iter().map(|t| t.seconds).collect::<Vec<_>>());
    let decode_s = median(
        &ours
            .iter()
            .filter_map(|t| t.decode_seconds)
            .collect::<Vec<_>>(),
    );
    println!(
        "time per song (decode + analysis), median over 40: marionette {:.3} s (decoding {:.3} s), \
         librosa {:.3} s: marionette {:.1}x faster",
        ours_s,
        decode_s,
        theirs_s,
        theirs_s / ours_s
    );
}
