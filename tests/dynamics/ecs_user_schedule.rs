//! A user's own schedule, as a game would build it: one World, one Schedule made with the
//! engine's `add_*_systems` helpers, a kinematic character playing a learned primitive and a
//! physical character being pushed, and the user's own set ordered between the engine's sets
//! (it adds a second push through the component the step reads). Both advance on the one clock
//! and both are recorded and drawn by the same motion systems.

use std::path::PathBuf;
use std::sync::Arc;

use bevy_ecs::prelude::*;
use glam::DVec3;
use marionette::clips::KeyframeClip;
use marionette::dynamics::forces::external::ExternalForce;
use marionette::ecs::human::{HumanFigure, add_human_physics_systems, drawn_body};
use marionette::ecs::physics::{BodyState, ExternalForces};
use marionette::ecs::primitive::{PrimitivePlayer, add_primitive_systems};
use marionette::ecs::{
    Clock, MotionSet, Recorder, SkeletonRef, add_core_systems, add_motion_systems,
    spawn_primitive_character,
};
use marionette::experiments::fall::{FallConfig, build_fall};
use marionette::experiments::fall::{add_fall_systems, fall_results, spawn_fall};
use marionette::humanoid::AgeGroup;
use marionette::humanoid::{HumanBody, humanoid24};
use marionette::primitive::{LearnConfig, Primitive};
use marionette::render::{StickFigure, Track, filmstrip_png};

const TICK: f64 = 1.0 / 120.0;
const SUBSTEPS: u32 = 16;
const TICKS: usize = 180;

/// The user's own set, between the engine's animation and control.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct GameplaySet;

/// What the user's system saw at each run: the player's elapsed time and the body's time.
#[derive(Resource, Default)]
struct Seen(Vec<(u64, f64, f64)>);

/// Marks the character the game hits.
#[derive(Component)]
struct Target;

/// The user's gameplay system: logs what it sees, and at 0.5 s hits the target from the side
/// by adding a force to the component the physics step reads.
fn gameplay(
    clock: Res<Clock>,
    mut seen: ResMut<Seen>,
    players: Query<&PrimitivePlayer>,
    mut bodies: Query<(&BodyState, &HumanFigure, &mut ExternalForces), With<Target>>,
) {
    let elapsed = players.iter().next().map_or(f64::NAN, |p| p.elapsed());
    for (state, human, mut forces) in &mut bodies {
        seen.0.push((clock.tick, elapsed, state.time_s));
        if clock.tick == 60 {
            let torso = human.link_index("torso").unwrap();
            forces.push(ExternalForce {
                body: torso,
                point: DVec3::new(0.0, 0.2, 0.0),
                force: DVec3::new(400.0, 0.0, 0.0),
                torque: DVec3::ZERO,
                start_s: state.time_s,
                duration_s: 0.1,
            });
        }
    }
}

fn jump_primitive() -> Primitive {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/clips/normal_jump.ron");
    let clip = KeyframeClip::load(&path).unwrap().to_figure_clip();
    Primitive::learn("jump", &clip.to_trajectory(), &LearnConfig::default())
        .unwrap()
        .primitive
}

/// Builds the World and the user's schedule; `hit` says whether the gameplay system runs.
fn world_and_schedule(hit: bool) -> (World, Schedule, Entity, Entity) {
    let clock = Clock::new(TICK, SUBSTEPS);
    let mut world = World::new();
    world.insert_resource(clock);
    world.insert_resource(Seen::default());

    let jumper = spawn_primitive_character(
        &mut world,
        "jumper",
        Arc::new(humanoid24()),
        vec![Arc::new(jump_primitive())],
    )
    .unwrap();

    let mut cfg = FallConfig::paper(AgeGroup::Elderly);
    cfg.dt_s = clock.physics_dt();
    cfg.duration_s = TICKS as f64 * TICK;
    let faller = build_fall(&cfg).unwrap();
    let body: Arc<HumanBody> = faller.human.0.clone();
    let faller = spawn_fall(&mut world, faller).unwrap();
    world
        .entity_mut(faller)
        .insert((drawn_body("faller", &body), Target));

    let mut schedule = Schedule::default();
    add_core_systems(&mut schedule);
    add_motion_systems(&mut schedule);
    add_primitive_systems(&mut schedule);
    add_human_physics_systems(&mut schedule);
    add_fall_systems(&mut schedule);
    schedule.configure_sets(
        GameplaySet
            .after(MotionSet::Animate)
            .before(MotionSet::Control),
    );
    if hit {
        schedule.add_systems(gameplay.in_set(GameplaySet));
    }
    (world, schedule, jumper, faller)
}

