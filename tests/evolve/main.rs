//! The genetic algorithm, its Ray evaluator and the EvolveFall scene.
//!
//! One test binary (`cargo test --release --test evolve NAME`), a module per file; a
//! module that needs a feature (`render`, `audio`, or `cli` for the `marionette` binary) is
//! built with it.

#[path = "../common/mod.rs"]
mod common;

#[cfg(feature = "cli")]
mod ga;
#[cfg(feature = "cli")]
mod ray;
#[cfg(feature = "cli")]
mod scene;
