//! Filling 64 bars over a database of 2,000 segments (issue 10: under 50 ms). The database is
//! the shared dance clips (`MARIONETTE_DATA/dance`, kinematic tempo at the octave nearest the
//! song's 136 BPM, as a scene builds it) grown to 2,000 segments by
//! mirror images and time offsets (`choreo::augment`), or, without the shared data, a database
//! of generated dance clips grown the same way. Four pins at bars 5, 21, 40 and 58.
//!
//! - `transition_table_2000`: every connection C(a → b) of the 2,000 × 2,000 pairs (rayon);
//! - `fill_64x2000`: [`fill`] as the API gives it, the table built inside, then the exact DP;
//! - `fill_with_table_64x2000` / `fill_dijkstra_with_table_64x2000`: the exact DP / Dijkstra on
//!   a prepared table (an editor builds the table once per database);
//! - `fill_assemble_64x2000` (issue 34: under 50 ms): what Generate does once the table is
//!   built: the fill with the music term within the seam budget, then the dance assembled at
//!   30 fps with every bar's beats warped onto the song's and its feet put on the floor
//!   ([`plant_feet`]), 64 bars of 1.76 s (136 BPM); `…_fixed_kappa` the same at κ as given
//!   (one DP instead of the paper's and κ's).
//!
//! The music: 64 bars whose loudness rises and falls, as percentile ranks.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use marionette::choreo::TransitionTable;
use marionette::choreo::augment;
use marionette::choreo::generated_database;
use marionette::choreo::music::Bar;
use marionette::choreo::percentile_ranks;
use marionette::choreo::{BuildParams, Database, Manifest, OnRefusal};
use marionette::choreo::{DanceParams, assemble};
use marionette::choreo::{FillParams, Pins, fill, fill_dijkstra_with_table, fill_with_table};
use marionette::choreo::{PlantParams, plant_feet};

/// The tempo of the bench's song, BPM.
const SONG_BPM: f64 = 136.0;

/// The 2,000-segment database (module docs), built for the song's tempo as a scene builds it.
fn database() -> Database {
    let dir = marionette::io::data_dir().join("dance");
    let params = BuildParams {
        music_bpm: Some(SONG_BPM),
        ..BuildParams::default()
    };
    let base = Manifest::from_folder(&dir)
        .and_then(|m| Database::build(&m, &params, OnRefusal::Fail, |_, _| {}));
    let base = match base {
        Ok(db) => {
            eprintln!("shared dance clips: {} segments", db.segments.len());
            db
        }
        Err(e) => {
            eprintln!("no shared dance data ({e}): generated clips instead");
            generated_database(1, 12, 10).expect("generated clips cut into bars")
        }
    };
    let db = augment(&base, 2000, 1);
    eprintln!("augmented to {} segments", db.segments.len());
    db
}

fn bench(c: &mut Criterion) {
    let db = database();
    let p = FillParams::default();
    let n = db.segments.len();
    let pins = Pins::from([(5, 17 % n), (21, 901 % n), (40, 1402 % n), (58, 3 % n)]);
    let table = TransitionTable::new(&db, &p.transition).unwrap();
    let loudness: Vec<f64> = (0..64)
        .map(|k| (k as f64 * 0.37).sin() + 1e-3 * k as f64)
        .collect();
    let music = percentile_ranks(&loudness);
    let bar_s = 4.0 * 60.0 / SONG_BPM;
    let bars: Vec<Bar> = (0..64)
        .map(|k| Bar {
            start_s: k as f64 * bar_s,
            end_s: (k + 1) as f64 * bar_s,
            rms: 0.1,
            rms_db: -20.0,
        })
        .collect();
    let beats: Vec<f64> = (0..=256).map(|k| k as f64 * bar_s / 4.0).collect();
    let a = fill_dijkstra_with_table(&db, &table, &music, &pins, &p).unwrap();
    let b = fill_with_table(&db, &table, &music, &pins, &p).unwrap();
    assert_eq!(a, b, "Dijkstra and the DP agree");
    eprintln!(
        "64 bars: total cost {:.4}, κ taken {} of {} (seam budget {:?})",
        a.total_cost, a.intensity_weight, p.intensity_weight, p.seam_budget
    );
    let mut g = c.benchmark_group("choreo_fill");
    g.sample_size(10);
    g.bench_function("transition_table_2000", |bch| {
        bch.iter(|| black_box(TransitionTable::new(&db, &p.transition).unwrap()))
    });
    g.bench_function("fill_64x2000", |bch| {
        bch.iter(|| black_box(fill(&db, &music, &pins, &p).unwrap()))
    });
    g.bench_function("fill_with_table_64x2000", |bch| {
        bch.iter(|| black_box(fill_with_table(&db, &table, &music, &pins, &p).unwrap()))
    });
    // The same fill at κ as given (no seam budget): one DP instead of the paper's and the top
    // rung's together.
    let fixed = FillParams {
        seam_budget: None,
        ..p.clone()
    };
    g.bench_function("fill_with_table_64x2000_fixed_kappa", |bch| {
        bch.iter(|| black_box(fill_with_table(&db, &table, &music, &pins, &fixed).unwrap()))
    });
    g.bench_function("fill_dijkstra_with_table_64x2000", |bch| {
        bch.iter(|| black_box(fill_dijkstra_with_table(&db, &table, &music, &pins, &p).unwrap()))
    });
    // The two halves of Generate after the fill, apart.
    let f = fill_with_table(&db, &table, &music, &pins, &p).unwrap();
    g.bench_function("assemble_64", |bch| {
        bch.iter(|| {
            black_box(assemble(
                &db,
                &f.segments,
                &bars,
                &beats,
                &DanceParams::default(),
            ))
        })
    });
    let d = assemble(&db, &f.segments, &bars, &beats, &DanceParams::default()).unwrap();
    g.bench_function("plant_feet_64", |bch| {
        bch.iter(|| {
            let mut clip = d.clip.clone();
            black_box(plant_feet(&mut clip, &PlantParams::default()))
        })
    });
    for (name, params) in [
        ("fill_assemble_64x2000", &p),
        ("fill_assemble_64x2000_fixed_kappa", &fixed),
    ] {
        g.bench_function(name, |bch| {
            bch.iter(|| {
                let f = fill_with_table(&db, &table, &music, &pins, params).unwrap();
                let mut d =
                    assemble(&db, &f.segments, &bars, &beats, &DanceParams::default()).unwrap();
                let planted = plant_feet(&mut d.clip, &PlantParams::default());
                black_box((d, planted))
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
