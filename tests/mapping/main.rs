//! Mapping motion capture onto the models: conventions, automatic mapping on real data, the mapping
//! command.
//!
//! One test binary (`cargo test --release --test mapping NAME`), a module per file; a
//! module that needs a feature (`render`, `audio`, or `cli` for the `marionette` binary) is
//! built with it.

#[path = "../common/mod.rs"]
mod common;

mod auto_real_data;
#[cfg(feature = "cli")]
mod cli;
mod conventions;
#[cfg(feature = "render")]
mod real_data;
