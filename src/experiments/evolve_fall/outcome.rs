//! The evolution as one call ([`run`]): the runs started (or resumed) and advanced to their last
//! generation, then what a report needs as typed values: the statistics over seeds, each age
//! group's best falls before and after evolution with their honesty figures, and the comparison
//! of two groups.

use std::time::Instant;

use rayon::prelude::*;

use super::{
    Checkpointing, EvolutionRun, EvolveConfig, GroupOutcome, advance, outcomes, problem_index,
    replay, start,
};
use crate::evolve::Failure;
use crate::evolve::{Evaluator, EvolveError};
use crate::experiments::fall::{FallConfig, FallResult, SimError, simulate_fall};
use crate::humanoid::AgeGroup;

/// Why an evolution could not be run or reported.
#[derive(Debug, thiserror::Error)]
pub enum EvolveFallError {
    /// The GA, its evaluators or its checkpoints failed.
    #[error(transparent)]
    Evolve(#[from] EvolveError),
    /// A best fall could not be replayed.
    #[error(transparent)]
    Fall(#[from] SimError),
    /// An age group has no run.
    #[error("no run")]
    NoRun,
}

/// The figures an evolved fall must not win by an artefact, besides those of its
/// [`FallResult`] (penetration, torque saturation, pelvis impact, rest).
#[derive(Clone, Debug, PartialEq)]
pub struct Honesty {
    /// The link that went deepest into the floor.
    pub max_penetration_link: Option<String>,
    /// The largest excursion of any DOF past its range (rad).
    pub worst_range_excursion_rad: f64,
    /// The DOF of that excursion.
    pub worst_range_excursion_dof: Option<String>,
    /// The damage of the same fall at half the time step (N; `None` if that run failed).
    pub damage_at_half_step: Option<f64>,
    /// `(damage at half step − damage) / damage`.
    pub half_step_relative_change: Option<f64>,
    /// Whether the damage moved by at most 10 % at half the step.
    pub half_step_within_10_percent: Option<bool>,
}

/// Largest share of the damage a best fall may move by at half the time step to count as
/// resolved ([`Honesty::half_step_within_10_percent`]).
const HALF_STEP_TOLERANCE: f64 = 0.1;

impl Honesty {
    /// The figures of `result`, the fall of `config` run to its end, with `half`, the damage
    /// of the same fall at half the step.
    fn of(result: &FallResult, half: Result<f64, SimError>) -> Self {
        let argmax = |xs: &[f64]| {
            xs.iter()
                .copied()
                .enumerate()
                .fold((0, 0.0), |b, (i, x)| if x > b.1 { (i, x) } else { b })
        };
        let (worst_dof, worst) = argmax(&result.max_limit_excursion_rad);
        let (deepest_link, _) = argmax(&result.max_penetration_by_link_m);
        let half = half.ok();
        let change = half.map(|d| (d - result.damage) / result.damage);
        Self {
            max_penetration_link: result.link_names.get(deepest_link).cloned(),
            worst_range_excursion_rad: worst,
            worst_range_excursion_dof: result.dof_names.get(worst_dof).cloned(),
            damage_at_half_step: half,
            half_step_relative_change: change,
            half_step_within_10_percent: change.map(|c| c.abs() <= HALF_STEP_TOLERANCE),
        }
    }
}

/// One best fall: its controlling configuration, the fall run to its full duration (for
/// pictures) and its honesty figures.
#[derive(Clone, Debug)]
pub struct BestFall {
    /// E.g. `adult before`, `elderly evolved`.
    pub label: String,
    /// The fall as the GA ran it (stopped at rest).
    pub config: FallConfig,
    /// The fall run to its full duration, with frames.
    pub result: FallResult,
    /// The honesty figures of `result`.
    pub honesty: Honesty,
}

/// An age group's best run (lowest final damage) and its falls: the best genome of generation
/// 0 and of the whole run (the paper's "before" and "after").
#[derive(Clone, Debug)]
pub struct GroupBest {
    /// The age group.
    pub age_group: AgeGroup,
    /// Index of the run among [`EvolveOutcome::runs`].
    pub run: usize,
    /// The best fall of generation 0.
    pub before: BestFall,
    /// The best fall of the run.
    pub evolved: BestFall,
}

/// Two age groups compared over their seeds: the gap of their mean best damage against the
/// spread over seeds, at generation 0 and at the end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Comparison {
    /// The groups, in the order of the configuration.
    pub groups: [AgeGroup; 2],
    /// Mean initial best damage of the first group minus the second's (N).
    pub initial_gap: f64,
    /// Sum of the two groups' standard deviations over seeds, initially (N).
    pub initial_seed_spread: f64,
    /// Whether the initial gap is within that spread.
    pub initial_within_seed_spread: bool,
    /// Mean final best damage of the first group minus the second's (N).
    pub final_gap: f64,
    /// Sum of the two groups' standard deviations over seeds, at the end (N).
    pub final_seed_spread: f64,
    /// Whether the final gap exceeds that spread.
    pub final_gap_exceeds_seed_spread: bool,
}

impl Comparison {
    /// Of two groups' outcomes.
    fn of(a: &GroupOutcome, b: &GroupOutcome) -> Self {
        let spread = a.final_.std + b.final_.std;
        let spread0 = a.initial.std + b.initial.std;
        Self {
            groups: [a.age_group, b.age_group],
            initial_gap: a.initial.mean - b.initial.mean,
            initial_seed_spread: spread0,
            initial_within_seed_spread: (a.initial.mean - b.initial.mean).abs() <= spread0,
            final_gap: a.final_.mean - b.final_.mean,
            final_seed_spread: spread,
            final_gap_exceeds_seed_spread: (a.final_.mean - b.final_.mean).abs() > spread,
        }
    }
}

/// What an evolution gives: the runs at their last generation and the figures over them.
#[derive(Clone, Debug)]
pub struct EvolveOutcome {
    /// Every (age group, seed) run, in the order of the configuration.
    pub runs: Vec<EvolutionRun>,
    /// Per age group the initial and final damage over seeds.
    pub groups: Vec<GroupOutcome>,
    /// Per age group its best run's falls.
    pub best: Vec<GroupBest>,
    /// The two groups compared, when there are two.
    pub comparison: Option<Comparison>,
    /// Wall time of the GA, from the start (or resume) to the last checkpoint (s).
    pub ga_wall_time_s: f64,
}

impl EvolveOutcome {
    /// Falls simulated by the GA over all runs.
    pub fn evaluations(&self) -> u64 {
        self.runs.iter().map(|r| r.state.evaluations).sum()
    }

