//! Motor-primitive benches: learning a 24-DOF primitive from a 1000-frame clip (120 fps) and a
//! 1000-step rollout of it (the workload on which movement_primitives takes ~14 ms to learn and
//! ~25 ms to roll out).
//!
//! Run: `cargo bench --bench primitive`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use marionette::primitive::synthetic::smooth_humanoid24;
use marionette::primitive::{KernelCount, LearnConfig, Primitive, Regression};

fn bench(c: &mut Criterion) {
    let demo = smooth_humanoid24(1000, 120.0, 7).expect("synthetic demo");
    let configs = [
        (
            "default (25 kernels/s = 209, ridge)",
            LearnConfig::default(),
        ),
        (
            "50 kernels, ridge",
            LearnConfig {
                kernels: KernelCount::Fixed(50),
                ..LearnConfig::default()
            },
        ),
        (
            "50 kernels, LWR",
            LearnConfig {
                kernels: KernelCount::Fixed(50),
                regression: Regression::LocallyWeighted,
                ..LearnConfig::default()
            },
        ),
    ];
    for (label, cfg) in &configs {
        let learned = Primitive::learn("bench", &demo, cfg).expect("learn");
        eprintln!(
            "{label}: {} kernels, median RMSE {:.4} deg",
            learned.primitive.basis.len(),
            learned.fit.median_angle_rmse_deg().unwrap_or(f64::NAN)
        );
        let p = learned.primitive;
        let times: Vec<f64> = (0..1000).map(|k| k as f64 * demo.dt).collect();
        c.bench_function(&format!("learn 24 DOF x 1000 frames, {label}"), |b| {
            b.iter(|| {
                marionette::primitive::learn_dofs(black_box(&demo), &p.basis, cfg).expect("learn")
            })
        });
        c.bench_function(&format!("rollout 24 DOF x 1000 steps, {label}"), |b| {
            b.iter(|| p.sample(black_box(&times), None).expect("rollout"))
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(std::time::Duration::from_secs(1))
        .measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
