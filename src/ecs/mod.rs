//! The ECS wiring of the engine's base: characters are entities carrying a skeleton, a joint
//! state, a clip playback and a recorder; a schedule advances time, samples clips, runs forward
//! kinematics and records, in explicit, user-orderable system sets.
//!
//! Characters driven by motor primitives carry a [`crate::ecs::primitive::PrimitivePlayer`] and
//! a [`ModelBinding`]: the players step in [`BaseSet::Pose`] and [`pose_from_dofs`] hands their
//! poses to forward kinematics ([`add_primitive_wiring`]).
//!
//! A [`bevy_ecs::world::World`] holds one whole experiment and is `Send`, so many run in
//! parallel ([`run_worlds_parallel`]). Build one schedule per world with [`base_schedule`]
//! (schedules are not `Clone`).

mod dof_pose;
mod motion;
pub mod primitive;
mod systems;

pub use motion::{Character, ClipPlayback, JointState, Recorder, SimulationClock, SkeletonRef};
pub use dof_pose::{
    ModelBinding, add_primitive_wiring, new_primitive_world, pose_from_dofs, run_primitive_world,
    spawn_primitive_character,
};
pub use systems::{
    BaseSet, advance_clock, base_schedule, forward_kinematics_system, record_frames, sample_clips,
};

use std::sync::Arc;

use bevy_ecs::prelude::*;
use rayon::prelude::*;

use crate::skeleton::Clip;

/// Spawns a character that plays `clip` (looping or not) and records the drawable points of
/// every step; returns its entity.
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

/// A world with a clock of step `dt` seconds, ready for characters.
pub fn new_world(dt: f64) -> World {
    let mut world = World::new();
    world.insert_resource(SimulationClock {
        time: 0.0,
        dt,
        step: 0,
    });
    world
}

/// Runs `steps` steps of the base schedule on every world, in parallel with rayon (one schedule
/// per world). Worlds share nothing, so the result does not depend on the thread count.
pub fn run_worlds_parallel(worlds: &mut [World], steps: usize) {
    worlds.par_iter_mut().for_each(|w| {
        let mut schedule = base_schedule();
        for _ in 0..steps {
            schedule.run(w);
        }
    });
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
                .to_model_clip()
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
        let mut world = new_world(clip.frame_time);
        let e = spawn_clip_character(&mut world, "a", clip.clone(), false);
        let mut schedule = base_schedule();
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
        let make = || -> Vec<World> {
            (0..8)
                .map(|i| {
                    let mut w = new_world(clip.frame_time * 0.37);
                    let e = spawn_clip_character(&mut w, "c", clip.clone(), true);
                    w.get_mut::<ClipPlayback>(e).unwrap().speed = 0.5 + 0.1 * i as f64;
                    w
                })
                .collect()
        };
        let run = |threads: usize| -> Vec<Vec<Vec<glam::DVec3>>> {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut worlds = make();
            pool.install(|| run_worlds_parallel(&mut worlds, 200));
            worlds
                .iter_mut()
                .map(|w| {
                    w.query::<&Recorder>()
                        .iter(w)
                        .next()
                        .unwrap()
                        .frames
                        .clone()
                })
                .collect()
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
