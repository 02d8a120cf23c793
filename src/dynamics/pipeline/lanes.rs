//! The stages for several bodies at once: the same sequence as [`step`](super::step), with the
//! articulated-body algorithm of [`LANES`] bodies in the lanes of one vector computation.
//!
//! [`LANES`]: crate::dynamics::lanes::LANES

use super::integrate::{Evaluation, Implicit, finish};
use super::{
    Forces, State, StepError, StepMonitor, StepSettings, StepWorkspace, check_sizes, check_stage,
    start_stages, step, step_stages,
};
use crate::dynamics::aba_lanes::{LaneData, LaneInput, lanes_inline};
use crate::dynamics::integrator::{self, Integrator};
use crate::dynamics::model::Model;

/// One body of [`step_lanes`]: the forces it feels, its state, buffers and monitor, and the
/// result of its latest step.
#[derive(Debug)]
pub struct LaneBody<'a> {
    /// The forces.
    pub forces: Forces<'a>,
    /// The state.
    pub state: &'a mut State,
    /// The buffers.
    pub ws: &'a mut StepWorkspace,
    /// The monitor.
    pub monitor: &'a mut StepMonitor,
    /// The outcome of the latest step of this body.
    pub result: Result<(), StepError>,
}

/// One step of `settings.dt` seconds for each body of `bodies` (all of `model`): the same
/// stages as [`step`], every body's state, monitor and result the bits [`step`] gives it
/// alone, with the articulated-body algorithm of [`LANES`] bodies at a time in the lanes of
/// one vector computation ([`crate::dynamics::aba_passes_lanes`]). That holds for semi-implicit
/// Euler with the floor's damping explicit; any other scheme steps each body by [`step`].
/// A body whose step fails keeps its error in `result` and the others go on; one whose state or
/// workspace does not fit the model is not stepped (a [`StepError::Size`]), and the others are
/// then each stepped by [`step`].
///
/// [`step`]: super::step
/// [`LANES`]: crate::dynamics::lanes::LANES
pub fn step_lanes(
    model: &Model,
    settings: StepSettings,
    bodies: &mut [LaneBody],
    lanes: &mut LaneData,
) {
    let mut fit = true;
    for b in bodies.iter_mut() {
        b.result = check_sizes(model, b.state, b.ws).map_err(StepError::from);
        fit &= b.result.is_ok();
    }
    if !fit {
        for b in bodies.iter_mut().filter(|b| b.result.is_ok()) {
            b.result = step(model, settings, &b.forces, b.state, b.ws, b.monitor);
        }
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if crate::cpu::has_avx2() {
        // SAFETY: the processor supports AVX2 (detected at run time just above).
        return unsafe { step_lanes_avx2(model, settings, bodies, lanes) };
    }
    step_lanes_stages(model, settings, bodies, lanes)
}

/// [`step_lanes_stages`] compiled for AVX2.
///
/// # Safety
/// The processor must support AVX2 ([`crate::cpu::has_avx2`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn step_lanes_avx2(
    model: &Model,
    settings: StepSettings,
    bodies: &mut [LaneBody],
    lanes: &mut LaneData,
) {
    step_lanes_stages(model, settings, bodies, lanes)
}

/// The stages of [`step_lanes`]: per body the stages before the integrator and the forces of
/// its one evaluation, the ABA of all bodies in lanes, then per body the semi-implicit Euler
/// advance and the check.
#[inline(always)]
fn step_lanes_stages(
    model: &Model,
    settings: StepSettings,
    bodies: &mut [LaneBody],
    lanes: &mut LaneData,
) {
    let explicit_contact = bodies
        .iter()
        .all(|b| b.forces.contact.is_none_or(|c| !c.params.implicit_damping));
    let implicit_damping = match settings.integrator {
        Integrator::SemiImplicitEuler { implicit_damping }
            if explicit_contact && bodies.len() > 1 =>
        {
            implicit_damping
        }
        // RK4, the floor's damping taken implicitly or a body alone: each by `step`.
        _ => {
            for b in bodies.iter_mut() {
                b.result = step_stages(model, settings, &b.forces, b.state, b.ws, b.monitor);
            }
            return;
        }
    };
    let h = settings.dt;
    let implicit = if implicit_damping {
        Implicit::Damping(h)
    } else {
        Implicit::Explicit
    };
    for b in bodies.iter_mut() {
        let (forces, state, ws, monitor) = (&b.forces, &mut *b.state, &mut *b.ws, &mut *b.monitor);
        let start = start_stages(model, settings, forces, state, ws, monitor);
        // The integrate stage: its one evaluation's forces here, its ABA in the lanes below.
        let (t, q, v) = (state.time_s, &state.q, &state.v);
        Evaluation::new(model, forces, &state.anchors, &mut ws.eval, Some(start))
            .prepare(t, q, v, implicit);
    }
    lanes_inline(
        model,
        lanes,
        bodies.iter_mut().map(|b| {
            let e = &mut b.ws.eval;
            LaneInput {
                data: &mut e.data,
                tau: &e.tau,
                f_ext: &e.f_ext,
                armature: implicit_damping.then_some(&e.armature[..]),
            }
        }),
    );
    for b in bodies.iter_mut() {
        let (state, ws) = (&mut *b.state, &mut *b.ws);
        let StepWorkspace { eval, iws } = ws;
        b.result = finish(model, eval, state.time_s, iws.acceleration_mut());
        if b.result.is_ok() {
            integrator::semi_implicit_euler_advance(model, iws, h, (&mut state.q, &mut state.v));
            state.count_step(h);
            b.result = check_stage(model, state, ws);
        }
    }
}
