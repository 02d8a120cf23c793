//! The pushed fall in a World: a falling character is the physics components of
//! [`crate::ecs::physics`] (stepped by the engine's physics systems) plus the paper's
//! [`FallController`] (in [`MotionSet::Control`]) and a [`FallRecorder`] (in
//! [`MotionSet::Record`]), which stops the body once its run is over. A World runs its falls
//! with its [`Clock`] ticking one physics step. Many falls run in parallel in a [`WorldPool`]
//! of one World per thread, each holding up to [`LANES`] falls at a time (their
//! articulated-body algorithms then share vector lanes, [`crate::ecs::physics::step_bodies`])
//! and taking the next fall as one finishes, from its own share of the batch and then from the
//! others'; every fall has the bits it has alone in its own World, on any number of threads.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use bevy_ecs::prelude::*;

use super::{FallCharacter, FallConfig, FallController, FallRecorder, FallResult, SimError};
use crate::dynamics::LANES;
use crate::dynamics::ModelError;
use crate::dynamics::StiffnessBasis;
use crate::ecs::human::{HumanFigure, add_human_physics_systems};
use crate::ecs::physics::{
    BodyState, ExternalForces, FloorContact, JointLimits, PdController, PhysicsBody,
    PhysicsMonitor, PhysicsStatus, PhysicsWorkspace,
};
use crate::ecs::{Clock, MotionSet, WorldPool, WorldSeed, add_core_systems, configure_motion_sets};

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
        &HumanFigure,
        &BodyState,
        &mut PhysicsWorkspace,
        &PhysicsMonitor,
        &mut FallRecorder,
        &mut PhysicsStatus,
    )>,
) {
    for (human, state, mut ws, monitor, mut recorder, mut status) in &mut q {
        if status.error.is_some() {
            continue;
        }
        let b = &**human;
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
    add_human_physics_systems(&mut s);
    add_fall_systems(&mut s);
    s
}

/// Spawns one falling character into `world` and records its first frame. The World's
/// [`Clock`] must step physics by the fall's `dt_s`.
pub fn spawn_fall(world: &mut World, mut ch: FallCharacter) -> Result<Entity, SimError> {
    check_clock(world, &ch)?;
    let p = &mut ch.physics;
    let b = &*ch.human;
    let data = p.workspace.kinematics_of(&b.model, &p.state);
    ch.recorder.record(b, &p.state, data, &p.monitor);
    if ch.recorder.finished(&p.state) {
        p.status.stopped = true;
    }
    Ok(spawn_components(world, ch))
}

/// The character's components as one entity.
fn spawn_components(world: &mut World, ch: FallCharacter) -> Entity {
    world
        .spawn((
            ch.physics,
            ch.human,
            ch.pd,
            ch.limits,
            ch.contact,
            ch.external,
            ch.controller,
            ch.recorder,
        ))
        .id()
}

/// The components of the falling character `e` of `world`, cloned.
fn character_of(world: &World, e: Entity) -> Option<FallCharacter> {
    Some(FallCharacter {
        physics: crate::ecs::physics::PhysicsBundle {
            body: world.get::<PhysicsBody>(e)?.clone(),
            state: world.get::<BodyState>(e)?.clone(),
            workspace: world.get::<PhysicsWorkspace>(e)?.clone(),
            monitor: world.get::<PhysicsMonitor>(e)?.clone(),
            status: world.get::<PhysicsStatus>(e)?.clone(),
        },
        human: world.get::<HumanFigure>(e)?.clone(),
        pd: world.get::<PdController>(e)?.clone(),
        limits: world.get::<JointLimits>(e)?.clone(),
        contact: world.get::<FloorContact>(e)?.clone(),
        external: world.get::<ExternalForces>(e)?.clone(),
        controller: world.get::<FallController>(e)?.clone(),
        recorder: world.get::<FallRecorder>(e)?.clone(),
    })
}

/// A fall run in its World up to its reaction time (`control_start_s`): before it, the body
/// stands, is pushed and is held by the stance gains, none of which depends on the reaction
/// (key pose, k_p, k_v), so the falls of a GA's population share that stretch. Each fall
/// continues from a copy of the whole World state (components and clock) with its own
/// reaction: the same bits as running it from the start, without the 0.25 s (some 360 steps at
/// the GA's 0.70 ms) before the reaction.
#[derive(Clone, Debug)]
pub struct ReactionStart {
    /// The configuration it was run for, the reaction's fields normalised.
    key: FallConfig,
    /// The character assembled standing, before settling (the stability check of each
    /// reaction's gains is made on it, as [`super::build_fall`] does).
    standing: FallCharacter,
    /// What the stability check of every reaction finds on `standing` independently of the
    /// gains, found once (or why it could not be).
    stiffness: Result<StiffnessBasis, ModelError>,
    /// The character at the reaction time.
    reacting: FallCharacter,
    /// The World's clock at the reaction time.
    clock: Clock,
}

impl ReactionStart {
    /// Runs `cfg` in a World until its reaction time (the standing start taken from `settled`
    /// where it fits).
    pub fn of(cfg: &FallConfig, settled: Option<&super::SettledStart>) -> Result<Self, SimError> {
        let standing = super::assemble(cfg)?;
        let ch = super::build_fall_from(cfg, settled)?;
        let mut world = World::new();
        world.insert_resource(Clock::physics(cfg.dt_s));
        let e = spawn_fall(&mut world, ch)?;
        let mut schedule = fall_schedule();
        // The controller switches in the first run whose state starts at or past the reaction
        // time; stop just before that run.
        while world
            .get::<PhysicsStatus>(e)
            .is_some_and(PhysicsStatus::running)
            && world
                .get::<BodyState>(e)
                .is_some_and(|s| s.time_s < cfg.control_start_s)
        {
            schedule.run(&mut world);
        }
        let missing = || SimError::Config {
            field: "world".into(),
            message: "the fall's components went missing".into(),
        };
        Ok(Self {
            key: super::reaction_key(cfg),
            stiffness: super::stiffness_basis(cfg, &standing),
            standing,
            reacting: character_of(&world, e).ok_or_else(missing)?,
            clock: *world.get_resource::<Clock>().ok_or_else(missing)?,
        })
    }

    /// True when `cfg` differs from the configuration this start was run for in its reaction
    /// (key pose, k_p, k_v) at most.
    pub fn fits(&self, cfg: &FallConfig) -> bool {
        self.key == super::reaction_key(cfg)
    }

    /// Spawns the fall of `cfg` (which must fit) at its reaction time into `world`, setting the
    /// World's clock: its reaction validated and stability-checked as [`super::build_fall`]
    /// does, the rest copied.
    pub fn spawn(&self, world: &mut World, cfg: &FallConfig) -> Result<Entity, SimError> {
        world.insert_resource(self.clock);
        self.spawn_keeping_clock(world, cfg)
    }

    /// [`Self::spawn`] into a World whose clock already steps physics by the fall's step
    /// (e.g. one running other falls), leaving the clock as it is: a body's time is its own
    /// state's.
    pub fn spawn_keeping_clock(
        &self,
        world: &mut World,
        cfg: &FallConfig,
    ) -> Result<Entity, SimError> {
        super::validate_reaction(cfg, self.standing.physics.body.dofs.len())?;
        super::check_stability_with(cfg, &self.standing, &self.stiffness)?;
        let mut ch = self.reacting.clone();
        ch.controller.key = super::key_targets(cfg);
        check_clock(world, &ch)?;
        Ok(spawn_components(world, ch))
    }
}

fn check_clock(world: &World, ch: &FallCharacter) -> Result<(), SimError> {
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
    Ok(())
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
        &HumanFigure,
        &BodyState,
        &PhysicsMonitor,
        &FallRecorder,
        &PhysicsStatus,
    )>();
    let mut out: Vec<(Entity, Result<FallResult, Arc<SimError>>)> = q
        .iter(world)
        .map(|(e, human, state, monitor, recorder, status)| {
            (e, result_of(human, state, monitor, recorder, status))
        })
        .collect();
    out.sort_by_key(|(e, _)| e.index());
    out.into_iter().map(|(_, r)| r).collect()
}