    /// Children that inherited a parent's fitness instead of being simulated.
    pub fn inherited_fitness(&self) -> u64 {
        self.runs.iter().map(|r| r.state.inherited).sum()
    }

    /// Failed evaluations, elite checks aside.
    pub fn failed_evaluations(&self) -> usize {
        self.failures().filter(|f| !f.is_elite_check()).count()
    }

    /// Elite re-simulations at half the step.
    pub fn check_evaluations(&self) -> u64 {
        self.runs.iter().map(|r| r.state.check_evaluations).sum()
    }

    /// Elites rejected by their check.
    pub fn rejected_elites(&self) -> usize {
        self.failures().filter(|f| f.is_elite_check()).count()
    }

    /// Why each failure failed.
    fn failures(&self) -> impl Iterator<Item = &Failure> {
        self.runs
            .iter()
            .flat_map(|r| &r.state.failures)
            .map(|f| &f.2)
    }

    /// The best damage so far per generation, mean over the seeds of `group` (N), and how many
    /// seeds that is (the curve of the paper's Fig. 2).
    pub fn mean_best_so_far(&self, group: AgeGroup) -> (usize, Vec<f64>) {
        let rs: Vec<&EvolutionRun> = self
            .runs
            .iter()
            .filter(|r| r.problem.age_group == group)
            .collect();
        let len = rs.iter().map(|r| r.state.logbook.len()).min().unwrap_or(0);
        let curve = (0..len)
            .map(|k| {
                rs.iter()
                    .map(|r| r.state.logbook[k].best_so_far)
                    .sum::<f64>()
                    / rs.len() as f64
            })
            .collect();
        (rs.len(), curve)
    }

