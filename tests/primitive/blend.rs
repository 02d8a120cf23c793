//! Blending: the extrapolation identity of the paper's high jump, all six arrangements, γ curves,
//! re-learning as one or two primitives, and the blends that must be refused.

use marionette::primitive::synthetic::{knee_jump, smooth_humanoid24};
use marionette::primitive::{
    Arrangement, BlendPlacement, Gamma, LearnConfig, Primitive, PrimitiveError, Relearn,
    Trajectory, blend, connect,
};

const DEG: f64 = std::f64::consts::PI / 180.0;
const FPS: f64 = 120.0;

fn knee_primitive(peak_deg: f64, duration: f64) -> Primitive {
    let k = knee_jump(peak_deg * DEG, duration, FPS);
    let demo = Trajectory::from_columns(1.0 / FPS, vec!["left_knee".into()], &[k]).unwrap();
    Primitive::learn("knee", &demo, &LearnConfig::default())
        .unwrap()
        .primitive
}

/// A 3-DOF primitive from frames `first..=last` of the smooth synthetic clip.
fn three_dof(seed: u64, first: usize, last: usize) -> Primitive {
    let full = smooth_humanoid24(1000, FPS, seed).unwrap();
    let cols: Vec<Vec<f64>> = [7, 19, 23]
        .iter()
        .map(|&j| full.column(j)[first..=last].to_vec())
        .collect();
    let names = [7, 19, 23].iter().map(|&j| full.names[j].clone()).collect();
    let demo = Trajectory::from_columns(full.dt, names, &cols).unwrap();
    Primitive::learn(&format!("m{seed}"), &demo, &LearnConfig::default())
        .unwrap()
        .primitive
}

#[test]
fn constant_gamma_minus_half_extrapolates_a_high_jump() {
    // A = low jump (70°, 0.9 s) time-scaled onto the normal jump's span, B = normal (110°, 1.2 s).
    let low = knee_primitive(70.0, 0.9);
    let normal = knee_primitive(110.0, 1.2);
    let placement = BlendPlacement {
        a_start: 0.0,
        a_end: 1.2,
        b_start: 0.0,
        b_end: 1.2,
    };
    let r = blend(
        &low,
        &normal,
        &placement,
        &Gamma::Constant(-0.5),
        1.0 / FPS,
        Relearn::Whole,
        &LearnConfig::default(),
    )
    .unwrap();
    assert_eq!(r.arrangement, Arrangement::StartsTogetherEndsTogether);
    let high = &r.primitives[0].primitive;
    assert!((high.duration - 1.2).abs() < 1e-12);
    let roll = high.rollout(1.0 / FPS, None).unwrap();
    let a = knee_jump(70.0 * DEG, 1.2, FPS);
    let b = knee_jump(110.0 * DEG, 1.2, FPS);
    let mut worst = 0.0f64;
    for k in 0..a.len() {
        let expect = 1.5 * b[k] - 0.5 * a[k];
        worst = worst.max((roll.value(k, 0) - expect).abs());
    }
    eprintln!(
        "high jump: max |θ − (1.5·B − 0.5·A)| = {:.4} deg",
        worst / DEG
    );
    assert!(worst < 2.0 * DEG, "max error {} deg", worst / DEG);
    // Deeper crouch than either input: 1.5·peak_B − 0.5·peak_A.
    let peak = |v: &[f64]| v.iter().cloned().fold(f64::MIN, f64::max);
    let hp = peak(&roll.column(0));
    assert!(hp > peak(&b) + 10.0 * DEG);
    assert!((hp - (1.5 * peak(&b) - 0.5 * peak(&a))).abs() < 2.0 * DEG);
}

#[test]
fn all_six_arrangements_follow_the_blend_equation() {
    let a = three_dof(1, 100, 400);
    let b = three_dof(2, 300, 520);
    let gamma = Gamma::Ramp { from: 0.8, to: 0.1 };
    let cases = [
        (0.5, 2.0, Arrangement::StartsBeforeEndsBefore),
        (0.5, 3.0, Arrangement::StartsBeforeEndsTogether),
        (1.0, 2.0, Arrangement::StartsTogetherEndsBefore),
        (1.0, 3.0, Arrangement::StartsTogetherEndsTogether),
        (1.5, 2.5, Arrangement::StartsAfterEndsBefore),
        (1.5, 3.0, Arrangement::StartsAfterEndsTogether),
    ];
    let dt = 1.0 / 100.0;
    for (bs, be, expect) in cases {
        let pl = BlendPlacement {
            a_start: 1.0,
            a_end: 3.0,
            b_start: bs,
            b_end: be,
        };
        let r = blend(
            &a,
            &b,
            &pl,
            &gamma,
            dt,
            Relearn::Whole,
            &LearnConfig::default(),
        )
        .unwrap();
        assert_eq!(r.arrangement, expect);
        let t0 = bs.min(1.0);
        assert!((r.start_time - t0).abs() < 1e-12);
        assert!(
            (r.trajectory.duration() - (3.0 - t0)).abs() < 1e-9,
            "{expect:?}"
        );
        let pa = a.with_duration(2.0).unwrap();
        let pb = b.with_duration(be - bs).unwrap();
        let (o0, o1) = (bs.max(1.0), be.min(3.0));
        let mut mixed = 0;
        for k in 0..r.trajectory.frames() {
            let t = t0 + k as f64 * r.trajectory.dt;
            let in_a = t >= 1.0 - 1e-9;
            let in_b = t >= bs - 1e-9 && t <= be + 1e-9;
            let va = in_a.then(|| pa.sample(&[(t - 1.0).clamp(0.0, 2.0)], None).unwrap());
            let vb = in_b.then(|| pb.sample(&[(t - bs).clamp(0.0, be - bs)], None).unwrap());
            for j in 0..3 {
                let expect_v = match (&va, &vb) {
                    (Some(x), Some(y)) if t >= o0 - 1e-9 && t <= o1 + 1e-9 => {
                        let g = 0.8 + (0.1 - 0.8) * ((t - o0) / (o1 - o0)).clamp(0.0, 1.0);
                        g * x.values[j] + (1.0 - g) * y.values[j]
                    }
                    (Some(x), _) => x.values[j],
                    (None, Some(y)) => y.values[j],
                    (None, None) => panic!("{expect:?}: frame {k} outside both"),
                };
                let got = r.trajectory.value(k, j);
                // Sampled in one go vs frame by frame: different sub-step partitions of the
                // same integrator (first-order hold, O(h²)) agree to ~1e−6 rad.
                assert!(
                    (got - expect_v).abs() < 1e-5,
                    "{expect:?} frame {k} dof {j}: {got} vs {expect_v}"
                );
            }
            if in_a && in_b {
                mixed += 1;
            }
        }
        assert!(
            mixed as f64 >= (o1 - o0) / dt - 1.0,
            "{expect:?}: overlap frames {mixed}"
        );
        // Re-learned as one primitive spanning [min(t_As, t_Bs), t_Ae].
        let p = &r.primitives[0].primitive;
        assert!((p.duration - (3.0 - t0)).abs() < 1e-9);
        assert!(r.primitives[0].fit.dofs.iter().all(|d| d.rmse.is_finite()));
    }
}

