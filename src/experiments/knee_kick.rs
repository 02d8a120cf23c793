//! The motor-primitive paper's §4.2: a jumping knee kick. A is the high jump of
//! [`high_jump`](super::high_jump) (Start … Land); B, a knee kick from its start to the strike,
//! is time-scaled and placed from A's Bend (deepest crouch) to its Leap (hips highest) and
//! blended with γ(t′) = 1 − t′ (A's posture at Bend, the kick's at Leap); the blend is re-learned
//! as two primitives split at Leap, "jumping knee kick" and "land", which are then connected
//! (each starts from the state the previous one ended in, so the junction has no jump).
//!
//! **What is blended for the root.** The joint angles are blended as the paper says; the root
//! (pelvis position and orientation) is the jump's (γ = 1 for the root channels). The kick is
//! demonstrated standing on one foot: blending its root in would, at Leap where γ = 0, put the
//! pelvis back at standing height, a kick on the ground. A jumping kick is a jump whose legs do
//! the kick, so the pelvis keeps the jump's ballistic flight and apex. Because the blended legs
//! are not the jump's, the root height is then solved so that the lowest foot point stands on the
//! floor before take-off (the correction fading to zero at Leap, the apex), and after the
//! connection the "land" part is learned again from the landing as it is played (the
//! connection's pull from the kick posture back onto the jump's course) with the feet on the
//! floor from Land on, so that the figure lands without sinking. What the parts' DMP fits and
//! the connection still miss by (millimetres) is taken up by the floor constraint on the
//! connected motion ([`FigureClip::lift_above_floor`], as on the high jump's rollouts): no foot
//! goes below the floor.
//!
//! [`run`] returns the primitives, the played motions and the paper's checks: the postures at
//! Bend and Leap, the jumps at the junction, the figure airborne at Leap and both feet down
//! after landing. Plain data in and out: the demonstrations come as [`FigureClip`]s already on
//! the model, nothing is read or written. Playing the connected sequence in an ECS world is left
//! to the caller.

use super::high_jump::{
    HighJumpConfig, HighJumpPrimitives, PrimitiveExperimentError, heights, learn_primitives,
    on_figure, peak_deg, rollout,
};
use super::jump_figures::{JumpFigures, jump_figures, jump_figures_against};
use crate::humanoid::FigureClip;
use crate::primitive::{
    Arrangement, BlendPlacement, Connected, EventConfig, Gamma, JumpEvents, Learned, Primitive,
    ROOT_DOF_NAMES, Relearn, Samples, Trajectory, blend, connect, find_jump_events,
};

/// The paper's γ for the kick: a ramp from 1 to 0, γ(t′) = 1 − t′.
pub const PAPER_GAMMA: Gamma = Gamma::Ramp { from: 1.0, to: 0.0 };

/// How long after Land both feet must be down, seconds.
pub const SETTLE_AFTER_LAND_S: f64 = 0.25;

/// Farthest a foot may be from the jump's floor at Land + [`SETTLE_AFTER_LAND_S`] to count as
/// down (above it, or through it), metres ([`crate::humanoid::FOOT_DOWN_M`]).
pub const FOOT_DOWN_M: f64 = crate::humanoid::FOOT_DOWN_M;

