//! Fuzz target: the worker side of the JSON-lines evaluation protocol (`serve`) on arbitrary
//! input after a valid header. It may not panic or hang; a refusal names a request line
//! within the input; every batch it answers holds one reply per genome and a `done` line.
#![no_main]

use libfuzzer_sys::fuzz_target;
use marionette::evolve::{PROTOCOL, serve};

fuzz_target!(|data: &[u8]| {
    let mut input = format!("{{\"protocol\":\"{PROTOCOL}\",\"problem\":null}}\n").into_bytes();
    input.extend_from_slice(data);
    let mut out = Vec::new();
    let r = serve(&input[..], &mut out, |_: serde_json::Value| {
        Ok(|g: &[Vec<f64>], _: u32| {
            g.iter()
                .map(|x| {
                    let s: f64 = x.iter().sum();
                    if s.is_finite() {
                        Ok(s)
                    } else {
                        Err("not finite".into())
                    }
                })
                .collect()
        })
    });
    let out = String::from_utf8(out).expect("replies are UTF-8");
    for line in out.lines() {
        let v: serde_json::Value = serde_json::from_str(line).expect("each reply is JSON");
        let tag = v
            .as_object()
            .and_then(|o| o.keys().next())
            .cloned()
            .unwrap_or_default();
        assert!(
            ["damage", "error", "done"].contains(&tag.as_str()),
            "{line}"
        );
    }
    if let Err(e) = r {
        let e = e.to_string();
        if let Some(rest) = e.split("request line ").nth(1) {
            let n: usize = rest
                .split(|c: char| !c.is_ascii_digit())
                .next()
                .and_then(|d| d.parse().ok())
                .expect("a request line number");
            let lines = input.split(|&b| b == b'\n').count();
            assert!(n >= 1 && n <= lines, "line {n} of {lines}: {e}");
        }
    }
});
