//! Scenes of the motor-primitive paper: the high jump by extrapolation (§4.1) and the jumping
//! knee kick (§4.2), on keyframed or captured clips.

use std::path::Path;
use std::sync::Arc;

use serde::{Deserialize, Serialize};
use serde_json::json;

use super::source::{ClipSource, load_motion};
use super::{SceneError, draw_tracks, write_output};
use crate::ecs::{Recorder, new_primitive_world, run_primitive_world, spawn_primitive_character};
use crate::humanoid::{Model, ModelClip};
use crate::primitive::{
    BlendPlacement, EventConfig, Gamma, JumpEvents, LearnConfig, Learned, Primitive, Relearn,
    Trajectory, blend, connect, find_jump_events,
};
use crate::render::{Plot, Series, Track, plot};

/// Pictures of a primitive scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PrimitiveRender {
    /// Frames in the filmstrip.
    pub filmstrip_frames: usize,
    /// Write an animated GIF.
    pub gif: bool,
    /// GIF frame rate.
    pub gif_fps: f64,
}

impl Default for PrimitiveRender {
    fn default() -> Self {
        PrimitiveRender {
            filmstrip_frames: 8,
            gif: true,
            gif_fps: 25.0,
        }
    }
}

fn extrapolate_half() -> Gamma {
    Gamma::Constant(-0.5)
}

/// The paper's §4.1: a high jump extrapolated from a low and a normal jump. The low jump (A) is
/// time-scaled to the normal jump's (B) duration, both span the same time, and
/// `θ = γ·θ_A + (1 − γ)·θ_B` with constant γ = −0.5 gives `1.5·normal − 0.5·low`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HighJumpScene {
    /// Scene format version.
    pub format_version: u32,
    /// Scene name.
    pub name: String,
    /// The low jump (A).
    pub low: ClipSource,
    /// The normal jump (B).
    pub normal: ClipSource,
    /// γ(t′) (default: constant −0.5).
    #[serde(default = "extrapolate_half")]
    pub gamma: Gamma,
    /// Learning settings (formulation, kernels, regression).
    #[serde(default)]
    pub learn: LearnConfig,
    /// Pictures.
    #[serde(default)]
    pub render: PrimitiveRender,
}

fn kick_gamma() -> Gamma {
    Gamma::Ramp { from: 1.0, to: 0.0 }
}

/// The paper's §4.2: a jumping knee kick. A is the high jump of [`HighJumpScene`] (Start … Land);
/// B, a knee kick, is placed from A's Bend (deepest crouch) to its Leap (hips highest) and
/// blended with γ(t′) = 1 − t′; the result is re-learned as two primitives split at Leap
/// ("jumping knee kick" and "land"), which are then connected.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JumpingKneeKickScene {
    /// Scene format version.
    pub format_version: u32,
    /// Scene name.
    pub name: String,
    /// How the high jump (A) is made.
    pub jump: HighJumpScene,
    /// The knee kick (B): from its start to the strike (knee highest).
    pub kick: ClipSource,
    /// γ(t′) of the kick blend (default: a ramp from 1 to 0, i.e. 1 − t′).
    #[serde(default = "kick_gamma")]
    pub gamma: Gamma,
    /// Jump-event detection settings.
    #[serde(default)]
    pub events: EventConfig,
    /// Pictures.
    #[serde(default)]
    pub render: PrimitiveRender,
}

fn primitive_error(e: crate::primitive::PrimitiveError) -> SceneError {
    SceneError::Invalid(e.to_string())
}

/// Loads a clip onto humanoid24 as a primitive trajectory.
fn demo(src: &ClipSource, base: &Path, model: &Model) -> Result<ModelClip, SceneError> {
    load_motion(src, base)?.on_model(model)
}

fn learn(name: &str, traj: &Trajectory, config: &LearnConfig) -> Result<Learned, SceneError> {
    Primitive::learn(name, traj, config).map_err(primitive_error)
}

fn rollout(p: &Primitive, dt: f64) -> Result<Trajectory, SceneError> {
    p.rollout(dt, None).map_err(primitive_error)
}

fn on_model(model: &Model, traj: &Trajectory) -> Result<ModelClip, SceneError> {
    ModelClip::from_trajectory(model, traj).map_err(SceneError::from)
}

