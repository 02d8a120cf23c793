//! The falling paper's pushed fall (SPEC §3) as an experiment: the fall21 human stands (PD
//! holding a stance), is pushed, and reacts with PD control toward one key pose; joints have
//! friction and range limits, links touch the floor through penalty boxes; the damage is the
//! weighted peak floor force per link (eq. 5.1).
//!
//! [`build_fall`] turns a [`FallConfig`] into the components of one falling character
//! ([`FallCharacter`]): the physics components the step reads (PD, joint limits, floor contact,
//! the push as an external force) plus the paper's [`FallController`] and a [`FallRecorder`].
//! [`simulate_fall`] runs them as a plain loop; the same parts run as systems in a World
//! ([`add_fall_systems`], [`build_fall_world`], [`run_fall_world`]) and many Worlds in parallel
//! ([`run_parallel`]), to the same bits.
//!
//! Everything is used from here (`marionette::experiments::fall::FallConfig`); the files are
//! private: `config` ([`FallConfig`]), `controller` ([`FallController`]), `recorder`
//! ([`FallRecorder`]), `result` ([`FallResult`], [`SimError`]) and `ecs` (the systems and the
//! parallel runs).

mod config;
mod controller;
mod ecs;
mod recorder;
mod result;

pub use self::config::{FallConfig, LIMIT_FREQUENCY_HZ, Ranges};
pub use self::controller::FallController;
pub use self::ecs::{
    ReactionStart, add_fall_systems, build_fall_world, fall_control_system, fall_record_system,
    fall_results, fall_schedule, run_fall_world, run_parallel, run_parallel_from,
    run_parallel_reacting, run_parallel_until, spawn_fall,
};
pub use self::recorder::FallRecorder;
pub use self::result::{
    FallFrame, FallResult, LinkImpact, PeakTorque, PelvisImpact, SimError, StandingStart,
    TorqueSaturation,
};

use std::sync::Arc;

use glam::{DQuat, DVec3};

use crate::dynamics::Data;
use crate::dynamics::ModelError;
use crate::dynamics::forces::contact::ContactModel;
use crate::dynamics::forces::limits::{JointRanges, limit_gains};
use crate::dynamics::forces::pd::PdTargets;
use crate::dynamics::kinematics;
use crate::dynamics::pipeline::{self, Forces, StepRefinement, StepSettings};
use crate::dynamics::{BalanceSettings, balance_base, holding_torques};
use crate::dynamics::{
    DofStiffness, StiffestMode, StiffnessBasis, inverse_joint_inertia, scheme_name,
};
use crate::ecs::human::{HumanFigure, human_physics};
use crate::ecs::physics::{ExternalForces, FloorContact, JointLimits, PdController, PhysicsBundle};
use crate::humanoid::RangeTable;
use crate::humanoid::tissue;
use crate::humanoid::{HumanBody, shared_fall21_body};

/// The most steps one fall may take (checked before it runs): 3 s at 0.15 µs.
pub const MAX_STEPS: u64 = 20_000_000;
/// The most frames one fall may record.
pub const MAX_FRAMES: u64 = 1_000_000;

