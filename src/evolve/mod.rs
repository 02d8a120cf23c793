//! Evolution: the genetic algorithm of the falling paper as a kernel over plain data (no World
//! inside) — a real-coded [`genome`] in [`Bounds`], the textbook [`operators`] (tournament, SBX,
//! polynomial mutation, elitism), the generational loop [`ga`], its [`logbook`] and
//! [`checkpoint`]s — and who computes fitness ([`evaluator`]: in-process rayon over parallel
//! Worlds, or a JSON-lines worker a Ray cluster can run). [`fall_fitness`] is the paper's
//! problem: genes k_p and θ_d of every DOF, fitness the fall's damage.

pub mod checkpoint;
pub mod evaluator;
pub mod fall_fitness;
pub mod ga;
pub mod genome;
pub mod logbook;
pub mod operators;

pub use evaluator::{Evaluation, Evaluator, EvolveError, InProcess, InProcessFalls, JsonLines};
pub use fall_fitness::FallProblem;
pub use ga::{GaConfig, GaState};
pub use genome::{Bounds, Genome};
pub use logbook::GenerationRecord;
