//! Stage 4, **integrate**: the integrator's step, and the force model it evaluates at each of
//! its stages ([`Evaluation`]: joint torques, contact and external forces, then the ABA).

use super::{
    EvalScratch, Forces, JointsAtStart, State, StepError, StepSettings, StepStart, StepWorkspace,
    read_angles,
};
use crate::dynamics::aba::aba_passes;
use crate::dynamics::forces::contact::ContactState;
use crate::dynamics::forces::external::apply_external;
use crate::dynamics::integrator::{self, Dynamics};
use crate::dynamics::kinematics::kinematics;
use crate::dynamics::linearly_implicit;
use crate::dynamics::model::Model;
use crate::dynamics::spatial::ForceVec;

/// Stage 4: the integrator step from the step-start state, whose first evaluation reuses what
/// the stages before it computed (`start`); time becomes `steps · dt`.
#[inline(always)]
pub(super) fn integrate_stage(
    model: &Model,
    settings: StepSettings,
    forces: &Forces,
    state: &mut State,
    ws: &mut StepWorkspace,
    start: StepStart,
) -> Result<(), StepError> {
    let StepWorkspace { eval, iws } = ws;
    let mut f = Evaluation::new(model, forces, &state.anchors, eval, Some(start));
    let t = state.time_s;
    integrator::step(
        settings.integrator,
        model,
        iws,
        &mut f,
        t,
        settings.dt,
        (&mut state.q, &mut state.v),
    )?;
    state.count_step(settings.dt);
    Ok(())
}

/// The force model evaluated at every integrator stage: joint torques (PD + joint model),
/// contact and external forces, then the ABA.
pub(super) struct Evaluation<'a> {
    model: &'a Model,
    forces: &'a Forces<'a>,
    anchors: &'a ContactState,
    ws: &'a mut EvalScratch,
    /// What the stages left at the step-start state, for the first evaluation only.
    start: Option<StepStart>,
}

impl<'a> Evaluation<'a> {
    /// The evaluation of `forces` with the friction anchors `anchors` in the buffers `ws`; its
    /// first evaluation reuses what `start` says the stages left (`None`: nothing). It
    /// overwrites the kinematics in `ws`, so their cache no longer matches any state.
    #[inline(always)]
    pub(super) fn new(
        model: &'a Model,
        forces: &'a Forces<'a>,
        anchors: &'a ContactState,
        ws: &'a mut EvalScratch,
        start: Option<StepStart>,
    ) -> Self {
        ws.kinematics_at_step = None;
        Self {
            model,
            forces,
            anchors,
            ws,
            start,
        }
    }
}

impl Dynamics for Evaluation<'_> {
    type Error = StepError;

    #[inline(always)]
    fn acceleration(
        &mut self,
        t: f64,
        q: &[f64],
        v: &[f64],
        implicit_dt: Option<f64>,
        qdd: &mut [f64],
    ) -> Result<(), StepError> {
        let implicit = implicit_dt.map_or(Implicit::Explicit, Implicit::Damping);
        self.evaluate(t, q, v, implicit, qdd)
    }

    #[inline(always)]
    fn acceleration_linearised(
        &mut self,
        t: f64,
        q: &[f64],
        v: &[f64],
        h: f64,
        theta: f64,
        qdd: &mut [f64],
    ) -> Result<(), StepError> {
        self.evaluate(t, q, v, Implicit::Linearised { h, theta }, qdd)
    }
}

