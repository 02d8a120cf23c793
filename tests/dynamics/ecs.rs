//! The ECS path: a World runs the same phases as `simulate_fall` bit for bit; Worlds are `Send`;
//! parallel Worlds give the same bits on 1 and 2 threads; a runaway state stops with its time,
//! body and quantity.

use glam::DVec3;
use marionette::dynamics::StepError;
use marionette::experiments::fall::{FallConfig, FallResult, SimError, simulate_fall};
use marionette::experiments::fall::{build_fall_world, run_fall_world, run_parallel};
use marionette::humanoid::AgeGroup;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;

fn short(group: AgeGroup) -> FallConfig {
    let mut c = FallConfig::paper(group);
    c.duration_s = 0.6;
    c
}

/// Every float of a result as raw bits, so equality means bit-identical.
fn bits(r: &FallResult) -> Vec<u64> {
    let mut out = vec![r.damage.to_bits(), r.max_penetration_m.to_bits(), r.steps];
    out.extend(r.peak_vertical_force_n.iter().map(|x| x.to_bits()));
    out.extend(r.impulse_n_s.iter().map(|x| x.to_bits()));
    for f in &r.frames {
        out.push(f.time_s.to_bits());
        out.extend(f.root_position.to_array().map(f64::to_bits));
        out.extend(f.root_orientation.to_array().map(f64::to_bits));
        out.extend(f.angles.iter().map(|x| x.to_bits()));
    }
    out
}

#[test]
fn world_is_send() {
    fn assert_send<T: Send>() {}
    assert_send::<bevy_ecs::world::World>();
}

#[test]
fn a_world_reproduces_simulate_fall_bit_for_bit() {
    let cfg = short(AgeGroup::Elderly);
    let direct = simulate_fall(&cfg).unwrap();
    let mut world = build_fall_world(&cfg).unwrap();
    let ecs = run_fall_world(&mut world).pop().unwrap().unwrap();
    assert_eq!(bits(&direct), bits(&ecs));
    assert!(direct.frames.len() > 30);
}

fn seeded_configs(seed: u64, n: usize) -> Vec<FallConfig> {
    let mut rng = Pcg64::seed_from_u64(seed);
    (0..n)
        .map(|i| {
            let mut c = short(if i % 2 == 0 {
                AgeGroup::Elderly
            } else {
                AgeGroup::Adult
            });
            c.push.force_n = rng.random_range(600.0..1200.0);
            c.push.direction = DVec3::new(rng.random_range(-0.3..0.3), 0.0, -1.0);
            for k in c.kp.iter_mut() {
                *k *= rng.random_range(0.5..1.5);
            }
            c
        })
        .collect()
}

#[test]
fn parallel_worlds_give_the_same_bits_on_one_and_two_threads() {
    let configs = seeded_configs(42, 6);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| run_parallel(&configs))
            .into_iter()
            .map(|r| bits(&r.unwrap()))
            .collect::<Vec<_>>()
    };
    let one = run(1);
    let two = run(2);
    assert_eq!(one, two);
    // Different seeds really give different falls (the check above is not vacuous).
    assert_ne!(one[0], one[2]);
}

#[test]
fn a_runaway_push_stops_with_time_body_and_quantity() {
    let mut cfg = short(AgeGroup::Elderly);
    cfg.push.force_n = 5.0e5;
    match simulate_fall(&cfg) {
        Err(SimError::Step(StepError::Exploding {
            time_s,
            body,
            quantity,
            ..
        })) => {
            assert!(time_s >= cfg.push.start_s && time_s < 0.6, "t = {time_s}");
            assert!(!body.is_empty() && !quantity.is_empty());
        }
        Err(SimError::Step(StepError::NonFinite { time_s, body, .. })) => {
            assert!(time_s > 0.0 && !body.is_empty())
        }
        other => panic!(
            "expected the run to stop, got {:?}",
            other.map(|r| r.damage)
        ),
    }
    // The World path reports the same failure.
    let mut world = build_fall_world(&cfg).unwrap();
    assert!(run_fall_world(&mut world).pop().unwrap().is_err());
}

#[test]
fn two_characters_in_one_world_fall_independently() {
    use bevy_ecs::world::World;
    use marionette::experiments::fall::build_fall;
    use marionette::experiments::fall::spawn_fall;
    let a = short(AgeGroup::Elderly);
    let mut b = short(AgeGroup::Adult);
    b.push.force_n = 700.0;
    let mut world = World::new();
    world.insert_resource(marionette::ecs::Clock::physics(a.dt_s));
    spawn_fall(&mut world, build_fall(&a).unwrap()).unwrap();
    spawn_fall(&mut world, build_fall(&b).unwrap()).unwrap();
    let results = run_fall_world(&mut world);
    assert_eq!(results.len(), 2);
    let ra = results[0].as_ref().unwrap();
    let rb = results[1].as_ref().unwrap();
    assert_eq!(bits(ra), bits(&simulate_fall(&a).unwrap()));
    assert_eq!(bits(rb), bits(&simulate_fall(&b).unwrap()));
}
