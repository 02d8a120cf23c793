//! The POP909 evaluation of the music analysis, shared by `tests/choreo/music_real_songs.rs` and
//! `benches/music_real_songs.rs`: the 40 shared songs (`$MARIONETTE_DATA/pop909/NNN.mid` with
//! `NNN.beats.txt`) rendered to audio with FluidSynth and the Fluid R3 GM soundfont (cached in
//! `target/pop909-audio/`), scored against their annotated beats and downbeats, beside librosa's
//! `beat_track` (`tools/librosa_beats.py`) run on the same files in the same run.
//!
//! The split: sorted by number, song i is held out of development when i mod 5 is 1 or 3 (16
//! songs); the other 24 are the ones the analysis was developed on.

#![allow(dead_code)] // the test and the bench each use part of it

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use marionette::choreo::music::decode_file;
use marionette::choreo::music::eval::{Annotations, BeatScores, read_annotations, score};
use marionette::choreo::music::{MusicParams, analyze};

/// The soundfont: `$MARIONETTE_SOUNDFONT`, else Debian's Fluid R3 GM.
pub fn soundfont() -> PathBuf {
    std::env::var_os("MARIONETTE_SOUNDFONT")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/share/sounds/sf2/FluidR3_GM.sf2"))
}

/// Whether `fluidsynth` runs and the soundfont is there (the reason when not).
pub fn renderer() -> Result<(), String> {
    let sf2 = soundfont();
    if !sf2.exists() {
        return Err(format!(
            "no soundfont at {} (Debian fluid-soundfont-gm)",
            sf2.display()
        ));
    }
    match Command::new("fluidsynth").arg("--version").output() {
        Ok(o) if o.status.success() => Ok(()),
        _ => Err("no fluidsynth on the PATH (Debian fluidsynth)".into()),
    }
}

/// One annotated song.
#[derive(Debug, Clone)]
pub struct Song {
    /// Its number, e.g. "003".
    pub id: String,
    /// Held out of development.
    pub held_out: bool,
    /// The MIDI file.
    pub midi: PathBuf,
    /// Its annotations.
    pub truth: Annotations,
}

/// The songs of `dir` (its `NNN.mid` with `NNN.beats.txt`), sorted, with the split.
pub fn songs(dir: &Path) -> Vec<Song> {
    let mut ids: Vec<String> = std::fs::read_dir(dir)
        .expect("the pop909 folder")
        .filter_map(|e| {
            let name = e.ok()?.file_name().to_string_lossy().into_owned();
            name.strip_suffix(".mid").map(str::to_string)
        })
        .collect();
    ids.sort();
    ids.into_iter()
        .enumerate()
        .map(|(i, id)| {
            let truth = read_annotations(&dir.join(format!("{id}.beats.txt")), (2, 1.0))
                .unwrap_or_else(|e| panic!("{e}"));
            Song {
                midi: dir.join(format!("{id}.mid")),
                held_out: matches!(i % 5, 1 | 3),
                id,
                truth,
            }
        })
        .collect()
}

/// The song rendered to a 22.05 kHz WAV (cached; rendered to a temporary name and renamed, so a
/// cached file is always whole).
pub fn render(song: &Song) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/pop909-audio");
    std::fs::create_dir_all(&dir).expect("target/pop909-audio");
    let wav = dir.join(format!("{}.wav", song.id));
    if wav.exists() {
        return wav;
    }
    let part = dir.join(format!("{}.{}.part.wav", song.id, std::process::id()));
    let out = Command::new("fluidsynth")
        .args(["-ni", "-q", "-r", "22050", "-T", "wav", "-F"])
        .arg(&part)
        .arg(soundfont())
        .arg(&song.midi)
        .output()
        .expect("fluidsynth runs");
    assert!(
        out.status.success() && part.exists(),
        "fluidsynth on {}: {}",
        song.midi.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::rename(&part, &wav).expect("rename the rendered song");
    wav
}

