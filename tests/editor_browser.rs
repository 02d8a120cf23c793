//! The dance editor end to end in a real browser: `marionette edit` on a database built here
//! from generated clips, and `tests/browser/editor.mjs` driving headless Chromium through
//! playwright-core — click a bar, six animated candidates drawn, like two, Search gives six new
//! ones, Set, Generate, play, next bar by key, save, export — then the server's state, the
//! saved scene and the exported BVH checked here. Screenshots go to
//! `target/editor-browser/`. Needs `/usr/bin/chromium` (or `$CHROMIUM`) and `npm ci` in
//! `tests/browser`: skipped with a SKIPPED line when absent, a failure under CI.

mod common;
mod editor_fixture;

use std::io::{BufRead, BufReader, Write};
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use editor_fixture::{assert_bvh_lasts_the_bars, get, scene};
use marionette::editor::scene::EditScene;

/// Chromium and the Node modules of `tests/browser`, or `None` after saying what is missing.
fn browser() -> Option<PathBuf> {
    let chromium = std::env::var_os("CHROMIUM")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/bin/chromium"));
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/browser");
    let node = Command::new("node")
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
    if common::in_ci() {
        panic!("{test}: missing {missing:?}; .ci/run installs them");
    }
    let _ = writeln!(
        std::io::stderr(),
        "SKIPPED: {test}: needs {} (run .ci/run)",
        missing.join(", ")
    );
    None
}

#[test]
fn the_page_searches_sets_generates_plays_saves_and_exports_in_chromium() {
    let Some(chromium) = browser() else { return };
    let path = scene("browser", 8, 10, 16);
    let mut child = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["edit", path.to_str().unwrap(), "--port", "0"])
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let url = line
        .trim()
        .strip_prefix("dance editor: ")
        .unwrap_or_else(|| panic!("no URL printed: {line:?}"))
        .to_string();
    let addr: SocketAddr = url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .parse()
        .unwrap();
    assert!(addr.ip().is_loopback());

    let shots = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/editor-browser");
    std::fs::create_dir_all(&shots).unwrap();
    let out = Command::new("node")
        .arg("editor.mjs")
        .arg(&url)
        .arg(&shots)
        .env("CHROMIUM", &chromium)
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/browser"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    if !out.status.success() {
        let _ = child.kill();
        panic!("the browser script failed:\n{stdout}\n{stderr}");
    }
    println!("{stdout}");
    let seen: serde_json::Value =
        serde_json::from_str(stdout.trim().lines().last().unwrap()).unwrap();

    // What the page did, as the server has it.
    let ids = |k: &str| -> Vec<u64> {
        seen[k]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_u64().unwrap())
            .collect()
    };
    let (first, second, liked) = (ids("first"), ids("second"), ids("liked"));
    assert_eq!((first.len(), second.len()), (6, 6));
    assert!(second.iter().all(|s| !first.contains(s)));
    let c = get(addr, "/api/candidates?bar=2");
    assert_eq!(c["round"], 2);
    assert_eq!(c["liked"].as_array().unwrap().len(), 2);
    assert!(
        liked
            .iter()
            .all(|s| c["liked"].as_array().unwrap().contains(&(*s).into()))
    );
    let pinned = seen["pinned"].as_u64().unwrap();
    let state = get(addr, "/api/state");
    assert_eq!(state["pins"], serde_json::json!({ "2": pinned }));
    let fill = state["fill"]["segments"].as_array().unwrap();
    assert_eq!(fill.len(), 16, "every bar filled");
    assert_eq!(fill[2], pinned, "the pin holds");
    let segments = state["segments"].as_u64().unwrap();
    assert!(fill.iter().all(|s| s.as_u64().unwrap() < segments));

    // The saved scene has the pin; the exported BVH lasts the 16 bars at 30 fps.
    let back = EditScene::load(&path).unwrap();
    assert_eq!(
        back.pins,
        std::collections::BTreeMap::from([(2, pinned as usize)])
    );
    let bvh = std::fs::read_to_string(seen["bvh"].as_str().unwrap()).unwrap();
    assert_bvh_lasts_the_bars(addr, &bvh);
    let _ = child.kill();
    let _ = child.wait();
}
