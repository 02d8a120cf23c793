//! A whole pushed fall (SPEC §3): the fall21 human stands (PD holding a stance), is pushed, and
//! reacts with PD control toward one key pose; joints have friction and range limits, links
//! touch the floor through penalty boxes. [`simulate_fall`] runs it as a plain function;
//! [`ecs`](super::ecs) runs the same phases as systems over components.
//!
//! Each step runs the phases in order: control (choose the active PD target), limits (monitor
//! range excursions), contact (friction anchors, per-link force statistics), dynamics step (the
//! integrator; every stage evaluates PD + joint model + contact + push and the ABA), record
//! (frames, rest detection, divergence checks).

use super::contact::{ContactModel, ContactParams, ContactState};
use super::crba::{cholesky_factor, cholesky_solve, crba};
use super::data::Data;
use super::human::{HumanBody, HumanError, fall21_body};
use super::integrator::{Dynamics, Integrator, IntegratorWorkspace, step};
use super::kinematics::kinematics;
use super::limits::{JointLimitParams, joint_torque};
use super::pd::pd_torque;
use super::push::Push;
use super::spatial::ForceVec;
use crate::model::ranges::{AgeGroup, RangeError, RangeTable};
use bevy_ecs::component::Component;
use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::sync::Arc;

/// Where the joint ranges come from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Ranges {
    /// A built-in age group (`scenes/models/fall21_{elderly,adult}.ron`).
    Builtin(AgeGroup),
    /// A user table (degrees), e.g. loaded with [`RangeTable::load`].
    Table(RangeTable),
    /// A range-table RON file (like `scenes/models/fall21_elderly.ron`), read when the fall is
    /// built; a relative path is taken from the working directory.
    File(std::path::PathBuf),
}

/// Everything that defines one pushed fall. Angles in degrees, per fall21 DOF in model order.
/// In a scene file every field may be left out: it then takes its value from
/// [`FallConfig::paper`] for the elderly group (`FallConfig::default()`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FallConfig {
    /// Standing height (m).
    pub height_m: f64,
    /// Body mass (kg).
    pub mass_kg: f64,
    /// Gravitational acceleration magnitude (m/s²), acting along −Y.
    pub gravity: f64,
    /// Joint ranges (age group).
    pub ranges: Ranges,
    /// Joint-model gains (friction inside the range, spring and damper past it).
    pub limits: JointLimitParams,
    /// Initial standing pose (deg, 21 DOFs), held by the stance gains until `control_start_s`.
    pub stance_pose_deg: Vec<f64>,
    /// Stance PD stiffness per DOF (N·m/rad).
    pub stance_kp: Vec<f64>,
    /// Stance PD damping per DOF (N·m·s/rad).
    pub stance_kv: Vec<f64>,
    /// Key pose θ_d (deg, 21 DOFs) the reaction drives toward (θ̇_d = 0).
    pub key_pose_deg: Vec<f64>,
    /// PD stiffness k_p per DOF toward the key pose (N·m/rad) — a GA gene.
    pub kp: Vec<f64>,
    /// PD damping k_v per DOF (N·m·s/rad).
    pub kv: Vec<f64>,
    /// Time at which control switches from the stance to the key pose (s).
    pub control_start_s: f64,
    /// The push.
    pub push: Push,
    /// Time step (s).
    pub dt_s: f64,
    /// Integration scheme.
    pub integrator: Integrator,
    /// Simulated time (s).
    pub duration_s: f64,
    /// Floor contact parameters.
    pub contact: ContactParams,
    /// Damage weight w_i per link name (links not listed weigh 1).
    pub damage_weights: BTreeMap<String, f64>,
    /// Frames recorded per second.
    pub record_hz: f64,
    /// The body is at rest while its kinetic energy stays below this (J)…
    pub rest_kinetic_energy_j: f64,
    /// …for at least this long (s), up to the end of the run.
    pub rest_hold_s: f64,
}

/// A per-DOF table in fall21 order from a function of the DOF name.
fn per_dof(names: &[String], f: impl Fn(&str) -> f64) -> Vec<f64> {
    names.iter().map(|n| f(n)).collect()
}

fn strip_side(n: &str) -> &str {
    n.trim_start_matches("left_").trim_start_matches("right_")
}

