//! The edit-scene file that `marionette edit` opens: the song (synthesized or a file), the
//! segment database (built with `marionette dance db`) and the pins (bar → segment), in RON:
//!
//! ```ron
//! EditScene(
//!     format_version: 1,
//!     song: Synth((bpm: 120.0, bars: 16)),   // or File("song.ogg")
//!     database: "dance.db.json",
//!     pins: {3: 12},                          // optional
//!     search: (rho: 0.5, candidates: 6, tau_decay: 0.95), // optional
//! )
//! ```
//!
//! Relative paths are relative to the scene file. Saving writes the scene back with its pins,
//! atomically (a temporary file renamed over the old one).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::EditorError;
use crate::choreo::fill::FillParams;
use crate::choreo::music::synth::SynthSong;
use crate::choreo::search::SearchParams;

/// The only edit-scene format version.
pub const EDIT_SCENE_VERSION: u32 = 1;

/// Where the song comes from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum SongSource {
    /// A drum track synthesized by [`crate::choreo::music::synth::synthesize`].
    Synth(SynthSong),
    /// A song file (WAV, OGG/Vorbis, MP3; needs the `audio` feature).
    File(PathBuf),
}

/// An edit scene (module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EditScene {
    /// [`EDIT_SCENE_VERSION`].
    pub format_version: u32,
    /// The song.
    pub song: SongSource,
    /// The segment database file.
    pub database: PathBuf,
    /// Pins: bar → segment index in the database.
    #[serde(default)]
    pub pins: BTreeMap<usize, usize>,
    /// The search parameters of eqs. (1)–(4).
    #[serde(default)]
    pub search: SearchParams,
    /// How unpinned bars are filled.
    #[serde(default)]
    pub fill: FillParams,
}

impl EditScene {
    /// Parses an edit scene; `name` labels errors (file, line and column).
    pub fn parse(text: &str, name: &str) -> Result<EditScene, EditorError> {
        let scene: EditScene = ron::from_str(text).map_err(|e| EditorError::Scene {
            path: name.to_string(),
            message: e.to_string(),
        })?;
        if scene.format_version != EDIT_SCENE_VERSION {
            return Err(EditorError::Scene {
                path: name.to_string(),
                message: format!(
                    "format_version {} is not supported (expected {EDIT_SCENE_VERSION})",
                    scene.format_version
                ),
            });
        }
        Ok(scene)
    }

    /// Reads and parses an edit-scene file.
    pub fn load(path: &Path) -> Result<EditScene, EditorError> {
        let text = std::fs::read_to_string(path).map_err(|e| EditorError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        EditScene::parse(&text, &path.display().to_string())
    }

    /// The scene as RON text (what [`EditScene::save`] writes).
    pub fn to_ron(&self) -> String {
        let cfg = ron::ser::PrettyConfig::new().depth_limit(3);
        // Plain data with string keys only: serialising cannot fail.
        ron::ser::to_string_pretty(self, cfg).unwrap_or_default() + "\n"
    }

    /// Writes the scene to `path` atomically.
    pub fn save(&self, path: &Path) -> Result<(), EditorError> {
        crate::io::write_atomic(path, self.to_ron().as_bytes()).map_err(|e| EditorError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })
    }
}

/// `p` relative to the folder of the scene file `scene`.
pub fn resolve(scene: &Path, p: &Path) -> PathBuf {
    if p.is_absolute() {
        p.to_path_buf()
    } else {
        scene.parent().unwrap_or(Path::new(".")).join(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_saves_and_reports_errors_with_position() {
        let s = EditScene::parse(
            "EditScene(format_version: 1, song: Synth((bpm: 100.0, bars: 8)), database: \"d.json\", pins: {2: 5})",
            "t.ron",
        )
        .unwrap();
        assert_eq!(s.pins, BTreeMap::from([(2, 5)]));
        let SongSource::Synth(song) = &s.song else {
            panic!("a synth song")
        };
        assert_eq!((song.bpm, song.bars), (100.0, 8));
        let back = EditScene::parse(&s.to_ron(), "back.ron").unwrap();
        assert_eq!(back, s);
        let e = EditScene::parse(
            "EditScene(format_version: 1,\n song: File(\"a.wav\"), database: \"d\", extra: 1)",
            "bad.ron",
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("bad.ron") && e.contains("2:") && e.contains("extra"),
            "{e}"
        );
        let e = EditScene::parse(
            "EditScene(format_version: 7, song: File(\"a.wav\"), database: \"d\")",
            "v.ron",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("format_version 7"), "{e}");
    }
}
