//! Physical characters: a humanoid24 body plays a learned primitive under PD control with
//! root assistance; with full assistance it tracks the primitive, without it falls; a push
//! that releases the assistance makes it fall, one that does not leaves it standing; two
//! characters in one World do not touch each other; Worlds give the same bits on 1 and 2 threads.

use crate::common;

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
use marionette::humanoid::humanoid24_body;
use marionette::primitive::{LearnConfig, Primitive};

fn primitive(file: &str) -> Primitive {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/clips")
        .join(file);
    let clip = KeyframeClip::load(&path).unwrap().to_figure_clip();
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
    assert!(full.tracking_rms_deg < 2.0, "{}", full.tracking_rms_deg);
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
            .get::<marionette::ecs::human::HumanFigure>(e)
            .unwrap()
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

/// The high jump (A) and the jumping knee kick as their experiments make them from the scenes'
/// clips (scenes/high_jump.ron, scenes/jumping_knee_kick.ron).
fn jumps() -> (Vec<Primitive>, Vec<Primitive>) {
    use marionette::experiments::high_jump::HighJumpConfig;
    use marionette::experiments::knee_kick::{self, KneeKickConfig};
    use marionette::primitive::{EventConfig, Gamma};
    let clip = |file: &str| {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("scenes/clips")
            .join(file);
        KeyframeClip::load(&path).unwrap().to_figure_clip()
    };
    let config = KneeKickConfig {
        jump: HighJumpConfig {
            model: marionette::humanoid::humanoid24(),
            low: clip("low_jump.ron"),
            normal: clip("normal_jump.ron"),
            gamma: Gamma::Constant(-0.5),
            learn: LearnConfig::default(),
        },
        kick: clip("knee_kick.ron").window(0.0, 0.5).unwrap(),
        gamma: Gamma::Ramp { from: 1.0, to: 0.0 },
        events: EventConfig::default(),
    };
    let kk = knee_kick::run(&config).unwrap();
    (vec![kk.jump.learned.high.primitive.clone()], kk.sequence())
}

/// Prints what a run measured per DOF (RMS, saturation, the motion's demand against the
/// strength) and per foot.
fn print_tracking(label: &str, o: &marionette::experiments::active::ActiveOutcome) {
    let worst = o
        .demands
        .iter()
        .max_by(|a, b| a.rms_deg.total_cmp(&b.rms_deg))
        .unwrap();
    println!(
        "{label}: joint RMS {:.3}°, worst DOF {} {:.3}°, worst tick {:.3} s ({:.2}°), fall {:?}",
        o.tracking_rms_deg, worst.dof, worst.rms_deg, o.worst_tick.0, o.worst_tick.1, o.fall_s
    );
    for d in &o.demands {
        println!(
            "  {:28} RMS {:6.2}°  clamped {:5.1} %  demand {:7.1} .. {:7.1}  limit {:6.0} .. {:4.0} N·m",
            d.dof,
            d.rms_deg,
            100.0 * d.saturated_fraction,
            d.demand_nm.0,
            d.demand_nm.1,
            d.limit_nm.0,
            d.limit_nm.1
        );
    }
    for f in &o.feet {
        println!(
            "  {}: animated down {:.3} s, physical gap ≤ {:.4} m (at {:.3} s)",
            f.link, f.animated_down_s, f.max_gap_m, f.max_gap_time_s
        );
    }
    println!(
        "  the motion needs a downward pull of up to {:.2} body weights (at {:.3} s)",
        o.pull.max_bw, o.pull.at_s
    );
}

/// Prints each junction of `seq`: the step in θ̈ the two DMPs' own accelerations make there,
/// which the connection's hand-over removes.
fn print_junctions(label: &str, seq: &[Primitive]) {
    let c = marionette::primitive::connect(seq, 1.0 / 120.0, None).unwrap();
    for j in &c.junctions {
        println!(
            "{label}: junction at {:.3} s, the DMPs' accelerations differ by up to {:.1} rad/s² \
             (the hand-over plays through it without a step)",
            j.time, j.max_acceleration_step
        );
    }
}

/// A physical foot counts as on the floor when its lowest corner is within this of the floor
/// (m): the animated foot counts as down within 1 cm of its floor
/// ([`marionette::ecs::character::ANIMATED_FOOT_DOWN_M`]), and the physical one may lag it by
/// another centimetre of tracking error (the assisted pelvis follows to about 1 cm).
const FOOT_ON_FLOOR_M: f64 = 0.02;

/// The high jump and the jumping knee kick, fully assisted (the assistance carries the root's
/// share of the motion's inverse dynamics): under adult strength and with unbounded torques
/// both track under 2° with the feet on the floor whenever the animated ones are. (The
/// keyframed jumps are keyed as a body can make them: the legs still extending fast at
/// take-off, the trunk lean and the arm swing within what the waist and shoulders' strength
/// can carry; `scenes/clips/normal_jump.ron`.)
#[test]
fn fully_assisted_tracking_of_both_jumps_under_adult_strength() {
    let (high, kick) = jumps();
    for (label, seq) in [("high jump", high), ("jumping knee kick", kick)] {
        let duration: f64 = seq.iter().map(|p| p.duration).sum();
        let cfg = ActiveConfig {
            duration_s: duration,
            ..ActiveConfig::default()
        };
        let o = run_active(&cfg, &seq).unwrap();
        print_tracking(label, &o);
        print_junctions(label, &seq);
        assert!(o.fall_s.is_none());
        assert!(o.tracking_rms_deg < 2.0, "{label}: {}", o.tracking_rms_deg);
        for f in &o.feet {
            assert!(f.animated_down_s > 0.5, "{label}: {f:?}");
            assert!(f.max_gap_m <= FOOT_ON_FLOOR_M, "{label}: {f:?}");
        }
        let mut c = cfg.clone();
        c.settings.strength = None;
        let o = run_active(&c, &seq).unwrap();
        print_tracking(&format!("{label}, unbounded torques"), &o);
        // Both jumps (the high jump's arms swing through a shoulder rotation of π: read
        // nearest the targets, not on the principal branch's opposite side).
        assert!(o.tracking_rms_deg < 2.0, "{label}: {}", o.tracking_rms_deg);
        for f in &o.feet {
            assert!(f.animated_down_s > 0.5, "{f:?}");
            assert!(f.max_gap_m <= FOOT_ON_FLOOR_M, "{f:?}");
        }
    }
}

/// The key-pose switch: at the release the PD leaves the primitives for the key pose (the
/// falling paper's fall controller), keeps it while the primitives play on, and the body
/// moves toward it.
#[test]
fn the_release_switches_the_pd_to_the_key_pose() {
    use marionette::dynamics::forces::pd::PdTargets;
    use marionette::ecs::DofPose;
    use marionette::ecs::physics::PdController;
    let jump = Arc::new(primitive("normal_jump.ron"));
    let body = Arc::new(humanoid24_body(1.70, 65.0, 9.81).unwrap());
    let n = body.dof_v.len();
    let knee = body.figure.dof_index("left_knee").unwrap();
    let mut key_angles = vec![0.0; n];
    key_angles[knee] = 90f64.to_radians();
    let key = PdTargets::hold(key_angles.clone(), vec![200.0; n], vec![20.0; n]);
    let reaction = Reaction {
        release_delay_s: Some(0.05),
        key_pose: Some(key.clone()),
        ..Reaction::default()
    };
    let mut world = new_world(Clock::physics(5e-4));
    let e = spawn_physical_character(
        &mut world,
        "k",
        body.clone(),
        vec![jump],
        &PhysicalSettings::default(),
        reaction,
    )
    .unwrap();
    let link = body.link_index("chest").unwrap();
    world
        .get_mut::<marionette::ecs::physics::ExternalForces>(e)
        .unwrap()
        .push(chest_push(0.1).to_force(link));
    let mut s = character_schedule();
    run_ticks(&mut world, &mut s, 200);
    let pd = &world.get::<PdController>(e).unwrap().0;
    assert_ne!(pd.target, key.target, "switched before the release");
    let knee_at = |w: &bevy_ecs::world::World| {
        let st = w.get::<BodyState>(e).unwrap();
        let mut a = vec![0.0; body.model.nv()];
        body.model.angles(&st.q, &mut a);
        a[body.dof_v[knee]]
    };
    run_ticks(&mut world, &mut s, 200);
    let released = world.get::<Reaction>(e).unwrap().released_at_s.unwrap();
    assert!((released - 0.15).abs() < 1e-3, "{released}");
    let knee_then = knee_at(&world);
    run_ticks(&mut world, &mut s, 600);
    let pd = &world.get::<PdController>(e).unwrap().0;
    assert_eq!(pd.target, key.target);
    assert!(pd.feedforward.is_empty());
    let pose = world.get::<DofPose>(e).unwrap();
    assert!(
        pose.theta.iter().any(|t| t.abs() > 0.01),
        "the primitives play on"
    );
    let knee_now = knee_at(&world);
    println!(
        "key pose: knee {:.1}° at the release ({released:.3} s), {:.1}° 0.3 s later (key 90°)",
        knee_then.to_degrees(),
        knee_now.to_degrees()
    );
    assert!(
        (knee_now - key_angles[knee]).abs() < (knee_then - key_angles[knee]).abs(),
        "the knee moved toward the key pose"
    );
}

/// The same two motions made from the CMU capture as `scenes/high_jump_cmu.ron` and
/// `scenes/jumping_knee_kick_cmu.ron` make them, or `None` (skipped) without the shared data.
fn cmu_jumps() -> Option<(Vec<Primitive>, Vec<Primitive>)> {
    use marionette::experiments::high_jump::HighJumpConfig;
    use marionette::experiments::knee_kick::{self, KneeKickConfig};
    use marionette::primitive::{EventConfig, Gamma};
    let jumps = common::data_path("cmu/cmu_01_01_forward_jumps.bvh")?;
    let kicks = common::data_path("cmu/acrnn_martial_04.bvh")?;
    let clip = |path: &PathBuf, a: f64, b: f64| {
        let (bvh, _) = marionette::bvh::parse_file(path).unwrap();
        let clip = marionette::skeleton::Clip::from_bvh(&bvh, None)
            .unwrap()
            .window(a, b)
            .unwrap();
        let mapping = marionette::mapping::Mapping::detect_clip(&clip).unwrap();
        marionette::mapping::retarget(&clip, &mapping, &marionette::humanoid::humanoid24()).unwrap()
    };
    let config = KneeKickConfig {
        jump: HighJumpConfig {
            model: marionette::humanoid::humanoid24(),
            low: clip(&jumps, 2.779, 4.2265),
            normal: clip(&jumps, 0.975, 2.65),
            gamma: Gamma::Constant(-0.5),
            learn: LearnConfig::default(),
        },
        kick: clip(&kicks, 2.70, 3.02),
        gamma: Gamma::Ramp { from: 1.0, to: 0.0 },
        events: EventConfig::default(),
    };
    let kk = knee_kick::run(&config).unwrap();
    Some((vec![kk.jump.learned.high.primitive.clone()], kk.sequence()))
}

/// The default character (fully assisted, adult strength) run for the whole of `seq`.
fn whole_sequence(seq: &[Primitive]) -> ActiveConfig {
    ActiveConfig {
        duration_s: seq.iter().map(|p| p.duration).sum(),
        ..ActiveConfig::default()
    }
}

/// The downward pull each motion needs (a floor only pushes up, so a motion a body can make
/// needs none; the assistance carries it), and the same two motions blended from the CMU
/// capture, fully assisted under adult strength: both track under 2° with the feet on the
/// floor, the high jump needing little pull. The keyframed ones still need a pull at times (printed:
/// the flight keeps the pelvis, not the centre of mass, on its ballistic arc while the limbs
/// swing, and the kick is blended into the flight), which no longer keeps them from tracking
/// under 2° ([`fully_assisted_tracking_of_both_jumps_under_adult_strength`]).
#[test]
fn captured_jumps_track_under_adult_strength() {
    let (high, kick) = jumps();
    for (label, seq) in [("high jump", &high), ("jumping knee kick", &kick)] {
        let o = run_active(&whole_sequence(seq), seq).unwrap();
        println!(
            "keyframed {label}: downward pull up to {:.2} body weights (at {:.3} s)",
            o.pull.max_bw, o.pull.at_s
        );
    }
    let Some((high, kick)) = cmu_jumps() else {
        return;
    };
    for (label, seq) in [("CMU high jump", &high), ("CMU jumping knee kick", &kick)] {
        let o = run_active(&whole_sequence(seq), seq).unwrap();
        print_tracking(&format!("{label}, adult strength"), &o);
        print_junctions(label, seq);
        assert!(o.fall_s.is_none());
        for f in &o.feet {
            assert!(f.max_gap_m <= FOOT_ON_FLOOR_M, "{label}: {f:?}");
        }
        if label == "CMU high jump" {
            assert!(o.pull.max_bw < 0.5, "{label}: {:?}", o.pull);
        }
        assert!(o.tracking_rms_deg < 2.0, "{label}: {}", o.tracking_rms_deg);
    }
}

/// Joint ranges (humanoid24's adult table) on a character that is pushed and falls once its
/// assistance is released: the joint model holds every joint near its range through the fall,
/// where the same fall without ranges takes some joint further past it.
#[test]
fn joint_ranges_hold_a_falling_character() {
    use marionette::humanoid::{AgeGroup, RangeTable};
    let jump = primitive("normal_jump.ron");
    let free_cfg = ActiveConfig {
        duration_s: 2.5,
        push: Some(chest_push(0.3)),
        release_delay_s: Some(0.1),
        ..ActiveConfig::default()
    };
    let mut cfg = free_cfg.clone();
    cfg.settings.joint_ranges = Some(AgeGroup::Adult);
    let held = run_active(&cfg, std::slice::from_ref(&jump)).unwrap();
    let free = run_active(&free_cfg, &[jump]).unwrap();
    assert_eq!(held.range_excursion_deg.len(), 24);
    assert!(free.range_excursion_deg.is_empty());
    let worst = |v: &[(String, f64)]| {
        v.iter()
            .cloned()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap()
    };
    let held_worst = worst(&held.range_excursion_deg);
    // The free fall's excursions, read off its recorded motion against the same table.
    let model = marionette::humanoid::humanoid24();
    let ranges = RangeTable::builtin_for("humanoid24", AgeGroup::Adult)
        .unwrap()
        .for_figure(&model)
        .unwrap();
    let m = &free.motion;
    let free_ex: Vec<(String, f64)> = model
        .dofs
        .iter()
        .enumerate()
        .map(|(d, dof)| {
            let (lo, hi) = ranges[d];
            let ex = (0..m.frame_count())
                .map(|f| {
                    let a = m.frame_angles(f)[d];
                    (lo - a).max(a - hi).max(0.0)
                })
                .fold(0.0, f64::max);
            (dof.name.clone(), ex.to_degrees())
        })
        .collect();
    let free_worst = worst(&free_ex);
    println!(
        "fall with joint ranges: fall at {:?} s, worst excursion {} {:.1}°; without: fall at {:?} s, worst {} {:.1}°",
        held.fall_s, held_worst.0, held_worst.1, free.fall_s, free_worst.0, free_worst.1
    );
    assert!(held.fall_s.is_some() && free.fall_s.is_some());
    assert!(
        held_worst.1 < free_worst.1,
        "{held_worst:?} vs {free_worst:?}"
    );
}
