//! The motor-primitive paper's §4.2: a jumping knee kick. A is the high jump of
//! [`high_jump`](super::high_jump) (Start … Land); B, a knee kick from its start to the strike,
//! is time-scaled and placed from A's Bend (deepest crouch) to its Leap (hips highest) and
//! blended with γ(t′) = 1 − t′ (A's posture at Bend, the kick's at Leap); the blend is re-learned
//! as two primitives split at Leap, "jumping knee kick" and "land", which are then connected
//! (each starts from the state the previous one ended in, so the junction has no jump).
//!
//! [`run`] returns the primitives, the played motions and the paper's checks: the postures at
//! Bend and Leap, the jumps at the junction, both feet down after landing. Plain data in and out:
//! the demonstrations come as [`ModelClip`]s already on the model, nothing is read or written.
//! Playing the connected sequence in an ECS world is left to the caller.

use super::high_jump::{
    HighJumpConfig, HighJumpPrimitives, PrimitiveExperimentError, heights, learn_primitives,
    lowest_foot, on_model, peak_deg, rollout,
};
use crate::humanoid::ModelClip;
use crate::primitive::{
    Arrangement, BlendPlacement, Connected, EventConfig, Gamma, JumpEvents, Learned, Primitive,
    Relearn, Trajectory, blend, connect, find_jump_events,
};

/// The paper's γ for the kick: a ramp from 1 to 0, γ(t′) = 1 − t′.
pub const PAPER_GAMMA: Gamma = Gamma::Ramp { from: 1.0, to: 0.0 };

/// How long after Land both feet must be down, seconds.
pub const SETTLE_AFTER_LAND_S: f64 = 0.25;

/// Highest a foot may be above the jump's floor at Land + [`SETTLE_AFTER_LAND_S`] to count as
/// down, metres.
pub const FOOT_DOWN_M: f64 = 0.05;

/// The inputs of the jumping knee kick.
#[derive(Clone, Debug, PartialEq)]
pub struct KneeKickConfig {
    /// How A, the high jump, is made; its model and learning settings are also those of the kick
    /// and of the two re-learned parts.
    pub jump: HighJumpConfig,
    /// The knee kick demonstration (B) on the jump's model, from its start to the strike (knee
    /// highest).
    pub kick: ModelClip,
    /// γ(t′) of the kick blend (the paper: [`PAPER_GAMMA`]).
    pub gamma: Gamma,
    /// Jump-event detection on A.
    pub events: EventConfig,
}

/// The jumps at the junction of the two parts.
#[derive(Clone, Debug, PartialEq)]
pub struct JunctionFigures {
    /// Time of the junction from the start of the sequence, seconds (`None` without a junction).
    pub time_s: Option<f64>,
    /// Largest jump in any DOF's value across the junction, degrees (0 without a junction).
    pub max_angle_jump_deg: f64,
    /// Largest jump in any DOF's rate across the junction, degrees per second.
    pub max_velocity_jump_deg_s: f64,
}

/// How far the result's posture is from the postures the blend should hand over to: the
/// largest difference over the DOFs, degrees.
#[derive(Clone, Debug, PartialEq)]
pub struct PostureGaps {
    /// The result at Bend vs the high jump at Bend (γ = 1 there).
    pub jump_at_bend_deg: f64,
    /// The result at Leap vs the kick demonstration's last frame (γ = 0 there).
    pub kick_at_leap_deg: f64,
}

/// Peak knee flexion of the jumping knee kick, degrees.
#[derive(Clone, Debug, PartialEq)]
pub struct KneePeaks {
    /// Left knee.
    pub left_knee: f64,
    /// Right knee (the kicking knee).
    pub right_knee: f64,
}

/// Everything the jumping knee kick found.
#[derive(Clone, Debug, PartialEq)]
pub struct KneeKickOutcome {
    /// A and the jumps it came from (see [`learn_primitives`]); the time step of every rollout
    /// is `jump.dt`.
    pub jump: HighJumpPrimitives,
    /// A played over its duration.
    pub jump_rollout: Trajectory,
    /// A as a clip on the model.
    pub jump_clip: ModelClip,
    /// A's events (Start, Bend, take-off, Leap, Land), seconds, found on `jump_clip`.
    pub events: JumpEvents,
    /// B learned from the kick demonstration (`knee_kick`).
    pub kick: Learned,
    /// B played over its own duration.
    pub kick_rollout: Trajectory,
    /// B as a clip on the model.
    pub kick_clip: ModelClip,
    /// B time-scaled to Leap − Bend, played from its own start (it is placed at `events.bend`).
    pub kick_placed_rollout: Trajectory,
    /// Which of the six arrangements the placement (A on [0, T_A], B on [Bend, Leap]) is.
    pub arrangement: Arrangement,
    /// The blend re-learned and split at Leap: `jumping_knee_kick`, then `land`.
    pub parts: [Learned; 2],
    /// The two parts connected, sampled at `jump.dt`.
    pub connected: Connected,
    /// The connected motion as a clip on the model.
    pub result_clip: ModelClip,
    /// The jumps at the junction.
    pub junction: JunctionFigures,
    /// The result's posture at Bend and at Leap against A's and the kick's.
    pub posture_gap_deg: PostureGaps,
    /// Each foot's lowest point above A's floor at Land + [`SETTLE_AFTER_LAND_S`], metres.
    pub feet_above_floor_after_landing_m: Vec<f64>,
    /// Every foot within [`FOOT_DOWN_M`] of the floor then.
    pub lands_with_both_feet: bool,
    /// Peak knee flexion of the connected motion.
    pub peak_knee_flexion_deg: KneePeaks,
}

