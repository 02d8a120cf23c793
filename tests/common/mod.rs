//! Shared by the integration tests: finding the shared motion-capture data.
//!
//! The data folder is [`marionette::io::data_dir`]: `$MARIONETTE_DATA`, else `../shared/data`
//! relative to the working directory. When the folder is absent, the tests that need it are
//! ignored with that reason (`build.rs` sets `cfg(shared_data)` when it is present, or under
//! CI); when a file a test needs is absent from a present folder, the test is skipped with a
//! `SKIPPED:` line on stderr, except under CI (`CI` set, e.g. `CI=true`), where the real-data
//! tests must run and the test fails instead.

#![allow(dead_code)] // each test file uses some of these

use std::io::Write;
use std::path::PathBuf;

/// `rel` inside the shared data folder (a file or a folder), or `None` after reporting that it
/// is absent; panics instead under CI.
pub fn data_path(rel: &str) -> Option<PathBuf> {
    let dir = marionette::io::data_dir();
    let path = if rel.is_empty() { dir } else { dir.join(rel) };
    if path.exists() {
        return Some(path);
    }
    let test = std::thread::current()
        .name()
        .unwrap_or("this test")
        .to_string();
    if in_ci() {
        panic!(
            "{test}: the shared motion data is absent ({} not found) and CI is set: the \
             real-data tests must run in CI; set MARIONETTE_DATA to the data folder",
            path.display()
        );
    }
    // Straight to stderr, past the test harness's output capture, so the skip is seen.
    let _ = writeln!(
        std::io::stderr(),
        "SKIPPED: {test}: needs the shared motion data, {} not found (set MARIONETTE_DATA)",
        path.display()
    );
    None
}

/// The shared data folder, or `None` after reporting that it is absent; panics instead under CI.
pub fn data_dir() -> Option<PathBuf> {
    data_path("")
}

/// Whether the tests run under CI: `CI` set to anything but empty, `0` or `false`.
pub fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !matches!(v.trim(), "" | "0" | "false" | "FALSE"))
}

/// A Python interpreter that can `import` every one of `modules` (the project's virtual
/// environment `.venv`, made by `.ci/run`, or `$MARIONETTE_PYTHON`), or `None` after reporting
/// that it is absent; panics instead under CI.
pub fn python_with(modules: &[&str]) -> Option<PathBuf> {
    let candidates: Vec<PathBuf> = std::env::var_os("MARIONETTE_PYTHON")
        .map(PathBuf::from)
        .into_iter()
        .chain(std::iter::once(
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(".venv/bin/python"),
        ))
        .collect();
    let import = format!("import {}", modules.join(", "));
    for py in &candidates {
        let ok = std::process::Command::new(py)
            .args(["-c", &import])
            .output()
            .is_ok_and(|o| o.status.success());
        if ok {
            return Some(py.clone());
        }
    }
    let test = std::thread::current()
        .name()
        .unwrap_or("this test")
        .to_string();
    let tried: Vec<String> = candidates.iter().map(|p| p.display().to_string()).collect();
    if in_ci() {
        panic!("{test}: no Python with {import:?} (tried {tried:?}); .ci/run makes .venv");
    }
    let _ = writeln!(
        std::io::stderr(),
        "SKIPPED: {test}: needs a Python with {import:?} (tried {tried:?}; run .ci/run or set MARIONETTE_PYTHON)"
    );
    None
}

/// Chromium and the Node modules of `tests/browser`, or `None` after saying what is missing.
pub fn browser() -> Option<PathBuf> {
    let chromium = std::env::var_os("CHROMIUM")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/bin/chromium"));
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/browser");
    let node = std::process::Command::new("node")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    let missing: Vec<String> = [
        (!chromium.exists()).then(|| format!("{} (apt-get install chromium)", chromium.display())),
        (!node).then(|| "node".to_string()),
        (!dir.join("node_modules/playwright-core").exists())
            .then(|| "tests/browser/node_modules (npm ci in tests/browser)".to_string()),
    ]
    .into_iter()
    .flatten()
    .collect();
    if missing.is_empty() {
        return Some(chromium);
    }
    let test = std::thread::current()
        .name()
        .unwrap_or("this test")
        .to_string();
    if in_ci() {
        panic!("{test}: missing {missing:?}; .ci/run installs them");
    }
    let _ = writeln!(
        std::io::stderr(),
        "SKIPPED: {test}: needs {} (run .ci/run)",
        missing.join(", ")
    );
    None
}
