//! The motor-primitive paper's §4.1: a high jump by extrapolation. A low jump (A) and a normal
//! jump (B) are learned as primitives; A is time-scaled to B's duration so both span [0, T], and
//! the blend `θ = γ·θ_A + (1 − γ)·θ_B` with constant γ = −0.5 gives `1.5·normal − 0.5·low`, a
//! jump deeper than either demonstration.
//!
//! **The root.** The root channels (`root_ty` …) are blended with the joints, pointwise, with
//! the same γ, as a user of DMP blending expects: both jumps stand on one floor and the apex
//! height does not change under time-scaling, so at the apex the blend's root is at about
//! `γ·apex_A + (1 − γ)·apex_B`, the demonstrations' highest root heights over the floor, γ at
//! the normal jump's apex ([`JumpPrediction::apex_root_m`]); the high jump is made to reach that
//! height. (Its apex *above its own standing* is measured from the extrapolated stance, which
//! stands lower wherever it bends the knees more than the demonstrations: the prediction's
//! standing is the blend's with its feet on the floor, [`JumpPrediction::standing_root_m`].)
//! Time-scaling A to B's
//! duration, however, gives both the same flight time, so a pointwise blend keeps the normal
//! jump's flight however high it rises, which no ballistic flight does. So the blend's flight
//! (the normal jump's, from foot contact) is stretched in time by what ballistics says the
//! higher apex needs: from the same take-off and landing heights, a flight over the high apex
//! takes `√(2h_up/g) + √(2h_down/g)` (gravity [`GRAVITY`]), longer than one over the normal
//! jump's apex by [`FlightPlan::extra_flight_s`]; the motion before take-off is unchanged, the
//! landing comes that much later, and the root's arc is scaled to reach the predicted apex
//! exactly ([`FlightPlan::arc_scale`] says how much was needed: on the project's keyframed
//! jumps and on the CMU ones the blend's own arc is within a few per cent of it). Before that
//! the root is raised or lowered so that the lowest foot point stands on the normal jump's
//! floor outside the flight (blending joint angles and root height separately lifts or sinks the
//! feet). The prediction of the flight is then the normal jump's flight plus that ballistic
//! extra time ([`JumpPrediction::flight_s`]); every jump's flight is measured from foot contact
//! against the normal jump's floor and foot-point rest heights, so the three are measured alike.
//!
//! [`learn_primitives`] makes the three primitives (the jumping knee kick of
//! [`knee_kick`](super::knee_kick) starts from them); [`run`] also plays them and measures them:
//! the paper's Fig. 8 (the left knee's crouch flexion of each jump) and what each jump did
//! ([`JumpFigures`]: apex above standing, flight from foot contact, the feet's lowest point).
//! Plain data in and out: the demonstrations come as [`FigureClip`]s already on the model,
//! nothing is read or written.

use super::jump_figures::{JumpFigures, contact_reference, jump_figures_against, standing_root_m};
use crate::analysis::{ContactReference, Span};
use crate::clips::GRAVITY;
use crate::humanoid::{Figure, FigureClip};
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
    OnModel(#[from] crate::humanoid::FigureError),
    /// A DOF the experiment measures is not in the trajectory.
    #[error("no DOF '{0}'")]
    NoDof(String),
    /// The blend re-learned no primitive.
    #[error("the blend re-learned no primitive")]
    NothingRelearned,
    /// A jump whose flight cannot be measured or made: no flight in a demonstration, or an
    /// apex the blend asks for that is not above the take-off and landing heights.
    #[error("{0}")]
    NoFlight(String),
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
    pub model: Figure,
    /// The low jump demonstration (A), on `model`'s DOFs.
    pub low: FigureClip,
    /// The normal jump demonstration (B), on `model`'s DOFs; its frame time is the time step of
    /// every rollout.
    pub normal: FigureClip,
    /// γ(t′) of the blend (the paper: [`PAPER_GAMMA`]).
    pub gamma: Gamma,
    /// Learning settings (formulation, kernels, regression) of every primitive.
    pub learn: LearnConfig,
}

