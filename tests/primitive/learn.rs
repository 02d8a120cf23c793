//! Learning: a 24-DOF primitive reproduces a smooth synthetic demonstration; every formulation
//! and both regressions fit; degenerate DOFs (g = s, tiny |g − s|) and clips starting
//! mid-motion are handled.

use marionette::primitive::synthetic::{knee_jump, smooth_humanoid24};
use marionette::primitive::{
    Formulation, KernelCount, LearnConfig, Primitive, Regression, SpatialScaling, Trajectory,
};

const DEG: f64 = std::f64::consts::PI / 180.0;

#[test]
fn learned_24_dof_primitive_reproduces_a_1000_frame_demo() {
    let demo = smooth_humanoid24(1000, 120.0, 7).unwrap();
    assert_eq!((demo.frames(), demo.dofs()), (1000, 24));
    let learned = Primitive::learn("smooth", &demo, &LearnConfig::default()).unwrap();
    let median = learned.fit.median_angle_rmse_deg().unwrap();
    let max = learned.fit.max_angle_rmse_deg().unwrap();
    eprintln!("24-DOF ridge: median RMSE {median:.4} deg, max {max:.4} deg");
    assert!(median < 0.5, "median RMSE {median} deg");
}

#[test]
fn every_formulation_and_regression_fits_the_demo() {
    let demo = smooth_humanoid24(1000, 120.0, 11).unwrap();
    for formulation in [
        Formulation::default(),
        Formulation::ijspeert2013(),
        Formulation::hoffmann2009(),
    ] {
        for regression in [
            Regression::LocallyWeighted,
            Regression::Ridge { lambda: 1e-6 },
        ] {
            let cfg = LearnConfig {
                formulation,
                regression,
                ..LearnConfig::default()
            };
            let l = Primitive::learn("smooth", &demo, &cfg).unwrap();
            let median = l.fit.median_angle_rmse_deg().unwrap();
            let max = l.fit.max_angle_rmse_deg().unwrap();
            eprintln!(
                "{} {regression:?}: median {median:.4} deg, max {max:.4} deg",
                formulation.name()
            );
            assert!(
                median < 1.0,
                "{} {regression:?}: {median}",
                formulation.name()
            );
        }
    }
}

fn knee_demo(peak_deg: f64, end_offset: f64) -> Trajectory {
    let mut k = knee_jump(peak_deg * DEG, 1.2, 120.0);
    let n = k.len();
    // Spread `end_offset` linearly so that g − s = end_offset exactly.
    for (i, v) in k.iter_mut().enumerate() {
        *v += end_offset * i as f64 / (n - 1) as f64;
    }
    Trajectory::from_columns(1.0 / 120.0, vec!["left_knee".into()], &[k]).unwrap()
}

#[test]
fn goal_equal_to_start_is_learned_unscaled_and_follows_the_demo() {
    let demo = knee_demo(110.0, 0.0);
    assert_eq!(demo.value(0, 0), demo.value(demo.frames() - 1, 0));
    let l = Primitive::learn("knee", &demo, &LearnConfig::default()).unwrap();
    let d = &l.primitive.dofs[0];
    assert_eq!(d.scaling, SpatialScaling::Unscaled);
    assert!(d.weights.iter().all(|w| w.is_finite()));
    let rmse = l.fit.dofs[0].rmse;
    assert!(rmse < 0.5, "g = s: RMSE {rmse} deg");
    // The motion really moves (it is not frozen at s = g).
    let roll = l.primitive.rollout(demo.dt, None).unwrap();
    let peak = roll.column(0).into_iter().fold(f64::MIN, f64::max);
    assert!((peak / DEG - demo.column(0).into_iter().fold(f64::MIN, f64::max) / DEG).abs() < 1.0);
}

#[test]
fn tiny_goal_minus_start_does_not_blow_up_on_a_goal_change() {
    let demo = knee_demo(110.0, 1e-7);
    let l = Primitive::learn("knee", &demo, &LearnConfig::default()).unwrap();
    assert_eq!(l.primitive.dofs[0].scaling, SpatialScaling::Unscaled);
    assert!(l.fit.dofs[0].rmse < 0.5, "RMSE {}", l.fit.dofs[0].rmse);
    // Move the goal by +5°: the motion stays a knee jump and ends at the new goal.
    let g = l.primitive.dofs[0].goal + 5.0 * DEG;
    let moved = l.primitive.with_goals(&[g]).unwrap();
    let times: Vec<f64> = (0..=240).map(|k| k as f64 / 120.0).collect();
    let s = moved.sample(&times, None).unwrap();
    let peak = s.values.iter().cloned().fold(f64::MIN, f64::max);
    assert!(peak < 120.0 * DEG, "peak {} deg", peak / DEG);
    assert!(
        (s.values[240] - g).abs() < 0.2 * DEG,
        "end {} vs goal {}",
        s.values[240] / DEG,
        g / DEG
    );

    // The paper's scaling forced on (no degeneracy threshold) turns the same +5° into a
    // (g′ − s)/(g − s) ≈ 8.7e5-fold forcing: the blow-up the threshold prevents.
    let forced = LearnConfig {
        degenerate_fraction: 0.0,
        ..LearnConfig::default()
    };
    let lf = Primitive::learn("knee", &demo, &forced).unwrap();
    assert!(matches!(
        lf.primitive.dofs[0].scaling,
        SpatialScaling::GoalMinusStart { .. }
    ));
    let sf = lf
        .primitive
        .with_goals(&[g])
        .unwrap()
        .sample(&times, None)
        .unwrap();
    let peak_f = sf.values.iter().cloned().fold(f64::MIN, f64::max);
    assert!(peak_f > 1000.0, "forced scaling peak {peak_f} rad");
}

