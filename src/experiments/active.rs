//! An active character: a humanoid24 body plays a sequence of motor primitives under physics
//! (PD toward the primitives' θ_d, θ̇_d with the strength limits, root assistance of a given
//! strength), may be pushed, and falls once its assistance is released. Plain data in and out:
//! [`run_active`] takes an [`ActiveConfig`] and the primitives and returns an
//! [`ActiveOutcome`] (tracking error, push, release and fall times, peak torques against the
//! limits, the damage as in the fall experiment: `D = Σ w_i f_i` over the peak floor force of
//! each link after the push).

use std::collections::BTreeMap;
use std::sync::Arc;

use bevy_ecs::prelude::{Entity, World};
use glam::DVec3;

use crate::dynamics::forces::external::Push;
use crate::ecs::character::{
    CharacterError, CharacterLog, FeetOnFloor, PhysicalSettings, Reaction, character_schedule,
    spawn_physical_character,
};
use crate::ecs::human::HumanFigure;
use crate::ecs::physics::{
    BodyState, ExternalForces, JointLimits, PdController, PhysicsMonitor, PhysicsStatus,
};
use crate::ecs::{Clock, Recorder};
use crate::humanoid::FigureClip;
use crate::humanoid::{HumanBody, HumanError, humanoid24_body};
use crate::primitive::Primitive;

/// The pelvis counts as fallen once its height is below this fraction of its start height.
pub const FALLEN_FRACTION: f64 = 0.5;

/// The most ticks one run may take.
pub const MAX_TICKS: f64 = 2.0e6;

/// The inputs of an active character run.
#[derive(Clone, Debug, PartialEq)]
pub struct ActiveConfig {
    /// Standing height (m).
    pub height_m: f64,
    /// Body mass (kg).
    pub mass_kg: f64,
    /// Gravity (m/s²).
    pub gravity: f64,
    /// PD, assistance, strength, integrator and floor.
    pub settings: PhysicalSettings,
    /// Physics step = tick (s).
    pub dt_s: f64,
    /// Simulated time (s).
    pub duration_s: f64,
    /// A push, if any (its `start_s` is on the motion's time line).
    pub push: Option<Push>,
    /// Seconds after the push at which the assistance is released; `None` keeps it.
    pub release_delay_s: Option<f64>,
    /// A key pose the PD switches to at the release (the falling paper's fall controller):
    /// angle (degrees) per DOF name, DOFs not named held at 0; the PD keeps the character's
    /// own gains and strength. `None` keeps following the primitives.
    pub key_pose_deg: Option<BTreeMap<String, f64>>,
    /// Damage weight per link (links not named weigh 1).
    pub damage_weights: BTreeMap<String, f64>,
    /// Frames kept per second in the outcome.
    pub record_hz: f64,
}

impl Default for ActiveConfig {
    fn default() -> Self {
        Self {
            height_m: 1.70,
            mass_kg: 65.0,
            gravity: 9.81,
            settings: PhysicalSettings::default(),
            dt_s: 5e-4,
            duration_s: 2.0,
            push: None,
            release_delay_s: None,
            key_pose_deg: None,
            damage_weights: BTreeMap::new(),
            record_hz: 60.0,
        }
    }
}

/// A DOF's peak PD torque against its strength.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct TorquePeak {
    /// DOF name.
    pub dof: String,
    /// Largest |τ| (N·m), sampled at the end of every tick.
    pub peak_nm: f64,
    /// The strength limit in that direction's larger magnitude (N·m).
    pub limit_nm: f64,
}

/// What the motion asked of a DOF before the push against its strength.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct DofDemand {
    /// DOF name.
    pub dof: String,
    /// Joint-angle RMS error before the push (degrees).
    pub rms_deg: f64,
    /// Fraction of the ticks before the push whose PD torque was clamped to the strength.
    pub saturated_fraction: f64,
    /// Smallest and largest feedforward torque (N·m): the animated motion's inverse dynamics
    /// with the root carried by the assistance.
    pub demand_nm: (f64, f64),
    /// The strength range `(τ_min, τ_max)` (N·m; `(0, 0)` when unbounded).
    pub limit_nm: (f64, f64),
}

