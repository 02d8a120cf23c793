//! The `marionette` command and what it writes: the commands, scene outputs, the results page in a
//! browser, the pictures.
//!
//! One test binary (`cargo test --release --test cli NAME`), a module per file; a
//! module that needs a feature (`render`, `audio`, or `cli` for the `marionette` binary) is
//! built with it.

#[path = "../common/mod.rs"]
mod common;

#[cfg(feature = "cli")]
mod cli;
#[cfg(feature = "render")]
mod render_pictures;
#[cfg(feature = "cli")]
mod results_page;
mod scene_outputs;
