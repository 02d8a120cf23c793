//! Motor primitives: learning, adjusting, connecting, blending, events, RON, the ECS, the
//! experiments and scenes, and the keyframed jumps' ballistic flights.
//!
//! One test binary (`cargo test --release --test primitive NAME`), a module per file; a
//! module that needs a feature (`render`, `audio`, or `cli` for the `marionette` binary) is
//! built with it.

#[path = "../common/mod.rs"]
mod common;

mod adjust;
mod blend;
mod clips_ballistic;
mod connect;
mod ecs;
mod events;
mod experiments;
mod learn;
mod ron;
#[cfg(feature = "render")]
mod scenes;
