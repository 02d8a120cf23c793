//! 64 pushed falls (3 s each, the paper's explicit 0.5 ms step) in parallel Worlds (up to four falls at a time in each) on a rayon
//! pool of 1 and of 2 threads:
//! throughput in falls per second.
//! Run: `cargo bench --bench falls_parallel`.

mod common;

use common::mujoco::pushed_falls;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use marionette::experiments::fall::run_parallel;
use std::hint::black_box;
use std::time::Duration;

fn bench_parallel(c: &mut Criterion) {
    let configs = pushed_falls();
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