/// The result of one falling body from its components.
fn result_of(
    human: &HumanFigure,
    state: &BodyState,
    monitor: &PhysicsMonitor,
    recorder: &FallRecorder,
    status: &PhysicsStatus,
) -> Result<FallResult, Arc<SimError>> {
    match &status.error {
        Some(err) => Err(Arc::new(SimError::Step((**err).clone()))),
        None => Ok(recorder.result(human, state, monitor)),
    }
}

/// The result of the falling body `e` of `world` once it no longer runs (finished or failed),
/// the body then despawned; `None` while it runs.
fn take_finished(world: &mut World, e: Entity) -> Option<Result<FallResult, Arc<SimError>>> {
    let r = {
        let status = world.get::<PhysicsStatus>(e)?;
        if status.running() {
            return None;
        }
        let parts = (
            world.get::<HumanFigure>(e),
            world.get::<BodyState>(e),
            world.get::<PhysicsMonitor>(e),
            world.get::<FallRecorder>(e),
        );
        match parts {
            (Some(human), Some(state), Some(monitor), Some(recorder)) => {
                result_of(human, state, monitor, recorder, status)
            }
            _ => Err(Arc::new(SimError::Config {
                field: "world".into(),
                message: "a fall's components went missing".into(),
            })),
        }
    };
    world.despawn(e);
    Some(r)
}

