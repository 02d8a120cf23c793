//! The music kernel on synthesized songs with exact ground truth (tempo, beats, bars, bar
//! loudness), decoding (WAV written here; the real OGG songs when the shared data is there),
//! and its errors.

use crate::common;

use marionette::choreo::music::eval::f_measure;
use marionette::choreo::music::wav_bytes;
use marionette::choreo::music::{MusicError, MusicParams, analyze};
use marionette::choreo::music::{SynthSong, synthesize};

/// The MIREX beat tolerance (s).
const TOL: f64 = 0.07;

fn check(song: &SynthSong) {
    let track = synthesize(song).unwrap();
    let a = analyze(&track.samples, track.sample_rate, &MusicParams::default()).unwrap();
    let label = format!(
        "{} BPM swing {} snr {:?} at {} Hz",
        song.bpm, song.swing, song.snr_db, song.sample_rate
    );
    let err = (a.tempo_bpm / song.bpm - 1.0).abs();
    assert!(
        err < 0.01,
        "{label}: tempo {} ({:.2} %)",
        a.tempo_bpm,
        100.0 * err
    );
    let f = f_measure(&a.beats_s, &track.beats_s, TOL);
    assert!(f >= 0.95, "{label}: F = {f:.3}; beats {:?}", a.beats_s);
    // Bars: every analysed bar is a true bar (right downbeat), nearly all are found, and each
    // one's RMS is within 0.5 dB of the level it was made with.
    assert!(
        a.bars.len() + 1 >= song.bars,
        "{label}: {} bars",
        a.bars.len()
    );
    for bar in &a.bars {
        let k = track
            .bars_s
            .iter()
            .position(|&(s, _)| (s - bar.start_s).abs() <= TOL)
            .unwrap_or_else(|| panic!("{label}: bar at {} s is not a true bar", bar.start_s));
        let (_, end) = track.bars_s[k];
        assert!(
            (bar.end_s - end).abs() <= TOL,
            "{label}: bar {k} ends {}",
            bar.end_s
        );
        let d = bar.rms_db - track.bar_rms_db[k];
        assert!(
            d.abs() < 0.5,
            "{label}: bar {k} RMS {:.2} dB vs {:.2} dB",
            bar.rms_db,
            track.bar_rms_db[k]
        );
    }
}

#[test]
fn tempi_60_to_180_straight_and_noisy() {
    for (i, bpm) in [60.0, 75.0, 97.3, 120.0, 133.7, 150.0, 180.0]
        .into_iter()
        .enumerate()
    {
        check(&SynthSong {
            bpm,
            bars: 16,
            seed: i as u64,
            ..SynthSong::default()
        });
    }
}

#[test]
fn swing_noise_and_sample_rates() {
    let cases = [
        (91.7, 0.62, Some(10.0), 44_100),
        (128.0, 2.0 / 3.0, Some(15.0), 22_050),
        (172.4, 0.58, None, 48_000),
        (64.2, 0.66, Some(12.0), 16_000),
    ];
    for (i, (bpm, swing, snr_db, sample_rate)) in cases.into_iter().enumerate() {
        check(&SynthSong {
            bpm,
            swing,
            snr_db,
            sample_rate,
            bars: 12,
            jitter_s: 0.005,
            seed: 100 + i as u64,
            ..SynthSong::default()
        });
    }
}

#[test]
fn a_given_downbeat_is_used() {
    let t = synthesize(&SynthSong::default()).unwrap();
    let p = MusicParams {
        downbeat: Some(1),
        ..MusicParams::default()
    };
    let a = analyze(&t.samples, t.sample_rate, &p).unwrap();
    assert!(a.downbeat_given);
    assert!((a.bars[0].start_s - a.beats_s[1]).abs() < 1e-12);
}

#[test]
fn silent_short_and_broken_songs_are_refused() {
    let sr = 22_050;
    let silent = vec![0f32; sr as usize * 10];
    assert!(matches!(
        analyze(&silent, sr, &MusicParams::default()),
        Err(MusicError::Silent { .. })
    ));
    let short = vec![0.1f32; sr as usize / 2];
    let e = analyze(&short, sr, &MusicParams::default()).unwrap_err();
    assert!(matches!(e, MusicError::TooShort { .. }), "{e}");
    assert!(e.to_string().contains("0.500 s"), "{e}");
    let mut nan = synthesize(&SynthSong::default()).unwrap().samples;
    nan[1234] = f32::NAN;
    let e = analyze(&nan, sr, &MusicParams::default()).unwrap_err();
    assert!(e.to_string().contains("sample 1234"), "{e}");
    assert!(matches!(
        analyze(&silent, 0, &MusicParams::default()),
        Err(MusicError::SampleRate(0))
    ));
    // A song of one bar has beats but no whole bar for a dance.
    let one = synthesize(&SynthSong {
        bars: 1,
        lead_in_s: 0.2,
        tail_s: 0.1,
        ..SynthSong::default()
    })
    .unwrap();
    if let Ok(a) = analyze(&one.samples, one.sample_rate, &MusicParams::default()) {
        let e = a.require_bars(2).unwrap_err();
        assert!(e.to_string().contains("whole bars"), "{e}");
    }
}

