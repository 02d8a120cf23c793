//! The generational genetic algorithm: an initial population uniform in the bounds, then per
//! generation elitism (the best `elites` pass unchanged), tournament selection, SBX crossover and
//! polynomial mutation. Every random draw of generation `g` comes from a generator seeded by the
//! run's seed and `g` ([`crate::ecs::world_seed`]); evaluations draw nothing, so a run is the
//! same bits whatever evaluates it and however many threads it uses, and a resumed run continues
//! exactly.

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use serde::{Deserialize, Serialize};

use super::evaluator::{Evaluator, EvolveError};
use super::genome::{Bounds, Genome};
use super::logbook::GenerationRecord;
use super::operators::{better, polynomial_mutation, sbx, tournament};
use crate::ecs::world_seed;

/// The GA's settings; every operator and rate is a field.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GaConfig {
    /// Chromosomes per generation (the paper: 30).
    pub population: usize,
    /// Generations after the initial one (the paper: up to 500).
    pub generations: u64,
    /// Individuals per tournament.
    pub tournament_size: usize,
    /// Probability that a pair of parents is crossed (else copied).
    pub crossover_probability: f64,
    /// SBX distribution index η_c (larger: children nearer the parents).
    pub crossover_eta: f64,
    /// Per-gene mutation probability (`None`: 1 / number of genes).
    pub mutation_probability: Option<f64>,
    /// Polynomial-mutation distribution index η_m.
    pub mutation_eta: f64,
    /// Best individuals copied unchanged into the next generation (≥ 1 keeps the best).
    pub elites: usize,
    /// Seed of every random draw.
    pub seed: u64,
}

impl Default for GaConfig {
    fn default() -> Self {
        Self {
            population: 30,
            generations: 500,
            tournament_size: 2,
            crossover_probability: 0.9,
            crossover_eta: 15.0,
            mutation_probability: None,
            mutation_eta: 20.0,
            elites: 2,
            seed: 1,
        }
    }
}

/// Largest population and generation count a run accepts.
pub const MAX_POPULATION: usize = 100_000;
/// Largest number of generations a run accepts.
pub const MAX_GENERATIONS: u64 = 1_000_000;

impl GaConfig {
    /// Checks the settings.
    pub fn validate(&self) -> Result<(), EvolveError> {
        let bad = |field: &str, msg: String| {
            Err(EvolveError::Config {
                field: field.into(),
                message: msg,
            })
        };
        if !(2..=MAX_POPULATION).contains(&self.population) {
            return bad(
                "population",
                format!("must be 2..={MAX_POPULATION}, found {}", self.population),
            );
        }
        if self.generations > MAX_GENERATIONS {
            return bad(
                "generations",
                format!("must be ≤ {MAX_GENERATIONS}, found {}", self.generations),
            );
        }
        if self.tournament_size == 0 || self.tournament_size > self.population {
            return bad(
                "tournament_size",
                format!("must be 1..=population, found {}", self.tournament_size),
            );
        }
        if self.elites >= self.population {
            return bad(
                "elites",
                format!("must be below the population, found {}", self.elites),
            );
        }
        for (f, p) in [
            ("crossover_probability", Some(self.crossover_probability)),
            ("mutation_probability", self.mutation_probability),
        ] {
            if let Some(p) = p
                && !(0.0..=1.0).contains(&p)
            {
                return bad(f, format!("must be a probability in [0, 1], found {p}"));
            }
        }
        for (f, e) in [
            ("crossover_eta", self.crossover_eta),
            ("mutation_eta", self.mutation_eta),
        ] {
            if !(e.is_finite() && (0.0..=1000.0).contains(&e)) {
                return bad(f, format!("must be in [0, 1000], found {e}"));
            }
        }
        Ok(())
    }
}

/// The whole state of a run after a generation: what a checkpoint holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GaState {
    /// Settings.
    pub config: GaConfig,
    /// Gene bounds.
    pub bounds: Bounds,
    /// The generation the population belongs to.
    pub generation: u64,
    /// Genomes.
    pub population: Vec<Genome>,
    /// Damage of each (`None`: the evaluation failed).
    pub fitness: Vec<Option<f64>>,
    /// The best genome found so far and its damage.
    pub best: Option<(Genome, f64)>,
    /// The best genome of generation 0 (the unevolved "before").
    pub initial_best: Option<Genome>,
    /// Evaluations so far.
    pub evaluations: u64,
    /// One record per generation so far.
    pub logbook: Vec<GenerationRecord>,
    /// Failed evaluations: (generation, index, why).
    pub failures: Vec<(u64, usize, String)>,
}