/// A foot's floor check before the push (see [`crate::ecs::character::FeetOnFloor`]).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FootCheck {
    /// Foot link name.
    pub link: String,
    /// Seconds at which the animated foot was down.
    pub animated_down_s: f64,
    /// Largest height of the physical foot's lowest corner above the floor while the animated
    /// one was down (m; ≤ 0: always on it).
    pub max_gap_m: f64,
    /// When that was (s).
    pub max_gap_time_s: f64,
}

/// The downward pull a motion needs, which no floor gives (see [`CharacterLog::max_pull_n`]).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct FloorPull {
    /// The largest downward whole-body external force, in body weights (`M g`).
    pub max_bw: f64,
    /// When that was (s).
    pub at_s: f64,
}

/// A link's peak floor force after the push and its share of the damage.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct LinkDamage {
    /// Link name.
    pub link: String,
    /// Peak normal force after the push (N).
    pub peak_force_n: f64,
    /// Damage weight.
    pub weight: f64,
}

/// What an active character did.
#[derive(Clone, Debug, PartialEq)]
pub struct ActiveOutcome {
    /// Drawable points of the body (joints, then End Sites) at `record_hz`.
    pub frames: Vec<Vec<DVec3>>,
    /// The body's motion as a clip on its model (DOF angles and pelvis), at `record_hz`.
    pub motion: FigureClip,
    /// Seconds between frames.
    pub frame_time_s: f64,
    /// Joint-angle RMS error against the primitives over all DOFs and ticks before the push
    /// (or the whole run without one), degrees.
    pub tracking_rms_deg: f64,
    /// The same per DOF, degrees.
    pub dof_rms_deg: Vec<(String, f64)>,
    /// Start of the push (s).
    pub push_s: Option<f64>,
    /// Release of the assistance (s).
    pub release_s: Option<f64>,
    /// First time the pelvis was below [`FALLEN_FRACTION`] of its start height (s).
    pub fall_s: Option<f64>,
    /// Pelvis height at the start and at the end (m).
    pub pelvis_height_m: (f64, f64),
    /// Largest gap between the body's and the animated pelvis height before the push (m).
    pub max_pelvis_gap_m: f64,
    /// Peak torques per DOF.
    pub torques: Vec<TorquePeak>,
    /// Per DOF the largest excursion past its joint range over the whole run (degrees), with
    /// [`PhysicalSettings::joint_ranges`]; empty without.
    pub range_excursion_deg: Vec<(String, f64)>,
    /// Per DOF the tracking error, saturation and the motion's torque demand before the push.
    pub demands: Vec<DofDemand>,
    /// The tick before the push with the largest mean squared joint error: its time (s) and
    /// RMS over the DOFs (degrees).
    pub worst_tick: (f64, f64),
    /// Per foot whether the physical foot was on the floor when the animated one was.
    pub feet: Vec<FootCheck>,
    /// The largest downward whole-body external force the animated motion needs before the
    /// push (see [`CharacterLog::max_pull_n`]): 0 for a motion a floor can carry; 0 also when
    /// the root feedforward is off (`assist_feedforward`), which then is not computed.
    pub pull: FloorPull,
    /// Peak floor force per link after the push.
    pub links: Vec<LinkDamage>,
    /// `D = Σ w_i f_i` (N).
    pub damage: f64,
    /// Pelvis height and animated pelvis height per tick, with the time (s, m, m).
    pub pelvis_track: Vec<(f64, f64, f64)>,
}

