//! The dance-segment database: every clip of a folder or a manifest mapped onto humanoid24 and
//! cut into bars ([`super::segments`]), saved as one compact JSON file that says what it was
//! built from (each source, its tempo and first beat and how they were found, its segment
//! count).
//!
//! A manifest (RON) lists clips, each with an optional tempo and first beat and an optional
//! time window:
//!
//! ```ron
//! (format_version: 1, clips: [
//!     (file: "dance_bars.ron", tempo_bpm: 120.0, first_beat_s: 0.0),
//!     (file: "salsa.bvh", window: (2.0, 30.0)),
//! ])
//! ```
//!
//! File names are relative to the manifest's folder; a clip without `tempo_bpm` gets the
//! kinematic beat (with `first_beat_s` kept when given).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::eros::eros_weights;
pub use super::segments::BuildParams;
use super::segments::{Beat, Segment, SegmentError, TempoSource, cut_segments, kinematic_beat};
use crate::humanoid::{ModelClip, humanoid24};

/// Newest manifest format this build reads.
pub const MANIFEST_VERSION: u32 = 1;

/// Newest database format this build reads and writes.
pub const DATABASE_VERSION: u32 = 1;

/// One clip of a manifest.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestClip {
    /// The clip (.bvh, or a keyframed .ron clip), relative to the manifest's folder.
    pub file: PathBuf,
    /// Its tempo, BPM, when known.
    #[serde(default)]
    pub tempo_bpm: Option<f64>,
    /// Its first beat from the start of the (windowed) clip, seconds, when known.
    #[serde(default)]
    pub first_beat_s: Option<f64>,
    /// The part of the clip to use, (start, end) seconds.
    #[serde(default)]
    pub window: Option<(f64, f64)>,
}

/// A manifest: the clips a database is built from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// Format version (1).
    pub format_version: u32,
    /// The clips.
    pub clips: Vec<ManifestClip>,
}

impl Manifest {
    /// Reads a manifest; file names in it become relative to its folder.
    pub fn load(path: &Path) -> Result<Manifest, SegmentError> {
        let origin = path.display().to_string();
        let load = |e: crate::Error| SegmentError::Load {
            path: origin.clone(),
            source: Box::new(e),
        };
        let text = crate::io::read_text(path).map_err(|e| load(e.into()))?;
        let mut m: Manifest = crate::io::parse_ron(&text, &origin).map_err(|e| load(e.into()))?;
        crate::io::check_version(&origin, m.format_version, MANIFEST_VERSION)
            .map_err(|e| load(e.into()))?;
        if m.clips.is_empty() {
            return Err(SegmentError::Manifest {
                path: origin,
                message: "the manifest lists no clips".into(),
            });
        }
        let dir = path.parent().unwrap_or(Path::new("."));
        for c in &mut m.clips {
            c.file = dir.join(&c.file);
        }
        Ok(m)
    }

    /// Every .bvh and keyframed .ron clip of a folder (sorted by name; .ron manifests skipped),
    /// with no tempo known.
    pub fn from_folder(dir: &Path) -> Result<Manifest, SegmentError> {
        let origin = dir.display().to_string();
        let entries = std::fs::read_dir(dir).map_err(|e| SegmentError::Load {
            path: origin.clone(),
            source: Box::new(e.into()),
        })?;
        let mut files: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                let ext = p
                    .extension()
                    .and_then(|e| e.to_str())
                    .map(str::to_lowercase);
                match ext.as_deref() {
                    Some("bvh") => true,
                    Some("ron") => !is_manifest(p),
                    _ => false,
                }
            })
            .collect();
        files.sort();
        if files.is_empty() {
            return Err(SegmentError::EmptyFolder { path: origin });
        }
        Ok(Manifest {
            format_version: MANIFEST_VERSION,
            clips: files
                .into_iter()
                .map(|file| ManifestClip {
                    file,
                    tempo_bpm: None,
                    first_beat_s: None,
                    window: None,
                })
                .collect(),
        })
    }

    /// A folder's clips, or a manifest's.
    pub fn from_path(path: &Path) -> Result<Manifest, SegmentError> {
        if path.is_dir() {
            Manifest::from_folder(path)
        } else {
            Manifest::load(path)
        }
    }
}

