//! Physical characters (active ragdolls): one entity that both plays motor primitives and lives
//! under physics. Its primitive player writes the [`DofPose`] (θ, θ̇ per DOF and the root
//! channels) as for a kinematic character; in [`MotionSet::Control`] the pose becomes the PD
//! targets of the simulated joints ([`ControlSet::Targets`]), pushes release the assistance or
//! switch to a key pose ([`ControlSet::Reactions`]), and a root assistance ("hand of god") pulls
//! the pelvis toward the animated root ([`ControlSet::Assist`]: its wrench joins the
//! character's [`ExternalForces`], which the step reads); the body steps in
//! [`MotionSet::Physics`] through the one pipeline (limits, contact and dynamics are its stages,
//! evaluated at every integrator stage, so they are not separate systems); its pose reaches the
//! joint state in [`MotionSet::Pose`] and the [`CharacterLog`] in [`MotionSet::Record`].
//!
//! The control laws are kernel functions ([`crate::dynamics::control`]); the systems here only
//! feed them the components. Root assistance ([`root_assist_wrench`]): a PD on the pelvis's pose
//! toward the animated root, with `M` the body's mass and `I` the mean of its composite
//! rotational inertia about the pelvis (CRBA's root block at the start pose); `ω_d` is taken
//! as the rate of the animated rotation vector (exact about a fixed axis, a first-order
//! approximation otherwise).
//!
//! Joint torques are PD plus the computed-torque feedforward of the animated motion
//! ([`Feedforward`], [`ComputedTorque`]). Joint PD gains come from the body itself
//! ([`inertia_scaled_gains`]: `k_p = ω_j² H_kk`, `k_v = 2ζ_j ω_j H_kk` with `H_kk` the
//! joint-space inertia of DOF `k` at the start pose), so every DOF tracks with the same
//! bandwidth `ω_j`; the torques are clamped to the DOF's strength
//! ([`crate::humanoid::strength`]).

use std::sync::Arc;

use bevy_ecs::prelude::*;
use glam::{DMat3, DQuat, DVec3};

use super::clock::Clock;
use super::dof_pose::{DofPose, FigureBinding};
use super::human::{HumanFigure, drawn_body, human_physics};
use super::physics::{
    BodyState, ExternalForces, FloorContact, JointLimits, PdController, PhysicsMonitor,
    PhysicsStatus,
};
use super::primitive::PrimitivePlayer;
use super::sets::{MotionSet, configure_motion_sets};
use crate::dynamics::Data;
use crate::dynamics::Integrator;
use crate::dynamics::Model;
use crate::dynamics::control::{
    ComputedTorque, RootAssistGains, RootTarget, Wrench, inertia_scaled_gains, root_assist_wrench,
    root_rotational_inertia, root_share,
};
use crate::dynamics::forces::contact::{ContactModel, ContactParams};
use crate::dynamics::forces::external::{ExternalForce, Push};
use crate::dynamics::forces::limits::{JointLimitParams, JointRanges};
use crate::dynamics::forces::pd::PdTargets;
use crate::dynamics::kinematics;
use crate::humanoid::HumanBody;
use crate::humanoid::strength::{NoStrength, torque_limits_for};
use crate::humanoid::tissue;
use crate::humanoid::{AgeGroup, RangeTable};
use crate::primitive::{Primitive, PrimitiveError};

/// The order of the control systems inside [`MotionSet::Control`].
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ControlSet {
    /// DOF poses become PD targets ([`pd_targets_from_pose`]).
    Targets,
    /// Pushes release the assistance or switch the controller ([`react_to_pushes`]).
    Reactions,
    /// The root assistance's force and torque for this tick, written into the character's
    /// [`ExternalForces`] ([`root_assist`]).
    Assist,
}

/// Marks a character whose PD targets follow its [`DofPose`] (θ_d, θ̇_d per DOF).
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct TrackPose;

/// The root assistance ("hand of god"): a PD pulling the pelvis toward the animated root pose
/// ([`root_assist_wrench`]).
#[derive(Component, Clone, Debug, PartialEq)]
pub struct RootAssist {
    /// Strength, bandwidth, damping, mass and inertia scale.
    pub gains: RootAssistGains,
    /// True once released: the wrench is zero from then on.
    pub released: bool,
    /// The root's share of the animated motion's inverse dynamics (world, N and N·m, about the
    /// pelvis origin): the wrench the pelvis needs for the whole body to move as animated with
    /// no other support; set by [`pd_targets_from_pose`] with a [`Feedforward`], else zero.
    pub feedforward: Wrench,
    /// The wrench (world, N and N·m, about the pelvis origin) for this tick.
    pub wrench: Wrench,
}