#[test]
fn clip_starting_mid_motion_keeps_its_initial_velocity() {
    let full = smooth_humanoid24(1000, 120.0, 3).unwrap();
    let clip = full.slice_frames(437, 700).unwrap();
    let l = Primitive::learn("mid", &clip, &LearnConfig::default()).unwrap();
    let s = l.primitive.sample(&[0.0], None).unwrap();
    let mut moving = 0;
    for j in 0..clip.dofs() {
        // Demonstrated velocity at frame 437 (central difference on the full clip).
        let v = (full.value(438, j) - full.value(436, j)) / (2.0 * full.dt);
        if v.abs() > 0.1 {
            moving += 1;
        }
        assert!(
            (s.velocity(0, j) - v).abs() < 0.01 * v.abs().max(0.05),
            "{}: θ̇(0) {} vs demo {v}",
            clip.names[j],
            s.velocity(0, j)
        );
    }
    assert!(moving > 10, "the clip should start mid-motion");
    let median = l.fit.median_angle_rmse_deg().unwrap();
    assert!(median < 0.5, "median RMSE {median}");
}

#[test]
fn too_short_or_malformed_demos_are_clear_errors() {
    let short = Trajectory::from_columns(0.01, vec!["a".into()], &[vec![0.0, 1.0, 2.0]]).unwrap();
    let e = Primitive::learn("x", &short, &LearnConfig::default()).unwrap_err();
    assert!(e.to_string().contains("at least 4 frames"), "{e}");
    let bad = LearnConfig {
        kernels: KernelCount::Fixed(1),
        ..LearnConfig::default()
    };
    let demo = knee_demo(70.0, 0.0);
    let e = Primitive::learn("x", &demo, &bad).unwrap_err();
    assert!(e.to_string().contains("kernels"), "{e}");
}

#[test]
fn root_motion_comes_along_and_is_reported_in_millimetres() {
    use marionette::primitive::DofUnit;
    use marionette::primitive::synthetic::jump_root_height;
    let (root, _, truth) = jump_root_height(120.0);
    let n = root.len();
    let knee: Vec<f64> = knee_jump(100.0 * DEG, (n - 1) as f64 / 120.0, 120.0);
    let demo = Trajectory::from_columns(
        1.0 / 120.0,
        vec!["left_knee".into(), "root_ty".into()],
        &[knee, root.clone()],
    )
    .unwrap();
    let l = Primitive::learn("jump", &demo, &LearnConfig::default()).unwrap();
    let fit = &l.fit.dofs[1];
    assert_eq!(fit.unit, DofUnit::Metre);
    eprintln!(
        "root_ty RMSE {:.3} mm, max {:.3} mm",
        fit.rmse, fit.max_error
    );
    assert!(fit.rmse < 2.0, "root RMSE {} mm", fit.rmse);
    // The flight survives: the rolled-out root peaks at the demonstrated apex, at Leap.
    let roll = l.primitive.rollout(demo.dt, None).unwrap();
    let y = roll.column(1);
    let (k_max, y_max) =
        y.iter().enumerate().fold(
            (0, f64::MIN),
            |a, (k, v)| if *v > a.1 { (k, *v) } else { a },
        );
    let apex = root.iter().cloned().fold(f64::MIN, f64::max);
    assert!((y_max - apex).abs() < 0.003, "apex {y_max} vs {apex}");
    assert!((k_max as f64 / 120.0 - truth.leap).abs() < 0.02);
}

#[test]
fn learning_a_primitives_own_rollout_reproduces_it() {
    let demo = smooth_humanoid24(600, 120.0, 5).unwrap();
    for formulation in [
        Formulation::default(),
        Formulation::ijspeert2013(),
        Formulation::hoffmann2009(),
    ] {
        let cfg = LearnConfig {
            formulation,
            ..LearnConfig::default()
        };
        let p = Primitive::learn("a", &demo, &cfg).unwrap().primitive;
        let roll = p.rollout(demo.dt, None).unwrap();
        let again = Primitive::learn("b", &roll, &cfg).unwrap();
        let max = again.fit.max_angle_rmse_deg().unwrap();
        assert!(max < 0.01, "{}: RMSE {max} deg", formulation.name());
        for (a, b) in p.dofs.iter().zip(&again.primitive.dofs) {
            // The rollout ends where the demonstration did, up to the fit error at the last frame.
            assert!((a.goal - b.goal).abs() < 1e-3 && (a.start - b.start).abs() < 1e-12);
            assert_eq!(
                std::mem::discriminant(&a.scaling),
                std::mem::discriminant(&b.scaling)
            );
        }
    }
    let bad = LearnConfig {
        degenerate_fraction: -1.0,
        ..LearnConfig::default()
    };
    assert!(Primitive::learn("x", &demo, &bad).is_err());
}
