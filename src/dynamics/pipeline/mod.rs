//! One simulation step as a pipeline of named stages, after MuJoCo's `mj_step`: every stage
//! takes the immutable [`Model`], the forces the body feels ([`Forces`], plain parameters) and
//! the mutable [`State`] and [`StepWorkspace`]. Each stage has its file:
//!
//! 1. **position** (`position.rs`): forward kinematics at the step start (reused when the
//!    previous step's check left it in the workspace);
//! 2. **limits** (`limits.rs`): each DOF's excursion past its range and whether its PD torque
//!    is at its strength limit, for the [`StepMonitor`];
//! 3. **contact** (`contact.rs`): friction anchors brought to the step start, contact forces
//!    there, per-link statistics ([`ContactStats`]);
//! 4. **integrate** (`integrate.rs`): the scheme's evaluations of `q̈ = ABA(q, v, τ, f_ext)`,
//!    each summing PD torques `τ = k_p(θ_d − θ) + k_v(θ̇_d − θ̇)` (θ read by [`read_angles`]: a
//!    ball joint's rotation vector nearest its targets), the joint model, contact and external
//!    forces;
//! 5. **check** (`check.rs`): kinematics of the new state; a non-finite or runaway body stops
//!    the run with its time, body and value.
//!
//! Stages 1–3 are one sequence for [`step`] and [`step_lanes`] (`lanes.rs`); it returns what
//! it computed at the step-start state (kinematics, contact forces, and the angles and PD
//! torques when the limits stage read them) as a value the integrator's first evaluation,
//! at that same state, takes and reuses. [`step_lanes`] differs from [`step`] only in running
//! the ABA of several bodies in the lanes of one vector computation.
//!
//! A force whose parameters are absent (`None`, or no external forces) is simply not felt.

mod check;
mod contact;
mod integrate;
mod lanes;
mod limits;
mod position;
#[cfg(test)]
mod tests;

pub use lanes::{LaneBody, step_lanes};

use super::data::Data;
use super::forces::contact::{ContactModel, ContactSample, ContactState, ContactStats};
use super::forces::external::ExternalForce;
use super::forces::limits::JointRanges;
use super::forces::pd::PdTargets;
use super::integrator::{Dynamics, Integrator, IntegratorWorkspace};
use super::kinematics::kinematics;
use super::model::{Model, ModelError};
use super::spatial::{ArticulatedInertia, ForceVec};
use check::check_stage;
use contact::contact_stage;
use integrate::{Evaluation, integrate_stage};
use limits::limits_stage;
use position::position_stage;

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
    pub(super) fn count_step(&mut self, dt: f64) {
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
    /// when the limits stage computed them (with PD strength limits to watch).
    pub pd_start: Vec<(f64, f64)>,
    /// The step-start contact's implicit inertias per touching link (body coordinates), when
    /// its damping is taken implicitly ([`ContactParams::implicit_damping`]).
    ///
    /// [`ContactParams::implicit_damping`]: super::forces::contact::ContactParams::implicit_damping
    pub implicit: Vec<(usize, ArticulatedInertia)>,
    /// `data` holds the kinematics of the state after this many steps.
    pub kinematics_at_step: Option<u64>,
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
                implicit: Vec::with_capacity(nb),
                kinematics_at_step: None,
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
    /// The state or the workspace does not fit the model ([`ModelError::SizeMismatch`]).
    #[error(transparent)]
    Size(#[from] ModelError),
}

/// `Ok` when `state` (`q`: nq, `v`: nv) and the workspace (built by [`StepWorkspace::new`])
/// fit `model`, else [`ModelError::SizeMismatch`].
#[inline]
pub fn check_sizes(model: &Model, state: &State, ws: &StepWorkspace) -> Result<(), ModelError> {
    model.check_state(&state.q, &state.v)?;
    model.check_data(&ws.eval.data)
}

/// Largest speed (m/s or rad/s) and position excursion (m) before a run counts as exploding:
/// far beyond any human motion (even a stiff PD snapping a hand reaches ~500 rad/s), so only a
/// numerical blow-up trips them.
pub const MAX_SPEED: f64 = 2000.0;
/// Largest distance of a body from the origin (m) before a run counts as exploding.
pub const MAX_EXTENT: f64 = 100.0;

/// One step of `settings.dt` seconds through the five stages; advances `state` (time
/// `steps · dt`) and accounts for the step in `monitor`. A state or workspace of another size
/// than the model's is a [`StepError::Size`] and leaves everything as it was.
///
/// On an x86-64 processor with AVX2 the stages run in a copy of their code compiled for it
/// (chosen once per process, [`crate::cpu::has_avx2`]; what it saves is measured in
/// `docs/falls.md`). The arithmetic is the same IEEE operations in the same
/// order (Rust never fuses a product and a sum), so both copies give the same bits.
pub fn step(
    model: &Model,
    settings: StepSettings,
    forces: &Forces,
    state: &mut State,
    ws: &mut StepWorkspace,
    monitor: &mut StepMonitor,
) -> Result<(), StepError> {
    check_sizes(model, state, ws)?;
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
            if let StepError::NonFinite { time_s, .. } | StepError::Exploding { time_s, .. } =
                &mut e
            {
                *time_s = t0 + f64::from(j + 1) * h;
            }
            e
        })?;
    }
    // The last sub-step counted `steps + 1` (its kinematics tagged so); its time is the step's.
    state.time_s = state.steps as f64 * settings.dt;
    Ok(())
}

