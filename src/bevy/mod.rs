//! The Bevy plugin (feature `bevy`): the engine's systems in a Bevy [`App`] for game
//! prototypes. [`MarionettePlugin`] inserts the World's [`Clock`], registers the character
//! components, adds every engine system with its [`MotionSet`] hierarchy to Bevy's
//! fixed-timestep schedule [`FixedUpdate`], and runs [`FixedMain`] `ticks_per_update` times per
//! app update from [`RunFixedMainLoop`] (one engine tick each, so the simulation advances by the
//! engine's clock, never by wall time, and gives the same bits as a plain World). Joint
//! transforms are published as [`Transform`]s of one child entity per joint
//! ([`spawn_joint_entities`], [`publish_joint_transforms`], after [`MotionSet::Kinematics`]), for
//! meshes to follow.
//!
//! In an app with Bevy's `TimePlugin` (part of `DefaultPlugins`), Bevy's own fixed loop also
//! runs [`FixedMain`] from virtual time (each run one more engine tick); to advance the engine
//! only through [`TicksPerUpdate`], pause `Time<Virtual>` (as `examples/viewer.rs` does), or
//! set `ticks_per_update` to 0 and `Time<Fixed>` to the clock's tick to let Bevy pace it.

use bevy_app::{App, FixedMain, FixedUpdate, Plugin, RunFixedMainLoop, RunFixedMainLoopSystems};
use bevy_ecs::prelude::*;
use bevy_transform::components::Transform;

use crate::ecs::DofPose;
use crate::ecs::character::{
    CharacterLog, Feedforward, Reaction, RootAssist, TrackPose, add_all_character_systems,
};
use crate::ecs::human::HumanFigure;
use crate::ecs::physics::{BodyState, ExternalForces, PdController, PhysicsBody};
use crate::ecs::primitive::PrimitivePlayer;
use crate::ecs::{Clock, JointState, MotionSet};

/// The plugin: the clock, the components, the engine's systems on [`FixedUpdate`].
#[derive(Clone, Copy, Debug)]
pub struct MarionettePlugin {
    /// The World's clock (tick length and physics substeps).
    pub clock: Clock,
    /// Engine ticks per app update.
    pub ticks_per_update: u32,
}

/// How many engine ticks ([`FixedMain`] runs) one app update takes.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct TicksPerUpdate(pub u32);

/// A character's joint entities (children of the character), in skeleton joint order.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct JointEntities(pub Vec<Entity>);

impl Plugin for MarionettePlugin {
    fn build(&self, app: &mut App) {
        app.insert_resource(self.clock)
            .insert_resource(TicksPerUpdate(self.ticks_per_update));
        let w = app.world_mut();
        w.register_component::<PhysicsBody>();
        w.register_component::<HumanFigure>();
        w.register_component::<BodyState>();
        w.register_component::<PdController>();
        w.register_component::<ExternalForces>();
        w.register_component::<PrimitivePlayer>();
        w.register_component::<DofPose>();
        w.register_component::<TrackPose>();
        w.register_component::<RootAssist>();
        w.register_component::<Reaction>();
        w.register_component::<Feedforward>();
        w.register_component::<CharacterLog>();
        w.register_component::<JointState>();
        w.register_component::<JointEntities>();
        app.edit_schedule(FixedUpdate, add_all_character_systems);
        app.add_systems(
            FixedUpdate,
            publish_joint_transforms
                .after(MotionSet::Kinematics)
                .before(MotionSet::Record),
        );
        app.add_systems(
            RunFixedMainLoop,
            run_engine_ticks.in_set(RunFixedMainLoopSystems::FixedMainLoop),
        );
    }
}

/// Runs [`FixedMain`] (hence [`FixedUpdate`]) [`TicksPerUpdate`] times.
pub fn run_engine_ticks(world: &mut World) {
    let n = world.get_resource::<TicksPerUpdate>().map_or(1, |t| t.0);
    for _ in 0..n {
        world.run_schedule(FixedMain);
    }
}

/// Spawns one child entity with a [`Transform`] per joint of `character` (which must carry a
/// [`JointState`]) and records them in its [`JointEntities`].
pub fn spawn_joint_entities(world: &mut World, character: Entity) -> Vec<Entity> {
    let n = world
        .get::<JointState>(character)
        .map_or(0, |s| s.globals.len());
    let joints: Vec<Entity> = (0..n)
        .map(|_| world.spawn((Transform::IDENTITY, ChildOf(character))).id())
        .collect();
    world
        .entity_mut(character)
        .insert(JointEntities(joints.clone()));
    joints
}

/// Sets every joint entity's [`Transform`] to its joint's global transform (world frame, f32).
pub fn publish_joint_transforms(
    characters: Query<(&JointState, &JointEntities)>,
    mut transforms: Query<&mut Transform>,
) {
    for (state, joints) in &characters {
        for (g, &e) in state.globals.iter().zip(&joints.0) {
            if let Ok(mut t) = transforms.get_mut(e) {
                t.translation = g.translation.as_vec3();
                t.rotation = g.rotation.as_quat();
            }
        }
    }
}
