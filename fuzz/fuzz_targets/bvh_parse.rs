//! Fuzz target: `bvh::parse` must never panic, and whatever it accepts must survive a
//! write → read round trip unchanged (same joints, frame time and motion values).
#![no_main]

use libfuzzer_sys::fuzz_target;
use marionette::bvh;

fuzz_target!(|data: &[u8]| {
    if let Ok((parsed, _warnings)) = bvh::parse(data) {
        parsed
            .validate()
            .expect("the reader returned data that fails Bvh::validate");
        let text = bvh::to_string(&parsed);
        let (again, warnings) =
            bvh::parse(text.as_bytes()).expect("the writer's output does not read back");
        assert!(warnings.is_empty(), "writer output gives warnings: {warnings:?}");
        assert_eq!(again, parsed, "write → read changed the data");
    }
});