impl FallConfig {
    /// The paper's experiment for `group`: a 1.70 m, 65 kg subject standing with bent knees
    /// (34°: the elderly knee range of the paper's Table 1 starts at 32°, so both groups stand
    /// alike inside their ranges), pushed with 1000 N on the chest from the front for 0.1 s from
    /// t = 0.1 s; the reaction toward the key pose (here the stance itself) starts at 0.25 s;
    /// semi-implicit Euler with implicit damping at 0.5 ms (the contact stability bound is
    /// 0.63 ms) for 3 s; damage weights protect the head most (w = 10).
    pub fn paper(group: AgeGroup) -> Self {
        let names = crate::model::fall21().dof_names();
        let stance = per_dof(&names, |n| match strip_side(n) {
            "waist_flexion" => 5.0,
            "elbow" => 30.0,
            "hip_flexion" => 16.0,
            "knee" => 34.0,
            "ankle" => 17.0,
            _ => 0.0,
        });
        let gain = |n: &str| match strip_side(n) {
            "neck_flexion" | "neck_lateral" | "neck_rotation" => 40.0,
            "waist_flexion" | "waist_rotation" => 600.0,
            "shoulder_flexion" | "shoulder_rotation" => 60.0,
            "elbow" => 40.0,
            "wrist" => 8.0,
            "hip_flexion" | "hip_abduction" => 600.0,
            "knee" => 600.0,
            "ankle" => 400.0,
            _ => 50.0,
        };
        let kp = per_dof(&names, gain);
        let kv = per_dof(&names, |n| 0.1 * gain(n));
        let mut w = BTreeMap::new();
        for (link, wi) in [
            ("head", 10.0),
            ("torso", 2.0),
            ("pelvis", 2.0),
            ("right_upper_arm", 1.0),
            ("left_upper_arm", 1.0),
            ("right_forearm", 1.0),
            ("left_forearm", 1.0),
            ("right_hand", 0.5),
            ("left_hand", 0.5),
            ("right_thigh", 1.0),
            ("left_thigh", 1.0),
            ("right_shin", 1.0),
            ("left_shin", 1.0),
            ("right_foot", 0.2),
            ("left_foot", 0.2),
        ] {
            w.insert(link.to_string(), wi);
        }
        let h = 1.70;
        Self {
            height_m: h,
            mass_kg: 65.0,
            gravity: 9.81,
            ranges: Ranges::Builtin(group),
            limits: JointLimitParams::default(),
            stance_pose_deg: stance.clone(),
            stance_kp: kp.clone(),
            stance_kv: kv.clone(),
            key_pose_deg: stance,
            kp,
            kv,
            control_start_s: 0.25,
            push: super::push::paper_push(0.1, 0.16 * h),
            dt_s: 5e-4,
            integrator: Integrator::SemiImplicitEuler {
                implicit_damping: true,
            },
            duration_s: 3.0,
            contact: ContactParams::default(),
            damage_weights: w,
            record_hz: 60.0,
            rest_kinetic_energy_j: 1.0,
            rest_hold_s: 0.3,
        }
    }
}

impl Default for FallConfig {
    /// The paper's experiment for the elderly group.
    fn default() -> Self {
        Self::paper(AgeGroup::Elderly)
    }
}

/// One recorded frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FallFrame {
    /// Time (s).
    pub time_s: f64,
    /// Pelvis (root) position, world (m).
    pub root_position: DVec3,
    /// Pelvis orientation (body → world).
    pub root_orientation: DQuat,
    /// Every fall21 DOF angle in model order (rad).
    pub angles: Vec<f64>,
    /// Height of the head's centre of mass above the floor (m).
    pub head_height_m: f64,
}

/// The outcome of a fall.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FallResult {
    /// DOF names (fall21 model order), matching `FallFrame::angles`.
    pub dof_names: Vec<String>,
    /// Link names, matching the per-link vectors.
    pub link_names: Vec<String>,
    /// Frames at `record_hz`: frame `k` is the state at the step nearest to `k / record_hz`.
    pub frames: Vec<FallFrame>,
    /// Frame rate of `frames` (Hz).
    pub record_hz: f64,
    /// Damage `D = Σ w_i f_i` (N): the paper's eq. 5.1.
    pub damage: f64,
    /// Peak vertical (normal) floor force per link, f_i (N).
    pub peak_vertical_force_n: Vec<f64>,
    /// Normal impulse per link (N·s).
    pub impulse_n_s: Vec<f64>,
    /// Deepest corner penetration into the floor over the run (m).
    pub max_penetration_m: f64,
    /// Deepest corner penetration per link over the run (m).
    pub max_penetration_by_link_m: Vec<f64>,
    /// Largest excursion of any DOF past its range over the run (rad), per DOF.
    pub max_limit_excursion_rad: Vec<f64>,
    /// True if the kinetic energy stayed below the rest threshold for the hold time at the end.
    pub came_to_rest: bool,
    /// Time from which the body stayed at rest (s).
    pub rest_time_s: Option<f64>,
    /// Integration steps taken.
    pub steps: u64,
    /// Time step (s).
    pub dt_s: f64,
    /// Standing height of the simulated subject (m).
    pub height_m: f64,
}

