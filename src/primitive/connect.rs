//! Connecting primitives (the paper's §2.2, Fig. 3): each primitive of a sequence starts from the
//! state (θ, θ̇ per DOF) the previous one ended in, and its dynamics pull the DOF smoothly onto its
//! own course. There is no jump in angle or velocity at a junction; the jumps are measured and
//! reported.
//!
//! **Acceleration.** A DMP's state is (θ, z): its acceleration follows from the state and its own
//! goal and forcing, so a hand-over of (θ, θ̇) alone steps θ̈ by Δa = θ̈_next(0) − θ̈_prev(τ)
//! ([`Junction::max_acceleration_step`]). A [`HandOver`] removes the step: over a window W after
//! the junction ([`handover_window_s`]) the played motion is the next primitive plus
//! `δ(t) = −½ Δa t² (1 − s)³`, `s = t/W` (t from the junction), which has δ = δ̇ = 0 and
//! δ̈ = −Δa at the junction and δ = δ̇ = δ̈ = 0 from the end of the window on: θ, θ̇ and θ̈ are
//! continuous, and after the window the motion is the next primitive's own.

use super::error::{PrimitiveError, Result, require_positive};
use super::primitive::Primitive;
use super::rollout::{DofState, Rollout};
use super::trajectory::Trajectory;

/// What happened at the junction between two consecutive primitives.
#[derive(Clone, Debug, PartialEq)]
pub struct Junction {
    /// Time of the junction from the start of the sequence, seconds.
    pub time: f64,
    /// Index of the primitive that starts here.
    pub index: usize,
    /// Largest |θ_next(0) − θ_prev(τ)| over the DOFs (rad, or m).
    pub max_angle_jump: f64,
    /// Largest |θ̇_next(0) − θ̇_prev(τ)| over the DOFs (rad/s, or m/s).
    pub max_velocity_jump: f64,
    /// Largest |θ̈_next(0) − θ̈_prev(τ)| over the DOFs of the two DMPs themselves (rad/s², or
    /// m/s²): the step a plain hand-over of (θ, θ̇) makes, which the [`HandOver`] removes.
    pub max_acceleration_step: f64,
}

/// Longest hand-over window, seconds (see the module docs). A quarter second: the jumping knee
/// kick's landing, played from the kick's pose at Leap, then leaves it at a pace the physical
/// character's clavicles and waist can follow (with 0.1 s the DMPs' accelerations still differed
/// by 332 rad/s² at the CMU knee kick's junction, and it tracked at 2.15° under adult strength;
/// `tests/fall/active_character.rs`).
pub const HANDOVER_WINDOW_S: f64 = 0.25;

/// The hand-over window at a junction into a primitive of `next_duration_s` seconds:
/// [`HANDOVER_WINDOW_S`], or half the next primitive if that is shorter (the window ends before
/// the next junction), seconds.
pub fn handover_window_s(next_duration_s: f64) -> f64 {
    HANDOVER_WINDOW_S.min(0.5 * next_duration_s)
}

/// Removes the step in acceleration at a junction (see the module docs): adds
/// `δ(t) = −½ Δa t² (1 − t/W)³` per DOF to the next primitive over the window W.
#[derive(Clone, Debug, PartialEq)]
pub struct HandOver {
    /// Δa per DOF: θ̈_next(0) − θ̈_prev(τ) (rad/s², or m/s²).
    step: Vec<f64>,
    window_s: f64,
}

impl HandOver {
    /// The hand-over from `previous` (at its end) to `next` (at its start, from the previous
    /// one's state), `next_duration_s` seconds long.
    pub fn new(previous: &Rollout, next: &Rollout, next_duration_s: f64) -> HandOver {
        let n = next.theta().len();
        let (mut a_prev, mut a_next) = (vec![0.0; n], vec![0.0; n]);
        previous.theta_ddot_into(&mut a_prev);
        next.theta_ddot_into(&mut a_next);
        HandOver {
            step: a_next.iter().zip(&a_prev).map(|(n, p)| n - p).collect(),
            window_s: handover_window_s(next_duration_s),
        }
    }

    /// Δa per DOF (rad/s², or m/s²).
    pub fn step(&self) -> &[f64] {
        &self.step
    }

    /// The window, seconds.
    pub fn window_s(&self) -> f64 {
        self.window_s
    }

    /// True while `since_s` (seconds after the junction) is inside the window.
    pub fn active(&self, since_s: f64) -> bool {
        since_s < self.window_s
    }

