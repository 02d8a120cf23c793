//! One simulation step as a pipeline of named stages, after MuJoCo's `mj_step`: every stage
//! takes the immutable [`Model`], the forces the body feels ([`Forces`], plain parameters) and
//! the mutable [`State`] and [`StepWorkspace`].
//!
//! 1. **position**: forward kinematics at the step start (reused when the previous step's check
//!    left it in the workspace);
//! 2. **limits**: each DOF's excursion past its range and whether its PD torque is at its
//!    strength limit, for the [`StepMonitor`];
//! 3. **contact**: friction anchors brought to the step start, contact forces there, per-link
//!    statistics ([`ContactStats`]);
//! 4. **integrate**: the scheme's evaluations of `q̈ = ABA(q, v, τ, f_ext)`, each summing PD
//!    torques `τ = k_p(θ_d − θ) + k_v(θ̇_d − θ̇)` (θ read by [`read_angles`]: a ball joint's
//!    rotation vector nearest its targets), the joint model, contact and external forces;
//! 5. **check**: kinematics of the new state; a non-finite or runaway body stops the run with
//!    its time, body and value.
//!
//! A force whose parameters are absent (`None`, or no external forces) is simply not felt.

use super::aba::aba_passes;
use super::aba_lanes::{LaneData, LaneInput, lanes_inline};
use super::data::Data;
use super::forces::contact::{
    ContactModel, ContactSample, ContactState, ContactStats, ImplicitFloor,
};
use super::forces::external::{ExternalForce, apply_external};
use super::forces::limits::JointRanges;
use super::forces::pd::PdTargets;
use super::integrator::{self, Dynamics, Integrator, IntegratorWorkspace};
use super::kinematics::kinematics;
use super::linearly_implicit;
use super::model::Model;
use super::spatial::{ArticulatedInertia, ForceVec};

/// The state of a simulated body: configuration `q` (nq), velocity `v` (nv), the friction
/// anchors of its contact corners, time (s) and steps taken.
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    /// Configuration (size nq).
    pub q: Vec<f64>,
    /// Velocity (size nv).
    pub v: Vec<f64>,
    /// Friction anchors of the contact corners.
    pub anchors: ContactState,
    /// Simulated time (s): `steps · dt`.
    pub time_s: f64,
    /// Steps taken.
    pub steps: u64,
}

impl State {
    /// A state at `q` with velocity `v` for a body of `nlinks` links, no corner touching, at
    /// time 0.
    pub fn new(q: Vec<f64>, v: Vec<f64>, nlinks: usize) -> Self {
        Self {
            q,
            v,
            anchors: ContactState::new(nlinks),
            time_s: 0.0,
            steps: 0,
        }
    }

    /// Counts one step of `dt` seconds: the time becomes `steps · dt`.
    #[inline(always)]
    fn count_step(&mut self, dt: f64) {
        self.steps += 1;
        self.time_s = self.steps as f64 * dt;
    }
}

/// The forces a body feels, all optional: PD control and the joint model act on the DOFs
/// `dofs` (their indices in `v`, the order of the per-DOF entries), contact on every link.
#[derive(Clone, Copy, Debug)]
pub struct Forces<'a> {
    /// Velocity index of each actuated DOF.
    pub dofs: &'a [usize],
    /// PD targets and gains per DOF.
    pub pd: Option<&'a PdTargets>,
    /// Joint ranges and the joint model's gains per DOF.
    pub limits: Option<&'a JointRanges>,
    /// Floor contact of the links.
    pub contact: Option<&'a ContactModel>,
    /// Applied forces.
    pub external: &'a [ExternalForce],
}

/// The time step and its scheme.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepSettings {
    /// Integration scheme.
    pub integrator: Integrator,
    /// Time step (s).
    pub dt: f64,
}

