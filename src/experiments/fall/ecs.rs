//! The pushed fall in a World: a falling character is the physics components of
//! [`crate::ecs::physics`] (stepped by the engine's physics systems) plus the paper's
//! [`FallController`] (in [`MotionSet::Control`]) and a [`FallRecorder`] (in
//! [`MotionSet::Record`]), which stops the body once its run is over. One World per fall runs
//! with the World's [`Clock`] ticking one physics step; many run in parallel in a
//! [`WorldPool`], to the same bits on any number of threads.

use std::sync::Arc;

use bevy_ecs::prelude::*;

use super::{FallCharacter, FallConfig, FallController, FallRecorder, FallResult, SimError};
use crate::ecs::physics::{
    BodyState, PdController, PhysicsBody, PhysicsMonitor, PhysicsStatus, PhysicsWorkspace,
    add_physics_systems,
};
use crate::ecs::{Clock, MotionSet, WorldPool, add_core_systems, configure_motion_sets};

/// The paper's controller: the key pose becomes the PD target at the reaction time.
pub fn fall_control_system(
    mut q: Query<(
        &BodyState,
        &PhysicsStatus,
        &mut FallController,
        &mut PdController,
    )>,
) {
    for (state, status, mut controller, mut pd) in &mut q {
        if status.running() {
            controller.apply(state.time_s, &mut pd.0);
        }
    }
}

/// Records every falling body that stepped (frames, rest) and stops it once its run is over.
pub fn fall_record_system(
    mut q: Query<(
        &PhysicsBody,
        &BodyState,
        &mut PhysicsWorkspace,
        &PhysicsMonitor,
        &mut FallRecorder,
        &mut PhysicsStatus,
    )>,
) {
    for (body, state, mut ws, monitor, mut recorder, mut status) in &mut q {
        if status.error.is_some() {
            continue;
        }
        let b = &*body.body;
        recorder.record(b, state, ws.kinematics_of(&b.model, state), monitor);
        if recorder.finished(state) {
            status.stopped = true;
        }
    }
}

/// Adds the fall systems to `schedule`: [`fall_control_system`] in [`MotionSet::Control`],
/// [`fall_record_system`] in [`MotionSet::Record`].
pub fn add_fall_systems(schedule: &mut Schedule) {
    configure_motion_sets(schedule);
    schedule.add_systems((
        fall_control_system.in_set(MotionSet::Control),
        fall_record_system.in_set(MotionSet::Record),
    ));
}

/// The schedule of a World of falls: core sets and clock, physics, the fall systems.
pub fn fall_schedule() -> Schedule {
    let mut s = Schedule::default();
    add_core_systems(&mut s);
    add_physics_systems(&mut s);
    add_fall_systems(&mut s);
    s
}

/// Spawns one falling character into `world` and records its first frame. The World's
/// [`Clock`] must step physics by the fall's `dt_s`.
pub fn spawn_fall(world: &mut World, mut ch: FallCharacter) -> Result<Entity, SimError> {
    let dt = world.get_resource::<Clock>().map(|c| c.physics_dt());
    if dt != Some(ch.recorder.dt) {
        return Err(SimError::Config {
            field: "dt_s".into(),
            message: format!(
                "the fall steps by {} s but the World's clock steps physics by {}",
                ch.recorder.dt,
                dt.map_or("nothing (no Clock)".to_string(), |d| format!("{d} s"))
            ),
        });
    }
    let p = &mut ch.physics;
    let b = &*p.body.body;
    let data = p.workspace.kinematics_of(&b.model, &p.state);
    ch.recorder.record(b, &p.state, data, &p.monitor);
    if ch.recorder.finished(&p.state) {
        p.status.stopped = true;
    }
    Ok(world
        .spawn((
            ch.physics,
            ch.pd,
            ch.limits,
            ch.contact,
            ch.external,
            ch.controller,
            ch.recorder,
        ))
        .id())
}

/// A World holding the fall of `config` (validated and stability-checked), its clock ticking
/// one step of `config.dt_s`.
pub fn build_fall_world(config: &FallConfig) -> Result<World, SimError> {
    let ch = super::build_fall(config)?;
    let mut world = World::new();
    world.insert_resource(Clock::physics(config.dt_s));
    spawn_fall(&mut world, ch)?;
    Ok(world)
}

/// Runs the fall schedule until every falling body in `world` has finished or failed; returns
/// the result of each in spawn order.
pub fn run_fall_world(world: &mut World) -> Vec<Result<FallResult, Arc<SimError>>> {
    let mut schedule = fall_schedule();
    let mut running = world.query_filtered::<&PhysicsStatus, With<FallRecorder>>();
    while running.iter(world).any(PhysicsStatus::running) {
        schedule.run(world);
    }
    fall_results(world)
}

/// The result of every falling body in `world`, in spawn order.
pub fn fall_results(world: &mut World) -> Vec<Result<FallResult, Arc<SimError>>> {
    let mut q = world.query::<(
        Entity,
        &PhysicsBody,
        &BodyState,
        &PhysicsMonitor,
        &FallRecorder,
        &PhysicsStatus,
    )>();
    let mut out: Vec<(Entity, Result<FallResult, Arc<SimError>>)> = q
        .iter(world)
        .map(|(e, body, state, monitor, recorder, status)| {
            let r = match &status.error {
                Some(err) => Err(Arc::new(SimError::Step((**err).clone()))),
                None => Ok(recorder.result(&body.body, state, monitor)),
            };
            (e, r)
        })
        .collect();
    out.sort_by_key(|(e, _)| e.index());
    out.into_iter().map(|(_, r)| r).collect()
}

/// Why a World of a pool holds no fall.
#[derive(Resource)]
struct NotBuilt(Arc<SimError>);

/// Simulates each configuration in its own World of a [`WorldPool`], in parallel on the
/// current rayon pool; the results are in input order and do not depend on the number of
/// threads.
pub fn run_parallel(configs: &[FallConfig]) -> Vec<Result<FallResult, Arc<SimError>>> {
    run_parallel_from(configs, None)
}

/// [`run_parallel`] with the falls' settled standing start taken from `start` where it fits
/// (see [`super::SettledStart`]): the same results, without settling each fall anew.
pub fn run_parallel_from(
    configs: &[FallConfig],
    start: Option<&super::SettledStart>,
) -> Vec<Result<FallResult, Arc<SimError>>> {
    let pool = WorldPool::new(configs.len(), 0, |k, world| {
        world.insert_resource(Clock::physics(configs[k].dt_s));
        let built = super::build_fall_from(&configs[k], start).and_then(|ch| spawn_fall(world, ch));
        if let Err(e) = built {
            world.insert_resource(NotBuilt(Arc::new(e)));
        }
        Ok::<(), std::convert::Infallible>(())
    });
    let mut pool = match pool {
        Ok(p) => p,
        Err(never) => match never {},
    };
    pool.run(|w| {
        if let Some(e) = w.get_resource::<NotBuilt>() {
            return Err(e.0.clone());
        }
        run_fall_world(w).pop().unwrap_or_else(|| {
            Err(Arc::new(SimError::Config {
                field: "world".into(),
                message: "no character".into(),
            }))
        })
    })
}
