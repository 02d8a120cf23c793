//! Where a scene's motion comes from: a BVH file or a keyframed clip, with an optional time
//! window, mapped onto a model when asked.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::SceneError;
use crate::bvh::{self, Bvh};
use crate::clips::KeyframeClip;
use crate::humanoid::{Figure, FigureClip};
use crate::mapping::{Mapping, retarget};
use crate::skeleton::Clip;

pub use crate::io::data_dir;

/// A clip in a scene: a file (`.bvh`, or `.ron` for a keyframed clip), optionally a window of
/// it, the unit scale of a BVH (metres per file unit; estimated when absent) and the mapping
/// file for its skeleton (detected among the built-ins when absent). Paths are relative to the
/// scene file and may use `${MARIONETTE_DATA}`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClipSource {
    /// The motion file.
    pub file: String,
    /// Start of the window, seconds.
    #[serde(default)]
    pub start_s: Option<f64>,
    /// End of the window, seconds.
    #[serde(default)]
    pub end_s: Option<f64>,
    /// Metres per file unit of a BVH.
    #[serde(default)]
    pub unit_scale: Option<f64>,
    /// Mapping file (RON) of the BVH's skeleton.
    #[serde(default)]
    pub mapping: Option<String>,
}

/// Expands `${MARIONETTE_DATA}` (see [`data_dir`]) and resolves `path` relative to `base` (the
/// scene's folder).
pub fn resolve_path(path: &str, base: &Path) -> PathBuf {
    let expanded = path.replace("${MARIONETTE_DATA}", &data_dir().to_string_lossy());
    let p = PathBuf::from(expanded);
    if p.is_absolute() { p } else { base.join(p) }
}

/// A loaded motion: the clip on its own skeleton, and where it came from.
#[derive(Clone, Debug)]
pub enum LoadedMotion {
    /// From a BVH file.
    Captured {
        /// The file's content.
        bvh: Box<Bvh>,
        /// The (windowed) clip in metres.
        clip: Clip,
        /// Its mapping onto the models: the scene's mapping file, else the built-in one detected
        /// from the joint names; `None` when none fits (the clip is still drawn as it is;
        /// mapping it onto a model says why it cannot).
        mapping: Option<Box<Mapping>>,
    },
    /// A keyframed clip, already on its model.
    Keyframed(FigureClip),
}

impl LoadedMotion {
    /// The motion on its own skeleton.
    pub fn clip(&self) -> Clip {
        match self {
            LoadedMotion::Captured { clip, .. } => clip.clone(),
            LoadedMotion::Keyframed(m) => m.to_clip(),
        }
    }

    /// The motion on `model` (retargeted from a capture; a keyframed clip must already be on it).
    pub fn on_figure(&self, model: &Figure) -> Result<FigureClip, SceneError> {
        match self {
            LoadedMotion::Captured {
                clip,
                mapping: Some(mapping),
                ..
            } => Ok(retarget(clip, mapping, model)?),
            // Detecting again gives the reason no built-in mapping fits.
            LoadedMotion::Captured { clip, .. } => {
                Ok(retarget(clip, &Mapping::detect(&clip.skeleton)?, model)?)
            }
            LoadedMotion::Keyframed(m) if m.model.name == model.name => Ok(m.clone()),
            LoadedMotion::Keyframed(m) => Err(SceneError::ClipModel {
                clip: m.model.name.clone(),
                model: model.name.clone(),
            }),
        }
    }
}

/// Loads a motion file (BVH or keyframed RON) with an optional window.
pub fn load_motion(src: &ClipSource, base: &Path) -> Result<LoadedMotion, SceneError> {
    let path = resolve_path(&src.file, base);
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let window =
        |len: f64| -> (f64, f64) { (src.start_s.unwrap_or(0.0), src.end_s.unwrap_or(len)) };
    match ext.as_str() {
        "bvh" => {
            let (bvh, warnings) = bvh::parse_file(&path)?;
            for w in warnings {
                eprintln!("warning: {}:{}: {}", path.display(), w.line, w.message);
            }
            let mut clip =
                Clip::from_bvh(&bvh, src.unit_scale).map_err(|source| SceneError::BvhClip {
                    path: path.to_path_buf(),
                    source,
                })?;
            if src.start_s.is_some() || src.end_s.is_some() {
                let (a, b) = window(clip.duration());
                clip = clip.window(a, b).map_err(|source| SceneError::ClipWindow {
                    path: path.to_path_buf(),
                    source,
                })?;
            }
            let mapping = match &src.mapping {
                Some(m) => Some(Mapping::load(&resolve_path(m, base))?),
                None => Mapping::detect_clip(&clip).ok(),
            };
            Ok(LoadedMotion::Captured {
                bvh: Box::new(bvh),
                clip,
                mapping: mapping.map(Box::new),
            })
        }
        "ron" => {
            let k = KeyframeClip::load(&path)?;
            let mut m = k.to_figure_clip();
            if src.start_s.is_some() || src.end_s.is_some() {
                let span = m.frame_count() as f64 * m.frame_time;
                let (a, b) = window(span);
                let inside = a.is_finite()
                    && b.is_finite()
                    && a >= 0.0
                    && a < b
                    && b <= span + 0.5 * m.frame_time;
                let windowed = if inside { m.window(a, b) } else { None };
                m = windowed.ok_or_else(|| SceneError::KeyframeWindow {
                    path: path.to_path_buf(),
                    start_s: a,
                    end_s: b,
                    span_s: span,
                })?;
            }
            Ok(LoadedMotion::Keyframed(m))
        }
        _ => Err(SceneError::MotionFormat(path.to_path_buf())),
    }
}