#[test]
fn split_at_b_end_keeps_b_end_pose_as_the_first_goal() {
    // The jumping-knee-kick arrangement: B inside A, γ = 1 − t′ (A at B's start, B at its end).
    let a = three_dof(3, 100, 340);
    let b = three_dof(4, 500, 620);
    let pl = BlendPlacement {
        a_start: 0.0,
        a_end: 2.0,
        b_start: 0.6,
        b_end: 1.4,
    };
    let r = blend(
        &a,
        &b,
        &pl,
        &Gamma::Ramp { from: 1.0, to: 0.0 },
        1.0 / FPS,
        Relearn::SplitAtBEnd,
        &LearnConfig::default(),
    )
    .unwrap();
    assert_eq!(r.primitives.len(), 2);
    let (first, second) = (&r.primitives[0], &r.primitives[1]);
    assert!((first.primitive.duration + second.primitive.duration - 2.0).abs() < 1e-9);
    let b_end = b.with_duration(0.8).unwrap().sample(&[0.8], None).unwrap();
    for j in 0..3 {
        assert!((first.primitive.dofs[j].goal - b_end.values[j]).abs() < 1e-5);
    }
    for l in [first, second] {
        let m = l.fit.max_angle_rmse_deg().unwrap();
        assert!(m < 1.0, "{}: RMSE {m} deg", l.primitive.name);
    }
    // The two parts connect (kick, then landing) without a jump.
    let c = connect(
        &[first.primitive.clone(), second.primitive.clone()],
        1.0 / FPS,
        None,
    )
    .unwrap();
    assert!(c.junctions[0].max_angle_jump < 1e-12 && c.junctions[0].max_velocity_jump < 1e-9);
    // Whole-span split is refused when B ends with A.
    let together = BlendPlacement { b_end: 2.0, ..pl };
    let e = blend(
        &a,
        &b,
        &together,
        &Gamma::Constant(0.5),
        0.01,
        Relearn::SplitAtBEnd,
        &LearnConfig::default(),
    );
    assert!(matches!(e, Err(PrimitiveError::InvalidPlacement { .. })));
}

#[test]
fn bad_blends_are_clear_errors() {
    let a = three_dof(1, 100, 400);
    let knee = knee_primitive(110.0, 1.0);
    let pl = BlendPlacement {
        a_start: 0.0,
        a_end: 1.0,
        b_start: 0.0,
        b_end: 1.0,
    };
    let cfg = LearnConfig::default();
    let g = Gamma::Constant(0.5);
    let e = blend(&a, &knee, &pl, &g, 0.01, Relearn::No, &cfg).unwrap_err();
    assert!(matches!(e, PrimitiveError::DofMismatch { .. }), "{e}");
    assert!(e.to_string().contains("models"), "{e}");
    let b = three_dof(2, 300, 520);
    let no_overlap = BlendPlacement {
        a_start: 0.0,
        a_end: 1.0,
        b_start: -2.0,
        b_end: -1.0,
    };
    let e = blend(&a, &b, &no_overlap, &g, 0.01, Relearn::No, &cfg).unwrap_err();
    assert!(e.to_string().contains("do not overlap"), "{e}");
    let late = BlendPlacement {
        a_start: 0.0,
        a_end: 1.0,
        b_start: 0.5,
        b_end: 1.5,
    };
    let e = blend(&a, &b, &late, &g, 0.01, Relearn::No, &cfg).unwrap_err();
    assert!(e.to_string().contains("must not end after A"), "{e}");
    let e = blend(
        &a,
        &b,
        &pl,
        &Gamma::Constant(f64::NAN),
        0.01,
        Relearn::No,
        &cfg,
    )
    .unwrap_err();
    assert!(matches!(e, PrimitiveError::NonFinite { .. }), "{e}");
}
