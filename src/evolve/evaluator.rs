//! Who computes the fitness of a generation: the [`Evaluator`] trait, the in-process rayon
//! backend ([`InProcess`]) and the JSON-lines worker protocol ([`JsonLines`] drives a worker
//! process; [`serve`] is the worker side, `marionette eval --stdin`), through which a Ray
//! cluster (`tools/ray_eval.py`) evaluates generations while the GA loop, its checkpoints and
//! its bits stay in the engine.
//!
//! The protocol, one JSON object per line:
//! 1. client → worker, once: `{"protocol": "marionette-eval/2", "problem": {…}}` (the problem,
//!    e.g. a [`FallProblem`](super::fall_fitness::FallProblem));
//! 2. per batch, client → worker: `{"index": i, "genes": [x, …], "refine": k}` for each genome
//!    (`refine` as in [`Evaluator::evaluate`]; absent means 1), then `{"evaluate": true}`;
//! 3. worker → client: `{"index": i, "damage": d}` or `{"index": i, "error": "why"}` for each,
//!    then `{"done": n}`.
//!
//! Numbers travel as shortest round-trip decimals, so genes and damages cross bit for bit.

use std::io::{BufRead, BufReader, Write};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::fall_fitness::FallProblem;
use super::genome::Genome;

/// The protocol's name and version.
/// Version 2 added `refine`; a version-1 worker would ignore it and answer at the problem's
/// own resolution, so the version is checked.
pub const PROTOCOL: &str = "marionette-eval/2";

