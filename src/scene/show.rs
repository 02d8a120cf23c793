//! The `Show` scene: load a clip, map it onto a model, play it through the ECS, render it.

use std::path::Path;
use std::sync::Arc;

use serde::{Deserialize, Serialize};
use serde_json::json;

use super::source::{ClipSource, LoadedMotion, load_motion};
use super::{SceneError, draw_tracks, page, write_output};
use crate::analysis::clip_contacts;
use crate::ecs::{Clock, Recorder, kinematic_schedule, new_world, spawn_clip_character};
use crate::humanoid::{Figure, FigureClip};
use crate::mapping::effector_errors;
use crate::render::{Page, PageMotion, Plot, Series, StickFigure, Track, plot, pose_png};
use crate::skeleton::Clip;

/// What pictures a scene draws.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderSettings {
    /// Frames in the filmstrip.
    pub filmstrip_frames: usize,
    /// Write an animated GIF.
    pub gif: bool,
    /// Frame rate of the GIF.
    pub gif_fps: f64,
    /// DOFs whose angle curves are plotted (model DOF names).
    pub plot: Vec<String>,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            filmstrip_frames: 8,
            gif: true,
            gif_fps: 25.0,
            plot: vec!["left_knee".into(), "right_knee".into()],
        }
    }
}

/// Load a clip, optionally map it onto one of the engine's models, and render it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShowScene {
    /// Scene format version.
    pub format_version: u32,
    /// Scene name (default output folder `out/<name>/`).
    pub name: String,
    /// The motion.
    pub clip: ClipSource,
    /// `humanoid24` or `fall21` to map the clip onto; absent: show it on its own skeleton.
    #[serde(default)]
    pub model: Option<String>,
    /// Pictures.
    #[serde(default)]
    pub render: RenderSettings,
}

/// Plays `clip` through a world of the base ECS and returns the recorded points of every frame.
pub fn play_through_ecs(clip: &Clip) -> Vec<Vec<glam::DVec3>> {
    let clip = Arc::new(clip.clone());
    let mut world = new_world(Clock::new(clip.frame_time, 1));
    let e = spawn_clip_character(&mut world, "character", clip.clone(), false);
    let mut schedule = kinematic_schedule();
    for _ in 0..clip.frame_count() {
        schedule.run(&mut world);
    }
    world
        .get::<Recorder>(e)
        .map(|r| r.frames.clone())
        .unwrap_or_default()
}

/// Runs a [`ShowScene`]; writes `motion.bvh`, `pose.png`, `filmstrip.png`, `motion.gif`, and on a
/// model `angles.csv` and `angles.png`. Returns the report.
pub fn run_show(
    scene: &ShowScene,
    base: &Path,
    out: &Path,
) -> Result<serde_json::Value, SceneError> {
    let motion = load_motion(&scene.clip, base)?;
    let mut report = json!({ "clip": scene.clip.file });
    let (clip, model_clip) = shown_clip(scene, &motion, &mut report)?;
    let frames = play_through_ecs(&clip);
    let figure = StickFigure::of(&clip.skeleton);
    let label = match &scene.model {
        Some(m) => format!("{} on {m}", scene.name),
        None => scene.name.clone(),
    };
    let track = Track {
        figure: &figure,
        frames: &frames,
        label,
        frame_time: clip.frame_time,
    };
    write_output(
        &out.join("motion.bvh"),
        crate::bvh::to_string(&clip.to_bvh()).as_bytes(),
    )?;
    pose_png(&track, 0, &out.join("pose.png"))?;
    draw_tracks(
        std::slice::from_ref(&track),
        scene.render.filmstrip_frames,
        scene.render.gif.then_some(scene.render.gif_fps),
        out,
    )?;
    let mut page = Page {
        title: format!("{}: motion", scene.name),
        motions: vec![PageMotion::from_track(&track)],
        ..Page::default()
    };
    report["frames"] = json!(clip.frame_count());
    report["fps"] = json!(1.0 / clip.frame_time);
    report["duration_s"] = json!(clip.duration());

    if let Some(c) = clip_contacts(&clip, 0.03, 0.1) {
        report["flights"] = json!(c.flights);
    }

    if let Some(m) = &model_clip {
        write_output(&out.join("angles.csv"), m.angles_csv().as_bytes())?;
        let (series, peaks) = plotted_angles(&scene.render.plot, m)?;
        if !series.is_empty() {
            let angles = Plot {
                title: format!("{}: joint angles on {}", scene.name, m.model.name),
                x_label: "time (s)".into(),
                y_label: "angle (deg)".into(),
                series,
                markers: vec![],
            };
            plot(&angles, &out.join("angles.png"))?;
            page.plots.push(page::timed(angles));
        }
        report["model"] = json!(m.model.name);
        report["dof_range_deg"] = serde_json::Value::Object(peaks);
    }
    page.headline.push(format!(
        "{} frames at {:.0} frames/s, {:.2} s, from {}{}.",
        clip.frame_count(),
        1.0 / clip.frame_time,
        clip.duration(),
        scene.clip.file,
        match &scene.model {
            Some(m) => format!(", mapped onto {m}"),
            None => String::new(),
        }
    ));
    if let Some(f) = report["flights"].as_array() {
        page.headline
            .push(format!("{} flights (both feet off the floor).", f.len()));
    }
    page::write(&page, out)?;
    Ok(report)
}

/// The clip shown: the motion as loaded, or mapped onto the scene's model (with it the model's
/// clip); a captured motion mapped onto a model puts its mapping and effector errors in
/// `report`.
fn shown_clip(
    scene: &ShowScene,
    motion: &LoadedMotion,
    report: &mut serde_json::Value,
) -> Result<(Clip, Option<FigureClip>), SceneError> {
    let (clip, model_clip) = match &scene.model {
        Some(name) => {
            let model = Figure::by_name(name)?;
            let m = motion.on_figure(&model)?;
            (m.to_clip(), Some(m))
        }
        None => (motion.clip(), None),
    };
    if let (
        LoadedMotion::Captured {
            clip: source,
            mapping: Some(mapping),
            ..
        },
        Some(m),
    ) = (motion, &model_clip)
    {
        report["mapping"] = json!(mapping.name);
        report["effector_error_m"] = json!(effector_errors(source, mapping, m)?);
    }
    Ok((clip, model_clip))
}

/// The curves of the DOFs `names` of `m` (degrees over time) and each one's range (minimum and
/// maximum, degrees). Errors: a name that is not a DOF of the model.
fn plotted_angles(
    names: &[String],
    m: &FigureClip,
) -> Result<(Vec<Series>, serde_json::Map<String, serde_json::Value>), SceneError> {
    let mut series = vec![];
    let mut peaks = serde_json::Map::new();
    for name in names {
        let d = m
            .model
            .dof_index(name)
            .ok_or_else(|| SceneError::UnknownName {
                field: "render.plot".into(),
                name: name.to_string(),
                expected: format!("a DOF of {}", m.model.name),
            })?;
        let s = m.dof_series(d);
        let max = s.iter().copied().fold(f64::MIN, f64::max).to_degrees();
        let min = s.iter().copied().fold(f64::MAX, f64::min).to_degrees();
        peaks.insert(name.clone(), json!({ "min_deg": min, "max_deg": max }));
        series.push(Series {
            name: name.clone(),
            points: s
                .iter()
                .enumerate()
                .map(|(f, a)| (f as f64 * m.frame_time, a.to_degrees()))
                .collect(),
        });
    }
    Ok((series, peaks))
}
