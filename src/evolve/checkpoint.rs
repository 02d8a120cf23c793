//! Checkpoints: the whole state of a run (settings, bounds, population, fitness, best, logbook,
//! failures; the random draws of a generation derive from the seed and the generation, so no
//! generator state is needed) written atomically as JSON, so a run killed at any moment loses at
//! most the generation in flight and `--resume` continues to the same bits.

use std::path::Path;

use super::evaluator::EvolveError;
use serde::Serialize;
use serde::de::DeserializeOwned;

/// The checkpoint file inside a run's folder.
pub const FILE: &str = "checkpoint.json";

/// Writes `states` (e.g. one GA state per age group and seed) to `dir/checkpoint.json`
/// atomically.
pub fn save<T: Serialize + ?Sized>(dir: &Path, states: &T) -> Result<(), EvolveError> {
    let path = dir.join(FILE);
    let err = |message: String| EvolveError::Checkpoint {
        path: path.display().to_string(),
        message,
    };
    let text = serde_json::to_string(states).map_err(|e| err(e.to_string()))?;
    std::fs::create_dir_all(dir).map_err(|e| err(e.to_string()))?;
    crate::io::write_atomic(&path, text.as_bytes()).map_err(|e| err(e.to_string()))
}

/// Reads the states saved in `dir`.
pub fn load<T: DeserializeOwned>(dir: &Path) -> Result<T, EvolveError> {
    let path = dir.join(FILE);
    let err = |message: String| EvolveError::Checkpoint {
        path: path.display().to_string(),
        message,
    };
    let text = std::fs::read_to_string(&path).map_err(|e| err(e.to_string()))?;
    serde_json::from_str(&text).map_err(|e| err(e.to_string()))
}
