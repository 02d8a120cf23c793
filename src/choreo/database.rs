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
pub use super::error::Skipped;
pub use super::segments::BuildParams;
use super::segments::{
    Beat, Segment, SegmentError, TempoSource, check_tempo, cut_segments, kinematic_beat,
};
use crate::humanoid::{FigureClip, humanoid24};

/// Newest manifest format this build reads.
pub const MANIFEST_VERSION: u32 = 1;

/// Newest database format this build reads and writes.
pub const DATABASE_VERSION: u32 = 1;

/// One clip of a manifest.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
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
    /// The landmark mapping of a BVH clip (RON, as `marionette mapping` writes it), relative
    /// to the manifest's folder; absent, the mapping is found from the skeleton.
    #[serde(default)]
    pub mapping: Option<PathBuf>,
}

/// A manifest: the clips a database is built from. A field it does not know (a misspelt
/// `tempo:`) is refused, not ignored.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
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
        let load = |e: Box<dyn std::error::Error + Send + Sync>| SegmentError::Load {
            path: origin.clone(),
            source: e,
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
        if let Err(message) = m.check() {
            return Err(SegmentError::Manifest {
                path: origin,
                message,
            });
        }
        let dir = path.parent().unwrap_or(Path::new("."));
        for c in &mut m.clips {
            c.file = dir.join(&c.file);
            c.mapping = c.mapping.as_ref().map(|f| dir.join(f));
        }
        Ok(m)
    }

    /// `Ok` when every clip's numbers are usable: a tempo within
    /// [`super::segments::TEMPO_RANGE_BPM`], a finite first beat ≥ 0 s and a finite window
    /// (start, end) with 0 ≤ start < end; else what is wrong, naming the clip (by its place
    /// and file) and the field.
    pub fn check(&self) -> Result<(), String> {
        for (i, c) in self.clips.iter().enumerate() {
            let clip = format!("clip {} ({})", i + 1, c.file.display());
            if let Some(t) = c.tempo_bpm {
                check_tempo("tempo_bpm", t).map_err(|e| format!("{clip}: {e}"))?;
            }
            if let Some(f) = c.first_beat_s.filter(|f| !(f.is_finite() && *f >= 0.0)) {
                return Err(format!(
                    "{clip}: first_beat_s is {f} s, not a finite time ≥ 0 s"
                ));
            }
            check_window(c.window).map_err(|e| format!("{clip}: {e}"))?;
        }
        Ok(())
    }

    /// Every .bvh and keyframed .ron clip of a folder (sorted by name; .ron manifests skipped),
    /// with no tempo known.
    pub fn from_folder(dir: &Path) -> Result<Manifest, SegmentError> {
        let origin = dir.display().to_string();
        let entries = std::fs::read_dir(dir).map_err(|e| SegmentError::Load {
            path: origin.clone(),
            source: e.into(),
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
                    mapping: None,
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

/// `Ok` when `window` is none or a finite (start, end) with 0 ≤ start < end, else what is
/// wrong.
fn check_window(window: Option<(f64, f64)>) -> Result<(), String> {
    match window {
        Some((a, b)) if !(a.is_finite() && b.is_finite() && 0.0 <= a && a < b) => Err(format!(
            "window is ({a}, {b}) s, not a finite (start, end) with 0 ≤ start < end"
        )),
        _ => Ok(()),
    }
}

/// Whether a .ron file has a manifest's shape (a version and a list of clips, whatever their
/// fields: a manifest with a misspelt field is still one, refused when loaded as such).
fn is_manifest(p: &Path) -> bool {
    #[derive(Deserialize)]
    struct Shape {
        #[serde(rename = "format_version")]
        _version: u32,
        #[serde(rename = "clips")]
        _clips: Vec<serde::de::IgnoredAny>,
    }
    crate::io::read_text(p)
        .ok()
        .is_some_and(|t| crate::io::parse_ron::<Shape>(&t, "").is_ok())
}

/// One manifest clip loaded, windowed, given its beat and cut into bars as the database's
/// clip `index`.
fn clip_segments(
    c: &ManifestClip,
    name: &str,
    index: usize,
    params: &BuildParams,
) -> Result<(Source, Vec<Segment>), SegmentError> {
    check_window(c.window).map_err(|message| SegmentError::Manifest {
        path: name.to_string(),
        message,
    })?;
    let mut clip = load_figure_clip_with(&c.file, c.mapping.as_deref())?;
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
/// ([`crate::mapping::onto_figure`]), or a keyframed .ron clip; set on its floor ([`grounded`]).
pub fn load_figure_clip(path: &Path) -> Result<FigureClip, SegmentError> {
    load_unground(path, None).map(grounded)
}

/// [`load_figure_clip`] with the BVH clip's landmark mapping read from `mapping` (a RON file)
/// when given, instead of found from its skeleton.
pub fn load_figure_clip_with(
    path: &Path,
    mapping: Option<&Path>,
) -> Result<FigureClip, SegmentError> {
    load_unground(path, mapping).map(grounded)
}

/// `clip` with its root moved vertically so that its floor is at y = 0: the floor is the one
/// [`crate::analysis::clip_contacts_with`] finds (the 2nd percentile over the clip of its
/// lowest foot point), so clips captured or mapped with their feet above or below y = 0 (a
/// mapped skeleton's feet are not the source's) stand on one floor when their bars are
/// joined. A clip without feet is returned as it is.
pub fn grounded(mut clip: FigureClip) -> FigureClip {
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

fn load_unground(path: &Path, mapping: Option<&Path>) -> Result<FigureClip, SegmentError> {
    let load = |e: Box<dyn std::error::Error + Send + Sync>| SegmentError::Load {
        path: path.display().to_string(),
        source: e,
    };
    let is_ron = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ron"));
    if is_ron {
        return crate::clips::KeyframeClip::load(path)
            .map(|k| k.to_figure_clip())
            .map_err(|e| load(e.into()));
    }
    let (bvh, _warnings) = crate::bvh::parse_file(path).map_err(|e| load(e.into()))?;
    let clip = crate::skeleton::Clip::from_bvh(&bvh, None).map_err(|e| load(e.into()))?;
    let mapping = match mapping {
        Some(file) => crate::mapping::Mapping::load(file).map_err(|e| SegmentError::Load {
            path: file.display().to_string(),
            source: e.into(),
        })?,
        None => crate::mapping::Mapping::detect_clip(&clip).map_err(|e| load(e.into()))?,
    };
    let model = humanoid24();
    let mapped = crate::mapping::retarget(&clip, &mapping, &model).map_err(|e| load(e.into()))?;
    // The source's angles on humanoid24 itself, the root path scaled with the legs, so that
    // every segment is measured and danced on the one figure it is played on.
    Ok(crate::mapping::onto_figure(&mapped, &model))
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
        params.check()?;
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
        clips: &[(String, FigureClip, Option<Beat>)],
        params: &BuildParams,
    ) -> Result<Database, SegmentError> {
        if clips.is_empty() {
            return Err(SegmentError::Manifest {
                path: "clips".into(),
                message: "no clip to build a dance database from".into(),
            });
        }
        params.check()?;
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

    /// `Ok` when the database is one this build can dance: made on humanoid24, its build
    /// parameters within bounds, every segment naming one of its sources, with
    /// `params.bar_frames` frames of humanoid24's DOFs and points, every source's segment
    /// count matching, an Eros weight per principal axis and every number finite (JSON has no NaN:
    /// a database holding one could not be read back). Otherwise what is wrong, naming the
    /// segment or source.
    pub fn validate(&self) -> Result<(), String> {
        if self.model != "humanoid24" {
            return Err(format!(
                "the database was made on model {:?}; this build dances on humanoid24 only",
                self.model
            ));
        }
        self.params.check().map_err(|e| match e {
            SegmentError::Manifest { message, .. } => format!("params: {message}"),
            e => e.to_string(),
        })?;
        let model = humanoid24();
        let shape = SegmentShape {
            frames: self.params.bar_frames,
            dofs: model.dofs.len(),
            points: model.skeleton().point_parents().len(),
        };
        let finite = |v: &[f64]| v.iter().position(|x| !x.is_finite());
        let mut counts = vec![0usize; self.sources.len()];
        for (i, s) in self.segments.iter().enumerate() {
            let seg = format!("segment {i} (bar {} of source {})", s.bar, s.clip);
            let Some(c) = counts.get_mut(s.clip) else {
                return Err(format!(
                    "{seg} names source {}, but the database has {} source(s)",
                    s.clip,
                    self.sources.len()
                ));
            };
            *c += 1;
            check_segment(&seg, s, &shape)?;
            self.check_eros(&seg, s)?;
        }
        self.check_sources(&counts)?;
        if let Some(k) = finite(&self.eros_weights) {
            return Err(format!("eros_weights[{k}] is not a finite number"));
        }
        Ok(())
    }

    /// A segment's Eros (as `seg` names it): a value and an axis per Eros weight of the
    /// database, axes as long as the first segment's, every number finite.
    fn check_eros(&self, seg: &str, s: &Segment) -> Result<(), String> {
        let axes = self.eros_weights.len();
        let dim = self.segments[0].eros.vectors.first().map_or(0, Vec::len);
        if s.eros.values.len() != axes
            || s.eros.vectors.len() != axes
            || s.eros.vectors.iter().any(|v| v.len() != dim)
        {
            return Err(format!(
                "{seg}: eros holds {} values and {} axes, the database {axes} Eros weights \
                 (and axes of {dim} values)",
                s.eros.values.len(),
                s.eros.vectors.len()
            ));
        }
        if s.eros
            .vectors
            .iter()
            .any(|v| v.iter().any(|x| !x.is_finite()))
        {
            return Err(format!(
                "{seg}: eros.vectors holds a number that is not finite"
            ));
        }
        Ok(())
    }

    /// Every source's segment count matching the segments that name it (`counts`), and its
    /// numbers finite.
    fn check_sources(&self, counts: &[usize]) -> Result<(), String> {
        for (k, (src, &got)) in self.sources.iter().zip(counts).enumerate() {
            let name = format!("source {k} ({})", src.file);
            if src.segments != got {
                return Err(format!(
                    "{name} says {} segment(s), but {got} segment(s) name it",
                    src.segments
                ));
            }
            let window_ok = src
                .window
                .is_none_or(|(a, b)| a.is_finite() && b.is_finite());
            let numbers_ok = src.fps.is_finite()
                && src.fps > 0.0
                && src.beat.tempo_bpm.is_finite()
                && src.beat.first_beat_s.is_finite();
            if !(window_ok && numbers_ok) {
                return Err(format!(
                    "{name}: fps {}, tempo {} BPM, first beat {} s, window {:?}: a number is \
                     not finite (or fps not positive)",
                    src.fps, src.beat.tempo_bpm, src.beat.first_beat_s, src.window
                ));
            }
        }
        Ok(())
    }

    /// Writes the database (compact JSON) atomically: nothing is left half-written. A
    /// database that [`Database::validate`] refuses (its own reader would) is not written.
    pub fn save(&self, path: &Path) -> Result<(), SegmentError> {
        self.validate()
            .map_err(|message| SegmentError::InvalidDatabase {
                path: format!("{} (not written)", path.display()),
                message,
            })?;
        crate::io::write_atomic(path, &self.to_json()).map_err(|e| SegmentError::Load {
            path: path.display().to_string(),
            source: e.into(),
        })
    }

    /// Reads a database written by [`Database::save`] and checks it ([`Database::validate`]):
    /// one that is inconsistent or made on another model is refused, naming the file, the
    /// segment or source and what is wrong.
    pub fn load(path: &Path) -> Result<Database, SegmentError> {
        let origin = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| SegmentError::Load {
            path: origin.clone(),
            source: e.into(),
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
        db.validate()
            .map_err(|message| SegmentError::InvalidDatabase {
                path: origin,
                message,
            })?;
        Ok(db)
    }

    /// Segments cut from source clip `clip`.
    pub fn segments_of(&self, clip: usize) -> impl Iterator<Item = &Segment> {
        self.segments.iter().filter(move |s| s.clip == clip)
    }
}

/// The sizes a segment must have: its frames, and humanoid24's DOFs and points.
struct SegmentShape {
    frames: usize,
    dofs: usize,
    points: usize,
}

/// A segment's (as `seg` names it) fields of the lengths `shape` gives, its bar a finite span
/// and its numbers finite.
fn check_segment(seg: &str, s: &Segment, shape: &SegmentShape) -> Result<(), String> {
    let (n, dofs, points) = (shape.frames, shape.dofs, shape.points);
    let links = points - 1;
    let finite = |v: &[f64]| v.iter().position(|x| !x.is_finite());
    let finite3 = |v: &[glam::DVec3]| v.iter().position(|x| !x.is_finite());
    let lengths = [
        ("root_translation", s.root_translation.len(), n),
        ("root_rotation", s.root_rotation.len(), n),
        ("angles", s.angles.len(), n * dofs),
        ("first_directions", s.first_directions.len(), links),
        ("last_directions", s.last_directions.len(), links),
        ("first_velocities", s.first_velocities.len(), points),
        ("last_velocities", s.last_velocities.len(), points),
    ];
    for (field, got, want) in lengths {
        if got != want {
            return Err(format!(
                "{seg}: {field} holds {got} values, {want} expected ({n} frames of \
                 humanoid24's {dofs} DOFs and {points} points)"
            ));
        }
    }
    if !(s.start_s.is_finite() && s.end_s.is_finite() && s.start_s < s.end_s) {
        return Err(format!(
            "{seg}: the bar spans {} to {} s, not a finite start before its end",
            s.start_s, s.end_s
        ));
    }
    let bad = [
        ("intensity", finite(std::slice::from_ref(&s.intensity))),
        ("angles", finite(&s.angles)),
        ("root_translation", finite3(&s.root_translation)),
        ("first_directions", finite3(&s.first_directions)),
        ("last_directions", finite3(&s.last_directions)),
        ("first_velocities", finite3(&s.first_velocities)),
        ("last_velocities", finite3(&s.last_velocities)),
        ("eros.values", finite(&s.eros.values)),
    ];
    if let Some((field, Some(k))) = bad.into_iter().find(|(_, k)| k.is_some()) {
        return Err(format!("{seg}: {field}[{k}] is not a finite number"));
    }
    if let Some(k) = s.root_rotation.iter().position(|q| !q.is_finite()) {
        return Err(format!("{seg}: root_rotation[{k}] is not a finite number"));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DQuat, DVec3};

    /// The project's four bars at 120 BPM as a database, built in memory.
    fn bars_db(tempo_bpm: f64, params: &BuildParams) -> Result<Database, SegmentError> {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/clips/dance_bars.ron");
        let clip = load_figure_clip(&path).unwrap();
        let beat = Beat {
            tempo_bpm,
            first_beat_s: 0.0,
            source: TempoSource::Manifest,
        };
        Database::from_clips(&[("bars".into(), clip, Some(beat))], params)
    }

    /// Point 9 of issue 38: a misspelt `tempo:` was ignored and the detected tempo used.
    #[test]
    fn a_manifest_field_it_does_not_know_is_refused_naming_it() {
        let dir = std::env::temp_dir().join(format!("marionette-manifest-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let m = dir.join("manifest.ron");
        std::fs::write(
            &m,
            "(format_version: 1, clips: [(file: \"a.bvh\", tempo: Some(120.0))])",
        )
        .unwrap();
        let e = Manifest::load(&m).unwrap_err().to_string();
        assert!(e.contains("tempo") && e.contains("manifest.ron:1:"), "{e}");
        assert!(e.contains("tempo_bpm"), "names the fields it knows: {e}");
        std::fs::write(
            &m,
            "(format_version: 1, clips: [(file: \"a.bvh\")], song: 1)",
        )
        .unwrap();
        assert!(Manifest::load(&m).unwrap_err().to_string().contains("song"));
        // Still a manifest to a folder listing, not a clip.
        assert!(is_manifest(&m));
        std::fs::write(
            &m,
            "(format_version: 1, clips: [(file: \"a.bvh\", tempo_bpm: 120.0)])",
        )
        .unwrap();
        assert_eq!(Manifest::load(&m).unwrap().clips[0].tempo_bpm, Some(120.0));
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn an_inconsistent_database_is_refused_naming_the_segment_and_never_written() {
        let db = bars_db(120.0, &BuildParams::default()).unwrap();
        assert_eq!(db.validate(), Ok(()));
        let mut bad = db.clone();
        bad.segments[3].clip = 2;
        let e = bad.validate().unwrap_err();
        assert!(
            e.contains("segment 3") && e.contains("names source 2"),
            "{e}"
        );
        let mut bad = db.clone();
        bad.model = "robot12".into();
        assert!(bad.validate().unwrap_err().contains("robot12"));
        let mut bad = db.clone();
        bad.eros_weights.pop();
        let e = bad.validate().unwrap_err();
        assert!(
            e.contains("segment 0") && e.contains("15 Eros weights"),
            "{e}"
        );
        let mut bad = db.clone();
        bad.segments[1].intensity = f64::NAN;
        let dir = std::env::temp_dir().join(format!("marionette-db-nan-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("db.json");
        let e = bad.save(&path).unwrap_err().to_string();
        assert!(e.contains("segment 1") && e.contains("intensity"), "{e}");
        assert!(!path.exists(), "a database its reader refuses was written");
        db.save(&path).unwrap();
        assert_eq!(Database::load(&path).unwrap(), db);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn tempi_and_bar_frames_out_of_bounds_are_refused_before_cutting() {
        for tempo in [1e9, 1e5, 10.0, f64::NAN] {
            let e = bars_db(tempo, &BuildParams::default())
                .unwrap_err()
                .to_string();
            assert!(e.contains("20 to 400 BPM"), "{tempo}: {e}");
        }
        for bar_frames in [0, 1, 1025, 4_000_000_000] {
            let params = BuildParams {
                bar_frames,
                ..BuildParams::default()
            };
            let e = bars_db(120.0, &params).unwrap_err().to_string();
            assert!(e.contains("bar_frames") && e.contains("2 to 1024"), "{e}");
        }
        let clip = |window: Option<(f64, f64)>, tempo_bpm: Option<f64>| Manifest {
            format_version: 1,
            clips: vec![ManifestClip {
                file: "a.bvh".into(),
                tempo_bpm,
                first_beat_s: None,
                window,
                mapping: None,
            }],
        };
        assert_eq!(clip(Some((1.0, 2.0)), Some(120.0)).check(), Ok(()));
        let e = clip(Some((f64::NAN, 10.0)), None).check().unwrap_err();
        assert!(e.contains("clip 1 (a.bvh): window is (NaN, 10)"), "{e}");
        let e = clip(None, Some(1e9)).check().unwrap_err();
        assert!(e.contains("tempo_bpm is 1000000000 BPM"), "{e}");
    }

    #[test]
    fn a_clip_is_set_on_its_floor_whatever_height_it_came_at() {
        let model = humanoid24();
        let d = model.dofs.len();
        let n = 60;
        for y in [0.3, 0.95, 2.0] {
            let clip = FigureClip {
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
