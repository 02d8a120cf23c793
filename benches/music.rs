//! Music analysis of a 3-minute song (onset envelope, tempo, beats, bars, bar RMS; decoding not
//! included): a song synthesized here (180 s at 44.1 kHz, 120 BPM, 90 bars), and the SuperTux
//! song `audio/supertux_forest-sprint.ogg` (208 s at 44.1 kHz, stereo) from `MARIONETTE_DATA`
//! when present, also with its OGG/Vorbis decoding timed on its own.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use marionette::choreo::music::decode_file;
use marionette::choreo::music::{MusicParams, analyze};
use marionette::choreo::music::{SynthSong, synthesize};

fn bench(c: &mut Criterion) {
    let song = synthesize(&SynthSong {
        bpm: 120.0,
        bars: 90,
        sample_rate: 44_100,
        lead_in_s: 0.0,
        tail_s: 0.0,
        ..SynthSong::default()
    })
    .unwrap();
    let params = MusicParams::default();
    let mut g = c.benchmark_group("music");
    g.sample_size(10);
    g.bench_function("analyze_synth_180s_44k", |b| {
        b.iter(|| black_box(analyze(&song.samples, song.sample_rate, &params).unwrap()))
    });
    let path = marionette::io::data_dir().join("audio/supertux_forest-sprint.ogg");
    match decode_file(&path) {
        Ok(audio) => {
            g.bench_function("analyze_forest_sprint_208s_44k", |b| {
                b.iter(|| black_box(analyze(&audio.samples, audio.sample_rate, &params).unwrap()))
            });
            g.bench_function("decode_forest_sprint_ogg", |b| {
                b.iter(|| black_box(decode_file(&path).unwrap()))
            });
        }
        Err(e) => eprintln!("skipping the real song: {e}"),
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