/// Why an active run failed.
#[derive(Debug, thiserror::Error)]
pub enum ActiveError {
    /// The body.
    #[error(transparent)]
    Body(#[from] HumanError),
    /// The character.
    #[error(transparent)]
    Character(#[from] CharacterError),
    /// A setting out of range.
    #[error("{field}: {message}")]
    Config {
        /// The field.
        field: &'static str,
        /// What is wrong.
        message: String,
    },
    /// The simulation diverged.
    #[error(transparent)]
    Step(#[from] crate::dynamics::pipeline::StepError),
}

fn positive(field: &'static str, x: f64) -> Result<(), ActiveError> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(ActiveError::Config {
            field,
            message: format!("must be a positive number, found {x}"),
        })
    }
}

/// Runs `sequence` (connected) on a physical humanoid24 character for `config.duration_s`.
pub fn run_active(
    config: &ActiveConfig,
    sequence: &[Primitive],
) -> Result<ActiveOutcome, ActiveError> {
    positive("dt_s", config.dt_s)?;
    positive("duration_s", config.duration_s)?;
    positive("record_hz", config.record_hz)?;
    let ticks = (config.duration_s / config.dt_s).round();
    if ticks > MAX_TICKS {
        return Err(ActiveError::Config {
            field: "duration_s",
            message: format!("{ticks} ticks; at most {MAX_TICKS} are allowed"),
        });
    }
    let body = Arc::new(humanoid24_body(
        config.height_m,
        config.mass_kg,
        config.gravity,
    )?);
    let (mut world, e) = spawn_active(config, &body, sequence)?;
    let mut schedule = character_schedule();
    let every = frame_stride(config);
    let mut configurations = Vec::new();
    for tick in 0..ticks as u64 {
        schedule.run(&mut world);
        if let Some(err) = world.get::<PhysicsStatus>(e).and_then(|s| s.error.clone()) {
            return Err(ActiveError::Step((*err).clone()));
        }
        if (tick as usize).is_multiple_of(every) {
            let q = &world.get::<BodyState>(e).expect("spawned with a state").q;
            configurations.push(q.clone());
        }
    }
    let log = world.get::<CharacterLog>(e).expect("log").clone();
    let reaction = world.get::<Reaction>(e).expect("reaction").clone();
    let feet = world.get::<FeetOnFloor>(e).expect("feet check");
    let rec = world.get::<Recorder>(e).expect("recorder");
    let pd = &world.get::<PdController>(e).expect("pd").0;
    let excursion: Vec<f64> = if world.get::<JointLimits>(e).is_some() {
        let m = &world.get::<PhysicsMonitor>(e).expect("monitor").0;
        m.max_excursion.iter().map(|x| x.to_degrees()).collect()
    } else {
        Vec::new()
    };
    let b = &world.get::<HumanFigure>(e).expect("body").0;
    let motion = body_clip(b, &configurations, every as f64 * config.dt_s);
    let mut o = outcome(config, b, pd, (&log, feet), &reaction, &rec.frames, motion);
    o.range_excursion_deg = b
        .figure
        .dofs
        .iter()
        .zip(&excursion)
        .map(|(d, x)| (d.name.clone(), *x))
        .collect();
    Ok(o)
}

