//! 64 pushed falls (3 s each) in parallel Worlds (up to four falls at a time in each) on a rayon
//! pool of 1 and of 2 threads:
//! throughput in falls per second.
//! Run: `cargo bench --bench falls_parallel`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use marionette::experiments::fall::FallConfig;
use marionette::experiments::fall::ecs::run_parallel;
use marionette::humanoid::ranges::AgeGroup;
use std::hint::black_box;
use std::time::Duration;

fn bench_parallel(c: &mut Criterion) {
    let configs: Vec<FallConfig> = (0..64)
        .map(|i| {
            let mut cfg = FallConfig::paper(if i % 2 == 0 {
                AgeGroup::Elderly
            } else {
                AgeGroup::Adult
            });
            cfg.push.force_n = 800.0 + 5.0 * i as f64;
            cfg
        })
        .collect();
    // Every fall must succeed, or the bench would time error paths.
    let failures: Vec<String> = run_parallel(&configs)
        .into_iter()
        .filter_map(|r| r.err().map(|e| e.to_string()))
        .collect();
    assert!(failures.is_empty(), "falls failed: {failures:?}");
    let mut g = c.benchmark_group("falls_parallel_64");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    g.throughput(Throughput::Elements(configs.len() as u64));
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        g.bench_function(format!("threads_{threads}"), |b| {
            b.iter(|| {
                let r = pool.install(|| run_parallel(black_box(&configs)));
                black_box(r.iter().filter(|x| x.is_ok()).count())
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench_parallel);
criterion_main!(benches);