impl KneeKickOutcome {
    /// The connected sequence: the two parts' primitives in order.
    pub fn sequence(&self) -> Vec<Primitive> {
        self.parts.iter().map(|l| l.primitive.clone()).collect()
    }
}

/// Runs the jumping knee kick: learns the high jump A ([`learn_primitives`]) and finds its
/// events; learns the kick B; blends B placed on [Bend, Leap] into A (on [0, T_A]) with
/// `config.gamma`, re-learned split at Leap; connects the two parts and measures them.
pub fn run(config: &KneeKickConfig) -> Result<KneeKickOutcome, PrimitiveExperimentError> {
    let model = &config.jump.model;
    let learn = &config.jump.learn;
    let jump = learn_primitives(&config.jump)?;
    let dt = jump.dt;
    let a = &jump.learned.high.primitive;
    let jump_rollout = rollout(a, dt)?;
    let jump_clip = on_model(model, &jump_rollout)?;
    let (root_y, feet) = heights(&jump_clip);
    let ev = find_jump_events(&root_y, dt, Some(&feet), &config.events)?;

    let kick_demo = &config.kick;
    let kick = Primitive::learn("knee_kick", &kick_demo.to_trajectory(), learn)?;
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
        &config.gamma,
        dt,
        Relearn::SplitAtBEnd,
        learn,
    )?;
    let found = result.primitives.len();
    let mut parts: [Learned; 2] = result
        .primitives
        .try_into()
        .map_err(|_| PrimitiveExperimentError::NotSplitInTwo(found))?;
    parts[0].primitive.name = "jumping_knee_kick".into();
    parts[1].primitive.name = "land".into();
    let sequence: Vec<Primitive> = parts.iter().map(|l| l.primitive.clone()).collect();
    let connected = connect(&sequence, dt, None)?;
    let junction = connected.junctions.first();
    let junction = JunctionFigures {
        time_s: junction.map(|j| j.time),
        max_angle_jump_deg: junction.map_or(0.0, |j| j.max_angle_jump.to_degrees()),
        max_velocity_jump_deg_s: junction.map_or(0.0, |j| j.max_velocity_jump.to_degrees()),
    };
    let result_clip = on_model(model, &connected.trajectory)?;

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
    let kick_end = kick_demo.frame_count() - 1;
    let posture_gap_deg = PostureGaps {
        jump_at_bend_deg: posture_gap(&jump_clip, frame_at(ev.bend), frame_at(ev.bend)),
        kick_at_leap_deg: posture_gap(kick_demo, kick_end, frame_at(ev.leap)),
    };
    let (_, result_feet) = heights(&result_clip);
    let settle = frame_at(ev.land + SETTLE_AFTER_LAND_S);
    let floor = lowest_foot(&jump_clip);
    let feet_after_landing: Vec<f64> = result_feet
        .iter()
        .map(|foot| foot[settle.min(foot.len() - 1)] - floor)
        .collect();
    let lands_with_both_feet = feet_after_landing.iter().all(|h| *h < FOOT_DOWN_M);

    let kick_rollout = rollout(&kick.primitive, dt)?;
    let kick_clip = on_model(model, &kick_rollout)?;
    let kick_placed_rollout = rollout(&kick.primitive.with_duration(ev.leap - ev.bend)?, dt)?;
    let peak_knee_flexion_deg = KneePeaks {
        right_knee: peak_deg(&connected.trajectory, "right_knee")?,
        left_knee: peak_deg(&connected.trajectory, "left_knee")?,
    };
    Ok(KneeKickOutcome {
        jump,
        jump_rollout,
        jump_clip,
        events: ev,
        kick,
        kick_rollout,
        kick_clip,
        kick_placed_rollout,
        arrangement: result.arrangement,
        parts,
        connected,
        result_clip,
        junction,
        posture_gap_deg,
        feet_above_floor_after_landing_m: feet_after_landing,
        lands_with_both_feet,
        peak_knee_flexion_deg,
    })
}