    /// Adds δ and δ̇ at `since_s` seconds after the junction to `theta` and `theta_dot` (the
    /// next primitive's θ and θ̇ there):
    /// `δ = −½Δa t²(1 − s)³`, `δ̇ = −Δa (t(1 − s)³ − (3/2)(t²/W)(1 − s)²)`, s = t/W.
    /// Outside the window it leaves them as they are.
    pub fn mix(&self, since_s: f64, theta: &mut [f64], theta_dot: &mut [f64]) {
        if !self.active(since_s) {
            return;
        }
        let t = since_s.max(0.0);
        let w = self.window_s;
        let r = 1.0 - t / w;
        let shape = 0.5 * t * t * r * r * r;
        let rate = t * r * r * r - 1.5 * t * t / w * r * r;
        for ((th, om), da) in theta.iter_mut().zip(theta_dot.iter_mut()).zip(&self.step) {
            *th -= da * shape;
            *om -= da * rate;
        }
    }
}

/// A played sequence.
#[derive(Clone, Debug, PartialEq)]
pub struct Connected {
    /// The whole sequence on a uniform grid (frame k at k·dt from the sequence start).
    pub trajectory: Trajectory,
    /// One entry per junction (sequence length − 1).
    pub junctions: Vec<Junction>,
    /// The state at the end of the last primitive.
    pub end_state: DofState,
}

/// The DOF names of a non-empty `sequence` whose primitives all drive the same DOFs.
fn sequence_dofs(sequence: &[Primitive]) -> Result<Vec<String>> {
    let first = sequence
        .first()
        .ok_or_else(|| PrimitiveError::InvalidParameter {
            field: "sequence".into(),
            reason: "empty".into(),
        })?;
    let names = first.names();
    for (i, p) in sequence.iter().enumerate().skip(1) {
        if p.names() != names {
            return Err(PrimitiveError::DofMismatch {
                what: format!(
                    "primitive {i} (`{}`) has DOFs {:?}, primitive 0 (`{}`) has {:?}",
                    p.name,
                    p.names(),
                    first.name,
                    names
                ),
            });
        }
    }
    Ok(names)
}

/// Plays `sequence` back to back — the first from its demonstrated start or from `start`, every
/// later one from the end state of the one before, handed over without a step in acceleration
/// ([`HandOver`]) — and samples it every `dt` seconds over the total duration Σ τ_i. All
/// primitives must have the same DOF names in the same order.
pub fn connect(sequence: &[Primitive], dt: f64, start: Option<&DofState>) -> Result<Connected> {
    require_positive("dt", dt)?;
    let names = sequence_dofs(sequence)?;
    let total: f64 = sequence.iter().map(|p| p.duration).sum();
    let frames = (total / dt + 1e-6).floor() as usize + 1;
    let d = names.len();
    let mut values = Vec::with_capacity(frames * d);
    let mut junctions = Vec::new();
    let mut previous: Option<Rollout> = None;
    let mut offset = 0.0;
    let mut k = 0;
    let (mut theta, mut theta_dot) = (vec![0.0; d], vec![0.0; d]);
    for (i, p) in sequence.iter().enumerate() {
        let hand_over_state = previous.as_ref().map(Rollout::state);
        let mut r = Rollout::new(p, hand_over_state.as_ref().or(start))?;
        let mut handover = None;
        if let (Some(prev_r), Some(prev)) = (previous.take(), &hand_over_state) {
            let now = r.state();
            let max_abs = |a: &[f64], b: &[f64]| {
                a.iter()
                    .zip(b)
                    .map(|(x, y)| (x - y).abs())
                    .fold(0.0, f64::max)
            };
            let h = HandOver::new(&prev_r, &r, p.duration);
            junctions.push(Junction {
                time: offset,
                index: i,
                max_angle_jump: max_abs(&now.theta, &prev.theta),
                max_velocity_jump: max_abs(&now.theta_dot, &prev.theta_dot),
                max_acceleration_step: h.step().iter().fold(0.0, |m, a| m.max(a.abs())),
            });
            handover = Some(h);
        }
        let end = offset + p.duration;
        let last = i + 1 == sequence.len();
        while k < frames {
            let t = k as f64 * dt;
            if t > end + 1e-9 || (!last && t >= end - 1e-9) {
                break;
            }
            let since = (t - offset).clamp(0.0, p.duration);
            r.advance_to(since);
            theta.copy_from_slice(r.theta());
            if let Some(h) = &handover {
                r.theta_dot_into(&mut theta_dot);
                h.mix(since, &mut theta, &mut theta_dot);
            }
            values.extend_from_slice(&theta);
            k += 1;
        }
        r.advance_to(p.duration);
        previous = Some(r);
        offset = end;
    }
    let trajectory = Trajectory::new(dt, names, values)?;
    Ok(Connected {
        trajectory,
        junctions,
        end_state: previous.map(|r| r.state()).unwrap_or_default(),
    })
}
