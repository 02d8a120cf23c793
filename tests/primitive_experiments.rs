//! The motor-primitive paper's experiments called as library functions (no scene file, no
//! outputs): typed configuration in, typed outcome out, on the project's keyframed clips.

use std::path::PathBuf;

use marionette::clips::KeyframeClip;
use marionette::experiments::high_jump::{self, HighJumpConfig};
use marionette::experiments::knee_kick::{self, KneeKickConfig};
use marionette::humanoid::{Model, ModelClip};
use marionette::primitive::{EventConfig, LearnConfig};

fn clip(name: &str) -> ModelClip {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/clips")
        .join(name);
    KeyframeClip::load(&path).unwrap().to_model_clip()
}

fn jump_config() -> HighJumpConfig {
    HighJumpConfig {
        model: Model::by_name("humanoid24").unwrap(),
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
    // Every rollout spans the normal jump's duration at its frame time.
    assert_eq!(o.duration_s, l.normal.primitive.duration);
    for r in [&o.rollouts.low, &o.rollouts.normal, &o.rollouts.high] {
        assert_eq!(r.dt, o.primitives.dt);
        assert_eq!(r.frames(), o.rollouts.normal.frames());
    }
    assert_eq!(o.clips.high.frame_count(), o.rollouts.high.frames());
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
    assert_eq!(o.result_clip.frame_count(), o.connected.trajectory.frames());
}