/// Why a run could not go on.
#[derive(Debug, thiserror::Error)]
pub enum EvolveError {
    /// A setting is invalid.
    #[error("ga.{field}: {message}")]
    Config {
        /// Field.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// The evaluator broke (worker died, protocol violated).
    #[error("evaluator: {0}")]
    Evaluator(String),
    /// A checkpoint could not be read or written.
    #[error("checkpoint {path}: {message}")]
    Checkpoint {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// Too many evaluations of a generation failed ([`super::GaConfig::max_failed_share`]):
    /// the run, the generation and the first failures.
    #[error("the GA stopped: {0}")]
    Stopped(String),
}

/// The result of one evaluation: the damage (lower is fitter) or why the simulation failed.
pub type Evaluation = Result<f64, String>;

/// Computes the fitness of a generation's genomes, in order.
pub trait Evaluator {
    /// The damage of each genome of `generation` (same order and length as `genomes`), the
    /// problem resolved `refine` times finer than its own resolution (1: as posed; for a fall,
    /// the time step divided by `refine`). The GA re-evaluates its elites at `refine = 2` to
    /// check that their fitness is not an artefact of the resolution.
    fn evaluate(
        &mut self,
        generation: u64,
        genomes: &[Genome],
        refine: u32,
    ) -> Result<Vec<Evaluation>, EvolveError>;

    /// The elite checks of `generation`: [`Self::evaluate`] of `checks` at `refine`. Meanwhile
    /// an evaluator may start on `ahead()`, the children the next generation evaluates (at
    /// refinement 1) if the checks change nothing (bred only when called), which `wanted`
    /// tells from the checks' evaluations; it then answers that next [`Self::evaluate`] from
    /// what it found, if the genomes asked for are those bit for bit. Only an evaluator whose
    /// results depend on nothing but the genome and the refinement (as a fall's do) may look
    /// ahead: it changes when results are computed, never what they are. The default
    /// evaluates the checks only (and breeds nothing).
    fn evaluate_checks(
        &mut self,
        generation: u64,
        checks: &[Genome],
        refine: u32,
        ahead: &dyn Fn() -> Vec<Genome>,
        wanted: &(dyn Fn(&[Evaluation]) -> bool + Sync),
    ) -> Result<Vec<Evaluation>, EvolveError> {
        let _ = (ahead, wanted);
        self.evaluate(generation, checks, refine)
    }
}

/// Evaluates in this process, in parallel on the current rayon pool.
pub struct InProcess<F: Fn(&[Genome], u32) -> Vec<Evaluation>> {
    /// Evaluates a batch at a refinement (for falls: in parallel Worlds, each fall to the bits it has alone, at the
    /// time step divided by the refinement).
    pub batch: F,
}

impl<F: Fn(&[Genome], u32) -> Vec<Evaluation>> Evaluator for InProcess<F> {
    fn evaluate(
        &mut self,
        _: u64,
        genomes: &[Genome],
        refine: u32,
    ) -> Result<Vec<Evaluation>, EvolveError> {
        Ok((self.batch)(genomes, refine))
    }
}

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

/// Evaluates a batch one genome at a time in parallel with `f`.
pub fn par_map(genomes: &[Genome], f: impl Fn(&[f64]) -> Evaluation + Sync) -> Vec<Evaluation> {
    genomes.par_iter().map(|g| f(g)).collect()
}

#[derive(Serialize, Deserialize)]
struct Header {
    protocol: String,
    problem: serde_json::Value,
}

#[derive(Serialize, Deserialize)]
#[serde(untagged)]
enum Request {
    Genome {
        index: usize,
        genes: Vec<f64>,
        #[serde(default = "unrefined", skip_serializing_if = "is_unrefined")]
        refine: u32,
    },
    Evaluate {
        evaluate: bool,
    },
}

fn unrefined() -> u32 {
    1
}

fn is_unrefined(k: &u32) -> bool {
    *k == 1
}

#[derive(Serialize, Deserialize)]
#[serde(untagged)]
enum Reply {
    Damage { index: usize, damage: f64 },
    Error { index: usize, error: String },
    Done { done: usize },
}

/// Drives a worker process over the JSON-lines protocol.
pub struct JsonLines {
    child: Child,
    stdin: ChildStdin,
    stdout: BufReader<ChildStdout>,
}

impl JsonLines {
    /// Starts `command` (e.g. `marionette eval --stdin`, or `python3 tools/ray_eval.py`) and
    /// sends it `problem`.
    pub fn start(mut command: Command, problem: &impl Serialize) -> Result<Self, EvolveError> {
        let err = |m: String| EvolveError::Evaluator(m);
        let mut child = command
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .map_err(|e| err(format!("cannot start {command:?}: {e}")))?;
        let stdin = child.stdin.take().ok_or_else(|| err("no stdin".into()))?;
        let stdout = BufReader::new(child.stdout.take().ok_or_else(|| err("no stdout".into()))?);
        let mut me = Self {
            child,
            stdin,
            stdout,
        };
        let header = Header {
            protocol: PROTOCOL.into(),
            problem: serde_json::to_value(problem).map_err(|e| err(e.to_string()))?,
        };
        me.send(&header)?;
        Ok(me)
    }

    fn send(&mut self, v: &impl Serialize) -> Result<(), EvolveError> {
        let mut line =
            serde_json::to_string(v).map_err(|e| EvolveError::Evaluator(e.to_string()))?;
        line.push('\n');
        self.stdin
            .write_all(line.as_bytes())
            .map_err(|e| EvolveError::Evaluator(format!("worker stdin: {e}")))
    }
}

impl Evaluator for JsonLines {
    fn evaluate(
        &mut self,
        _: u64,
        genomes: &[Genome],
        refine: u32,
    ) -> Result<Vec<Evaluation>, EvolveError> {
        for (index, g) in genomes.iter().enumerate() {
            self.send(&Request::Genome {
                index,
                genes: g.clone(),
                refine,
            })?;
        }
        self.send(&Request::Evaluate { evaluate: true })?;
        self.stdin
            .flush()
            .map_err(|e| EvolveError::Evaluator(format!("worker stdin: {e}")))?;
        let mut out: Vec<Option<Evaluation>> = vec![None; genomes.len()];
        let mut line = String::new();
        loop {
            line.clear();
            let n = self
                .stdout
                .read_line(&mut line)
                .map_err(|e| EvolveError::Evaluator(format!("worker stdout: {e}")))?;
            if n == 0 {
                return Err(EvolveError::Evaluator(
                    "the worker closed its output".into(),
                ));
            }
            let reply: Reply = serde_json::from_str(line.trim()).map_err(|e| {
                EvolveError::Evaluator(format!("bad reply line {:?}: {e}", line.trim()))
            })?;
            let (index, r) = match reply {
                Reply::Done { .. } => break,
                Reply::Damage { index, damage } => (index, Ok(damage)),
                Reply::Error { index, error } => (index, Err(error)),
            };
            let slot = out.get_mut(index).ok_or_else(|| {
                EvolveError::Evaluator(format!("reply for index {index} of {}", genomes.len()))
            })?;
            *slot = Some(r);
        }
        out.into_iter()
            .enumerate()
            .map(|(i, r)| {
                r.ok_or_else(|| EvolveError::Evaluator(format!("no reply for genome {i}")))
            })
            .collect()
    }
}

impl Drop for JsonLines {
    fn drop(&mut self) {
        // Closing stdin ends the worker; wait so no zombie is left.
        let _ = self.stdin.flush();
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Longest request line the worker accepts (bytes).
pub const MAX_LINE: usize = 1 << 20;

/// Largest refinement a worker accepts (a fall at 1/64 of its step already takes 64 times as
/// long).
pub const MAX_REFINE: u32 = 64;

/// The worker side: reads the header, builds the evaluator of its problem with `make`, then
/// answers batches until its input ends (a batch mixing refinements is evaluated per
/// refinement).
pub fn serve<R: BufRead, W: Write, E: Fn(&[Genome], u32) -> Vec<Evaluation>>(
    input: R,
    mut output: W,
    make: impl FnOnce(serde_json::Value) -> Result<E, String>,
) -> Result<(), EvolveError> {
    let err = |m: String| EvolveError::Evaluator(m);
    let mut lines = input.lines();
    let first = lines
        .next()
        .ok_or_else(|| err("no header line".into()))?
        .map_err(|e| err(e.to_string()))?;
    let header: Header = serde_json::from_str(&first).map_err(|e| err(format!("header: {e}")))?;
    if header.protocol != PROTOCOL {
        return Err(err(format!(
            "protocol '{}' is not '{PROTOCOL}'",
            header.protocol
        )));
    }
    let eval = make(header.problem).map_err(|e| err(format!("problem: {e}")))?;
    let mut batch: Vec<(usize, Genome, u32)> = Vec::new();
    for (k, line) in lines.enumerate() {
        let line = line.map_err(|e| err(e.to_string()))?;
        if line.len() > MAX_LINE {
            return Err(err(format!("line {} longer than {MAX_LINE} bytes", k + 2)));
        }
        if line.trim().is_empty() {
            continue;
        }
        match serde_json::from_str::<Request>(&line)
            .map_err(|e| err(format!("line {}: {e}", k + 2)))?
        {
            Request::Genome {
                index,
                genes,
                refine,
            } => {
                if !(1..=MAX_REFINE).contains(&refine) {
                    return Err(err(format!(
                        "line {}: refine must be 1..={MAX_REFINE}, found {refine}",
                        k + 2
                    )));
                }
                batch.push((index, genes, refine))
            }
            Request::Evaluate { .. } => {
                let mut results: Vec<Option<Evaluation>> = vec![None; batch.len()];
                let mut levels: Vec<u32> = batch.iter().map(|b| b.2).collect();
                levels.sort_unstable();
                levels.dedup();
                for level in levels {
                    let at: Vec<usize> =
                        (0..batch.len()).filter(|&i| batch[i].2 == level).collect();
                    let genomes: Vec<Genome> = at.iter().map(|&i| batch[i].1.clone()).collect();
                    for (i, r) in at.into_iter().zip(eval(&genomes, level)) {
                        results[i] = Some(r);
                    }
                }
                let mut text = String::new();
                for ((index, _, _), r) in batch.iter().zip(results) {
                    let r = r.unwrap_or_else(|| Err("not evaluated".into()));
                    let reply = match r {
                        Ok(damage) if damage.is_finite() => Reply::Damage {
                            index: *index,
                            damage,
                        },
                        Ok(damage) => Reply::Error {
                            index: *index,
                            error: format!("damage {damage}"),
                        },
                        Err(error) => Reply::Error {
                            index: *index,
                            error,
                        },
                    };
                    text.push_str(&serde_json::to_string(&reply).map_err(|e| err(e.to_string()))?);
                    text.push('\n');
                }
                text.push_str(&format!("{{\"done\":{}}}\n", batch.len()));
                output
                    .write_all(text.as_bytes())
                    .and_then(|_| output.flush())
                    .map_err(|e| err(e.to_string()))?;
                batch.clear();
            }
        }
    }
    Ok(())
}
