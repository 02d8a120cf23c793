//! The relevance-feedback search over a database of 2,000 segments grown by mirror images and
//! time offsets (`augment`) from the shared dance clips (`dance/` in `MARIONETTE_DATA`; from
//! the clips generated in `tests/common/dance_clips.rs` when that is absent): one round of six
//! candidates on a fresh bar (S_n empty) and one after three rounds with two likes each (the two
//! likes of the last round not yet taken in); and the throughput of building a database from
//! clips (BVH → humanoid24 → segments) and of growing one by `augment`.

#[path = "../tests/common/dance_clips.rs"]
mod dance_clips;

use std::hint::black_box;

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use marionette::choreo::augment;
use marionette::choreo::{BarSearch, SearchIndex, SearchParams};
use marionette::choreo::{BuildParams, Database, Manifest, OnRefusal};

fn bench(c: &mut Criterion) {
    let dir = marionette::io::data_dir().join("dance");
    let (real, source) = match Manifest::from_folder(&dir) {
        Ok(m) => (
            Database::build(&m, &BuildParams::default(), OnRefusal::Fail, |_, _| {}).unwrap(),
            "shared dance clips",
        ),
        Err(e) => {
            eprintln!("no shared dance clips ({e}): generated clips instead");
            (
                dance_clips::generated_database("bench", 6).0,
                "generated clips",
            )
        }
    };
    let db = augment(&real, 2000, 1);
    eprintln!(
        "{} segments of the {source} augmented to {}",
        real.segments.len(),
        db.segments.len()
    );
    let index = SearchIndex::new(&db);
    let p = SearchParams::default();
    let mut g = c.benchmark_group("choreo_search");
    g.bench_function("round_2000_first", |b| {
        b.iter(|| {
            let mut s = BarSearch::new();
            black_box(index.round(0.7, &mut s, &p).unwrap())
        })
    });
    // Three rounds with two likes each; the likes of the third not yet in the cache.
    let mut warm = BarSearch::new();
    for _ in 0..3 {
        let shown = index.round(0.7, &mut warm, &p).unwrap();
        warm.like(shown[0], true);
        warm.like(shown[3], true);
    }
    g.bench_function("round_2000_fourth_with_2_new_likes", |b| {
        b.iter_batched(
            || warm.clone(),
            |mut s| black_box(index.round(0.7, &mut s, &p).unwrap()),
            BatchSize::SmallInput,
        )
    });
    g.bench_function("index_2000", |b| {
        b.iter(|| black_box(SearchIndex::new(&db)))
    });
    g.finish();

    let mut g = c.benchmark_group("choreo_database");
    g.sample_size(10);
    let (gen_db, gen_dir) = dance_clips::generated_database("bench-build", 6);
    let manifest = Manifest::from_folder(&gen_dir).unwrap();
    // The folder holds the six BVH clips only; their tempo comes from the kinematic beat here.
    let built = Database::build(
        &manifest,
        &BuildParams::default(),
        OnRefusal::Fail,
        |_, _| {},
    )
    .unwrap();
    g.throughput(Throughput::Elements(built.segments.len() as u64));
    g.bench_function("build_6_generated_clips_kinematic_beat", |b| {
        b.iter(|| {
            black_box(
                Database::build(
                    &manifest,
                    &BuildParams::default(),
                    OnRefusal::Fail,
                    |_, _| {},
                )
                .unwrap(),
            )
        })
    });
    if let Ok(m) = Manifest::from_folder(&dir) {
        g.throughput(Throughput::Elements(real.segments.len() as u64));
        g.bench_function("build_shared_dance_clips", |b| {
            b.iter(|| {
                black_box(
                    Database::build(&m, &BuildParams::default(), OnRefusal::Fail, |_, _| {})
                        .unwrap(),
                )
            })
        });
    }
    g.throughput(Throughput::Elements(200));
    g.bench_function("augment_to_200", |b| {
        b.iter(|| black_box(augment(&gen_db, 200, 1)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