    /// The best falls, each group's before and evolved in turn.
    pub fn best_falls(&self) -> impl Iterator<Item = &BestFall> {
        self.best.iter().flat_map(|b| [&b.before, &b.evolved])
    }
}

/// Runs the evolution of `config`: from `resumed` (runs read from a checkpoint, already checked
/// against `config`) or started afresh, advanced to the last generation ([`advance`], with
/// `evaluators`, `checkpointing` and `progress`), then each age group's best run replayed
/// before and after evolution (all these falls in parallel) and the figures over seeds.
pub fn run(
    config: &EvolveConfig,
    resumed: Option<Vec<EvolutionRun>>,
    evaluators: &mut [Box<dyn Evaluator>],
    checkpointing: Option<&Checkpointing>,
    progress: impl FnMut(&[EvolutionRun]),
) -> Result<EvolveOutcome, EvolveFallError> {
    let started = Instant::now();
    let mut runs = match resumed {
        Some(runs) => runs,
        None => start(config, evaluators)?,
    };
    advance(
        &mut runs,
        evaluators,
        |r| problem_index(config, r),
        checkpointing,
        progress,
    )?;
    let ga_wall_time_s = started.elapsed().as_secs_f64();
    let groups = outcomes(&runs);
    let best = best_of_groups(&runs, &groups)?;
    let comparison = match groups.as_slice() {
        [a, b] => Some(Comparison::of(a, b)),
        _ => None,
    };
    Ok(EvolveOutcome {
        runs,
        groups,
        best,
        comparison,
        ga_wall_time_s,
    })
}

/// Each group's best run (lowest final damage; the first of equals) and its falls before and
/// after, each replayed to its full duration and at half the step, all in parallel.
fn best_of_groups(
    runs: &[EvolutionRun],
    groups: &[GroupOutcome],
) -> Result<Vec<GroupBest>, EvolveFallError> {
    let mut picks: Vec<(AgeGroup, usize)> = Vec::new();
    for g in groups {
        let (i, _) = runs
            .iter()
            .enumerate()
            .filter(|(_, r)| r.problem.age_group == g.age_group)
            .min_by(|(_, a), (_, b)| {
                let fa = a.state.best.as_ref().map_or(f64::INFINITY, |b| b.1);
                let fb = b.state.best.as_ref().map_or(f64::INFINITY, |b| b.1);
                fa.total_cmp(&fb)
            })
            .ok_or(EvolveFallError::NoRun)?;
        picks.push((g.age_group, i));
    }
    let config = |run: &EvolutionRun, genes: Option<&Vec<f64>>| {
        genes.map_or_else(|| run.problem.fall.clone(), |g| run.problem.config(g))
    };
    let falls: Vec<(String, FallConfig)> = picks
        .iter()
        .flat_map(|&(group, i)| {
            let r = &runs[i];
            [
                (
                    format!("{} before", group.name()),
                    config(r, r.state.initial_best.as_ref()),
                ),
                (
                    format!("{} evolved", group.name()),
                    config(r, r.state.best.as_ref().map(|b| &b.0)),
                ),
            ]
        })
        .collect();
    let simulated: Vec<(Result<FallResult, SimError>, Result<f64, SimError>)> = falls
        .par_iter()
        .map(|(_, c)| {
            let mut half = c.clone();
            half.dt_s *= 0.5;
            half.stop_at_rest = false;
            (replay(c), simulate_fall(&half).map(|r| r.damage))
        })
        .collect();
    let mut best_falls = Vec::with_capacity(falls.len());
    for ((label, config), (result, half)) in falls.into_iter().zip(simulated) {
        let result = result?;
        best_falls.push(BestFall {
            label,
            config,
            honesty: Honesty::of(&result, half),
            result,
        });
    }
    let mut best_falls = best_falls.into_iter();
    Ok(picks
        .into_iter()
        .filter_map(|(age_group, run)| {
            Some(GroupBest {
                age_group,
                run,
                before: best_falls.next()?,
                evolved: best_falls.next()?,
            })
        })
        .collect())
}