/// A world holding the physical character playing `sequence`, with the config's key pose (the
/// reaction's PD targets) and push.
fn spawn_active(
    config: &ActiveConfig,
    body: &Arc<HumanBody>,
    sequence: &[Primitive],
) -> Result<(World, Entity), ActiveError> {
    let push_link = match &config.push {
        Some(p) => Some(
            body.link_index(&p.link)
                .ok_or_else(|| ActiveError::Config {
                    field: "push.link",
                    message: format!("'{}' is not a link ({:?})", p.link, body.link_names),
                })?,
        ),
        None => None,
    };
    let mut world = crate::ecs::new_world(Clock::physics(config.dt_s));
    let reaction = Reaction {
        release_delay_s: config.release_delay_s,
        ..Reaction::default()
    };
    let seq = sequence.iter().cloned().map(Arc::new).collect();
    let e = spawn_physical_character(
        &mut world,
        "active",
        body.clone(),
        seq,
        &config.settings,
        reaction,
    )?;
    if let Some(key) = &config.key_pose_deg {
        let mut pd = world.get::<PdController>(e).expect("pd").0.clone();
        pd.target.iter_mut().for_each(|t| *t = 0.0);
        pd.target_velocity.iter_mut().for_each(|t| *t = 0.0);
        pd.feedforward.clear();
        for (name, deg) in key {
            let d = body
                .figure
                .dof_index(name)
                .ok_or_else(|| ActiveError::Config {
                    field: "key_pose_deg",
                    message: format!(
                        "'{name}' is not a DOF of {} ({:?})",
                        body.figure.name,
                        body.figure.dof_names()
                    ),
                })?;
            pd.target[d] = deg.to_radians();
        }
        world.get_mut::<Reaction>(e).expect("reaction").key_pose = Some(pd);
    }
    if let (Some(p), Some(link)) = (&config.push, push_link) {
        world
            .get_mut::<ExternalForces>(e)
            .expect("spawned with external forces")
            .push(p.to_force(link));
    }
    Ok((world, e))
}

/// Each DOF's peak torque against its strength, and its demand: tracking error (`dof_rms_deg`),
/// share of ticks saturated, demanded torques.
fn torque_figures(
    body: &HumanBody,
    pd: &crate::dynamics::forces::pd::PdTargets,
    log: &CharacterLog,
    dof_rms_deg: &[(String, f64)],
) -> (Vec<TorquePeak>, Vec<DofDemand>) {
    let n = log.tracked_ticks.max(1) as f64;
    let torques = body
        .figure
        .dofs
        .iter()
        .enumerate()
        .map(|(d, dof)| {
            let (lo, hi) = pd.torque_limits.get(d).copied().unwrap_or((0.0, 0.0));
            TorquePeak {
                dof: dof.name.clone(),
                peak_nm: log.peak_torque_nm[d],
                limit_nm: lo.abs().max(hi.abs()),
            }
        })
        .collect();
    let demands = dof_rms_deg
        .iter()
        .enumerate()
        .map(|(d, (name, rms))| DofDemand {
            dof: name.clone(),
            rms_deg: *rms,
            saturated_fraction: log.saturated_ticks[d] as f64 / n,
            demand_nm: log.demand_nm[d],
            limit_nm: pd.torque_limits.get(d).copied().unwrap_or((0.0, 0.0)),
        })
        .collect();
    (torques, demands)
}

/// Each link's weighted peak floor force after the push, and their sum (the damage).
fn link_damage(
    config: &ActiveConfig,
    body: &HumanBody,
    log: &CharacterLog,
) -> (Vec<LinkDamage>, f64) {
    let links: Vec<LinkDamage> = body
        .link_names
        .iter()
        .zip(&log.peak_force_after_push_n)
        .map(|(l, f)| LinkDamage {
            link: l.clone(),
            peak_force_n: *f,
            weight: config.damage_weights.get(l).copied().unwrap_or(1.0),
        })
        .collect();
    let damage = links.iter().map(|l| l.weight * l.peak_force_n).sum();
    (links, damage)
}

/// Each foot's time held down by the animation and its largest gap to the floor.
fn foot_checks(config: &ActiveConfig, body: &HumanBody, feet: &FeetOnFloor) -> Vec<FootCheck> {
    feet.links
        .iter()
        .enumerate()
        .map(|(k, &l)| FootCheck {
            link: body.link_names[l].clone(),
            animated_down_s: feet.down_ticks[k] as f64 * config.dt_s,
            max_gap_m: feet.max_gap_m[k],
            max_gap_time_s: feet.max_gap_time_s[k],
        })
        .collect()
}

/// Ticks between kept frames.
fn frame_stride(config: &ActiveConfig) -> usize {
    ((1.0 / config.record_hz) / config.dt_s).round().max(1.0) as usize
}

