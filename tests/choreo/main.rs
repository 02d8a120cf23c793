//! Choreography: music analysis (synthetic and the POP909 songs), segments, search, fill, the dance
//! scene and its commands.
//!
//! One test binary (`cargo test --release --test choreo NAME`), a module per file; a
//! module that needs a feature (`render`, `audio`, or `cli` for the `marionette` binary) is
//! built with it.

#[path = "../common/mod.rs"]
mod common;
#[path = "../common/dance_clips.rs"]
mod dance_clips;
#[path = "../common/pop909.rs"]
mod pop909;

#[cfg(feature = "cli")]
mod cli;
#[cfg(all(feature = "render", feature = "audio"))]
mod dance;
mod features;
mod fill;
mod music;
mod music_real_songs;
#[cfg(all(feature = "render", feature = "audio"))]
mod real_dance;
mod search;
mod segments;