/// Whether a .ron file reads as a manifest.
fn is_manifest(p: &Path) -> bool {
    crate::io::read_text(p)
        .ok()
        .is_some_and(|t| crate::io::parse_ron::<Manifest>(&t, "").is_ok())
}

/// One manifest clip loaded, windowed, given its beat and cut into bars as the database's
/// clip `index`.
fn clip_segments(
    c: &ManifestClip,
    name: &str,
    index: usize,
    params: &BuildParams,
) -> Result<(Source, Vec<Segment>), SegmentError> {
    let mut clip = load_model_clip(&c.file)?;
    if let Some((a, b)) = c.window {
        clip = clip.window(a, b).ok_or_else(|| SegmentError::Manifest {
            path: name.to_string(),
            message: format!(
                "window {a:.3}..{b:.3} s holds no frame of the clip ({:.3} s)",
                clip.frame_count() as f64 * clip.frame_time
            ),
        })?;
    }
    let beat = match c.tempo_bpm {
        Some(tempo_bpm) => Beat {
            tempo_bpm,
            first_beat_s: c.first_beat_s.unwrap_or(0.0),
            source: TempoSource::Manifest,
        },
        None => {
            let mut b = kinematic_beat(&clip, name, params.music_bpm)?;
            if let Some(f) = c.first_beat_s {
                b.first_beat_s = f;
            }
            b
        }
    };
    let cut = cut_segments(&clip, name, index, &beat, params)?;
    let source = Source {
        file: name.to_string(),
        frames: clip.frame_count(),
        fps: 1.0 / clip.frame_time,
        window: c.window,
        beat,
        segments: cut.len(),
    };
    Ok((source, cut))
}

/// A clip on humanoid24: a BVH mapped with the detected mapping, retargeted and played on
/// humanoid24's own proportions with its root path scaled by the ratio of the leg lengths
/// ([`crate::mapping::onto_model`]), or a keyframed .ron clip; set on its floor ([`grounded`]).
pub fn load_model_clip(path: &Path) -> Result<ModelClip, SegmentError> {
    load_unground(path).map(grounded)
}

/// `clip` with its root moved vertically so that its floor is at y = 0: the floor is the one
/// [`crate::analysis::clip_contacts_with`] finds (the 2nd percentile over the clip of its
/// lowest foot point), so clips captured or mapped with their feet above or below y = 0 (a
/// mapped skeleton's feet are not the source's) stand on one floor when their bars are
/// joined. A clip without feet is returned as it is.
pub fn grounded(mut clip: ModelClip) -> ModelClip {
    let config = crate::analysis::ContactConfig::default();
    if let Some(c) = crate::analysis::clip_contacts_with(&clip.to_clip(), &config) {
        let floor = c.floor_y_m;
        if floor.is_finite() && floor != 0.0 {
            for t in &mut clip.root_translation {
                t.y -= floor;
            }
        }
    }
    clip
}

fn load_unground(path: &Path) -> Result<ModelClip, SegmentError> {
    let load = |e: crate::Error| SegmentError::Load {
        path: path.display().to_string(),
        source: Box::new(e),
    };
    let is_ron = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ron"));
    if is_ron {
        return crate::clips::KeyframeClip::load(path)
            .map(|k| k.to_model_clip())
            .map_err(|e| load(e.into()));
    }
    let (bvh, _warnings) = crate::bvh::parse_file(path).map_err(|e| load(e.into()))?;
    let clip = crate::skeleton::Clip::from_bvh(&bvh, None).map_err(|e| load(e.into()))?;
    let mapping = crate::mapping::Mapping::detect_clip(&clip).map_err(|e| load(e.into()))?;
    let model = humanoid24();
    let mapped = crate::mapping::retarget(&clip, &mapping, &model).map_err(|e| load(e.into()))?;
    // The source's angles on humanoid24 itself, the root path scaled with the legs, so that
    // every segment is measured and danced on the one figure it is played on.
    Ok(crate::mapping::onto_model(&mapped, &model))
}

