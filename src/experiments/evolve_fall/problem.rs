//! The falling paper's fitness (SPEC §3, paper §5): a genome is the key pose θ_d and the
//! stiffness k_p of every fall21 DOF (2 × 21 = 42 genes; k_v and θ̇_d fixed), its fitness the
//! damage `D = Σ w_i f_i` of the pushed fall it controls (lower is fitter). θ_d is bounded by the
//! age group's joint ranges, the quantity the paper studies; k_p by `[0, kp_max]` with `kp_max`
//! the gain at which a 5° error already asks for the age group's maximal torque
//! ([`crate::humanoid::strength`]): the dynamics saturates PD at that torque, so strength, not
//! the gain, is what bounds an individual, and no one wins by superhuman gains.
//!
//! Genes, in order: `θ_d` (rad) of DOF 0..21, then `k_p` (N·m/rad) of DOF 0..21.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use serde::{Deserialize, Serialize};

use crate::evolve::genome::BoundsError;
use crate::evolve::{Bounds, Evaluation, EvaluationError, Genome};
use crate::experiments::fall::{FallConfig, Ranges, SettledStart, SimError};
use crate::experiments::fall::{ReactionStart, run_parallel_until};
use crate::humanoid::fall21;
use crate::humanoid::{AgeGroup, RangeTable};

/// One age group's optimisation problem: the fall every genome is tried on and the gene bounds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FallProblem {
    /// The age group (its joint ranges bound θ_d and act in the simulation).
    pub age_group: AgeGroup,
    /// The fall a genome controls (its key pose and k_p are replaced by the genes; it stops
    /// once the body rests).
    pub fall: FallConfig,
    /// Upper bound of k_p per DOF (N·m/rad).
    pub kp_max: Vec<f64>,
    /// The fall's settled standing start, kept from one generation to the next.
    #[serde(skip)]
    pub settled: SettleCache,
}

/// The shared starts of a problem's fall, one pair per time step it is evaluated at (its own
/// and the elite check's half of it): the settled standing body ([`SettledStart`]) and the fall
/// run to its reaction time from it ([`ReactionStart`]), computed at the first evaluation and
/// kept for the next ones (anew if the fall has changed since). Not part of the problem: a
/// clone starts empty and equality ignores it.
#[derive(Default)]
pub struct SettleCache(std::sync::Mutex<Vec<FallStarts>>);

/// The starts of one fall: settled, and run to the reaction time when that succeeded.
#[derive(Clone)]
pub struct FallStarts {
    /// The settled standing body.
    pub settled: SettledStart,
    /// The fall at its reaction time (`None` if it could not be run there: each evaluation then
    /// runs from the settled start and reports why).
    pub reaction: Option<ReactionStart>,
}

/// Fall steps a [`SettleCache`] keeps starts for (the oldest is dropped first).
const SETTLE_CACHE_SIZE: usize = 4;

impl SettleCache {
    /// The starts of `fall`, from the cache when they fit; `None` if the fall cannot be built
    /// (each evaluation then reports why).
    pub fn of(&self, fall: &FallConfig) -> Option<FallStarts> {
        let mut c = self.0.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(s) = c
            .iter()
            .find(|s| s.settled.fits(fall) && s.reaction.as_ref().is_none_or(|r| r.fits(fall)))
        {
            return Some(s.clone());
        }
        let settled = SettledStart::of(fall).ok()?;
        let reaction = ReactionStart::of(fall, Some(&settled)).ok();
        let s = FallStarts { settled, reaction };
        if c.len() >= SETTLE_CACHE_SIZE {
            c.remove(0);
        }
        c.push(s.clone());
        Some(s)
    }
}

impl Clone for SettleCache {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl PartialEq for SettleCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::fmt::Debug for SettleCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("SettleCache")
    }
}

