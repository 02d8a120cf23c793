//! Scenes of the motor-primitive paper: the high jump by extrapolation (§4.1) and the jumping
//! knee kick (§4.2), on keyframed or captured clips. The experiments themselves are
//! [`experiments::high_jump`](crate::experiments::high_jump) and
//! [`experiments::knee_kick`](crate::experiments::knee_kick); a scene loads the clips onto
//! humanoid24, builds their configuration, runs them and writes the outputs (BVH, primitive RON
//! files, pictures, the report's figures).

use std::path::Path;
use std::sync::Arc;

use serde::{Deserialize, Serialize};
use serde_json::json;

use super::source::{ClipSource, load_motion};
use super::{SceneError, draw_tracks, page, write_output};
use crate::ecs::{
    Clock, Recorder, kinematic_schedule, new_world, run_ticks, spawn_primitive_character,
};
use crate::experiments::high_jump::{self, HighJumpConfig, HighJumpOutcome};
use crate::experiments::knee_kick::{self, KneeKickConfig, KneeKickOutcome};
use crate::humanoid::{Figure, FigureClip};
use crate::primitive::{
    EventConfig, Gamma, JumpEvents, LearnConfig, Learned, Primitive, Trajectory,
};
use crate::render::{Page, PageMotion, PagePlot, Plot, Series, StickFigure, Track, plot};

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
    high_jump::PAPER_GAMMA
}

/// The paper's §4.1 as a scene ([`high_jump::run`]): a high jump extrapolated from a low and a
/// normal jump. The low jump (A) is time-scaled to the normal jump's (B) duration, both span the
/// same time, and `θ = γ·θ_A + (1 − γ)·θ_B` with constant γ = −0.5 gives `1.5·normal − 0.5·low`.
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
    knee_kick::PAPER_GAMMA
}

/// The paper's §4.2 as a scene ([`knee_kick::run`]): a jumping knee kick. A is the high jump of
/// [`HighJumpScene`] (Start … Land);
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

/// Loads a clip onto humanoid24 as a primitive trajectory.
fn demo(src: &ClipSource, base: &Path, model: &Figure) -> Result<FigureClip, SceneError> {
    load_motion(src, base)?.on_figure(model)
}

/// The high jump's configuration: the scene's clips loaded onto `model`.
fn high_jump_config(
    scene: &HighJumpScene,
    base: &Path,
    model: &Figure,
) -> Result<HighJumpConfig, SceneError> {
    Ok(HighJumpConfig {
        model: model.clone(),
        low: demo(&scene.low, base, model)?,
        normal: demo(&scene.normal, base, model)?,
        gamma: scene.gamma.clone(),
        learn: scene.learn,
    })
}

fn fit_json(l: &Learned) -> serde_json::Value {
    json!({ "median": l.fit.median_angle_rmse_deg(), "max": l.fit.max_angle_rmse_deg() })
}

/// Draws tracks of model clips: filmstrip, GIF; returns them as motions of the results page.
pub(super) fn draw(
    tracks: &[(&str, &FigureClip)],
    render: &PrimitiveRender,
    out: &Path,
) -> Result<Vec<PageMotion>, SceneError> {
    let clips: Vec<_> = tracks.iter().map(|(_, m)| m.to_clip()).collect();
    let figures: Vec<_> = clips.iter().map(|c| StickFigure::of(&c.skeleton)).collect();
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
    Ok(t.iter().map(PageMotion::from_track).collect())
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
        .ok_or_else(|| SceneError::NoDof(dof.to_string()))?;
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

/// Writes primitives as `<name>.primitive.ron` into `out`.
fn save_primitives<'a>(
    learned: impl IntoIterator<Item = &'a Learned>,
    out: &Path,
) -> Result<(), SceneError> {
    for l in learned {
        l.primitive
            .save(&out.join(format!("{}.primitive.ron", l.primitive.name)))
            .map_err(SceneError::from)?;
    }
    Ok(())
}

