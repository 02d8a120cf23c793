//! Simulated humans: what a body needs beyond the rigid-body kernel's components when it is a
//! human. A human character carries its [`PhysicsBundle`] (the kernel's model and actuated
//! DOFs) and a [`HumanFigure`] (the figure model, DOF map, link names and contact boxes it was
//! built from, shared by every character of that body); [`human_physics`] makes both from one
//! [`HumanBody`]. Systems that need the human (its DOF names, its links, its figure's joints)
//! query the [`HumanFigure`]; [`publish_body_pose`] hands a drawn body's pose to the joint
//! state, forward kinematics and recorder of a kinematic character in [`MotionSet::Pose`].

use std::ops::Deref;
use std::sync::Arc;

use bevy_ecs::prelude::*;
use glam::{DQuat, DVec3};

use super::motion::{Character, JointState, Recorder, SkeletonRef};
use super::physics::{BodyState, PhysicsBody, PhysicsBundle};
use super::sets::MotionSet;
use crate::dynamics::Integrator;
use crate::humanoid::HumanBody;

/// The human a simulated body is (immutable, shared): its figure model, DOF map (`dof_v`),
/// link names and contact boxes, and the rigid-body model its [`PhysicsBody`] steps.
#[derive(Component, Clone, Debug)]
pub struct HumanFigure(pub Arc<HumanBody>);

impl Deref for HumanFigure {
    type Target = HumanBody;
    fn deref(&self) -> &HumanBody {
        &self.0
    }
}

/// The physics components of `body` at configuration `q` (m and unit quaternion for the
/// pelvis, rad for the joints), at rest, integrated with `integrator`, and its
/// [`HumanFigure`]: both share the body's model and DOF map, nothing is copied.
pub fn human_physics(
    body: Arc<HumanBody>,
    integrator: Integrator,
    q: Vec<f64>,
) -> (PhysicsBundle, HumanFigure) {
    let physics = PhysicsBundle::new(body.model.clone(), body.dof_v.clone(), integrator, q);
    (physics, HumanFigure(body))
}

/// The drawable side of a simulated body: a character with the body's figure skeleton, so the
/// motion systems draw and record it as any other character.
pub fn drawn_body(name: &str, body: &HumanBody) -> impl Bundle {
    let skeleton = Arc::new(body.figure.skeleton());
    let n = skeleton.joints.len();
    (
        Character { name: name.into() },
        SkeletonRef(skeleton),
        JointState::new(n),
        Recorder::default(),
    )
}

/// Sets the joint state of every drawn body from its configuration: the pelvis from the
/// floating base, every other joint from its DOF angles (as a model clip does).
pub fn publish_body_pose(
    mut scratch: Local<(Vec<f64>, Vec<f64>)>,
    mut q: Query<(&HumanFigure, &BodyState, &mut JointState), With<PhysicsBody>>,
) {
    let (all, angles) = &mut *scratch;
    for (human, state, mut joints) in &mut q {
        let b = &**human;
        all.resize(b.model.nv(), 0.0);
        b.model.angles(&state.q, all);
        angles.clear();
        angles.extend(b.dof_v.iter().map(|&k| all[k]));
        let js = &mut *joints;
        b.figure.local_rotations(angles, &mut js.rotations);
        for (t, j) in js.translations.iter_mut().zip(&b.figure.joints) {
            *t = j.offset;
        }
        let qs = &state.q;
        js.translations[0] = DVec3::new(qs[0], qs[1], qs[2]);
        js.rotations[0] = DQuat::from_xyzw(qs[3], qs[4], qs[5], qs[6]);
    }
}

/// Adds the physics systems ([`super::physics::add_physics_systems`]) and
/// [`publish_body_pose`] in [`MotionSet::Pose`] to `schedule`: simulated human bodies that are
/// drawn and recorded as characters.
pub fn add_human_physics_systems(schedule: &mut Schedule) {
    super::physics::add_physics_systems(schedule);
    schedule.add_systems(publish_body_pose.in_set(MotionSet::Pose));
}