impl GaState {
    /// Generation 0: `config.population` genomes uniform in `bounds`, evaluated.
    pub fn initial(
        config: GaConfig,
        bounds: Bounds,
        evaluator: &mut dyn Evaluator,
    ) -> Result<Self, EvolveError> {
        config.validate()?;
        let mut rng = Pcg64::seed_from_u64(world_seed(config.seed, 0));
        let population: Vec<Genome> = (0..config.population)
            .map(|_| {
                (0..bounds.len())
                    .map(|i| bounds.lo[i] + rng.random::<f64>() * bounds.width(i))
                    .collect()
            })
            .collect();
        let mut s = Self {
            config,
            bounds,
            generation: 0,
            population: Vec::new(),
            fitness: Vec::new(),
            best: None,
            initial_best: None,
            evaluations: 0,
            logbook: Vec::new(),
            failures: Vec::new(),
        };
        s.accept(population, None, evaluator)?;
        s.initial_best = s.best.as_ref().map(|b| b.0.clone());
        Ok(s)
    }

    /// True once the configured number of generations has run.
    pub fn done(&self) -> bool {
        self.generation >= self.config.generations
    }

    /// The indices of the population ranked best first.
    pub fn ranking(&self) -> Vec<usize> {
        let mut idx: Vec<usize> = (0..self.population.len()).collect();
        idx.sort_by(|&a, &b| {
            if better(self.fitness[a], a, self.fitness[b], b) {
                std::cmp::Ordering::Less
            } else if better(self.fitness[b], b, self.fitness[a], a) {
                std::cmp::Ordering::Greater
            } else {
                std::cmp::Ordering::Equal
            }
        });
        idx
    }

    /// Breeds and evaluates the next generation.
    pub fn step(&mut self, evaluator: &mut dyn Evaluator) -> Result<(), EvolveError> {
        let c = &self.config;
        let g = self.generation + 1;
        let mut rng = Pcg64::seed_from_u64(world_seed(c.seed, g));
        let rank = self.ranking();
        let elites: Vec<(Genome, Option<f64>)> = rank[..c.elites]
            .iter()
            .map(|&i| (self.population[i].clone(), self.fitness[i]))
            .collect();
        let pm = c
            .mutation_probability
            .unwrap_or(1.0 / self.bounds.len() as f64);
        let mut children: Vec<Genome> = Vec::with_capacity(c.population);
        while elites.len() + children.len() < c.population {
            let a = tournament(&mut rng, &self.fitness, c.tournament_size);
            let b = tournament(&mut rng, &self.fitness, c.tournament_size);
            let (mut x, mut y) = if rng.random::<f64>() < c.crossover_probability {
                sbx(
                    &mut rng,
                    &self.population[a],
                    &self.population[b],
                    &self.bounds,
                    c.crossover_eta,
                )
            } else {
                (self.population[a].clone(), self.population[b].clone())
            };
            polynomial_mutation(&mut rng, &mut x, &self.bounds, pm, c.mutation_eta);
            polynomial_mutation(&mut rng, &mut y, &self.bounds, pm, c.mutation_eta);
            children.push(x);
            if elites.len() + children.len() < c.population {
                children.push(y);
            }
        }
        self.generation = g;
        self.accept(children, Some(elites), evaluator)
    }

    /// Evaluates `children`, forms the population (elites first) and logs the generation.
    fn accept(
        &mut self,
        children: Vec<Genome>,
        elites: Option<Vec<(Genome, Option<f64>)>>,
        evaluator: &mut dyn Evaluator,
    ) -> Result<(), EvolveError> {
        let results = evaluator.evaluate(self.generation, &children)?;
        if results.len() != children.len() {
            return Err(EvolveError::Evaluator(format!(
                "{} results for {} genomes",
                results.len(),
                children.len()
            )));
        }
        self.evaluations += children.len() as u64;
        let (mut pop, mut fit): (Vec<Genome>, Vec<Option<f64>>) =
            elites.unwrap_or_default().into_iter().unzip();
        let offset = pop.len();
        let failed_before = self.failures.len();
        for (k, (genome, r)) in children.into_iter().zip(results).enumerate() {
            let f = match r {
                Ok(d) if d.is_finite() => Some(d),
                Ok(d) => {
                    self.failures
                        .push((self.generation, offset + k, format!("damage {d}")));
                    None
                }
                Err(why) => {
                    self.failures.push((self.generation, offset + k, why));
                    None
                }
            };
            pop.push(genome);
            fit.push(f);
        }
        self.population = pop;
        self.fitness = fit;
        let before = self.best.as_ref().map(|b| b.1);
        if let Some(&i) = self.ranking().first()
            && let Some(f) = self.fitness[i]
            && before.is_none_or(|b| f < b)
        {
            self.best = Some((self.population[i].clone(), f));
        }
        self.logbook.push(GenerationRecord::of(
            (
                self.generation,
                self.evaluations,
                self.failures.len() - failed_before,
            ),
            &self.population,
            &self.fitness,
            &self.bounds,
            before,
        ));
        Ok(())
    }
}