/// The inputs of the jumping knee kick.
#[derive(Clone, Debug, PartialEq)]
pub struct KneeKickConfig {
    /// How A, the high jump, is made; its model and learning settings are also those of the kick
    /// and of the two re-learned parts.
    pub jump: HighJumpConfig,
    /// The knee kick demonstration (B) on the jump's model, from its start to the strike (knee
    /// highest).
    pub kick: FigureClip,
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
    /// A as a clip on the model, lifted where a foot went below the floor.
    pub jump_clip: FigureClip,
    /// A's events (Start, Bend, take-off, Leap, Land), seconds, found on `jump_clip`.
    pub events: JumpEvents,
    /// B learned from the kick demonstration (`knee_kick`).
    pub kick: Learned,
    /// B played over its own duration.
    pub kick_rollout: Trajectory,
    /// B as a clip on the model.
    pub kick_clip: FigureClip,
    /// B time-scaled to Leap − Bend, played from its own start (it is placed at `events.bend`).
    pub kick_placed_rollout: Trajectory,
    /// Which of the six arrangements the placement (A on [0, T_A], B on [Bend, Leap]) is.
    pub arrangement: Arrangement,
    /// The blend re-learned and split at Leap: `jumping_knee_kick`, then `land` (learned from the
    /// connected landing with its feet on the floor).
    pub parts: [Learned; 2],
    /// The two parts connected, sampled at `jump.dt`.
    pub connected: Connected,
    /// The connected motion as a clip on the model, lifted where a foot of it went below the
    /// floor ([`FigureClip::lift_above_floor`]; `connected` is the motion as the primitives play
    /// it, before the lift).
    pub result_clip: FigureClip,
    /// The largest lift that put `result_clip`'s feet on or above the floor, metres.
    pub floor_lift_m: f64,
    /// The jumps at the junction.
    pub junction: JunctionFigures,
    /// The result's posture at Bend and at Leap against A's and the kick's.
    pub posture_gap_deg: PostureGaps,
    /// Each foot's lowest point above A's floor at Land + [`SETTLE_AFTER_LAND_S`], metres.
    pub feet_above_floor_after_landing_m: Vec<f64>,
    /// Every foot within [`FOOT_DOWN_M`] of the floor then.
    pub lands_with_both_feet: bool,
    /// Each foot's lowest point above A's floor at Leap, `[left, right]`, metres.
    pub feet_above_floor_at_leap_m: [f64; 2],
    /// The result's root at Leap minus A's apex (its root at Leap), metres.
    pub root_at_leap_minus_jump_apex_m: f64,
    /// Both feet above the floor (by more than the contact threshold) at Leap.
    pub airborne_at_leap: bool,
    /// What A did (apex above standing, flight, lowest foot).
    pub jump_figures: JumpFigures,
    /// What the jumping knee kick did, on A's floor.
    pub figures: JumpFigures,
    /// Largest root-height correction that stood the blend's feet on the floor before take-off,
    /// metres.
    pub ground_correction_m: f64,
    /// Largest root-height correction that stood the landing's feet on the floor, metres.
    pub landing_correction_m: f64,
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
/// `config.gamma` for the joints and A's root (see the module docs); stands the feet on the
/// floor; learns the two parts split at Leap, connects them, learns "land" again from the
/// connected landing with its feet on the floor, connects again and measures the result.
pub fn run(config: &KneeKickConfig) -> Result<KneeKickOutcome, PrimitiveExperimentError> {
    config.gamma.validate()?;
    config.jump.gamma.validate()?;
    let model = &config.jump.model;
    let learn = &config.jump.learn;
    let jump = learn_primitives(&config.jump)?;
    let dt = jump.dt;
    let played = play_jump(config, &jump)?;
    let kick = Primitive::learn("knee_kick", &config.kick.to_trajectory(), learn)?;
    let blended = blend_kick_into_jump(config, &jump, &played, &kick.primitive)?;
    let (parts, landing_correction_m) = learn_parts(config, &jump, &blended)?;
    let sequence: Vec<Primitive> = parts.iter().map(|l| l.primitive.clone()).collect();
    let connected = connect(&sequence, dt, None)?;
    let junction = connected.junctions.first();
    let junction = JunctionFigures {
        time_s: junction.map(|j| j.time),
        max_angle_jump_deg: junction.map_or(0.0, |j| j.max_angle_jump.to_degrees()),
        max_velocity_jump_deg_s: junction.map_or(0.0, |j| j.max_velocity_jump.to_degrees()),
    };
    // The floor constraint on the connected motion: the parts' DMP fits and the connection's
    // pull reproduce the landing to within millimetres, which puts a foot that far through the
    // floor; the root is lifted by the depth where it is.
    let mut result_clip = on_figure(model, &connected.trajectory)?;
    let floor_lift_m = result_clip.lift_above_floor(jump.floor_y_m);
    let checks = paper_checks(config, &jump, &played, &result_clip);
    let ev = played.events;
    let kick_rollout = rollout(&kick.primitive, dt)?;
    let kick_clip = on_figure(model, &kick_rollout)?;
    let kick_placed_rollout = rollout(&kick.primitive.with_duration(ev.leap - ev.bend)?, dt)?;
    let peak_knee_flexion_deg = KneePeaks {
        right_knee: peak_deg(&connected.trajectory, "right_knee")?,
        left_knee: peak_deg(&connected.trajectory, "left_knee")?,
    };
    Ok(KneeKickOutcome {
        figures: jump_figures_against(&result_clip, &jump.contact_reference),
        jump_figures: played.figures,
        jump,
        jump_rollout: played.rollout,
        jump_clip: played.clip,
        events: ev,
        kick,
        kick_rollout,
        kick_clip,
        kick_placed_rollout,
        arrangement: blended.arrangement,
        parts,
        connected,
        result_clip,
        floor_lift_m,
        junction,
        posture_gap_deg: checks.posture_gap_deg,
        feet_above_floor_after_landing_m: checks.feet_after_landing,
        lands_with_both_feet: checks.lands_with_both_feet,
        feet_above_floor_at_leap_m: checks.feet_above_floor_at_leap_m,
        root_at_leap_minus_jump_apex_m: checks.root_at_leap_minus_jump_apex_m,
        airborne_at_leap: checks.airborne_at_leap,
        ground_correction_m: blended.ground_correction_m,
        landing_correction_m,
        peak_knee_flexion_deg,
    })
}

/// The high jump A as played: its rollout on the model with the floor constraint, its
/// events, figures and flight.
struct PlayedJump {
    rollout: Trajectory,
    clip: FigureClip,
    /// The root's height in each frame of `clip`, metres.
    root_y: Vec<f64>,
    events: JumpEvents,
    figures: JumpFigures,
    /// Take-off and landing (both feet off the floor between), seconds.
    flight: (f64, f64),
}

/// Plays A and finds its events (Bend, Leap, Land) and flight.
fn play_jump(
    config: &KneeKickConfig,
    jump: &HighJumpPrimitives,
) -> Result<PlayedJump, PrimitiveExperimentError> {
    let floor = jump.floor_y_m;
    let rollout = rollout(&jump.learned.high.primitive, jump.dt)?;
    let mut clip = on_figure(&config.jump.model, &rollout)?;
    // The floor constraint on the rollout, as the high jump's own clips have it.
    clip.lift_above_floor(floor);
    let (root_y, feet) = heights(&clip);
    let events = find_jump_events(&root_y, jump.dt, Some(&feet), &config.events)?;
    // Reported as the high jump's scene measures it (against the normal jump's contacts); the
    // floor constraint below keeps the feet down outside the span where this clip's own feet
    // (their own rest heights) are off the floor.
    let figures = jump_figures_against(&clip, &jump.contact_reference);
    let flight = jump_figures(&clip, floor).flight.ok_or_else(|| {
        PrimitiveExperimentError::NoFlight("the high jump never has both feet off the floor".into())
    })?;
    Ok(PlayedJump {
        rollout,
        clip,
        root_y,
        events,
        figures,
        flight: (flight.start_s, flight.end_s),
    })
}

/// The kick B blended into A, with A's root, its feet stood on the floor before take-off.
struct BlendedKick {
    /// The blend's trajectory.
    trajectory: Trajectory,
    /// A sampled at the blend's frames.
    on_a: Samples,
    arrangement: Arrangement,
    /// Frames of Leap (the end of B) and of A's landing.
    leap: usize,
    land: usize,
    ground_correction_m: f64,
}

/// Blends B placed on [Bend, Leap] into A with `config.gamma`, takes the root from A and stands
/// the feet on the floor up to take-off and from landing on (the correction zero at Leap).
fn blend_kick_into_jump(
    config: &KneeKickConfig,
    jump: &HighJumpPrimitives,
    played: &PlayedJump,
    kick: &Primitive,
) -> Result<BlendedKick, PrimitiveExperimentError> {
    let a = &jump.learned.high.primitive;
    let ev = &played.events;
    let placement = BlendPlacement {
        a_start: 0.0,
        a_end: a.duration,
        b_start: ev.bend,
        b_end: ev.leap,
    };
    let learn = &config.jump.learn;
    let result = blend(
        a,
        kick,
        &placement,
        &config.gamma,
        jump.dt,
        Relearn::No,
        learn,
    )?;
    // The joints from the blend, the root from the jump.
    let mut traj = result.trajectory;
    let step = traj.dt;
    let n = traj.frames() - 1;
    let times: Vec<f64> = (0..=n).map(|k| k as f64 * step).collect();
    let on_a = a.sample(&times, None)?;
    let d = traj.dofs();
    for name in ROOT_DOF_NAMES {
        let j = traj
            .index_of(name)
            .ok_or_else(|| PrimitiveExperimentError::NoDof(name.into()))?;
        for k in 0..=n {
            traj.values[k * d + j] = on_a.values[k * d + j];
        }
    }
    let frame = |t: f64| ((t / step).round() as usize).min(n);
    let (take_off, leap, land) = (
        frame(played.flight.0),
        result.b_end_frame,
        frame(played.flight.1),
    );
    let mut blended = on_figure(&config.jump.model, &traj)?;
    let ground_correction_m = stand_on_floor(
        &mut blended,
        0,
        &|k| k <= take_off || k >= land,
        leap,
        jump.floor_y_m,
    );
    Ok(BlendedKick {
        trajectory: blended.to_trajectory(),
        on_a,
        arrangement: result.arrangement,
        leap,
        land,
        ground_correction_m,
    })
}

/// Re-learns the blend as two primitives split at Leap, "jumping knee kick" and "land" (from
/// A's pose at Leap, the right limit of the blend), then "land" again from the landing as the
/// connection plays it, its feet stood on the floor from Land on. Returns the two parts and
/// the landing's largest correction, metres.
fn learn_parts(
    config: &KneeKickConfig,
    jump: &HighJumpPrimitives,
    blended: &BlendedKick,
) -> Result<([Learned; 2], f64), PrimitiveExperimentError> {
    let learn = &config.jump.learn;
    let (leap, land) = (blended.leap, blended.land);
    let traj = &blended.trajectory;
    let (n, d) = (traj.frames() - 1, traj.dofs());
    let first = traj.slice_frames(0, leap)?;
    let mut second = traj.slice_frames(leap, n)?;
    second.values[..d].copy_from_slice(&blended.on_a.values[leap * d..(leap + 1) * d]);
    let part = |name: &str, t: &Trajectory| -> Result<Learned, PrimitiveExperimentError> {
        let mut l = Primitive::learn(name, t, learn)?;
        l.primitive.name = name.into();
        Ok(l)
    };
    let kick_part = part("jumping_knee_kick", &first)?;
    let land_part = part("land", &second)?;
    let played = connect(
        &[kick_part.primitive.clone(), land_part.primitive],
        jump.dt,
        None,
    )?;
    let mut landing = on_figure(&config.jump.model, &played.trajectory)?;
    let last = landing.frame_count() - 1;
    let landing_correction_m = stand_on_floor(
        &mut landing,
        leap,
        &|k| k >= land.min(last),
        leap,
        jump.floor_y_m,
    );
    let landing = landing.to_trajectory().slice_frames(leap, last)?;
    Ok(([kick_part, part("land", &landing)?], landing_correction_m))
}

/// The paper's checks on the connected motion `result_clip`.
struct PaperChecks {
    posture_gap_deg: PostureGaps,
    feet_above_floor_at_leap_m: [f64; 2],
    airborne_at_leap: bool,
    root_at_leap_minus_jump_apex_m: f64,
    feet_after_landing: Vec<f64>,
    lands_with_both_feet: bool,
}

/// Checks of the paper's figure: the jump's posture at Bend, the kick's at Leap, in the air at
/// Leap, both feet down after landing.
fn paper_checks(
    config: &KneeKickConfig,
    jump: &HighJumpPrimitives,
    played: &PlayedJump,
    result_clip: &FigureClip,
) -> PaperChecks {
    let (dt, floor, ev) = (jump.dt, jump.floor_y_m, &played.events);
    let frame_at = |t: f64| ((t / dt).round() as usize).min(result_clip.frame_count() - 1);
    let posture_gap = |a_clip: &FigureClip, fa: usize, fb: usize| -> f64 {
        a_clip
            .frame_angles(fa)
            .iter()
            .zip(result_clip.frame_angles(fb))
            .map(|(x, y)| (x - y).abs().to_degrees())
            .fold(0.0, f64::max)
    };
    let kick_end = config.kick.frame_count() - 1;
    let posture_gap_deg = PostureGaps {
        jump_at_bend_deg: posture_gap(&played.clip, frame_at(ev.bend), frame_at(ev.bend)),
        kick_at_leap_deg: posture_gap(&config.kick, kick_end, frame_at(ev.leap)),
    };
    let (result_root, result_feet) = heights(result_clip);
    let at_leap = frame_at(ev.leap);
    let feet_above_floor_at_leap_m = [
        result_feet[0][at_leap] - floor,
        result_feet[1][at_leap] - floor,
    ];
    let airborne_at_leap = feet_above_floor_at_leap_m
        .iter()
        .all(|h| *h > super::jump_figures::CONTACT_THRESHOLD_M);
    let root_at_leap_minus_jump_apex_m = result_root[at_leap] - played.root_y[frame_at(ev.leap)];
    let settle = frame_at(ev.land + SETTLE_AFTER_LAND_S);
    let feet_after_landing: Vec<f64> = result_feet
        .iter()
        .map(|foot| foot[settle.min(foot.len() - 1)] - floor)
        .collect();
    let lands_with_both_feet = feet_after_landing.iter().all(|h| h.abs() < FOOT_DOWN_M);
    PaperChecks {
        posture_gap_deg,
        feet_above_floor_at_leap_m,
        airborne_at_leap,
        root_at_leap_minus_jump_apex_m,
        feet_after_landing,
        lands_with_both_feet,
    }
}

/// Raises or lowers the root of frames `from..` of `clip` so that at every `ground` frame the
/// lowest foot point (ankles and toes) is at `floor` (metres); at frame `pinned` the correction
/// is zero, and between these frames it is interpolated linearly (held beyond the last known
/// one). Returns the largest correction, metres.
fn stand_on_floor(
    clip: &mut FigureClip,
    from: usize,
    ground: &dyn Fn(usize) -> bool,
    pinned: usize,
    floor: f64,
) -> f64 {
    let [left, right] = clip.foot_heights();
    let n = clip.frame_count();
    let known: Vec<(usize, f64)> = (from..n)
        .filter_map(|k| {
            if k == pinned {
                Some((k, 0.0))
            } else if ground(k) {
                Some((k, floor - left[k].min(right[k])))
            } else {
                None
            }
        })
        .collect();
    if known.is_empty() {
        return 0.0;
    }
    let mut largest: f64 = 0.0;
    for k in from..n {
        let i = known.partition_point(|(f, _)| *f < k);
        let c = match (known.get(i.wrapping_sub(1)), known.get(i)) {
            (_, Some(&(f, c))) if f == k => c,
            (Some(&(f0, c0)), Some(&(f1, c1))) => {
                c0 + (c1 - c0) * (k - f0) as f64 / (f1 - f0) as f64
            }
            (Some(&(_, c)), None) | (None, Some(&(_, c))) => c,
            (None, None) => 0.0,
        };
        clip.root_translation[k].y += c;
        largest = largest.max(c.abs());
    }
    largest
}
