//! Scene files: a whole experiment described in RON, validated with clear messages, run into one
//! output folder with a `report.json` of its figures.
//!
//! A scene is one variant of [`Scene`], written `Kind(format_version: 1, name: "…", …)`.
//! Unknown fields are rejected with file, line and column; [`apply_overrides`] sets any field
//! from the command line (`--set clip.end_s=2.5`) so a parameter can be swept without editing
//! files.

mod active;
mod dance;
mod evolve;
mod fall;
mod output;
mod page;
mod primitives;
mod show;
mod source;
mod summary;

pub use active::{ActiveCharacter, ActiveKneeKickScene, run_active_knee_kick};
pub use dance::{
    DanceInputs, DanceRender, DanceScene, DatabaseSource, Pin, SongSource, load_dance, run_dance,
    scene_pins, song_timed_bvh, validate_dance,
};
pub use evolve::{
    EvaluatorChoice, EvolveFallScene, GaStep, ResumeMismatch, SettingMismatch, run_evolve,
};
pub use fall::{Controller, FallScene, SceneFall, fall_report, run_fall};
pub use page::{PAGE_FILE, RunPage, write_run_index};
pub use primitives::{
    HighJumpScene, JumpingKneeKickScene, PrimitiveRender, knee_kick_config, run_high_jump,
    run_jumping_knee_kick,
};
pub use show::{RenderSettings, ShowScene, run_show};
pub use source::{ClipSource, LoadedMotion, data_dir, load_motion, resolve_path};
pub use summary::headline;

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

/// The scene format version this build reads.
pub const FORMAT_VERSION: u32 = 1;

/// An experiment.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Scene {
    /// Load a clip, map it onto a model, play it through the ECS and render it.
    Show(ShowScene),
    /// The motor-primitive paper's high jump by extrapolation.
    HighJump(Box<HighJumpScene>),
    /// The motor-primitive paper's jumping knee kick.
    JumpingKneeKick(Box<JumpingKneeKickScene>),
    /// The falling paper's pushed figure.
    Fall(Box<FallScene>),
    /// The jumping knee kick played by a physical character, pushed and falling.
    ActiveKneeKick(Box<ActiveKneeKickScene>),
    /// The falling paper's GA for both age groups over several seeds.
    EvolveFall(Box<EvolveFallScene>),
    /// The dance-editing paper: a song, a segment database, pins, the rest filled.
    Dance(Box<DanceScene>),
}

