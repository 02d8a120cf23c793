//! Stage 1, **position**: forward kinematics at the step start.

use super::{State, StepWorkspace};
use crate::dynamics::model::Model;

/// Stage 1: kinematics at the step start.
#[inline(always)]
pub(super) fn position_stage(model: &Model, state: &State, ws: &mut StepWorkspace) {
    ws.kinematics_of(model, state);
}
