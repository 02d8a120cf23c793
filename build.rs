//! Tells the tests whether the shared motion data is present: `cfg(shared_data)` when the data
//! folder exists (`$MARIONETTE_DATA`, else `../shared/data` from the package root, as
//! `marionette::io::data_dir` resolves it when the tests run) or when `CI` is set (there the
//! real-data tests must run, and fail when their files are absent). Without it the tests that
//! need the data are ignored with that reason, so `cargo test` shows them as skipped.
//!
//! The same for the outside tools some tests run, each present or under `CI` (where `.ci/run`
//! installs them and their tests must run): `cfg(tool_python)` for the project's Python
//! environment (`.venv/bin/python`, or `$MARIONETTE_PYTHON`), `cfg(tool_browser)` for Chromium
//! (`$CHROMIUM` or `/usr/bin/chromium`), Node and `tests/browser/node_modules`, and
//! `cfg(tool_fluidsynth)` for `fluidsynth` on the PATH with its General MIDI soundfont.

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
    tools(&package, ci);
}

/// The `cfg(tool_…)` of the outside tools present (module docs), each watched where it appears.
fn tools(package: &Path, ci: bool) {
    for name in ["tool_python", "tool_browser", "tool_fluidsynth"] {
        println!("cargo::rustc-check-cfg=cfg({name})");
    }
    for var in [
        "MARIONETTE_PYTHON",
        "CHROMIUM",
        "PATH",
        "MARIONETTE_SOUNDFONT",
    ] {
        println!("cargo::rerun-if-env-changed={var}");
    }
    let env_path = |var: &str| {
        std::env::var_os(var)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    let venv = package.join(".venv/bin/python");
    let python = env_path("MARIONETTE_PYTHON").is_some_and(|p| p.exists()) || venv.exists();
    let chromium = env_path("CHROMIUM").unwrap_or_else(|| PathBuf::from("/usr/bin/chromium"));
    let modules = package.join("tests/browser/node_modules/playwright-core/package.json");
    let browser = chromium.exists() && on_path("node") && modules.exists();
    let soundfont = env_path("MARIONETTE_SOUNDFONT")
        .unwrap_or_else(|| PathBuf::from("/usr/share/sounds/sf2/FluidR3_GM.sf2"));
    let fluidsynth = on_path("fluidsynth") && soundfont.exists();
    // Watch each marker, or where it will appear (never the package root itself: the build
    // writes into it, so watching it would re-run this script on every build).
    for marker in [&venv, &chromium, &modules, &soundfont] {
        let watch = if marker.exists() {
            Some(marker.as_path())
        } else {
            marker.ancestors().find(|a| a.exists() && *a != package)
        };
        if let Some(w) = watch.filter(|w| !package.starts_with(w)) {
            println!("cargo::rerun-if-changed={}", w.display());
        }
    }
    for (name, present) in [
        ("tool_python", python),
        ("tool_browser", browser),
        ("tool_fluidsynth", fluidsynth),
    ] {
        if present || ci {
            println!("cargo::rustc-cfg={name}");
        }
    }
}

/// Whether an executable file `name` is in one of the `PATH` folders.
fn on_path(name: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|d| d.join(name).is_file()))
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