/// Simulates the configurations in the Worlds of a [`WorldPool`], in parallel on the current
/// rayon pool; the results are in input order and do not depend on the number of threads.
///
/// One World per thread runs up to [`LANES`] falls at a time (of one time step and start, see
/// [`run_parallel_reacting`]), so that the engine's step takes their articulated-body
/// algorithm in vector lanes ([`crate::ecs::physics::step_bodies`]), and takes the next fall
/// as one finishes, from its own share of the batch and then from the others'; each fall has
/// the bits it has alone in its own World.
pub fn run_parallel(configs: &[FallConfig]) -> Vec<Result<FallResult, Arc<SimError>>> {
    run_parallel_from(configs, None)
}

/// [`run_parallel`] with the falls' settled standing start taken from `start` where it fits
/// (see [`super::SettledStart`]): the same results, without settling each fall anew.
pub fn run_parallel_from(
    configs: &[FallConfig],
    start: Option<&super::SettledStart>,
) -> Vec<Result<FallResult, Arc<SimError>>> {
    run_parallel_reacting(configs, start, None)
}

/// [`run_parallel_from`] with every fall that fits `reaction` continued from it (see
/// [`ReactionStart`]): the same results, without each fall's stretch before its reaction.
pub fn run_parallel_reacting(
    configs: &[FallConfig],
    start: Option<&super::SettledStart>,
    reaction: Option<&ReactionStart>,
) -> Vec<Result<FallResult, Arc<SimError>>> {
    run_parallel_until(configs, start, reaction, &AtomicBool::new(false)).expect("never stopped")
}

/// [`run_parallel_reacting`] that gives up as soon as `stop` is set (checked before every
/// step of every World): `None` then, else every fall's result.
pub fn run_parallel_until(
    configs: &[FallConfig],
    start: Option<&super::SettledStart>,
    reaction: Option<&ReactionStart>,
    stop: &AtomicBool,
) -> Option<Vec<Result<FallResult, Arc<SimError>>>> {
    let fits = |k: usize| reaction.is_some_and(|r| r.fits(&configs[k]));
    // Falls of one time step and start share Worlds (one clock); usually there is one kind.
    let mut kinds: Vec<((u64, bool), Vec<usize>)> = Vec::new();
    for (k, c) in configs.iter().enumerate() {
        let key = (c.dt_s.to_bits(), fits(k));
        match kinds.iter_mut().find(|(kk, _)| *kk == key) {
            Some((_, v)) => v.push(k),
            None => kinds.push((key, vec![k])),
        }
    }
    let mut out: Vec<Option<Result<FallResult, Arc<SimError>>>> = vec![None; configs.len()];
    for ((_, reacting), members) in kinds {
        let dt = configs[members[0]].dt_s;
        let workers = rayon::current_num_threads().clamp(1, members.len());
        let pool = WorldPool::new(workers, 0, |_, world| {
            world.insert_resource(Clock::physics(dt));
            Ok::<(), std::convert::Infallible>(())
        });
        let mut pool = match pool {
            Ok(p) => p,
            Err(never) => match never {},
        };
        let queue = FallQueue::new(members.len(), workers);
        let spawn = |world: &mut World, k: usize| match reaction {
            Some(r) if reacting => r.spawn_keeping_clock(world, &configs[k]),
            _ => super::build_fall_from(&configs[k], start).and_then(|ch| spawn_fall(world, ch)),
        };
        for (k, r) in pool
            .run(|w| {
                let own = w.get_resource::<WorldSeed>().map_or(0, |s| s.index);
                run_queue(w, &members, &|| queue.take(own), &spawn, stop)
            })
            .into_iter()
            .flatten()
        {
            out[k] = Some(r);
        }
        if stop.load(Ordering::Relaxed) {
            return None;
        }
    }
    let out = out
        .into_iter()
        .map(|r| {
            r.unwrap_or_else(|| {
                Err(Arc::new(SimError::Config {
                    field: "world".into(),
                    message: "a fall was not run".into(),
                }))
            })
        })
        .collect();
    Some(out)
}

