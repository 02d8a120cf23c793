//! The motion systems: clip playback, forward kinematics and recording of every character.

use bevy_ecs::prelude::*;

use super::clock::Clock;
use super::motion::{ClipPlayback, JointState, Recorder, SkeletonRef};
use super::sets::{MotionSet, configure_motion_sets};
use crate::skeleton::forward_kinematics;

/// Samples every playing clip at its current time into the joint state, then advances the clip
/// time by `speed × tick`.
pub fn sample_clips(clock: Res<Clock>, mut q: Query<(&mut ClipPlayback, &mut JointState)>) {
    for (mut play, mut state) in &mut q {
        let clip = play.clip.clone();
        let frames = clip.frame_count();
        let last = frames.saturating_sub(1) as f64;
        let mut u = play.time / clip.frame_time;
        if play.looping && frames > 1 {
            u = u.rem_euclid(frames as f64);
        }
        let u = u.clamp(0.0, last);
        let f0 = u.floor() as usize;
        let f1 = (f0 + 1).min(frames - 1);
        let w = u - f0 as f64;
        let (t0, t1) = (clip.frame_translations(f0), clip.frame_translations(f1));
        let (r0, r1) = (clip.frame_rotations(f0), clip.frame_rotations(f1));
        let st = &mut *state;
        for j in 0..clip.joint_count() {
            st.translations[j] = t0[j].lerp(t1[j], w);
            st.rotations[j] = if w == 0.0 {
                r0[j]
            } else {
                r0[j].slerp(r1[j], w)
            };
        }
        play.time += play.speed * clock.tick_s;
    }
}

/// Global transforms of every character's joints.
pub fn forward_kinematics_system(mut q: Query<(&SkeletonRef, &mut JointState)>) {
    for (sk, mut state) in &mut q {
        let st = &mut *state;
        forward_kinematics(&sk.0, &st.translations, &st.rotations, &mut st.globals);
    }
}

/// Appends every character's drawable points to its recorder.
pub fn record_frames(mut q: Query<(&SkeletonRef, &JointState, &mut Recorder)>) {
    for (sk, state, mut rec) in &mut q {
        let mut pts = Vec::with_capacity(state.globals.len() + 8);
        sk.0.points(&state.globals, &mut pts);
        rec.frames.push(pts);
    }
}

/// Adds the motion systems to `schedule`: clip playback in [`MotionSet::Animate`], forward
/// kinematics in [`MotionSet::Kinematics`], recording in [`MotionSet::Record`].
pub fn add_motion_systems(schedule: &mut Schedule) {
    configure_motion_sets(schedule);
    schedule.add_systems((
        sample_clips.in_set(MotionSet::Animate),
        forward_kinematics_system.in_set(MotionSet::Kinematics),
        record_frames.in_set(MotionSet::Record),
    ));
}
