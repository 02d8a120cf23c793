//! The falling paper's evolution (SPEC §3, paper §5–6) as an experiment: for each age group and
//! each seed, a GA evolves the key pose θ_d and stiffness k_p of every DOF to minimise the damage
//! of the pushed fall; the runs advance generation by generation together, checkpointing every K
//! generations, and report per group the initial and final damage over seeds. The problem a
//! genome is tried on ([`FallProblem`]) and its in-process evaluator ([`InProcessFalls`]) live
//! here, above the GA kernel ([`crate::evolve`]) that knows no fall.

mod in_process;
mod outcome;
mod problem;

pub use in_process::InProcessFalls;
pub use outcome::{BestFall, Comparison, EvolveFallError, EvolveOutcome, GroupBest, Honesty, run};
pub use problem::{
    FallProblem, FallStarts, KP_SATURATION_RAD, ProblemError, STEP_MARGIN, STEP_QUANTA_PER_S,
    SettleCache, stable_step_for, strength_kp_max,
};

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::evolve::ELITE_CHECK_REFINE;
use crate::evolve::ga::Brood;
use crate::evolve::{
    Evaluation, Evaluator, EvolveError, GaConfig, GaState, Genome, StopCause, checkpoint,
};
use crate::experiments::fall::{FallConfig, FallResult, SimError, simulate_fall};
use crate::humanoid::AgeGroup;

/// One evolution: an age group's problem and its GA (the seed is in `state.config`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EvolutionRun {
    /// The problem.
    pub problem: FallProblem,
    /// Where the GA stands.
    pub state: GaState,
}

impl EvolutionRun {
    /// The run's name in messages: age group and seed, e.g. `adult seed 3`.
    pub fn name(&self) -> String {
        format!(
            "{} seed {}",
            self.problem.age_group.name(),
            self.state.config.seed
        )
    }
}

/// The runs of a checkpoint: each run's state consistent ([`GaState::consistency`]) with the
/// bounds of its problem, no run twice, all at the same generation.
impl checkpoint::Consistent for [EvolutionRun] {
    fn consistency(&self) -> Result<(), String> {
        for (k, r) in self.iter().enumerate() {
            let name = r.name();
            r.state
                .consistency()
                .map_err(|m| format!("run {name}: {m}"))?;
            match r.problem.bounds() {
                Ok(b) if b == r.state.bounds => {}
                Ok(_) => {
                    return Err(format!(
                        "run {name}: the bounds differ from those of its problem"
                    ));
                }
                Err(e) => return Err(format!("run {name}: problem: {e}")),
            }
            if self[..k].iter().any(|o| o.name() == name) {
                return Err(format!("run {name} is there twice"));
            }
            if let Some(first) = self.first()
                && first.state.generation != r.state.generation
            {
                return Err(format!(
                    "run {name} is at generation {}, run {} at generation {}: the runs advance \
                     together",
                    r.state.generation,
                    first.name(),
                    first.state.generation
                ));
            }
        }
        Ok(())
    }
}

impl checkpoint::Consistent for Vec<EvolutionRun> {
    fn consistency(&self) -> Result<(), String> {
        self.as_slice().consistency()
    }
}

/// `Err(EvolveError::Stopped)` naming the first run whose GA stopped ([`GaState::stopped`]) and
/// why.
pub fn halted(runs: &[EvolutionRun]) -> Result<(), EvolveError> {
    match runs.iter().find(|r| r.state.stopped.is_some()) {
        Some(r) => Err(EvolveError::Stopped {
            run: r.name(),
            cause: StopCause::from_message(r.state.stopped.as_deref().unwrap_or_default()),
        }),
        None => Ok(()),
    }
}

/// Where and how often the runs are checkpointed.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpointing {
    /// Folder of `checkpoint.json`.
    pub dir: PathBuf,
    /// Generations between checkpoints (≥ 1).
    pub every: u64,
}

