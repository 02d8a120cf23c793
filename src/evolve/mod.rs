//! Evolution: a genetic algorithm as a kernel over plain data, knowing no problem in particular
//! (no World inside): a real-coded [`genome`] in [`Bounds`], the textbook [`operators`]
//! (tournament, SBX, polynomial mutation, elitism), the generational loop [`ga`], its
//! [`logbook`] and [`checkpoint`]s, why an individual has no fitness ([`failure`]), why a run cannot go on ([`error`]), and who computes fitness ([`evaluator`]: the [`Evaluator`]
//! trait, an in-process rayon backend, or a JSON-lines worker a Ray cluster can run, generic over
//! a serialisable problem). The falling paper's problem lives with its experiment
//! (`experiments::evolve_fall`).

pub mod checkpoint;
pub(crate) mod error;
pub(crate) mod evaluator;
pub(crate) mod failure;
mod formats;
pub(crate) mod ga;
pub(crate) mod genome;
pub(crate) mod logbook;
pub(crate) mod operators;

pub use error::{
    CheckpointError, EvaluatorError, LineError, StopCause, WorkerFailure, WorkerFault,
};
pub use evaluator::{Evaluation, Evaluator, EvolveError, InProcess, JsonLines, par_map, serve};
pub use failure::{ELITE_CHECK, ELITE_CHECK_REFINE, EvaluationError, Failure, ProblemFailure};
pub use formats::{MAX_LINE, MAX_REFINE, PROTOCOL};
pub use ga::{GaConfig, GaState};
pub use genome::{Bounds, Genome};
pub use logbook::{CSV_HEADER, GenerationRecord, from_json_lines, to_csv, to_json_lines};