/// Peak of a DOF over a trajectory, degrees.
fn peak_deg(traj: &Trajectory, dof: &str) -> Result<f64, SceneError> {
    let j = traj
        .index_of(dof)
        .ok_or_else(|| SceneError::Invalid(format!("no DOF '{dof}'")))?;
    Ok(traj
        .column(j)
        .into_iter()
        .fold(f64::MIN, f64::max)
        .to_degrees())
}

fn fit_json(l: &Learned) -> serde_json::Value {
    json!({ "median": l.fit.median_angle_rmse_deg(), "max": l.fit.max_angle_rmse_deg() })
}

/// Learned A (low), B (normal), and the high jump; their rollouts on the model.
struct HighJump {
    low: Learned,
    normal: Learned,
    high: Learned,
    dt: f64,
    /// Largest root-height correction that put the feet back on the floor, metres.
    ground_correction_m: f64,
}

/// The lowest foot point (ankles and toes) of a clip over all frames: its floor, metres.
fn lowest_foot(clip: &ModelClip) -> f64 {
    heights(clip)
        .1
        .iter()
        .flatten()
        .copied()
        .fold(f64::INFINITY, f64::min)
}

fn make_high_jump(
    scene: &HighJumpScene,
    base: &Path,
    model: &Model,
) -> Result<HighJump, SceneError> {
    let low_clip = demo(&scene.low, base, model)?;
    let normal_clip = demo(&scene.normal, base, model)?;
    let dt = normal_clip.frame_time;
    let low = learn("low_jump", &low_clip.to_trajectory(), &scene.learn)?;
    let normal = learn("normal_jump", &normal_clip.to_trajectory(), &scene.learn)?;
    let t = normal.primitive.duration;
    // A time-scaled to B's duration; both on [0, T].
    let placement = BlendPlacement {
        a_start: 0.0,
        a_end: t,
        b_start: 0.0,
        b_end: t,
    };
    let result = blend(
        &low.primitive,
        &normal.primitive,
        &placement,
        &scene.gamma,
        dt,
        Relearn::Whole,
        &scene.learn,
    )
    .map_err(primitive_error)?;
    let blended = result
        .primitives
        .into_iter()
        .next()
        .ok_or_else(|| SceneError::Invalid("the blend re-learned no primitive".into()))?;
    // Put the feet back on the floor outside the normal jump's flight, then learn the high jump.
    let normal_roll = on_model(model, &rollout(&normal.primitive, dt)?)?;
    let (root_y, feet) = heights(&normal_roll);
    let ev = find_jump_events(&root_y, dt, Some(&feet), &EventConfig::default())
        .map_err(primitive_error)?;
    let mut high_clip = on_model(model, &rollout(&blended.primitive, dt)?)?;
    let floor = lowest_foot(&normal_roll);
    let ground_correction_m = high_clip.keep_feet_on_floor(&[(ev.take_off, ev.land)], floor);
    let high = learn("high_jump", &high_clip.to_trajectory(), &scene.learn)?;
    Ok(HighJump {
        low,
        normal,
        high,
        dt,
        ground_correction_m,
    })
}

/// Draws tracks of model clips: filmstrip, GIF.
fn draw(
    tracks: &[(&str, &ModelClip)],
    render: &PrimitiveRender,
    out: &Path,
) -> Result<(), SceneError> {
    let clips: Vec<_> = tracks.iter().map(|(_, m)| m.to_clip()).collect();
    let figures: Vec<_> = clips.iter().map(|c| c.skeleton.figure()).collect();
    let frames: Vec<_> = clips.iter().map(|c| c.point_frames()).collect();
    let t: Vec<Track> = tracks
        .iter()
        .enumerate()
        .map(|(i, (label, _))| Track {
            figure: &figures[i],
            frames: &frames[i],
            label: label.to_string(),
            frame_time: clips[i].frame_time,
        })
        .collect();
    draw_tracks(
        &t,
        render.filmstrip_frames,
        render.gif.then_some(render.gif_fps),
        out,
    )?;
    Ok(())
}