/// What one source clip gave the database.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Source {
    /// The clip file as given.
    pub file: String,
    /// Frames used (after the window).
    pub frames: usize,
    /// Frames per second.
    pub fps: f64,
    /// The window used, (start, end) seconds, if any.
    pub window: Option<(f64, f64)>,
    /// Its tempo and first beat and how they were found.
    pub beat: Beat,
    /// Segments cut from it.
    pub segments: usize,
}

/// A clip the database was not built from, and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Skipped {
    /// The clip file as given.
    pub file: String,
    /// Why it was refused (the error, naming the file).
    pub reason: String,
}

/// What [`Database::build`] does with a clip it cannot use (unreadable, not mappable onto
/// humanoid24, no tempo found, shorter than a bar, a window outside it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OnRefusal {
    /// Skip it, record it in [`Database::skipped`] and go on; an error only when no clip is
    /// left.
    #[default]
    Skip,
    /// Fail with its error.
    Fail,
}

/// What happened to one clip of a build, for progress reports.
#[derive(Debug, Clone, Copy)]
pub enum ClipOutcome<'a> {
    /// The clip gave segments.
    Used(&'a Source),
    /// The clip was skipped ([`OnRefusal::Skip`]).
    Skipped(&'a Skipped),
}

/// The dance-segment database.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Database {
    /// Format version ([`DATABASE_VERSION`]).
    pub format_version: u32,
    /// The model the segments are on ("humanoid24").
    pub model: String,
    /// The parameters it was built with.
    pub params: BuildParams,
    /// The clips it was built from.
    pub sources: Vec<Source>,
    /// The clips of the manifest or folder it was not built from, and why (in their order).
    #[serde(default)]
    pub skipped: Vec<Skipped>,
    /// Every segment, clip by clip, bar by bar.
    pub segments: Vec<Segment>,
    /// Eros weights over all segments ([`eros_weights`]).
    pub eros_weights: Vec<f64>,
}

