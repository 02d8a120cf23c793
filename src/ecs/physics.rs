//! Simulated bodies: every force a body feels comes from a component the step reads.
//!
//! A physical body carries a [`PhysicsBundle`] (the rigid-body kernel's [`Model`] and its
//! actuated DOFs, its state, workspace, monitor and status) and any of [`PdController`]
//! (targets θ_d, θ̇_d and gains per DOF), [`JointLimits`] (ranges and the joint model),
//! [`FloorContact`] (the link boxes' corners and gains) and [`ExternalForces`]. Removing one
//! removes that force; a controller of the user's (a primitive player, a GA genome, a game's
//! input) writes [`PdController`] in [`MotionSet::Control`]. [`step_bodies`] takes the clock's
//! substeps in [`MotionSet::Physics`] through [`pipeline::step`]. Nothing here knows what the
//! body is: a human's figure, DOF names and links are its `ecs::human::HumanFigure`, from
//! which `ecs::human::publish_body_pose` hands the pose to the same joint state, forward
//! kinematics and recorder as a kinematic character in [`MotionSet::Pose`].

use std::ops::{Deref, DerefMut};
use std::sync::Arc;

use bevy_ecs::prelude::*;

use super::clock::Clock;
use super::sets::{MotionSet, configure_motion_sets};
use crate::dynamics::Integrator;
use crate::dynamics::LaneData;
use crate::dynamics::Model;
use crate::dynamics::forces::contact::ContactModel;
use crate::dynamics::forces::external::ExternalForce;
use crate::dynamics::forces::limits::JointRanges;
use crate::dynamics::forces::pd::PdTargets;
use crate::dynamics::pipeline::{
    self, Forces, LaneBody, State, StepError, StepMonitor, StepRefinement, StepSettings,
    StepWorkspace,
};

macro_rules! wrapper {
    ($name:ident, $inner:ty) => {
        impl Deref for $name {
            type Target = $inner;
            fn deref(&self) -> &$inner {
                &self.0
            }
        }
        impl DerefMut for $name {
            fn deref_mut(&mut self) -> &mut $inner {
                &mut self.0
            }
        }
    };
}

/// The simulated body: the rigid-body model (immutable, shared), the DOFs its per-DOF forces
/// act on, and its integration scheme.
#[derive(Component, Clone, Debug)]
pub struct PhysicsBody {
    /// The articulated body (immutable); bodies sharing one model step together in vector
    /// lanes ([`step_bodies`]).
    pub model: Arc<Model>,
    /// Velocity index (in `v`) of each actuated DOF: the order of the per-DOF entries of
    /// [`PdController`], [`JointLimits`] and [`PhysicsMonitor`].
    pub dofs: Arc<[usize]>,
    /// Integration scheme.
    pub integrator: Integrator,
    /// Finer steps over a stretch of time (`None`: every step whole); a body with one steps
    /// alone ([`pipeline::step_refined`]), not in vector lanes.
    pub refinement: Option<StepRefinement>,
}

/// The body's state `(q, v)`, friction anchors, time (s) and steps.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct BodyState(pub State);
wrapper!(BodyState, State);

/// PD control toward θ_d, θ̇_d per DOF (body DOF order), read at every evaluation.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct PdController(pub PdTargets);
wrapper!(PdController, PdTargets);

/// Joint ranges and the joint model (friction inside, spring–damper past a limit).
#[derive(Component, Clone, Debug, PartialEq)]
pub struct JointLimits(pub JointRanges);
wrapper!(JointLimits, JointRanges);

/// Floor contact of the body's link boxes (their corners, bounds, masses and gains).
#[derive(Component, Clone, Debug)]
pub struct FloorContact(pub Arc<ContactModel>);

/// Forces applied to the body, in the order the step applies them: the pushes (each with its
/// time window) as they were added, then the root assistance's wrench for the tick when a
/// system has set one ([`ExternalForces::set_assist`]). Removing the component removes them all.
#[derive(Component, Clone, Debug, PartialEq, Default)]
pub struct ExternalForces {
    /// The pushes, then the assistance when `assisted`.
    forces: Vec<ExternalForce>,
    /// Whether the last entry of `forces` is the assistance.
    assisted: bool,
}

impl ExternalForces {
    /// The forces `pushes` (world frame, each with its time window), no assistance.
    pub fn new(pushes: Vec<ExternalForce>) -> Self {
        Self {
            forces: pushes,
            assisted: false,
        }
    }

    /// Adds `force` after the pushes already there (and before the assistance).
    pub fn push(&mut self, force: ExternalForce) {
        let at = self.pushes().len();
        self.forces.insert(at, force);
    }

    /// The pushes, in the order they were added.
    pub fn pushes(&self) -> &[ExternalForce] {
        &self.forces[..self.forces.len() - usize::from(self.assisted)]
    }