#[test]
fn a_kinematic_and_a_physical_character_share_one_schedule_and_one_clock() {
    let (mut world, mut schedule, jumper, faller) = world_and_schedule(true);
    for _ in 0..TICKS {
        schedule.run(&mut world);
    }

    // One clock: the tick count, the player's time and the body's time agree.
    let clock = *world.resource::<Clock>();
    assert_eq!(clock.tick, TICKS as u64);
    let elapsed = world.get::<PrimitivePlayer>(jumper).unwrap().elapsed();
    let body_time = world.get::<BodyState>(faller).unwrap().time_s;
    let t = TICKS as f64 * TICK;
    assert!(
        (elapsed - t).abs() < 1e-9,
        "player at {elapsed} s, clock {t} s"
    );
    assert!(
        (body_time - t).abs() < 1e-9,
        "body at {body_time} s, clock {t} s"
    );
    assert_eq!(
        world.get::<BodyState>(faller).unwrap().steps,
        (TICKS as u64) * SUBSTEPS as u64
    );

    // The user's set ran after the players advanced and before physics stepped, every tick.
    let seen = &world.resource::<Seen>().0;
    assert_eq!(seen.len(), TICKS);
    for &(tick, elapsed, body_t) in seen {
        let start = tick as f64 * TICK;
        assert!(
            (elapsed - (start + TICK)).abs() < 1e-9,
            "tick {tick}: player {elapsed}"
        );
        assert!((body_t - start).abs() < 1e-9, "tick {tick}: body {body_t}");
    }

    // Both are recorded by the same recorder, one frame per tick.
    let rec_jumper = world.get::<Recorder>(jumper).unwrap().frames.clone();
    let rec_faller = world.get::<Recorder>(faller).unwrap().frames.clone();
    assert_eq!(rec_jumper.len(), TICKS);
    assert_eq!(rec_faller.len(), TICKS);

    // The recorded pelvis of the faller is the simulated one.
    let q = &world.get::<BodyState>(faller).unwrap().q;
    let pelvis = rec_faller.last().unwrap()[0];
    assert!((pelvis - DVec3::new(q[0], q[1], q[2])).length() < 1e-12);
    // The pushed figure falls: its head ends far below where it stood.
    let head_y = |f: &Vec<DVec3>| f.iter().map(|p| p.y).fold(f64::MIN, f64::max);
    let (top0, top1) = (head_y(&rec_faller[0]), head_y(rec_faller.last().unwrap()));
    assert!(top0 > 1.4 && top1 < 0.8, "top point {top0} m → {top1} m");
    // The jumper jumps: its pelvis rises above the standing height during the clip.
    let pelvis_y: Vec<f64> = rec_jumper.iter().map(|f| f[0].y).collect();
    let apex = pelvis_y.iter().cloned().fold(f64::MIN, f64::max);
    assert!(
        apex > pelvis_y[0] + 0.1,
        "pelvis {} → apex {apex}",
        pelvis_y[0]
    );

    // The game's push is a force the body feels: without it the fall is different.
    let (mut w2, mut s2, _, f2) = world_and_schedule(false);
    for _ in 0..TICKS {
        s2.run(&mut w2);
    }
    let q2 = &w2.get::<BodyState>(f2).unwrap().q;
    assert!(
        (q[0] - q2[0]).abs() > 1e-3,
        "the side push moved the pelvis sideways by {} m",
        q[0] - q2[0]
    );
    let results = fall_results(&mut world);
    assert_eq!(results.len(), 1);
    assert!(results[0].as_ref().unwrap().damage > 0.0);

    // Both are drawn from their recordings.
    let fig_j = StickFigure::of(&world.get::<SkeletonRef>(jumper).unwrap().0);
    let fig_f = StickFigure::of(&world.get::<SkeletonRef>(faller).unwrap().0);
    let tracks = [
        Track {
            figure: &fig_j,
            frames: &rec_jumper,
            label: "jumper (primitive)".into(),
            frame_time: TICK,
        },
        Track {
            figure: &fig_f,
            frames: &rec_faller,
            label: "faller (physics)".into(),
            frame_time: TICK,
        },
    ];
    // MARIONETTE_TEST_OUT=DIR keeps the picture for a look.
    let keep = std::env::var_os("MARIONETTE_TEST_OUT").map(PathBuf::from);
    let dir = keep.clone().unwrap_or_else(std::env::temp_dir);
    let out = dir.join(format!("user_schedule_{}.png", std::process::id()));
    filmstrip_png(&tracks, 6, &out).unwrap();
    let size = std::fs::metadata(&out).unwrap().len();
    assert!(size > 10_000, "filmstrip of {size} bytes");
    if keep.is_none() {
        std::fs::remove_file(&out).ok();
    }
}