/// What the steps saw: at the start of the latest step what each link felt from the floor
/// ([`ContactSample`]); over all steps the contact statistics, the largest range excursion per
/// DOF (rad), and per DOF how long its PD torque was held at its strength limit (s) and when
/// that first happened.
#[derive(Clone, Debug, PartialEq)]
pub struct StepMonitor {
    /// The floor at the latest step start.
    pub sample: ContactSample,
    /// Peaks, impulses, depths, touchdowns and absorbed energies over all steps.
    pub contact: ContactStats,
    /// Largest excursion past the range per DOF so far (rad).
    pub max_excursion: Vec<f64>,
    /// Time each DOF's PD torque spent at its strength limit (s, sampled at step starts).
    pub saturated_s: Vec<f64>,
    /// First step start at which each DOF's PD torque was at its limit (s).
    pub first_saturated_s: Vec<Option<f64>>,
    /// The PD torque of largest magnitude per DOF so far (N·m, signed, after the strength clamp,
    /// sampled at step starts).
    pub peak_torque: Vec<f64>,
}

impl StepMonitor {
    /// Zeros for `nlinks` links and `ndofs` actuated DOFs.
    pub fn new(nlinks: usize, ndofs: usize) -> Self {
        Self {
            sample: ContactSample::new(nlinks),
            contact: ContactStats::new(nlinks),
            max_excursion: vec![0.0; ndofs],
            saturated_s: vec![0.0; ndofs],
            first_saturated_s: vec![None; ndofs],
            peak_torque: vec![0.0; ndofs],
        }
    }
}

/// Buffers of the pipeline (no allocation per step).
#[derive(Clone, Debug)]
pub struct StepWorkspace {
    /// Buffers of the force evaluation.
    pub eval: EvalScratch,
    /// Integrator buffers.
    pub iws: IntegratorWorkspace,
}

/// Buffers of one force evaluation.
#[derive(Clone, Debug)]
pub struct EvalScratch {
    /// Dynamics buffers; after a step, the kinematics of the new state.
    pub data: Data,
    /// External forces per body (body coordinates).
    pub f_ext: Vec<ForceVec>,
    /// Joint forces (nv).
    pub tau: Vec<f64>,
    /// Joint damping coefficients (nv).
    pub damping: Vec<f64>,
    /// Joint stiffness coefficients `−∂τ/∂θ` (nv), for the linearly implicit step.
    pub stiffness: Vec<f64>,
    /// Armature `h·d` (nv).
    pub armature: Vec<f64>,
    /// Angles (nv).
    pub angles: Vec<f64>,
    /// The PD targets in velocity order (nv, zero where no DOF is driven): the reference
    /// ball joints are read nearest ([`read_angles`]).
    pub reference: Vec<f64>,
    /// Per-link normal forces (scratch).
    pub normal: Vec<f64>,
    /// PD torque and velocity coefficient per actuated DOF at the step start (N·m, N·m·s/rad),
    /// when the limits stage computed them (`step_start_pd`).
    pub pd_start: Vec<(f64, f64)>,
    /// `angles` hold the step-start angles (the limits stage computed them).
    pub step_start_angles: bool,
    /// `pd_start` holds the step-start PD torques.
    pub step_start_pd: bool,
    /// The step-start contact's implicit inertias per touching link (body coordinates), when
    /// its damping is taken implicitly ([`ContactParams::implicit_damping`]).
    ///
    /// [`ContactParams::implicit_damping`]: super::forces::contact::ContactParams::implicit_damping
    pub implicit: Vec<(usize, ArticulatedInertia)>,
    /// `data` holds the kinematics of the state after this many steps.
    pub kinematics_at_step: Option<u64>,
    /// `data` and `f_ext` hold the step-start kinematics and contact forces, so the
    /// integrator's first evaluation (always at the step-start state) reuses them.
    pub step_start_ready: bool,
}

impl StepWorkspace {
    /// Buffers for `model`.
    pub fn new(model: &Model) -> Self {
        let (nb, nv) = (model.nbodies(), model.nv);
        Self {
            eval: EvalScratch {
                data: Data::new(model),
                f_ext: vec![ForceVec::ZERO; nb],
                tau: vec![0.0; nv],
                damping: vec![0.0; nv],
                stiffness: vec![0.0; nv],
                armature: vec![0.0; nv],
                angles: vec![0.0; nv],
                reference: vec![0.0; nv],
                normal: vec![0.0; nb],
                pd_start: Vec::new(),
                step_start_angles: false,
                step_start_pd: false,
                implicit: Vec::with_capacity(nb),
                kinematics_at_step: None,
                step_start_ready: false,
            },
            iws: IntegratorWorkspace::new(model),
        }
    }