/// One DOF of a trajectory as a plot series in degrees, its time shifted by `offset` seconds.
fn dof_series(
    label: &str,
    traj: &Trajectory,
    dof: &str,
    offset: f64,
) -> Result<Series, SceneError> {
    let j = traj
        .index_of(dof)
        .ok_or_else(|| SceneError::Invalid(format!("no DOF '{dof}'")))?;
    Ok(Series {
        name: label.into(),
        points: traj
            .column(j)
            .iter()
            .enumerate()
            .map(|(k, v)| (offset + k as f64 * traj.dt, v.to_degrees()))
            .collect(),
    })
}

/// Runs the high-jump scene. A jump's knee flexion is that of its crouch (the peak before
/// take-off, found by [`find_jump_events`] on each rollout), as in the paper's Fig. 8; the whole
/// clip's peak, which for a low jump can be the landing, is reported apart. Writes
/// `high_jump.bvh`, the primitives (`*.primitive.ron`),
/// `filmstrip.png`, `motion.gif`, `left_knee.png` (the paper's Fig. 8) and returns the report.
pub fn run_high_jump(
    scene: &HighJumpScene,
    base: &Path,
    out: &Path,
) -> Result<serde_json::Value, SceneError> {
    let model = Model::by_name("humanoid24")?;
    let hj = make_high_jump(scene, base, &model)?;
    let t = hj.normal.primitive.duration;
    // Rollouts on the common span: the low jump time-scaled to the normal jump's duration.
    let low_scaled = hj.low.primitive.with_duration(t).map_err(primitive_error)?;
    let r_low = rollout(&low_scaled, hj.dt)?;
    let r_normal = rollout(&hj.normal.primitive, hj.dt)?;
    let r_high = rollout(&hj.high.primitive, hj.dt)?;
    let high_clip = on_model(&model, &r_high)?;
    let low_clip = on_model(&model, &r_low)?;
    let normal_clip = on_model(&model, &r_normal)?;
    // The paper's knee flexion of a jump is that of its crouch: the peak before take-off.
    let crouch_peak = |traj: &Trajectory, clip: &ModelClip| -> Result<f64, SceneError> {
        let (root_y, feet) = heights(clip);
        let ev = find_jump_events(&root_y, hj.dt, Some(&feet), &EventConfig::default())
            .map_err(primitive_error)?;
        let frames = ((ev.take_off / traj.dt).round() as usize).clamp(1, traj.frames() - 1);
        peak_deg(
            &traj.slice_frames(0, frames).map_err(primitive_error)?,
            "left_knee",
        )
    };
    let (p_low, p_normal, p_high) = (
        crouch_peak(&r_low, &low_clip)?,
        crouch_peak(&r_normal, &normal_clip)?,
        crouch_peak(&r_high, &high_clip)?,
    );
    let whole = (
        peak_deg(&r_low, "left_knee")?,
        peak_deg(&r_normal, "left_knee")?,
        peak_deg(&r_high, "left_knee")?,
    );
    let expected = 1.5 * p_normal - 0.5 * p_low;
    write_output(
        &out.join("high_jump.bvh"),
        crate::bvh::to_string(&high_clip.to_clip().to_bvh()).as_bytes(),
    )?;
    for l in [&hj.low, &hj.normal, &hj.high] {
        l.primitive
            .save(&out.join(format!("{}.primitive.ron", l.primitive.name)))
            .map_err(primitive_error)?;
    }
    draw(
        &[
            ("low (time-scaled)", &low_clip),
            ("normal", &normal_clip),
            ("high (γ = −0.5)", &high_clip),
        ],
        &scene.render,
        out,
    )?;
    plot(
        &Plot {
            title: "Left knee flexion: low, normal and extrapolated high jump".into(),
            x_label: "time (s)".into(),
            y_label: "left knee flexion (deg)".into(),
            series: vec![
                dof_series("low", &r_low, "left_knee", 0.0)?,
                dof_series("normal", &r_normal, "left_knee", 0.0)?,
                dof_series("high", &r_high, "left_knee", 0.0)?,
            ],
            markers: vec![],
        },
        &out.join("left_knee.png"),
    )?;
    Ok(json!({
        "peak_knee_flexion_deg": { "low": p_low, "normal": p_normal, "high": p_high },
        "peak_knee_flexion_whole_clip_deg": { "low": whole.0, "normal": whole.1, "high": whole.2 },
        "expected_high_deg": expected,
        "high_minus_expected_deg": p_high - expected,
        "fit_rmse_deg": fit_json(&hj.high),
        "fit_rmse_deg_by_primitive": { "low": fit_json(&hj.low), "normal": fit_json(&hj.normal), "high": fit_json(&hj.high) },
        "duration_s": t,
        "ground_correction_m": hj.ground_correction_m,
    }))
}