impl Evaluation<'_> {
    /// `q̈` at `(t, q, v)` with the forces taken as `implicit` says.
    #[inline(always)]
    fn evaluate(
        &mut self,
        t: f64,
        q: &[f64],
        v: &[f64],
        implicit: Implicit,
        qdd: &mut [f64],
    ) -> Result<(), StepError> {
        let arm = self.prepare(t, q, v, implicit);
        let ws = &mut *self.ws;
        let arm = arm.then_some(&ws.armature[..]);
        aba_passes(
            self.model,
            &mut ws.data,
            &ws.tau,
            &ws.f_ext,
            arm,
            &ws.implicit,
        );
        finish(self.model, ws, t, qdd)
    }

    /// The force evaluation before the ABA: kinematics and contact forces (unless the
    /// step-start stages left them), external forces, angles, PD torques
    /// `τ = k_p(θ_d − θ) + k_v(θ̇_d − θ̇)` and the joint model's, and, with `implicit`, the
    /// armature (`h·d`, or `h d + h² k` with the torques corrected by `−h k v`); returns
    /// whether the armature applies. The first call takes what the stages left; later ones
    /// compute everything.
    #[inline(always)]
    pub(super) fn prepare(&mut self, t: f64, q: &[f64], v: &[f64], implicit: Implicit) -> bool {
        let (model, forces) = (self.model, self.forces);
        let ws = &mut *self.ws;
        let start = self.start.take();
        let joints = start.map_or(JointsAtStart::Nothing, |s| s.joints);
        if start.is_none() {
            // The implicit contact damping belongs to the step-start evaluation only.
            ws.implicit.clear();
            kinematics(model, &mut ws.data, q, v);
            ws.f_ext.fill(ForceVec::ZERO);
            if let Some(cm) = forces.contact {
                cm.apply(&ws.data, self.anchors, &mut ws.f_ext, &mut ws.normal);
            }
        }
        apply_external(&ws.data, forces.external, t, &mut ws.f_ext);
        if (forces.pd.is_some() || forces.limits.is_some()) && !joints.angles() {
            read_angles(model, forces, q, &mut ws.reference, &mut ws.angles);
        }
        let linearised = matches!(implicit, Implicit::Linearised { .. });
        for (d, &k) in forces.dofs.iter().enumerate() {
            let (th, thd) = (ws.angles[k], v[k]);
            let (mut tau, mut damp) = (0.0, 0.0);
            if joints.pd() {
                (tau, damp) = ws.pd_start[d];
            } else if let Some(pd) = forces.pd {
                (tau, damp) = pd.torque(d, th, thd);
            }
            if linearised {
                let mut stiff = forces
                    .pd
                    .map_or(0.0, |pd| linearly_implicit::pd_stiffness(pd, d, tau));
                if let Some(l) = forces.limits {
                    stiff += linearly_implicit::limit_stiffness(l, d, th);
                }
                ws.stiffness[k] = stiff;
            }
            if let Some(l) = forces.limits {
                let (t2, d2) = l.torque(d, th, thd);
                tau += t2;
                damp += d2;
            }
            ws.tau[k] = tau;
            ws.damping[k] = damp;
        }
        implicit_armature(ws, v, implicit)
    }
}

/// What an evaluation takes implicitly over a step of `h` seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Implicit {
    /// Nothing: every force at `(q, v)`.
    Explicit,
    /// The joint damping (armature `h d`).
    Damping(f64),
    /// The joint forces' stiffness and damping ([`linearly_implicit::joint`]) over the step
    /// `h` at weight `theta`.
    Linearised {
        /// The step (s).
        h: f64,
        /// The weight (1: the step end, ½: its midpoint).
        theta: f64,
    },
}

/// The armature of the joint forces taken implicitly over the step `h`: `h·d` (damping), or
/// `h d + h² k` with the torques corrected by `−h k v` ([`linearly_implicit::joint`]); returns
/// whether the armature applies (not with [`Implicit::Explicit`]).
#[inline(always)]
fn implicit_armature(ws: &mut EvalScratch, v: &[f64], implicit: Implicit) -> bool {
    match implicit {
        Implicit::Damping(h) => {
            for k in 0..ws.armature.len() {
                ws.armature[k] = h * ws.damping[k];
            }
            true
        }
        Implicit::Linearised { h, theta } => {
            for k in 0..ws.armature.len() {
                let (arm, tau) = linearly_implicit::joint(
                    h,
                    theta,
                    ws.tau[k],
                    ws.damping[k],
                    ws.stiffness[k],
                    v[k],
                );
                ws.armature[k] = arm;
                ws.tau[k] = tau;
            }
            true
        }
        Implicit::Explicit => false,
    }
}

/// The force evaluation after the ABA: `q̈` from the data into `qdd`, a non-finite one an
/// error with the time and body.
#[inline(always)]
pub(super) fn finish(
    model: &Model,
    ws: &EvalScratch,
    t: f64,
    qdd: &mut [f64],
) -> Result<(), StepError> {
    qdd.copy_from_slice(&ws.data.qdd);
    if let Some(k) = qdd.iter().position(|x| !x.is_finite()) {
        let b = (0..model.nbodies())
            .rev()
            .find(|&b| model.v_idx[b] <= k)
            .unwrap_or(0);
        return Err(StepError::NonFinite {
            time_s: t,
            body: model.bodies[b].name.clone(),
            quantity: "joint acceleration".into(),
        });
    }
    Ok(())
}
