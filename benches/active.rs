//! Physical characters under physics: one humanoid24 character playing the keyframed jump as a
//! learned primitive (PD + feedforward toward it, root assistance, floor contact), and 100 such
//! characters in one World; throughput in engine ticks (physics steps of 0.5 ms) per second.
//! Run: `cargo bench --bench active`.

use std::hint::black_box;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use marionette::clips::KeyframeClip;
use marionette::ecs::character::{
    PhysicalSettings, Reaction, character_schedule, spawn_physical_character,
};
use marionette::ecs::{Clock, new_world, run_ticks};
use marionette::humanoid::humanoid24_body;
use marionette::primitive::{LearnConfig, Primitive};

const TICKS: usize = 200;

fn bench_active(c: &mut Criterion) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/clips/normal_jump.ron");
    let clip = KeyframeClip::load(&path).expect("clip").to_figure_clip();
    let jump = Arc::new(
        Primitive::learn("jump", &clip.to_trajectory(), &LearnConfig::default())
            .expect("learn")
            .primitive,
    );
    let body = Arc::new(humanoid24_body(1.70, 65.0, 9.81).expect("body"));
    let world_of = |n: usize| {
        let mut w = new_world(Clock::physics(5e-4));
        for i in 0..n {
            spawn_physical_character(
                &mut w,
                &format!("c{i}"),
                body.clone(),
                vec![jump.clone()],
                &PhysicalSettings::default(),
                Reaction::default(),
            )
            .expect("spawn");
        }
        w
    };
    let mut g = c.benchmark_group("active_character");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    for n in [1usize, 100] {
        g.throughput(Throughput::Elements((n * TICKS) as u64));
        g.bench_function(format!("{n}_characters_{TICKS}_ticks"), |b| {
            b.iter_batched(
                || (world_of(n), character_schedule()),
                |(mut w, mut s)| {
                    run_ticks(&mut w, &mut s, TICKS);
                    black_box(w)
                },
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

criterion_group!(benches, bench_active);
criterion_main!(benches);
