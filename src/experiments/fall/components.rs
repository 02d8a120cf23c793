//! The ECS components of a falling character (body, joint state, PD controller, joint limits,
//! contact, damage, recorder, workspace), plain data that the phases of
//! [`fall`](super::fall) update and the systems of [`ecs`](super::ecs) query.

use crate::dynamics::forces::contact::{ContactModel, ContactState};
use crate::dynamics::data::Data;
use super::result::{FallFrame, SimError};
use crate::humanoid::body::HumanBody;
use crate::dynamics::integrator::{Integrator, IntegratorWorkspace};
use crate::dynamics::forces::limits::JointLimitParams;
use crate::dynamics::forces::external::Push;
use crate::dynamics::spatial::ForceVec;
use bevy_ecs::component::Component;
use std::sync::Arc;

/// The body component: the immutable articulated human and its contact geometry.
#[derive(Component, Clone, Debug)]
pub struct BodyModel {
    /// The fall21 human.
    pub body: Arc<HumanBody>,
    /// Its contact boxes, gains and the floor.
    pub contact: Arc<ContactModel>,
}

/// The joint-state component: configuration, velocity and clock.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct JointState {
    /// Configuration `q` (size nq).
    pub q: Vec<f64>,
    /// Velocity `v` (size nv).
    pub v: Vec<f64>,
    /// Simulated time (s).
    pub time_s: f64,
    /// Steps taken.
    pub steps: u64,
}

/// The PD-controller component (per DOF, fall21 order; radians inside).
#[derive(Component, Clone, Debug, PartialEq)]
pub struct PdController {
    /// Stance target (rad).
    pub stance_pose: Vec<f64>,
    /// Stance gains.
    pub stance_kp: Vec<f64>,
    /// Stance damping.
    pub stance_kv: Vec<f64>,
    /// Key pose θ_d (rad).
    pub key_pose: Vec<f64>,
    /// Key-pose gains k_p.
    pub kp: Vec<f64>,
    /// Key-pose damping k_v.
    pub kv: Vec<f64>,
    /// Switch time (s).
    pub control_start_s: f64,
    /// True once the key pose is the active target (set by the control phase).
    pub reacting: bool,
}

/// The joint-limit component: ranges and the joint-model gains, and the largest excursions.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct JointLimits {
    /// `(lo, hi)` per DOF (rad).
    pub ranges: Vec<(f64, f64)>,
    /// Gains.
    pub params: JointLimitParams,
    /// Largest excursion past the range per DOF so far (rad).
    pub max_excursion: Vec<f64>,
}

/// The contact component: friction anchors, the push, and the latest per-link normal forces.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct ContactComponent {
    /// Friction anchors.
    pub state: ContactState,
    /// The push and the index of the pushed link.
    pub push: Push,
    /// Index of the pushed link.
    pub push_link: usize,
    /// Normal force per link at the start of the current step (N).
    pub normal: Vec<f64>,
    /// Deepest penetration at the start of the current step (m).
    pub penetration: f64,
    /// Deepest penetration per link at the start of the current step (m).
    pub depth: Vec<f64>,
}

/// The damage component: per-link peaks and impulses (the paper's eq. 5.1).
#[derive(Component, Clone, Debug, PartialEq)]
pub struct DamageRecord {
    /// Weight w_i per link.
    pub weights: Vec<f64>,
    /// Peak normal force per link (N).
    pub peak: Vec<f64>,
    /// Normal impulse per link (N·s).
    pub impulse: Vec<f64>,
    /// Deepest penetration (m).
    pub max_penetration: f64,
    /// Deepest penetration per link (m).
    pub max_depth: Vec<f64>,
}

/// The recorder component: frames and rest detection.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct Recorder {
    /// Index of the next frame to record; frame `k` is the state at the step nearest to
    /// `k / hz` (within half a step).
    pub next_frame: u64,
    /// Frames so far.
    pub frames: Vec<FallFrame>,
    /// Rest threshold (J).
    pub rest_energy: f64,
    /// Start of the current rest interval (s).
    pub rest_since: Option<f64>,
    /// Rest is only detected from this time on (the end of the push, s).
    pub rest_after: f64,
    /// Hold time (s).
    pub rest_hold: f64,
    /// Steps to run in total.
    pub total_steps: u64,
    /// Time step (s).
    pub dt: f64,
    /// Frame rate (Hz).
    pub hz: f64,
    /// Integration scheme.
    pub integrator: Integrator,
    /// End the run once the body has rested for the hold time.
    pub stop_at_rest: bool,
}

impl Recorder {
    /// True once the run is over for `state`: all steps taken, or (with `stop_at_rest`) the
    /// body has stayed at rest for the hold time.
    pub fn finished(&self, state: &JointState) -> bool {
        state.steps >= self.total_steps
            || (self.stop_at_rest
                && self
                    .rest_since
                    .is_some_and(|t0| state.time_s - t0 >= self.rest_hold))
    }
}

/// The scratch workspace component (dynamics and integrator buffers; no allocation per step).
#[derive(Component, Clone, Debug)]
pub struct Workspace {
    /// Buffers of the force model and the algorithms.
    pub scratch: Scratch,
    /// Integrator buffers.
    pub iws: IntegratorWorkspace,
    /// The first error of the run; the world stops stepping once set.
    pub error: Option<Arc<SimError>>,
}

/// Buffers of the force model.
#[derive(Clone, Debug)]
pub struct Scratch {
    /// Dynamics buffers.
    pub data: Data,
    /// External forces per body.
    pub f_ext: Vec<ForceVec>,
    /// Joint forces (nv).
    pub tau: Vec<f64>,
    /// Joint damping coefficients (nv).
    pub damping: Vec<f64>,
    /// Armature `h·d` (nv).
    pub armature: Vec<f64>,
    /// Angles (nv).
    pub angles: Vec<f64>,
    /// Per-link normal forces (scratch).
    pub normal: Vec<f64>,
    /// `data` holds the kinematics of the state after this many steps (a cache the record and
    /// contact phases share; cleared when the integrator overwrites `data`).
    pub kinematics_at_step: Option<u64>,
    /// `data` and `f_ext` hold the step-start kinematics and contact forces, so the integrator's
    /// first evaluation (always at the step-start state) reuses them.
    pub step_start_ready: bool,
}

/// All components of one falling character.
#[derive(Clone, Debug)]
pub struct FallParts {
    /// Body.
    pub body: BodyModel,
    /// State.
    pub state: JointState,
    /// Controller.
    pub pd: PdController,
    /// Joint limits.
    pub limits: JointLimits,
    /// Contact.
    pub contact: ContactComponent,
    /// Damage.
    pub damage: DamageRecord,
    /// Recorder.
    pub recorder: Recorder,
    /// Workspace.
    pub ws: Workspace,
}
