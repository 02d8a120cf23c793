//! Tells the tests whether the shared motion data is present: `cfg(shared_data)` when the data
//! folder exists (`$MARIONETTE_DATA`, else `../shared/data` from the package root, as
//! `marionette::io::data_dir` resolves it when the tests run) or when `CI` is set (there the
//! real-data tests must run, and fail when their files are absent). Without it the tests that
//! need the data are ignored with that reason, so `cargo test` shows them as skipped.

use std::path::PathBuf;

fn main() {
    println!("cargo::rustc-check-cfg=cfg(shared_data)");
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rerun-if-env-changed=MARIONETTE_DATA");
    println!("cargo::rerun-if-env-changed=CI");
    let dir = match std::env::var_os("MARIONETTE_DATA") {
        Some(d) if !d.is_empty() => PathBuf::from(d),
        _ => PathBuf::from("../shared/data"),
    };
    // Re-run when the folder appears or changes (a missing path re-runs every build).
    println!("cargo::rerun-if-changed={}", dir.display());
    let ci = std::env::var("CI").is_ok_and(|v| !matches!(v.trim(), "" | "0" | "false" | "FALSE"));
    if dir.is_dir() || ci {
        println!("cargo::rustc-cfg=shared_data");
    }
}
