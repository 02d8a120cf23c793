//! The generational genetic algorithm: an initial population uniform in the bounds, then per
//! generation elitism (the best `elites` pass unchanged), tournament selection, SBX crossover and
//! polynomial mutation. Every random draw of generation `g` comes from a generator seeded by the
//! run's seed and `g` ([`crate::seed::world_seed`]); evaluations draw nothing, so a run is the
//! same bits whatever evaluates it and however many threads it uses, and a resumed run continues
//! exactly. As in the textbook loop (e.g. DEAP's `eaSimple`, which evaluates only the individuals
//! whose fitness crossover or mutation invalidated), a child that is gene for gene a copy of an
//! evaluated parent (copied without crossover, no gene mutated) inherits its fitness instead of
//! being simulated again: an evaluation draws nothing and depends on the genome alone, so the
//! run is the same bits as one that re-evaluates it.

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use serde::{Deserialize, Serialize};

use super::checkpoint::Consistent;
use super::error::{EvaluatorError, StopCause};
use super::evaluator::{Evaluation, Evaluator, EvolveError};
use super::failure::ELITE_CHECK_REFINE;
use super::failure::{EvaluationError, Failure};
use super::genome::{Bounds, Genome};
use super::logbook::GenerationRecord;
use super::operators::{better, polynomial_mutation, sbx, tournament};
use crate::seed::world_seed;

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
    /// The resolution check of the elites: before an individual passes on as one of the best
    /// `max(elites, 1)` of its generation (and before it can be the run's best), it is
    /// re-evaluated at twice the resolution (a fall at half its time step); if its fitness
    /// moves by more than this fraction of itself, `|D(h/2) − D(h)| > tol · D(h)`, it won
    /// through a simulation artefact and gets the worst fitness (logged as a failure), and the
    /// next best is checked in turn. `None`: no check. Default 0.10 (issue 14's criterion).
    pub elite_check_tolerance: Option<f64>,
    /// The share of a generation's evaluations that may fail (an unstable simulation, a
    /// worker's error, a damage negative or not finite; a child that inherits a parent's
    /// fitness counts as that parent's successful evaluation): a generation with more failures
    /// stops the GA at once, naming the first failures ([`GaState::stopped`]). In [0, 1);
    /// default 0.5.
    pub max_failed_share: f64,
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
            elite_check_tolerance: Some(0.10),
            max_failed_share: 0.5,
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
        if let Some(t) = self.elite_check_tolerance
            && !(t.is_finite() && t >= 0.0)
        {
            return bad(
                "elite_check_tolerance",
                format!("must be a finite fraction ≥ 0 (or None), found {t}"),
            );
        }
        if !(0.0..1.0).contains(&self.max_failed_share) {
            return bad(
                "max_failed_share",
                format!("must be in [0, 1), found {}", self.max_failed_share),
            );
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
    /// Damage of each (`None`: the evaluation failed, or the elite check rejected it).
    pub fitness: Vec<Option<f64>>,
    /// Whether each individual has passed the elite check (its fitness held at twice the
    /// resolution); elites carry it into the next generation.
    #[serde(default)]
    pub checked: Vec<bool>,
    /// The best genome found so far and its damage.
    pub best: Option<(Genome, f64)>,
    /// The best genome of generation 0 (the unevolved "before").
    pub initial_best: Option<Genome>,
    /// Evaluations so far (at the problem's own resolution).
    pub evaluations: u64,
    /// Children that were copies of an evaluated parent and inherited its fitness (and elite
    /// check) instead of an evaluation, so far.
    #[serde(default)]
    pub inherited: u64,
    /// Re-evaluations of elites at twice the resolution so far ([`GaConfig::elite_check_tolerance`]).
    #[serde(default)]
    pub check_evaluations: u64,
    /// Re-evaluations of elites in the current generation.
    #[serde(default)]
    pub generation_checks: u64,
    /// One record per generation so far.
    pub logbook: Vec<GenerationRecord>,
    /// Failed evaluations and rejected elite checks: (generation, index, why); in a
    /// checkpoint, why is its message.
    pub failures: Vec<(u64, usize, Failure)>,
    /// Why the GA stopped: a generation in which more than [`GaConfig::max_failed_share`] of
    /// the evaluations failed (the generation is closed; every later step refuses with this).
    #[serde(default)]
    pub stopped: Option<String>,
}