impl FallResult {
    /// The recorded motion as a clip on the fall21 model (scaled to the subject's height), ready
    /// for BVH output and pictures.
    pub fn to_model_clip(&self) -> crate::model::ModelClip {
        crate::model::ModelClip {
            model: crate::model::fall21().scaled_to_height(self.height_m),
            frame_time: 1.0 / self.record_hz,
            root_translation: self.frames.iter().map(|f| f.root_position).collect(),
            root_rotation: self.frames.iter().map(|f| f.root_orientation).collect(),
            angles: self
                .frames
                .iter()
                .flat_map(|f| f.angles.iter().copied())
                .collect(),
        }
    }
}

/// Why a fall could not be simulated.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// A configuration field is invalid.
    #[error("fall configuration: {field}: {message}")]
    Config {
        /// Field name.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// The body could not be built.
    #[error(transparent)]
    Body(#[from] HumanError),
    /// The joint ranges could not be resolved.
    #[error(transparent)]
    Ranges(#[from] RangeError),
    /// The step is too large for a stiffness (checked before running).
    #[error(
        "dt = {dt_s} s exceeds the {integrator} stability bound {bound_s:.3e} s for the {what} of '{body}' \
         (natural frequency {omega:.1} rad/s, damping ratio {zeta:.2}); lower dt_s or the {what} stiffness"
    )]
    Unstable {
        /// "contact" or "joint <dof>".
        what: String,
        /// Link concerned.
        body: String,
        /// Natural frequency bound (rad/s).
        omega: f64,
        /// Damping ratio.
        zeta: f64,
        /// Step given (s).
        dt_s: f64,
        /// Largest stable step (s).
        bound_s: f64,
        /// Scheme name.
        integrator: &'static str,
    },
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

fn cfg_err(field: &str, message: impl Into<String>) -> SimError {
    SimError::Config {
        field: field.into(),
        message: message.into(),
    }
}

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

fn check_len(field: &str, v: &[f64], n: usize) -> Result<(), SimError> {
    if v.len() != n {
        return Err(cfg_err(
            field,
            format!("needs {n} values (one per fall21 DOF), found {}", v.len()),
        ));
    }
    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
        return Err(cfg_err(field, format!("non-finite value {x}")));
    }
    Ok(())
}

fn positive(field: &str, x: f64) -> Result<(), SimError> {
    if !(x.is_finite() && x > 0.0) {
        return Err(cfg_err(
            field,
            format!("must be a positive number, found {x}"),
        ));
    }
    Ok(())
}

/// The stable step bound for a damped oscillator `ẍ = −ω²x − 2ζωẋ`: semi-implicit Euler
/// `h ≤ 2(√(1+ζ²) − ζ)/ω`; RK4 `h ≤ 2.5 / (ω(ζ + √(1+ζ²)))` (the real-axis limit is 2.78 and
/// the imaginary-axis limit 2.83 in units of `1/|λ|`).
pub fn stable_step(integrator: Integrator, omega: f64, zeta: f64) -> f64 {
    if omega <= 0.0 {
        return f64::INFINITY;
    }
    let s = (1.0 + zeta * zeta).sqrt();
    match integrator {
        Integrator::Rk4 => 2.5 / (omega * (zeta + s)),
        Integrator::SemiImplicitEuler { .. } => 2.0 * (s - zeta) / omega,
    }
}

fn scheme_name(i: Integrator) -> &'static str {
    match i {
        Integrator::Rk4 => "RK4",
        Integrator::SemiImplicitEuler {
            implicit_damping: true,
        } => "semi-implicit Euler (implicit damping)",
        Integrator::SemiImplicitEuler { .. } => "semi-implicit Euler",
    }
}