    /// Forward kinematics of `state` into the workspace, unless it already holds them; returns
    /// the data.
    #[inline(always)]
    pub fn kinematics_of(&mut self, model: &Model, state: &State) -> &Data {
        let e = &mut self.eval;
        if e.kinematics_at_step != Some(state.steps) {
            kinematics(model, &mut e.data, &state.q, &state.v);
            e.kinematics_at_step = Some(state.steps);
        }
        &e.data
    }
}

/// Why a step failed: a non-finite or runaway quantity, with the time and the body.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum StepError {
    /// A non-finite value appeared.
    #[error("non-finite {quantity} of '{body}' at t = {time_s:.4} s")]
    NonFinite {
        /// Simulated time (s).
        time_s: f64,
        /// Body (link) name.
        body: String,
        /// Which quantity.
        quantity: String,
    },
    /// The state ran away.
    #[error(
        "exploding {quantity} of '{body}' at t = {time_s:.4} s: {value:.3e} (limit {limit:.1e})"
    )]
    Exploding {
        /// Simulated time (s).
        time_s: f64,
        /// Body (link) name.
        body: String,
        /// Which quantity.
        quantity: String,
        /// Value found.
        value: f64,
        /// Allowed magnitude.
        limit: f64,
    },
}

/// Largest speed (m/s or rad/s) and position excursion (m) before a run counts as exploding:
/// far beyond any human motion (even a stiff PD snapping a hand reaches ~500 rad/s), so only a
/// numerical blow-up trips them.
pub const MAX_SPEED: f64 = 2000.0;
/// Largest distance of a body from the origin (m) before a run counts as exploding.
pub const MAX_EXTENT: f64 = 100.0;

/// One step of `settings.dt` seconds through the five stages; advances `state` (time
/// `steps · dt`) and accounts for the step in `monitor`.
///
/// On an x86-64 processor with AVX2 the stages run in a copy of their code compiled for it
/// (chosen once per process, [`crate::cpu::has_avx2`]); on evolved falls it took about 5 % less
/// wall time than the portable copy. The arithmetic is the same IEEE operations in the same
/// order (Rust never fuses a product and a sum), so both copies give the same bits.
pub fn step(
    model: &Model,
    settings: StepSettings,
    forces: &Forces,
    state: &mut State,
    ws: &mut StepWorkspace,
    monitor: &mut StepMonitor,
) -> Result<(), StepError> {
    #[cfg(target_arch = "x86_64")]
    if crate::cpu::has_avx2() {
        // SAFETY: the processor supports AVX2 (detected at run time just above).
        return unsafe { step_avx2(model, settings, forces, state, ws, monitor) };
    }
    step_stages(model, settings, forces, state, ws, monitor)
}

/// [`step_stages`] compiled for AVX2: the stages and the kernels they call are inlined here.
///
/// # Safety
/// The processor must support AVX2 ([`crate::cpu::has_avx2`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn step_avx2(
    model: &Model,
    settings: StepSettings,
    forces: &Forces,
    state: &mut State,
    ws: &mut StepWorkspace,
    monitor: &mut StepMonitor,
) -> Result<(), StepError> {
    step_stages(model, settings, forces, state, ws, monitor)
}

/// Finer steps over a stretch of time: every step whose start time (s) lies in
/// `[from_s, until_s)` is taken as `substeps` sub-steps of `dt / substeps` seconds
/// ([`step_refined`]), counted as one step of `dt`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepRefinement {
    /// Start of the stretch (s).
    pub from_s: f64,
    /// End of the stretch (s, excluded).
    pub until_s: f64,
    /// Sub-steps per step inside it (1 = none).
    pub substeps: u32,
}

impl StepRefinement {
    /// The sub-steps of a step that starts at `t` (s): [`Self::substeps`] inside the stretch
    /// (at least 1), 1 outside.
    pub fn substeps_at(&self, t: f64) -> u32 {
        if t >= self.from_s && t < self.until_s {
            self.substeps.max(1)
        } else {
            1
        }
    }
}

