//! Fuzz target: `bvh::parse` must never panic; every error must name a line inside (or just
//! past) the input and lead its message with it; whatever it accepts must be valid and survive
//! a write → read round trip unchanged (same joints, frame time and motion values).
#![no_main]

use libfuzzer_sys::fuzz_target;
use marionette::bvh;

fuzz_target!(|data: &[u8]| {
    match bvh::parse(data) {
        Err(e) => {
            let line = e.line().expect("a parse error names its line");
            let lines = data.split(|&b| b == b'\n').count();
            assert!(line >= 1 && line <= lines + 1, "line {line} of {lines}: {e}");
            assert!(e.to_string().starts_with(&format!("line {line}")), "{e}");
        }
        Ok((parsed, _warnings)) => {
            parsed
                .validate()
                .expect("the reader returned data that fails Bvh::validate");
            let text = bvh::to_string(&parsed);
            let (again, warnings) =
                bvh::parse(text.as_bytes()).expect("the writer's output does not read back");
            assert!(warnings.is_empty(), "writer output gives warnings: {warnings:?}");
            assert_eq!(again, parsed, "write → read changed the data");
        }
    }
});