/// Checks the step against the contact and joint stiffnesses before running: per link the
/// contact bound of [`ContactModel::link_frequency`]; per DOF `ω² = (k_p + k_lim)(H⁻¹)_jj`,
/// `2ζω = d (H⁻¹)_jj` (`d` the joint damping, zero when it is taken implicitly) with `H` the
/// joint-space inertia at the stance.
pub fn check_stability(cfg: &FallConfig, parts: &FallParts) -> Result<(), SimError> {
    let body = &parts.body.body;
    let cm = &parts.body.contact;
    let dt = cfg.dt_s;
    for i in 0..body.model.nbodies() {
        let (omega, zeta) = cm.link_frequency(i, &body.model.bodies[i].inertia);
        let bound = stable_step(cfg.integrator, omega, zeta);
        if dt > bound {
            return Err(SimError::Unstable {
                what: "contact".into(),
                body: body.link_names[i].clone(),
                omega,
                zeta,
                dt_s: dt,
                bound_s: bound,
                integrator: scheme_name(cfg.integrator),
            });
        }
    }
    let model = &body.model;
    let nv = model.nv;
    let mut data = Data::new(model);
    crba(model, &mut data, &parts.state.q);
    let mut h = data.h.clone();
    cholesky_factor(&mut h, nv).map_err(|e| cfg_err("body", e.to_string()))?;
    let implicit = matches!(
        cfg.integrator,
        Integrator::SemiImplicitEuler {
            implicit_damping: true
        }
    );
    for (d, &k) in body.dof_v.iter().enumerate() {
        let mut e = vec![0.0; nv];
        e[k] = 1.0;
        cholesky_solve(&h, nv, &mut e);
        let w = e[k];
        let stiff = cfg.kp[d].max(cfg.stance_kp[d]) + cfg.limits.limit_kp;
        let damp = if implicit {
            0.0
        } else {
            cfg.kv[d].max(cfg.stance_kv[d]) + cfg.limits.limit_kv.max(cfg.limits.friction_kv)
        };
        let omega = (stiff * w).sqrt();
        let zeta = if omega > 0.0 {
            damp * w / (2.0 * omega)
        } else {
            0.0
        };
        let bound = stable_step(cfg.integrator, omega, zeta);
        if dt > bound {
            let j = body.figure.dofs[d].joint;
            return Err(SimError::Unstable {
                what: format!("joint {}", body.figure.dofs[d].name),
                body: body.link_names[j].clone(),
                omega,
                zeta,
                dt_s: dt,
                bound_s: bound,
                integrator: scheme_name(cfg.integrator),
            });
        }
    }
    Ok(())
}