/// Root height and each foot's lowest point over time (`feet[foot][frame]`), metres.
fn heights(clip: &ModelClip) -> (Vec<f64>, Vec<Vec<f64>>) {
    let root: Vec<f64> = clip.root_translation.iter().map(|t| t.y).collect();
    (root, clip.foot_heights().into())
}

/// Plays the connected sequence by a character in an ECS world (players → pose → forward
/// kinematics → recorder) and returns the largest distance between its recorded points and
/// the kernel's `expected` motion, metres. The recorder holds the state after each step, so
/// recorded frame i is expected frame i + 1.
fn play_in_world(
    model: &Model,
    sequence: &[Primitive],
    expected: &ModelClip,
) -> Result<f64, SceneError> {
    let dt = expected.frame_time;
    let mut world = new_primitive_world(dt);
    let seq = sequence.iter().cloned().map(Arc::new).collect();
    let e = spawn_primitive_character(
        &mut world,
        "jumping knee kick",
        Arc::new(model.clone()),
        seq,
    )
    .map_err(primitive_error)?;
    let frames = expected.frame_count();
    run_primitive_world(&mut world, frames - 1);
    let recorded = &world
        .get::<Recorder>(e)
        .ok_or_else(|| SceneError::Invalid("no recorder".into()))?
        .frames;
    let kernel = expected.to_clip().point_frames();
    Ok(recorded
        .iter()
        .zip(&kernel[1..])
        .flat_map(|(a, b)| a.iter().zip(b).map(|(p, q)| (*p - *q).length()))
        .fold(0.0, f64::max))
}

fn events_json(e: &JumpEvents) -> serde_json::Value {
    json!({ "start": e.start, "bend": e.bend, "take_off": e.take_off, "leap": e.leap, "land": e.land })
}

