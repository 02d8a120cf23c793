//! The choreography database's errors: why a clip could not be cut into segments or a
//! database built, and a clip the database was not built from.

use serde::{Deserialize, Serialize};

/// Why a clip could not be cut into segments or a database built.
#[derive(Debug, thiserror::Error)]
pub enum SegmentError {
    /// A clip shorter than one bar after its first beat.
    #[error(
        "{clip}: the clip lasts {duration_s:.3} s after its first beat at {first_beat_s:.3} s, \
         shorter than one bar of {counts} counts ({bar_s:.3} s at {tempo_bpm:.2} BPM)"
    )]
    TooShort {
        /// The clip.
        clip: String,
        /// Its duration, seconds.
        duration_s: f64,
        /// Its first beat, seconds.
        first_beat_s: f64,
        /// The bar length, seconds.
        bar_s: f64,
        /// Its counts (beats).
        counts: usize,
        /// The tempo, BPM.
        tempo_bpm: f64,
    },
    /// A tempo or first beat that is not usable (given in a manifest, or not found in the motion).
    #[error("{clip}: {message}")]
    Tempo {
        /// The clip.
        clip: String,
        /// What was wrong.
        message: String,
    },
    /// A folder with no clip in it.
    #[error("{path}: no dance clip in the folder (expected .bvh or keyframed .ron clips)")]
    EmptyFolder {
        /// The folder.
        path: String,
    },
    /// A clip or manifest that could not be read, parsed or mapped onto humanoid24 (the file
    /// named once: the reason's own text when it names it already).
    #[error("{}", name_once(path, source))]
    Load {
        /// The file.
        path: String,
        /// Why.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// A manifest whose content is inconsistent.
    #[error("{path}: {message}")]
    Manifest {
        /// The manifest.
        path: String,
        /// What was wrong.
        message: String,
    },
    /// A folder or manifest none of whose clips could be used: each clip and why.
    #[error(
        "no clip could be used ({} refused):{}",
        skipped.len(),
        skipped.iter().map(|s| format!("\n  {}", s.reason)).collect::<String>()
    )]
    NoUsableClip {
        /// Every clip and why it was refused.
        skipped: Vec<Skipped>,
    },
    /// A database whose content is inconsistent or not for this build: a segment naming a
    /// missing source, another model, lengths that disagree, a number that is not finite.
    #[error("{path}: {message}")]
    InvalidDatabase {
        /// The file (or "database" when it is not yet written).
        path: String,
        /// What is wrong, naming the segment or source.
        message: String,
    },
    /// A database file that could not be read or is not a database.
    #[error("{path}: not a dance database: {message}")]
    Database {
        /// The file.
        path: String,
        /// What was wrong (with line and column for JSON errors).
        message: String,
    },
}

/// `source`'s text, preceded by `path` unless it names it already.
fn name_once(path: &str, source: &impl std::fmt::Display) -> String {
    let s = source.to_string();
    if s.contains(path) {
        s
    } else {
        format!("{path}: {s}")
    }
}

/// A clip the database was not built from, and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Skipped {
    /// The clip file as given.
    pub file: String,
    /// Why it was refused (the error, naming the file).
    pub reason: String,
}