/// Validates `cfg`, builds the body and its initial state (standing on the floor), and checks
/// the step against the stability bounds.
pub fn build_fall(cfg: &FallConfig) -> Result<FallParts, SimError> {
    positive("dt_s", cfg.dt_s)?;
    positive("duration_s", cfg.duration_s)?;
    positive("record_hz", cfg.record_hz)?;
    positive("gravity", cfg.gravity)?;
    let body = fall21_body(cfg.height_m, cfg.mass_kg, cfg.gravity)?;
    let n = body.dof_v.len();
    for (f, v) in [
        ("stance_pose_deg", &cfg.stance_pose_deg),
        ("stance_kp", &cfg.stance_kp),
        ("stance_kv", &cfg.stance_kv),
        ("key_pose_deg", &cfg.key_pose_deg),
        ("kp", &cfg.kp),
        ("kv", &cfg.kv),
    ] {
        check_len(f, v, n)?;
    }
    for (f, v) in [
        ("stance_kp", &cfg.stance_kp),
        ("stance_kv", &cfg.stance_kv),
        ("kp", &cfg.kp),
        ("kv", &cfg.kv),
    ] {
        if let Some(x) = v.iter().find(|x| **x < 0.0) {
            return Err(cfg_err(f, format!("gains must be ≥ 0, found {x}")));
        }
    }
    let c = &cfg.contact;
    for (f, x) in [
        ("contact.stiffness_per_kg", c.stiffness_per_kg),
        (
            "contact.tangential_stiffness_per_kg",
            c.tangential_stiffness_per_kg,
        ),
    ] {
        positive(f, x)?;
    }
    if !(c.damping_per_kg >= 0.0 && c.tangential_damping_per_kg >= 0.0 && c.friction >= 0.0) {
        return Err(cfg_err("contact", "damping and friction must be ≥ 0"));
    }
    if c.floor_normal.is_nan() || (c.floor_normal.length() - 1.0).abs() >= 1e-9 {
        return Err(cfg_err("contact.floor_normal", "must be a unit vector"));
    }
    for (f, x) in [
        ("limits.friction_kv", cfg.limits.friction_kv),
        ("limits.limit_kp", cfg.limits.limit_kp),
        ("limits.limit_kv", cfg.limits.limit_kv),
    ] {
        if !(x.is_finite() && x >= 0.0) {
            return Err(cfg_err(f, format!("must be ≥ 0, found {x}")));
        }
    }
    let push_link = body.link_index(&cfg.push.link).ok_or_else(|| {
        cfg_err(
            "push.link",
            format!(
                "'{}' is not a fall21 link ({:?})",
                cfg.push.link, body.link_names
            ),
        )
    })?;
    if !(cfg.push.force_n.is_finite()
        && cfg.push.duration_s >= 0.0
        && cfg.push.direction.length() > 0.0)
    {
        return Err(cfg_err(
            "push",
            "force must be finite, duration ≥ 0 and direction non-zero",
        ));
    }
    let mut weights = vec![1.0; body.link_names.len()];
    for (name, w) in &cfg.damage_weights {
        let i = body.link_index(name).ok_or_else(|| {
            cfg_err(
                "damage_weights",
                format!("'{name}' is not a fall21 link ({:?})", body.link_names),
            )
        })?;
        if !(w.is_finite() && *w >= 0.0) {
            return Err(cfg_err(
                "damage_weights",
                format!("weight of '{name}' must be ≥ 0, found {w}"),
            ));
        }
        weights[i] = *w;
    }
    let table = match &cfg.ranges {
        Ranges::Builtin(g) => RangeTable::builtin(*g),
        Ranges::Table(t) => t.clone(),
        Ranges::File(p) => RangeTable::load(p)?,
    };
    let ranges = table.for_model(&body.figure)?;
    let rad = |v: &[f64]| v.iter().map(|x| x.to_radians()).collect::<Vec<_>>();
    let stance = rad(&cfg.stance_pose_deg);

    // Stand the figure on the floor: lowest foot corner at the floor, less the static sink.
    let masses: Vec<f64> = body.model.bodies.iter().map(|b| b.inertia.mass).collect();
    let cm = ContactModel::new(&body.boxes, &masses, cfg.contact);
    let mut q = body.configuration(&stance, DVec3::ZERO, DQuat::IDENTITY);
    let mut data = Data::new(&body.model);
    let zeros = vec![0.0; body.model.nv];
    kinematics(&body.model, &mut data, &q, &zeros);
    let n_up = cfg.contact.floor_normal;
    let mut lowest = f64::INFINITY;
    for (i, corners) in cm.corners.iter().enumerate() {
        for &cl in corners {
            lowest = lowest.min(n_up.dot(data.pos[i] + data.rot[i] * cl));
        }
    }
    let sink = cfg.gravity / (4.0 * cfg.contact.stiffness_per_kg);
    let shift = n_up * (cfg.contact.floor_height - lowest - sink);
    for k in 0..3 {
        q[k] += shift[k];
    }

    let nl = body.link_names.len();
    let nv = body.model.nv;
    let frames = (cfg.duration_s * cfg.record_hz).floor() as usize + 1;
    let total_steps = (cfg.duration_s / cfg.dt_s).round() as u64;
    let body = Arc::new(body);
    let parts = FallParts {
        state: JointState {
            q,
            v: zeros,
            time_s: 0.0,
            steps: 0,
        },
        pd: PdController {
            stance_pose: stance,
            stance_kp: cfg.stance_kp.clone(),
            stance_kv: cfg.stance_kv.clone(),
            key_pose: rad(&cfg.key_pose_deg),
            kp: cfg.kp.clone(),
            kv: cfg.kv.clone(),
            control_start_s: cfg.control_start_s,
            reacting: false,
        },
        limits: JointLimits {
            ranges,
            params: cfg.limits,
            max_excursion: vec![0.0; n],
        },
        contact: ContactComponent {
            state: ContactState::new(nl),
            push: cfg.push.clone(),
            push_link,
            normal: vec![0.0; nl],
            penetration: 0.0,
            depth: vec![0.0; nl],
        },
        damage: DamageRecord {
            weights,
            peak: vec![0.0; nl],
            impulse: vec![0.0; nl],
            max_penetration: 0.0,
            max_depth: vec![0.0; nl],
        },
        recorder: Recorder {
            next_frame: 0,
            frames: Vec::with_capacity(frames),
            rest_energy: cfg.rest_kinetic_energy_j,
            rest_since: None,
            rest_hold: cfg.rest_hold_s,
            total_steps,
            dt: cfg.dt_s,
            hz: cfg.record_hz,
            integrator: cfg.integrator,
        },
        ws: Workspace {
            scratch: Scratch {
                data,
                f_ext: vec![ForceVec::ZERO; nl],
                tau: vec![0.0; nv],
                damping: vec![0.0; nv],
                armature: vec![0.0; nv],
                angles: vec![0.0; nv],
                normal: vec![0.0; nl],
                kinematics_at_step: None,
                step_start_ready: false,
            },
            iws: IntegratorWorkspace::new(&body.model),
            error: None,
        },
        body: BodyModel {
            body,
            contact: Arc::new(cm),
        },
    };
    check_stability(cfg, &parts)?;
    Ok(parts)
}

/// The force model of the fall, evaluated at every integrator stage: PD + joint model torques,
/// contact and push forces, then the ABA.
pub struct FallDynamics<'a> {
    /// Body.
    pub body: &'a HumanBody,
    /// Contact model.
    pub contact_model: &'a ContactModel,
    /// Controller.
    pub pd: &'a PdController,
    /// Limits.
    pub limits: &'a JointLimits,
    /// Contact anchors and push.
    pub contact: &'a ContactComponent,
    /// Buffers.
    pub ws: &'a mut Scratch,
}