/// Runs the jumping-knee-kick scene: writes `jumping_knee_kick.bvh`, the two primitives,
/// `filmstrip.png`, `motion.gif`, `left_knee.png`, `right_knee.png` and returns the report.
pub fn run_jumping_knee_kick(
    scene: &JumpingKneeKickScene,
    base: &Path,
    out: &Path,
) -> Result<serde_json::Value, SceneError> {
    let model = Model::by_name("humanoid24")?;
    let hj = make_high_jump(&scene.jump, base, &model)?;
    let dt = hj.dt;
    let a = &hj.high.primitive;
    let r_jump = rollout(a, dt)?;
    let jump_clip = on_model(&model, &r_jump)?;
    let (root_y, feet) = heights(&jump_clip);
    let ev = find_jump_events(&root_y, dt, Some(&feet), &scene.events).map_err(primitive_error)?;

    let kick_clip = demo(&scene.kick, base, &model)?;
    let kick = learn("knee_kick", &kick_clip.to_trajectory(), &scene.jump.learn)?;
    let placement = BlendPlacement {
        a_start: 0.0,
        a_end: a.duration,
        b_start: ev.bend,
        b_end: ev.leap,
    };
    let result = blend(
        a,
        &kick.primitive,
        &placement,
        &scene.gamma,
        dt,
        Relearn::SplitAtBEnd,
        &scene.jump.learn,
    )
    .map_err(primitive_error)?;
    if result.primitives.len() != 2 {
        return Err(SceneError::Invalid(format!(
            "expected two primitives split at Leap, got {}",
            result.primitives.len()
        )));
    }
    let mut parts: Vec<Learned> = result.primitives;
    parts[0].primitive.name = "jumping_knee_kick".into();
    parts[1].primitive.name = "land".into();
    let sequence: Vec<Primitive> = parts.iter().map(|l| l.primitive.clone()).collect();
    let connected = connect(&sequence, dt, None).map_err(primitive_error)?;
    let junction = connected.junctions.first();
    let angle_jump = junction.map_or(0.0, |j| j.max_angle_jump.to_degrees());
    let velocity_jump = junction.map_or(0.0, |j| j.max_velocity_jump.to_degrees());
    let result_clip = on_model(&model, &connected.trajectory)?;
    let ecs_gap = play_in_world(&model, &sequence, &result_clip)?;

    // Checks of the paper's figure: the jump's posture at Bend, the kick's at Leap, both feet
    // down after landing.
    let frame_at = |t: f64| ((t / dt).round() as usize).min(result_clip.frame_count() - 1);
    let posture_gap = |a_clip: &ModelClip, fa: usize, fb: usize| -> f64 {
        a_clip
            .frame_angles(fa)
            .iter()
            .zip(result_clip.frame_angles(fb))
            .map(|(x, y)| (x - y).abs().to_degrees())
            .fold(0.0, f64::max)
    };
    let kick_end = kick_clip.frame_count() - 1;
    let at_bend = posture_gap(&jump_clip, frame_at(ev.bend), frame_at(ev.bend));
    let at_leap = posture_gap(&kick_clip, kick_end, frame_at(ev.leap));
    let (_, result_feet) = heights(&result_clip);
    let settle = frame_at(ev.land + 0.25);
    let floor = lowest_foot(&jump_clip);
    let feet_after_landing: Vec<f64> = result_feet
        .iter()
        .map(|foot| foot[settle.min(foot.len() - 1)] - floor)
        .collect();
    let both_feet_down = feet_after_landing.iter().all(|h| *h < 0.05);

    write_output(
        &out.join("jumping_knee_kick.bvh"),
        crate::bvh::to_string(&result_clip.to_clip().to_bvh()).as_bytes(),
    )?;
    for l in &parts {
        l.primitive
            .save(&out.join(format!("{}.primitive.ron", l.primitive.name)))
            .map_err(primitive_error)?;
    }
    let r_kick = rollout(&kick.primitive, dt)?;
    let kick_model = on_model(&model, &r_kick)?;
    draw(
        &[
            ("high jump (A)", &jump_clip),
            ("knee kick (B)", &kick_model),
            ("jumping knee kick", &result_clip),
        ],
        &scene.render,
        out,
    )?;
    let markers = vec![
        (ev.start, "Start".to_string()),
        (ev.bend, "Bend".into()),
        (ev.leap, "Leap".into()),
        (ev.land, "Land".into()),
    ];
    for dof in ["left_knee", "right_knee"] {
        let series =
            |label: &str, traj: &Trajectory, offset: f64| dof_series(label, traj, dof, offset);
        plot(
            &Plot {
                title: format!(
                    "{dof}: high jump, knee kick (placed Bend→Leap) and jumping knee kick"
                ),
                x_label: "time (s)".into(),
                y_label: format!("{dof} flexion (deg)"),
                series: vec![
                    series("high jump", &r_jump, 0.0)?,
                    series(
                        "knee kick (time-scaled)",
                        &rollout(
                            &kick
                                .primitive
                                .with_duration(ev.leap - ev.bend)
                                .map_err(primitive_error)?,
                            dt,
                        )?,
                        ev.bend,
                    )?,
                    series("jumping knee kick", &connected.trajectory, 0.0)?,
                ],
                markers: markers.clone(),
            },
            &out.join(format!("{dof}.png")),
        )?;
    }
    Ok(json!({
        "events_s": events_json(&ev),
        "arrangement": format!("{:?}", result.arrangement),
        "junction": { "time_s": junction.map(|j| j.time), "max_angle_jump_deg": angle_jump, "max_velocity_jump_deg_s": velocity_jump },
        "posture_gap_deg": { "jump_at_bend": at_bend, "kick_at_leap": at_leap },
        "feet_above_floor_after_landing_m": feet_after_landing,
        "lands_with_both_feet": both_feet_down,
        "ecs_vs_kernel_max_m": ecs_gap,
        "fit_rmse_deg": fit_json(&parts[0]),
        "fit_rmse_deg_by_primitive": {
            "jumping_knee_kick": fit_json(&parts[0]),
            "land": fit_json(&parts[1]),
            "knee_kick": fit_json(&kick),
            "high_jump": fit_json(&hj.high),
        },
        "peak_knee_flexion_deg": {
            "right_knee": peak_deg(&connected.trajectory, "right_knee")?,
            "left_knee": peak_deg(&connected.trajectory, "left_knee")?,
        },
    }))
}