impl RootAssist {
    /// The assistance as the external force the step applies (none when zero).
    pub fn external(&self) -> Option<ExternalForce> {
        let Wrench { force, torque } = self.wrench;
        (force != DVec3::ZERO || torque != DVec3::ZERO).then_some(ExternalForce {
            body: 0,
            point: DVec3::ZERO,
            force,
            torque,
            start_s: 0.0,
            duration_s: f64::INFINITY,
        })
    }
}

/// What a push does to the character.
#[derive(Component, Clone, Debug, PartialEq, Default)]
pub struct Reaction {
    /// Seconds after the first push starts at which the assistance is released; `None` keeps
    /// it on.
    pub release_delay_s: Option<f64>,
    /// A key pose (the falling paper's controller) the PD switches to at the release; `None`
    /// keeps following the primitives.
    pub key_pose: Option<PdTargets>,
    /// Start of the first push (s), once one has started.
    pub pushed_at_s: Option<f64>,
    /// Time the assistance was released (s).
    pub released_at_s: Option<f64>,
}

/// One tick of a character's log.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LogSample {
    /// Time at the end of the tick (s).
    pub time_s: f64,
    /// Height of the pelvis origin (m).
    pub pelvis_height_m: f64,
    /// Animated (target) pelvis height (m).
    pub target_pelvis_height_m: f64,
    /// Mean over DOFs of `(θ − θ_d)²` (rad²).
    pub mean_sq_error: f64,
}

/// Records a physical character: per tick the tracking error and pelvis heights, per DOF the
/// peak PD torque (sampled at the end of each tick), per link the peak floor force after the
/// first push.
#[derive(Component, Clone, Debug, Default, PartialEq)]
pub struct CharacterLog {
    /// One sample per tick.
    pub samples: Vec<LogSample>,
    /// Per DOF the sum of `(θ − θ_d)²` over the ticks before the first push (rad²).
    pub dof_sq_error: Vec<f64>,
    /// Ticks summed in `dof_sq_error`.
    pub tracked_ticks: usize,
    /// Per DOF the largest |PD torque| (N·m).
    pub peak_torque_nm: Vec<f64>,
    /// Per link the largest normal floor force after the first push (N).
    pub peak_force_after_push_n: Vec<f64>,
    /// Per DOF the ticks before the first push whose PD torque was clamped to the strength.
    pub saturated_ticks: Vec<usize>,
    /// Per DOF the smallest and largest feedforward torque before the first push (N·m): what
    /// the animated motion asks of the joint (its inverse dynamics with the root carried).
    pub demand_nm: Vec<(f64, f64)>,
    /// The largest downward whole-body external force the animated motion needs before the
    /// first push (N, ≥ 0): of its root feedforward ([`RootAssist::feedforward`]) the
    /// component against gravity, where negative. A floor can only push up, so a motion that
    /// needs to be pulled down (e.g. a flight whose centre of mass falls faster than gravity)
    /// is not one a body can make; the assistance supplies it and the joints feel it.
    pub max_pull_n: f64,
    /// When that was (s).
    pub max_pull_time_s: f64,
    angles: Vec<f64>,
    reference: Vec<f64>,
}

/// An animated foot counts as down while its lowest contact corner is within this height of
/// the animated floor (m): the tolerance the jumps use for a planted foot
/// ([`crate::humanoid::FOOT_DOWN_M`]).
pub const ANIMATED_FOOT_DOWN_M: f64 = crate::humanoid::FOOT_DOWN_M;

/// Whether the physical feet are on the floor when the animated ones are: for every foot link,
/// over the ticks before the first push at which the animated foot is down (its lowest corner
/// within [`ANIMATED_FOOT_DOWN_M`] of the animated floor, the start pose's lowest corner), the
/// largest height of the physical foot's lowest corner above the physical floor (m; ≤ 0 means
/// it touched the floor at every such tick).
#[derive(Component, Clone, Debug)]
pub struct FeetOnFloor {
    /// Foot links (body indices).
    pub links: Vec<usize>,
    /// Height of the animated floor (m): the lowest corner of the start pose.
    pub animated_floor_m: f64,
    /// Ticks at which each animated foot was down.
    pub down_ticks: Vec<usize>,
    /// Per foot the largest physical gap above the floor at those ticks (m).
    pub max_gap_m: Vec<f64>,
    /// Per foot the time of that largest gap (s).
    pub max_gap_time_s: Vec<f64>,
    animated: Option<Data>,
    physical: Option<Data>,
}

