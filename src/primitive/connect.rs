//! Connecting primitives (the paper's §2.2, Fig. 3): each primitive of a sequence starts from the
//! state (θ, θ̇ per DOF) the previous one ended in, and its dynamics pull the DOF smoothly onto its
//! own course. There is no jump in angle or velocity at a junction; the jumps are measured and
//! reported.

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

/// Plays `sequence` back to back — the first from its demonstrated start or from `start`, every
/// later one from the end state of the one before — and samples it every `dt` seconds over the
/// total duration Σ τ_i. All primitives must have the same DOF names in the same order.
pub fn connect(sequence: &[Primitive], dt: f64, start: Option<&DofState>) -> Result<Connected> {
    require_positive("dt", dt)?;
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
    let total: f64 = sequence.iter().map(|p| p.duration).sum();
    let frames = (total / dt + 1e-6).floor() as usize + 1;
    let d = names.len();
    let mut values = Vec::with_capacity(frames * d);
    let mut junctions = Vec::new();
    let mut state: Option<DofState> = start.cloned();
    let mut offset = 0.0;
    let mut k = 0;
    for (i, p) in sequence.iter().enumerate() {
        let mut r = Rollout::new(p, state.as_ref())?;
        if let Some(prev) = &state
            && i > 0
        {
            let now = r.state();
            let max_abs = |a: &[f64], b: &[f64]| {
                a.iter()
                    .zip(b)
                    .map(|(x, y)| (x - y).abs())
                    .fold(0.0, f64::max)
            };
            junctions.push(Junction {
                time: offset,
                index: i,
                max_angle_jump: max_abs(&now.theta, &prev.theta),
                max_velocity_jump: max_abs(&now.theta_dot, &prev.theta_dot),
            });
        }
        let end = offset + p.duration;
        let last = i + 1 == sequence.len();
        while k < frames {
            let t = k as f64 * dt;
            if t > end + 1e-9 || (!last && t >= end - 1e-9) {
                break;
            }
            r.advance_to((t - offset).clamp(0.0, p.duration));
            values.extend_from_slice(r.theta());
            k += 1;
        }
        r.advance_to(p.duration);
        state = Some(r.state());
        offset = end;
    }
    let trajectory = Trajectory::new(dt, names, values)?;
    Ok(Connected {
        trajectory,
        junctions,
        end_state: state.unwrap_or_default(),
    })
}