impl GaState {
    /// Generation 0: `config.population` genomes uniform in `bounds`, evaluated. If more than
    /// [`GaConfig::max_failed_share`] of them failed, the state is [`Self::stopped`] and every
    /// step refuses ([`Self::halted`]).
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
            checked: Vec::new(),
            best: None,
            initial_best: None,
            evaluations: 0,
            inherited: 0,
            check_evaluations: 0,
            generation_checks: 0,
            logbook: Vec::new(),
            failures: Vec::new(),
            stopped: None,
        };
        let results = evaluator.evaluate(0, &population, 1)?;
        s.receive(
            Brood {
                generation: 0,
                elites: Vec::new(),
                inherited: vec![None; population.len()],
                children: population,
            },
            results,
        )?;
        if s.stopped.is_some() {
            s.close();
        } else {
            s.check_and_close(evaluator)?;
        }
        s.initial_best = s.best.as_ref().map(|b| b.0.clone());
        Ok(s)
    }

    /// `Err(EvolveError::Stopped)` with the cause if the GA has stopped ([`Self::stopped`]).
    pub fn halted(&self) -> Result<(), EvolveError> {
        match &self.stopped {
            Some(why) => Err(EvolveError::Stopped {
                run: format!("seed {}", self.config.seed),
                cause: StopCause::from_message(why),
            }),
            None => Ok(()),
        }
    }

    /// The whole-state consistency check of a state read from elsewhere (a checkpoint): valid
    /// settings and bounds, one genome, fitness and check flag per individual, every gene
    /// finite and within its bounds, every damage finite and ≥ 0, one logbook record per
    /// generation so far, failures of generations so far. `Err` says what disagrees.
    pub fn consistency(&self) -> Result<(), String> {
        self.config.validate().map_err(|e| e.to_string())?;
        self.individuals_consistency()?;
        self.history_consistency()
    }

    /// One genome, fitness and check flag per individual, valid bounds, every gene within
    /// them, every damage finite and ≥ 0 (the best's too).
    fn individuals_consistency(&self) -> Result<(), String> {
        let n = self.config.population;
        if self.population.len() != n {
            return Err(format!(
                "population has {} genomes, ga.population is {n}",
                self.population.len()
            ));
        }
        for (name, len) in [
            ("fitness", self.fitness.len()),
            ("checked", self.checked.len()),
        ] {
            if len != n {
                return Err(format!("{name} has {len} entries for a population of {n}"));
            }
        }
        let b = &self.bounds;
        Bounds::new(b.lo.clone(), b.hi.clone()).map_err(|e| format!("bounds: {e}"))?;
        for (i, x) in self.population.iter().enumerate() {
            self.genome_consistency(&format!("genome {i}"), x)?;
        }
        let damage = |d: f64| d.is_finite() && d >= 0.0;
        if let Some((i, f)) = self
            .fitness
            .iter()
            .enumerate()
            .find_map(|(i, f)| f.filter(|&d| !damage(d)).map(|d| (i, d)))
        {
            return Err(format!(
                "fitness of individual {i} is {f}, not a damage (finite, ≥ 0)"
            ));
        }
        if let Some((x, f)) = &self.best {
            self.genome_consistency("best genome", x)?;
            if !damage(*f) {
                return Err(format!("best damage is {f}, not a damage (finite, ≥ 0)"));
            }
        }
        if let Some(x) = &self.initial_best {
            self.genome_consistency("initial best genome", x)?;
        }
        Ok(())
    }

    /// The genome `x` (named `what`) has one gene per bound, each within its bounds.
    fn genome_consistency(&self, what: &str, x: &Genome) -> Result<(), String> {
        let b = &self.bounds;
        if x.len() != b.len() {
            return Err(format!(
                "{what} has {} genes, the bounds {}",
                x.len(),
                b.len()
            ));
        }
        match (0..x.len()).find(|&k| !(b.lo[k]..=b.hi[k]).contains(&x[k])) {
            Some(k) => Err(format!(
                "{what}: gene {k} = {} is outside its bounds [{}, {}]",
                x[k], b.lo[k], b.hi[k]
            )),
            None => Ok(()),
        }
    }

    /// The generation within ga.generations, one logbook record per generation so far, the
    /// evaluations as the last record says, failures of generations so far in order.
    fn history_consistency(&self) -> Result<(), String> {
        let n = self.config.population;
        let g = self.generation;
        if g > self.config.generations {
            return Err(format!(
                "generation {g} is past ga.generations = {}",
                self.config.generations
            ));
        }
        if self.logbook.len() as u64 != g + 1 {
            return Err(format!(
                "the logbook has {} records at generation {g} (one per generation 0..={g})",
                self.logbook.len()
            ));
        }
        if let Some((k, r)) = self
            .logbook
            .iter()
            .enumerate()
            .find(|(k, r)| r.generation != *k as u64)
        {
            return Err(format!(
                "logbook record {k} is of generation {}",
                r.generation
            ));
        }
        let logged = self.logbook.last().map_or(0, |r| r.evaluations);
        if logged != self.evaluations {
            return Err(format!(
                "evaluations is {}, the logbook's last record says {logged}",
                self.evaluations
            ));
        }
        let mut previous = 0;
        for (fg, i, _) in &self.failures {
            if *fg > g || *fg < previous || *i >= n {
                return Err(format!(
                    "failures: an entry of generation {fg}, individual {i}, at generation {g} \
                     with a population of {n} (entries in generation order)"
                ));
            }
            previous = *fg;
        }
        Ok(())
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

    /// Breeds and evaluates the next generation: [`Self::breed`], its evaluation,
    /// [`Self::receive`], the elite check ([`Self::unchecked_elites`], [`Self::receive_checks`])
    /// and [`Self::close`]. A caller running several GAs can take the phases itself to evaluate
    /// all their broods in one batch (the same bits).
    pub fn step(&mut self, evaluator: &mut dyn Evaluator) -> Result<(), EvolveError> {
        self.halted()?;
        let brood = self.breed();
        let todo = brood.to_evaluate();
        let results = if todo.is_empty() {
            Vec::new()
        } else {
            evaluator.evaluate(brood.generation, &todo, 1)?
        };
        self.receive(brood, results)?;
        if self.stopped.is_some() {
            self.close();
            return self.halted();
        }
        self.check_and_close(evaluator)
    }

    /// The elite check by `evaluator`, then [`Self::close`].
    fn check_and_close(&mut self, evaluator: &mut dyn Evaluator) -> Result<(), EvolveError> {
        loop {
            let todo = self.unchecked_elites();
            if todo.is_empty() {
                break;
            }
            let genomes: Vec<Genome> = todo.iter().map(|&i| self.population[i].clone()).collect();
            // The next brood, bred only if the evaluator asks for it.
            let ahead = || {
                self.brood_if_checks_hold(&todo)
                    .map_or_else(Vec::new, |b| b.to_evaluate())
            };
            let wanted = |r: &[Evaluation]| self.checks_hold(&todo, r);
            let results = evaluator.evaluate_checks(
                self.generation,
                &genomes,
                ELITE_CHECK_REFINE,
                &ahead,
                &wanted,
            )?;
            self.receive_checks(&todo, results)?;
        }
        self.close();
        Ok(())
    }

    /// The next generation, bred but not evaluated: the elites (the best `elites`, unchanged,
    /// with their fitness) and the children of tournament selection, SBX crossover and
    /// polynomial mutation, every draw from the generator of (seed, generation). A child
    /// identical to an individual of this generation that has a fitness inherits it and its
    /// elite check ([`Brood::to_evaluate`] leaves it out).
    pub fn breed(&self) -> Brood {
        self.breed_with(&self.checked)
    }

    /// The brood of the next generation if the elite checks of `todo` (from
    /// [`Self::unchecked_elites`]) all hold: [`Self::breed`] with them checked, as it will be
    /// after [`Self::receive_checks`] and [`Self::close`] (`None` when this generation is the
    /// run's last). What an evaluator may work on while the checks run
    /// ([`Evaluator::evaluate_checks`]).
    pub fn brood_if_checks_hold(&self, todo: &[usize]) -> Option<Brood> {
        if self.generation >= self.config.generations {
            return None;
        }
        let mut checked = self.checked.clone();
        for &i in todo {
            if let Some(c) = checked.get_mut(i) {
                *c = true;
            }
        }
        Some(self.breed_with(&checked))
    }

    /// True if the checks' `results` of `todo` all hold, as [`Self::receive_checks`] judges
    /// them (then they leave the ranking, and so the next brood, unchanged).
    pub fn checks_hold(&self, todo: &[usize], results: &[Evaluation]) -> bool {
        let tol = self.config.elite_check_tolerance.unwrap_or(f64::INFINITY);
        results.len() == todo.len()
            && todo.iter().zip(results).all(|(&i, r)| {
                let d = self.fitness.get(i).copied().flatten().unwrap_or(f64::NAN);
                check_holds(d, r, tol)
            })
    }

    /// [`Self::breed`] with the elite-check flags `checked`.
    fn breed_with(&self, checked: &[bool]) -> Brood {
        let c = &self.config;
        let g = self.generation + 1;
        let mut rng = Pcg64::seed_from_u64(world_seed(c.seed, g));
        let rank = self.ranking();
        let elites: Vec<Elite> = rank[..c.elites]
            .iter()
            .map(|&i| Elite {
                genome: self.population[i].clone(),
                fitness: self.fitness[i],
                checked: checked.get(i).copied().unwrap_or(false),
            })
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
        // Copies are found by the genes' bits: an evaluation depends on nothing else.
        let key = |x: &Genome| x.iter().map(|v| v.to_bits()).collect::<Vec<u64>>();
        let mut known = std::collections::HashMap::new();
        for (i, x) in self.population.iter().enumerate() {
            if let Some(f) = self.fitness[i] {
                let checked = checked.get(i).copied().unwrap_or(false);
                // The same genes have the same damage; checked if any copy was.
                known
                    .entry(key(x))
                    .and_modify(|k: &mut (f64, bool)| k.1 |= checked)
                    .or_insert((f, checked));
            }
        }
        let inherited = children
            .iter()
            .map(|x| known.get(&key(x)).copied())
            .collect();
        Brood {
            generation: g,
            elites,
            children,
            inherited,
        }
    }

    /// Takes a brood and the evaluations of its children to evaluate
    /// ([`Brood::to_evaluate`], in order): the population (elites first) of the brood's
    /// generation, failures logged (a damage that is negative or not finite is a failure). The
    /// generation is closed by [`Self::close`] after the elite check; if more than
    /// [`GaConfig::max_failed_share`] of the evaluations failed, the GA is [`Self::stopped`]
    /// (the caller closes the generation and goes no further).
    pub fn receive(&mut self, brood: Brood, results: Vec<Evaluation>) -> Result<(), EvolveError> {
        let copies = brood.copies();
        let expected = brood.children.len() - copies;
        result_count(expected, &results)?;
        self.generation = brood.generation;
        self.evaluations += expected as u64;
        self.inherited += copies as u64;
        self.generation_checks = 0;
        let (mut pop, mut fit, mut checked) = (Vec::new(), Vec::new(), Vec::new());
        for e in brood.elites {
            pop.push(e.genome);
            fit.push(e.fitness);
            checked.push(e.checked);
        }
        let offset = pop.len();
        let mut results = results.into_iter();
        for (k, (genome, known)) in brood.children.into_iter().zip(brood.inherited).enumerate() {
            if let Some((f, was_checked)) = known {
                pop.push(genome);
                fit.push(Some(f));
                checked.push(was_checked);
                continue;
            }
            // The count was checked: a result is always there.
            let r = results.next().unwrap_or(Err(EvaluationError::NotEvaluated));
            let f = match r.and_then(|d| EvaluationError::of_damage(d).map_or(Ok(d), Err)) {
                Ok(d) => Some(d),
                Err(why) => {
                    self.failures
                        .push((self.generation, offset + k, why.into()));
                    None
                }
            };
            pop.push(genome);
            fit.push(f);
            checked.push(false);
        }
        self.population = pop;
        self.fitness = fit;
        self.checked = checked;
        // A child that inherits a parent's fitness counts as that parent's evaluation, which
        // succeeded.
        self.stop_if_too_many_failed(expected + copies);
        Ok(())
    }

    /// Stops the GA ([`Self::stopped`]) if more than [`GaConfig::max_failed_share`] of this
    /// generation's `children` evaluations failed, naming the first three failures.
    fn stop_if_too_many_failed(&mut self, children: usize) {
        let failed: Vec<&(u64, usize, Failure)> = self
            .failures
            .iter()
            .rev()
            .take_while(|f| f.0 == self.generation)
            .collect();
        if failed.len() as f64 > self.config.max_failed_share * children as f64 {
            let cause = StopCause::TooManyFailed {
                generation: self.generation,
                failed: failed.len(),
                evaluations: children,
                limit: self.config.max_failed_share,
                first: failed
                    .iter()
                    .rev()
                    .take(3)
                    .map(|(_, i, why)| (*i, why.clone()))
                    .collect(),
            };
            self.stopped = Some(cause.to_string());
        }
    }

    /// The individuals the elite check ([`GaConfig::elite_check_tolerance`]) has yet to
    /// re-evaluate at [`ELITE_CHECK_REFINE`]: those among the best `max(elites, 1)` with a
    /// fitness and not checked (empty when the check is off). Re-rank after
    /// [`Self::receive_checks`]: a rejection brings the next one up.
    pub fn unchecked_elites(&self) -> Vec<usize> {
        if self.config.elite_check_tolerance.is_none() {
            return Vec::new();
        }
        let k = self.config.elites.max(1).min(self.population.len());
        self.ranking()[..k]
            .iter()
            .copied()
            .filter(|&i| self.fitness[i].is_some() && !self.checked.get(i).copied().unwrap_or(true))
            .collect()
    }

    /// Takes the refined evaluations of the individuals `todo` (from
    /// [`Self::unchecked_elites`]): each is marked checked, and one whose fitness moved by more
    /// than the tolerance, `|D_fine − D| > tol · |D|`, or whose re-evaluation failed, gets the
    /// worst fitness and is logged with why.
    pub fn receive_checks(
        &mut self,
        todo: &[usize],
        results: Vec<Evaluation>,
    ) -> Result<(), EvolveError> {
        result_count(todo.len(), &results)?;
        let tol = self.config.elite_check_tolerance.unwrap_or(f64::INFINITY);
        self.check_evaluations += todo.len() as u64;
        self.generation_checks += todo.len() as u64;
        for (&i, r) in todo.iter().zip(results) {
            self.checked[i] = true;
            let d = self.fitness[i].unwrap_or(f64::NAN);
            if check_holds(d, &r, tol) {
                continue;
            }
            let why = match r {
                Ok(fine) => Failure::EliteCheckMoved {
                    damage: d,
                    fine,
                    tolerance: tol,
                },
                Err(e) => Failure::EliteCheckFailed(e),
            };
            self.fitness[i] = None;
            self.failures.push((self.generation, i, why));
        }
        Ok(())
    }

    /// Closes the generation: the best so far (never worse) and the logbook's record.
    pub fn close(&mut self) {
        let before = self.best.as_ref().map(|b| b.1);
        if let Some(&i) = self.ranking().first()
            && let Some(f) = self.fitness[i]
            && before.is_none_or(|b| f < b)
        {
            self.best = Some((self.population[i].clone(), f));
        }
        let failed = self
            .failures
            .iter()
            .rev()
            .take_while(|f| f.0 == self.generation)
            .count();
        self.logbook.push(GenerationRecord::of(
            (
                self.generation,
                self.evaluations,
                failed,
                self.generation_checks,
            ),
            &self.population,
            &self.fitness,
            &self.bounds,
            before,
        ));
    }
}

