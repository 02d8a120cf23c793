//! Connecting: each primitive starts from the state the previous one ended in, with no jump in
//! angle or velocity at the junctions.

use marionette::primitive::synthetic::smooth_humanoid24;
use marionette::primitive::{LearnConfig, Primitive, PrimitiveError, Trajectory, connect};

const DEG: f64 = std::f64::consts::PI / 180.0;

fn clip_primitive(seed: u64, first: usize, last: usize) -> Primitive {
    let full = smooth_humanoid24(1000, 120.0, seed).unwrap();
    Primitive::learn(
        &format!("clip{seed}"),
        &full.slice_frames(first, last).unwrap(),
        &LearnConfig::default(),
    )
    .unwrap()
    .primitive
}

#[test]
fn a_sequence_has_no_jump_at_its_junctions() {
    let seq = [
        clip_primitive(1, 0, 150),
        clip_primitive(2, 200, 380),
        clip_primitive(3, 600, 700),
    ];
    // Played alone, each starts far from where the previous ended: a naive concatenation jumps.
    let naive_jump = {
        let end = seq[0].sample(&[seq[0].duration], None).unwrap();
        let start = seq[1].sample(&[0.0], None).unwrap();
        end.values
            .iter()
            .zip(&start.values)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    };
    assert!(
        naive_jump > 5.0 * DEG,
        "test motions too similar: {}",
        naive_jump / DEG
    );

    let dt = 1.0 / 120.0;
    let c = connect(&seq, dt, None).unwrap();
    assert_eq!(c.junctions.len(), 2);
    for j in &c.junctions {
        eprintln!(
            "junction at {:.4} s: max angle jump {:.3e} rad, max velocity jump {:.3e} rad/s",
            j.time, j.max_angle_jump, j.max_velocity_jump
        );
        assert!(j.max_angle_jump < 1e-12 && j.max_velocity_jump < 1e-9);
    }
    let total: f64 = seq.iter().map(|p| p.duration).sum();
    assert_eq!(
        c.trajectory.frames(),
        (total / dt + 1e-6).floor() as usize + 1
    );
    // On the sampled trajectory the junction frames step no more than their neighbours do
    // (a velocity-continuous curve), for every DOF.
    for jn in &c.junctions {
        let k = (jn.time / dt).round() as usize;
        for d in 0..c.trajectory.dofs() {
            let step = |i: usize| c.trajectory.value(i + 1, d) - c.trajectory.value(i, d);
            let across = step(k - 1).abs().max(step(k).abs());
            let around = step(k - 3).abs().max(step(k + 2).abs());
            assert!(
                across <= 2.0 * around + 0.02 * DEG,
                "dof {d} at {} s: step {across} vs {around}",
                jn.time
            );
        }
    }
}

#[test]
fn connecting_different_models_or_nothing_is_an_error() {
    let a = clip_primitive(1, 0, 150);
    let demo = Trajectory::from_columns(
        1.0 / 120.0,
        vec!["left_knee".into()],
        &[(0..50).map(|k| k as f64 * 0.01).collect()],
    )
    .unwrap();
    let b = Primitive::learn("knee", &demo, &LearnConfig::default())
        .unwrap()
        .primitive;
    assert!(matches!(
        connect(&[a, b], 0.01, None),
        Err(PrimitiveError::DofMismatch { .. })
    ));
    assert!(connect(&[], 0.01, None).is_err());
}

#[test]
fn a_hand_over_far_from_the_start_keeps_the_primitives_own_scaling() {
    use marionette::primitive::{DofState, SpatialScaling};
    // Knee: 5° → 110° crouch → 20° (g − s = 15°, goal-scaled).
    let n = 121;
    let knee: Vec<f64> = (0..n)
        .map(|k| {
            let x = k as f64 / (n - 1) as f64;
            (5.0 + 105.0 * (std::f64::consts::PI * x).sin().powi(2) * (1.0 - x) + 15.0 * x) * DEG
        })
        .collect();
    let demo = Trajectory::from_columns(1.0 / 120.0, vec!["knee".into()], &[knee]).unwrap();
    let p = Primitive::learn("knee", &demo, &LearnConfig::default())
        .unwrap()
        .primitive;
    assert!(matches!(
        p.dofs[0].scaling,
        SpatialScaling::GoalMinusStart { .. }
    ));
    // Handed over at 19° (almost at the goal): rescaling by (g − θ_c)/(g − s) would flatten the
    // crouch to 1/15 of its size; keeping the primitive's own s keeps the crouch.
    let start = DofState {
        theta: vec![19.0 * DEG],
        theta_dot: vec![0.0],
    };
    let s = p
        .sample(
            &(0..=180).map(|k| k as f64 / 120.0).collect::<Vec<_>>(),
            Some(&start),
        )
        .unwrap();
    let peak = s.values.iter().cloned().fold(f64::MIN, f64::max);
    let demo_peak = demo.column(0).into_iter().fold(f64::MIN, f64::max);
    assert!(
        (peak - demo_peak).abs() < 10.0 * DEG,
        "peak {} vs demo {}",
        peak / DEG,
        demo_peak / DEG
    );
    assert!((s.values[180] - p.dofs[0].goal).abs() < 0.5 * DEG);
}

/// The hand-over keeps the acceleration: sampled finely, the connected motion's second
/// differences change across a junction no more than the hand-over's correction
/// `δ = −½Δa t²(1 − t/W)³` allows (its jerk is at most 9|Δa|/W), where the two DMPs' own
/// accelerations differ by a step Δa (which would show as about Δa/2 in one tick).
#[test]
fn a_sequence_has_no_step_in_acceleration_at_its_junctions() {
    use marionette::primitive::HANDOVER_WINDOW_S;
    let seq = [clip_primitive(1, 0, 150), clip_primitive(2, 200, 380)];
    let dt = 2e-4;
    let c = connect(&seq, dt, None).unwrap();
    let jn = &c.junctions[0];
    let k = (jn.time / dt).round() as usize;
    let acc = |i: usize, d: usize| {
        (c.trajectory.value(i + 1, d) - 2.0 * c.trajectory.value(i, d)
            + c.trajectory.value(i - 1, d))
            / (dt * dt)
    };
    let mut worst: f64 = 0.0;
    for d in 0..c.trajectory.dofs() {
        for i in k - 3..k + 3 {
            worst = worst.max((acc(i + 1, d) - acc(i, d)).abs());
        }
    }
    let allowed = 10.0 * jn.max_acceleration_step * dt / HANDOVER_WINDOW_S;
    println!(
        "junction at {:.3} s: the DMPs' own accelerations differ by up to {:.1} rad/s²; the \
         connected motion's acceleration changes by at most {worst:.3} rad/s² per {dt} s tick \
         there (allowed {allowed:.3})",
        jn.time, jn.max_acceleration_step
    );
    assert!(jn.max_acceleration_step > 1.0, "{jn:?}");
    assert!(worst < allowed, "{worst} vs {allowed}");
    assert!(allowed < 0.1 * jn.max_acceleration_step);
}