    /// The root assistance's wrench for this tick (world-frame force at the pelvis origin and
    /// torque), if one is set.
    pub fn assist(&self) -> Option<&ExternalForce> {
        self.forces.last().filter(|_| self.assisted)
    }

    /// Sets the root assistance's wrench the step applies after the pushes this tick, or with
    /// `None` removes it (a system in [`MotionSet::Control`] writes it every tick).
    pub fn set_assist(&mut self, force: Option<ExternalForce>) {
        if self.assisted {
            self.forces.pop();
        }
        self.assisted = force.is_some();
        self.forces.extend(force);
    }

    /// Every force the step applies: the pushes, then the assistance.
    pub fn all(&self) -> &[ExternalForce] {
        &self.forces
    }
}

/// The pipeline's buffers.
#[derive(Component, Clone, Debug)]
pub struct PhysicsWorkspace(pub StepWorkspace);
wrapper!(PhysicsWorkspace, StepWorkspace);

/// What the steps saw: contact forces and depths, their peaks and impulses, range excursions.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct PhysicsMonitor(pub StepMonitor);
wrapper!(PhysicsMonitor, StepMonitor);

/// Whether the body steps: `stopped` by its owner (e.g. a finished experiment) or by an error
/// (a runaway state, with time, body and value).
#[derive(Component, Clone, Debug, Default)]
pub struct PhysicsStatus {
    /// The body no longer steps.
    pub stopped: bool,
    /// The error that stopped it.
    pub error: Option<Arc<StepError>>,
}

impl PhysicsStatus {
    /// True while the body steps.
    pub fn running(&self) -> bool {
        !self.stopped && self.error.is_none()
    }
}

/// The components every simulated body needs.
#[derive(Bundle, Clone, Debug)]
pub struct PhysicsBundle {
    /// Model, actuated DOFs and scheme.
    pub body: PhysicsBody,
    /// State.
    pub state: BodyState,
    /// Buffers.
    pub workspace: PhysicsWorkspace,
    /// Monitor.
    pub monitor: PhysicsMonitor,
    /// Status.
    pub status: PhysicsStatus,
}

impl PhysicsBundle {
    /// A body of `model` actuated at the velocity indices `dofs`, at configuration `q`, at
    /// rest, integrated with `integrator`.
    pub fn new(model: Arc<Model>, dofs: Arc<[usize]>, integrator: Integrator, q: Vec<f64>) -> Self {
        let state = State::new(q, vec![0.0; model.nv()], model.nbodies());
        let workspace = StepWorkspace::new(&model);
        let monitor = StepMonitor::new(model.nbodies(), dofs.len());
        Self {
            body: PhysicsBody {
                model,
                dofs,
                integrator,
                refinement: None,
            },
            state: BodyState(state),
            workspace: PhysicsWorkspace(workspace),
            monitor: PhysicsMonitor(monitor),
            status: PhysicsStatus::default(),
        }
    }
}

/// The components of one body as the step reads them.
type StepQuery<'a> = (
    &'a PhysicsBody,
    &'a mut BodyState,
    Option<&'a PdController>,
    Option<&'a JointLimits>,
    Option<&'a FloorContact>,
    Option<&'a ExternalForces>,
    &'a mut PhysicsWorkspace,
    &'a mut PhysicsMonitor,
    &'a mut PhysicsStatus,
);

/// Steps every running body by the clock's substeps of `tick / substeps` seconds; an error
/// stops that body (recorded in its [`PhysicsStatus`]) and no other.
///
/// Bodies of one model integrated by semi-implicit Euler step together through
/// [`pipeline::step_lanes`] (their articulated-body algorithm
/// [`LANES`](crate::dynamics::LANES) at a time in vector lanes), each to the bits it has
/// stepped alone.
pub fn step_bodies(
    clock: Res<Clock>,
    mut lanes: Local<Vec<(Arc<Model>, LaneData)>>,
    mut q: Query<StepQuery>,
) {
    let dt = clock.physics_dt();
    let mut together = Vec::new();
    for one in &mut q {
        if !one.8.running() {
            continue;
        }
        if one.0.refinement.is_none()
            && matches!(one.0.integrator, Integrator::SemiImplicitEuler { .. })
        {
            together.push(one);
            continue;
        }
        step_alone(one, dt, clock.substeps);
    }
    // The bodies of one model and scheme, in query order.
    while let Some(first) = together.first() {
        let (model, integrator) = (first.0.model.clone(), first.0.integrator);
        let same = |b: &StepItem| Arc::ptr_eq(&b.0.model, &model) && b.0.integrator == integrator;
        let mut group = if together.iter().all(same) {
            std::mem::take(&mut together)
        } else {
            let (group, rest): (Vec<_>, Vec<_>) = together.into_iter().partition(same);
            together = rest;
            group
        };
        // Lane buffers per model, dropped with the last holder of that model.
        lanes.retain(|(m, _)| Arc::strong_count(m) > 1);
        let k = match lanes.iter().position(|(m, _)| Arc::ptr_eq(m, &model)) {
            Some(k) => k,
            None => {
                lanes.push((model.clone(), LaneData::new(&model)));
                lanes.len() - 1
            }
        };
        let settings = StepSettings { integrator, dt };
        step_together(
            &model,
            settings,
            clock.substeps,
            &mut group,
            &mut lanes[k].1,
        );
    }
}