/// The experiment: per age group a problem, per seed a GA run.
#[derive(Clone, Debug, PartialEq)]
pub struct EvolveConfig {
    /// One problem per age group.
    pub problems: Vec<FallProblem>,
    /// Seeds; each problem is evolved once per seed.
    pub seeds: Vec<u64>,
    /// GA settings (its `seed` is replaced by each of `seeds`).
    pub ga: GaConfig,
}

/// Starts every (problem, seed) run: generation 0 drawn and evaluated, `evaluators[p]`
/// evaluating problem `p`. A run whose GA stopped in generation 0 ([`GaState::stopped`]) is the
/// last started: [`advance`] then refuses with its cause.
pub fn start(
    config: &EvolveConfig,
    evaluators: &mut [Box<dyn Evaluator>],
) -> Result<Vec<EvolutionRun>, EvolveError> {
    if evaluators.len() != config.problems.len() {
        return Err(EvolveError::Config {
            field: "evaluators".into(),
            message: format!(
                "{} evaluators for {} problems",
                evaluators.len(),
                config.problems.len()
            ),
        });
    }
    let mut runs = Vec::new();
    for (p, problem) in config.problems.iter().enumerate() {
        let bounds = problem.bounds().map_err(|e| EvolveError::Config {
            field: "problem".into(),
            message: e.to_string(),
        })?;
        for &seed in &config.seeds {
            let ga = GaConfig {
                seed,
                ..config.ga.clone()
            };
            let state = GaState::initial(ga, bounds.clone(), evaluators[p].as_mut())?;
            let stopped = state.stopped.is_some();
            runs.push(EvolutionRun {
                problem: problem.clone(),
                state,
            });
            if stopped {
                return Ok(runs);
            }
        }
    }
    Ok(runs)
}

/// Advances every run to its last generation, one generation at a time for all, writing a
/// checkpoint every `checkpointing.every` generations and once at the end, and calling `progress`
/// after each generation. `evaluator_of(run)` names the index of the run's evaluator. The
/// broods of all runs sharing an evaluator are evaluated in one batch (and so are their elite
/// checks), so the cores stay busy past the end of any one run's generation; every run gets
/// the bits it would get alone ([`GaState::step`]). When a run's GA stops (more than
/// `ga.max_failed_share` of a generation's evaluations failed), the generation is closed in
/// every run, checkpointed, and the cause returned ([`halted`]); runs read from a stopped
/// checkpoint are refused with the same cause.
pub fn advance(
    runs: &mut [EvolutionRun],
    evaluators: &mut [Box<dyn Evaluator>],
    evaluator_of: impl Fn(&EvolutionRun) -> usize,
    checkpointing: Option<&Checkpointing>,
    mut progress: impl FnMut(&[EvolutionRun]),
) -> Result<(), EvolveError> {
    let owner: Vec<usize> = runs.iter().map(&evaluator_of).collect();
    if let Some(&e) = owner.iter().find(|&&e| e >= evaluators.len()) {
        return Err(EvolveError::Config {
            field: "evaluators".into(),
            message: format!("evaluator {e} of {}", evaluators.len()),
        });
    }
    let stop = |runs: &[EvolutionRun]| -> Result<(), EvolveError> {
        if halted(runs).is_err()
            && let Some(c) = checkpointing
        {
            checkpoint::save(&c.dir, runs)?;
        }
        halted(runs)
    };
    stop(runs)?;
    // Whether the checkpoint holds the runs as they stand.
    let mut saved = false;
    loop {
        let active: Vec<usize> = (0..runs.len()).filter(|&i| !runs[i].state.done()).collect();
        if active.is_empty() {
            break;
        }
        saved = false;
        let broods: Vec<(usize, Brood)> =
            active.iter().map(|&i| (i, runs[i].state.breed())).collect();
        let generation = broods.iter().map(|b| b.1.generation).max().unwrap_or(0);
        let parts: Vec<(usize, Vec<Genome>)> =
            broods.iter().map(|(i, b)| (*i, b.to_evaluate())).collect();
        let results = evaluate_by_owner(evaluators, &owner, generation, &parts, Batch::Children)?;
        for ((i, brood), r) in broods.into_iter().zip(results) {
            runs[i].state.receive(brood, r)?;
        }
        if halted(runs).is_err() {
            for &i in &active {
                runs[i].state.close();
            }
            progress(runs);
            return stop(runs);
        }
        check_elites(runs, evaluators, &owner, &active, generation)?;
        for &i in &active {
            runs[i].state.close();
        }
        progress(runs);
        let g = runs.iter().map(|r| r.state.generation).max().unwrap_or(0);
        let all_done = runs.iter().all(|r| r.state.done());
        if let Some(c) = checkpointing
            && (g % c.every.max(1) == 0 || all_done)
        {
            checkpoint::save(&c.dir, runs)?;
            saved = true;
        }
    }
    if !saved && let Some(c) = checkpointing {
        checkpoint::save(&c.dir, runs)?;
    }
    Ok(())
}