impl Dynamics for FallDynamics<'_> {
    type Error = SimError;

    fn acceleration(
        &mut self,
        t: f64,
        q: &[f64],
        v: &[f64],
        implicit_dt: Option<f64>,
        qdd: &mut [f64],
    ) -> Result<(), SimError> {
        let model = &self.body.model;
        let ws = &mut *self.ws;
        if ws.step_start_ready {
            // First evaluation of the step: the contact phase already computed kinematics and
            // contact forces at exactly this state.
            ws.step_start_ready = false;
        } else {
            kinematics(model, &mut ws.data, q, v);
            ws.f_ext.fill(ForceVec::ZERO);
            self.contact_model
                .apply(&ws.data, &self.contact.state, &mut ws.f_ext, &mut ws.normal);
        }
        let push = &self.contact.push;
        if push.active(t) {
            let i = self.contact.push_link;
            let f = push.body_force(&ws.data, i);
            ws.f_ext[i] += f;
        }
        model.angles(q, &mut ws.angles);
        let pd = self.pd;
        let (target, kp, kv) = if pd.reacting {
            (&pd.key_pose, &pd.kp, &pd.kv)
        } else {
            (&pd.stance_pose, &pd.stance_kp, &pd.stance_kv)
        };
        for (d, &k) in self.body.dof_v.iter().enumerate() {
            let (th, thd) = (ws.angles[k], v[k]);
            let (t1, d1) = pd_torque(kp[d], kv[d], target[d], 0.0, th, thd);
            let (t2, d2) = joint_torque(&self.limits.params, self.limits.ranges[d], th, thd);
            ws.tau[k] = t1 + t2;
            ws.damping[k] = d1 + d2;
        }
        let arm = match implicit_dt {
            Some(h) => {
                for k in 0..ws.armature.len() {
                    ws.armature[k] = h * ws.damping[k];
                }
                Some(&ws.armature[..])
            }
            None => None,
        };
        super::aba::aba_passes(model, &mut ws.data, &ws.tau, &ws.f_ext, arm);
        qdd.copy_from_slice(&ws.data.qdd);
        if let Some(k) = qdd.iter().position(|x| !x.is_finite()) {
            let b = (0..model.nbodies())
                .rev()
                .find(|&b| model.v_idx[b] <= k)
                .unwrap_or(0);
            return Err(SimError::NonFinite {
                time_s: t,
                body: self.body.link_names[b].clone(),
                quantity: "joint acceleration".into(),
            });
        }
        Ok(())
    }
}

/// Control phase: the key pose becomes the PD target at `control_start_s`.
pub fn control_phase(state: &JointState, pd: &mut PdController) {
    pd.reacting = state.time_s >= pd.control_start_s;
}

/// Limits phase: the largest excursion past each DOF's range at the step start.
pub fn limits_phase(
    body: &BodyModel,
    state: &JointState,
    limits: &mut JointLimits,
    ws: &mut Workspace,
) {
    let ws = &mut ws.scratch;
    body.body.model.angles(&state.q, &mut ws.angles);
    for (d, &k) in body.body.dof_v.iter().enumerate() {
        let (lo, hi) = limits.ranges[d];
        let th = ws.angles[k];
        let ex = (lo - th).max(th - hi).max(0.0);
        limits.max_excursion[d] = limits.max_excursion[d].max(ex);
    }
}

/// Contact phase at the step start: updates the friction anchors, then records per link the
/// normal force (peak), its impulse over the coming step of `dt` seconds and the deepest
/// penetration.
pub fn contact_phase(
    body: &BodyModel,
    state: &JointState,
    contact: &mut ContactComponent,
    damage: &mut DamageRecord,
    dt: f64,
    ws: &mut Workspace,
) {
    let ws = &mut ws.scratch;
    let model = &body.body.model;
    if ws.kinematics_at_step != Some(state.steps) {
        kinematics(model, &mut ws.data, &state.q, &state.v);
    }
    ws.f_ext.fill(ForceVec::ZERO);
    contact.penetration = body.contact.update_and_apply(
        &ws.data,
        &mut contact.state,
        &mut ws.f_ext,
        &mut contact.normal,
        &mut contact.depth,
    );
    ws.step_start_ready = true;
    for i in 0..contact.normal.len() {
        let f = contact.normal[i];
        damage.peak[i] = damage.peak[i].max(f);
        damage.impulse[i] += f * dt;
        damage.max_depth[i] = damage.max_depth[i].max(contact.depth[i]);
    }
    damage.max_penetration = damage.max_penetration.max(contact.penetration);
}

