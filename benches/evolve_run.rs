//! The paper's whole GA for one age group, the unit of issue 14's speed aim: the elderly
//! problem, seed 1, 30 chromosomes × 500 generations as `scenes/evolve_fall.ron` runs it (two
//! elites kept, children that copy an evaluated parent inheriting its fitness, the elites
//! checked at half the step), evaluated in process on a rayon pool of 2 threads as the scene
//! does ([`InProcessFalls`]: the next generation's falls run alongside each elite check).
//! Unlike the generation bench of `benches/evolve.rs` (the initial population), it includes
//! the evolved generations, whose falls last longer before they rest. Each iteration starts from a fresh
//! problem (the standing body settled once, as in a run). One iteration takes about 1.5 min, so
//! the 10 samples take about 15–20 minutes.
//! Run: `cargo bench --bench evolve_run`.

use criterion::{Criterion, criterion_group, criterion_main};
use marionette::evolve::{GaConfig, GaState};
use marionette::experiments::evolve_fall::{FallProblem, InProcessFalls};
use marionette::humanoid::ranges::AgeGroup;
use std::hint::black_box;
use std::time::Duration;

/// One whole GA; returns the final state.
fn paper_ga(seed: u64) -> GaState {
    let problem = FallProblem::paper(AgeGroup::Elderly);
    let bounds = problem.bounds().expect("bounds");
    let cfg = GaConfig {
        seed,
        ..GaConfig::default()
    };
    let mut e = InProcessFalls::new(problem);
    let mut s = GaState::initial(cfg, bounds, &mut e).expect("GA");
    while !s.done() {
        s.step(&mut e).expect("GA step");
    }
    s
}

fn bench_paper_ga(c: &mut Criterion) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("pool");
    let mut g = c.benchmark_group("paper_ga_elderly_30x500");
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(600));
    let mut reported = false;
    g.bench_function("threads_2", |b| {
        b.iter(|| {
            let s = pool.install(|| paper_ga(black_box(1)));
            if !reported {
                reported = true;
                eprintln!(
                    "falls simulated {}, inherited {}, at half the step {}, best damage {:.1} N",
                    s.evaluations,
                    s.inherited,
                    s.check_evaluations,
                    s.best.as_ref().map_or(f64::NAN, |b| b.1)
                );
            }
            black_box(s.generation)
        })
    });
    g.finish();
}

criterion_group!(benches, bench_paper_ga);
criterion_main!(benches);
