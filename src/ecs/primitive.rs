//! ECS wiring (bevy_ecs): characters carry primitive players; systems step them every frame.
//!
//! - [`PrimitivePlayer`] plays a sequence of primitives, connected: each starts from the state the
//!   previous one ended in and takes over without a step in acceleration (as
//!   [`crate::primitive::connect()`], with its [`HandOver`]); after the last one the DMP keeps
//!   running and settles on its goal.
//! - [`BlendPlayer`] plays two primitives placed on a time line and mixes them live with γ(t′)
//!   (step 3 of the paper's blending, as [`crate::primitive::blend()`] without re-learning).
//! - Both write the character's [`DofPose`] (θ and θ̇ per DOF) for the systems downstream
//!   (forward kinematics, rendering).
//! - The World's [`Clock`] gives the step (one tick); [`PrimitiveSet`] orders the systems inside
//!   [`MotionSet::Animate`]; [`add_primitive_systems`] adds them to a [`Schedule`]. Many
//!   characters live in one World.

use std::collections::VecDeque;
use std::sync::Arc;

use bevy_ecs::prelude::*;

use super::clock::Clock;
use super::dof_pose::{DofPose, FigureBinding, pose_from_dofs};
use super::motion::{Character, JointState, Recorder, SkeletonRef};
use super::sets::{MotionSet, configure_motion_sets};
use crate::humanoid::Figure;

use crate::primitive::HandOver;
use crate::primitive::Primitive;
use crate::primitive::Rollout;
use crate::primitive::blend::{BlendPlacement, Gamma};
use crate::primitive::error::{PrimitiveError, Result};

/// Plays a connected sequence of primitives.
#[derive(Component, Clone, Debug)]
pub struct PrimitivePlayer {
    names: Arc<[String]>,
    upcoming: VecDeque<Arc<Primitive>>,
    current: Rollout,
    /// The previous primitive playing on while the current one takes over.
    handover: Option<HandOver>,
    index: usize,
    elapsed: f64,
    finished: bool,
}

impl PrimitivePlayer {
    /// A player for `sequence` (non-empty, all with the same DOF names), starting at the first
    /// primitive's demonstrated start.
    pub fn new(sequence: Vec<Arc<Primitive>>) -> Result<PrimitivePlayer> {
        let mut upcoming: VecDeque<_> = sequence.into();
        let first = upcoming
            .pop_front()
            .ok_or_else(|| PrimitiveError::InvalidParameter {
                field: "sequence".into(),
                reason: "empty".into(),
            })?;
        for p in &upcoming {
            if p.names() != first.names() {
                return Err(PrimitiveError::DofMismatch {
                    what: format!("`{}` and `{}` have different DOFs", first.name, p.name),
                });
            }
        }
        Ok(PrimitivePlayer {
            names: first.names().into(),
            upcoming,
            current: Rollout::new(&first, None)?,
            handover: None,
            index: 0,
            elapsed: 0.0,
            finished: false,
        })
    }

    /// The current pose (θ, θ̇) as a new [`DofPose`], e.g. to spawn a character with.
    pub fn pose(&self) -> DofPose {
        let mut p = DofPose {
            names: self.names.clone(),
            ..DofPose::default()
        };
        self.write_pose(&mut p);
        p
    }

    /// Index in the sequence of the primitive playing now.
    pub fn index(&self) -> usize {
        self.index
    }

    /// Seconds since the sequence started.
    pub fn elapsed(&self) -> f64 {
        self.elapsed
    }

    /// True once the last primitive has reached its duration.
    pub fn is_finished(&self) -> bool {
        self.finished
    }

    /// Advances by `dt` seconds, handing the state over to the next primitive at each junction
    /// (the remainder of the step is played by the next one).
    pub fn advance(&mut self, dt: f64) {
        let mut left = dt.max(0.0);
        self.elapsed += left;
        loop {
            let to_end = self.current.duration() - self.current.time();
            if left < to_end || self.upcoming.is_empty() {
                self.current.advance(left);
                if self
                    .handover
                    .as_ref()
                    .is_some_and(|h| !h.active(self.current.time()))
                {
                    self.handover = None;
                }
                if self.upcoming.is_empty()
                    && self.current.time() >= self.current.duration() - 1e-12
                {
                    self.finished = true;
                }
                return;
            }
            self.current.advance_to(self.current.duration());
            left -= to_end.max(0.0);
            let state = self.current.state();
            let next = self.upcoming.pop_front().expect("checked non-empty");
            match Rollout::new(&next, Some(&state)) {
                Ok(r) => {
                    self.handover = Some(HandOver::new(&self.current, &r, next.duration));
                    self.current = r;
                    self.index += 1;
                }
                Err(_) => {
                    // Unreachable for sequences checked in `new`; stop rather than panic.
                    self.upcoming.clear();
                }
            }
        }
    }

    /// Writes the current θ and θ̇ into `pose` (inside a hand-over window, the mix of the
    /// previous primitive played on and the current one).
    pub fn write_pose(&self, pose: &mut DofPose) {
        pose.theta.clear();
        pose.theta.extend_from_slice(self.current.theta());
        pose.theta_dot.resize(pose.theta.len(), 0.0);
        self.current.theta_dot_into(&mut pose.theta_dot);
        if let Some(h) = &self.handover {
            h.mix(self.current.time(), &mut pose.theta, &mut pose.theta_dot);
        }
    }
}

/// Plays a live blend of A and B: θ = γ(t′)θ_A + (1 − γ(t′))θ_B on the overlap, whichever is
/// defined outside it; time runs from min(t_As, t_Bs).
#[derive(Component, Clone, Debug)]
pub struct BlendPlayer {
    names: Arc<[String]>,
    a: Rollout,
    b: Rollout,
    placement: BlendPlacement,
    gamma: Gamma,
    time: f64,
}