impl Consistent for GaState {
    fn consistency(&self) -> Result<(), String> {
        GaState::consistency(self).map_err(|m| format!("seed {}: {m}", self.config.seed))
    }
}

/// Whether an elite check holds: the re-evaluation `r` of an individual of damage `d` is finite
/// and within `|D_fine − D| ≤ tol · |D|`.
/// `Ok` if an evaluator gave one result for each of the `expected` genomes, else
/// [`EvaluatorError::ResultCount`].
pub fn result_count(expected: usize, results: &[Evaluation]) -> Result<(), EvolveError> {
    if results.len() == expected {
        Ok(())
    } else {
        Err(EvaluatorError::ResultCount {
            expected,
            found: results.len(),
        }
        .into())
    }
}

fn check_holds(d: f64, r: &Evaluation, tol: f64) -> bool {
    matches!(r, Ok(fine) if fine.is_finite() && *fine >= 0.0 && (fine - d).abs() <= tol * d.abs())
}

/// An elite passing unchanged into a brood.
#[derive(Clone, Debug, PartialEq)]
struct Elite {
    genome: Genome,
    fitness: Option<f64>,
    checked: bool,
}

/// A generation bred by [`GaState::breed`], its children awaiting evaluation.
#[derive(Clone, Debug, PartialEq)]
pub struct Brood {
    /// The generation it becomes.
    pub generation: u64,
    elites: Vec<Elite>,
    /// The children's genomes, in order.
    pub children: Vec<Genome>,
    /// Per child, the fitness and elite check it inherits from an identical individual of the
    /// parent generation (`None`: it is to be evaluated).
    inherited: Vec<Option<(f64, bool)>>,
}

impl Brood {
    /// The children that need an evaluation (those that are not copies of an evaluated
    /// parent), in order: what [`GaState::receive`] takes the results of.
    pub fn to_evaluate(&self) -> Vec<Genome> {
        self.children
            .iter()
            .zip(&self.inherited)
            .filter(|(_, k)| k.is_none())
            .map(|(x, _)| x.clone())
            .collect()
    }

    /// Children that inherit a parent's fitness.
    pub fn copies(&self) -> usize {
        self.inherited.iter().filter(|k| k.is_some()).count()
    }
}
