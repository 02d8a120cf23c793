//! The ECS wiring every character shares (experiments above it add their own systems).
//! Characters are entities; what they carry decides what happens to them:
//!
//! - every character: [`Character`], [`SkeletonRef`], [`JointState`] and a [`Recorder`] of its
//!   drawable points; forward kinematics and recording treat all alike;
//! - kinematic motion: a [`ClipPlayback`], or primitive players
//!   ([`primitive::PrimitivePlayer`], [`primitive::BlendPlayer`]) writing a
//!   [`DofPose`] that a [`FigureBinding`] turns into the joint state;
//! - physics: a [`physics::PhysicsBundle`] (the rigid-body model, nothing human) and the force
//!   components the step reads ([`physics::PdController`], [`physics::JointLimits`],
//!   [`physics::FloorContact`], [`physics::ExternalForces`]); a human body also carries a
//!   [`human::HumanFigure`], through which its pose reaches the same joint state;
//! - physical characters (active ragdolls, [`character`]): both at once, a primitive player
//!   whose pose is the PD target of the simulated body, with root assistance and reactions to
//!   pushes.
//!
//! One [`Clock`] per World (a tick per schedule run, physics substeps inside it) and one
//! hierarchy of sets, [`MotionSet`], that a user orders their own systems against. Each domain
//! adds its systems to the user's schedule: [`add_core_systems`] (sets and clock, once),
//! [`add_motion_systems`], [`primitive::add_primitive_systems`],
//! [`physics::add_physics_systems`] (with the human bodies' pose,
//! [`human::add_human_physics_systems`]). A World holds one experiment and is `Send`; a
//! [`WorldPool`] runs many in parallel, each with its own seeded generator.
//!
//! The four domains that add systems of their own stay namespaces, as Bevy plugins would:
//! [`primitive`], [`physics`], [`human`] and [`character`]; the shared wiring (clock, sets,
//! motion, DOF pose, worlds) is in private files re-exported here.

pub mod character;
mod clock;
mod dof_pose;
pub mod human;
mod motion;
pub mod physics;
pub mod primitive;
mod sets;
mod systems;
mod worlds;

pub use clock::{Clock, advance_clock};
pub use dof_pose::{DofPose, FigureBinding, pose_from_dofs};
pub use motion::{Character, ClipPlayback, JointState, Recorder, SkeletonRef};
pub use primitive::spawn_primitive_character;
pub use sets::{MotionSet, add_core_systems, configure_motion_sets};
pub use systems::{add_motion_systems, forward_kinematics_system, record_frames, sample_clips};
pub use worlds::{WorldPool, WorldRng, WorldSeed, world_seed};

use std::sync::Arc;

use bevy_ecs::prelude::*;

use crate::skeleton::Clip;

/// Spawns a character that plays `clip` (looping or not) and records the drawable points of
/// every tick; returns its entity.
pub fn spawn_clip_character(
    world: &mut World,
    name: &str,
    clip: Arc<Clip>,
    looping: bool,
) -> Entity {
    let skeleton = Arc::new(clip.skeleton.clone());
    let n = skeleton.joints.len();
    world
        .spawn((
            Character {
                name: name.to_string(),
            },
            SkeletonRef(skeleton),
            JointState::new(n),
            ClipPlayback {
                clip,
                time: 0.0,
                speed: 1.0,
                looping,
            },
            Recorder::default(),
        ))
        .id()
}

/// A World with `clock`, ready for characters.
pub fn new_world(clock: Clock) -> World {
    let mut world = World::new();
    world.insert_resource(clock);
    world
}

/// The schedule of kinematic characters: core sets and clock, clip playback, primitive players,
/// forward kinematics and recording.
pub fn kinematic_schedule() -> Schedule {
    let mut s = Schedule::default();
    add_core_systems(&mut s);
    add_motion_systems(&mut s);
    primitive::add_primitive_systems(&mut s);
    s
}

/// Runs `ticks` runs of `schedule` on `world`.
pub fn run_ticks(world: &mut World, schedule: &mut Schedule, ticks: usize) {
    for _ in 0..ticks {
        schedule.run(world);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::clips::KeyframeClip;

    fn test_clip() -> Arc<Clip> {
        let text = r#"(format_version: 1, name: "wave", model: "humanoid24", fps: 60.0, duration: 1.0,
            keys: [(t: 0.0, dofs: {"left_shoulder_abduction": 0.0}), (t: 0.5, dofs: {"left_shoulder_abduction": 90.0}),
                   (t: 1.0, dofs: {"left_shoulder_abduction": 0.0})])"#;
        Arc::new(
            KeyframeClip::parse(text, "wave")
                .unwrap()
                .to_figure_clip()
                .to_clip(),
        )
    }

    #[test]
    fn world_is_send() {
        fn assert_send<T: Send>() {}
        assert_send::<World>();
    }

    #[test]
    fn playback_records_the_clip_frames() {
        let clip = test_clip();
        let mut world = new_world(Clock::new(clip.frame_time, 1));
        let e = spawn_clip_character(&mut world, "a", clip.clone(), false);
        let mut schedule = kinematic_schedule();
        for _ in 0..clip.frame_count() {
            schedule.run(&mut world);
        }
        let rec = world.get::<Recorder>(e).unwrap();
        assert_eq!(rec.frames.len(), clip.frame_count());
        let expected = clip.point_frames();
        for (f, (a, b)) in rec.frames.iter().zip(&expected).enumerate() {
            for (p, q) in a.iter().zip(b) {
                assert!((*p - *q).length() < 1e-9, "frame {f}");
            }
        }
    }

    #[test]
    fn parallel_worlds_give_the_same_bits_on_one_and_two_threads() {
        let clip = test_clip();
        let make = || -> WorldPool {
            WorldPool::new(8, 1, |i, w| {
                w.insert_resource(Clock::new(clip.frame_time * 0.37, 1));
                let e = spawn_clip_character(w, "c", clip.clone(), true);
                w.get_mut::<ClipPlayback>(e).unwrap().speed = 0.5 + 0.1 * i as f64;
                Ok::<(), ()>(())
            })
            .unwrap()
        };
        let run = |threads: usize| -> Vec<Vec<Vec<glam::DVec3>>> {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut worlds = make();
                worlds.run(|w| {
                    let mut schedule = kinematic_schedule();
                    run_ticks(w, &mut schedule, 200);
                });
                worlds.run(|w| {
                    w.query::<&Recorder>()
                        .iter(w)
                        .next()
                        .unwrap()
                        .frames
                        .clone()
                })
            })
        };
        let one = run(1);
        let two = run(2);
        assert_eq!(one.len(), 8);
        for (a, b) in one.iter().zip(&two) {
            assert_eq!(a.len(), 200);
            for (fa, fb) in a.iter().zip(b) {
                for (p, q) in fa.iter().zip(fb) {
                    assert_eq!(
                        p.to_array().map(f64::to_bits),
                        q.to_array().map(f64::to_bits)
                    );
                }
            }
        }
    }
}
