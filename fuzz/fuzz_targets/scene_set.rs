//! Fuzz target: the RON scene reader and `--set` overrides. The input is scene text, then
//! after a NUL byte one override per line. Neither may panic; a refusal names its place (a
//! RON error a line and column inside the text or just past it, an override error its
//! assignment); a scene read and overridden is validated without panicking.
#![no_main]

use libfuzzer_sys::fuzz_target;
use marionette::scene::{Scene, SceneError, apply_overrides, validate};

fuzz_target!(|data: &[u8]| {
    let Ok(data) = std::str::from_utf8(data) else {
        return;
    };
    let (text, sets) = data.split_once('\0').unwrap_or((data, ""));
    let sets: Vec<String> = sets.lines().map(str::to_string).collect();
    let scene = match Scene::parse(text, "fuzz.ron") {
        Ok(s) => s,
        Err(SceneError::Ron(e)) => {
            let lines = text.split('\n').count();
            assert!(
                e.line >= 1 && e.line <= lines + 1,
                "line {} of {lines}: {e}",
                e.line
            );
            assert!(e.to_string().starts_with("fuzz.ron:"), "{e}");
            return;
        }
        Err(e) => {
            assert!(!e.to_string().is_empty());
            return;
        }
    };
    let _ = validate(&scene);
    match apply_overrides(&scene, &sets) {
        Ok(s) => {
            let _ = validate(&s);
        }
        Err(SceneError::Override {
            assignment,
            message,
        }) => {
            assert!(
                sets.contains(&assignment),
                "{assignment:?} is not one of {sets:?}"
            );
            assert!(!message.is_empty());
        }
        Err(e) => assert!(!e.to_string().is_empty()),
    }
});
