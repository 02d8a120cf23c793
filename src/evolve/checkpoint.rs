//! Checkpoints: the whole state of a run (settings, bounds, population, fitness, best, logbook,
//! failures; the random draws of a generation derive from the seed and the generation, so no
//! generator state is needed) written atomically as JSON after every generation by default
//! (`checkpoint_every`), so a run killed at any moment loses at most the generation in flight
//! (with `checkpoint_every: K`, at most the K − 1 generations since the last checkpoint and the
//! one in flight) and `--resume` continues to the same bits.
//!
//! The file is `{"format_version": 2, "checksum": "fnv1a64:…", "content": …}`: the checksum is
//! the 64-bit FNV-1a hash of the content's bytes as written, so a file cut short, edited by
//! hand or of another format version is refused before anything resumes. The content is then
//! held to a whole-state consistency check ([`Consistent`]: list lengths, genes within their
//! bounds, finite non-negative damages, generation numbers in step), and a state that fails it
//! is refused on writing as on reading. Every file written is read back before it replaces the
//! previous one: a number the reader would not give back bit for bit is refused, never written.

use std::path::Path;

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use serde_json::value::RawValue;

use super::error::{CheckpointError, EvolveError};
pub use super::formats::FORMAT_VERSION;

/// The checkpoint file inside a run's folder.
pub const FILE: &str = "checkpoint.json";

/// A state a checkpoint may hold: it says what in it disagrees.
pub trait Consistent {
    /// `Err(what disagrees)`, naming the run it is in.
    fn consistency(&self) -> Result<(), String>;
}

/// The 64-bit FNV-1a hash of `bytes` as the checkpoint writes it, `fnv1a64:` and 16 hex digits.
pub fn checksum(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("fnv1a64:{h:016x}")
}

/// The text of a checkpoint file holding `content`: the format version, the checksum and the
/// content. No check of consistency: [`save`] makes it first.
pub fn encode<T: Serialize + ?Sized>(content: &T) -> Result<String, String> {
    let text = serde_json::to_string(content).map_err(|e| e.to_string())?;
    Ok(format!(
        "{{\"format_version\":{FORMAT_VERSION},\"checksum\":\"{}\",\"content\":{text}}}",
        checksum(text.as_bytes())
    ))
}

/// The envelope of a checkpoint file, its content unparsed.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Envelope<'a> {
    format_version: u32,
    checksum: String,
    #[serde(borrow)]
    content: &'a RawValue,
}

/// The content of a checkpoint file's text, its version, checksum and consistency checked.
pub fn decode<T: DeserializeOwned + Consistent>(text: &str) -> Result<T, CheckpointError> {
    let envelope: Envelope = serde_json::from_str(text).map_err(|e| {
        if text.trim_start().starts_with('[') {
            CheckpointError::Version1
        } else {
            CheckpointError::NotACheckpoint(e)
        }
    })?;
    if envelope.format_version != FORMAT_VERSION {
        return Err(CheckpointError::FormatVersion(envelope.format_version));
    }
    let content = envelope.content.get();
    let computed = checksum(content.as_bytes());
    if computed != envelope.checksum {
        return Err(CheckpointError::Checksum {
            computed,
            stated: envelope.checksum,
        });
    }
    let state: T = serde_json::from_str(content).map_err(CheckpointError::Content)?;
    state.consistency().map_err(CheckpointError::Inconsistent)?;
    Ok(state)
}

/// Writes `states` (e.g. one GA state per age group and seed) to `dir/checkpoint.json`
/// atomically, after checking their consistency and that the file reads back to the same
/// content bit for bit.
pub fn save<T>(dir: &Path, states: &T) -> Result<(), EvolveError>
where
    T: Serialize + Consistent + ToOwned + ?Sized,
    T::Owned: Serialize + DeserializeOwned + Consistent,
{
    let path = dir.join(FILE);
    written(dir, states).map_err(|why| EvolveError::Checkpoint { path, why })
}

