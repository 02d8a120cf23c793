//! Stage 2, **limits**: each DOF's excursion past its range and whether its PD torque is at its
//! strength limit at the step start, for the [`StepMonitor`].

use super::{Forces, JointsAtStart, State, StepMonitor, StepWorkspace, read_angles};
use crate::dynamics::model::Model;

/// Stage 2: the largest excursion past each DOF's range at the step start (rad), and which PD
/// torques are at their strength limit; returns what it left in the [`EvalScratch`] for the
/// integrator's first evaluation.
///
/// [`EvalScratch`]: super::EvalScratch
#[inline(always)]
pub(super) fn limits_stage(
    model: &Model,
    forces: &Forces,
    state: &State,
    ws: &mut StepWorkspace,
    monitor: &mut StepMonitor,
    dt: f64,
) -> JointsAtStart {
    let limited = forces.pd.filter(|pd| !pd.torque_limits.is_empty());
    let e = &mut ws.eval;
    if forces.limits.is_none() && limited.is_none() {
        return JointsAtStart::Nothing;
    }
    read_angles(model, forces, &state.q, &mut e.reference, &mut e.angles);
    // The integrator's first evaluation is at this same state: it reuses the angles and the
    // PD torques computed here (the same bits, computed once).
    let joints = if limited.is_some() {
        e.pd_start.resize(forces.dofs.len(), (0.0, 0.0));
        JointsAtStart::AnglesAndPd
    } else {
        JointsAtStart::Angles
    };
    for (d, &k) in forces.dofs.iter().enumerate() {
        if let Some(l) = forces.limits {
            let ex = l.excursion(d, e.angles[k]);
            monitor.max_excursion[d] = monitor.max_excursion[d].max(ex);
        }
        if let Some(pd) = limited {
            let (tau, damp) = pd.torque(d, e.angles[k], state.v[k]);
            e.pd_start[d] = (tau, damp);
            if tau.abs() > monitor.peak_torque[d].abs() {
                monitor.peak_torque[d] = tau;
            }
            if pd.saturates(d, tau) {
                monitor.saturated_s[d] += dt;
                monitor.first_saturated_s[d].get_or_insert(state.time_s);
            }
        }
    }
    joints
}