/// Dynamics phase: one integrator step of the full force model.
pub fn dynamics_phase(
    body: &BodyModel,
    state: &mut JointState,
    pd: &PdController,
    limits: &JointLimits,
    contact: &ContactComponent,
    recorder: &Recorder,
    ws: &mut Workspace,
) -> Result<(), SimError> {
    let b = &*body.body;
    let JointState {
        q,
        v,
        time_s,
        steps,
    } = state;
    let Workspace { scratch, iws, .. } = ws;
    // The stages overwrite `data`: the cached kinematics will no longer match any state.
    scratch.kinematics_at_step = None;
    let mut dynm = FallDynamics {
        body: b,
        contact_model: &body.contact,
        pd,
        limits,
        contact,
        ws: scratch,
    };
    step(
        recorder.integrator,
        &b.model,
        iws,
        &mut dynm,
        *time_s,
        recorder.dt,
        q,
        v,
    )?;
    *steps += 1;
    *time_s = *steps as f64 * recorder.dt;
    Ok(())
}

/// Largest speed (m/s or rad/s) and position excursion (m) before a run counts as exploding:
/// far beyond any human motion (even a stiff PD snapping a hand reaches ~500 rad/s), so only a
/// numerical blow-up trips them.
const MAX_SPEED: f64 = 2000.0;
const MAX_EXTENT: f64 = 100.0;

/// Record phase after the step: divergence checks (non-finite or exploding state names the
/// body), frames at the record rate, and rest detection from the kinetic energy.
pub fn record_phase(
    body: &BodyModel,
    state: &JointState,
    recorder: &mut Recorder,
    ws: &mut Workspace,
) -> Result<(), SimError> {
    let b = &*body.body;
    let model = &b.model;
    let sc = &mut ws.scratch;
    let t = state.time_s;
    kinematics(model, &mut sc.data, &state.q, &state.v);
    sc.kinematics_at_step = Some(state.steps);
    let mut ke = 0.0;
    for i in 0..model.nbodies() {
        let (p, vel) = (sc.data.pos[i], sc.data.v[i]);
        let name = || b.link_names[i].clone();
        if !p.is_finite() || !sc.data.rot[i].is_finite() {
            return Err(SimError::NonFinite {
                time_s: t,
                body: name(),
                quantity: "position".into(),
            });
        }
        if !vel.is_finite() {
            return Err(SimError::NonFinite {
                time_s: t,
                body: name(),
                quantity: "velocity".into(),
            });
        }
        let speed = vel.ang.length().max(vel.lin.length());
        if speed > MAX_SPEED {
            return Err(SimError::Exploding {
                time_s: t,
                body: name(),
                quantity: "speed".into(),
                value: speed,
                limit: MAX_SPEED,
            });
        }
        if p.abs().max_element() > MAX_EXTENT {
            return Err(SimError::Exploding {
                time_s: t,
                body: name(),
                quantity: "position".into(),
                value: p.abs().max_element(),
                limit: MAX_EXTENT,
            });
        }
        ke += model.bodies[i].inertia.kinetic_energy(vel);
    }
    if ke < recorder.rest_energy {
        recorder.rest_since.get_or_insert(t);
    } else {
        recorder.rest_since = None;
    }
    if state.steps >= frame_step(recorder, recorder.next_frame) {
        recorder.frames.push(frame(b, state, sc));
        recorder.next_frame += 1;
    }
    Ok(())
}

/// The step at which frame `k` is taken: the one nearest to `k / hz`.
fn frame_step(rec: &Recorder, k: u64) -> u64 {
    (k as f64 / (rec.hz * rec.dt)).round() as u64
}

fn frame(b: &HumanBody, state: &JointState, sc: &mut Scratch) -> FallFrame {
    let q = &state.q;
    b.model.angles(q, &mut sc.angles);
    let angles = b.dof_v.iter().map(|&k| sc.angles[k]).collect();
    let head = b.link_index("head").unwrap_or(0);
    let head_com = sc.data.pos[head] + sc.data.rot[head] * b.model.bodies[head].inertia.com;
    FallFrame {
        time_s: state.time_s,
        root_position: DVec3::new(q[0], q[1], q[2]),
        root_orientation: DQuat::from_xyzw(q[3], q[4], q[5], q[6]),
        angles,
        head_height_m: head_com.y,
    }
}