/// Why a scene could not be read or run. Module errors keep their own type (and message), so a
/// runner writes `?`; the other variants say what in the scene is out of range, unknown or
/// inconsistent, with the values concerned.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: String,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// RON syntax or schema error (file, line, column, field).
    #[error(transparent)]
    Ron(#[from] crate::io::RonError),
    /// A data file: unreadable, bad RON, or a newer format version.
    #[error(transparent)]
    File(#[from] crate::io::FileError),
    /// A `--set` override that does not fit the scene.
    #[error("--set {assignment}: {message}")]
    Override {
        /// The `field.path=value` assignments.
        assignment: String,
        /// Why it does not fit.
        message: String,
    },
    /// A number out of its range: the field, its value and what it should be.
    #[error("{field} is {value}, expected {expected}")]
    OutOfRange {
        /// The field.
        field: String,
        /// Its value.
        value: f64,
        /// What it should be.
        expected: String,
    },
    /// A number outside its interval: the field, the interval and the value.
    #[error("{field} must be in {range}, found {value}")]
    NotInRange {
        /// The field.
        field: &'static str,
        /// The interval (with its unit).
        range: &'static str,
        /// Its value.
        value: f64,
    },
    /// A filmstrip frame count outside 1 to [`MAX_FILMSTRIP_FRAMES`].
    #[error("render.filmstrip_frames is {}, expected 1 to {}", .0, MAX_FILMSTRIP_FRAMES)]
    FilmstripFrames(usize),
    /// A name the field does not know: the field, the name and what it should be (with the
    /// names it knows).
    #[error("{field}: '{name}' is not {expected}")]
    UnknownName {
        /// The field.
        field: String,
        /// The name given.
        name: String,
        /// What it should be.
        expected: String,
    },
    /// A pushed link that is not a humanoid24 link.
    #[error("push.link '{link}' is not a humanoid24 link; links: {}", .links.join(", "))]
    UnknownPushLink {
        /// The link given.
        link: String,
        /// The humanoid24 links.
        links: Vec<String>,
    },
    /// A DOF a plotted trajectory does not have.
    #[error("no DOF '{0}'")]
    NoDof(String),
    /// A scene name that is not a plain folder name.
    #[error(
        "name {:?}: expected a plain folder name (letters, digits, '_', '-', '.'; not \
         starting with '.'; at most {} characters): it names the output folder out/<name>/",
        .0,
        MAX_NAME_LEN
    )]
    Name(String),
    /// A value of the scene file itself (no `--set` names it) that did not survive its trip
    /// through JSON, e.g. a NaN or infinite number.
    #[error(
        "field `{field}` of the scene itself (no --set names it): {message}{}",
        if .message.contains("null") {
            "; a NaN or infinite number in the scene file reads as null here: write a finite \
             number"
        } else {
            ""
        }
    )]
    SceneValue {
        /// The field's path.
        field: String,
        /// The reader's message.
        message: String,
    },
    /// A motion file that is neither a BVH file nor a keyframed clip.
    #[error("{}: expected a .bvh motion file or a .ron keyframed clip", .0.display())]
    MotionFormat(PathBuf),
    /// A BVH file's motion that is not a clip.
    #[error("{}: {source}", .path.display())]
    BvhClip {
        /// The file.
        path: PathBuf,
        /// Why.
        source: crate::skeleton::ClipError,
    },
    /// A BVH clip's window that could not be cut.
    #[error("{}: clip window: {source}", .path.display())]
    ClipWindow {
        /// The file.
        path: PathBuf,
        /// Why.
        source: crate::skeleton::ClipError,
    },
    /// A keyframed clip's window that is empty or reaches outside the clip.
    #[error(
        "{}: clip window {start_s}..{end_s} s is empty or reaches outside the clip, which spans \
         0..{span_s:.3} s",
        .path.display()
    )]
    KeyframeWindow {
        /// The file.
        path: PathBuf,
        /// Window start (s).
        start_s: f64,
        /// Window end (s).
        end_s: f64,
        /// The clip's span (s).
        span_s: f64,
    },
    /// A keyframed clip on another model than the scene's.
    #[error("the keyframed clip is on model {clip}, not {model}")]
    ClipModel {
        /// The clip's model.
        clip: String,
        /// The scene's model.
        model: String,
    },
    /// A song file to decode in a build without the `audio` feature.
    #[error("{}: decoding songs needs the `audio` feature", .0.display())]
    NoAudio(PathBuf),
    /// A song too long for a WAV file.
    #[error("the song is too long for a WAV file")]
    SongTooLong,
    /// An output path that does not end in a folder name.
    #[error("output folder {}: expected a path ending in a folder name", .0.display())]
    OutputName(PathBuf),
    /// An output folder that is a file.
    #[error("output folder {} is a file", .0.display())]
    OutputIsFile(PathBuf),
    /// An output folder that holds files but no `report.json`.
    #[error(
        "output folder {} holds files but no report.json, so it is not a scene's output: \
         choose another --out (a run replaces its folder whole)",
        .0.display()
    )]
    NotSceneOutput(PathBuf),
    /// A body that could not be built.
    #[error(transparent)]
    Body(#[from] crate::humanoid::HumanError),
    /// The fall's body, for its picture.
    #[error("the fall's body: {0}")]
    FallBody(#[source] crate::humanoid::HumanError),
    /// A fall's body without one contact box per joint.
    #[error("the fall's body has {boxes} contact boxes for {joints} joints")]
    BoxCount {
        /// Contact boxes.
        boxes: usize,
        /// Joints.
        joints: usize,
    },
    /// A checked character without its recorder.
    #[error("no recorder")]
    NoRecorder,
    /// A fall's step given beside a controller evolved at another one.
    #[error(
        "fall.dt_s = {dt} s, but {from} gives the step the controller was evolved at, \
         dt_s = {evolved} s (its damage holds at that step): leave fall.dt_s out to replay \
         it, or set controller.dt_s to run it at another step (e.g. --set controller.dt_s={} \
         for half the step)",
        .evolved / 2.0
    )]
    StepMismatch {
        /// `fall.dt_s` (s).
        dt: f64,
        /// The controller's step (s).
        evolved: f64,
        /// Where the controller's step comes from.
        from: String,
    },
    /// An active character's run.
    #[error(transparent)]
    Active(#[from] crate::experiments::active::ActiveError),
    /// An evolution with no group or no seed.
    #[error("groups and seeds must not be empty")]
    NoRuns,
    /// Groups or seeds given twice.
    #[error("{field} must not repeat an entry, found groups {groups:?}, seeds {seeds:?}")]
    Repeated {
        /// `groups` or `seeds`.
        field: &'static str,
        /// The groups.
        groups: Vec<crate::humanoid::AgeGroup>,
        /// The seeds.
        seeds: Vec<u64>,
    },
    /// More falls than an evolution may simulate.
    #[error("{0} falls to simulate is past the limit of 100 000 000")]
    TooManyFalls(u64),
    /// A worker command without a program.
    #[error("evaluator: Command needs a program")]
    NoProgram,
    /// The GA: its settings, its worker or its checkpoint.
    #[error(transparent)]
    Evolve(#[from] crate::evolve::EvolveError),
    /// A fall's GA problem.
    #[error(transparent)]
    FallProblem(#[from] crate::experiments::evolve_fall::ProblemError),
    /// Evolving the falls.
    #[error(transparent)]
    EvolveFall(#[from] crate::experiments::evolve_fall::EvolveFallError),
    /// Writing an evolved controller file.
    #[error("controller file: {0}")]
    ControllerFile(#[source] ron::Error),
    /// A checkpoint to resume that was made with other settings.
    #[error(
        "resume: the checkpoint in {} was made with other settings: {why}",
        .dir.display()
    )]
    ResumeSettings {
        /// The checkpoint's folder.
        dir: PathBuf,
        /// What differs.
        why: ResumeMismatch,
    },
    /// A pin that gives both or neither of a segment and a clip's bar.
    #[error("pins[{pin}] (bar {bar}): give either segment: N, or clip: \"name\" with clip_bar: N")]
    PinChoice {
        /// The pin's index.
        pin: usize,
        /// Its bar.
        bar: usize,
    },
    /// A bar pinned twice.
    #[error("pins[{pin}]: bar {bar} is pinned already by pins[{first}]")]
    PinTwice {
        /// The pin's index.
        pin: usize,
        /// Its bar.
        bar: usize,
        /// The pin that took the bar first.
        first: usize,
    },
    /// A pin's clip that is not in the database.
    #[error(
        "pins[{pin}] (bar {bar}): no clip '{clip}' in the database; its clips: {}",
        .clips.join(", ")
    )]
    PinClip {
        /// The pin's index.
        pin: usize,
        /// Its bar.
        bar: usize,
        /// The clip named.
        clip: String,
        /// The database's clips.
        clips: Vec<String>,
    },
    /// A pin's clip bar past the clip's bars.
    #[error(
        "pins[{pin}] (bar {bar}): clip '{clip}' has {bars} bars (0 to {}), not bar {clip_bar}",
        .bars.saturating_sub(1)
    )]
    PinClipBar {
        /// The pin's index.
        pin: usize,
        /// Its bar.
        bar: usize,
        /// The clip named.
        clip: String,
        /// The clip's bars.
        bars: usize,
        /// The bar asked for.
        clip_bar: usize,
    },
    /// A dance of no bars.
    #[error("bars is 0: expected at least one bar to dance (or leave it out for the whole song)")]
    NoBars,
    /// Converting a scene to or from its JSON form.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// Reading a BVH file.
    #[error(transparent)]
    Bvh(#[from] crate::bvh::BvhError),
    /// Building a clip.
    #[error(transparent)]
    Clip(#[from] crate::skeleton::ClipError),
    /// A keyframed clip.
    #[error(transparent)]
    Keyframes(#[from] crate::clips::KeyframeError),
    /// Mapping a skeleton.
    #[error(transparent)]
    Mapping(#[from] crate::mapping::MappingError),
    /// A model.
    #[error(transparent)]
    Figure(#[from] crate::humanoid::FigureError),
    /// A joint-range table.
    #[error(transparent)]
    Ranges(#[from] crate::humanoid::RangeError),
    /// Motor primitives: learning, playing, blending, connecting, events.
    #[error(transparent)]
    Primitive(#[from] crate::primitive::PrimitiveError),
    /// The fall simulation.
    #[error(transparent)]
    Fall(#[from] crate::experiments::fall::SimError),
    /// A fall that failed in a World (shared with the pool that ran it).
    #[error(transparent)]
    FallRun(#[from] std::sync::Arc<crate::experiments::fall::SimError>),
    /// A motor-primitive experiment.
    #[error(transparent)]
    Experiment(#[from] crate::experiments::high_jump::PrimitiveExperimentError),
    /// Drawing.
    #[error(transparent)]
    Render(#[from] crate::render::RenderError),
    /// A song: decoding, synthesis or analysis.
    #[error(transparent)]
    Music(#[from] crate::choreo::music::MusicError),
    /// Dance clips and their segment database.
    #[error(transparent)]
    Segment(#[from] crate::choreo::segments::SegmentError),
    /// The project's own dance.
    #[error(transparent)]
    Authored(#[from] crate::choreo::authored::AuthoredError),
    /// Filling the unpinned bars.
    #[error(transparent)]
    Fill(#[from] crate::choreo::fill::FillError),
    /// Assembling the dance.
    #[error(transparent)]
    Dance(#[from] crate::choreo::dance::DanceError),
}

impl Scene {
    /// The scene's name (its default output folder is `out/<name>/`).
    pub fn name(&self) -> &str {
        match self {
            Scene::Show(s) => &s.name,
            Scene::HighJump(s) => &s.name,
            Scene::JumpingKneeKick(s) => &s.name,
            Scene::Fall(s) => &s.name,
            Scene::ActiveKneeKick(s) => &s.name,
            Scene::EvolveFall(s) => &s.name,
            Scene::Dance(s) => &s.name,
        }
    }

    fn format_version(&self) -> u32 {
        match self {
            Scene::Show(s) => s.format_version,
            Scene::HighJump(s) => s.format_version,
            Scene::JumpingKneeKick(s) => s.format_version,
            Scene::Fall(s) => s.format_version,
            Scene::ActiveKneeKick(s) => s.format_version,
            Scene::EvolveFall(s) => s.format_version,
            Scene::Dance(s) => s.format_version,
        }
    }

    /// Parses and checks scene text; `origin` names the file in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Scene, SceneError> {
        let scene: Scene = crate::io::parse_ron(text, origin)?;
        crate::io::check_version(origin, scene.format_version(), FORMAT_VERSION)?;
        Ok(scene)
    }

    /// Reads a scene file.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Scene::parse(&text, &path.display().to_string())
    }
}

/// Sets fields of `scene` from `path=value` assignments. The path names fields from the scene's
/// top (`clip.end_s`, `render.gif_fps`); the value is JSON-like (`2.5`, `true`, `null`,
/// `"text"`, `[1, 2]`) or a bare word taken as text (`humanoid24`), also inside a list
/// (`[elderly, adult]`, as the scene files write such lists).
pub fn apply_overrides(scene: &Scene, assignments: &[String]) -> Result<Scene, SceneError> {
    if assignments.is_empty() {
        return Ok(scene.clone());
    }
    let mut value = serde_json::to_value(scene)?;
    for a in assignments {
        let err = |message: String| SceneError::Override {
            assignment: a.clone(),
            message,
        };
        let (path, raw) = a
            .split_once('=')
            .ok_or_else(|| err("expected field.path=value".into()))?;
        let new = override_value(raw);
        // The top level is the scene kind: {"Show": {...}}.
        let top = value
            .as_object_mut()
            .and_then(|o| o.values_mut().next())
            .ok_or_else(|| err("empty scene".into()))?;
        let cur = field_at(top, path).map_err(err)?;
        // A bare number for a one-number enum variant (`gamma=-1` where the scene has
        // `Constant(-0.5)`) keeps the variant and sets its number.
        let variant = match (&*cur, &new) {
            (serde_json::Value::Object(map), serde_json::Value::Number(_)) if map.len() == 1 => map
                .iter()
                .next()
                .filter(|(_, v)| v.is_number())
                .map(|(k, _)| k.clone()),
            _ => None,
        };
        *cur = match variant {
            Some(k) => serde_json::json!({ k: new }),
            None => new,
        };
    }
    let scene: Scene = serde_path_to_error::deserialize(value)
        .map_err(|e| overridden_field_error(&e, assignments))?;
    if let Some(a) = assignments.iter().rev().find(|a| {
        a.split_once('=')
            .is_some_and(|(p, _)| p.trim() == "format_version")
    }) {
        crate::io::check_version("--set", scene.format_version(), FORMAT_VERSION).map_err(|e| {
            SceneError::Override {
                assignment: a.clone(),
                message: e.to_string(),
            }
        })?;
    }
    Ok(scene)
}

/// The field at the dotted `path` (names of fields, indices of list items) inside `cur`, or
/// why there is none.
fn field_at<'v>(
    mut cur: &'v mut serde_json::Value,
    path: &str,
) -> Result<&'v mut serde_json::Value, String> {
    let parts: Vec<&str> = path.split('.').collect();
    for (i, part) in parts.iter().enumerate() {
        let here = parts[..i].join(".");
        let next = match cur {
            serde_json::Value::Object(map) => {
                let keys: Vec<String> = map.keys().cloned().collect();
                map.get_mut(*part).ok_or_else(|| {
                    format!(
                        "no field '{part}' at '{here}'; fields there: {}",
                        keys.join(", ")
                    )
                })?
            }
            serde_json::Value::Array(items) => {
                let len = items.len();
                let k: usize = part
                    .parse()
                    .map_err(|_| format!("'{here}' is a list: expected an index"))?;
                items
                    .get_mut(k)
                    .ok_or_else(|| format!("index {k} past the end of '{here}' ({len} items)"))?
            }
            _ => {
                return Err(format!("'{here}' is a value, it has no field '{part}'"));
            }
        };
        cur = next;
    }
    Ok(cur)
}

/// The error for a scene that does not read back after the `assignments`: naming the last
/// assignment that set the field or a field holding it, or else the scene's own field.
fn overridden_field_error(
    e: &serde_path_to_error::Error<serde_json::Error>,
    assignments: &[String],
) -> SceneError {
    // The field, written as an assignment's path (the scene kind left out).
    let field = e
        .path()
        .iter()
        .skip(1)
        .map(|s| match s {
            serde_path_to_error::Segment::Seq { index } => index.to_string(),
            s => s.to_string(),
        })
        .collect::<Vec<_>>()
        .join(".");
    let message = e.inner().to_string();
    // The last assignment that set this field or a field holding it.
    let setter = assignments.iter().rev().find(|a| {
        let p = a.split_once('=').map_or(a.as_str(), |(p, _)| p);
        field == p || field.starts_with(&format!("{p}.")) || p.starts_with(&format!("{field}."))
    });
    match setter {
        Some(a) => SceneError::Override {
            assignment: a.clone(),
            message: format!("field `{field}`: {message}"),
        },
        // Not a field any --set touched: the scene's own value, which survives its trip
        // through JSON only when it is finite.
        None => SceneError::SceneValue {
            field: field.to_string(),
            message,
        },
    }
}

/// The value of an override: JSON if it parses, else a list `[a, b, …]` whose items are
/// values in turn (so bare words may stand in it), else the text itself.
fn override_value(raw: &str) -> serde_json::Value {
    if let Ok(v) = serde_json::from_str(raw) {
        return v;
    }
    let text = || serde_json::Value::String(raw.to_string());
    let t = raw.trim();
    let Some(inner) = t.strip_prefix('[').and_then(|r| r.strip_suffix(']')) else {
        return text();
    };
    // Split at the commas outside brackets, braces and quotes.
    let (mut items, mut depth, mut quoted, mut start) = (Vec::new(), 0i32, false, 0);
    let mut prev = ' ';
    for (i, c) in inner.char_indices() {
        match c {
            '"' if prev != '\\' => quoted = !quoted,
            '[' | '{' if !quoted => depth += 1,
            ']' | '}' if !quoted => depth -= 1,
            ',' if !quoted && depth == 0 => {
                items.push(&inner[start..i]);
                start = i + 1;
            }
            _ => {}
        }
        prev = c;
    }
    if depth != 0 || quoted {
        return text();
    }
    items.push(&inner[start..]);
    if items.iter().any(|s| s.trim().is_empty()) {
        return text();
    }
    serde_json::Value::Array(items.iter().map(|s| override_value(s.trim())).collect())
}

/// Longest scene name, characters.
pub const MAX_NAME_LEN: usize = 100;

/// Most filmstrip frames a scene may ask for.
pub const MAX_FILMSTRIP_FRAMES: usize = 64;

/// Checks what can be checked before any work: the scene's name is a plain folder name (it
/// names the default output folder, so it may not be empty, absolute or climb with `..`), the
/// picture settings are in range, and a `Show` scene's model and plotted DOFs exist.
pub fn validate(scene: &Scene) -> Result<(), SceneError> {
    let name = scene.name();
    let plain = name
        .chars()
        .all(|c| c.is_alphanumeric() || matches!(c, '_' | '-' | '.'));
    if name.is_empty() || name.starts_with('.') || !plain || name.chars().count() > MAX_NAME_LEN {
        return Err(SceneError::Name(name.to_string()));
    }
    match scene {
        Scene::Show(s) => validate_show(s)?,
        Scene::HighJump(s) => {
            check_pictures(s.render.filmstrip_frames, s.render.gif, s.render.gif_fps)?
        }
        Scene::JumpingKneeKick(s) => {
            check_pictures(s.render.filmstrip_frames, s.render.gif, s.render.gif_fps)?
        }
        Scene::Fall(s) => {
            check_pictures(s.render.filmstrip_frames, s.render.gif, s.render.gif_fps)?
        }
        Scene::ActiveKneeKick(s) => validate_active_knee_kick(s)?,
        Scene::EvolveFall(s) => {
            check_pictures(s.render.filmstrip_frames, s.render.gif, s.render.gif_fps)?
        }
        Scene::Dance(s) => validate_dance(s)?,
    }
    Ok(())
}

/// Errors unless the picture settings are in range: 1 to [`MAX_FILMSTRIP_FRAMES`] filmstrip
/// frames, and with a GIF a frame rate above 0 and at most [`crate::render::MAX_GIF_FPS`].
fn check_pictures(frames: usize, gif: bool, fps: f64) -> Result<(), SceneError> {
    if !(1..=MAX_FILMSTRIP_FRAMES).contains(&frames) {
        return Err(SceneError::FilmstripFrames(frames));
    }
    check_gif_fps(gif, fps)
}

/// Errors unless, with a GIF, its frame rate is above 0 and at most
/// [`crate::render::MAX_GIF_FPS`].
fn check_gif_fps(gif: bool, fps: f64) -> Result<(), SceneError> {
    if gif && !(fps.is_finite() && fps > 0.0 && fps <= crate::render::MAX_GIF_FPS) {
        return Err(SceneError::OutOfRange {
            field: "render.gif_fps".into(),
            value: fps,
            expected: format!("more than 0 and at most {}", crate::render::MAX_GIF_FPS),
        });
    }
    Ok(())
}

/// [`validate`]'s checks of a `Show` scene: its pictures, and its model's plotted DOFs.
fn validate_show(s: &ShowScene) -> Result<(), SceneError> {
    check_pictures(s.render.filmstrip_frames, s.render.gif, s.render.gif_fps)?;
    // Without a model there are no DOFs: the plot is not drawn.
    if let Some(name) = &s.model {
        let model = crate::humanoid::Figure::by_name(name)?;
        for d in &s.render.plot {
            if model.dof_index(d).is_none() {
                return Err(SceneError::UnknownName {
                    field: "render.plot".into(),
                    name: d.clone(),
                    expected: format!(
                        "a DOF of {}; its DOFs: {}",
                        model.name,
                        model.dof_names().join(", ")
                    ),
                });
            }
        }
    }
    Ok(())
}

/// [`validate`]'s checks of an `ActiveKneeKick` scene: its pictures, positive times and
/// rates, an assist from 0 to 1, a push inside the run on a humanoid24 link.
fn validate_active_knee_kick(s: &ActiveKneeKickScene) -> Result<(), SceneError> {
    check_pictures(s.render.filmstrip_frames, s.render.gif, s.render.gif_fps)?;
    let positive = |field: &str, x: f64| {
        if x.is_finite() && x > 0.0 {
            Ok(())
        } else {
            Err(SceneError::OutOfRange {
                field: field.into(),
                value: x,
                expected: "a positive number".into(),
            })
        }
    };
    positive("dt_s", s.dt_s)?;
    positive("duration_s", s.duration_s)?;
    positive("character.joint_omega", s.character.joint_omega)?;
    positive("character.assist_omega", s.character.assist_omega)?;
    if !(0.0..=1.0).contains(&s.character.assist) {
        return Err(SceneError::OutOfRange {
            field: "character.assist".into(),
            value: s.character.assist,
            expected: "0 (none) to 1 (full)".into(),
        });
    }
    if let Some(d) = s.release_delay_s
        && !(d.is_finite() && d >= 0.0)
    {
        return Err(SceneError::OutOfRange {
            field: "release_delay_s".into(),
            value: d,
            expected: "≥ 0 or None".into(),
        });
    }
    if !(s.push.start_s.is_finite() && s.push.start_s >= 0.0 && s.push.start_s < s.duration_s) {
        return Err(SceneError::OutOfRange {
            field: "push.start_s".into(),
            value: s.push.start_s,
            expected: format!("inside the run [0, {})", s.duration_s),
        });
    }
    let links = crate::humanoid::humanoid24_body(1.70, 65.0, 9.81)?.link_names;
    if !links.contains(&s.push.link) {
        return Err(SceneError::UnknownPushLink {
            link: s.push.link.clone(),
            links,
        });
    }
    Ok(())
}

/// Runs a scene into `out_dir`, all outputs together or none: the scene is checked first
/// ([`validate`]), every output is written into a temporary folder beside `out_dir` (same file
/// system, named `.<folder>.partial-<pid>`, never taken for output), the last one `report.json`,
/// and only when all are written does that folder replace `out_dir`. A failure, or an
/// interrupted run, leaves the previous outputs as they were; temporary folders left by
/// interrupted runs are removed by the next run. `out_dir` must be absent, empty or a previous
/// scene output (holding `report.json`), so that no other files are replaced. `base` is the
/// folder relative paths in the scene refer to. Returns the report.
pub fn run(scene: &Scene, base: &Path, out_dir: &Path) -> Result<serde_json::Value, SceneError> {
    validate(scene)?;
    let staging = output::Staging::begin(out_dir)?;
    let started = std::time::Instant::now();
    let tmp = staging.path();
    let mut report = match scene {
        Scene::Show(s) => run_show(s, base, tmp)?,
        Scene::HighJump(s) => run_high_jump(s, base, tmp)?,
        Scene::JumpingKneeKick(s) => run_jumping_knee_kick(s, base, tmp)?,
        Scene::Fall(s) => run_fall(s, base, tmp)?,
        Scene::ActiveKneeKick(s) => run_active_knee_kick(s, base, tmp)?,
        Scene::EvolveFall(s) => run_evolve(s, base, tmp, out_dir)?,
        Scene::Dance(s) => run_dance(s, base, tmp)?,
    };
    if let Some(o) = report.as_object_mut() {
        o.insert("scene".into(), scene.name().into());
        o.insert("wall_time_s".into(), started.elapsed().as_secs_f64().into());
    }
    let lines = headline(scene, &report);
    if let Some(o) = report.as_object_mut() {
        o.insert("headline".into(), lines.into());
    }
    write_output(
        &tmp.join("report.json"),
        serde_json::to_string_pretty(&report)
            .unwrap_or_default()
            .as_bytes(),
    )?;
    staging.commit()?;
    Ok(report)
}

/// The default output folder of a scene: `out/<name>/`.
pub fn default_out_dir(scene: &Scene) -> PathBuf {
    PathBuf::from("out").join(scene.name())
}

/// Draws `tracks` into `out`: `filmstrip.png` with `filmstrip_frames` columns, and
/// `motion.gif` at `gif_fps` frames per second when that is given.
pub fn draw_tracks(
    tracks: &[crate::render::Track],
    filmstrip_frames: usize,
    gif_fps: Option<f64>,
    out: &Path,
) -> Result<(), SceneError> {
    crate::render::filmstrip_png(tracks, filmstrip_frames.max(1), &out.join("filmstrip.png"))?;
    if let Some(fps) = gif_fps {
        crate::render::animation_gif(tracks, fps, &out.join("motion.gif"))?;
    }
    Ok(())
}

/// Writes an output file whole or not at all.
pub fn write_output(path: &Path, bytes: &[u8]) -> Result<(), SceneError> {
    crate::io::write_atomic(path, bytes).map_err(|source| SceneError::Io {
        path: path.display().to_string(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = r#"Show(
    format_version: 1,
    name: "t",
    clip: (file: "clips/normal_jump.ron"),
    model: "humanoid24",
)"#;

    #[test]
    fn parses_and_overrides() {
        let s = Scene::parse(SCENE, "t.ron").unwrap();
        let s2 = apply_overrides(
            &s,
            &[
                "clip.end_s=1.5".into(),
                "render.gif=false".into(),
                "name=other".into(),
            ],
        )
        .unwrap();
        let Scene::Show(sh) = &s2 else {
            panic!("not a Show scene")
        };
        assert_eq!(sh.clip.end_s, Some(1.5));
        assert!(!sh.render.gif);
        assert_eq!(sh.name, "other");
    }

    #[test]
    fn an_override_list_may_hold_bare_words() {
        use serde_json::json;
        assert_eq!(
            override_value("[elderly, adult]"),
            json!(["elderly", "adult"])
        );
        assert_eq!(override_value("[elderly]"), json!(["elderly"]));
        assert_eq!(override_value("[1, x, \"a, b\"]"), json!([1, "x", "a, b"]));
        assert_eq!(
            override_value("[[a, 1], {\"k\": 2}]"),
            json!([["a", 1], {"k": 2}])
        );
        // JSON stays JSON; what is no list stays text.
        assert_eq!(override_value("[1, 2]"), json!([1, 2]));
        assert_eq!(override_value("humanoid24"), json!("humanoid24"));
        assert_eq!(override_value("[a, ]"), json!("[a, ]"));
        assert_eq!(override_value("[a, [b]"), json!("[a, [b]"));
    }

    #[test]
    fn errors_name_file_line_column_and_field() {
        let bad = SCENE.replace("model:", "modle:");
        let e = Scene::parse(&bad, "t.ron").unwrap_err().to_string();
        assert!(e.starts_with("t.ron:5:"), "{e}");
        assert!(e.contains("modle"), "{e}");
        let s = Scene::parse(SCENE, "t.ron").unwrap();
        let e = apply_overrides(&s, &["clip.ends=2".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("no field 'ends' at 'clip'"), "{e}");
        let e = apply_overrides(&s, &["render.gif_fps=fast".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("render.gif_fps=fast"), "{e}");
        // Point 10 of issue 38: each type error names its own assignment and field only.
        let e = apply_overrides(
            &s,
            &[
                "render.gif=false".into(),
                "render.gif_fps=fast".into(),
                "name=\"ok\"".into(),
            ],
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("--set render.gif_fps=fast: field `render.gif_fps`"),
            "{e}"
        );
        assert!(e.contains("invalid type: string \"fast\""), "{e}");
        assert!(!e.contains("name=") && !e.contains("gif=false"), "{e}");
        // Point 9: a format version set on the command line is checked as the file's is.
        for v in ["2", "0"] {
            let e = apply_overrides(&s, &[format!("format_version={v}")])
                .unwrap_err()
                .to_string();
            assert!(
                e.starts_with(&format!("--set format_version={v}:"))
                    && e.contains("is not one this build reads"),
                "{e}"
            );
        }
        assert!(apply_overrides(&s, &["format_version=1".into()]).is_ok());
        // Point 10: a NaN in the file is the file's, not the --set's.
        let nan = SCENE.replace("model:", "render: (gif_fps: NaN),\n    model:");
        let s = Scene::parse(&nan, "t.ron").unwrap();
        let e = apply_overrides(&s, &["name=x".into()])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("field `render.gif_fps` of the scene itself") && e.contains("NaN"),
            "{e}"
        );
        assert!(!e.starts_with("--set"), "{e}");
        let newer = SCENE.replace("format_version: 1", "format_version: 7");
        assert!(
            Scene::parse(&newer, "t.ron")
                .unwrap_err()
                .to_string()
                .contains("newer")
        );
    }

    /// The typed errors carry their values, and show the text the scene's checks wrote
    /// before they were typed (the old `format!` calls, copied here), byte for byte.
    #[test]
    fn scene_errors_carry_their_values_and_keep_their_messages() {
        let e = check_pictures(0, false, 10.0).unwrap_err();
        assert!(matches!(e, SceneError::FilmstripFrames(0)), "{e:?}");
        assert_eq!(
            e.to_string(),
            format!("render.filmstrip_frames is 0, expected 1 to {MAX_FILMSTRIP_FRAMES}")
        );
        let e = check_pictures(8, true, 60.0).unwrap_err();
        let SceneError::OutOfRange { field, value, .. } = &e else {
            panic!("{e:?}")
        };
        assert_eq!((field.as_str(), *value), ("render.gif_fps", 60.0));
        assert_eq!(
            e.to_string(),
            format!(
                "render.gif_fps is {}, expected more than 0 and at most {}",
                60.0,
                crate::render::MAX_GIF_FPS
            )
        );
        let e = validate(&Scene::parse(&SCENE.replace("\"t\"", "\"../t\""), "t.ron").unwrap())
            .unwrap_err();
        assert!(matches!(&e, SceneError::Name(n) if n == "../t"), "{e:?}");
        let name = "../t";
        assert_eq!(
            e.to_string(),
            format!(
                "name {name:?}: expected a plain folder name (letters, digits, '_', '-', '.'; \
                 not starting with '.'; at most {MAX_NAME_LEN} characters): it names the \
                 output folder out/<name>/"
            )
        );
        let (dt, evolved, from) = (0.001, 0.0007, "controller.dt_s".to_string());
        assert_eq!(
            SceneError::StepMismatch {
                dt,
                evolved,
                from: from.clone()
            }
            .to_string(),
            format!(
                "fall.dt_s = {dt} s, but {from} gives the step the controller was \
                 evolved at, dt_s = {evolved} s (its damage holds at that step): leave \
                 fall.dt_s out to replay it, or set controller.dt_s to run it at \
                 another step (e.g. --set controller.dt_s={} for half the step)",
                evolved / 2.0
            )
        );
        for message in ["invalid type: null, expected f64", "invalid value: 3"] {
            let e = SceneError::SceneValue {
                field: "render.gif_fps".into(),
                message: message.into(),
            };
            assert_eq!(
                e.to_string(),
                format!(
                    "field `render.gif_fps` of the scene itself (no --set names it): {message}{}",
                    if message.contains("null") {
                        "; a NaN or infinite number in the scene file reads as null here: \
                         write a finite number"
                    } else {
                        ""
                    }
                )
            );
        }
        let path = Path::new("clips/x.ron");
        let (a, b, span) = (1.5, 0.5, 2.25);
        assert_eq!(
            SceneError::KeyframeWindow {
                path: path.into(),
                start_s: a,
                end_s: b,
                span_s: span
            }
            .to_string(),
            format!(
                "{}: clip window {a}..{b} s is empty or reaches outside the clip, which \
                 spans 0..{span:.3} s",
                path.display()
            )
        );
        assert_eq!(
            SceneError::NotSceneOutput(path.into()).to_string(),
            format!(
                "output folder {} holds files but no report.json, so it is not a scene's \
                 output: choose another --out (a run replaces its folder whole)",
                path.display()
            )
        );
        let (k, bar, clip, bars, clip_bar) = (2, 5, "c", 4, 9);
        assert_eq!(
            SceneError::PinClipBar {
                pin: k,
                bar,
                clip: clip.into(),
                bars,
                clip_bar
            }
            .to_string(),
            format!(
                "pins[{k}] (bar {bar}): clip '{clip}' has {bars} bars (0 to {}), not bar \
                 {clip_bar}",
                bars - 1
            )
        );
    }
}