fn cfg_err(field: &str, message: impl Into<String>) -> SimError {
    SimError::Config {
        field: field.into(),
        message: message.into(),
    }
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

/// Checks every field of `cfg` and resolves what it names: the body, the pushed link, the
/// damage weights per link and the joint ranges per DOF (rad).
fn validate(cfg: &FallConfig) -> Result<Resolved, SimError> {
    positive("dt_s", cfg.dt_s)?;
    positive("duration_s", cfg.duration_s)?;
    positive("record_hz", cfg.record_hz)?;
    positive("gravity", cfg.gravity)?;
    let body = shared_fall21_body(cfg.height_m, cfg.mass_kg, cfg.gravity)?;
    let n = body.dof_v.len();
    check_pose_and_gains(
        n,
        ("stance_pose_deg", &cfg.stance_pose_deg),
        [("stance_kp", &cfg.stance_kp), ("stance_kv", &cfg.stance_kv)],
    )?;
    validate_reaction(cfg, n)?;
    positive("settle_max_s", cfg.settle_max_s)?;
    check_refinement(cfg)?;
    check_run_size(cfg)?;
    check_contact_and_limits(cfg)?;
    let push_link = resolve_push(cfg, &body)?;
    let weights = damage_weights(cfg, &body)?;
    let table = match &cfg.ranges {
        Ranges::Builtin(g) => RangeTable::builtin(*g),
        Ranges::Table(t) => t.clone(),
        Ranges::File(p) => RangeTable::load(p)?,
    };
    let ranges = table.for_figure(&body.figure)?;
    check_torque_limits(cfg, &body)?;
    Ok(Resolved {
        body,
        push_link,
        weights,
        ranges,
    })
}

/// The reaction's sub-steps (at least 1) and their window (finite, ≥ 0 s).
fn check_refinement(cfg: &FallConfig) -> Result<(), SimError> {
    if cfg.reaction_substeps < 1 {
        return Err(cfg_err("reaction_substeps", "must be at least 1"));
    }
    let w = cfg.reaction_window_s;
    if !(w.is_finite() && w >= 0.0) {
        return Err(cfg_err(
            "reaction_window_s",
            format!("must be ≥ 0 s, found {w}"),
        ));
    }
    Ok(())
}

/// The reaction's finer steps of `cfg` (see [`FallConfig::reaction_substeps`]), if any.
fn reaction_refinement(cfg: &FallConfig) -> Option<StepRefinement> {
    (cfg.reaction_substeps > 1 && cfg.reaction_window_s > 0.0).then_some(StepRefinement {
        from_s: cfg.control_start_s,
        until_s: cfg.control_start_s + cfg.reaction_window_s,
        substeps: cfg.reaction_substeps,
    })
}

/// The run's size (steps and recorded frames, checked before anything is allocated or run)
/// and the push's start inside it.
fn check_run_size(cfg: &FallConfig) -> Result<(), SimError> {
    let refined = cfg.reaction_window_s.min(cfg.duration_s) / cfg.dt_s;
    let steps =
        cfg.duration_s / cfg.dt_s + refined * (f64::from(cfg.reaction_substeps) - 1.0).max(0.0);
    if steps > MAX_STEPS as f64 {
        return Err(cfg_err(
            "duration_s",
            format!(
                "{} s at dt = {} s is {steps:.3e} steps; at most {MAX_STEPS} are allowed \
                 (shorten the duration or enlarge the step)",
                cfg.duration_s, cfg.dt_s
            ),
        ));
    }
    let frames = cfg.duration_s * cfg.record_hz;
    if frames > MAX_FRAMES as f64 {
        return Err(cfg_err(
            "record_hz",
            format!(
                "{} s at {} Hz is {frames:.3e} frames; at most {MAX_FRAMES} are allowed",
                cfg.duration_s, cfg.record_hz
            ),
        ));
    }
    if !(cfg.push.start_s.is_finite() && cfg.push.start_s >= 0.0)
        || cfg.push.start_s >= cfg.duration_s
    {
        return Err(cfg_err(
            "push.start_s",
            format!(
                "the push starts at {} s, but the simulation runs from 0 to {} s: \
                 it must start inside the run",
                cfg.push.start_s, cfg.duration_s
            ),
        ));
    }
    Ok(())
}

/// The floor contact's stiffnesses (> 0), damping and friction (≥ 0) and unit normal; the joint
/// limits' gains (≥ 0).
fn check_contact_and_limits(cfg: &FallConfig) -> Result<(), SimError> {
    let c = &cfg.contact;
    for (f, x) in [
        ("contact.stiffness_scale", c.stiffness_scale),
        (
            "contact.tangential_stiffness_per_kg",
            c.tangential_stiffness_per_kg,
        ),
    ] {
        positive(f, x)?;
    }
    if !(c.damping_scale >= 0.0 && c.tangential_damping_per_kg >= 0.0 && c.friction >= 0.0) {
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
    if let Some(hz) = cfg.limits.limit_frequency_hz {
        positive("limits.limit_frequency_hz", hz)?;
    }
    let zeta = cfg.limits.limit_damping_ratio;
    if !(zeta.is_finite() && zeta >= 0.0) {
        return Err(cfg_err(
            "limits.limit_damping_ratio",
            format!("must be ≥ 0, found {zeta}"),
        ));
    }
    Ok(())
}

/// The pushed link's index, the push's force finite, its duration ≥ 0, its direction non-zero.
fn resolve_push(cfg: &FallConfig, body: &HumanBody) -> Result<usize, SimError> {
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
    Ok(push_link)
}

/// The damage weight of each link: 1 unless `cfg.damage_weights` names it (weights ≥ 0).
fn damage_weights(cfg: &FallConfig, body: &HumanBody) -> Result<Vec<f64>, SimError> {
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
    Ok(weights)
}

/// The torque limits, if given: one finite (min ≤ 0, max ≥ 0) pair per DOF.
fn check_torque_limits(cfg: &FallConfig, body: &HumanBody) -> Result<(), SimError> {
    let Some(t) = &cfg.torque_limits_nm else {
        return Ok(());
    };
    let n = body.dof_v.len();
    if t.len() != n {
        return Err(cfg_err(
            "torque_limits_nm",
            format!(
                "needs {n} (min, max) pairs (one per fall21 DOF), found {}",
                t.len()
            ),
        ));
    }
    if let Some((d, (lo, hi))) = t
        .iter()
        .enumerate()
        .find(|(_, (lo, hi))| !(lo.is_finite() && hi.is_finite() && *lo <= 0.0 && *hi >= 0.0))
    {
        return Err(cfg_err(
            "torque_limits_nm",
            format!(
                "{}: ({lo}, {hi}) must be finite with min ≤ 0 ≤ max",
                body.figure.dofs[d].name
            ),
        ));
    }
    Ok(())
}

/// Checks the reaction's fields of `cfg` (key pose, k_p, k_v: `n` finite values each, gains
/// ≥ 0), the only fields in which falls sharing a [`ecs::ReactionStart`] differ.
fn validate_reaction(cfg: &FallConfig, n: usize) -> Result<(), SimError> {
    check_pose_and_gains(
        n,
        ("key_pose_deg", &cfg.key_pose_deg),
        [("kp", &cfg.kp), ("kv", &cfg.kv)],
    )
}

/// A pose and its two gains: `n` finite values each, the gains ≥ 0.
fn check_pose_and_gains(
    n: usize,
    pose: (&str, &[f64]),
    gains: [(&str, &[f64]); 2],
) -> Result<(), SimError> {
    check_len(pose.0, pose.1, n)?;
    for (f, v) in gains {
        check_len(f, v, n)?;
    }
    for (f, v) in gains {
        if let Some(x) = v.iter().find(|x| **x < 0.0) {
            return Err(cfg_err(f, format!("gains must be ≥ 0, found {x}")));
        }
    }
    Ok(())
}

/// The reaction's PD targets of `cfg`: the key pose θ_d (rad) held with k_p and k_v, capped by
/// the strength.
fn key_targets(cfg: &FallConfig) -> PdTargets {
    let rad = |v: &[f64]| v.iter().map(|x| x.to_radians()).collect::<Vec<_>>();
    PdTargets::hold(rad(&cfg.key_pose_deg), cfg.kp.clone(), cfg.kv.clone())
        .with_torque_limits(cfg.torque_limits_nm.clone().unwrap_or_default())
}

/// `cfg` with the reaction's fields (key pose, k_p, k_v) set to fixed values: what falls that
/// may share a [`ecs::ReactionStart`] have in common.
fn reaction_key(cfg: &FallConfig) -> FallConfig {
    let base = FallConfig::default();
    FallConfig {
        key_pose_deg: base.key_pose_deg,
        kp: base.kp,
        kv: base.kv,
        ..cfg.clone()
    }
}

/// What a configuration names, resolved.
struct Resolved {
    body: Arc<HumanBody>,
    push_link: usize,
    weights: Vec<f64>,
    ranges: Vec<(f64, f64)>,
}

/// The components of one falling character.
#[derive(Clone, Debug)]
pub struct FallCharacter {
    /// Model, state, buffers, monitor and status.
    pub physics: PhysicsBundle,
    /// The human the body is (figure, DOF map, link names).
    pub human: HumanFigure,
    /// PD targets and gains (the stance first).
    pub pd: PdController,
    /// Joint ranges of the age group and the joint model.
    pub limits: JointLimits,
    /// Floor contact.
    pub contact: FloorContact,
    /// The push.
    pub external: ExternalForces,
    /// Stance, then key pose.
    pub controller: FallController,
    /// Frames, rest, damage weights.
    pub recorder: FallRecorder,
}

/// The configuration standing on the floor in `pose` (rad): the lowest contact corner at the
/// floor, less the static sink of the contact springs.
fn standing_configuration(
    cfg: &FallConfig,
    body: &HumanBody,
    contact: &ContactModel,
    pose: &[f64],
) -> Vec<f64> {
    let mut q = body.configuration(pose, DVec3::ZERO, DQuat::IDENTITY);
    let mut data = Data::new(&body.model);
    let zeros = vec![0.0; body.model.nv()];
    kinematics(&body.model, &mut data, &q, &zeros);
    let n_up = cfg.contact.floor_normal;
    let mut lowest = f64::INFINITY;
    for (i, corners) in contact.corners().iter().enumerate() {
        for &cl in corners {
            lowest = lowest.min(n_up.dot(data.pos[i] + data.rot[i] * cl));
        }
    }
    // Sink of the feet under the whole weight, half on each (the settling phase finds the rest).
    let weight = body.model.total_mass() * cfg.gravity;
    let foot = body.link_index("right_foot").unwrap_or(0);
    let sink = contact.static_sink(foot, 0.5 * weight);
    let shift = n_up * (cfg.contact.floor_height - lowest - sink);
    for k in 0..3 {
        q[k] += shift[k];
    }
    q
}

/// Checks the step against the contact and joint stiffnesses before running and, if it is too
/// large, names the most restrictive mode (its bound is the largest usable step). A DOF's
/// stiffness is its larger PD gain plus the limit spring; its damping is taken explicitly
/// unless the scheme takes it implicitly.
pub fn check_stability(cfg: &FallConfig, ch: &FallCharacter) -> Result<(), SimError> {
    check_stability_with(cfg, ch, &stiffness_basis(cfg, ch))
}

/// [`check_stability`] with the part that does not depend on the gains already found
/// ([`stiffness_basis`] of the same character and configuration but for its gains): the same
/// answer, bit for bit.
pub(crate) fn check_stability_with(
    cfg: &FallConfig,
    ch: &FallCharacter,
    basis: &Result<StiffnessBasis, ModelError>,
) -> Result<(), SimError> {
    let body = &*ch.human;
    let basis = basis.as_ref().map_err(|e| cfg_err("body", e.to_string()))?;
    match basis.stiffest_mode(&dof_stiffness(cfg, ch)) {
        Some(m) if cfg.dt_s > m.bound_s => Err(SimError::Unstable {
            what: m.what,
            body: body.link_names[m.body].clone(),
            omega: m.omega,
            zeta: m.zeta,
            dt_s: cfg.dt_s,
            bound_s: m.bound_s,
            integrator: scheme_name(cfg.integrator),
        }),
        _ => Ok(()),
    }
}

/// The stiffest mode of the fall `cfg` standing at its start (contact per link; per DOF its
/// larger PD gain plus its limit spring): its bound is the largest stable step (s). `None` when
/// nothing is stiff.
pub fn stiffest_mode_of_config(cfg: &FallConfig) -> Result<Option<StiffestMode>, SimError> {
    let ch = assemble(cfg)?;
    let basis = stiffness_basis(cfg, &ch).map_err(|e| cfg_err("body", e.to_string()))?;
    Ok(basis.stiffest_mode(&dof_stiffness(cfg, &ch)))
}

/// What the stability check of the character `ch` of `cfg` at its current configuration finds
/// independently of the gains (contact modes, inverse joint inertia); an error if its
/// joint-space inertia is not positive definite.
pub(crate) fn stiffness_basis(
    cfg: &FallConfig,
    ch: &FallCharacter,
) -> Result<StiffnessBasis, ModelError> {
    let body = &*ch.human;
    StiffnessBasis::new(
        &body.model,
        &ch.physics.state.q,
        cfg.integrator,
        Some(&ch.contact.0),
    )
}

/// Each DOF's stiffness for the stability check: its larger PD gain plus its limit spring, its
/// damping explicit unless the scheme takes it implicitly.
fn dof_stiffness(cfg: &FallConfig, ch: &FallCharacter) -> Vec<DofStiffness> {
    let body = &*ch.human;
    let implicit = matches!(
        cfg.integrator,
        crate::dynamics::Integrator::SemiImplicitEuler {
            implicit_damping: true
        }
    );
    let l = &ch.limits.0;
    body.dof_v
        .iter()
        .enumerate()
        .map(|(d, &k)| {
            let (limit_kp, limit_kv) = l.limit(d);
            DofStiffness {
                v: k,
                body: body.figure.dofs[d].joint,
                name: body.figure.dofs[d].name.clone(),
                stiffness: cfg.kp[d].max(cfg.stance_kp[d]) + limit_kp,
                damping: if implicit {
                    0.0
                } else {
                    cfg.kv[d].max(cfg.stance_kv[d]) + limit_kv.max(l.params.friction_kv)
                },
            }
        })
        .collect()
}

/// Validates `cfg`, builds the body standing on the floor with its controller, push and
/// recorder, checks the step against the stability bounds and settles the standing body.
pub fn build_fall(cfg: &FallConfig) -> Result<FallCharacter, SimError> {
    build_fall_from(cfg, None)
}

/// A settled standing start: the state the settling phase of a configuration ends in. It
/// depends only on what the body stands with (subject, stance pose and gains, strength, joint
/// model, floor, step), not on the key pose, its gains or the push, so many falls that differ only
/// in those (a GA's population) can share one.
#[derive(Clone, Debug, PartialEq)]
pub struct SettledStart {
    /// The configuration it was settled for, with the fields that do not affect settling
    /// normalised.
    key: FallConfig,
    /// The settled state (at rest).
    state: pipeline::State,
    /// The stance's holding torque per DOF (N·m), its feedforward.
    hold: Vec<f64>,
}

/// `cfg` with every field that does not affect the settling phase set to a fixed value.
fn settle_key(cfg: &FallConfig) -> FallConfig {
    let base = FallConfig::default();
    FallConfig {
        control_start_s: base.control_start_s,
        push: base.push,
        duration_s: base.duration_s,
        damage_weights: base.damage_weights,
        record_hz: base.record_hz,
        rest_kinetic_energy_j: base.rest_kinetic_energy_j,
        rest_hold_s: base.rest_hold_s,
        stop_at_rest: base.stop_at_rest,
        reaction_substeps: base.reaction_substeps,
        reaction_window_s: base.reaction_window_s,
        ..reaction_key(cfg)
    }
}

impl SettledStart {
    /// Settles the standing body of `cfg`.
    pub fn of(cfg: &FallConfig) -> Result<Self, SimError> {
        let ch = build_fall(cfg)?;
        Ok(Self {
            key: settle_key(cfg),
            state: ch.physics.state.0,
            hold: ch.controller.stance.feedforward,
        })
    }

    /// True when `cfg` stands as this start was settled for.
    pub fn fits(&self, cfg: &FallConfig) -> bool {
        self.key == settle_key(cfg)
    }
}

/// [`build_fall`], taking the settled state from `start` when it fits `cfg` (the same bits as
/// settling anew), else settling.
pub fn build_fall_from(
    cfg: &FallConfig,
    start: Option<&SettledStart>,
) -> Result<FallCharacter, SimError> {
    let mut ch = assemble(cfg)?;
    check_stability(cfg, &ch)?;
    let (settled, hold) = match start {
        Some(s) if s.fits(cfg) => (s.state.clone(), s.hold.clone()),
        _ => settle(cfg, &ch)?,
    };
    ch.recorder.settle_s = settled.time_s;
    let st = &mut ch.physics.state.0;
    st.q = settled.q;
    st.anchors = settled.anchors;
    ch.controller.stance.feedforward = hold.clone();
    ch.pd.0.feedforward = hold;
    Ok(ch)
}

/// The validated character of `cfg` standing on the floor, before the stability check and the
/// settling phase.
fn assemble(cfg: &FallConfig) -> Result<FallCharacter, SimError> {
    let Resolved {
        body,
        push_link,
        weights,
        ranges,
    } = validate(cfg)?;
    let rad = |v: &[f64]| v.iter().map(|x| x.to_radians()).collect::<Vec<_>>();
    let stance_pose = rad(&cfg.stance_pose_deg);
    let masses: Vec<f64> = body.model.bodies().iter().map(|b| b.inertia.mass).collect();
    let gains: Vec<_> = body
        .link_names
        .iter()
        .map(|n| {
            tissue::region(n)
                .map(|r| r.gains())
                .ok_or_else(|| cfg_err("body", format!("link '{n}' has no tissue region")))
        })
        .collect::<Result<_, _>>()?;
    let contact = ContactModel::new(&body.boxes, &masses, &gains, cfg.contact);
    let q = standing_configuration(cfg, &body, &contact, &stance_pose);
    let strength = cfg.torque_limits_nm.clone().unwrap_or_default();
    let stance = PdTargets::hold(stance_pose, cfg.stance_kp.clone(), cfg.stance_kv.clone())
        .with_torque_limits(strength);
    let key = key_targets(cfg);
    let limit_gains = match cfg.limits.limit_frequency_hz {
        Some(hz) => inverse_joint_inertia(&body.model, &q, &body.dof_v)
            .map_err(|e| cfg_err("body", e.to_string()))?
            .into_iter()
            .map(|w| limit_gains(hz, cfg.limits.limit_damping_ratio, w))
            .collect(),
        None => Vec::new(),
    };
    let nv = body.model.nv();
    let (mut physics, human) = human_physics(body, cfg.integrator, q);
    physics.body.refinement = reaction_refinement(cfg);
    Ok(FallCharacter {
        physics,
        human,
        pd: PdController(stance.clone()),
        limits: JointLimits(JointRanges {
            ranges,
            params: cfg.limits,
            limit_gains,
        }),
        contact: FloorContact(Arc::new(contact)),
        external: ExternalForces::new(vec![cfg.push.to_force(push_link)]),
        controller: FallController {
            stance,
            key,
            start_s: cfg.control_start_s,
            reacting: false,
        },
        recorder: FallRecorder::new(cfg, weights, nv),
    })
}

/// Relaxation time of the settling phase's velocity damping (s).
const SETTLE_TAU_S: f64 = 0.02;
/// The damped phase ends once the kinetic energy stays below this (J)…
const SETTLED_KE_J: f64 = 1e-4;
/// …for this long (s).
const SETTLED_HOLD_S: f64 = 0.05;
/// Largest joint acceleration (rad/s², m/s²) the settled state may keep under the stance with
/// its holding torques: rounding only.
const SETTLED_QDD: f64 = 1e-6;

/// The settling phase, in two parts.
///
/// 1. From the standing configuration the body is stepped with the stance control, joint model
///    and floor (no push), its velocity relaxed by `v ← v e^{−h/τ}` (τ = 20 ms) after each
///    step, until the kinetic energy has stayed below 1e-4 J for 50 ms: the feet land and
///    anchor where they come to rest, the joints sag under the stance gains.
/// 2. That state is not an equilibrium. The PD stance alone leans on a very soft whole-body
///    mode (the body pivoting over its ankles against stance gains barely above `m g h`): the
///    damping slows that lean to a creep of about a millimetre per second long before it is
///    balanced (a Newton step toward a balance of the PD stance alone asks for 0.18 rad, ten
///    degrees, more lean: far outside its linearisation). A standing person holds
///    the posture with the static torque of their muscles, and so does the stance here: the
///    body is placed where gravity and the floor balance on it
///    ([`balance_base`]: the net wrench on the free base zeroed, joints held, anchors
///    re-seated), and the joint torques that hold the pose there ([`holding_torques`],
///    `τ_hold = −(H q̈)_joints` at rest) are added to the stance PD as its feedforward.
///
/// Returns the state (`v = 0`, its anchors, its time the settling time) and the holding torque
/// per DOF (N·m); with them `q̈ = 0` to rounding, so the push acts on a body at rest: forces in
/// equilibrium, foot force equal to the weight.
fn settle(cfg: &FallConfig, ch: &FallCharacter) -> Result<(pipeline::State, Vec<f64>), SimError> {
    let physics = &ch.physics.body;
    let model = &*physics.model;
    let mut state = ch.physics.state.0.clone();
    let mut ws = pipeline::StepWorkspace::new(model);
    let settings = StepSettings {
        integrator: physics.integrator,
        dt: cfg.dt_s,
    };
    let forces = Forces {
        dofs: &physics.dofs,
        pd: Some(&ch.pd.0),
        limits: Some(&ch.limits.0),
        contact: Some(&ch.contact.0),
        external: &[],
    };
    relax_to_rest(cfg, model, settings, &forces, &mut state, &mut ws)?;
    let base = model.v_offset(0)..model.v_offset(0) + model.bodies()[0].joint.nv();
    balance_base(
        model,
        &forces,
        &mut state,
        &mut ws,
        base,
        BalanceSettings::default(),
    )?;
    let hold = holding_torques(model, &forces, &state, &mut ws, &physics.dofs)?;
    let mut held = ch.pd.0.clone();
    held.feedforward = hold.clone();
    check_holding_strength(&ch.human, &held, &state)?;
    let mut qdd = vec![0.0; model.nv()];
    let held_forces = Forces {
        pd: Some(&held),
        ..forces
    };
    pipeline::acceleration(model, &held_forces, &state, &mut ws, &mut qdd)?;
    let left = qdd.iter().fold(0.0f64, |m, a| m.max(a.abs()));
    if left > SETTLED_QDD {
        return Err(cfg_err(
            "settle_max_s",
            format!(
                "the settled stance is not at rest: a joint acceleration of {left:.2e} remains"
            ),
        ));
    }
    Ok((state, hold))
}

/// Steps the standing body with its velocities relaxed (time constant [`SETTLE_TAU_S`]) until
/// its kinetic energy has stayed under [`SETTLED_KE_J`] for [`SETTLED_HOLD_S`]; an error if
/// that takes `cfg.settle_max_s`.
fn relax_to_rest(
    cfg: &FallConfig,
    model: &crate::dynamics::Model,
    settings: StepSettings,
    forces: &Forces,
    state: &mut pipeline::State,
    ws: &mut pipeline::StepWorkspace,
) -> Result<(), SimError> {
    let mut monitor = pipeline::StepMonitor::new(model.nbodies(), forces.dofs.len());
    let relax = (-cfg.dt_s / SETTLE_TAU_S).exp();
    let mut quiet_since: Option<f64> = None;
    loop {
        if state.time_s >= cfg.settle_max_s {
            return Err(cfg_err(
                "settle_max_s",
                format!(
                    "the standing body did not come to rest within {} s (stance gains too weak \
                     or the stance pose out of balance)",
                    cfg.settle_max_s
                ),
            ));
        }
        pipeline::step(model, settings, forces, state, ws, &mut monitor)?;
        state.v.iter_mut().for_each(|x| *x *= relax);
        ws.eval.kinematics_at_step = None;
        let data = ws.kinematics_of(model, state);
        let ke: f64 = (0..model.nbodies())
            .map(|i| model.bodies()[i].inertia.kinetic_energy(data.v[i]))
            .sum();
        if ke < SETTLED_KE_J {
            let t0 = *quiet_since.get_or_insert(state.time_s);
            if state.time_s - t0 >= SETTLED_HOLD_S {
                return Ok(());
            }
        } else {
            quiet_since = None;
        }
    }
}

/// The stance PD with its holding feedforward within each DOF's strength at the settled pose.
fn check_holding_strength(
    body: &HumanBody,
    held: &PdTargets,
    state: &pipeline::State,
) -> Result<(), SimError> {
    let model = &body.model;
    let mut angles = vec![0.0; model.nv()];
    model.angles(&state.q, &mut angles);
    for (d, &k) in body.dof_v.iter().enumerate() {
        let (tau, _) = held.torque(d, angles[k], 0.0);
        if held.saturates(d, tau) {
            return Err(cfg_err(
                "torque_limits_nm",
                format!(
                    "holding the settled stance needs {tau:.1} N·m at {}, at or beyond its \
                     strength {:?} N·m",
                    body.figure.dofs[d].name, held.torque_limits[d]
                ),
            ));
        }
    }
    Ok(())
}

/// Simulates one pushed fall from `config` without a World (the same parts and steps as
/// [`ecs::run_fall_world`]) and returns its record.
pub fn simulate_fall(config: &FallConfig) -> Result<FallResult, SimError> {
    let mut ch = build_fall(config)?;
    let FallCharacter {
        physics,
        human,
        pd,
        limits,
        contact,
        external,
        controller,
        recorder,
    } = &mut ch;
    let body = &*human.0;
    let (model, dofs) = (&*physics.body.model, &*physics.body.dofs);
    let state = &mut physics.state.0;
    let ws = &mut physics.workspace.0;
    let monitor = &mut physics.monitor.0;
    let settings = StepSettings {
        integrator: physics.body.integrator,
        dt: config.dt_s,
    };
    let refinement = physics.body.refinement;
    recorder.record(body, state, ws.kinematics_of(model, state), monitor);
    while !recorder.finished(state) {
        controller.apply(state.time_s, &mut pd.0);
        let forces = Forces {
            dofs,
            pd: Some(&pd.0),
            limits: Some(&limits.0),
            contact: Some(&contact.0),
            external: external.all(),
        };
        let substeps = refinement.map_or(1, |r| r.substeps_at(state.time_s));
        pipeline::step_refined(model, settings, substeps, &forces, state, ws, monitor)?;
        recorder.record(body, state, ws.kinematics_of(model, state), monitor);
    }
    Ok(recorder.result(body, state, monitor))
}