/// The elite checks of the `active` runs' generation `generation`, round by round, one batch
/// per evaluator (`owner[run]`) per round, until no run has an elite left to check.
fn check_elites(
    runs: &mut [EvolutionRun],
    evaluators: &mut [Box<dyn Evaluator>],
    owner: &[usize],
    active: &[usize],
    generation: u64,
) -> Result<(), EvolveError> {
    loop {
        let todo: Vec<(usize, Vec<usize>)> = active
            .iter()
            .map(|&i| (i, runs[i].state.unchecked_elites()))
            .filter(|t| !t.1.is_empty())
            .collect();
        if todo.is_empty() {
            break;
        }
        let parts: Vec<(usize, Vec<Genome>)> = todo
            .iter()
            .map(|(i, idx)| {
                let pop = &runs[*i].state.population;
                (*i, idx.iter().map(|&k| pop[k].clone()).collect())
            })
            .collect();
        // What the runs of evaluator `e` evaluate next if their checks hold, in the order
        // the next generation's batch asks for it (a run that ends here asks for nothing),
        // bred only if that evaluator asks.
        let ahead = |e: usize| -> Vec<Genome> {
            active
                .iter()
                .filter(|&&i| owner[i] == e)
                .filter_map(|&i| {
                    let idx = todo.iter().find(|t| t.0 == i).map_or(&[][..], |t| &t.1[..]);
                    let brood = runs[i].state.brood_if_checks_hold(idx)?;
                    Some(brood.to_evaluate())
                })
                .flatten()
                .collect()
        };
        let holds = |k: usize, r: &[Evaluation]| runs[todo[k].0].state.checks_hold(&todo[k].1, r);
        let checks = Batch::Checks {
            ahead: &ahead,
            holds: &holds,
        };
        let results = evaluate_by_owner(evaluators, owner, generation, &parts, checks)?;
        for ((i, idx), r) in todo.iter().zip(results) {
            runs[*i].state.receive_checks(idx, r)?;
        }
    }
    Ok(())
}

/// What [`evaluate_by_owner`] evaluates: a generation's children at the problems' own
/// resolution, or elite checks at [`ELITE_CHECK_REFINE`] with `ahead(e)` (the genomes the runs
/// of evaluator `e` evaluate next if their checks hold, bred when called) for the evaluators to
/// work on meanwhile ([`Evaluator::evaluate_checks`]) and `holds(k, results)` telling whether
/// the checks of part `k` hold.
enum Batch<'a> {
    Children,
    Checks {
        ahead: &'a dyn Fn(usize) -> Vec<Genome>,
        holds: &'a (dyn Fn(usize, &[Evaluation]) -> bool + Sync),
    },
}