/// [`save`], its error without the path.
fn written<T>(dir: &Path, states: &T) -> Result<(), CheckpointError>
where
    T: Serialize + Consistent + ToOwned + ?Sized,
    T::Owned: Serialize + DeserializeOwned + Consistent,
{
    states
        .consistency()
        .map_err(CheckpointError::InconsistentState)?;
    let text = encode(states).map_err(CheckpointError::Encode)?;
    let back: T::Owned = decode(&text).map_err(|e| CheckpointError::Unreadable(Box::new(e)))?;
    if encode(&back).map_err(CheckpointError::Encode)? != text {
        return Err(CheckpointError::NotBitExact);
    }
    std::fs::create_dir_all(dir).map_err(CheckpointError::Io)?;
    crate::io::write_atomic(&dir.join(FILE), text.as_bytes()).map_err(CheckpointError::Io)
}

/// Reads the states saved in `dir`: refused, naming the file and what is wrong, unless the
/// format version and checksum match and the states are consistent.
pub fn load<T: DeserializeOwned + Consistent>(dir: &Path) -> Result<T, EvolveError> {
    let path = dir.join(FILE);
    std::fs::read_to_string(&path)
        .map_err(CheckpointError::Io)
        .and_then(|text| decode(&text))
        .map_err(|why| EvolveError::Checkpoint { path, why })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A state that is consistent when its numbers are in ascending order.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    struct Rising(Vec<f64>);

    impl Consistent for Rising {
        fn consistency(&self) -> Result<(), String> {
            match self
                .0
                .windows(2)
                .position(|w| w[0].partial_cmp(&w[1]) != Some(std::cmp::Ordering::Less))
            {
                Some(k) => Err(format!("entry {} does not rise", k + 1)),
                None => Ok(()),
            }
        }
    }

    #[test]
    fn a_checkpoint_reads_back_and_refuses_a_changed_cut_foreign_or_inconsistent_file() {
        let good = encode(&Rising(vec![0.1, 2.5, 1e300])).unwrap();
        assert_eq!(
            decode::<Rising>(&good).unwrap(),
            Rising(vec![0.1, 2.5, 1e300])
        );
        // A number changed by hand: the checksum no longer holds.
        let edited = good.replace("2.5", "2.4");
        assert!(
            decode::<Rising>(&edited)
                .unwrap_err()
                .to_string()
                .contains("checksum")
        );
        // Cut short.
        let cut = &good[..good.len() - 3];
        assert!(
            decode::<Rising>(cut)
                .unwrap_err()
                .to_string()
                .contains("not a checkpoint")
        );
        // Another format version, and the bare state of version 1.
        let v3 = good.replace("\"format_version\":2", "\"format_version\":3");
        assert!(
            decode::<Rising>(&v3)
                .unwrap_err()
                .to_string()
                .contains("format version 3")
        );
        let v1 = serde_json::to_string(&vec![Rising(vec![1.0])]).unwrap();
        assert!(
            decode::<Rising>(&v1)
                .unwrap_err()
                .to_string()
                .contains("format version 1")
        );
        // Sealed right but inconsistent: refused by what disagrees; never written.
        let falling = encode(&Rising(vec![3.0, 1.0])).unwrap();
        assert_eq!(
            decode::<Rising>(&falling).unwrap_err().to_string(),
            "entry 1 does not rise"
        );
        let dir = std::env::temp_dir().join(format!("marionette-ck-unit-{}", std::process::id()));
        let err = save(&dir, &Rising(vec![3.0, 1.0])).unwrap_err().to_string();
        assert!(
            err.contains("checkpoint.json") && err.contains("inconsistent"),
            "{err}"
        );
        assert!(!dir.join(FILE).exists());
        // A number JSON cannot hold is refused before writing, never written as null.
        let err = save(&dir, &Rising(vec![1.0, f64::INFINITY]))
            .unwrap_err()
            .to_string();
        assert!(err.contains("not written"), "{err}");
        assert!(!dir.join(FILE).exists());
        save(&dir, &Rising(vec![1.0, 2.0])).unwrap();
        assert_eq!(load::<Rising>(&dir).unwrap(), Rising(vec![1.0, 2.0]));
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn fnv1a_of_known_strings() {
        // The reference values of the FNV-1a 64-bit hash (Fowler, Noll, Vo).
        assert_eq!(checksum(b""), "fnv1a64:cbf29ce484222325");
        assert_eq!(checksum(b"a"), "fnv1a64:af63dc4c8601ec8c");
        assert_eq!(checksum(b"foobar"), "fnv1a64:85944171f73967e8");
    }
}
