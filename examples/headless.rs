//! A headless Bevy app (feature `bevy`): two physical characters play the project's keyframed
//! jump as a learned primitive under PD control with root assistance; one is pushed (1000 N on the chest for 0.1 s) at 0.3 s
//! and released 0.1 s later. The app runs on `ScheduleRunnerPlugin`, advances by the engine's
//! clock through `MarionettePlugin` and exits by itself; it then runs the same two characters in
//! a plain World and checks that the pelvis positions agree to 1e-9 m, and that the published
//! joint transforms are the joints' positions.
//!
//!     cargo run --release --example headless --features bevy

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use bevy_app::{App, AppExit, ScheduleRunnerPlugin, Update};
use bevy_ecs::prelude::*;
use bevy_transform::components::Transform;
use glam::DVec3;
use marionette::bevy::{JointEntities, MarionettePlugin, spawn_joint_entities};
use marionette::clips::KeyframeClip;
use marionette::dynamics::forces::external::Push;
use marionette::ecs::character::{
    PhysicalSettings, Reaction, character_schedule, spawn_physical_character,
};
use marionette::ecs::human::HumanFigure;
use marionette::ecs::physics::{BodyState, ExternalForces};
use marionette::ecs::{Clock, JointState, new_world, run_ticks};
use marionette::humanoid::humanoid24_body;
use marionette::primitive::{LearnConfig, Primitive};

const DT: f64 = 5e-4;
const TICKS: u64 = 5000;
const PER_UPDATE: u32 = 50;

fn jump() -> Arc<Primitive> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/clips/normal_jump.ron");
    let clip = KeyframeClip::load(&path)
        .expect("scenes/clips/normal_jump.ron")
        .to_figure_clip();
    Arc::new(
        Primitive::learn("jump", &clip.to_trajectory(), &LearnConfig::default())
            .expect("learn the jump")
            .primitive,
    )
}

/// Spawns the two characters (the second pushed); returns their entities.
fn spawn_pair(world: &mut World, jump: &Arc<Primitive>) -> [Entity; 2] {
    let body = Arc::new(humanoid24_body(1.70, 65.0, 9.81).expect("humanoid24 body"));
    let mut out = [Entity::PLACEHOLDER; 2];
    for (k, name) in ["steady", "pushed"].iter().enumerate() {
        let reaction = Reaction {
            release_delay_s: (k == 1).then_some(0.1),
            ..Reaction::default()
        };
        let e = spawn_physical_character(
            world,
            name,
            body.clone(),
            vec![jump.clone()],
            &PhysicalSettings::default(),
            reaction,
        )
        .expect("spawn");
        if k == 1 {
            let push = Push {
                link: "chest".into(),
                point: DVec3::new(0.0, 0.25, 0.0),
                direction: DVec3::new(0.0, 0.0, -1.0),
                force_n: 1000.0,
                start_s: 0.3,
                duration_s: 0.1,
            };
            let link = body.link_index("chest").expect("chest");
            world
                .get_mut::<ExternalForces>(e)
                .expect("forces")
                .push(push.to_force(link));
        }
        out[k] = e;
    }
    out
}

/// What the check at the end needs: the two characters and the primitive they play.
#[derive(Resource)]
struct Pair {
    entities: [Entity; 2],
    jump: Arc<Primitive>,
}

/// After `TICKS` engine ticks: prints what happened, checks the app against a plain World and
/// exits (with an error code if a check fails).
fn finish(world: &mut World) {
    let tick = world.resource::<Clock>().tick;
    if tick < TICKS {
        return;
    }
    let ok = report(world, tick);
    world.write_message(if ok {
        AppExit::Success
    } else {
        AppExit::error()
    });
}

fn pelvis(world: &World, e: Entity) -> DVec3 {
    let q = &world.get::<BodyState>(e).expect("state").q;
    DVec3::new(q[0], q[1], q[2])
}

fn main() {
    let jump = jump();
    let mut app = App::new();
    app.add_plugins(ScheduleRunnerPlugin::run_loop(Duration::ZERO))
        .add_plugins(MarionettePlugin {
            clock: Clock::physics(DT),
            ticks_per_update: PER_UPDATE,
        })
        .add_systems(Update, finish);
    let pair = spawn_pair(app.world_mut(), &jump);
    for e in pair {
        spawn_joint_entities(app.world_mut(), e);
    }
    app.insert_resource(Pair {
        entities: pair,
        jump,
    });
    let exit = app.run();
    if exit.is_error() {
        eprintln!("headless example: check failed");
        std::process::exit(1);
    }
}

/// Prints what happened in the app and checks it; true when every check holds.
fn report(world: &World, tick: u64) -> bool {
    let Pair {
        entities: pair,
        jump,
    } = world.resource::<Pair>();
    let pair = *pair;
    println!(
        "bevy app: {tick} engine ticks ({:.2} s) on FixedUpdate",
        tick as f64 * DT
    );
    // The same characters in a plain World with the engine's own schedule.
    let mut plain = new_world(Clock::physics(DT));
    let plain_pair = spawn_pair(&mut plain, jump);
    run_ticks(&mut plain, &mut character_schedule(), tick as usize);
    let mut worst = 0.0f64;
    for (k, (&a, &b)) in pair.iter().zip(&plain_pair).enumerate() {
        let (pa, pb) = (pelvis(world, a), pelvis(&plain, b));
        worst = worst.max((pa - pb).length());
        let name = ["steady", "pushed"][k];
        println!(
            "{name}: pelvis at ({:.3}, {:.3}, {:.3}) m, plain World ({:.3}, {:.3}, {:.3}) m",
            pa.x, pa.y, pa.z, pb.x, pb.y, pb.z
        );
    }
    println!("largest pelvis difference, Bevy app vs plain World: {worst:e} m");
    // The published transforms are the joints' global positions (f32).
    let mut worst_t = 0.0f64;
    for &e in &pair {
        let globals = &world.get::<JointState>(e).expect("joints").globals;
        let joints = &world.get::<JointEntities>(e).expect("joint entities").0;
        for (g, &j) in globals.iter().zip(joints) {
            let t = world.get::<Transform>(j).expect("transform");
            worst_t = worst_t.max((t.translation.as_dvec3() - g.translation).length());
        }
    }
    println!("largest published-transform gap: {worst_t:e} m (f32 rounding)");
    let body = &world.get::<HumanFigure>(pair[1]).expect("body").0;
    let standing = body.figure.joints[0].offset.y;
    let fell = pelvis(world, pair[1]).y < 0.5 * standing;
    let stood = pelvis(world, pair[0]).y > 0.7 * standing;
    println!("pushed character fell: {fell}; steady character standing: {stood}");
    worst <= 1e-9 && worst_t < 1e-5 && fell && stood
}