/// The body's configurations as a clip on its figure model.
fn body_clip(body: &HumanBody, configurations: &[Vec<f64>], frame_time: f64) -> FigureClip {
    let mut all = vec![0.0; body.model.nv()];
    let mut angles = Vec::with_capacity(configurations.len() * body.dof_v.len());
    let mut root_translation = Vec::with_capacity(configurations.len());
    let mut root_rotation = Vec::with_capacity(configurations.len());
    for q in configurations {
        // Each frame's ball joints read nearest the previous frame's (continuous curves).
        let previous = all.clone();
        body.model.angles_near(q, &previous, &mut all);
        angles.extend(body.dof_v.iter().map(|&k| all[k]));
        root_translation.push(DVec3::new(q[0], q[1], q[2]));
        root_rotation.push(glam::DQuat::from_xyzw(q[3], q[4], q[5], q[6]));
    }
    FigureClip {
        model: body.figure.clone(),
        frame_time,
        root_translation,
        root_rotation,
        angles,
    }
}

fn outcome(
    config: &ActiveConfig,
    body: &HumanBody,
    pd: &crate::dynamics::forces::pd::PdTargets,
    (log, feet): (&CharacterLog, &FeetOnFloor),
    reaction: &Reaction,
    all_frames: &[Vec<DVec3>],
    motion: FigureClip,
) -> ActiveOutcome {
    let n = log.tracked_ticks.max(1) as f64;
    let dof_rms_deg: Vec<(String, f64)> = body
        .figure
        .dofs
        .iter()
        .zip(&log.dof_sq_error)
        .map(|(d, s)| (d.name.clone(), (s / n).sqrt().to_degrees()))
        .collect();
    let total: f64 = log.dof_sq_error.iter().sum();
    let tracking_rms_deg = (total / (n * log.dof_sq_error.len().max(1) as f64))
        .sqrt()
        .to_degrees();
    let start_h = log.samples.first().map_or(0.0, |s| s.pelvis_height_m);
    let end_h = log.samples.last().map_or(0.0, |s| s.pelvis_height_m);
    let fall_s = log
        .samples
        .iter()
        .find(|s| s.pelvis_height_m < FALLEN_FRACTION * start_h)
        .map(|s| s.time_s);
    let before = |t: f64| reaction.pushed_at_s.is_none_or(|p| t <= p);
    let max_pelvis_gap_m = log
        .samples
        .iter()
        .filter(|s| before(s.time_s))
        .map(|s| (s.pelvis_height_m - s.target_pelvis_height_m).abs())
        .fold(0.0, f64::max);
    let (torques, demands) = torque_figures(body, pd, log, &dof_rms_deg);
    let worst_tick = log
        .samples
        .iter()
        .filter(|s| before(s.time_s))
        .map(|s| (s.time_s, s.mean_sq_error.sqrt().to_degrees()))
        .fold((0.0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
    let weight = body.model.total_mass() * body.model.gravity().length();
    let pull = FloorPull {
        max_bw: log.max_pull_n / weight,
        at_s: log.max_pull_time_s,
    };
    let feet = foot_checks(config, body, feet);
    let (links, damage) = link_damage(config, body, log);
    let every = frame_stride(config);
    let frames = all_frames.iter().step_by(every).cloned().collect();
    ActiveOutcome {
        frames,
        motion,
        frame_time_s: every as f64 * config.dt_s,
        tracking_rms_deg,
        dof_rms_deg,
        push_s: reaction.pushed_at_s,
        release_s: reaction.released_at_s,
        fall_s,
        pelvis_height_m: (start_h, end_h),
        max_pelvis_gap_m,
        torques,
        range_excursion_deg: Vec::new(),
        demands,
        worst_tick,
        feet,
        pull,
        links,
        damage,
        pelvis_track: log
            .samples
            .iter()
            .map(|s| (s.time_s, s.pelvis_height_m, s.target_pelvis_height_m))
            .collect(),
    }
}