/// The falls of a batch shared among the Worlds of a pool: each World has its own share (the
/// batch split into as many near-equal runs as Worlds, so equal falls end together) and takes
/// from its front; a World whose share is done takes from the back of the share with the most
/// left, so none waits while another still has falls to start.
struct FallQueue {
    /// Per World, the positions of its share not yet started.
    shares: Vec<Mutex<std::ops::Range<usize>>>,
}

impl FallQueue {
    /// `n` falls over `workers` Worlds.
    fn new(n: usize, workers: usize) -> Self {
        let workers = workers.max(1);
        let (base, extra) = (n / workers, n % workers);
        let mut start = 0;
        let shares = (0..workers)
            .map(|w| {
                let len = base + usize::from(w < extra);
                let r = start..start + len;
                start += len;
                Mutex::new(r)
            })
            .collect();
        Self { shares }
    }

    /// The next fall position for World `own`, if any is left.
    fn take(&self, own: usize) -> Option<usize> {
        fn lock(
            m: &Mutex<std::ops::Range<usize>>,
        ) -> std::sync::MutexGuard<'_, std::ops::Range<usize>> {
            m.lock().unwrap_or_else(|e| e.into_inner())
        }
        if let Some(m) = self.shares.get(own)
            && let Some(k) = lock(m).next()
        {
            return Some(k);
        }
        let longest = self.shares.iter().max_by_key(|m| lock(m).len())?;
        lock(longest).next_back()
    }
}

