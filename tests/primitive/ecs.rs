//! ECS: 100 characters in one World — sequence players and live blends — stepped by the
//! primitive systems reproduce the kernel's `connect` and `blend` frame by frame.

use std::sync::Arc;

use bevy_ecs::prelude::*;
use marionette::ecs::DofPose;
use marionette::ecs::primitive::{BlendPlayer, PrimitivePlayer, add_primitive_systems};
use marionette::primitive::synthetic::smooth_humanoid24;
use marionette::primitive::{
    BlendPlacement, Gamma, LearnConfig, Primitive, Relearn, Trajectory, blend, connect,
};

const FPS: f64 = 120.0;

fn three_dof(seed: u64, first: usize, last: usize) -> Primitive {
    let full = smooth_humanoid24(1000, FPS, seed).unwrap();
    let idx = [4, 7, 19];
    let cols: Vec<Vec<f64>> = idx
        .iter()
        .map(|&j| full.column(j)[first..=last].to_vec())
        .collect();
    let names = idx.iter().map(|&j| full.names[j].clone()).collect();
    let demo = Trajectory::from_columns(full.dt, names, &cols).unwrap();
    Primitive::learn(&format!("m{seed}"), &demo, &LearnConfig::default())
        .unwrap()
        .primitive
}

enum Reference {
    Sequence(Trajectory),
    Blend(Trajectory),
}

#[test]
fn hundred_characters_in_one_world_match_the_kernel() {
    let dt = 1.0 / FPS;
    let a = three_dof(1, 0, 150);
    let b = three_dof(2, 300, 420);
    let mut world = World::new();
    world.insert_resource(marionette::ecs::Clock::new(dt, 1));
    let mut schedule = Schedule::default();
    add_primitive_systems(&mut schedule);

    let mut refs = Vec::new();
    for i in 0..100 {
        if i % 10 < 7 {
            // A connected pair with a per-character tempo.
            let s = 1.0 + 0.01 * i as f64;
            let seq = vec![
                Arc::new(a.with_duration(a.duration * s).unwrap()),
                Arc::new(b.with_duration(b.duration * s).unwrap()),
            ];
            let reference = connect(
                &seq.iter().map(|p| (**p).clone()).collect::<Vec<_>>(),
                dt,
                None,
            )
            .unwrap();
            let player = PrimitivePlayer::new(seq).unwrap();
            let pose = player.pose();
            let e = world.spawn((player, pose)).id();
            refs.push((e, Reference::Sequence(reference.trajectory)));
        } else {
            // A live blend: B inside A, γ = 1 − t′.
            let pl = BlendPlacement {
                a_start: 0.0,
                a_end: 2.0,
                b_start: 0.5,
                b_end: 1.5,
            };
            let gamma = Gamma::Ramp { from: 1.0, to: 0.0 };
            let reference = blend(
                &a,
                &b,
                &pl,
                &gamma,
                dt,
                Relearn::No,
                &LearnConfig::default(),
            )
            .unwrap();
            let mut player = BlendPlayer::new(&a, &b, pl, gamma).unwrap();
            let pose = player.pose();
            let e = world.spawn((player, pose)).id();
            refs.push((e, Reference::Blend(reference.trajectory)));
        }
    }

    let frames = 240;
    let mut worst = 0.0f64;
    for k in 1..=frames {
        schedule.run(&mut world);
        for (e, r) in &refs {
            let pose = world.get::<DofPose>(*e).unwrap();
            let tr = match r {
                Reference::Sequence(t) | Reference::Blend(t) => t,
            };
            if k >= tr.frames() {
                continue;
            }
            for j in 0..3 {
                worst = worst.max((pose.theta[j] - tr.value(k, j)).abs());
            }
        }
    }
    eprintln!("100 characters × {frames} frames: max |ECS − kernel| = {worst:.3e} rad");
    assert!(worst < 1e-6, "max deviation {worst} rad");
    // Sequence players crossed their junction and report it.
    let (e0, _) = refs[0];
    let p = world.get::<PrimitivePlayer>(e0).unwrap();
    assert_eq!(p.index(), 1);
    assert!((p.elapsed() - frames as f64 * dt).abs() < 1e-9);
}

#[test]
fn players_refuse_bad_input() {
    assert!(PrimitivePlayer::new(vec![]).is_err());
    let a = three_dof(1, 0, 150);
    let knee = Primitive::learn(
        "knee",
        &Trajectory::from_columns(
            0.01,
            vec!["knee".into()],
            &[(0..30).map(|k| k as f64 * 0.01).collect()],
        )
        .unwrap(),
        &LearnConfig::default(),
    )
    .unwrap()
    .primitive;
    assert!(PrimitivePlayer::new(vec![Arc::new(a.clone()), Arc::new(knee.clone())]).is_err());
    let pl = BlendPlacement {
        a_start: 0.0,
        a_end: 1.0,
        b_start: 0.0,
        b_end: 1.0,
    };
    assert!(BlendPlayer::new(&a, &knee, pl, Gamma::Constant(0.5)).is_err());
}