impl BlendPlayer {
    /// A live blend (the same checks as [`crate::primitive::blend()`]: same DOFs, a valid
    /// arrangement, a valid γ).
    pub fn new(
        a: &Primitive,
        b: &Primitive,
        placement: BlendPlacement,
        gamma: Gamma,
    ) -> Result<BlendPlayer> {
        if a.names() != b.names() {
            return Err(PrimitiveError::DofMismatch {
                what: format!(
                    "cannot blend `{}` with `{}`: the DOF sets differ",
                    a.name, b.name
                ),
            });
        }
        placement.arrangement()?;
        gamma.validate()?;
        let pa = a.with_duration(placement.a_end - placement.a_start)?;
        let pb = b.with_duration(placement.b_end - placement.b_start)?;
        Ok(BlendPlayer {
            names: a.names().into(),
            a: Rollout::new(&pa, None)?,
            b: Rollout::new(&pb, None)?,
            placement,
            gamma,
            time: placement.span().0,
        })
    }

    /// The current blended pose as a new [`DofPose`], e.g. to spawn a character with.
    pub fn pose(&mut self) -> DofPose {
        let mut p = DofPose {
            names: self.names.clone(),
            ..DofPose::default()
        };
        self.write_pose(&mut p);
        p
    }

    /// Current time on the blend's time line, seconds.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Advances by `dt` seconds and writes the blended θ and θ̇ into `pose`.
    pub fn advance(&mut self, dt: f64, pose: &mut DofPose) {
        self.time += dt.max(0.0);
        self.write_pose(pose);
    }

    /// Writes the blended θ and θ̇ at the current time into `pose`.
    pub fn write_pose(&mut self, pose: &mut DofPose) {
        let pl = self.placement;
        let t = self.time.min(pl.a_end);
        let eps = 1e-9;
        let have_a = t >= pl.a_start - eps;
        let have_b = t >= pl.b_start - eps && t <= pl.b_end + eps;
        if have_a {
            self.a.advance_to(t - pl.a_start);
        }
        if have_b {
            self.b.advance_to(t - pl.b_start);
        }
        let d = self.a.theta().len();
        pose.theta.resize(d, 0.0);
        pose.theta_dot.resize(d, 0.0);
        let (o0, o1) = pl.overlap();
        if have_a && have_b && t >= o0 - eps {
            let g = self.gamma.at((t - o0) / (o1 - o0));
            let mut va = vec![0.0; d];
            let mut vb = vec![0.0; d];
            self.a.theta_dot_into(&mut va);
            self.b.theta_dot_into(&mut vb);
            for j in 0..d {
                pose.theta[j] = g * self.a.theta()[j] + (1.0 - g) * self.b.theta()[j];
                pose.theta_dot[j] = g * va[j] + (1.0 - g) * vb[j];
            }
        } else if have_a {
            pose.theta.copy_from_slice(self.a.theta());
            self.a.theta_dot_into(&mut pose.theta_dot);
        } else {
            pose.theta.copy_from_slice(self.b.theta());
            self.b.theta_dot_into(&mut pose.theta_dot);
        }
    }
}

/// Ordering of the primitive systems: sequence players, then blend players.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PrimitiveSet {
    /// [`step_primitive_players`].
    Players,
    /// [`step_blend_players`].
    Blends,
}

/// Steps every [`PrimitivePlayer`] by one tick and writes its [`DofPose`].
pub fn step_primitive_players(
    clock: Res<Clock>,
    mut q: Query<(&mut PrimitivePlayer, &mut DofPose)>,
) {
    for (mut player, mut pose) in &mut q {
        player.advance(clock.tick_s);
        player.write_pose(&mut pose);
    }
}

/// Steps every [`BlendPlayer`] by one tick and writes its [`DofPose`].
pub fn step_blend_players(clock: Res<Clock>, mut q: Query<(&mut BlendPlayer, &mut DofPose)>) {
    for (mut player, mut pose) in &mut q {
        player.advance(clock.tick_s, &mut pose);
    }
}

/// Adds the primitive systems to `schedule`: [`PrimitiveSet::Players`] then
/// [`PrimitiveSet::Blends`] inside [`MotionSet::Animate`], and [`pose_from_dofs`] in
/// [`MotionSet::Pose`] (characters with a [`FigureBinding`] get their joint state from their DOF
/// pose).
pub fn add_primitive_systems(schedule: &mut Schedule) {
    configure_motion_sets(schedule);
    schedule.configure_sets(
        (PrimitiveSet::Players, PrimitiveSet::Blends)
            .chain()
            .in_set(MotionSet::Animate),
    );
    schedule.add_systems((
        step_primitive_players.in_set(PrimitiveSet::Players),
        step_blend_players.in_set(PrimitiveSet::Blends),
        pose_from_dofs.in_set(MotionSet::Pose),
    ));
}

/// Spawns a character on `model` that plays `sequence` (connected) and records its points.
pub fn spawn_primitive_character(
    world: &mut World,
    name: &str,
    model: Arc<Figure>,
    sequence: Vec<Arc<Primitive>>,
) -> Result<Entity> {
    let player = PrimitivePlayer::new(sequence)?;
    let pose = player.pose();
    let binding = FigureBinding::new(model.clone(), &pose.names)?;
    let skeleton = Arc::new(model.skeleton());
    let n = skeleton.joints.len();
    Ok(world
        .spawn((
            Character { name: name.into() },
            SkeletonRef(skeleton),
            JointState::new(n),
            Recorder::default(),
            pose,
            player,
            binding,
        ))
        .id())
}