/// Runs the high-jump scene ([`high_jump::run`] on the scene's clips). A jump's knee flexion is
/// that of its crouch (the peak before take-off), as in the paper's Fig. 8; the whole clip's
/// peak, which for a low jump can be the landing, is reported apart. Per jump the report gives
/// its root apex above standing, its flight (both feet off the floor) and its feet's lowest
/// point; for the high jump also what extrapolating the two jumps with the scene's γ predicts.
/// Writes `low_jump.bvh`, `normal_jump.bvh`, `high_jump.bvh` (each at its own duration), the
/// primitives (`*.primitive.ron`), `filmstrip.png`, `motion.gif`, `left_knee.png` (the paper's
/// Fig. 8) and returns the report.
pub fn run_high_jump(
    scene: &HighJumpScene,
    base: &Path,
    out: &Path,
) -> Result<serde_json::Value, SceneError> {
    scene.gamma.validate()?;
    let model = Figure::by_name("humanoid24")?;
    let config = high_jump_config(scene, base, &model)?;
    let hj = high_jump::run(&config).map_err(SceneError::from)?;
    let learned = &hj.primitives.learned;
    let (clips, rollouts) = (&hj.clips, &hj.rollouts);
    for (name, clip) in [
        ("low_jump", &clips.low),
        ("normal_jump", &clips.normal),
        ("high_jump", &clips.high),
    ] {
        write_bvh(&out.join(format!("{name}.bvh")), clip)?;
    }
    save_primitives([&learned.low, &learned.normal, &learned.high], out)?;
    let label = scene.gamma.label();
    let motions = draw(
        &[
            ("low", &clips.low),
            ("normal", &clips.normal),
            (&format!("high ({label})"), &clips.high),
        ],
        &scene.render,
        out,
    )?;
    let knee = Plot {
        title: format!("Left knee flexion: low, normal and blended high jump ({label})"),
        x_label: "time (s)".into(),
        y_label: "left knee flexion (deg)".into(),
        series: vec![
            dof_series("low (time-scaled)", &rollouts.low, "left_knee", 0.0)?,
            dof_series("normal", &rollouts.normal, "left_knee", 0.0)?,
            dof_series("high", &rollouts.high, "left_knee", 0.0)?,
        ],
        markers: vec![],
    };
    plot(&knee, &out.join("left_knee.png"))?;
    page::write(
        &Page {
            title: format!("{}: high jump", scene.name),
            headline: high_jump_headline(&label, &hj),
            motions,
            plots: vec![page::timed(knee)],
            ..Page::default()
        },
        out,
    )?;
    Ok(high_jump_report(&label, &hj))
}

/// The high jump's headline: each jump's apex, flight and crouch, and what extrapolating the
/// two jumps predicts for the high one.
fn high_jump_headline(label: &str, hj: &HighJumpOutcome) -> Vec<String> {
    let (fig, pred) = (&hj.figures, &hj.primitives.prediction);
    let p = &hj.crouch_knee_flexion_deg;
    let mut headline: Vec<String> = [
        ("low", &fig.low, p.low),
        ("normal", &fig.normal, p.normal),
        (&format!("high ({label})"), &fig.high, p.high),
    ]
    .iter()
    .map(|(name, f, knee)| {
        format!(
            "{name} jump: the root rises {:.3} m above standing at {:.2} s, {:.3} s in flight; \
             the left knee bends {knee:.1}° in the crouch.",
            f.apex_above_standing_m, f.apex_time_s, f.flight_s
        )
    })
    .collect();
    headline.push(format!(
        "Extrapolating the two jumps predicts {:.3} m above standing and {:.3} s in flight for \
         the high jump.",
        pred.apex_above_standing_m, pred.flight_s
    ));
    headline
}

/// The high jump's report: the jumps' figures, the prediction and the high jump's difference
/// from it, the knee flexions, the fits and the floor corrections ([`run_high_jump`]).
fn high_jump_report(label: &str, hj: &HighJumpOutcome) -> serde_json::Value {
    let learned = &hj.primitives.learned;
    let (p, whole) = (&hj.crouch_knee_flexion_deg, &hj.whole_clip_knee_flexion_deg);
    let (fig, pred, plan) = (
        &hj.figures,
        &hj.primitives.prediction,
        &hj.primitives.flight,
    );
    json!({
        "gamma": label,
        "jumps": { "low": fig.low, "normal": fig.normal, "high": fig.high },
        "prediction": pred,
        "high_minus_predicted": {
            "apex_above_standing_m": fig.high.apex_above_standing_m - pred.apex_above_standing_m,
            "apex_root_m": fig.high.apex_root_m - pred.apex_root_m,
            "flight_s": fig.high.flight_s - pred.flight_s,
        },
        "flight_plan": plan,
        "floor_y_m": hj.primitives.floor_y_m,
        "flights_measured_against": FLIGHTS_AGAINST,
        "contact_reference": hj.primitives.contact_reference,
        "peak_knee_flexion_deg": { "low": p.low, "normal": p.normal, "high": p.high },
        "peak_knee_flexion_whole_clip_deg": { "low": whole.low, "normal": whole.normal, "high": whole.high },
        "expected_high_deg": hj.expected_high_deg,
        "high_minus_expected_deg": hj.high_minus_expected_deg,
        "fit_rmse_deg": fit_json(&learned.high),
        "fit_rmse_deg_by_primitive": { "low": fit_json(&learned.low), "normal": fit_json(&learned.normal), "high": fit_json(&learned.high) },
        "duration_s": hj.duration_s,
        "high_duration_s": learned.high.primitive.duration,
        "ground_correction_m": hj.primitives.ground_correction_m,
        "floor_lift_m": { "low": hj.floor_lift_m.low, "normal": hj.floor_lift_m.normal, "high": hj.floor_lift_m.high },
    })
}

