//! `marionette music` on a song the test synthesizes and writes as WAV: the text report, the
//! JSON object other tools read, the picture, and a clear error for a file that is not audio.

use std::process::Command;

use marionette::choreo::music::synth::{SynthSong, synthesize};
use marionette::choreo::music::wav::wav_bytes;

#[test]
fn music_prints_tempo_beats_bars_as_text_and_json_and_draws_them() {
    let song = SynthSong {
        bpm: 104.5,
        bars: 8,
        ..SynthSong::default()
    };
    let t = synthesize(&song).unwrap();
    let dir = std::env::temp_dir().join(format!("marionette-music-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("song.wav");
    std::fs::write(&path, wav_bytes(&t.samples, 1, t.sample_rate).unwrap()).unwrap();
    let png = dir.join("song.png");
    let out = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["music", path.to_str().unwrap(), "--json", "--out"])
        .arg(&png)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let tempo = v["tempo_bpm"].as_f64().unwrap();
    assert!((tempo / 104.5 - 1.0).abs() < 0.01, "{tempo}");
    let beats = v["beats_s"].as_array().unwrap();
    assert!(beats.len() >= 30, "{}", beats.len());
    let bars = v["bars"].as_array().unwrap();
    assert!(bars.len() >= 7, "{}", bars.len());
    for key in ["start_s", "end_s", "rms", "rms_db"] {
        assert!(bars[0][key].is_f64(), "bars[0].{key}: {}", bars[0]);
    }
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let text = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["music", path.to_str().unwrap()])
        .output()
        .unwrap();
    let s = String::from_utf8_lossy(&text.stdout);
    assert!(
        s.contains("tempo") && s.contains("BPM") && s.contains("RMS (dB)"),
        "{s}"
    );
    let junk = dir.join("junk.mp3");
    std::fs::write(&junk, b"not audio at all").unwrap();
    let bad = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["music", junk.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    let e = String::from_utf8_lossy(&bad.stderr);
    assert!(e.contains("junk.mp3") && e.contains("cannot decode"), "{e}");
    // A silent song: the error names the file and says why.
    let silent = dir.join("silent.wav");
    std::fs::write(&silent, wav_bytes(&vec![0.0; 44_100], 1, 22_050).unwrap()).unwrap();
    let bad = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["music", silent.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    let e = String::from_utf8_lossy(&bad.stderr);
    assert!(
        e.contains("silent.wav") && e.contains("the song is silent"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