/// What extrapolating the two jumps predicts for the high jump: the crouch and the root apex are
/// `γ·A + (1 − γ)·B` of the low (A) and normal (B) jumps' figures, γ taken where that figure
/// happens in the blend; the standing height is the extrapolated stance's, and the flight follows
/// from the apex by ballistics.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct JumpPrediction {
    /// The blend's span T (the normal jump's duration), seconds: t′ = t / T.
    pub span_s: f64,
    /// The normal jump's Bend, seconds.
    pub normal_bend_s: f64,
    /// The normal jump's apex (root highest), seconds.
    pub normal_apex_s: f64,
    /// γ at the normal jump's Bend (its deepest crouch), normalised time t′ = Bend / T.
    pub gamma_at_bend: f64,
    /// γ at the normal jump's apex (its root highest), t′ = apex / T.
    pub gamma_at_apex: f64,
    /// Left-knee crouch flexion: γ_bend·low + (1 − γ_bend)·normal, degrees.
    pub crouch_knee_flexion_deg: f64,
    /// Root apex over the floor: γ_apex·low + (1 − γ_apex)·normal of the demonstrations' highest
    /// root heights (both on the normal jump's floor), metres. The root channel is blended
    /// pointwise with the same γ as the joints, so this is where the blend's root is at the
    /// apex; the high jump is made to reach it.
    pub apex_root_m: f64,
    /// Root height of the extrapolated stance: the blend's root over its first
    /// [`STANDING_WINDOW_S`](super::jump_figures::STANDING_WINDOW_S) (median) once its feet are
    /// put on the floor, metres. The blended joint angles decide how high a stance with the feet
    /// on the floor holds the root (a deeper knee bend stands lower); the blend of the two
    /// demonstrations' standing heights does not.
    pub standing_root_m: f64,
    /// Root apex above standing: `apex_root_m − standing_root_m`, metres.
    pub apex_above_standing_m: f64,
    /// Flight from foot contact: the normal jump's flight plus what ballistics says the higher
    /// apex adds, [`FlightPlan::extra_flight_s`] (from the same take-off and landing heights),
    /// seconds. The pointwise blend keeps the normal jump's timing (A is time-scaled to B's
    /// span), so the extrapolated apex is the only thing that can change how long the figure is
    /// in the air.
    pub flight_s: f64,
}

/// How the high jump's flight was made from the blend (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct FlightPlan {
    /// Take-off and landing in the blend: the normal jump's flight from foot contact, widened to
    /// where its feet leave and touch the floor ([`STANDING_FOOT_M`]), seconds.
    pub blend_take_off_s: f64,
    /// See `blend_take_off_s`.
    pub blend_land_s: f64,
    /// Root height at take-off and at landing with the feet on the floor, metres.
    pub take_off_root_m: f64,
    /// See `take_off_root_m`.
    pub land_root_m: f64,
    /// The normal jump's root apex over the floor, metres.
    pub normal_apex_root_m: f64,
    /// The root apex the high jump is to reach ([`JumpPrediction::apex_root_m`]), metres.
    pub apex_root_m: f64,
    /// How much longer a ballistic flight over `apex_root_m` is than one over
    /// `normal_apex_root_m`, from the same take-off and landing heights, seconds.
    pub extra_flight_s: f64,
    /// How much longer the high jump is than the blend (`extra_flight_s` to whole frames),
    /// seconds.
    pub stretch_s: f64,
    /// The factor on the blend's root arc (over the line from take-off to landing) that puts
    /// its top at `apex_root_m` (1: the blend's own root already rose that high).
    pub arc_scale: f64,
}

/// The three primitives of the high jump, as [`learn_primitives`] makes them.
#[derive(Clone, Debug, PartialEq)]
pub struct HighJumpPrimitives {
    /// The learned jumps with their fits: `low_jump` and `normal_jump` from the demonstrations,
    /// `high_jump` from the blend with its feet put back on the floor and its flight made
    /// ballistic.
    pub learned: Jumps<Learned>,
    /// The time step of the rollouts: the normal jump's frame time, seconds.
    pub dt: f64,
    /// The floor the jumps stand on: where the normal jump's feet touch, metres.
    pub floor_y_m: f64,
    /// The floor and foot-point rest heights of the normal jump, which every jump's contacts
    /// and flight are measured against ([`jump_figures_against`]).
    pub contact_reference: ContactReference,
    /// Largest root-height correction that put the blend's feet back on the floor, metres.
    pub ground_correction_m: f64,
    /// The low and normal demonstrations measured (at their own durations).
    pub demo_figures: [JumpFigures; 2],
    /// What extrapolating them predicts.
    pub prediction: JumpPrediction,
    /// How the high jump's flight was made.
    pub flight: FlightPlan,
}

