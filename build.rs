//! Tells the tests whether the shared motion data is present: `cfg(shared_data)` when the data
//! folder exists (`$MARIONETTE_DATA`, else `../shared/data` from the package root, as
//! `marionette::io::data_dir` resolves it when the tests run) or when `CI` is set (there the
//! real-data tests must run, and fail when their files are absent). Without it the tests that
//! need the data are ignored with that reason, so `cargo test` shows them as skipped.

use std::path::{Component, Path, PathBuf};

fn main() {
    println!("cargo::rustc-check-cfg=cfg(shared_data)");
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rerun-if-env-changed=MARIONETTE_DATA");
    println!("cargo::rerun-if-env-changed=CI");
    let dir = match std::env::var_os("MARIONETTE_DATA") {
        Some(d) if !d.is_empty() => PathBuf::from(d),
        _ => PathBuf::from("../shared/data"),
    };
    // Re-run when the folder changes, or when it appears: watch its nearest existing ancestor,
    // unless that holds the package itself (a missing path, or a folder the build writes into,
    // would re-run the script, and so recompile the crate, on every build).
    let package = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default());
    let absolute = normalised(&package.join(&dir));
    if let Some(watch) = absolute.ancestors().find(|a| a.exists())
        && !package.starts_with(watch)
    {
        println!("cargo::rerun-if-changed={}", watch.display());
    }
    let ci = std::env::var("CI").is_ok_and(|v| !matches!(v.trim(), "" | "0" | "false" | "FALSE"));
    if dir.is_dir() || ci {
        println!("cargo::rustc-cfg=shared_data");
    }
}

/// `p` with its `.` and `..` components resolved lexically.
fn normalised(p: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out
}
