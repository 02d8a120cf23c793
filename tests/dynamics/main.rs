//! Rigid-body dynamics: the algorithms, contact, integration, lanes, the ECS step and a user's
//! schedule, and the body cross-checked by Pinocchio and MuJoCo.
//!
//! One test binary (`cargo test --release --test dynamics NAME`), a module per file; a
//! module that needs a feature (`render`, `audio`, or `cli` for the `marionette` binary) is
//! built with it.

#[path = "../common/mod.rs"]
mod common;

mod algorithms;
mod body_cross_check;
mod contact;
mod ecs;
#[cfg(feature = "render")]
mod ecs_user_schedule;
mod fall;
mod implicit;
mod integration;
mod lanes;
