//! Pushed falls: the Fall scene, the credibility of the fall, and the active (physical) character
//! that is pushed and falls.
//!
//! One test binary (`cargo test --release --test fall NAME`), a module per file; a
//! module that needs a feature (`render`, `audio`, or `cli` for the `marionette` binary) is
//! built with it.

#[path = "../common/mod.rs"]
mod common;

mod active_character;
#[cfg(feature = "render")]
mod active_scene;
mod credible;
#[cfg(feature = "render")]
mod scene;
