//! The motor-primitive paper's §4.1: a high jump by extrapolation. A low jump (A) and a normal
//! jump (B) are learned as primitives; A is time-scaled to B's duration so both span [0, T], and
//! the blend `θ = γ·θ_A + (1 − γ)·θ_B` with constant γ = −0.5 gives `1.5·normal − 0.5·low`, a
//! jump deeper than either demonstration. Blending joint angles and root height separately lifts
//! the feet during the extrapolated crouch, so the blend's feet are put back on the floor outside
//! the normal jump's flight before the high jump is learned as one primitive.
//!
//! [`learn_primitives`] makes the three primitives (the jumping knee kick of
//! [`knee_kick`](super::knee_kick) starts from them); [`run`] also plays them and measures the
//! paper's Fig. 8: the left knee's crouch flexion of each jump. Plain data in and out: the
//! demonstrations come as [`ModelClip`]s already on the model, nothing is read or written.

use crate::humanoid::{Model, ModelClip};
use crate::primitive::{
    BlendPlacement, EventConfig, Gamma, LearnConfig, Learned, Primitive, PrimitiveError, Relearn,
    Trajectory, blend, find_jump_events,
};

/// The paper's γ for the high jump: constant −0.5 (extrapolation beyond the normal jump).
pub const PAPER_GAMMA: Gamma = Gamma::Constant(-0.5);