/// One step of `settings.dt` seconds taken as `substeps` sub-steps of `dt / substeps` by
/// [`step`], each seeing the forces at its own start time and accounted for in `monitor`
/// (peaks, impulses, saturation times of every sub-step); the state then counts one step
/// (time `steps · dt`). With `substeps` ≤ 1 it is [`step`], to the bit. An error carries the
/// end time (s) of the sub-step that failed.
pub fn step_refined(
    model: &Model,
    settings: StepSettings,
    substeps: u32,
    forces: &Forces,
    state: &mut State,
    ws: &mut StepWorkspace,
    monitor: &mut StepMonitor,
) -> Result<(), StepError> {
    if substeps <= 1 {
        return step(model, settings, forces, state, ws, monitor);
    }
    let (steps, t0) = (state.steps, state.time_s);
    let h = settings.dt / f64::from(substeps);
    let sub = StepSettings { dt: h, ..settings };
    for j in 0..substeps {
        // Each sub-step starts from the step's count at its own time; the kinematics the
        // previous sub-step left are those of this start.
        state.steps = steps;
        state.time_s = t0 + f64::from(j) * h;
        if j > 0 {
            ws.eval.kinematics_at_step = Some(steps);
        }
        step(model, sub, forces, state, ws, monitor).map_err(|mut e| {
            let (StepError::NonFinite { time_s, .. } | StepError::Exploding { time_s, .. }) =
                &mut e;
            *time_s = t0 + f64::from(j + 1) * h;
            e
        })?;
    }
    // The last sub-step counted `steps + 1` (its kinematics tagged so); its time is the step's.
    state.time_s = state.steps as f64 * settings.dt;
    Ok(())
}

/// The five stages of [`step`].
#[inline(always)]
fn step_stages(
    model: &Model,
    settings: StepSettings,
    forces: &Forces,
    state: &mut State,
    ws: &mut StepWorkspace,
    monitor: &mut StepMonitor,
) -> Result<(), StepError> {
    position_stage(model, state, ws);
    limits_stage(model, forces, state, ws, monitor, settings.dt);
    contact_stage(forces, settings, state, ws, monitor);
    integrate_stage(model, settings, forces, state, ws)?;
    check_stage(model, state, ws)
}

/// The acceleration `q̈(q, v)` (size nv) the body of `state` has under `forces` at its
/// configuration and velocity, with its friction anchors as they are (not brought to the state)
/// and joint damping explicit; time `state.time_s`. The force model is the one a step
/// integrates; the workspace's cached kinematics are invalidated.
pub fn acceleration(
    model: &Model,
    forces: &Forces,
    state: &State,
    ws: &mut StepWorkspace,
    qdd: &mut [f64],
) -> Result<(), StepError> {
    let eval = &mut ws.eval;
    eval.kinematics_at_step = None;
    eval.step_start_ready = false;
    eval.step_start_angles = false;
    eval.step_start_pd = false;
    let mut f = Evaluation {
        model,
        forces,
        anchors: &state.anchors,
        ws: eval,
    };
    f.acceleration(state.time_s, &state.q, &state.v, None, qdd)
}

/// Stage 1: kinematics at the step start.
#[inline(always)]
fn position_stage(model: &Model, state: &State, ws: &mut StepWorkspace) {
    ws.kinematics_of(model, state);
}

/// The DOF angles of `q` as the PD and the joint model see them: with PD targets, every ball
/// joint is read nearest its targets ([`Model::angles_near`]), so an arm tracked through a
/// rotation of π is not read on the opposite side; without, the principal reading
/// ([`Model::angles`]). `reference` is scratch of size nv.
#[inline(always)]
pub fn read_angles(
    model: &Model,
    forces: &Forces,
    q: &[f64],
    reference: &mut [f64],
    out: &mut [f64],
) {
    match forces.pd {
        Some(pd) => {
            reference.fill(0.0);
            for (d, &k) in forces.dofs.iter().enumerate() {
                reference[k] = pd.target[d];
            }
            model.angles_near(q, reference, out);
        }
        None => model.angles(q, out),
    }
}

/// Stage 2: the largest excursion past each DOF's range at the step start, and which PD
/// torques are at their strength limit.
#[inline(always)]
fn limits_stage(
    model: &Model,
    forces: &Forces,
    state: &State,
    ws: &mut StepWorkspace,
    monitor: &mut StepMonitor,
    dt: f64,
) {
    let limited = forces.pd.filter(|pd| !pd.torque_limits.is_empty());
    let e = &mut ws.eval;
    e.step_start_angles = false;
    e.step_start_pd = false;
    if forces.limits.is_none() && limited.is_none() {
        return;
    }
    read_angles(model, forces, &state.q, &mut e.reference, &mut e.angles);
    // The integrator's first evaluation is at this same state: it reuses the angles and the
    // PD torques computed here (the same bits, computed once).
    e.step_start_angles = true;
    if limited.is_some() {
        e.pd_start.resize(forces.dofs.len(), (0.0, 0.0));
        e.step_start_pd = true;
    }
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
}

