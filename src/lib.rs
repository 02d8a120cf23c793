//! marionette: a data-oriented ECS simulation engine for human character motion.
//!
//! Three research systems in one engine: learned motor primitives (adjusted, connected,
//! blended), choreography from motion segments, and physically simulated falls whose PD
//! controllers a genetic algorithm evolves. Kernels are plain Rust over plain data; the ECS
//! (`bevy_ecs`) is the wiring.
//!
//! Conventions: metres, seconds, radians inside (degrees only at the edges: files, reports,
//! plots); Y is up, a character faces +Z and its left is +X (right-handed).

pub mod analysis;
#[cfg(feature = "bevy")]
pub mod bevy;
pub mod bvh;
pub mod choreo;
pub mod clips;
pub mod cpu;
pub mod dynamics;
pub mod ecs;
#[cfg(feature = "editor")]
pub mod editor;
pub mod error;
pub mod evolve;
pub mod experiments;
pub mod humanoid;
pub mod io;
pub mod mapping;
pub mod prelude;
pub mod primitive;
#[cfg(feature = "render")]
pub mod render;
#[cfg(feature = "render")]
pub mod scene;
pub mod seed;
pub mod signal;
pub mod skeleton;

pub use error::{Error, Result};