impl FeetOnFloor {
    /// Feet check of the foot `links` over a floor whose animated height is `animated_floor_m`.
    pub fn new(links: Vec<usize>, animated_floor_m: f64) -> Self {
        let n = links.len();
        Self {
            links,
            animated_floor_m,
            down_ticks: vec![0; n],
            max_gap_m: vec![f64::NEG_INFINITY; n],
            max_gap_time_s: vec![0.0; n],
            animated: None,
            physical: None,
        }
    }
}

/// Lowest height along the floor normal of the contact corners of `link` posed by `data`.
fn lowest_corner(contact: &ContactModel, data: &Data, link: usize) -> f64 {
    let n = contact.params.floor_normal;
    contact.corners()[link]
        .iter()
        .map(|&c| n.dot(data.pos[link] + data.rot[link] * c))
        .fold(f64::INFINITY, f64::min)
}

/// What [`check_feet`] reads and writes.
type FeetQuery<'a> = (
    &'a HumanFigure,
    &'a BodyState,
    &'a FloorContact,
    &'a FigureBinding,
    &'a DofPose,
    &'a Reaction,
    &'a mut FeetOnFloor,
);

/// Updates every character's [`FeetOnFloor`] after its step, before its first push.
pub fn check_feet(mut q: Query<FeetQuery>) {
    for (human, state, contact, binding, pose, reaction, mut feet) in &mut q {
        if reaction.pushed_at_s.is_some_and(|p| state.time_s > p) {
            continue;
        }
        let b = &**human;
        let feet = &mut *feet;
        let (q_d, v_d) = pose_configuration(b, binding, pose);
        let anim = feet.animated.get_or_insert_with(|| Data::new(&b.model));
        kinematics(&b.model, anim, &q_d, &v_d);
        let phys = feet.physical.get_or_insert_with(|| Data::new(&b.model));
        kinematics(&b.model, phys, &state.q, &state.v);
        let floor = contact.0.params.floor_height;
        for (k, &link) in feet.links.iter().enumerate() {
            let (anim, phys) = (feet.animated.as_ref(), feet.physical.as_ref());
            let (Some(anim), Some(phys)) = (anim, phys) else {
                continue;
            };
            let a = lowest_corner(&contact.0, anim, link) - feet.animated_floor_m;
            if a > ANIMATED_FOOT_DOWN_M {
                continue;
            }
            let gap = lowest_corner(&contact.0, phys, link) - floor;
            feet.down_ticks[k] += 1;
            if gap > feet.max_gap_m[k] {
                feet.max_gap_m[k] = gap;
                feet.max_gap_time_s[k] = state.time_s;
            }
        }
    }
}

/// Settings of a physical character.
#[derive(Clone, Debug, PartialEq)]
pub struct PhysicalSettings {
    /// Joint PD bandwidth `ω_j` (rad/s).
    pub joint_omega: f64,
    /// Joint PD damping ratio `ζ_j`.
    pub joint_zeta: f64,
    /// Root assistance strength (1 full, 0 none).
    pub assist: f64,
    /// Root assistance bandwidth `ω_a` (rad/s).
    pub assist_omega: f64,
    /// Root assistance damping ratio.
    pub assist_zeta: f64,
    /// Whose strength bounds the joint torques; `None` leaves them unbounded.
    pub strength: Option<AgeGroup>,
    /// Integration scheme.
    pub integrator: Integrator,
    /// Floor contact parameters (the floor height is set from the start pose).
    pub contact: ContactParams,
    /// Add the computed-torque feedforward ([`Feedforward`]) to the PD.
    pub feedforward: bool,
    /// With `feedforward`, the root assistance also carries the root's share of the animated
    /// motion's inverse dynamics ([`RootAssist::feedforward`]): the whole-body weight and
    /// root wrench, so the joints only move the limbs, and the floor is placed for the weight
    /// the assistance does not carry.
    pub assist_feedforward: bool,
    /// How far the floor lies below the start pose's lowest contact corner (m, ≥ 0; 0 = the
    /// feet start on it).
    pub floor_clearance_m: f64,
    /// Whose joint ranges bound the joints (the joint model of
    /// [`crate::dynamics::forces::limits`] with its default gains: a spring and damper past
    /// each range, joint friction inside it), from the model's built-in table
    /// ([`RangeTable::builtin_for`]); `None` leaves the joints free.
    pub joint_ranges: Option<AgeGroup>,
}