impl Database {
    /// Builds a database from a manifest's clips; a clip it cannot use is skipped or fails the
    /// build as `on_refusal` says, and with every clip skipped the build fails naming each and
    /// why ([`SegmentError::NoUsableClip`]). `progress` is called after each clip with its
    /// index in the manifest and what it gave.
    pub fn build(
        manifest: &Manifest,
        params: &BuildParams,
        on_refusal: OnRefusal,
        mut progress: impl FnMut(usize, ClipOutcome<'_>),
    ) -> Result<Database, SegmentError> {
        if params.bar_frames < 2 {
            return Err(SegmentError::Manifest {
                path: "build parameters".into(),
                message: format!("bar_frames must be at least 2, found {}", params.bar_frames),
            });
        }
        let mut sources = vec![];
        let mut skipped = vec![];
        let mut segments = vec![];
        for (i, c) in manifest.clips.iter().enumerate() {
            let name = c.file.display().to_string();
            match clip_segments(c, &name, sources.len(), params) {
                Ok((source, cut)) => {
                    progress(i, ClipOutcome::Used(&source));
                    sources.push(source);
                    segments.extend(cut);
                }
                Err(e) if on_refusal == OnRefusal::Skip => {
                    let s = Skipped {
                        file: name,
                        reason: e.to_string(),
                    };
                    progress(i, ClipOutcome::Skipped(&s));
                    skipped.push(s);
                }
                Err(e) => return Err(e),
            }
        }
        if sources.is_empty() {
            return Err(SegmentError::NoUsableClip { skipped });
        }
        let mut db = Database::of_segments(params, sources, segments);
        db.skipped = skipped;
        Ok(db)
    }

    /// A database from clips already on humanoid24 (e.g. the project's own dance, built in
    /// memory), each with its name and its beat when known (else the kinematic beat).
    pub fn from_clips(
        clips: &[(String, ModelClip, Option<Beat>)],
        params: &BuildParams,
    ) -> Result<Database, SegmentError> {
        if clips.is_empty() {
            return Err(SegmentError::Manifest {
                path: "clips".into(),
                message: "no clip to build a dance database from".into(),
            });
        }
        let mut sources = vec![];
        let mut segments = vec![];
        for (i, (name, clip, beat)) in clips.iter().enumerate() {
            let beat = match beat {
                Some(b) => *b,
                None => kinematic_beat(clip, name, params.music_bpm)?,
            };
            let cut = cut_segments(clip, name, i, &beat, params)?;
            sources.push(Source {
                file: name.clone(),
                frames: clip.frame_count(),
                fps: 1.0 / clip.frame_time,
                window: None,
                beat,
                segments: cut.len(),
            });
            segments.extend(cut);
        }
        Ok(Database::of_segments(params, sources, segments))
    }

    /// The database of `segments` cut from `sources`, with their Eros weights.
    fn of_segments(params: &BuildParams, sources: Vec<Source>, segments: Vec<Segment>) -> Database {
        let pcas: Vec<_> = segments.iter().map(|s| &s.eros).collect();
        let eros_weights = eros_weights(&pcas);
        Database {
            format_version: DATABASE_VERSION,
            model: "humanoid24".into(),
            params: params.clone(),
            sources,
            skipped: vec![],
            segments,
            eros_weights,
        }
    }

    /// The database as compact JSON.
    pub fn to_json(&self) -> Vec<u8> {
        serde_json::to_vec(self).expect("a database serialises")
    }

    /// Writes the database (compact JSON) atomically: nothing is left half-written.
    pub fn save(&self, path: &Path) -> Result<(), SegmentError> {
        crate::io::write_atomic(path, &self.to_json()).map_err(|e| SegmentError::Load {
            path: path.display().to_string(),
            source: Box::new(e.into()),
        })
    }

    /// Reads a database written by [`Database::save`].
    pub fn load(path: &Path) -> Result<Database, SegmentError> {
        let origin = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| SegmentError::Load {
            path: origin.clone(),
            source: Box::new(e.into()),
        })?;
        let db: Database = serde_json::from_slice(&bytes).map_err(|e| SegmentError::Database {
            path: origin.clone(),
            message: format!("line {} column {}: {e}", e.line(), e.column()),
        })?;
        if db.format_version == 0 || db.format_version > DATABASE_VERSION {
            return Err(SegmentError::Database {
                path: origin,
                message: format!(
                    "format_version {} is not one this build reads (1 to {DATABASE_VERSION})",
                    db.format_version
                ),
            });
        }
        Ok(db)
    }

    /// Segments cut from source clip `clip`.
    pub fn segments_of(&self, clip: usize) -> impl Iterator<Item = &Segment> {
        self.segments.iter().filter(move |s| s.clip == clip)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DQuat, DVec3};

    #[test]
    fn a_clip_is_set_on_its_floor_whatever_height_it_came_at() {
        let model = humanoid24();
        let d = model.dofs.len();
        let n = 60;
        for y in [0.3, 0.95, 2.0] {
            let clip = ModelClip {
                model: model.clone(),
                frame_time: 1.0 / 30.0,
                root_translation: vec![DVec3::new(0.5, y, -1.0); n],
                root_rotation: vec![DQuat::IDENTITY; n],
                angles: vec![0.0; n * d],
            };
            let g = grounded(clip);
            let c = g.to_clip();
            let feet: Vec<_> = crate::analysis::foot_points(&c.skeleton).concat();
            let lowest = crate::analysis::point_tracks(&c, &feet)[0]
                .iter()
                .map(|p| p.y)
                .fold(f64::INFINITY, f64::min);
            assert!(
                lowest.abs() < 1e-9,
                "from {y} m: lowest foot point at {lowest} m"
            );
            assert_eq!(g.root_translation[0].x, 0.5, "only the height moves");
        }
    }
}
