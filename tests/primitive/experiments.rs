//! The motor-primitive paper's experiments called as library functions (no scene file, no
//! outputs): typed configuration in, typed outcome out, on the project's keyframed clips.

use std::path::PathBuf;

use marionette::clips::KeyframeClip;
use marionette::experiments::high_jump::{self, HighJumpConfig};
use marionette::experiments::knee_kick::{self, KneeKickConfig};
use marionette::humanoid::{Figure, FigureClip};
use marionette::primitive::{EventConfig, LearnConfig};

fn clip(name: &str) -> FigureClip {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/clips")
        .join(name);
    KeyframeClip::load(&path).unwrap().to_figure_clip()
}

fn jump_config() -> HighJumpConfig {
    HighJumpConfig {
        model: Figure::by_name("humanoid24").unwrap(),
        low: clip("low_jump.ron"),
        normal: clip("normal_jump.ron"),
        gamma: high_jump::PAPER_GAMMA,
        learn: LearnConfig::default(),
    }
}

#[test]
fn high_jump_extrapolates_the_crouch() {
    let o = high_jump::run(&jump_config()).unwrap();
    let p = &o.crouch_knee_flexion_deg;
    assert!((p.low - 70.0).abs() < 1.0, "{p:?}");
    assert!((p.normal - 110.0).abs() < 1.0, "{p:?}");
    assert!((p.high - 130.0).abs() < 2.0, "{p:?}");
    assert_eq!(o.expected_high_deg, 1.5 * p.normal - 0.5 * p.low);
    assert!(o.high_minus_expected_deg.abs() < 2.0);
    let l = &o.primitives.learned;
    assert_eq!(
        [&l.low, &l.normal, &l.high].map(|l| l.primitive.name.as_str()),
        ["low_jump", "normal_jump", "high_jump"]
    );
    assert!(l.high.fit.median_angle_rmse_deg().unwrap() < 0.5);
    // The low jump is blended time-scaled to the normal jump's duration; the high jump is
    // longer by the stretch of its flight.
    assert_eq!(o.duration_s, l.normal.primitive.duration);
    for r in [&o.rollouts.low, &o.rollouts.normal, &o.rollouts.high] {
        assert_eq!(r.dt, o.primitives.dt);
    }
    assert_eq!(o.rollouts.low.frames(), o.rollouts.normal.frames());
    let stretch = o.primitives.flight.stretch_s;
    assert!(stretch > 0.0, "{:?}", o.primitives.flight);
    assert!((l.high.primitive.duration - (o.duration_s + stretch)).abs() < 1e-9);
    assert_eq!(o.clips.high.frame_count(), o.rollouts.high.frames());
}

#[test]
fn high_jump_rises_higher_and_flies_longer() {
    let o = high_jump::run(&jump_config()).unwrap();
    let (f, pred) = (&o.figures, &o.primitives.prediction);
    // The keyframed jumps fly over their whole keyed flights (0.34 s and 0.40 s), less the few
    // frames the feet take to rise 3 cm.
    assert!(
        f.low.flight_s > 0.28 && f.low.flight_s < 0.35,
        "{:?}",
        f.low
    );
    assert!(
        f.normal.flight_s > 0.34 && f.normal.flight_s < 0.41,
        "{:?}",
        f.normal
    );
    // Higher and longer than the normal jump, as extrapolating the two predicts.
    assert!(f.high.apex_above_standing_m > f.normal.apex_above_standing_m + 0.015);
    assert!(f.high.flight_s > f.normal.flight_s + 0.015);
    assert!((f.high.apex_above_standing_m - pred.apex_above_standing_m).abs() < 0.002);
    // The root extrapolated with the joints' γ: its apex over the floor is the blend of the
    // two jumps', and above the normal jump's.
    assert!(
        (f.high.apex_root_m - pred.apex_root_m).abs() < 0.002,
        "{f:?} {pred:?}"
    );
    assert!(f.high.apex_root_m > f.normal.apex_root_m + 0.015, "{f:?}");
    assert!(
        (f.high.flight_s - pred.flight_s).abs() < 0.015,
        "{f:?} {pred:?}"
    );
    // The stretched flight is as ballistic as the normal jump's own: the gravity that would
    // carry each from its take-off height over its apex to its landing height in the time it
    // is given agrees to 2 % (the stretch is rounded to whole frames).
    let plan = &o.primitives.flight;
    let g_over = |apex: f64, t: f64| {
        let legs =
            (2.0 * (apex - plan.take_off_root_m)).sqrt() + (2.0 * (apex - plan.land_root_m)).sqrt();
        (legs / t).powi(2)
    };
    let span = plan.blend_land_s - plan.blend_take_off_s;
    let g_normal = g_over(plan.normal_apex_root_m, span);
    let g_high = g_over(plan.apex_root_m, span + plan.stretch_s);
    assert!(
        (g_high / g_normal - 1.0).abs() < 0.02,
        "g {g_high} vs the normal jump's {g_normal} ({plan:?})"
    );
    assert!((plan.arc_scale - 1.0).abs() < 0.05, "{plan:?}");
    // The feet never go through the floor: the floor constraint lifts the rollouts by no more
    // than the DMP fit of the demonstrations misses by.
    for j in [&f.low, &f.normal, &f.high] {
        assert!(j.lowest_foot_above_floor_m > -1e-9, "{j:?}");
    }
    for lift in [
        o.floor_lift_m.low,
        o.floor_lift_m.normal,
        o.floor_lift_m.high,
    ] {
        assert!((0.0..0.005).contains(&lift), "lift {lift} m");
    }
}

#[test]
fn jumping_knee_kick_connects_without_a_jump() {
    let config = KneeKickConfig {
        jump: jump_config(),
        kick: clip("knee_kick.ron").window(0.0, 0.5).unwrap(),
        gamma: knee_kick::PAPER_GAMMA,
        events: EventConfig::default(),
    };
    let o = knee_kick::run(&config).unwrap();
    let e = &o.events;
    assert!(
        e.start < e.bend && e.bend < e.leap && e.leap < e.land,
        "{e:?}"
    );
    assert_eq!(
        o.sequence()
            .iter()
            .map(|p| p.name.as_str())
            .collect::<Vec<_>>(),
        ["jumping_knee_kick", "land"]
    );
    assert!(o.junction.time_s.is_some());
    assert!(o.junction.max_angle_jump_deg < 1e-6);
    assert!(o.junction.max_velocity_jump_deg_s < 1e-6);
    assert!(
        o.posture_gap_deg.jump_at_bend_deg < 2.0,
        "{:?}",
        o.posture_gap_deg
    );
    assert!(
        o.posture_gap_deg.kick_at_leap_deg < 2.0,
        "{:?}",
        o.posture_gap_deg
    );
    assert!(
        o.lands_with_both_feet,
        "{:?}",
        o.feet_above_floor_after_landing_m
    );
    // A kick in the air: both feet up at Leap, the root at the jump's apex.
    assert!(o.airborne_at_leap, "{:?}", o.feet_above_floor_at_leap_m);
    assert!(o.root_at_leap_minus_jump_apex_m.abs() < 0.005);
    assert!(o.figures.flight_s > 0.25, "{:?}", o.figures);
    // No foot below the floor, the landing's connection included (the lift takes up what the
    // fits miss by, millimetres).
    for fig in [&o.figures, &o.jump_figures] {
        assert!(fig.lowest_foot_above_floor_m > -1e-9, "{fig:?}");
    }
    assert!((0.0..0.01).contains(&o.floor_lift_m), "{}", o.floor_lift_m);
    assert_eq!(o.result_clip.frame_count(), o.connected.trajectory.frames());
}