/// Everything the high jump found.
#[derive(Clone, Debug, PartialEq)]
pub struct HighJumpOutcome {
    /// The three primitives.
    pub primitives: HighJumpPrimitives,
    /// The common span T of the blend: the normal jump's duration, seconds (the high jump is
    /// longer by `primitives.flight.stretch_s`).
    pub duration_s: f64,
    /// Rollouts at `dt`: the low jump time-scaled to T (as it is blended), the normal jump over
    /// [0, T] and the high jump over its own, longer, duration.
    pub rollouts: Jumps<Trajectory>,
    /// Each jump played over its own duration (the low jump not time-scaled) as a clip on the
    /// model.
    pub clips: Jumps<FigureClip>,
    /// The low jump time-scaled to T as a clip (`rollouts.low`).
    pub low_time_scaled: FigureClip,
    /// How far each of `clips` was lifted where a foot of its rollout went below the floor
    /// ([`FigureClip::lift_above_floor`]), metres: the largest lift.
    pub floor_lift_m: Jumps<f64>,
    /// What each of `clips` did: apex above standing, flight from foot contact, lowest foot.
    pub figures: Jumps<JumpFigures>,
    /// Left-knee flexion of each jump's crouch, degrees: the peak before take-off (found by
    /// [`find_jump_events`] on each rollout), as in the paper's Fig. 8.
    pub crouch_knee_flexion_deg: Jumps<f64>,
    /// Left-knee flexion peak over each whole rollout, degrees (for a low jump this can be the
    /// landing rather than the crouch).
    pub whole_clip_knee_flexion_deg: Jumps<f64>,
    /// The expected crouch flexion of the high jump, `γ·low + (1 − γ)·normal` with γ at the
    /// normal jump's Bend (the paper: `1.5·normal − 0.5·low`), degrees
    /// (`prediction.crouch_knee_flexion_deg`).
    pub expected_high_deg: f64,
    /// `crouch_knee_flexion_deg.high − expected_high_deg`, degrees.
    pub high_minus_expected_deg: f64,
}