/// One running body's components as the step takes them (its [`StepQuery`] item).
type StepItem<'w> = (
    &'w PhysicsBody,
    Mut<'w, BodyState>,
    Option<&'w PdController>,
    Option<&'w JointLimits>,
    Option<&'w FloorContact>,
    Option<&'w ExternalForces>,
    Mut<'w, PhysicsWorkspace>,
    Mut<'w, PhysicsMonitor>,
    Mut<'w, PhysicsStatus>,
);

/// Steps one body alone by `substeps` steps of `dt` (each refined where its
/// [`PhysicsBody::refinement`] says); an error stops it.
fn step_alone(item: StepItem, dt: f64, substeps: u32) {
    let (body, mut state, pd, limits, contact, external, mut ws, mut monitor, mut status) = item;
    let external = external.map_or(&[][..], |e| e.all());
    let forces = Forces {
        dofs: &body.dofs,
        pd: pd.map(|p| &p.0),
        limits: limits.map(|l| &l.0),
        contact: contact.map(|c| &*c.0),
        external,
    };
    let settings = StepSettings {
        integrator: body.integrator,
        dt,
    };
    for _ in 0..substeps {
        let refined = body.refinement.map_or(1, |r| r.substeps_at(state.0.time_s));
        if let Err(e) = pipeline::step_refined(
            &body.model,
            settings,
            refined,
            &forces,
            &mut state.0,
            &mut ws.0,
            &mut monitor.0,
        ) {
            status.error = Some(Arc::new(e));
            break;
        }
    }
}

/// Steps the bodies of `group` (one model, one scheme) together by `substeps` steps through
/// [`pipeline::step_lanes`]; an error stops its body and no other.
fn step_together(
    model: &Model,
    settings: StepSettings,
    substeps: u32,
    group: &mut [StepItem],
    lane_data: &mut LaneData,
) {
    for _ in 0..substeps {
        let mut bodies: Vec<LaneBody> = group
            .iter_mut()
            .filter(|b| b.8.running())
            .map(
                |(body, state, pd, limits, contact, external, ws, monitor, _)| LaneBody {
                    forces: Forces {
                        dofs: &body.dofs,
                        pd: pd.map(|p| &p.0),
                        limits: limits.map(|l| &l.0),
                        contact: contact.map(|c| &*c.0),
                        external: external.map_or(&[][..], |e| e.all()),
                    },
                    state: &mut state.0,
                    ws: &mut ws.0,
                    monitor: &mut monitor.0,
                    result: Ok(()),
                },
            )
            .collect();
        if bodies.is_empty() {
            break;
        }
        pipeline::step_lanes(model, settings, &mut bodies, lane_data);
        if bodies.iter().all(|b| b.result.is_ok()) {
            continue;
        }
        let errors: Vec<Option<StepError>> = bodies.into_iter().map(|b| b.result.err()).collect();
        let mut errors = errors.into_iter();
        for b in group.iter_mut().filter(|b| b.8.running()) {
            if let Some(Some(e)) = errors.next() {
                b.8.error = Some(Arc::new(e));
            }
        }
    }
}

/// Adds the physics systems to `schedule`: [`step_bodies`] in [`MotionSet::Physics`]. Human
/// bodies drawn as characters also need their pose published
/// (`ecs::human::add_human_physics_systems` adds both).
pub fn add_physics_systems(schedule: &mut Schedule) {
    configure_motion_sets(schedule);
    schedule.add_systems(step_bodies.in_set(MotionSet::Physics));
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn force(body: usize) -> ExternalForce {
        ExternalForce {
            body,
            point: DVec3::ZERO,
            force: DVec3::X,
            torque: DVec3::ZERO,
            start_s: 0.0,
            duration_s: 0.1,
        }
    }

    #[test]
    fn the_assistance_stays_after_the_pushes() {
        let mut f = ExternalForces::new(vec![force(1)]);
        f.set_assist(Some(force(0)));
        f.push(force(2));
        assert_eq!(f.pushes(), &[force(1), force(2)]);
        assert_eq!(f.assist(), Some(&force(0)));
        assert_eq!(f.all(), &[force(1), force(2), force(0)]);
        f.set_assist(Some(force(3)));
        assert_eq!(f.all(), &[force(1), force(2), force(3)]);
        f.set_assist(None);
        assert_eq!(f.all(), f.pushes());
        assert_eq!(f.assist(), None);
    }
}