/// What the limits stage read of the joints at the step-start state and left in the
/// [`EvalScratch`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum JointsAtStart {
    /// Nothing: neither a joint model nor a PD strength limit to watch.
    Nothing,
    /// The angles ([`EvalScratch::angles`]).
    Angles,
    /// The angles and the PD torques ([`EvalScratch::angles`], [`EvalScratch::pd_start`]).
    AnglesAndPd,
}

impl JointsAtStart {
    /// The angles are there.
    #[inline(always)]
    pub(super) fn angles(self) -> bool {
        self != Self::Nothing
    }

    /// The PD torques are there.
    #[inline(always)]
    pub(super) fn pd(self) -> bool {
        self == Self::AnglesAndPd
    }
}

/// What the stages before the integrator computed at the step-start state and left in the
/// [`EvalScratch`]: the kinematics (position stage), the contact forces and implicit inertias
/// (contact stage), and what `joints` says (limits stage). The integrator's first evaluation,
/// at that same state, takes it and reuses them (the same bits, computed once); every later
/// evaluation computes its own.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct StepStart {
    /// The joint quantities the limits stage computed.
    pub(super) joints: JointsAtStart,
}

/// The stages before the integrator (position, limits, contact), shared by [`step`] and
/// [`step_lanes`]; returns what they left for the integrator's first evaluation.
#[inline(always)]
pub(super) fn start_stages(
    model: &Model,
    settings: StepSettings,
    forces: &Forces,
    state: &mut State,
    ws: &mut StepWorkspace,
    monitor: &mut StepMonitor,
) -> StepStart {
    position_stage(model, state, ws);
    let joints = limits_stage(model, forces, state, ws, monitor, settings.dt);
    contact_stage(forces, settings, state, ws, monitor);
    StepStart { joints }
}

/// The five stages of [`step`].
#[inline(always)]
pub(super) fn step_stages(
    model: &Model,
    settings: StepSettings,
    forces: &Forces,
    state: &mut State,
    ws: &mut StepWorkspace,
    monitor: &mut StepMonitor,
) -> Result<(), StepError> {
    let start = start_stages(model, settings, forces, state, ws, monitor);
    integrate_stage(model, settings, forces, state, ws, start)?;
    check_stage(model, state, ws)
}

/// The acceleration `q̈(q, v)` (size nv) the body of `state` has under `forces` at its
/// configuration and velocity, with its friction anchors as they are (not brought to the state)
/// and joint damping explicit; time `state.time_s`. The force model is the one a step
/// integrates; the workspace's cached kinematics are invalidated. Arguments of another size
/// than the model's are a [`StepError::Size`].
pub fn acceleration(
    model: &Model,
    forces: &Forces,
    state: &State,
    ws: &mut StepWorkspace,
    qdd: &mut [f64],
) -> Result<(), StepError> {
    check_sizes(model, state, ws)?;
    super::model::check_size("qdd", model.nv, qdd.len())?;
    // Nothing computed at a step start: the evaluation computes every force itself.
    let mut f = Evaluation::new(model, forces, &state.anchors, &mut ws.eval, None);
    f.acceleration(state.time_s, &state.q, &state.v, None, qdd)
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
    debug_assert!(q.len() == model.nq && reference.len() == model.nv);
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