impl Default for PhysicalSettings {
    fn default() -> Self {
        Self {
            joint_omega: 40.0,
            joint_zeta: 1.0,
            assist: 1.0,
            assist_omega: 20.0,
            assist_zeta: 1.0,
            strength: Some(AgeGroup::Adult),
            integrator: Integrator::SemiImplicitEuler {
                implicit_damping: true,
            },
            contact: ContactParams::default(),
            feedforward: true,
            assist_feedforward: true,
            floor_clearance_m: 0.0,
            joint_ranges: None,
        }
    }
}

/// Why a physical character could not be made.
#[derive(Debug, thiserror::Error)]
pub enum CharacterError {
    /// The primitives do not fit the body's model.
    #[error(transparent)]
    Primitive(#[from] PrimitiveError),
    /// A DOF has no strength row.
    #[error(transparent)]
    Strength(#[from] NoStrength),
    /// A link has no tissue region for its contact gains.
    #[error("link '{0}' has no tissue region (contact gains)")]
    Tissue(String),
    /// A configuration that does not fit the body's model.
    #[error(transparent)]
    Model(#[from] crate::dynamics::ModelError),
    /// A setting out of range.
    #[error("{field}: {message}")]
    Setting {
        /// The field.
        field: &'static str,
        /// What is wrong.
        message: String,
    },
}

/// The body configuration and velocity of a DOF pose: the pelvis at the root channels, every
/// joint at its DOF angles, every joint velocity from its DOF rates (a ball joint's DOFs are
/// the components of its rotation vector, whose rates become its angular velocity through
/// `dexp`: [`crate::dynamics::Model::velocity_from_rates`]).
pub fn pose_configuration(
    body: &HumanBody,
    binding: &FigureBinding,
    pose: &DofPose,
) -> (Vec<f64>, Vec<f64>) {
    let angles: Vec<f64> = binding
        .dof_columns()
        .iter()
        .map(|&c| pose.theta[c])
        .collect();
    let r = binding.root_columns();
    let at = |k: usize| pose.theta[r[k]];
    let rot = DQuat::from_scaled_axis(DVec3::new(at(3), at(4), at(5)));
    let q = body.configuration(&angles, DVec3::new(at(0), at(1), at(2)), rot);
    let nv = body.model.nv();
    let (mut at_v, mut rates) = (vec![0.0; nv], vec![0.0; nv]);
    for (d, &c) in binding.dof_columns().iter().enumerate() {
        at_v[body.dof_v[d]] = pose.theta[c];
        rates[body.dof_v[d]] = pose.theta_dot[c];
    }
    let mut v = vec![0.0; nv];
    body.model.velocity_from_rates(&at_v, &rates, &mut v);
    let rate = |k: usize| pose.theta_dot[r[k]];
    let rt = DMat3::from_quat(rot).transpose();
    let w = rt * DVec3::new(rate(3), rate(4), rate(5));
    let lin = rt * DVec3::new(rate(0), rate(1), rate(2));
    v[0..3].copy_from_slice(&w.to_array());
    v[3..6].copy_from_slice(&lin.to_array());
    (q, v)
}

/// Spawns a physical character named `name`: `body` playing `sequence` (connected) under PD
/// control with root assistance, standing on a floor at the height of its lowest contact corner
/// in the first pose (less the feet's static sink under half the weight each).
pub fn spawn_physical_character(
    world: &mut World,
    name: &str,
    body: Arc<HumanBody>,
    sequence: Vec<Arc<Primitive>>,
    settings: &PhysicalSettings,
    reaction: Reaction,
) -> Result<Entity, CharacterError> {
    check_physical_settings(settings)?;
    let player = PrimitivePlayer::new(sequence)?;
    let pose = player.pose();
    let binding = FigureBinding::new(Arc::new(body.figure.clone()), &pose.names)?;
    let model = &body.model;
    let (q, v) = pose_configuration(&body, &binding, &pose);
    let mut data = Data::new(model);
    kinematics(model, &mut data, &q, &v);
    let floor = floor_contact(&body, settings, &data)?;
    // Gains from the joint-space inertia at the start pose.
    let h = crate::dynamics::crba(model, &mut data, &q)?.to_vec();
    let targets: Vec<f64> = binding
        .dof_columns()
        .iter()
        .map(|&c| pose.theta[c])
        .collect();
    let pd = pd_targets(&body, settings, &h, targets)?;
    let joint_limits = joint_limits(&body, settings)?;
    let assist = new_root_assist(settings, model, &h);
    let ndofs = body.dof_v.len();
    let nlinks = model.nbodies();
    let (mut physics, human) = human_physics(body.clone(), settings.integrator, q);
    physics.state.v = v;
    let log = CharacterLog {
        dof_sq_error: vec![0.0; ndofs],
        peak_torque_nm: vec![0.0; ndofs],
        peak_force_after_push_n: vec![0.0; nlinks],
        saturated_ticks: vec![0; ndofs],
        demand_nm: vec![(0.0, 0.0); ndofs],
        ..CharacterLog::default()
    };
    let mut entity = world.spawn((
        drawn_body(name, &body),
        (physics, human),
        (pose, player, binding, TrackPose),
        (
            PdController(pd),
            FloorContact(Arc::new(floor.contact)),
            ExternalForces::default(),
            assist,
            reaction,
            log,
            FeetOnFloor::new(floor.feet, floor.lowest),
        ),
    ));
    if let Some(l) = joint_limits {
        entity.insert(l);
    }
    if settings.feedforward {
        entity.insert(Feedforward {
            root: settings.assist_feedforward,
            ..Feedforward::default()
        });
    }
    Ok(entity.id())
}

/// The settings of [`spawn_physical_character`] in range: positive frequencies, a clearance
/// ≥ 0 and an assistance in [0, 1].
fn check_physical_settings(settings: &PhysicalSettings) -> Result<(), CharacterError> {
    for (field, x) in [
        ("joint_omega", settings.joint_omega),
        ("assist_omega", settings.assist_omega),
    ] {
        if !(x.is_finite() && x > 0.0) {
            return Err(CharacterError::Setting {
                field,
                message: format!("must be a positive number, found {x}"),
            });
        }
    }
    if !(settings.floor_clearance_m.is_finite() && settings.floor_clearance_m >= 0.0) {
        return Err(CharacterError::Setting {
            field: "floor_clearance_m",
            message: format!("must be ≥ 0, found {}", settings.floor_clearance_m),
        });
    }
    if !(0.0..=1.0).contains(&settings.assist) {
        return Err(CharacterError::Setting {
            field: "assist",
            message: format!("must lie in [0, 1], found {}", settings.assist),
        });
    }
    Ok(())
}

/// The floor a character stands on, and what it is measured from.
struct StartFloor {
    contact: ContactModel,
    /// The feet's link indices.
    feet: Vec<usize>,
    /// The height of the start pose's lowest contact corner along the floor normal, metres.
    lowest: f64,
}

/// The floor under the lowest corner of the start pose (kinematics in `data`), lowered by the
/// feet's static sink under half the weight the floor carries each, and raised by the
/// clearance; the links' tissue gains from their regions.
fn floor_contact(
    body: &HumanBody,
    settings: &PhysicalSettings,
    data: &Data,
) -> Result<StartFloor, CharacterError> {
    let model = &body.model;
    let masses: Vec<f64> = model.bodies().iter().map(|b| b.inertia.mass).collect();
    let gains = body
        .link_names
        .iter()
        .map(|n| {
            tissue::region(n)
                .map(|r| r.gains())
                .ok_or_else(|| CharacterError::Tissue(n.clone()))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut params = settings.contact;
    let probe = ContactModel::new(&body.boxes, &masses, &gains, params);
    let lowest = probe
        .corners()
        .iter()
        .enumerate()
        .flat_map(|(i, cs)| cs.iter().map(move |&c| (i, c)))
        .map(|(i, c)| params.floor_normal.dot(data.pos[i] + data.rot[i] * c))
        .fold(f64::INFINITY, f64::min);
    // The floor carries the share of the weight the assistance does not (with the root
    // feedforward a fully assisted body is carried by the assistance alone).
    let carried = if settings.feedforward && settings.assist_feedforward {
        1.0 - settings.assist
    } else {
        1.0
    };
    let weight = carried * model.total_mass() * model.gravity().length();
    let feet: Vec<usize> = (0..body.link_names.len())
        .filter(|&i| body.link_names[i].ends_with("foot"))
        .collect();
    let foot = feet.first().copied().unwrap_or(0);
    params.floor_height =
        lowest + probe.static_sink(foot, 0.5 * weight) - settings.floor_clearance_m;
    Ok(StartFloor {
        contact: ContactModel::new(&body.boxes, &masses, &gains, params),
        feet,
        lowest,
    })
}

/// PD gains holding `targets` from the joint-space inertia `h` (nv×nv) at the start pose
/// ([`inertia_scaled_gains`]), with the strength's torque limits.
fn pd_targets(
    body: &HumanBody,
    settings: &PhysicalSettings,
    h: &[f64],
    targets: Vec<f64>,
) -> Result<PdTargets, CharacterError> {
    let (w, z) = (settings.joint_omega, settings.joint_zeta);
    let (kp, kv) = inertia_scaled_gains(h, body.model.nv(), &body.dof_v, w, z);
    let limits = match settings.strength {
        Some(g) => torque_limits_for(&body.figure, g)?,
        None => Vec::new(),
    };
    Ok(PdTargets::hold(targets, kp, kv).with_torque_limits(limits))
}

/// The built-in joint ranges of the settings' group for the body's model, if asked for.
fn joint_limits(
    body: &HumanBody,
    settings: &PhysicalSettings,
) -> Result<Option<JointLimits>, CharacterError> {
    let Some(g) = settings.joint_ranges else {
        return Ok(None);
    };
    let name = &body.figure.name;
    let table = RangeTable::builtin_for(name, g).ok_or_else(|| CharacterError::Setting {
        field: "joint_ranges",
        message: format!("no built-in {g:?} joint ranges for model {name}"),
    })?;
    let ranges = table
        .for_figure(&body.figure)
        .map_err(|e| CharacterError::Setting {
            field: "joint_ranges",
            message: e.to_string(),
        })?;
    Ok(Some(JointLimits(JointRanges {
        ranges,
        params: JointLimitParams::default(),
        limit_gains: Vec::new(),
    })))
}

/// The root assistance of the settings, its rotational inertia the mean of the free root's
/// diagonal of `h` (nv×nv).
fn new_root_assist(settings: &PhysicalSettings, model: &Model, h: &[f64]) -> RootAssist {
    RootAssist {
        gains: RootAssistGains {
            strength: settings.assist,
            omega: settings.assist_omega,
            zeta: settings.assist_zeta,
            mass_kg: model.total_mass(),
            inertia_kg_m2: root_rotational_inertia(h, model.nv()),
        },
        released: false,
        feedforward: Wrench::ZERO,
        wrench: Wrench::ZERO,
    }
}

/// Pushes `entity` with `push` starting now (the body's time), e.g. from a game's input; the
/// push's own `start_s` is replaced. Returns false when the entity is not a simulated human
/// body.
pub fn push_now(world: &mut World, entity: Entity, push: &Push) -> bool {
    let Some(body) = world.get::<HumanFigure>(entity).map(|h| h.0.clone()) else {
        return false;
    };
    let Some(link) = body.link_index(&push.link) else {
        return false;
    };
    let Some(t) = world.get::<BodyState>(entity).map(|s| s.time_s) else {
        return false;
    };
    let Some(mut forces) = world.get_mut::<ExternalForces>(entity) else {
        return false;
    };
    let mut f = push.to_force(link);
    f.start_s = t;
    forces.push(f);
    true
}

/// Computed-torque feedforward of a tracking character ([`ComputedTorque`] on the animated
/// motion, one sample a tick: no contact; the root's share is left to the assistance).
#[derive(Component, Clone, Debug, Default)]
pub struct Feedforward {
    /// Also hand the root's share to the [`RootAssist`].
    pub root: bool,
    law: ComputedTorque,
}

/// What [`pd_targets_from_pose`] reads and writes.
type TargetQuery<'a> = (
    &'a HumanFigure,
    &'a FigureBinding,
    &'a DofPose,
    &'a mut PdController,
    Option<&'a mut Feedforward>,
    Option<&'a mut RootAssist>,
);

/// What [`react_to_pushes`] reads and writes.
type ReactionQuery<'a> = (
    &'a BodyState,
    &'a ExternalForces,
    &'a mut Reaction,
    Option<&'a mut RootAssist>,
    Option<&'a mut PdController>,
);

/// Copies every tracking character's DOF pose into its PD targets (θ_d per DOF, θ̇_d the joint
/// velocity of the pose: [`pose_configuration`]) and,
/// with a [`Feedforward`], the inverse dynamics of the animated motion into its feedforward.
pub fn pd_targets_from_pose(clock: Res<Clock>, mut q: Query<TargetQuery, With<TrackPose>>) {
    for (human, binding, pose, mut pd, ff, assist) in &mut q {
        let pd = &mut pd.0;
        let b = &**human;
        let (q_d, v_d) = pose_configuration(b, binding, pose);
        for (d, &c) in binding.dof_columns().iter().enumerate() {
            pd.target[d] = pose.theta[c];
            pd.target_velocity[d] = v_d[b.dof_v[d]];
        }
        let Some(mut ff) = ff else { continue };
        let ff = &mut *ff;
        // `pose_configuration` sizes `q_d` and `v_d` by the model.
        let tau = ff
            .law
            .torques(&b.model, &q_d, v_d, clock.tick_s)
            .expect("a pose configuration has the model's sizes");
        pd.feedforward.clear();
        pd.feedforward.extend(b.dof_v.iter().map(|&k| tau[k]));
        if let Some(mut a) = assist.filter(|_| ff.root) {
            a.feedforward = root_share(&q_d, tau);
        }
    }
}

/// Notes the first push of every reacting character and, `release_delay_s` after it, releases
/// its assistance and (if given) switches its PD to the key pose.
pub fn react_to_pushes(mut q: Query<ReactionQuery>) {
    for (state, forces, mut reaction, assist, pd) in &mut q {
        let t = state.time_s;
        if reaction.pushed_at_s.is_none() {
            reaction.pushed_at_s = forces
                .pushes()
                .iter()
                .filter(|f| f.start_s <= t)
                .map(|f| f.start_s)
                .reduce(f64::min);
        }
        let (Some(p), Some(delay)) = (reaction.pushed_at_s, reaction.release_delay_s) else {
            continue;
        };
        if t + 1e-12 >= p + delay {
            if reaction.released_at_s.is_none() {
                reaction.released_at_s = Some(t);
            }
            if let Some(mut a) = assist {
                a.released = true;
            }
            if let (Some(key), Some(mut pd)) = (&reaction.key_pose, pd) {
                pd.0.clone_from(key);
            }
        }
    }
}

/// What [`root_assist`] reads and writes.
type AssistQuery<'a> = (
    &'a BodyState,
    &'a FigureBinding,
    &'a DofPose,
    &'a mut RootAssist,
    Option<&'a mut ExternalForces>,
);

/// The root assistance's force and torque for this tick from the body's pelvis at the tick
/// start and the animated root (see the module doc), written into the character's
/// [`ExternalForces`] ([`ExternalForces::set_assist`]; none when zero) for the step to apply.
pub fn root_assist(mut q: Query<AssistQuery>) {
    for (state, binding, pose, mut a, external) in &mut q {
        assist_wrench(state, binding, pose, &mut a);
        if let Some(mut external) = external {
            external.set_assist(a.external());
        }
    }
}

/// Sets `a.wrench` for this tick ([`root_assist_wrench`]; zero once released) toward the
/// animated root of `pose`, its angular velocity the rate of the animated rotation vector.
fn assist_wrench(state: &BodyState, binding: &FigureBinding, pose: &DofPose, a: &mut RootAssist) {
    if a.released {
        a.wrench = Wrench::ZERO;
        return;
    }
    let r = binding.root_columns();
    let th = |k: usize| pose.theta[r[k]];
    let rate = |k: usize| pose.theta_dot[r[k]];
    let target = RootTarget {
        position: DVec3::new(th(0), th(1), th(2)),
        velocity: DVec3::new(rate(0), rate(1), rate(2)),
        rotation: DQuat::from_scaled_axis(DVec3::new(th(3), th(4), th(5))),
        angular_velocity: DVec3::new(rate(3), rate(4), rate(5)),
    };
    a.wrench = root_assist_wrench(&a.gains, a.feedforward, &state.q, &state.v, &target);
}

/// Logs every physical character after its step (see [`CharacterLog`]).
#[allow(clippy::type_complexity)]
pub fn log_characters(
    mut q: Query<(
        &HumanFigure,
        &BodyState,
        &PhysicsMonitor,
        &PdController,
        &FigureBinding,
        &DofPose,
        &Reaction,
        Option<&RootAssist>,
        &mut CharacterLog,
    )>,
) {
    for (human, state, monitor, pd, binding, pose, reaction, assist, mut log) in &mut q {
        let b = &**human;
        let log = &mut *log;
        log.angles.resize(b.model.nv(), 0.0);
        log.reference.resize(b.model.nv(), 0.0);
        for (d, &c) in binding.dof_columns().iter().enumerate() {
            log.reference[b.dof_v[d]] = pose.theta[c];
        }
        // Read as the PD reads them (ball joints nearest the targets).
        b.model
            .angles_near(&state.q, &log.reference, &mut log.angles);
        let before_push = reaction.pushed_at_s.is_none_or(|p| state.time_s <= p);
        let mut sum = 0.0;
        for (d, &c) in binding.dof_columns().iter().enumerate() {
            let k = b.dof_v[d];
            let e = log.angles[k] - pose.theta[c];
            sum += e * e;
            if before_push {
                log.dof_sq_error[d] += e * e;
            }
            let (tau, _) = pd.torque(d, log.angles[k], state.v[k]);
            log.peak_torque_nm[d] = log.peak_torque_nm[d].max(tau.abs());
            if before_push {
                log.saturated_ticks[d] += usize::from(pd.saturates(d, tau));
                if let Some(&ff) = pd.feedforward.get(d) {
                    let m = &mut log.demand_nm[d];
                    *m = (m.0.min(ff), m.1.max(ff));
                }
            }
        }
        if before_push {
            log.tracked_ticks += 1;
            let up = -b.model.gravity().normalize_or_zero();
            let pull = assist.map_or(0.0, |a| -a.feedforward.force.dot(up));
            if pull > log.max_pull_n {
                log.max_pull_n = pull;
                log.max_pull_time_s = state.time_s;
            }
        }
        if reaction.pushed_at_s.is_some() && !before_push {
            for (peak, f) in log
                .peak_force_after_push_n
                .iter_mut()
                .zip(&monitor.sample.normal)
            {
                *peak = peak.max(*f);
            }
        }
        let n = binding.dof_columns().len().max(1) as f64;
        log.samples.push(LogSample {
            time_s: state.time_s,
            pelvis_height_m: state.q[1],
            target_pelvis_height_m: pose.theta[binding.root_columns()[1]],
            mean_sq_error: sum / n,
        });
    }
}

/// Adds the physical-character systems to `schedule`: [`ControlSet::Targets`] →
/// [`ControlSet::Reactions`] → [`ControlSet::Assist`] inside [`MotionSet::Control`], and
/// [`log_characters`] in [`MotionSet::Record`]. The primitive and physics systems come from
/// their own helpers.
pub fn add_character_systems(schedule: &mut Schedule) {
    configure_motion_sets(schedule);
    schedule.configure_sets(
        (
            ControlSet::Targets,
            ControlSet::Reactions,
            ControlSet::Assist,
        )
            .chain()
            .in_set(MotionSet::Control),
    );
    schedule.add_systems((
        pd_targets_from_pose.in_set(ControlSet::Targets),
        react_to_pushes.in_set(ControlSet::Reactions),
        root_assist.in_set(ControlSet::Assist),
        (log_characters, check_feet).in_set(MotionSet::Record),
    ));
}

/// The schedule of physical characters: core sets and clock, motion (forward kinematics,
/// recording), primitive players, the character systems and physics.
pub fn character_schedule() -> Schedule {
    let mut s = Schedule::default();
    add_all_character_systems(&mut s);
    s
}

/// Adds everything [`character_schedule`] holds to `schedule` (e.g. a game's fixed-timestep
/// schedule): core sets and clock, motion, primitive, character and physics systems.
pub fn add_all_character_systems(schedule: &mut Schedule) {
    super::add_core_systems(schedule);
    super::add_motion_systems(schedule);
    super::primitive::add_primitive_systems(schedule);
    add_character_systems(schedule);
    super::human::add_human_physics_systems(schedule);
}

/// True while the character's body steps.
pub fn running(world: &World, e: Entity) -> bool {
    world.get::<PhysicsStatus>(e).is_some_and(|s| s.running())
}