/// Evaluates `parts` (run index, genomes), all the parts of one evaluator (`owner[run]`) in one
/// batch; returns each part's evaluations, in the order of `parts`.
fn evaluate_by_owner(
    evaluators: &mut [Box<dyn Evaluator>],
    owner: &[usize],
    generation: u64,
    parts: &[(usize, Vec<Genome>)],
    batch: Batch,
) -> Result<Vec<Vec<Evaluation>>, EvolveError> {
    let mut out: Vec<Vec<Evaluation>> = vec![Vec::new(); parts.len()];
    for (e, evaluator) in evaluators.iter_mut().enumerate() {
        let mine: Vec<usize> = (0..parts.len())
            .filter(|&k| owner[parts[k].0] == e)
            .collect();
        let genomes: Vec<Genome> = mine.iter().flat_map(|&k| parts[k].1.clone()).collect();
        if genomes.is_empty() {
            continue;
        }
        let results = match batch {
            Batch::Children => evaluator.evaluate(generation, &genomes, 1)?,
            Batch::Checks { ahead, holds } => {
                let next = || ahead(e);
                let wanted = |results: &[Evaluation]| {
                    let mut rest = results;
                    mine.iter().all(|&k| {
                        let n = parts[k].1.len().min(rest.len());
                        let (part, tail) = rest.split_at(n);
                        rest = tail;
                        n == parts[k].1.len() && holds(k, part)
                    })
                };
                evaluator.evaluate_checks(
                    generation,
                    &genomes,
                    ELITE_CHECK_REFINE,
                    &next,
                    &wanted,
                )?
            }
        };
        crate::evolve::ga::result_count(genomes.len(), &results)?;
        let mut all = results.into_iter();
        for k in mine {
            out[k] = all.by_ref().take(parts[k].1.len()).collect();
        }
    }
    Ok(out)
}

/// The index of `problem`'s age group among `config.problems`.
pub fn problem_index(config: &EvolveConfig, run: &EvolutionRun) -> usize {
    config
        .problems
        .iter()
        .position(|p| p.age_group == run.problem.age_group)
        .unwrap_or(0)
}

/// A figure over seeds: mean and (population) standard deviation.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spread {
    /// Mean.
    pub mean: f64,
    /// Standard deviation.
    pub std: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
}

impl Spread {
    /// Of `xs` (finite values only).
    pub fn of(xs: &[f64]) -> Spread {
        let v: Vec<f64> = xs.iter().copied().filter(|x| x.is_finite()).collect();
        let n = v.len().max(1) as f64;
        let mean = v.iter().sum::<f64>() / n;
        let std = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt();
        Spread {
            mean,
            std,
            min: v.iter().copied().fold(f64::INFINITY, f64::min),
            max: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }
}

/// One age group's outcome over its seeds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GroupOutcome {
    /// The age group.
    pub age_group: AgeGroup,
    /// Seeds.
    pub seeds: Vec<u64>,
    /// Best damage of generation 0 per seed (N).
    pub initial_best: Vec<f64>,
    /// Best damage so far at the last generation per seed (N).
    pub final_best: Vec<f64>,
    /// Over seeds.
    pub initial: Spread,
    /// Over seeds.
    pub final_: Spread,
}

/// Per age group the initial and final damage over seeds.
pub fn outcomes(runs: &[EvolutionRun]) -> Vec<GroupOutcome> {
    let mut groups: Vec<AgeGroup> = Vec::new();
    for r in runs {
        if !groups.contains(&r.problem.age_group) {
            groups.push(r.problem.age_group);
        }
    }
    groups
        .into_iter()
        .map(|g| {
            let rs: Vec<&EvolutionRun> = runs.iter().filter(|r| r.problem.age_group == g).collect();
            let first = |r: &EvolutionRun| r.state.logbook.first().map_or(f64::NAN, |l| l.best);
            let last =
                |r: &EvolutionRun| r.state.logbook.last().map_or(f64::NAN, |l| l.best_so_far);
            let initial_best: Vec<f64> = rs.iter().map(|r| first(r)).collect();
            let final_best: Vec<f64> = rs.iter().map(|r| last(r)).collect();
            GroupOutcome {
                age_group: g,
                seeds: rs.iter().map(|r| r.state.config.seed).collect(),
                initial: Spread::of(&initial_best),
                final_: Spread::of(&final_best),
                initial_best,
                final_best,
            }
        })
        .collect()
}

/// A fall simulated to its full duration (not stopped at rest), for pictures.
pub fn replay(config: &FallConfig) -> Result<FallResult, SimError> {
    let mut c = config.clone();
    c.stop_at_rest = false;
    simulate_fall(&c)
}
