//! The dance editor: its server over TCP and its page in headless Chromium.
//!
//! One test binary (`cargo test --release --test editor NAME`), a module per file; a
//! module that needs a feature (`render`, `audio`, or `cli` for the `marionette` binary) is
//! built with it.

#[path = "../common/mod.rs"]
mod common;
#[cfg(feature = "cli")]
mod fixture;

#[cfg(feature = "cli")]
mod browser;
#[cfg(feature = "cli")]
mod server;
