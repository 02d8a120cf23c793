//! Stage 5, **check**: kinematics of the new state and the divergence checks.

use super::{MAX_EXTENT, MAX_SPEED, State, StepError, StepWorkspace};
use crate::dynamics::model::Model;

/// Stage 5: kinematics of the new state (kept for the next step) and the divergence checks.
#[inline(always)]
pub(super) fn check_stage(
    model: &Model,
    state: &State,
    ws: &mut StepWorkspace,
) -> Result<(), StepError> {
    let t = state.time_s;
    let data = ws.kinematics_of(model, state);
    // The common case first, without square roots: every body within bounds
    // (`|v|² ≤ MAX_SPEED²`), where a NaN fails every comparison and a sum of the orientation's
    // entries is finite only if all are; only a failing state is searched for its first
    // culprit below.
    let (max_speed2, r) = (MAX_SPEED * MAX_SPEED, MAX_EXTENT);
    // (A loop, not `all`: an iterator adaptor left out of line would run without AVX2.)
    let mut within = true;
    for i in 0..model.nbodies() {
        let (p, vel, rot) = (data.pos[i], data.v[i], &data.rot[i]);
        if !(vel.ang.length_squared() <= max_speed2
            && vel.lin.length_squared() <= max_speed2
            && p.x.abs() <= r
            && p.y.abs() <= r
            && p.z.abs() <= r
            && (rot.x_axis + rot.y_axis + rot.z_axis)
                .element_sum()
                .is_finite())
        {
            within = false;
            break;
        }
    }
    if within {
        return Ok(());
    }
    for i in 0..model.nbodies() {
        let (p, vel) = (data.pos[i], data.v[i]);
        let name = || model.bodies[i].name.clone();
        if !p.is_finite() || !data.rot[i].is_finite() {
            return Err(StepError::NonFinite {
                time_s: t,
                body: name(),
                quantity: "position".into(),
            });
        }
        if !vel.is_finite() {
            return Err(StepError::NonFinite {
                time_s: t,
                body: name(),
                quantity: "velocity".into(),
            });
        }
        let speed = vel.ang.length().max(vel.lin.length());
        if speed > MAX_SPEED {
            return Err(StepError::Exploding {
                time_s: t,
                body: name(),
                quantity: "speed".into(),
                value: speed,
                limit: MAX_SPEED,
            });
        }
        if p.abs().max_element() > MAX_EXTENT {
            return Err(StepError::Exploding {
                time_s: t,
                body: name(),
                quantity: "position".into(),
                value: p.abs().max_element(),
                limit: MAX_EXTENT,
            });
        }
    }
    Ok(())
}
