//! The one hierarchy of system sets, run in this order every tick:
//!
//! [`MotionSet::Animate`] (clip playback, primitive players and blends) →
//! [`MotionSet::Control`] (controllers set PD targets, pushes set external forces) →
//! [`MotionSet::Physics`] (the simulated bodies take their substeps) →
//! [`MotionSet::Pose`] (DOF poses and body states become joint states) →
//! [`MotionSet::Kinematics`] (global transforms) → [`MotionSet::Record`] → [`MotionSet::Clock`].
//!
//! A user's own systems go in or between them (`.after(MotionSet::Animate)
//! .before(MotionSet::Control)`), and sub-sets order systems inside one of them:
//! [`PrimitiveSet`](super::primitive::PrimitiveSet) (players → blends) inside `Animate`,
//! [`ControlSet`](super::character::ControlSet) (PD targets from the primitives → reactions to
//! pushes → root assistance) inside `Control`. Joint limits, floor contact and the dynamics are
//! the stages of one physics step ([`crate::dynamics::pipeline`]), evaluated at every
//! integrator stage, so they run inside `Physics` as one system.

use bevy_ecs::prelude::*;

use super::clock::advance_clock;

/// The stages of a tick.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MotionSet {
    /// Kinematic motion sources advance: clips, primitive players, blends.
    Animate,
    /// Controllers write PD targets and external forces.
    Control,
    /// Simulated bodies step.
    Physics,
    /// Every character's joint state is set from its source (DOF pose or body state).
    Pose,
    /// Global transforms from local ones.
    Kinematics,
    /// Outputs are recorded.
    Record,
    /// The clock advances.
    Clock,
}

/// Orders the [`MotionSet`]s in `schedule` (idempotent: every `add_*_systems` calls it).
pub fn configure_motion_sets(schedule: &mut Schedule) {
    schedule.configure_sets(
        (
            MotionSet::Animate,
            MotionSet::Control,
            MotionSet::Physics,
            MotionSet::Pose,
            MotionSet::Kinematics,
            MotionSet::Record,
            MotionSet::Clock,
        )
            .chain(),
    );
}

/// The sets and the clock: call once per schedule, before or after the domain helpers
/// ([`add_motion_systems`](super::add_motion_systems),
/// [`add_primitive_systems`](super::primitive::add_primitive_systems),
/// [`add_physics_systems`](super::physics::add_physics_systems)).
pub fn add_core_systems(schedule: &mut Schedule) {
    configure_motion_sets(schedule);
    schedule.add_systems(advance_clock.in_set(MotionSet::Clock));
}