/// Stage 3: anchors and contact forces at the step start, per-link statistics; with
/// [`ContactParams::implicit_damping`](super::forces::contact::ContactParams::implicit_damping)
/// and semi-implicit Euler, or with linearly implicit Euler, the implicit inertias of the
/// touching links for the step.
#[inline(always)]
fn contact_stage(
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
        let implicit = match settings.integrator {
            Integrator::LinearlyImplicitEuler | Integrator::LinearlyImplicitMidpoint => {
                Some(ImplicitFloor {
                    h: dt,
                    stiffness: true,
                    theta: settings.integrator.linearisation_weight().unwrap_or(1.0),
                })
            }
            Integrator::SemiImplicitEuler { .. } if cm.params.implicit_damping => {
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
    e.step_start_ready = true;
}

/// Stage 4: the integrator step; time becomes `steps · dt`.
#[inline(always)]
fn integrate_stage(
    model: &Model,
    settings: StepSettings,
    forces: &Forces,
    state: &mut State,
    ws: &mut StepWorkspace,
) -> Result<(), StepError> {
    let StepWorkspace { eval, iws } = ws;
    // The stages overwrite `data`: the cached kinematics no longer match any state.
    eval.kinematics_at_step = None;
    let mut f = Evaluation {
        model,
        forces,
        anchors: &state.anchors,
        ws: eval,
    };
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

/// Stage 5: kinematics of the new state (kept for the next step) and the divergence checks.
#[inline(always)]
fn check_stage(model: &Model, state: &State, ws: &mut StepWorkspace) -> Result<(), StepError> {
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

/// The force model evaluated at every integrator stage: joint torques (PD + joint model),
/// contact and external forces, then the ABA.
struct Evaluation<'a> {
    model: &'a Model,
    forces: &'a Forces<'a>,
    anchors: &'a ContactState,
    ws: &'a mut EvalScratch,
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
        let arm = prepare(
            self.model,
            self.forces,
            self.anchors,
            self.ws,
            t,
            q,
            v,
            implicit,
        );
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
}

/// What an evaluation takes implicitly over a step of `h` seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Implicit {
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

/// The force evaluation before the ABA: kinematics and contact forces (unless the step-start
/// stages left them), external forces, angles, PD and joint-model torques and, with
/// `implicit`, the armature (`h·d`, or `h d + h² k` with the torques corrected by `−h k v`);
/// returns whether the armature applies.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn prepare(
    model: &Model,
    forces: &Forces,
    anchors: &ContactState,
    ws: &mut EvalScratch,
    t: f64,
    q: &[f64],
    v: &[f64],
    implicit: Implicit,
) -> bool {
    let at_start = ws.step_start_ready;
    // The implicit contact damping belongs to the step-start evaluation only.
    if !at_start {
        ws.implicit.clear();
    }
    let (start_angles, start_pd) = (
        at_start && ws.step_start_angles,
        at_start && ws.step_start_pd,
    );
    ws.step_start_angles = false;
    ws.step_start_pd = false;
    if at_start {
        // First evaluation of the step: the contact stage computed kinematics and contact
        // forces at exactly this state (and the limits stage its angles and PD torques).
        ws.step_start_ready = false;
    } else {
        kinematics(model, &mut ws.data, q, v);
        ws.f_ext.fill(ForceVec::ZERO);
        if let Some(cm) = forces.contact {
            cm.apply(&ws.data, anchors, &mut ws.f_ext, &mut ws.normal);
        }
    }
    apply_external(&ws.data, forces.external, t, &mut ws.f_ext);
    if (forces.pd.is_some() || forces.limits.is_some()) && !start_angles {
        read_angles(model, forces, q, &mut ws.reference, &mut ws.angles);
    }
    let linearised = matches!(implicit, Implicit::Linearised { .. });
    for (d, &k) in forces.dofs.iter().enumerate() {
        let (th, thd) = (ws.angles[k], v[k]);
        let (mut tau, mut damp) = (0.0, 0.0);
        if start_pd {
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
fn finish(model: &Model, ws: &EvalScratch, t: f64, qdd: &mut [f64]) -> Result<(), StepError> {
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
/// one vector computation ([`crate::dynamics::aba_lanes`]). That holds for semi-implicit
/// Euler with the floor's damping explicit; any other scheme steps each body by [`step`].
/// A body whose step fails keeps its error in `result` and the others go on.
pub fn step_lanes(
    model: &Model,
    settings: StepSettings,
    bodies: &mut [LaneBody],
    lanes: &mut LaneData,
) {
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

/// The stages of [`step_lanes`].
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
        position_stage(model, state, ws);
        limits_stage(model, forces, state, ws, monitor, h);
        contact_stage(forces, settings, state, ws, monitor);
        // The integrate stage: its one evaluation's forces here, its ABA in the lanes below.
        ws.eval.kinematics_at_step = None;
        let (t, q, v) = (state.time_s, &state.q, &state.v);
        prepare(
            model,
            forces,
            &state.anchors,
            &mut ws.eval,
            t,
            q,
            v,
            implicit,
        );
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::forces::contact::{ContactGains, ContactParams, LinkBox};
    use crate::dynamics::joint::JointType;
    use crate::dynamics::model::Body;
    use crate::dynamics::spatial::{Inertia, SpatialTransform};
    use glam::DVec3;

    const SIZE: DVec3 = DVec3::new(0.4, 0.2, 0.3);

    fn free_box() -> Model {
        Model::new(
            vec![Body {
                name: "box".into(),
                joint_name: "free".into(),
                parent: None,
                joint: JointType::Free,
                x_tree: SpatialTransform::IDENTITY,
                inertia: Inertia::solid_box(2.0, DVec3::ZERO, SIZE),
            }],
            DVec3::new(0.0, -9.81, 0.0),
        )
        .unwrap()
    }

    fn run(model: &Model, forces: &Forces, steps: usize) -> (State, StepMonitor) {
        let mut q = model.neutral();
        q[1] = 0.5;
        let mut state = State::new(q, vec![0.0; model.nv], 1);
        let mut ws = StepWorkspace::new(model);
        let mut monitor = StepMonitor::new(1, 0);
        let settings = StepSettings {
            integrator: Integrator::SemiImplicitEuler {
                implicit_damping: false,
            },
            dt: 1e-3,
        };
        for _ in 0..steps {
            step(model, settings, forces, &mut state, &mut ws, &mut monitor).unwrap();
        }
        (state, monitor)
    }

    #[test]
    fn a_force_that_is_absent_is_not_felt() {
        let model = free_box();
        let none = Forces {
            dofs: &[],
            pd: None,
            limits: None,
            contact: None,
            external: &[],
        };
        // Free fall, semi-implicit Euler's closed form: y_n = y_0 − g h² n(n+1)/2.
        let n = 1000;
        let (s, m) = run(&model, &none, n);
        let expected = 0.5 - 9.81 * 1e-6 * (n * (n + 1)) as f64 / 2.0;
        assert!(
            (s.q[1] - expected).abs() < 1e-9,
            "y = {} vs {expected}",
            s.q[1]
        );
        assert_eq!(s.steps, n as u64);
        assert!((s.time_s - 1.0).abs() < 1e-12);
        assert_eq!(m.contact.peak[0], 0.0);
        // With the floor it rests on it, carrying its weight.
        let cm = ContactModel::new(
            &[LinkBox {
                center: DVec3::ZERO,
                half: SIZE * 0.5,
            }],
            &[2.0],
            &[ContactGains::per_kg(2.0, 1.2e5 * 4.0, 160.0)],
            ContactParams::default(),
        );
        let floor = Forces {
            contact: Some(&cm),
            ..none
        };
        let (s, m) = run(&model, &floor, 3000);
        assert!(s.q[1] > 0.09 && s.q[1] < 0.1, "y = {}", s.q[1]);
        assert!((m.sample.normal[0] - 2.0 * 9.81).abs() < 0.05 * 2.0 * 9.81);
        assert!(m.contact.peak[0] > 2.0 * 9.81);
        // An upward external force equal to the weight holds it in the air.
        let lift = [ExternalForce {
            body: 0,
            point: DVec3::ZERO,
            force: DVec3::new(0.0, 2.0 * 9.81, 0.0),
            torque: DVec3::ZERO,
            start_s: 0.0,
            duration_s: f64::INFINITY,
        }];
        let held = Forces {
            external: &lift,
            ..none
        };
        let (s, _) = run(&model, &held, 1000);
        assert!((s.q[1] - 0.5).abs() < 1e-9, "y = {}", s.q[1]);
    }

    /// Drops the box from 0.3 m onto a floor with a heavily damped contact (ζ ≈ 3 flat) for
    /// `seconds` at step `dt`; the final state, or the step error.
    fn drop_on_damped_floor(
        implicit_damping: bool,
        dt: f64,
        seconds: f64,
    ) -> Result<State, StepError> {
        let model = free_box();
        let cm = ContactModel::new(
            &[LinkBox {
                center: DVec3::ZERO,
                half: SIZE * 0.5,
            }],
            &[2.0],
            &[ContactGains::per_kg(2.0, 1.0e5, 2000.0)],
            ContactParams {
                implicit_damping,
                ..ContactParams::default()
            },
        );
        let forces = Forces {
            dofs: &[],
            pd: None,
            limits: None,
            contact: Some(&cm),
            external: &[],
        };
        let mut q = model.neutral();
        q[1] = 0.3;
        let mut state = State::new(q, vec![0.0; model.nv], 1);
        let mut ws = StepWorkspace::new(&model);
        let mut monitor = StepMonitor::new(1, 0);
        let settings = StepSettings {
            integrator: Integrator::SemiImplicitEuler {
                implicit_damping: true,
            },
            dt,
        };
        for _ in 0..(seconds / dt).round() as usize {
            step(&model, settings, &forces, &mut state, &mut ws, &mut monitor)?;
        }
        Ok(state)
    }

    #[test]
    fn implicit_contact_damping_lifts_the_damped_bound_and_agrees_at_small_steps() {
        // Flat on four corners ω = √(k/m) ≈ 316 rad/s, ζ = c/(2mω) ≈ 3.2: the explicit damper
        // bounds semi-implicit Euler at 2(√(1+ζ²) − ζ)/ω ≈ 1 ms (less on an edge), the
        // undamped spring at 2/ω ≈ 6 ms.
        let coarse = 2e-3;
        // Explicit at 2 ms the damper pumps energy in: the box leaves the floor higher than it
        // was dropped from (the force never pulls, so it flies instead of diverging).
        let e = drop_on_damped_floor(false, coarse, 1.0).expect("explicit at 2 ms");
        assert!(e.q[1] > 0.3, "explicit damping at 2 ms: y = {}", e.q[1]);
        let s = drop_on_damped_floor(true, coarse, 1.0).expect("implicit damping at 2 ms");
        // At rest on the floor: the box centre at half its height less the static sink.
        let sink = 2.0 * 9.81 / 1.0e5;
        assert!((s.q[1] - (0.1 - sink)).abs() < 1e-4, "y = {}", s.q[1]);
        assert!(s.v.iter().all(|v| v.abs() < 1e-3), "v = {:?}", s.v);
        // At a step far inside both bounds the two treatments are the same motion to first
        // order in h.
        let fine = 5e-5;
        let a = drop_on_damped_floor(false, fine, 0.3).unwrap();
        let b = drop_on_damped_floor(true, fine, 0.3).unwrap();
        for (x, y) in a.q.iter().zip(&b.q) {
            assert!((x - y).abs() < 1e-4, "{:?} vs {:?}", a.q, b.q);
        }
    }

    #[test]
    fn pd_follows_a_moving_target_through_its_velocity_term() {
        // τ = k_p(θ_d − θ) + k_v(θ̇_d − θ̇): at θ = θ_d the torque is k_v(θ̇_d − θ̇).
        let pd = PdTargets {
            target: vec![0.3],
            target_velocity: vec![2.0],
            kp: vec![100.0],
            kv: vec![10.0],
            torque_limits: Vec::new(),
            feedforward: Vec::new(),
        };
        let (tau, d) = pd.torque(0, 0.3, 0.5);
        assert!((tau - 15.0).abs() < 1e-12);
        assert_eq!(d, 10.0);
    }
}
