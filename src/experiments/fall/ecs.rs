//! The ECS wiring of the pushed fall: a character is an entity carrying the body, joint-state,
//! PD-controller, joint-limit, contact, damage, recorder and workspace components of
//! [`fall`](super::fall); systems run the phases in explicit, user-orderable sets
//! [`FallSet::Control`] → [`FallSet::Limits`] → [`FallSet::Contact`] → [`FallSet::Step`] →
//! [`FallSet::Record`]. One `World` per simulation (it is `Send`); N Worlds run in parallel with
//! rayon and give bit-identical results on any number of threads, because each World is a
//! deterministic, single-threaded computation that shares nothing mutable.

use super::{
    BodyModel, ContactComponent, DamageRecord, FallConfig, FallParts, FallResult, JointLimits,
    JointState, PdController, Recorder, SimError, Workspace, build_fall, contact_phase,
    control_phase, dynamics_phase, finish, limits_phase, record_initial, record_phase,
};
use bevy_ecs::prelude::*;
use rayon::prelude::*;
use std::sync::Arc;

/// The ordered phases of one fall step.
#[derive(SystemSet, Debug, Clone, PartialEq, Eq, Hash)]
pub enum FallSet {
    /// Choose the PD target (stance or key pose).
    Control,
    /// Monitor joint-range excursions.
    Limits,
    /// Friction anchors and per-link contact statistics.
    Contact,
    /// One integrator step of the full force model.
    Step,
    /// Frames, rest detection, divergence checks.
    Record,
}

/// True while a character still has steps to take and no error.
fn running(state: &JointState, rec: &Recorder, ws: &Workspace) -> bool {
    ws.error.is_none() && !rec.finished(state)
}

/// Control system: the key pose becomes the target at the reaction time.
pub fn control_system(mut q: Query<(&JointState, &Recorder, &Workspace, &mut PdController)>) {
    for (state, rec, ws, mut pd) in &mut q {
        if running(state, rec, ws) {
            control_phase(state, &mut pd);
        }
    }
}

/// Limits system: records range excursions at the step start.
pub fn limits_system(
    mut q: Query<(
        &BodyModel,
        &JointState,
        &Recorder,
        &mut JointLimits,
        &mut Workspace,
    )>,
) {
    for (body, state, rec, mut limits, mut ws) in &mut q {
        if running(state, rec, &ws) {
            limits_phase(body, state, &mut limits, &mut ws);
        }
    }
}

/// Contact system: anchors and per-link peak force, impulse, penetration.
pub fn contact_system(
    mut q: Query<(
        &BodyModel,
        &JointState,
        &Recorder,
        &mut ContactComponent,
        &mut DamageRecord,
        &mut Workspace,
    )>,
) {
    for (body, state, rec, mut contact, mut damage, mut ws) in &mut q {
        if running(state, rec, &ws) {
            contact_phase(body, state, &mut contact, &mut damage, rec.dt, &mut ws);
        }
    }
}

/// Dynamics-step system: integrates one step; an error stops the character.
pub fn step_system(
    mut q: Query<(
        &BodyModel,
        &mut JointState,
        &PdController,
        &JointLimits,
        &ContactComponent,
        &Recorder,
        &mut Workspace,
    )>,
) {
    for (body, mut state, pd, limits, contact, rec, mut ws) in &mut q {
        if running(&state, rec, &ws)
            && let Err(e) = dynamics_phase(body, &mut state, pd, limits, contact, rec, &mut ws)
        {
            ws.error = Some(Arc::new(e));
        }
    }
}

/// Record system: frames, rest detection and divergence checks after the step.
pub fn record_system(mut q: Query<(&BodyModel, &JointState, &mut Recorder, &mut Workspace)>) {
    for (body, state, mut rec, mut ws) in &mut q {
        // The step has been taken: `steps` counts it, so record while no error is set.
        if ws.error.is_none()
            && state.steps > 0
            && let Err(e) = record_phase(body, state, &mut rec, &mut ws)
        {
            ws.error = Some(Arc::new(e));
        }
    }
}

/// The schedule of one fall step with its sets chained in order.
pub fn fall_schedule() -> Schedule {
    let mut s = Schedule::default();
    s.configure_sets(
        (
            FallSet::Control,
            FallSet::Limits,
            FallSet::Contact,
            FallSet::Step,
            FallSet::Record,
        )
            .chain(),
    );
    s.add_systems((
        control_system.in_set(FallSet::Control),
        limits_system.in_set(FallSet::Limits),
        contact_system.in_set(FallSet::Contact),
        step_system.in_set(FallSet::Step),
        record_system.in_set(FallSet::Record),
    ));
    s
}

/// Spawns one falling character's components into `world`.
pub fn spawn_fall(world: &mut World, mut parts: FallParts) -> Entity {
    record_initial(&mut parts);
    let FallParts {
        body,
        state,
        pd,
        limits,
        contact,
        damage,
        recorder,
        ws,
    } = parts;
    world
        .spawn((body, state, pd, limits, contact, damage, recorder, ws))
        .id()
}

/// A World holding the character of `config` (validated and stability-checked).
pub fn build_fall_world(config: &FallConfig) -> Result<World, SimError> {
    let parts = build_fall(config)?;
    let mut world = World::new();
    spawn_fall(&mut world, parts);
    Ok(world)
}

/// Runs the fall schedule until every character in `world` has finished or failed; returns the
/// result of each character in spawn order.
pub fn run_world(world: &mut World) -> Vec<Result<FallResult, Arc<SimError>>> {
    let mut schedule = fall_schedule();
    loop {
        let mut q = world.query::<(&JointState, &Recorder, &Workspace)>();
        if !q.iter(world).any(|(s, r, w)| running(s, r, w)) {
            break;
        }
        schedule.run(world);
    }
    let mut q = world.query::<(
        Entity,
        &BodyModel,
        &JointState,
        &JointLimits,
        &DamageRecord,
        &Recorder,
        &Workspace,
    )>();
    let mut out: Vec<(Entity, Result<FallResult, Arc<SimError>>)> = q
        .iter(world)
        .map(|(e, body, state, limits, damage, recorder, ws)| {
            let r = match &ws.error {
                Some(err) => Err(err.clone()),
                None => Ok(finish(body, state, limits, damage, recorder)),
            };
            (e, r)
        })
        .collect();
    out.sort_by_key(|(e, _)| e.index());
    out.into_iter().map(|(_, r)| r).collect()
}

/// Simulates each configuration in its own World, in parallel on the current rayon pool; the
/// results are in input order and do not depend on the number of threads.
pub fn run_parallel(configs: &[FallConfig]) -> Vec<Result<FallResult, Arc<SimError>>> {
    configs
        .par_iter()
        .map(|c| {
            let mut world = build_fall_world(c).map_err(Arc::new)?;
            run_world(&mut world).pop().unwrap_or_else(|| {
                Err(Arc::new(SimError::Config {
                    field: "world".into(),
                    message: "no character".into(),
                }))
            })
        })
        .collect()
}