/// Runs falls of `members` in `world`, up to [`LANES`] at a time, the position of each next
/// one in `members` from `take` as a fall finishes (so the Worlds of a pool stay busy while
/// falls are left); returns each fall's input index and result. A fall's result does not
/// depend on which World or with which others it ran.
fn run_queue(
    world: &mut World,
    members: &[usize],
    take: &impl Fn() -> Option<usize>,
    spawn: &(impl Fn(&mut World, usize) -> Result<Entity, SimError> + Sync),
    stop: &AtomicBool,
) -> Vec<(usize, Result<FallResult, Arc<SimError>>)> {
    let mut schedule = fall_schedule();
    let mut live: Vec<(usize, Entity)> = Vec::with_capacity(LANES);
    let mut out = Vec::new();
    loop {
        if stop.load(Ordering::Relaxed) {
            // Given up: what is left in the World is dropped with it.
            return out;
        }
        while live.len() < LANES {
            let Some(&k) = take().and_then(|j| members.get(j)) else {
                break;
            };
            match spawn(world, k) {
                Ok(e) => live.push((k, e)),
                Err(e) => out.push((k, Err(Arc::new(e)))),
            }
        }
        if live.is_empty() {
            return out;
        }
        let before = live.len();
        live.retain(|&(k, e)| match take_finished(world, e) {
            Some(r) => {
                out.push((k, r));
                false
            }
            None => true,
        });
        // A finished fall frees its lane for the next before the World steps again.
        if live.len() == before {
            schedule.run(world);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::fall::SettledStart;

    /// The paper's elderly fall, stopped at rest, with reactions that differ per fall.
    fn reactions() -> (FallConfig, Vec<FallConfig>) {
        let base = FallConfig {
            stop_at_rest: true,
            duration_s: 1.5,
            ..FallConfig::default()
        };
        let n = base.kp.len();
        let configs = (0..4)
            .map(|k| {
                let mut c = base.clone();
                for d in 0..n {
                    c.key_pose_deg[d] += [0.0, 20.0, -15.0, 35.0][k] * ((d % 3) as f64 - 1.0);
                    c.kp[d] *= [1.0, 0.3, 2.0, 0.05][k];
                    c.kv[d] *= [1.0, 2.0, 0.5, 1.0][k];
                }
                c
            })
            .collect();
        (base, configs)
    }

    #[test]
    fn falls_continued_from_the_reaction_time_are_the_falls_run_from_the_start() {
        let (base, mut configs) = reactions();
        let settled = SettledStart::of(&base).unwrap();
        let reaction = ReactionStart::of(&base, Some(&settled)).unwrap();
        assert!(configs.iter().all(|c| reaction.fits(c)));
        // The shared stretch ends at the reaction time, after the push began.
        let t = reaction.reacting.physics.state.time_s;
        assert!(t >= base.control_start_s && t < base.control_start_s + base.dt_s);
        assert!(!reaction.reacting.controller.reacting);
        // Two reactions it cannot take, refused as building them would refuse them.
        let mut negative = configs[0].clone();
        negative.kp[3] = -1.0;
        let mut too_stiff = configs[0].clone();
        too_stiff.kp.iter_mut().for_each(|k| *k = 1e9);
        configs.extend([negative, too_stiff]);
        let from_start = run_parallel_from(&configs, Some(&settled));
        let continued = run_parallel_reacting(&configs, Some(&settled), Some(&reaction));
        assert_eq!(from_start.len(), continued.len());
        for (a, b) in from_start.iter().zip(&continued) {
            match (a, b) {
                (Ok(x), Ok(y)) => assert_eq!(x, y),
                (Err(x), Err(y)) => assert_eq!(x.to_string(), y.to_string()),
                _ => panic!("{a:?} against {b:?}"),
            }
        }
        assert!(continued[..4].iter().all(|r| r.is_ok()));
        assert!(
            continued[4]
                .as_ref()
                .unwrap_err()
                .to_string()
                .contains("kp")
        );
        assert!(continued[5].is_err());
        // A fall that differs before the reaction does not fit and runs from its start.
        let mut pushed_harder = configs[0].clone();
        pushed_harder.push.force_n *= 1.5;
        assert!(!reaction.fits(&pushed_harder));
        let alone = run_parallel_from(std::slice::from_ref(&pushed_harder), Some(&settled));
        let mixed = run_parallel_reacting(&[pushed_harder], Some(&settled), Some(&reaction));
        assert_eq!(alone[0].as_ref().unwrap(), mixed[0].as_ref().unwrap());
        assert_ne!(alone[0].as_ref().unwrap(), from_start[0].as_ref().unwrap());
    }

    #[test]
    fn falls_that_share_worlds_have_the_results_of_falls_alone() {
        // Seven falls (more than the lanes of one World; reactions that rest at different
        // times, one that cannot be built) through the pool on 1 and 2 threads, against each
        // fall alone in its own World: the same results, in input order.
        let (_, mut configs) = reactions();
        let mut more = configs.clone();
        for (k, c) in more.iter_mut().enumerate().take(2) {
            c.key_pose_deg
                .iter_mut()
                .for_each(|x| *x = -*x * (k as f64 + 0.5));
        }
        configs.extend(more.into_iter().take(2));
        let mut negative = configs[0].clone();
        negative.kp[3] = -1.0;
        configs.insert(2, negative);
        let alone: Vec<_> = configs
            .iter()
            .map(|c| build_fall_world(c).map(|mut w| run_fall_world(&mut w).remove(0)))
            .collect();
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let shared = pool.install(|| run_parallel(&configs));
            assert_eq!(shared.len(), configs.len());
            for (k, (a, b)) in alone.iter().zip(&shared).enumerate() {
                match (a, b) {
                    (Ok(Ok(x)), Ok(y)) => assert_eq!(x, y, "fall {k} on {threads} threads"),
                    (Err(x), Err(y)) => assert_eq!(x.to_string(), y.to_string()),
                    _ => panic!("fall {k}: {a:?} against {b:?}"),
                }
            }
        }
        let steps: Vec<u64> = alone
            .iter()
            .filter_map(|r| r.as_ref().ok()?.as_ref().ok().map(|f| f.steps))
            .collect();
        assert_eq!(steps.len(), 6);
        assert!(
            steps.iter().any(|&s| s != steps[0]),
            "every fall as long: {steps:?}"
        );
    }
}