/// One full step of all phases in order: control → limits → contact → dynamics step → record.
pub fn step_fall(parts: &mut FallParts) -> Result<(), SimError> {
    let FallParts {
        body,
        state,
        pd,
        limits,
        contact,
        damage,
        recorder,
        ws,
    } = parts;
    control_phase(state, pd);
    limits_phase(body, state, limits, ws);
    contact_phase(body, state, contact, damage, recorder.dt, ws);
    dynamics_phase(body, state, pd, limits, contact, recorder, ws)?;
    record_phase(body, state, recorder, ws)
}

/// The first frame (t = 0), recorded before stepping.
pub fn record_initial(parts: &mut FallParts) {
    let FallParts {
        body,
        state,
        recorder,
        ws,
        ..
    } = parts;
    kinematics(&body.body.model, &mut ws.scratch.data, &state.q, &state.v);
    ws.scratch.kinematics_at_step = Some(state.steps);
    let f = frame(&body.body, state, &mut ws.scratch);
    recorder.frames.push(f);
    recorder.next_frame = 1;
}

/// Collects the result of a finished run from its components; the damage is
/// `D = Σ w_i f_i` (eq. 5.1).
pub fn finish(
    body: &BodyModel,
    state: &JointState,
    limits: &JointLimits,
    damage: &DamageRecord,
    recorder: &Recorder,
) -> FallResult {
    let b = &body.body;
    let d = damage;
    let total = d.weights.iter().zip(&d.peak).map(|(w, f)| w * f).sum();
    let end = state.time_s;
    let rest_time_s = recorder
        .rest_since
        .filter(|&t0| end - t0 >= recorder.rest_hold);
    FallResult {
        dof_names: b.figure.dof_names(),
        link_names: b.link_names.clone(),
        frames: recorder.frames.clone(),
        record_hz: recorder.hz,
        damage: total,
        peak_vertical_force_n: d.peak.clone(),
        impulse_n_s: d.impulse.clone(),
        max_penetration_m: d.max_penetration,
        max_penetration_by_link_m: d.max_depth.clone(),
        max_limit_excursion_rad: limits.max_excursion.clone(),
        came_to_rest: rest_time_s.is_some(),
        rest_time_s,
        steps: state.steps,
        dt_s: recorder.dt,
        height_m: b.figure.height,
    }
}

/// Simulates one pushed fall from `config` and returns its record.
pub fn simulate_fall(config: &FallConfig) -> Result<FallResult, SimError> {
    let mut parts = build_fall(config)?;
    record_initial(&mut parts);
    for _ in 0..parts.recorder.total_steps {
        step_fall(&mut parts)?;
    }
    Ok(finish(
        &parts.body,
        &parts.state,
        &parts.limits,
        &parts.damage,
        &parts.recorder,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Largest |x| after `n` steps of `ẍ = −ω²x − 2ζωẋ` from x = 1 with the given scheme.
    fn oscillate(integrator: Integrator, omega: f64, zeta: f64, h: f64, n: usize) -> f64 {
        let f = |x: f64, v: f64| -omega * omega * x - 2.0 * zeta * omega * v;
        let (mut x, mut v) = (1.0f64, 0.0f64);
        let mut peak: f64 = 0.0;
        for _ in 0..n {
            match integrator {
                Integrator::SemiImplicitEuler { .. } => {
                    v += h * f(x, v);
                    x += h * v;
                }
                Integrator::Rk4 => {
                    let (k1x, k1v) = (v, f(x, v));
                    let (k2x, k2v) = (v + 0.5 * h * k1v, f(x + 0.5 * h * k1x, v + 0.5 * h * k1v));
                    let (k3x, k3v) = (v + 0.5 * h * k2v, f(x + 0.5 * h * k2x, v + 0.5 * h * k2v));
                    let (k4x, k4v) = (v + h * k3v, f(x + h * k3x, v + h * k3v));
                    x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
                    v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
                }
            }
            peak = peak.max(x.abs());
        }
        peak
    }

    #[test]
    fn the_step_bound_separates_stable_from_unstable() {
        let euler = Integrator::SemiImplicitEuler {
            implicit_damping: false,
        };
        for zeta in [0.0, 0.3, 1.0, 3.0] {
            let b = stable_step(euler, 100.0, zeta);
            assert!(
                oscillate(euler, 100.0, zeta, 0.99 * b, 20_000) < 10.0,
                "ζ={zeta}"
            );
            assert!(
                oscillate(euler, 100.0, zeta, 1.02 * b, 20_000) > 1e3,
                "ζ={zeta}"
            );
            // RK4's bound is conservative: stable at it.
            let r = stable_step(Integrator::Rk4, 100.0, zeta);
            assert!(
                oscillate(Integrator::Rk4, 100.0, zeta, r, 20_000) <= 1.0 + 1e-9,
                "ζ={zeta}"
            );
        }
    }
}
