//! Fuzz target: the checkpoint reader. The input is read as a whole checkpoint file, and
//! again as the content of one sealed with a matching checksum (so the fuzzer reaches the
//! state checks). Neither may panic; a state accepted is consistent and encodes to a file
//! that decodes to the same state.
#![no_main]

use libfuzzer_sys::fuzz_target;
use marionette::evolve::checkpoint::{Consistent, checksum, decode, encode};
use marionette::experiments::evolve_fall::EvolutionRun;

fn check(text: &str) {
    if let Ok(runs) = decode::<Vec<EvolutionRun>>(text) {
        runs.consistency().expect("a checkpoint read is consistent");
        let file = encode(&runs).expect("a state read encodes");
        let again: Vec<EvolutionRun> = decode(&file).expect("an encoded state decodes");
        assert_eq!(
            serde_json::to_string(&again).unwrap(),
            serde_json::to_string(&runs).unwrap()
        );
    }
}

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    check(text);
    let sealed = format!(
        "{{\"format_version\":2,\"checksum\":\"{}\",\"content\":{text}}}",
        checksum(text.as_bytes())
    );
    check(&sealed);
});