#[cfg(feature = "audio")]
#[test]
fn a_stereo_wav_decodes_to_its_mono_mix_and_analyses_like_the_buffer() {
    use marionette::choreo::music::decode_file;
    let t = synthesize(&SynthSong {
        bpm: 111.0,
        bars: 8,
        ..SynthSong::default()
    })
    .unwrap();
    // Left half the song (inside full scale), right a quarter: the mono mix is 3/8 of it.
    let inter: Vec<f32> = t
        .samples
        .iter()
        .flat_map(|&s| [0.5 * s, 0.25 * s])
        .collect();
    let dir = std::env::temp_dir().join(format!("marionette-choreo-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("song.wav");
    std::fs::write(&path, wav_bytes(&inter, 2, t.sample_rate).unwrap()).unwrap();
    let audio = decode_file(&path).unwrap();
    assert_eq!((audio.channels, audio.sample_rate), (2, t.sample_rate));
    assert_eq!(audio.samples.len(), t.samples.len());
    for (i, (m, s)) in audio.samples.iter().zip(&t.samples).enumerate().step_by(97) {
        assert!(
            (m - 0.375 * s).abs() < 1e-4,
            "sample {i}: {m} vs {}",
            0.375 * s
        );
    }
    let a = analyze(&audio.samples, audio.sample_rate, &MusicParams::default()).unwrap();
    assert!((a.tempo_bpm / 111.0 - 1.0).abs() < 0.01, "{}", a.tempo_bpm);
    // Not audio, and absent: clear errors naming the file.
    let junk = dir.join("junk.ogg");
    std::fs::write(&junk, b"this is not a song").unwrap();
    let e = decode_file(&junk).unwrap_err();
    assert!(
        e.to_string().contains("junk.ogg") && e.to_string().contains("cannot decode"),
        "{e}"
    );
    let e = decode_file(&dir.join("absent.wav")).unwrap_err();
    assert!(e.to_string().contains("absent.wav"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(feature = "audio")]
#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn the_real_songs_decode_and_have_a_steady_beat() {
    use marionette::choreo::music::decode_file;
    let Some(dir) = common::data_path("audio") else {
        return;
    };
    for name in ["supertux_chipdisko.ogg", "supertux_forest-sprint.ogg"] {
        let audio = decode_file(&dir.join(name)).unwrap();
        assert!(
            audio.duration_s() > 60.0,
            "{name}: {} s",
            audio.duration_s()
        );
        let a = analyze(&audio.samples, audio.sample_rate, &MusicParams::default()).unwrap();
        // A steady song: beats cover it, their spacing barely varies.
        let ibi: Vec<f64> = a.beats_s.windows(2).map(|w| w[1] - w[0]).collect();
        let period = 60.0 / a.tempo_bpm;
        let steady = ibi
            .iter()
            .filter(|&&d| (d / period - 1.0).abs() < 0.05)
            .count();
        assert!(
            steady as f64 > 0.9 * ibi.len() as f64,
            "{name}: {steady}/{}",
            ibi.len()
        );
        assert!(a.bars.len() > 20, "{name}: {} bars", a.bars.len());
    }
}

#[test]
fn bar_rms_follows_20_db_contrasts_on_a_steady_grid() {
    // Without timing jitter the true bar boundaries are where the downbeats sound, so the RMS
    // compares like for like even where a bar is 20 dB quieter than the one before.
    for (i, bpm) in [68.0, 118.5, 166.0].into_iter().enumerate() {
        check(&SynthSong {
            bpm,
            bars: 12,
            bar_levels_db: vec![-30.0, -15.0, -25.0, -10.0],
            jitter_s: 0.0,
            snr_db: Some(15.0),
            seed: 200 + i as u64,
            ..SynthSong::default()
        });
    }
}

/// Point 10 of issue 38: a cut file was analysed in part without a word, and a corrupt file,
/// even a directory, was "not a WAV, OGG/Vorbis or MP3 file".
#[cfg(feature = "audio")]
#[test]
fn decoding_names_each_failure_and_warns_how_much_of_a_cut_file_was_read() {
    use marionette::choreo::music::decode_file;
    let dir = std::env::temp_dir().join(format!("marionette-decode-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let t = synthesize(&SynthSong {
        bpm: 120.0,
        bars: 4,
        ..SynthSong::default()
    })
    .unwrap();
    let whole = wav_bytes(&t.samples, 1, t.sample_rate).unwrap();
    let full = dir.join("whole.wav");
    std::fs::write(&full, &whole).unwrap();
    let a = decode_file(&full).unwrap();
    assert_eq!(a.warning, None);
    // Cut at 40 %: analysed, with a warning saying how much was read.
    let cut = dir.join("cut.wav");
    std::fs::write(&cut, &whole[..whole.len() * 2 / 5]).unwrap();
    let a = decode_file(&cut).unwrap();
    let w = a.warning.clone().expect("no warning for a cut file");
    let total_s = t.samples.len() as f64 / t.sample_rate as f64;
    assert!(
        w.contains(&format!("of the {total_s:.2} s its header states")) && w.contains("cut short"),
        "{w}"
    );
    assert!(w.contains("(40 %)"), "{w}");
    assert!(
        (a.duration_s() - 0.4 * total_s).abs() < 0.01,
        "{}",
        a.duration_s()
    );
    let msg = |p: &std::path::Path| decode_file(p).unwrap_err().to_string();
    let e = msg(&dir);
    assert!(e.contains("is a directory"), "{e}");
    let empty = dir.join("empty.wav");
    std::fs::write(&empty, b"").unwrap();
    assert!(msg(&empty).contains("empty (0 bytes)"), "{}", msg(&empty));
    // A WAV whose header is garbage after its RIFF tag.
    let corrupt = dir.join("corrupt.wav");
    let mut bytes = whole[..64].to_vec();
    bytes[8..16].copy_from_slice(b"XXXXXXXX");
    std::fs::write(&corrupt, &bytes).unwrap();
    let e = msg(&corrupt);
    assert!(
        e.contains("a WAV (RIFF) file") && e.contains("corrupt"),
        "{e}"
    );
    // A format the build does not read, named from its first bytes.
    let flac = dir.join("song.flac");
    std::fs::write(&flac, b"fLaC\0\0\0\x22 and then some bytes").unwrap();
    let e = msg(&flac);
    assert!(
        e.contains("a FLAC file") && e.contains("unsupported format"),
        "{e}"
    );
    // A WAV in a codec the build does not decode (MPEG audio in WAV, format tag 0x55).
    let mpeg = dir.join("mpeg.wav");
    let mut bytes = whole.clone();
    bytes[20..22].copy_from_slice(&0x55u16.to_le_bytes());
    std::fs::write(&mpeg, &bytes).unwrap();
    let e = msg(&mpeg);
    assert!(
        e.contains("mpeg.wav") && e.contains("unsupported codec"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Point 9 of issue 38: a song at −100 dB SNR (pure noise) was danced to random beats. Now it
/// is refused, saying why and how to force it; a noisy but rhythmic song still passes.
#[test]
fn a_song_of_pure_noise_is_refused_as_having_no_beat() {
    for seed in 0..3 {
        let noise = synthesize(&SynthSong {
            snr_db: Some(-100.0),
            bars: 16,
            seed,
            ..SynthSong::default()
        })
        .unwrap();
        let e = analyze(&noise.samples, noise.sample_rate, &MusicParams::default()).unwrap_err();
        assert!(matches!(e, MusicError::NoBeat { .. }), "seed {seed}: {e}");
        assert!(
            e.to_string().contains("no beat structure")
                && e.to_string().contains("min_beat_strength"),
            "{e}"
        );
        // Forced, it is analysed.
        let any = MusicParams {
            min_beat_strength: 0.0,
            ..MusicParams::default()
        };
        assert!(analyze(&noise.samples, noise.sample_rate, &any).is_ok());
    }
    let noisy = synthesize(&SynthSong {
        snr_db: Some(-10.0),
        bars: 16,
        ..SynthSong::default()
    })
    .unwrap();
    let a = analyze(&noisy.samples, noisy.sample_rate, &MusicParams::default()).unwrap();
    assert!((a.tempo_bpm / 120.0 - 1.0).abs() < 0.02, "{}", a.tempo_bpm);
    let bad = MusicParams {
        min_beat_strength: 1.5,
        ..MusicParams::default()
    };
    assert!(matches!(
        analyze(&noisy.samples, noisy.sample_rate, &bad),
        Err(MusicError::Parameter {
            name: "min_beat_strength",
            ..
        })
    ));
}
