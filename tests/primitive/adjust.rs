//! Adjusting primitives: time scaling (τ is the duration; 2τ traces the same path in twice the
//! time), goal scaling (θ − s scales by (g′ − s)/(g − s)), a goal that flips the sign of g − s
//! (2002/2013 mirror; Hoffmann 2009 does not).

use marionette::primitive::synthetic::knee_jump;
use marionette::primitive::{Formulation, LearnConfig, Primitive, Trajectory};

const DEG: f64 = std::f64::consts::PI / 180.0;

/// A knee flexing from 5° to a 110° crouch and ending at 30° (g − s = 25°), starting at rest.
fn knee_to_30(formulation: Formulation) -> Primitive {
    let k = knee_jump(110.0 * DEG, 1.0, 120.0);
    let n = k.len();
    let k: Vec<f64> = k
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let x = i as f64 / (n - 1) as f64;
            v + 25.0 * DEG * x * x * (3.0 - 2.0 * x)
        })
        .collect();
    let demo = Trajectory::from_columns(1.0 / 120.0, vec!["left_knee".into()], &[k]).unwrap();
    let cfg = LearnConfig {
        formulation,
        ..LearnConfig::default()
    };
    let l = Primitive::learn("knee", &demo, &cfg).unwrap();
    assert!(l.fit.dofs[0].rmse < 0.5, "fit {}", l.fit.dofs[0].rmse);
    l.primitive
}

#[test]
fn twice_the_duration_traces_the_same_path_in_twice_the_time() {
    for f in [
        Formulation::default(),
        Formulation::ijspeert2013(),
        Formulation::hoffmann2009(),
    ] {
        let p = knee_to_30(f);
        let slow = p.with_duration(2.0 * p.duration).unwrap();
        let times: Vec<f64> = (0..=150).map(|k| k as f64 / 120.0).collect();
        let times2: Vec<f64> = times.iter().map(|t| 2.0 * t).collect();
        let a = p.sample(&times, None).unwrap();
        let b = slow.sample(&times2, None).unwrap();
        for k in 0..times.len() {
            assert!(
                (a.values[k] - b.values[k]).abs() < 1e-9,
                "{} k={k}",
                f.name()
            );
            assert!(
                (a.velocities[k] - 2.0 * b.velocities[k]).abs() < 1e-8,
                "{} k={k}",
                f.name()
            );
        }
        // And the slow one really is slower: half-way through the fast one is at its crouch.
        let crouch = p.sample(&[0.3], None).unwrap().values[0];
        let slow_at = slow.sample(&[0.3], None).unwrap().values[0];
        assert!(crouch - slow_at > 20.0 * DEG);
    }
}

#[test]
fn a_new_goal_scales_the_motion_about_the_start() {
    for f in [Formulation::default(), Formulation::ijspeert2013()] {
        let p = knee_to_30(f);
        let s0 = p.dofs[0].start;
        let g = p.dofs[0].goal;
        let k = 1.5;
        let q = p.with_goals(&[s0 + k * (g - s0)]).unwrap();
        let times: Vec<f64> = (0..=180).map(|i| i as f64 / 120.0).collect();
        let a = p.sample(&times, None).unwrap();
        let b = q.sample(&times, None).unwrap();
        for i in 0..times.len() {
            let expect = s0 + k * (a.values[i] - s0);
            assert!((b.values[i] - expect).abs() < 1e-9, "{} i={i}", f.name());
        }
        // It settles on the new goal (2013's forcing, gated by s = e^{−α_s u}, fades more slowly
        // after the end of the movement than 2002's, gated by the phase velocity).
        let end = q.sample(&[3.0], None).unwrap().values[0];
        assert!(
            (end - (s0 + k * (g - s0))).abs() < 0.1 * DEG,
            "{}: end {}",
            f.name(),
            end / DEG
        );
    }
}

#[test]
fn a_goal_across_the_start_mirrors_2002_but_not_hoffmann() {
    let times: Vec<f64> = (0..=120).map(|i| i as f64 / 120.0).collect();
    // 2002: the new goal s − 25° flips g − s; the crouch (+105° about s) becomes −105°.
    let p = knee_to_30(Formulation::default());
    let s0 = p.dofs[0].start;
    let flipped = [s0 - 25.0 * DEG];
    assert_eq!(p.goal_sign_flips(&flipped), vec![0]);
    let m = p
        .with_goals(&flipped)
        .unwrap()
        .sample(&times, None)
        .unwrap();
    let a = p.sample(&times, None).unwrap();
    for i in 0..times.len() {
        assert!(
            (m.values[i] - (2.0 * s0 - a.values[i])).abs() < 1e-9,
            "i={i}"
        );
    }
    let min = m.values.iter().cloned().fold(f64::MAX, f64::min);
    let max = a.values.iter().cloned().fold(f64::MIN, f64::max);
    assert!(
        max > s0 + 60.0 * DEG && min < s0 - 60.0 * DEG,
        "crouch {} mirrored to {}",
        max / DEG,
        min / DEG
    );

    // Hoffmann 2009 keeps the crouch and goes to the new goal.
    let h = knee_to_30(Formulation::hoffmann2009());
    assert!(h.goal_sign_flips(&flipped).is_empty());
    let hm = h
        .with_goals(&flipped)
        .unwrap()
        .sample(&times, None)
        .unwrap();
    let hmax = hm.values.iter().cloned().fold(f64::MIN, f64::max);
    let hmin = hm.values.iter().cloned().fold(f64::MAX, f64::min);
    assert!(
        hmax - s0 > 0.6 * (max - s0),
        "Hoffmann crouch {}",
        hmax / DEG
    );
    assert!(
        hmin > flipped[0] - 3.0 * DEG,
        "Hoffmann went to {}",
        hmin / DEG
    );
    let end = h
        .with_goals(&flipped)
        .unwrap()
        .sample(&[2.0], None)
        .unwrap()
        .values[0];
    assert!(
        (end - flipped[0]).abs() < 1.0 * DEG,
        "end {} vs {}",
        end / DEG,
        flipped[0] / DEG
    );
}

#[test]
fn bad_adjustments_are_clear_errors() {
    let p = knee_to_30(Formulation::default());
    assert!(p.with_duration(0.0).is_err());
    assert!(p.with_duration(f64::NAN).is_err());
    assert!(p.with_goals(&[1.0, 2.0]).is_err());
    assert!(p.with_goal("right_knee", 1.0).is_err());
    assert!(p.sample(&[0.2, 0.1], None).is_err());
}