/// Renders every song (two at a time), returning the WAV paths in order.
pub fn render_all(songs: &[Song]) -> Vec<PathBuf> {
    let mut out = vec![PathBuf::new(); songs.len()];
    std::thread::scope(|s| {
        let (a, b) = out.split_at_mut(songs.len() / 2);
        let (sa, sb) = songs.split_at(songs.len() / 2);
        s.spawn(move || {
            for (o, song) in a.iter_mut().zip(sa) {
                *o = render(song);
            }
        });
        for (o, song) in b.iter_mut().zip(sb) {
            *o = render(song);
        }
    });
    out
}

/// One tracker's result on one song.
#[derive(Debug, Clone, Copy)]
pub struct Tracked {
    /// Its scores.
    pub scores: BeatScores,
    /// Wall time of decoding and analysis (s).
    pub seconds: f64,
    /// The part of `seconds` spent decoding, when measured apart (s).
    pub decode_seconds: Option<f64>,
}

/// marionette's analysis (default parameters) of `wav`, decoded and analysed in this process.
pub fn ours(song: &Song, wav: &Path) -> Tracked {
    let start = Instant::now();
    let audio = decode_file(wav).unwrap_or_else(|e| panic!("{e}"));
    let decode_seconds = start.elapsed().as_secs_f64();
    let a = analyze(&audio.samples, audio.sample_rate, &MusicParams::default())
        .unwrap_or_else(|e| panic!("{}: {e}", song.id));
    let seconds = start.elapsed().as_secs_f64();
    let downbeats: Vec<f64> = a.downbeats.iter().map(|&i| a.beats_s[i]).collect();
    Tracked {
        scores: score(
            &a.beats_s,
            &downbeats,
            a.tempo_bpm,
            &song.truth.beats_s,
            &song.truth.downbeats_s,
        ),
        seconds,
        decode_seconds: Some(decode_seconds),
    }
}

/// librosa's `beat_track` on each of `wavs` by `python` (`tools/librosa_beats.py`), in order.
pub fn librosa(python: &Path, songs: &[&Song], wavs: &[&Path]) -> Vec<Tracked> {
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tools/librosa_beats.py");
    let out = Command::new(python)
        .arg(&script)
        .args(wavs)
        .output()
        .expect("python runs");
    assert!(
        out.status.success(),
        "librosa_beats.py: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).expect("utf-8");
    let rows: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON line"))
        .collect();
    assert_eq!(rows.len(), songs.len(), "{text}");
    rows.iter()
        .zip(songs)
        .map(|(r, song)| {
            let beats: Vec<f64> = r["beats_s"]
                .as_array()
                .expect("beats_s")
                .iter()
                .filter_map(|v| v.as_f64())
                .collect();
            let tempo = r["tempo_bpm"].as_f64().expect("tempo_bpm");
            Tracked {
                // librosa has no downbeats: every fourth beat from its first, as a 4/4 reading.
                scores: score(
                    &beats,
                    &beats.iter().step_by(4).copied().collect::<Vec<_>>(),
                    tempo,
                    &song.truth.beats_s,
                    &song.truth.downbeats_s,
                ),
                seconds: r["seconds"].as_f64().expect("seconds"),
                decode_seconds: None,
            }
        })
        .collect()
}

/// Means of a set of scores: (F, CMLt, AMLt, Acc1, Acc2, downbeat F).
pub fn means(rows: &[BeatScores]) -> [f64; 6] {
    let n = rows.len().max(1) as f64;
    let m = |f: &dyn Fn(&BeatScores) -> f64| rows.iter().map(f).sum::<f64>() / n;
    [
        m(&|s| s.f_measure),
        m(&|s| s.continuity.cml_t),
        m(&|s| s.continuity.aml_t),
        m(&|s| s.acc1 as u8 as f64),
        m(&|s| s.acc2 as u8 as f64),
        m(&|s| s.downbeat_f),
    ]
}

/// One line of the table: a tracker's means over a set of songs.
pub fn line(name: &str, rows: &[BeatScores]) -> String {
    let [f, cmlt, amlt, a1, a2, df] = means(rows);
    format!(
        "{name:<28} F {f:.3}  CMLt {cmlt:.3}  AMLt {amlt:.3}  Acc1 {:>3.0} %  Acc2 {:>3.0} %  downbeat F {df:.3}",
        100.0 * a1,
        100.0 * a2
    )
}
