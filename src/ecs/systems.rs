//! Systems of the base ECS and their ordering sets.

use bevy_ecs::prelude::*;

use super::motion::{ClipPlayback, JointState, Recorder, SimulationClock, SkeletonRef};
use crate::skeleton::forward_kinematics;

/// The stages of a base step, run in this order: sample poses from clips, forward kinematics,
/// record, advance the clock. Other domains put their systems in or between these sets.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BaseSet {
    /// Poses are set (clip sampling, primitives, dynamics).
    Pose,
    /// Global transforms from local ones.
    Kinematics,
    /// Outputs are recorded.
    Record,
    /// Time advances.
    Clock,
}

/// Samples every playing clip at its current time into the joint state, then advances the clip
/// time by `speed × dt`.
pub fn sample_clips(
    clock: Res<SimulationClock>,
    mut q: Query<(&mut ClipPlayback, &mut JointState)>,
) {
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
        play.time += play.speed * clock.dt;
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

/// Advances the world clock by one step.
pub fn advance_clock(mut clock: ResMut<SimulationClock>) {
    clock.time += clock.dt;
    clock.step += 1;
}

/// The base schedule: [`BaseSet`]s chained in order, with the base systems in them.
pub fn base_schedule() -> Schedule {
    let mut s = Schedule::default();
    s.configure_sets(
        (
            BaseSet::Pose,
            BaseSet::Kinematics,
            BaseSet::Record,
            BaseSet::Clock,
        )
            .chain(),
    );
    s.add_systems((
        sample_clips.in_set(BaseSet::Pose),
        forward_kinematics_system.in_set(BaseSet::Kinematics),
        record_frames.in_set(BaseSet::Record),
        advance_clock.in_set(BaseSet::Clock),
    ));
    s
}