/// What the primitive reports' `flight` of every jump is measured against.
const FLIGHTS_AGAINST: &str = "the normal jump's floor and foot rest heights \
    (contact_reference), so that the jumps are measured alike; own_contacts_flight is each \
    clip's flight with its own, as `marionette inspect` finds it in the written BVH";

/// Writes a clip on the model as BVH.
pub(super) fn write_bvh(path: &Path, clip: &FigureClip) -> Result<(), SceneError> {
    write_output(
        path,
        crate::bvh::to_string(&clip.to_clip().to_bvh()).as_bytes(),
    )
}

/// Plays the connected sequence by a character in an ECS world (players → pose → forward
/// kinematics → recorder) and returns the largest distance between its recorded points and
/// the kernel's `expected` motion, metres. The recorder holds the state after each step, so
/// recorded frame i is expected frame i + 1.
fn play_in_world(
    model: &Figure,
    sequence: &[Primitive],
    expected: &FigureClip,
) -> Result<f64, SceneError> {
    let dt = expected.frame_time;
    let mut world = new_world(Clock::new(dt, 1));
    let seq = sequence.iter().cloned().map(Arc::new).collect();
    let e = spawn_primitive_character(
        &mut world,
        "jumping knee kick",
        Arc::new(model.clone()),
        seq,
    )
    .map_err(SceneError::from)?;
    let frames = expected.frame_count();
    run_ticks(&mut world, &mut kinematic_schedule(), frames - 1);
    let recorded = &world
        .get::<Recorder>(e)
        .ok_or(SceneError::NoRecorder)?
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

/// The jumping knee kick's configuration: the scene's clips loaded onto humanoid24, γs checked.
pub fn knee_kick_config(
    scene: &JumpingKneeKickScene,
    base: &Path,
) -> Result<KneeKickConfig, SceneError> {
    scene.gamma.validate()?;
    scene.jump.gamma.validate()?;
    let model = Figure::by_name("humanoid24")?;
    Ok(KneeKickConfig {
        jump: high_jump_config(&scene.jump, base, &model)?,
        kick: demo(&scene.kick, base, &model)?,
        gamma: scene.gamma.clone(),
        events: scene.events,
    })
}

/// Runs the jumping-knee-kick scene ([`knee_kick::run`] on the scene's clips, then the connected
/// sequence played in an ECS world and compared with the kernel): writes
/// `jumping_knee_kick.bvh`, the two primitives, `filmstrip.png`, `motion.gif`, `left_knee.png`,
/// `right_knee.png` and returns the report.
pub fn run_jumping_knee_kick(
    scene: &JumpingKneeKickScene,
    base: &Path,
    out: &Path,
) -> Result<serde_json::Value, SceneError> {
    let model = Figure::by_name("humanoid24")?;
    let config = knee_kick_config(scene, base)?;
    let kk = knee_kick::run(&config).map_err(SceneError::from)?;
    // The world plays the primitives, so it is compared with the motion before the floor lift.
    let played = FigureClip::from_trajectory(&model, &kk.connected.trajectory)?;
    let ecs_gap = play_in_world(&model, &kk.sequence(), &played)?;
    let ev = &kk.events;

    write_bvh(&out.join("jumping_knee_kick.bvh"), &kk.result_clip)?;
    save_primitives(&kk.parts, out)?;
    let motions = draw(
        &[
            (
                &format!("high jump (A, {})", scene.jump.gamma.label()),
                &kk.jump_clip,
            ),
            ("knee kick (B)", &kk.kick_clip),
            (
                &format!("jumping knee kick ({})", scene.gamma.label()),
                &kk.result_clip,
            ),
        ],
        &scene.render,
        out,
    )?;
    let plots = knee_plots(&kk, out)?;
    page::write(
        &Page {
            title: format!("{}: jumping knee kick", scene.name),
            headline: vec![
                format!(
                    "Events: start {:.2} s, bend {:.2} s, leap {:.2} s, land {:.2} s.",
                    ev.start, ev.bend, ev.leap, ev.land
                ),
                format!(
                    "Peak knee flexion of the jumping knee kick: right {:.1}°, left {:.1}°; it \
                     lands with both feet: {}.",
                    kk.peak_knee_flexion_deg.right_knee,
                    kk.peak_knee_flexion_deg.left_knee,
                    if kk.lands_with_both_feet { "yes" } else { "no" }
                ),
            ],
            motions,
            plots,
            ..Page::default()
        },
        out,
    )?;
    Ok(knee_kick_report(scene, &kk, ecs_gap))
}

/// The left and right knee's flexion over time in the high jump, the knee kick (placed Bend→Leap)
/// and the jumping knee kick, the events marked: written as `left_knee.png` and
/// `right_knee.png` into `out`, and returned for the page.
fn knee_plots(kk: &KneeKickOutcome, out: &Path) -> Result<Vec<PagePlot>, SceneError> {
    let ev = &kk.events;
    let markers = vec![
        (ev.start, "Start".to_string()),
        (ev.bend, "Bend".into()),
        (ev.leap, "Leap".into()),
        (ev.land, "Land".into()),
    ];
    let ev = &kk.events;
    let mut plots = vec![];
    for dof in ["left_knee", "right_knee"] {
        let series =
            |label: &str, traj: &Trajectory, offset: f64| dof_series(label, traj, dof, offset);
        let knee = Plot {
            title: format!("{dof}: high jump, knee kick (placed Bend→Leap) and jumping knee kick"),
            x_label: "time (s)".into(),
            y_label: format!("{dof} flexion (deg)"),
            series: vec![
                series("high jump", &kk.jump_rollout, 0.0)?,
                series("knee kick (time-scaled)", &kk.kick_placed_rollout, ev.bend)?,
                series("jumping knee kick", &kk.connected.trajectory, 0.0)?,
            ],
            markers: markers.clone(),
        };
        plot(&knee, &out.join(format!("{dof}.png")))?;
        plots.push(page::timed(knee));
    }
    Ok(plots)
}

/// The jumping knee kick's report: the γs, the figures, the state at the leap, the
/// corrections, the events, the junction, the ECS check, the fits and the knee flexions.
fn knee_kick_report(
    scene: &JumpingKneeKickScene,
    kk: &KneeKickOutcome,
    ecs_gap: f64,
) -> serde_json::Value {
    let (ev, j, gap, parts) = (&kk.events, &kk.junction, &kk.posture_gap_deg, &kk.parts);
    json!({
        "gamma": scene.gamma.label(),
        "jump_gamma": scene.jump.gamma.label(),
        "jump": kk.jump_figures,
        "jumping_knee_kick": kk.figures,
        "flights_measured_against": FLIGHTS_AGAINST,
        "contact_reference": kk.jump.contact_reference,
        "at_leap": {
            "airborne": kk.airborne_at_leap,
            "feet_above_floor_m": kk.feet_above_floor_at_leap_m,
            "root_minus_jump_apex_m": kk.root_at_leap_minus_jump_apex_m,
        },
        "ground_correction_m": kk.ground_correction_m,
        "landing_correction_m": kk.landing_correction_m,
        "floor_lift_m": kk.floor_lift_m,
        "events_s": events_json(ev),
        "arrangement": format!("{:?}", kk.arrangement),
        "junction": { "time_s": j.time_s, "max_angle_jump_deg": j.max_angle_jump_deg, "max_velocity_jump_deg_s": j.max_velocity_jump_deg_s },
        "posture_gap_deg": { "jump_at_bend": gap.jump_at_bend_deg, "kick_at_leap": gap.kick_at_leap_deg },
        "feet_above_floor_after_landing_m": kk.feet_above_floor_after_landing_m,
        "lands_with_both_feet": kk.lands_with_both_feet,
        "ecs_vs_kernel_max_m": ecs_gap,
        "fit_rmse_deg": fit_json(&parts[0]),
        "fit_rmse_deg_by_primitive": {
            "jumping_knee_kick": fit_json(&parts[0]),
            "land": fit_json(&parts[1]),
            "knee_kick": fit_json(&kk.kick),
            "high_jump": fit_json(&kk.jump.learned.high),
        },
        "peak_knee_flexion_deg": {
            "right_knee": kk.peak_knee_flexion_deg.right_knee,
            "left_knee": kk.peak_knee_flexion_deg.left_knee,
        },
    })
}