/// Why a problem is unusable.
#[derive(Debug, thiserror::Error)]
pub enum ProblemError {
    /// The fall's ranges could not be resolved.
    #[error(transparent)]
    Fall(#[from] SimError),
    /// The bounds are not a box.
    #[error(transparent)]
    Bounds(#[from] BoundsError),
    /// `kp_max` does not have one value per DOF.
    #[error("kp_max needs {expected} values (one per fall21 DOF), found {found}")]
    KpMax {
        /// DOFs.
        expected: usize,
        /// Values given.
        found: usize,
    },
}

/// The angle error (rad) at which the largest k_p asks for the maximal torque: 5°.
pub const KP_SATURATION_RAD: f64 = 5.0 * std::f64::consts::PI / 180.0;

/// The k_p bound of `group` per DOF (N·m/rad): `scale · max(|τ_min|, τ_max) / 5°`, with the age
/// group's torque limits.
pub fn strength_kp_max(group: AgeGroup, scale: f64) -> Vec<f64> {
    crate::humanoid::strength::torque_limits(group)
        .iter()
        .map(|(lo, hi)| scale * lo.abs().max(*hi) / KP_SATURATION_RAD)
        .collect()
}

/// The GA's step is the largest multiple of `1 / STEP_QUANTA_PER_S` seconds (50 µs) within
/// the margin of the stability bound ([`stable_step_for`]).
pub const STEP_QUANTA_PER_S: f64 = 20_000.0;
/// The fraction of the stability bound the GA's step may take: 0.8 (0.70 ms on the paper's
/// falls, bound 0.92 ms). An accuracy margin, not only a stability one: near its bound (ω h → 2)
/// semi-implicit Euler distorts the stiffest mode's frequency by `asin(ωh/2)/(ωh/2)` (+14 % at
/// 0.8, +40 % at 0.98), and the GA would select falls that win through that error. The largest
/// margin at which the elite check rejects such falls as rarely as at 0.65; the measurements
/// that chose it are in `docs/falls.md` ("The step margin"). The scene field `step_margin`
/// sets another.
pub const STEP_MARGIN: f64 = 0.8;

/// The GA's step for every genome of the box `kp ≤ kp_max` on `fall` (s): the
/// stiffest mode of the strongest genome (k_p = `kp_max` on every DOF; θ_d does not change the
/// standing bound) through [`crate::dynamics::stable_step`], times `margin` (a fraction of that
/// bound in (0, 1]; the GA's default is [`STEP_MARGIN`]), rounded down to a multiple of 50 µs
/// ([`STEP_QUANTA_PER_S`]); `fall.dt_s` when nothing is stiff or the fall's scheme has no
/// bound.
pub fn stable_step_for(fall: &FallConfig, kp_max: &[f64], margin: f64) -> Result<f64, SimError> {
    let mut strongest = fall.clone();
    strongest.kp = kp_max.to_vec();
    Ok(
        match crate::experiments::fall::stiffest_mode_of_config(&strongest)? {
            // A scheme without a bound (linearly implicit Euler) keeps the fall's step.
            Some(m) if m.bound_s.is_finite() => {
                (margin * m.bound_s * STEP_QUANTA_PER_S).floor().max(1.0) / STEP_QUANTA_PER_S
            }
            _ => fall.dt_s,
        },
    )
}

impl FallProblem {
    /// The paper's problem for `group`: its fall, stopped at rest, k_p up to the strength
    /// bound ([`strength_kp_max`] with scale 1), stepped at the GA's step of the
    /// strongest genome within the accuracy margin ([`stable_step_for`]: 0.70 ms, 0.8 of the
    /// heel-pad contact's bound of 0.92 ms, against the fall's 0.5 ms).
    pub fn paper(group: AgeGroup) -> Self {
        Self::with_strength(group, 1.0, STEP_MARGIN)
    }

    /// The paper's problem for `group` with k_p bounded by `kp_scale` times the strength bound
    /// ([`strength_kp_max`]) and stepped at `step_margin` of the stability bound of the
    /// strongest genome ([`stable_step_for`]).
    pub fn with_strength(group: AgeGroup, kp_scale: f64, step_margin: f64) -> Self {
        let mut fall = FallConfig::paper(group);
        fall.stop_at_rest = true;
        let kp_max = strength_kp_max(group, kp_scale);
        // The built-in fall is valid, so the bound exists; should it not, the fall's own
        // (smaller) step stays.
        if let Ok(dt) = stable_step_for(&fall, &kp_max, step_margin) {
            fall.dt_s = dt;
        }
        Self {
            age_group: group,
            fall,
            kp_max,
            settled: SettleCache::default(),
        }
    }

    /// The joint ranges of the problem's fall (rad per DOF).
    pub fn ranges(&self) -> Result<Vec<(f64, f64)>, ProblemError> {
        let table = match &self.fall.ranges {
            Ranges::Builtin(g) => RangeTable::builtin(*g),
            Ranges::Table(t) => t.clone(),
            Ranges::File(p) => RangeTable::load(p).map_err(SimError::from)?,
        };
        Ok(table.for_figure(&fall21()).map_err(SimError::from)?)
    }

    /// The gene box: θ_d within the ranges, k_p within `[0, kp_max]`.
    pub fn bounds(&self) -> Result<Bounds, ProblemError> {
        let ranges = self.ranges()?;
        if self.kp_max.len() != ranges.len() {
            return Err(ProblemError::KpMax {
                expected: ranges.len(),
                found: self.kp_max.len(),
            });
        }
        let mut lo: Vec<f64> = ranges.iter().map(|r| r.0).collect();
        let mut hi: Vec<f64> = ranges.iter().map(|r| r.1).collect();
        lo.extend(std::iter::repeat_n(0.0, self.kp_max.len()));
        hi.extend(self.kp_max.iter().copied());
        Ok(Bounds::new(lo, hi)?)
    }

    /// The fall controlled by `genes`.
    pub fn config(&self, genes: &[f64]) -> FallConfig {
        let n = self.kp_max.len();
        let mut c = self.fall.clone();
        c.key_pose_deg = genes[..n].iter().map(|x| x.to_degrees()).collect();
        c.kp = genes[n..2 * n].to_vec();
        c
    }

    /// The damage of every genome, the falls in parallel Worlds (up to four at a time in each,
    /// [`run_parallel_reacting`](crate::experiments::fall::run_parallel_reacting)), at
    /// the problem's time step divided by `refine` (1: the problem's own step); the standing
    /// body is settled once per step for the whole run (the genes do not change how it stands;
    /// the same bits as settling each fall).
    pub fn evaluate(&self, genomes: &[Genome], refine: u32) -> Vec<Evaluation> {
        self.evaluate_until(genomes, refine, &AtomicBool::new(false))
            .expect("never stopped")
    }

    /// [`Self::evaluate`] that gives up as soon as `stop` is set (`None` then).
    pub fn evaluate_until(
        &self,
        genomes: &[Genome],
        refine: u32,
        stop: &AtomicBool,
    ) -> Option<Vec<Evaluation>> {
        let mut fall = self.fall.clone();
        fall.dt_s /= f64::from(refine.max(1));
        let genes = 2 * self.kp_max.len();
        // Genomes of the wrong length (e.g. from a worker's input) are answered, not run.
        let runnable: Vec<usize> = (0..genomes.len())
            .filter(|&i| genomes[i].len() == genes)
            .collect();
        let configs: Vec<FallConfig> = runnable
            .iter()
            .map(|&i| {
                let mut c = self.config(&genomes[i]);
                c.dt_s = fall.dt_s;
                c
            })
            .collect();
        let start = self.settled.of(&fall);
        let mut ran = run_parallel_until(
            &configs,
            start.as_ref().map(|s| &s.settled),
            start.as_ref().and_then(|s| s.reaction.as_ref()),
            stop,
        )?
        .into_iter();
        let out = genomes
            .iter()
            .map(|g| {
                if g.len() != genes {
                    return Err(EvaluationError::GenomeLength {
                        expected: genes,
                        found: g.len(),
                    });
                }
                match ran.next() {
                    Some(r) => r
                        .map(|f| f.damage)
                        .map_err(|e: Arc<SimError>| EvaluationError::Problem(e.into())),
                    None => Err(EvaluationError::NotEvaluated),
                }
            })
            .collect();
        Some(out)
    }
}
