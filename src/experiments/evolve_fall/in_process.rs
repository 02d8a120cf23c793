//! The in-process evaluator of the falling paper's problem: its falls in parallel Worlds on the
//! current rayon pool, each round of elite checks overlapped with the next generation.

use std::sync::atomic::{AtomicBool, Ordering};

use super::problem::FallProblem;
use crate::evolve::{Evaluation, Evaluator, EvolveError, Genome};

/// Evaluates a [`FallProblem`] in this process (its falls in parallel Worlds on the current
/// rayon pool), overlapping each round of elite checks with the next generation
/// ([`Evaluator::evaluate_checks`]): a check is a single fall that occupies one thread, so the
/// next generation's falls run on the others meanwhile and are given up as soon as a check
/// changes the next generation.
pub struct InProcessFalls {
    /// The problem (private: what was evaluated ahead holds for it alone).
    problem: FallProblem,
    /// Batches answered from the look-ahead so far (generations whose falls ran alongside
    /// their parents' elite checks).
    pub answered_ahead: u64,
    /// The genomes evaluated ahead and their evaluations, for the next [`Evaluator::evaluate`].
    ahead: Option<(Vec<Genome>, Vec<Evaluation>)>,
}

impl InProcessFalls {
    /// Evaluates `problem`.
    pub fn new(problem: FallProblem) -> Self {
        Self {
            problem,
            answered_ahead: 0,
            ahead: None,
        }
    }

    /// The problem.
    pub fn problem(&self) -> &FallProblem {
        &self.problem
    }
}

/// True if `a` and `b` are the same genomes bit for bit.
fn same_genomes(a: &[Genome], b: &[Genome]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| {
            x.len() == y.len() && x.iter().zip(y).all(|(u, v)| u.to_bits() == v.to_bits())
        })
}

impl Evaluator for InProcessFalls {
    fn evaluate(
        &mut self,
        _: u64,
        genomes: &[Genome],
        refine: u32,
    ) -> Result<Vec<Evaluation>, EvolveError> {
        if let Some((g, r)) = self.ahead.take()
            && refine == 1
            && same_genomes(&g, genomes)
        {
            self.answered_ahead += 1;
            return Ok(r);
        }
        Ok(self.problem.evaluate(genomes, refine))
    }

    fn evaluate_checks(
        &mut self,
        _: u64,
        checks: &[Genome],
        refine: u32,
        ahead: &dyn Fn() -> Vec<Genome>,
        wanted: &(dyn Fn(&[Evaluation]) -> bool + Sync),
    ) -> Result<Vec<Evaluation>, EvolveError> {
        self.ahead = None;
        let p = &self.problem;
        let ahead = ahead();
        if ahead.is_empty() {
            return Ok(p.evaluate(checks, refine));
        }
        let stop = AtomicBool::new(false);
        let ((done, hold), next) = rayon::join(
            || {
                let r = p.evaluate(checks, refine);
                let hold = wanted(&r);
                if !hold {
                    stop.store(true, Ordering::Relaxed);
                }
                (r, hold)
            },
            || p.evaluate_until(&ahead, 1, &stop),
        );
        if let Some(next) = next
            && hold
        {
            self.ahead = Some((ahead, next));
        }
        Ok(done)
    }
}
