//! What the paper's GA costs: one generation of 30 chromosomes of the initial population (the
//! elderly group's problem: 42 genes, falls stopped once the body rests) in the fall pool's
//! parallel Worlds (up to four falls at a time in each), at the problem's step (0.70 ms, within the accuracy margin), the standing body settled once
//! and kept across iterations as across a GA's generations, on a rayon pool of 1 and of 2
//! threads. The ratio of the two rates is the parallel efficiency × 2. These are initial
//! genomes, whose falls rest sooner than evolved ones: 15 000 / rate understates the paper's
//! whole GA, which `benches/evolve_vs_mujoco.rs` times against MuJoCo. Also one GA step alone (selection,
//! crossover, mutation) without evaluation, and what a checkpoint costs at the size of
//! `scenes/evolve_fall.ron` at its end (2 groups × 5 seeds, 30 × 42 genes, 501 logbook records
//! each): written (checked, read back, written atomically) every generation by default.
//! Run: `cargo bench --bench evolve`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use marionette::evolve::{GaConfig, GaState, InProcess, checkpoint};
use marionette::experiments::evolve_fall::{EvolutionRun, FallProblem};
use marionette::humanoid::AgeGroup;
use std::hint::black_box;
use std::time::Duration;

fn bench_generation(c: &mut Criterion) {
    let problem = FallProblem::paper(AgeGroup::Elderly);
    let bounds = problem.bounds().expect("bounds");
    let cfg = GaConfig {
        population: 30,
        generations: 1,
        seed: 1,
        ..GaConfig::default()
    };
    let mut count = InProcess {
        batch: |g: &[Vec<f64>], refine: u32| problem.evaluate(g, refine),
    };
    let state = GaState::initial(cfg.clone(), bounds.clone(), &mut count).expect("GA");
    let genomes = state.population.clone();
    let failures = state.fitness.iter().filter(|f| f.is_none()).count();
    assert_eq!(failures, 0, "falls of the bench population failed");
    let mut g = c.benchmark_group("ga_generation_30_falls");
    g.sample_size(10).measurement_time(Duration::from_secs(15));
    g.throughput(Throughput::Elements(genomes.len() as u64));
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        g.bench_function(format!("threads_{threads}"), |b| {
            b.iter(|| pool.install(|| black_box(problem.evaluate(black_box(&genomes), 1))))
        });
    }
    g.finish();
    // The GA's own work per generation, with a free evaluation.
    let mut free = InProcess {
        batch: |g: &[Vec<f64>], _: u32| {
            g.iter()
                .map(|x| Ok(x.iter().map(|v| v * v).sum::<f64>()))
                .collect()
        },
    };
    let base = GaState::initial(cfg, bounds, &mut free).expect("GA");
    c.bench_function("ga_step_operators_only_30x42", |b| {
        b.iter(|| {
            let mut s = base.clone();
            s.config.generations = 2;
            s.step(&mut free).expect("step");
            black_box(s.generation)
        })
    });
    // The checkpoint of the scene's ten runs after their 500 generations.
    let mut runs = Vec::new();
    for group in [AgeGroup::Elderly, AgeGroup::Adult] {
        let problem = FallProblem::paper(group);
        let bounds = problem.bounds().expect("bounds");
        for seed in 1..=5 {
            let cfg = GaConfig {
                population: 30,
                generations: 500,
                seed,
                ..GaConfig::default()
            };
            let mut s = GaState::initial(cfg, bounds.clone(), &mut free).expect("GA");
            while !s.done() {
                s.step(&mut free).expect("step");
            }
            runs.push(EvolutionRun {
                problem: problem.clone(),
                state: s,
            });
        }
    }
    let dir = std::env::temp_dir().join(format!("marionette-bench-ck-{}", std::process::id()));
    let mut g = c.benchmark_group("checkpoint_save");
    g.sample_size(20);
    g.bench_function("evolve_fall_10_runs_30x42_500_generations", |b| {
        b.iter(|| checkpoint::save(&dir, black_box(&runs)).expect("save"))
    });
    g.finish();
    let bytes = std::fs::metadata(dir.join(checkpoint::FILE)).map_or(0, |m| m.len());
    println!("checkpoint of the 10 runs: {bytes} bytes");
    std::fs::remove_dir_all(&dir).ok();
}

criterion_group!(benches, bench_generation);
criterion_main!(benches);
