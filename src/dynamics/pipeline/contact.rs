//! Stage 3, **contact**: friction anchors brought to the step start, the contact forces there
//! and the per-link statistics.

use super::{Forces, State, StepMonitor, StepSettings, StepWorkspace};
use crate::dynamics::forces::contact::ImplicitFloor;
use crate::dynamics::integrator::Integrator;
use crate::dynamics::spatial::ForceVec;

/// Stage 3: anchors and contact forces at the step start, per-link statistics; with
/// [`ContactParams::implicit_damping`] and semi-implicit Euler, or with a linearly implicit
/// scheme, the implicit inertias of the touching links for the step. The forces stay in the
/// [`EvalScratch`] for the integrator's first evaluation.
///
/// [`EvalScratch`]: super::EvalScratch
/// [`ContactParams::implicit_damping`]: crate::dynamics::forces::contact::ContactParams::implicit_damping
#[inline(always)]
pub(super) fn contact_stage(
    forces: &Forces,
    settings: StepSettings,
    state: &mut State,
    ws: &mut StepWorkspace,
    monitor: &mut StepMonitor,
) {
    let dt = settings.dt;
    let e = &mut ws.eval;
    e.f_ext.fill(ForceVec::ZERO);
    e.implicit.clear();
    if let Some(cm) = forces.contact {
        let implicit = match (
            settings.integrator,
            settings.integrator.linearisation_weight(),
        ) {
            (_, Some(theta)) => Some(ImplicitFloor {
                h: dt,
                stiffness: true,
                theta,
            }),
            (Integrator::SemiImplicitEuler { .. }, None) if cm.params.implicit_damping => {
                Some(ImplicitFloor {
                    h: dt,
                    stiffness: false,
                    theta: 1.0,
                })
            }
            _ => None,
        };
        cm.update_and_apply_implicit(
            &e.data,
            &mut state.anchors,
            &mut e.f_ext,
            &mut monitor.sample,
            implicit.map(|f| (f, &mut e.implicit)),
        );
        monitor
            .contact
            .accumulate(&monitor.sample, state.time_s, dt);
    }
}