/// Why a motor-primitive experiment (the high jump, the jumping knee kick) could not run.
#[derive(Debug, thiserror::Error)]
pub enum PrimitiveExperimentError {
    /// Learning, blending, playing, connecting primitives or finding jump events.
    #[error(transparent)]
    Primitive(#[from] PrimitiveError),
    /// A played trajectory does not fit the model (a model DOF or root channel is missing).
    #[error(transparent)]
    OnModel(#[from] crate::humanoid::ModelError),
    /// A DOF the experiment measures is not in the trajectory.
    #[error("no DOF '{0}'")]
    NoDof(String),
    /// The blend re-learned no primitive.
    #[error("the blend re-learned no primitive")]
    NothingRelearned,
    /// The jumping knee kick's blend was not re-learned as two primitives split at Leap.
    #[error("expected two primitives split at Leap, got {0}")]
    NotSplitInTwo(usize),
}

/// One value for each of the three jumps.
#[derive(Clone, Debug, PartialEq)]
pub struct Jumps<T> {
    /// The low jump (A).
    pub low: T,
    /// The normal jump (B).
    pub normal: T,
    /// The extrapolated high jump.
    pub high: T,
}

/// The inputs of the high jump.
#[derive(Clone, Debug, PartialEq)]
pub struct HighJumpConfig {
    /// The model the results are put on (humanoid24): rollouts become clips on it.
    pub model: Model,
    /// The low jump demonstration (A), on `model`'s DOFs.
    pub low: ModelClip,
    /// The normal jump demonstration (B), on `model`'s DOFs; its frame time is the time step of
    /// every rollout.
    pub normal: ModelClip,
    /// γ(t′) of the blend (the paper: [`PAPER_GAMMA`]).
    pub gamma: Gamma,
    /// Learning settings (formulation, kernels, regression) of every primitive.
    pub learn: LearnConfig,
}

/// The three primitives of the high jump, as [`learn_primitives`] makes them.
#[derive(Clone, Debug, PartialEq)]
pub struct HighJumpPrimitives {
    /// The learned jumps with their fits: `low_jump` and `normal_jump` from the demonstrations,
    /// `high_jump` from the blend with its feet put back on the floor.
    pub learned: Jumps<Learned>,
    /// The time step of the rollouts: the normal jump's frame time, seconds.
    pub dt: f64,
    /// Largest root-height correction that put the blend's feet back on the floor, metres.
    pub ground_correction_m: f64,
}

/// Everything the high jump found.
#[derive(Clone, Debug, PartialEq)]
pub struct HighJumpOutcome {
    /// The three primitives.
    pub primitives: HighJumpPrimitives,
    /// The common span T: the normal jump's duration, seconds.
    pub duration_s: f64,
    /// Rollouts at `dt` over [0, T]: the low jump time-scaled to T, the normal and the high jump.
    pub rollouts: Jumps<Trajectory>,
    /// The rollouts as clips on the model.
    pub clips: Jumps<ModelClip>,
    /// Left-knee flexion of each jump's crouch, degrees: the peak before take-off (found by
    /// [`find_jump_events`] on each rollout), as in the paper's Fig. 8.
    pub crouch_knee_flexion_deg: Jumps<f64>,
    /// Left-knee flexion peak over each whole rollout, degrees (for a low jump this can be the
    /// landing rather than the crouch).
    pub whole_clip_knee_flexion_deg: Jumps<f64>,
    /// The paper's expected crouch flexion of the high jump, `1.5·normal − 0.5·low`, degrees (the
    /// γ = −0.5 extrapolation of the crouch peaks; it does not follow another `gamma`).
    pub expected_high_deg: f64,
    /// `crouch_knee_flexion_deg.high − expected_high_deg`, degrees.
    pub high_minus_expected_deg: f64,
}

/// A trajectory as a clip on `model`.
pub(super) fn on_model(
    model: &Model,
    traj: &Trajectory,
) -> Result<ModelClip, PrimitiveExperimentError> {
    Ok(ModelClip::from_trajectory(model, traj)?)
}

/// Plays `p` over [0, τ] at step `dt`.
pub(super) fn rollout(p: &Primitive, dt: f64) -> Result<Trajectory, PrimitiveExperimentError> {
    Ok(p.rollout(dt, None)?)
}

/// Peak of a DOF over a trajectory, degrees.
pub(super) fn peak_deg(traj: &Trajectory, dof: &str) -> Result<f64, PrimitiveExperimentError> {
    let j = traj
        .index_of(dof)
        .ok_or_else(|| PrimitiveExperimentError::NoDof(dof.into()))?;
    Ok(traj
        .column(j)
        .into_iter()
        .fold(f64::MIN, f64::max)
        .to_degrees())
}

/// Root height and each foot's lowest point over time (`feet[foot][frame]`), metres.
pub(super) fn heights(clip: &ModelClip) -> (Vec<f64>, Vec<Vec<f64>>) {
    let root: Vec<f64> = clip.root_translation.iter().map(|t| t.y).collect();
    (root, clip.foot_heights().into())
}

/// The lowest foot point (ankles and toes) of a clip over all frames: its floor, metres.
pub(super) fn lowest_foot(clip: &ModelClip) -> f64 {
    heights(clip)
        .1
        .iter()
        .flatten()
        .copied()
        .fold(f64::INFINITY, f64::min)
}

/// Learns the low and normal jumps, blends them with `config.gamma` over the common span
/// (`a = [0, T]`, `b = [0, T]`, T the normal jump's duration, re-learned whole), puts the
/// blend's feet back on the normal jump's floor outside its flight (take-off to land) and learns
/// the result as the high jump.
pub fn learn_primitives(
    config: &HighJumpConfig,
) -> Result<HighJumpPrimitives, PrimitiveExperimentError> {
    let model = &config.model;
    let dt = config.normal.frame_time;
    let low = Primitive::learn("low_jump", &config.low.to_trajectory(), &config.learn)?;
    let normal = Primitive::learn("normal_jump", &config.normal.to_trajectory(), &config.learn)?;
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
        &config.gamma,
        dt,
        Relearn::Whole,
        &config.learn,
    )?;
    let blended = result
        .primitives
        .into_iter()
        .next()
        .ok_or(PrimitiveExperimentError::NothingRelearned)?;
    // Put the feet back on the floor outside the normal jump's flight, then learn the high jump.
    let normal_roll = on_model(model, &rollout(&normal.primitive, dt)?)?;
    let (root_y, feet) = heights(&normal_roll);
    let ev = find_jump_events(&root_y, dt, Some(&feet), &EventConfig::default())?;
    let mut high_clip = on_model(model, &rollout(&blended.primitive, dt)?)?;
    let floor = lowest_foot(&normal_roll);
    let ground_correction_m = high_clip.keep_feet_on_floor(&[(ev.take_off, ev.land)], floor);
    let high = Primitive::learn("high_jump", &high_clip.to_trajectory(), &config.learn)?;
    Ok(HighJumpPrimitives {
        learned: Jumps { low, normal, high },
        dt,
        ground_correction_m,
    })
}

/// Runs the high jump: [`learn_primitives`], then plays the three jumps on the common span and
/// measures each one's left-knee flexion (crouch peak and whole-clip peak).
pub fn run(config: &HighJumpConfig) -> Result<HighJumpOutcome, PrimitiveExperimentError> {
    let model = &config.model;
    let primitives = learn_primitives(config)?;
    let dt = primitives.dt;
    let learned = &primitives.learned;
    let t = learned.normal.primitive.duration;
    // Rollouts on the common span: the low jump time-scaled to the normal jump's duration.
    let low_scaled = learned.low.primitive.with_duration(t)?;
    let rollouts = Jumps {
        low: rollout(&low_scaled, dt)?,
        normal: rollout(&learned.normal.primitive, dt)?,
        high: rollout(&learned.high.primitive, dt)?,
    };
    let clips = Jumps {
        high: on_model(model, &rollouts.high)?,
        low: on_model(model, &rollouts.low)?,
        normal: on_model(model, &rollouts.normal)?,
    };
    // The paper's knee flexion of a jump is that of its crouch: the peak before take-off.
    let crouch_peak =
        |traj: &Trajectory, clip: &ModelClip| -> Result<f64, PrimitiveExperimentError> {
            let (root_y, feet) = heights(clip);
            let ev = find_jump_events(&root_y, dt, Some(&feet), &EventConfig::default())?;
            let frames = ((ev.take_off / traj.dt).round() as usize).clamp(1, traj.frames() - 1);
            peak_deg(&traj.slice_frames(0, frames)?, "left_knee")
        };
    let crouch = Jumps {
        low: crouch_peak(&rollouts.low, &clips.low)?,
        normal: crouch_peak(&rollouts.normal, &clips.normal)?,
        high: crouch_peak(&rollouts.high, &clips.high)?,
    };
    let whole = Jumps {
        low: peak_deg(&rollouts.low, "left_knee")?,
        normal: peak_deg(&rollouts.normal, "left_knee")?,
        high: peak_deg(&rollouts.high, "left_knee")?,
    };
    let expected = 1.5 * crouch.normal - 0.5 * crouch.low;
    Ok(HighJumpOutcome {
        duration_s: t,
        rollouts,
        clips,
        high_minus_expected_deg: crouch.high - expected,
        crouch_knee_flexion_deg: crouch,
        whole_clip_knee_flexion_deg: whole,
        expected_high_deg: expected,
        primitives,
    })
}
