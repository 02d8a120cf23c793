//! One 3-second pushed fall of the fall21 human (the paper's experiment, elderly ranges, default
//! step 0.5 ms with semi-implicit Euler and implicit joint damping): wall time per fall; steps
//! per second = 6000 / time. Also the same fall stopped once at rest (a GA evaluation), and RK4
//! at 0.25 ms (its stability bound) for comparison.
//! Run: `cargo bench --bench fall`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use marionette::dynamics::Integrator;
use marionette::experiments::fall::{FallConfig, simulate_fall};
use marionette::humanoid::AgeGroup;
use std::hint::black_box;
use std::time::Duration;

fn bench_fall(c: &mut Criterion) {
    let cfg = FallConfig::paper(AgeGroup::Elderly);
    let steps = (cfg.duration_s / cfg.dt_s).round() as u64;
    let mut g = c.benchmark_group("fall_3s");
    g.sample_size(20).measurement_time(Duration::from_secs(8));
    g.throughput(Throughput::Elements(steps));
    g.bench_function("semi_implicit_euler_dt0.5ms", |b| {
        b.iter(|| black_box(simulate_fall(black_box(&cfg)).expect("fall").damage))
    });
    g.finish();
    // What a GA evaluation needs: the same fall, ended once the body has rested 0.3 s (wall
    // time only: the step count depends on when it rests).
    let mut until_rest = cfg.clone();
    until_rest.stop_at_rest = true;
    let mut g = c.benchmark_group("fall_until_rest");
    g.sample_size(20).measurement_time(Duration::from_secs(5));
    g.bench_function("semi_implicit_euler_dt0.5ms", |b| {
        b.iter(|| black_box(simulate_fall(black_box(&until_rest)).expect("fall").steps))
    });
    g.finish();
    // RK4 takes the joint damping explicitly: the stability check asks for 0.25 ms here
    // (12 000 steps, 4 evaluations each).
    let mut rk = cfg.clone();
    rk.integrator = Integrator::Rk4;
    rk.dt_s = 2.5e-4;
    let mut g = c.benchmark_group("fall_3s_rk4");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    g.throughput(Throughput::Elements(12_000));
    g.bench_function("rk4_dt0.25ms", |b| {
        b.iter(|| black_box(simulate_fall(black_box(&rk)).expect("fall").damage))
    });
    g.finish();
}

criterion_group!(benches, bench_fall);
criterion_main!(benches);