/// A trajectory as a clip on `model`.
pub(super) fn on_figure(
    model: &Figure,
    traj: &Trajectory,
) -> Result<FigureClip, PrimitiveExperimentError> {
    Ok(FigureClip::from_trajectory(model, traj)?)
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
pub(super) fn heights(clip: &FigureClip) -> (Vec<f64>, Vec<Vec<f64>>) {
    let root: Vec<f64> = clip.root_translation.iter().map(|t| t.y).collect();
    (root, clip.foot_heights().into())
}

/// Learns the low and normal jumps, blends them with `config.gamma` over the common span
/// (`a = [0, T]`, `b = [0, T]`, T the normal jump's duration), puts the blend's feet on the
/// normal jump's floor outside its flight, makes the flight ballistic up to the predicted apex
/// ([`JumpPrediction`], see the module docs) and learns the result as the high jump.
pub fn learn_primitives(
    config: &HighJumpConfig,
) -> Result<HighJumpPrimitives, PrimitiveExperimentError> {
    config.gamma.validate()?;
    let model = &config.model;
    let dt = config.normal.frame_time;
    let low = Primitive::learn("low_jump", &config.low.to_trajectory(), &config.learn)?;
    let normal = Primitive::learn("normal_jump", &config.normal.to_trajectory(), &config.learn)?;
    let t = normal.primitive.duration;
    // What the demonstrations did, each at its own duration, on the normal jump's floor.
    let mut normal_clip = on_figure(model, &rollout(&normal.primitive, dt)?)?;
    let mut low_clip = on_figure(model, &rollout(&low.primitive, dt)?)?;
    // The normal jump's floor and foot rest heights: every jump is measured against them.
    let reference = contact_reference(&normal_clip)
        .ok_or_else(|| PrimitiveExperimentError::NoFlight("the model has no feet".into()))?;
    let floor = reference.floor_y_m;
    // Measured as `run` writes them: with the floor constraint.
    normal_clip.lift_above_floor(floor);
    low_clip.lift_above_floor(floor);
    let demo_figures = [
        jump_figures_against(&low_clip, &reference),
        jump_figures_against(&normal_clip, &reference),
    ];
    let [fl, fn_] = demo_figures;
    let normal_flight = fn_.flight.ok_or_else(|| {
        PrimitiveExperimentError::NoFlight(
            "the normal jump never has both feet off the floor".into(),
        )
    })?;
    if fl.flight.is_none() {
        return Err(PrimitiveExperimentError::NoFlight(
            "the low jump never has both feet off the floor".into(),
        ));
    }
    let (root_y, feet) = heights(&normal_clip);
    let ev = find_jump_events(&root_y, dt, Some(&feet), &EventConfig::default())?;
    let gamma_at_bend = config.gamma.at(ev.bend / t);
    let gamma_at_apex = config.gamma.at(fn_.apex_time_s / t);
    let mix = |g: f64, a: f64, b: f64| g * a + (1.0 - g) * b;
    let crouch = |c: &FigureClip| crouch_peak_deg(c, dt);
    let crouch_knee_flexion_deg = mix(gamma_at_bend, crouch(&low_clip)?, crouch(&normal_clip)?);
    let apex_root_m = mix(gamma_at_apex, fl.apex_root_m, fn_.apex_root_m);

    let mut blended = blend_jumps(config, (&low.primitive, &normal.primitive), t, dt)?;
    let (take_off, land) = feet_leave_and_touch(&normal_clip, normal_flight, floor);
    let ground_correction_m = blended.keep_feet_on_floor(&[(take_off, land)], floor);
    let (high_clip, flight) =
        lengthen_flight(&blended, take_off, land, apex_root_m, fn_.apex_root_m)?;
    let standing = standing_root_m(&blended);
    let prediction = JumpPrediction {
        span_s: t,
        normal_bend_s: ev.bend,
        normal_apex_s: fn_.apex_time_s,
        gamma_at_bend,
        gamma_at_apex,
        crouch_knee_flexion_deg,
        apex_root_m,
        standing_root_m: standing,
        apex_above_standing_m: apex_root_m - standing,
        flight_s: fn_.flight_s + flight.extra_flight_s,
    };
    let high = Primitive::learn("high_jump", &high_clip.to_trajectory(), &config.learn)?;
    Ok(HighJumpPrimitives {
        learned: Jumps { low, normal, high },
        dt,
        floor_y_m: floor,
        contact_reference: reference,
        ground_correction_m,
        demo_figures,
        prediction,
        flight,
    })
}

/// The paper's blend of the low jump A and the normal jump B with `config.gamma`: A
/// time-scaled to B's duration `t`, both on [0, T], played on the model at `dt`.
fn blend_jumps(
    config: &HighJumpConfig,
    (low, normal): (&Primitive, &Primitive),
    t: f64,
    dt: f64,
) -> Result<FigureClip, PrimitiveExperimentError> {
    let placement = BlendPlacement {
        a_start: 0.0,
        a_end: t,
        b_start: 0.0,
        b_end: t,
    };
    let result = blend(
        low,
        normal,
        &placement,
        &config.gamma,
        dt,
        Relearn::No,
        &config.learn,
    )?;
    on_figure(&config.model, &result.trajectory)
}

/// Height above the floor under which a foot still stands on it when the flight's ends are
/// placed ([`feet_leave_and_touch`]), metres.
pub const STANDING_FOOT_M: f64 = 0.005;

/// Where a flight found by foot contact really begins and ends (contact detection counts a foot
/// as off the floor only some centimetres up, so its flight starts after the feet leave and ends
/// before they touch): from its start back, and from its end forward, the lowest foot point of
/// `clip` is followed down to the first frame where it is within [`STANDING_FOOT_M`] of `floor`
/// or stops coming down. Seconds.
fn feet_leave_and_touch(clip: &FigureClip, flight: Span, floor: f64) -> (f64, f64) {
    let [l, r] = clip.foot_heights();
    let dt = clip.frame_time;
    let low: Vec<f64> = l.iter().zip(&r).map(|(a, b)| a.min(*b)).collect();
    let n = low.len();
    let down = |k: usize, next: usize| low[k] - floor <= STANDING_FOOT_M || low[next] >= low[k];
    let start = ((flight.start_s / dt).round() as usize).min(n - 1);
    let end = ((flight.end_s / dt).round() as usize).min(n - 1);
    let leave = (1..=start).rev().find(|&k| down(k, k - 1)).unwrap_or(0);
    let touch = (end..n - 1).find(|&k| down(k, k + 1)).unwrap_or(n - 1);
    (leave as f64 * dt, touch as f64 * dt)
}

/// Left-knee flexion of a jump's crouch, degrees: its peak before take-off (found by
/// [`find_jump_events`]), as in the paper's Fig. 8.
fn crouch_peak_deg(clip: &FigureClip, dt: f64) -> Result<f64, PrimitiveExperimentError> {
    let (root_y, feet) = heights(clip);
    let ev = find_jump_events(&root_y, dt, Some(&feet), &EventConfig::default())?;
    let traj = clip.to_trajectory();
    let frames = ((ev.take_off / dt).round() as usize).clamp(1, traj.frames() - 1);
    peak_deg(&traj.slice_frames(0, frames)?, "left_knee")
}

/// The time a ballistic flight (gravity [`GRAVITY`]) takes from height `y0` over an apex at
/// `apex` down to `y1`: `√(2(apex − y0)/g) + √(2(apex − y1)/g)`, seconds (a leg below zero
/// counts as zero).
pub fn ballistic_flight_s(y0: f64, apex: f64, y1: f64) -> f64 {
    let leg = |h: f64| (2.0 * h.max(0.0) / GRAVITY).sqrt();
    leg(apex - y0) + leg(apex - y1)
}

/// Lengthens the flight of `clip` (feet on the floor outside `[take_off, land]`, seconds) by
/// what ballistics says an apex at `apex_y` needs beyond one at `normal_apex_y` (metres), from
/// the same take-off and landing heights ([`ballistic_flight_s`]): the clip's flight frames
/// (joint angles, root path and orientation) are stretched in time, linearly, to fill the new
/// flight, later frames follow shifted; the root's arc over the line from take-off to landing is
/// then scaled so that its top is at `apex_y`.
fn lengthen_flight(
    clip: &FigureClip,
    take_off: f64,
    land: f64,
    apex_y: f64,
    normal_apex_y: f64,
) -> Result<(FigureClip, FlightPlan), PrimitiveExperimentError> {
    let dt = clip.frame_time;
    let n = clip.frame_count();
    let frame = |t: f64| ((t / dt).round().max(0.0) as usize).min(n - 1);
    let (fa, fb) = (frame(take_off), frame(land));
    let (y0, y1) = (clip.root_translation[fa].y, clip.root_translation[fb].y);
    if fb <= fa || apex_y <= y0.max(y1) {
        return Err(PrimitiveExperimentError::NoFlight(format!(
            "the blend asks for a root apex of {apex_y:.3} m, not above the take-off \
             ({y0:.3} m) and landing ({y1:.3} m) heights: γ gives no flight"
        )));
    }
    let extra = ballistic_flight_s(y0, apex_y, y1) - ballistic_flight_s(y0, normal_apex_y, y1);
    let nf = (fb - fa) as f64 + extra / dt;
    if nf < 1.0 {
        return Err(PrimitiveExperimentError::NoFlight(format!(
            "the apex γ asks for ({apex_y:.3} m) shortens the normal jump's flight of {:.3} s \
             by {:.3} s: γ gives no flight",
            (fb - fa) as f64 * dt,
            -extra
        )));
    }
    let nf = nf.round() as usize;
    let shift = nf as isize - (fb - fa) as isize;
    let mut out = stretch_flight(clip, fa, fb, nf);
    let (y0, y1, arc_scale) = raise_arc(&mut out, fa, nf, apex_y)?;
    let plan = FlightPlan {
        blend_take_off_s: take_off,
        blend_land_s: land,
        take_off_root_m: y0,
        land_root_m: y1,
        normal_apex_root_m: normal_apex_y,
        apex_root_m: apex_y,
        extra_flight_s: extra,
        stretch_s: shift as f64 * dt,
        arc_scale,
    };
    Ok((out, plan))
}

/// `clip` with its flight frames `fa..=fb` stretched in time, linearly, over `nf` frames
/// (joint angles, root path and orientation interpolated), the later frames following shifted.
fn stretch_flight(clip: &FigureClip, fa: usize, fb: usize, nf: usize) -> FigureClip {
    let (dt, n) = (clip.frame_time, clip.frame_count());
    let shift = nf as isize - (fb - fa) as isize;
    let m = (n as isize + shift) as usize;
    let mut out = FigureClip::with_capacity(clip.model.clone(), dt, m);
    for k in 0..m {
        let src = if k <= fa {
            k as f64
        } else if k < fa + nf {
            fa as f64 + (k - fa) as f64 * (fb - fa) as f64 / nf as f64
        } else {
            (k as isize - shift) as f64
        };
        let (i, u) = (src.floor() as usize, src.fract());
        let j = (i + 1).min(n - 1);
        let (a, b) = (clip.frame_angles(i), clip.frame_angles(j));
        out.angles
            .extend(a.iter().zip(b).map(|(x, y)| x + u * (y - x)));
        out.root_translation
            .push(clip.root_translation[i].lerp(clip.root_translation[j], u));
        out.root_rotation
            .push(clip.root_rotation[i].slerp(clip.root_rotation[j], u));
    }
    out
}

/// Scales the root's arc over the chord from take-off (frame `fa`) to landing (`fa + nf`) so
/// that its top is at `apex_y`. Returns the root's take-off and landing heights and the scale.
fn raise_arc(
    out: &mut FigureClip,
    fa: usize,
    nf: usize,
    apex_y: f64,
) -> Result<(f64, f64, f64), PrimitiveExperimentError> {
    // The arc over the chord from take-off to landing, scaled so that its top is at `apex_y`.
    let (y0, y1) = (out.root_translation[fa].y, out.root_translation[fa + nf].y);
    let chord = |k: usize| y0 + (y1 - y0) * (k - fa) as f64 / nf as f64;
    let top = (fa..=fa + nf)
        .max_by(|a, b| {
            out.root_translation[*a]
                .y
                .total_cmp(&out.root_translation[*b].y)
        })
        .unwrap_or(fa);
    let bump = out.root_translation[top].y - chord(top);
    if bump <= 0.0 {
        return Err(PrimitiveExperimentError::NoFlight(format!(
            "the blend's root does not rise above the line from take-off ({y0:.3} m) to \
             landing ({y1:.3} m): no flight arc"
        )));
    }
    let arc_scale = (apex_y - chord(top)) / bump;
    for k in fa + 1..fa + nf {
        let c = chord(k);
        let y = &mut out.root_translation[k].y;
        *y = c + arc_scale * (*y - c);
    }
    Ok((y0, y1, arc_scale))
}

/// Runs the high jump: [`learn_primitives`], then plays the three jumps and measures each one:
/// the left-knee flexion (crouch peak and whole-clip peak) and what it did ([`JumpFigures`]).
pub fn run(config: &HighJumpConfig) -> Result<HighJumpOutcome, PrimitiveExperimentError> {
    let model = &config.model;
    let primitives = learn_primitives(config)?;
    let dt = primitives.dt;
    let learned = &primitives.learned;
    let t = learned.normal.primitive.duration;
    // Rollouts: the low jump time-scaled to the normal jump's duration, as it is blended.
    let low_scaled = learned.low.primitive.with_duration(t)?;
    let rollouts = Jumps {
        low: rollout(&low_scaled, dt)?,
        normal: rollout(&learned.normal.primitive, dt)?,
        high: rollout(&learned.high.primitive, dt)?,
    };
    let mut clips = Jumps {
        low: on_figure(model, &rollout(&learned.low.primitive, dt)?)?,
        normal: on_figure(model, &rollouts.normal)?,
        high: on_figure(model, &rollouts.high)?,
    };
    let floor = primitives.floor_y_m;
    // A rollout reproduces its demonstration to within millimetres, which puts a standing foot
    // that far through the floor: the floor constraint lifts the root by the depth where it is.
    let floor_lift_m = Jumps {
        low: clips.low.lift_above_floor(floor),
        normal: clips.normal.lift_above_floor(floor),
        high: clips.high.lift_above_floor(floor),
    };
    let mut low_time_scaled = on_figure(model, &rollouts.low)?;
    low_time_scaled.lift_above_floor(floor);
    let reference = &primitives.contact_reference;
    let figures = Jumps {
        low: jump_figures_against(&clips.low, reference),
        normal: jump_figures_against(&clips.normal, reference),
        high: jump_figures_against(&clips.high, reference),
    };
    // The paper's knee flexion of a jump is that of its crouch: the peak before take-off.
    let crouch = Jumps {
        low: crouch_peak_deg(&clips.low, dt)?,
        normal: crouch_peak_deg(&clips.normal, dt)?,
        high: crouch_peak_deg(&clips.high, dt)?,
    };
    let whole = Jumps {
        low: peak_deg(&rollouts.low, "left_knee")?,
        normal: peak_deg(&rollouts.normal, "left_knee")?,
        high: peak_deg(&rollouts.high, "left_knee")?,
    };
    let expected = primitives.prediction.crouch_knee_flexion_deg;
    Ok(HighJumpOutcome {
        duration_s: t,
        low_time_scaled,
        floor_lift_m,
        rollouts,
        clips,
        figures,
        high_minus_expected_deg: crouch.high - expected,
        crouch_knee_flexion_deg: crouch,
        whole_clip_knee_flexion_deg: whole,
        expected_high_deg: expected,
        primitives,
    })
}
