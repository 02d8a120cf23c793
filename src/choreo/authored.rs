//! The project's own dance: clips of dance on humanoid24 generated in code at a known tempo, so
//! that a segment database (and the `dance` scene) needs nothing from outside.
//!
//! Each bar is one 4-count move — step-touch, grapevine, arm waves, a stepping turn, a kick, a
//! knee drop — with variations of side, amplitude and arm pattern. A move is five poses, on
//! counts 1, 2, 3, 4 and the next bar's 1 (so consecutive bars of a clip join exactly); between
//! two counts every channel moves by the cosine ease e(u) = (1 − cos πu)/2, whose velocity is zero
//! on the count, so the joints' speed has its minima on the beats (the kinematic beat of
//! [`super::segments`] finds the tempo).
//!
//! A pose gives the toe (the foot's End Site) of each foot on the floor or in the air, each
//! foot's heading, the share of weight on the right foot (the pelvis stands over the weighted
//! toes, over the ankles), the pelvis drop below the planted toes' full reach and its turn, and the upper body's angles. The
//! legs follow by inverse kinematics ([`leg_ik`]): a planted toe stays exactly where it was put
//! (no skating, no penetration; humanoid24's ankle is rigid, so the foot turns with the shin),
//! and a stepping foot lifts on an arc sin(πu) between its places.

use std::f64::consts::PI;

use glam::{DMat3, DQuat, DVec2, DVec3};
use serde::{Deserialize, Serialize};

use crate::humanoid::{Figure, FigureClip, humanoid24};

/// What to generate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AuthoredDance {
    /// Tempo, beats per minute (a bar is 4 beats).
    pub bpm: f64,
    /// Number of clips.
    pub clips: usize,
    /// Bars per clip.
    pub bars_per_clip: usize,
    /// Frames per second.
    pub fps: f64,
    /// Scale of every move's reach (step length, kick height, drop depth), 1 as authored.
    pub amplitude: f64,
}

impl Default for AuthoredDance {
    /// 4 clips of 8 bars at 118 BPM, 60 fps, amplitude 1.
    fn default() -> Self {
        AuthoredDance {
            bpm: 118.0,
            clips: 4,
            bars_per_clip: 8,
            fps: 60.0,
            amplitude: 1.0,
        }
    }
}

/// Why a dance could not be generated.
#[derive(Debug, thiserror::Error)]
pub enum AuthoredError {
    /// A parameter out of its range.
    #[error("authored dance: {name} = {value}: expected {expected}")]
    Parameter {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: f64,
        /// Its valid range.
        expected: &'static str,
    },
}

/// One generated clip: its moves, bar by bar, and the motion.
#[derive(Debug, Clone, PartialEq)]
pub struct AuthoredClip {
    /// Clip name (`authored_<k>`).
    pub name: String,
    /// The move of each bar, as a name with its variation (`step-touch left, clap`).
    pub moves: Vec<String>,
    /// The move family of each bar (`step-touch`, `grapevine`, …).
    pub families: Vec<&'static str>,
    /// The motion on humanoid24; frame 0 is the first bar's downbeat, and the clip holds the last
    /// pose for one more beat after its last bar.
    pub motion: FigureClip,
}

impl AuthoredClip {
    /// The motion as BVH text (humanoid24's skeleton, through the project's BVH writer).
    pub fn to_bvh_string(&self) -> String {
        crate::bvh::to_string(&self.motion.to_clip().to_bvh())
    }
}

/// Writes every clip as `<name>.bvh` into `dir` (created if absent), each file whole or not at
/// all; returns the files written.
pub fn write_bvh_folder(
    clips: &[AuthoredClip],
    dir: &std::path::Path,
) -> std::io::Result<Vec<std::path::PathBuf>> {
    std::fs::create_dir_all(dir)?;
    clips
        .iter()
        .map(|c| {
            let path = dir.join(format!("{}.bvh", c.name));
            crate::io::write_atomic(&path, c.to_bvh_string().as_bytes())?;
            Ok(path)
        })
        .collect()
}

/// Arm positions a move starts or ends in.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Arms {
    Low,
    Hips,
    High,
    Front,
    Open,
}

/// One arm: shoulder flexion, shoulder abduction, elbow flexion (degrees).
type Arm = [f64; 3];

fn arm(a: Arms) -> Arm {
    match a {
        Arms::Low => [0.0, 12.0, 15.0],
        Arms::Hips => [-10.0, 45.0, 100.0],
        Arms::High => [170.0, 15.0, 10.0],
        Arms::Front => [80.0, 5.0, 35.0],
        Arms::Open => [10.0, 85.0, 15.0],
    }
}

/// The channels of a pose in world coordinates (index 0 left, 1 right).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Pose {
    /// Toe positions (y = height above the floor), metres.
    toes: [DVec3; 2],
    /// Foot headings about +Y, radians (0 faces +Z).
    heading: [f64; 2],
    /// Share of the weight on the right foot.
    weight: f64,
    /// Pelvis turn about +Y, radians.
    yaw: f64,
    /// Pelvis lowering from standing, metres.
    drop: f64,
    /// Waist flexion and lateral bend, degrees.
    waist: [f64; 2],
    /// Left and right arm.
    arms: [Arm; 2],
}

/// Half the stance width: a toe's distance from the mid-line, metres.
const STANCE: f64 = 0.11;
/// Height of a step's arc, metres.
const STEP_LIFT: f64 = 0.07;
/// Pelvis drop of a standing pose (soft knees), metres.
const SOFT: f64 = 0.005;

/// A dancer's frame at the start of a bar: the mid-point between the toes on the floor and the
/// heading.
#[derive(Debug, Clone, Copy)]
struct Place {
    origin: DVec2,
    yaw: f64,
}

impl Place {
    /// The world point of local (x to the dancer's left, z forward), at height `y`.
    fn at(&self, x: f64, z: f64, y: f64) -> DVec3 {
        let (s, c) = self.yaw.sin_cos();
        DVec3::new(
            self.origin.x + c * x + s * z,
            y,
            self.origin.y - s * x + c * z,
        )
    }

    /// The floor point of local (x, z).
    fn floor(&self, x: f64, z: f64) -> DVec3 {
        self.at(x, z, 0.0)
    }

    /// The feet's floor points standing square, `[left, right]`.
    fn home(&self) -> [DVec3; 2] {
        [self.floor(STANCE, 0.0), self.floor(-STANCE, 0.0)]
    }

    /// Local coordinates (x, z) of a world point.
    fn local(&self, p: DVec3) -> (f64, f64) {
        let (s, c) = self.yaw.sin_cos();
        let (dx, dz) = (p.x - self.origin.x, p.z - self.origin.y);
        (c * dx - s * dz, s * dx + c * dz)
    }
}

/// A move and its variation.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Move {
    /// Step to a side (+1 left, −1 right), touch, step back, touch; an arm pattern.
    StepTouch { side: f64, step: f64, pattern: u8 },
    /// Step to a side, cross behind, step, close.
    Grapevine { side: f64, step: f64, high: bool },
    /// Feet planted, knees bouncing on every beat; an arm pattern.
    ArmWave { pattern: u8 },
    /// Four steps turning by `angle` (radians, + to the left).
    Turn { angle: f64, high: bool },
    /// A kick of the left (+1) or right (−1) leg, to the front or the side.
    Kick { side: f64, front: bool, height: f64 },
    /// Knee drops on counts 1 and 3.
    KneeDrop { depth: f64, pattern: u8 },
}

impl Move {
    fn family(&self) -> &'static str {
        match self {
            Move::StepTouch { .. } => "step-touch",
            Move::Grapevine { .. } => "grapevine",
            Move::ArmWave { .. } => "arm-wave",
            Move::Turn { .. } => "turn",
            Move::Kick { .. } => "kick",
            Move::KneeDrop { .. } => "knee-drop",
        }
    }

    fn describe(&self) -> String {
        let side = |s: f64| if s > 0.0 { "left" } else { "right" };
        match *self {
            Move::StepTouch {
                side: s, pattern, ..
            } => format!(
                "step-touch {}, {}",
                side(s),
                ["arm swings", "claps", "pumps"][pattern as usize % 3]
            ),
            Move::Grapevine { side: s, high, .. } => format!(
                "grapevine {}, arms {}",
                side(s),
                if high { "high" } else { "open" }
            ),
            Move::ArmWave { pattern } => format!(
                "arm waves, {}",
                ["alternating", "raise the roof", "punches"][pattern as usize % 3]
            ),
            Move::Turn { angle, high } => format!(
                "{:.0}° turn {}, arms {}",
                angle.abs().to_degrees(),
                side(angle),
                if high { "high" } else { "open" }
            ),
            Move::Kick { side: s, front, .. } => {
                format!("{} kick, {}", side(s), if front { "front" } else { "side" })
            }
            Move::KneeDrop { pattern, .. } => format!(
                "knee drops, arms {}",
                ["pushing down", "up"][pattern as usize % 2]
            ),
        }
    }
}

/// Index of the foot on side `s` (+1 left → 0, −1 right → 1).
fn foot(s: f64) -> usize {
    if s > 0.0 { 0 } else { 1 }
}

/// Weight on the right foot when foot `i` carries the share `w` of it.
fn weight_on(i: usize, w: f64) -> f64 {
    if i == 1 { w } else { 1.0 - w }
}

/// The four poses (counts 2, 3, 4 and the next bar's 1) of `m` from the start pose `p0` in the
/// place `at`, ending with the arms in `end`.
fn move_poses(m: Move, p0: &Pose, at: Place, amp: f64, end: Arms) -> [Pose; 4] {
    let mut p = [*p0; 4];
    for q in &mut p {
        q.drop = SOFT;
        q.waist = [0.0, 0.0];
    }
    let from = [at.local(p0.toes[0]), at.local(p0.toes[1])];
    let endarm = arm(end);
    match m {
        Move::StepTouch {
            side,
            step,
            pattern,
        } => step_touch(&mut p, at, amp, from, side, step, pattern),
        Move::Grapevine { side, step, high } => {
            let x0 = from[foot(side)].0;
            grapevine(&mut p, at, amp, x0, side, step, high)
        }
        Move::ArmWave { pattern } => arm_wave(&mut p, at, amp, pattern),
        Move::Turn { angle, high } => turn(&mut p, at, amp, angle, high),
        Move::Kick {
            side,
            front,
            height,
        } => kick(&mut p, at, amp, side, front, height),
        Move::KneeDrop { depth, pattern } => knee_drop(&mut p, at, amp, depth, pattern),
    }
    // Feet that do not turn keep their heading; the last pose stands square.
    if !matches!(m, Move::Turn { .. }) {
        for q in &mut p {
            q.heading = p0.heading;
            q.yaw = p0.yaw;
        }
    }
    p[3].arms = [endarm; 2];
    p[3].drop = SOFT;
    p[3].waist = [0.0, 0.0];
    p
}

/// [`Move::StepTouch`]'s poses: the lead foot steps `step` to `side` from the toes' local
/// places `from`, the trail foot touches beside it, back home; one of three arm patterns.
fn step_touch(
    p: &mut [Pose; 4],
    at: Place,
    amp: f64,
    from: [(f64, f64); 2],
    side: f64,
    step: f64,
    pattern: u8,
) {
    let home = at.home();
    let d = step * amp;
    let (lead, trail) = (foot(side), 1 - foot(side));
    let shifted = |i: usize| at.floor(from[i].0 + side * d, from[i].1);
    p[0].toes[lead] = shifted(lead);
    p[0].weight = weight_on(lead, 0.7);
    p[0].drop = SOFT + 0.05 * amp;
    p[1].toes = p[0].toes;
    p[1].toes[trail] = shifted(trail);
    p[1].weight = weight_on(lead, 0.6);
    p[2].toes = p[1].toes;
    p[2].toes[trail] = home[trail];
    p[2].weight = weight_on(trail, 0.7);
    p[2].drop = SOFT + 0.05 * amp;
    p[3].toes = home;
    p[3].weight = 0.5;
    p[0].waist[1] = -6.0 * side;
    p[2].waist[1] = 6.0 * side;
    let (a, b) = match pattern % 3 {
        0 => ([60.0, 15.0, 30.0], [-30.0, 15.0, 20.0]),
        1 => (arm(Arms::Open), [70.0, -5.0, 70.0]),
        _ => (arm(Arms::High), [120.0, 20.0, 80.0]),
    };
    match pattern % 3 {
        0 => {
            p[0].arms[lead] = b;
            p[0].arms[trail] = a;
            p[1].arms = [arm(Arms::Low); 2];
            p[2].arms[lead] = a;
            p[2].arms[trail] = b;
        }
        _ => {
            p[0].arms = [a; 2];
            p[1].arms = [b; 2];
            p[2].arms = [a; 2];
        }
    }
}

/// [`Move::Grapevine`]'s poses: the lead foot (its toe at local x `x0`) steps to `side`, the
/// trail foot crosses behind, step, close; arms open (or `high`).
fn grapevine(p: &mut [Pose; 4], at: Place, amp: f64, x0: f64, side: f64, step: f64, high: bool) {
    let d = step * amp;
    let (lead, trail) = (foot(side), 1 - foot(side));
    let x1 = x0 + side * d;
    p[0].toes[lead] = at.floor(x1, 0.0);
    p[0].weight = weight_on(lead, 0.7);
    p[0].drop = SOFT + 0.04 * amp;
    p[1].toes = p[0].toes;
    p[1].toes[trail] = at.floor(x1 - side * 0.03, -0.2);
    p[1].weight = weight_on(trail, 0.6);
    p[1].drop = SOFT + 0.07 * amp;
    let x3 = x1 + side * (STANCE + 0.5 * d);
    p[2].toes = p[1].toes;
    p[2].toes[lead] = at.floor(x3, 0.0);
    p[2].weight = weight_on(lead, 0.7);
    p[2].drop = SOFT + 0.04 * amp;
    p[3].toes = p[2].toes;
    p[3].toes[trail] = at.floor(x3 - side * 2.0 * STANCE, 0.0);
    p[3].weight = 0.5;
    let out = if high {
        arm(Arms::High)
    } else {
        arm(Arms::Open)
    };
    p[0].arms = [out; 2];
    p[1].arms = [arm(Arms::Front); 2];
    p[2].arms = [out; 2];
    p[1].waist = [8.0, 0.0];
}

/// [`Move::ArmWave`]'s poses: feet home, knees bouncing on every beat, one of three arm
/// patterns.
fn arm_wave(p: &mut [Pose; 4], at: Place, amp: f64, pattern: u8) {
    let home = at.home();
    p.iter_mut().for_each(|q| q.toes = home);
    for (k, q) in p.iter_mut().enumerate() {
        let down = k % 2 == 0;
        q.drop = if down { SOFT + 0.06 * amp } else { SOFT };
        q.weight = if k == 3 {
            0.5
        } else if down {
            0.35
        } else {
            0.65
        };
        q.waist[1] = if k == 3 {
            0.0
        } else if down {
            8.0
        } else {
            -8.0
        };
    }
    match pattern % 3 {
        0 => {
            p[0].arms = [arm(Arms::High), arm(Arms::Open)];
            p[1].arms = [arm(Arms::Open); 2];
            p[2].arms = [arm(Arms::Open), arm(Arms::High)];
        }
        1 => {
            let bent = [160.0, 30.0, 80.0];
            p[0].arms = [bent; 2];
            p[1].arms = [arm(Arms::High); 2];
            p[2].arms = [bent; 2];
        }
        _ => {
            let punch = [90.0, 0.0, 0.0];
            p[0].arms = [punch, arm(Arms::Hips)];
            p[1].arms = [arm(Arms::Hips), punch];
            p[2].arms = [punch, arm(Arms::Hips)];
        }
    }
}

/// [`Move::Turn`]'s poses: four steps turning by `angle` about the place's origin; arms open
/// (or `high`).
fn turn(p: &mut [Pose; 4], at: Place, amp: f64, angle: f64, high: bool) {
    // Turn about the place's origin; the feet step alternately to their places under the
    // new heading (the inside foot first), the other keeping its toe and heading.
    let first = foot(angle);
    let order = [first, 1 - first, first, 1 - first];
    let yaws = [angle / 3.0, 2.0 * angle / 3.0, angle, angle];
    for k in 0..4 {
        let turned = Place {
            origin: at.origin,
            yaw: at.yaw + yaws[k],
        };
        if k > 0 {
            p[k].toes = p[k - 1].toes;
            p[k].heading = p[k - 1].heading;
        }
        let i = order[k];
        let x = if i == 0 { STANCE } else { -STANCE };
        p[k].toes[i] = turned.at(x, 0.0, 0.0);
        p[k].heading[i] = turned.yaw;
        p[k].yaw = turned.yaw;
        p[k].weight = if k == 3 { 0.5 } else { weight_on(i, 0.65) };
        p[k].drop = SOFT + if k % 2 == 0 { 0.04 * amp } else { 0.0 };
        p[k].arms = if high {
            [arm(Arms::High); 2]
        } else {
            [arm(Arms::Open); 2]
        };
    }
}

/// [`Move::Kick`]'s poses: chamber, kick to the front (or the side) `height` high, chamber,
/// home.
fn kick(p: &mut [Pose; 4], at: Place, amp: f64, side: f64, front: bool, height: f64) {
    let home = at.home();
    let (kick, support) = (foot(side), 1 - foot(side));
    let hx = if kick == 0 { STANCE } else { -STANCE };
    let h = height * amp;
    let chamber = at.at(hx, 0.12, 0.22 * h / 0.45);
    let out = if front {
        at.at(hx, 0.45, h)
    } else {
        at.at(hx + side * 0.4 * h / 0.45, 0.05, 0.8 * h)
    };
    p[0].toes[kick] = chamber;
    p[1].toes[kick] = out;
    p[2].toes[kick] = chamber;
    p[3].toes = home;
    for q in &mut p[..3] {
        q.weight = weight_on(support, 0.92);
        q.drop = SOFT + 0.04;
    }
    p[3].weight = 0.5;
    let (ka, sa) = (kick, support);
    p[0].arms[ka] = arm(Arms::Hips);
    p[0].arms[sa] = arm(Arms::Hips);
    p[1].arms[ka] = arm(Arms::Open);
    p[1].arms[sa] = arm(Arms::Front);
    p[2].arms = p[0].arms;
    p[1].waist = [if front { -5.0 } else { 0.0 }, -8.0 * side];
}

/// [`Move::KneeDrop`]'s poses: the knees dropped `depth` in the first and third poses, one of
/// two arm patterns.
fn knee_drop(p: &mut [Pose; 4], at: Place, amp: f64, depth: f64, pattern: u8) {
    let home = at.home();
    p.iter_mut().for_each(|q| q.toes = home);
    let d = depth * amp;
    let (down, up) = if pattern.is_multiple_of(2) {
        ([40.0, 20.0, 10.0], arm(Arms::High))
    } else {
        ([150.0, 40.0, 60.0], [170.0, 5.0, 0.0])
    };
    p[0].drop = SOFT + d;
    p[0].waist = [18.0, 0.0];
    p[0].arms = [down; 2];
    p[1].arms = [up; 2];
    p[2].drop = SOFT + d;
    p[2].waist = [18.0, 0.0];
    p[2].arms = [down; 2];
    for q in p.iter_mut() {
        q.weight = 0.5;
    }
}

/// Orders of the six move families in a clip (cycled), one per clip (cycled).
const ORDERS: [[usize; 6]; 4] = [
    [0, 1, 2, 3, 4, 5],
    [2, 5, 0, 4, 1, 3],
    [1, 3, 5, 0, 2, 4],
    [4, 0, 3, 1, 5, 2],
];

/// The moves of clip `c` (bar by bar) and the arm position each bar ends in.
fn choreography(c: usize, bars: usize) -> Vec<(Move, Arms)> {
    let ends = [Arms::Low, Arms::Hips, Arms::Front, Arms::Open, Arms::High];
    let deg = PI / 180.0;
    (0..bars)
        .map(|b| {
            let k = c * 7 + b * 3 + b / 6;
            let h = (c * 31 + b * 17 + 5) % 8;
            let side = if h < 4 { 1.0 } else { -1.0 };
            let m = match ORDERS[c % ORDERS.len()][b % 6] {
                0 => Move::StepTouch {
                    side,
                    step: [0.18, 0.24, 0.14][k % 3],
                    pattern: (k % 3) as u8,
                },
                1 => Move::ArmWave {
                    pattern: (k % 3) as u8,
                },
                2 => Move::Grapevine {
                    side,
                    step: [0.18, 0.24][k % 2],
                    high: k.is_multiple_of(2),
                },
                3 => Move::Kick {
                    side,
                    front: k.is_multiple_of(2),
                    height: [0.45, 0.6][(k / 2) % 2],
                },
                4 => Move::Turn {
                    angle: side * [90.0, 180.0][k % 2] * deg,
                    high: k.is_multiple_of(3),
                },
                _ => Move::KneeDrop {
                    depth: [0.15, 0.26][k % 2],
                    pattern: (k / 2 % 2) as u8,
                },
            };
            (m, ends[(k + b) % ends.len()])
        })
        .collect()
}

/// The cosine ease e(u) = (1 − cos πu)/2 of a fraction u ∈ [0, 1].
pub fn ease(u: f64) -> f64 {
    0.5 * (1.0 - (PI * u.clamp(0.0, 1.0)).cos())
}

/// Angle interpolation along the shorter way.
fn lerp_angle(a: f64, b: f64, e: f64) -> f64 {
    let mut d = (b - a) % (2.0 * PI);
    if d > PI {
        d -= 2.0 * PI;
    } else if d < -PI {
        d += 2.0 * PI;
    }
    a + d * e
}

/// The pose between `a` and `b` at the fraction u of a beat; a toe that moves lifts on the arc
/// [`STEP_LIFT`]·sin(πu).
fn between(a: &Pose, b: &Pose, u: f64) -> Pose {
    let e = ease(u);
    let mut p = *a;
    for i in 0..2 {
        let mut t = a.toes[i].lerp(b.toes[i], e);
        let moved = (DVec2::new(b.toes[i].x - a.toes[i].x, b.toes[i].z - a.toes[i].z)).length();
        if moved > 0.01 && a.toes[i].y < 1e-9 && b.toes[i].y < 1e-9 {
            t.y += STEP_LIFT * (PI * u).sin();
        }
        p.toes[i] = t;
        p.heading[i] = lerp_angle(a.heading[i], b.heading[i], e);
    }
    let l = |x: f64, y: f64| x + (y - x) * e;
    p.weight = l(a.weight, b.weight);
    p.yaw = lerp_angle(a.yaw, b.yaw, e);
    p.drop = l(a.drop, b.drop);
    for k in 0..2 {
        p.waist[k] = l(a.waist[k], b.waist[k]);
        for j in 0..3 {
            p.arms[k][j] = l(a.arms[k][j], b.arms[k][j]);
        }
    }
    p
}

/// The leg of humanoid24 as inverse kinematics needs it.
#[derive(Debug, Clone, Copy)]
struct Leg {
    /// Hip joint offset from the pelvis, metres.
    hip: DVec3,
    /// Thigh and shin lengths, metres.
    thigh: f64,
    shin: f64,
    /// The toe (End Site) from the ankle in the shin's frame, metres.
    toe: DVec3,
    /// The hip's three DOF axes and the knee's (pelvis frame at rest).
    hip_axes: [DVec3; 3],
    knee_axis: DVec3,
}

impl Leg {
    fn of(model: &Figure, side: &str) -> Leg {
        let j = |n: &str| {
            model
                .joint_index(&format!("{side}_{n}"))
                .expect("humanoid24 has the leg joints")
        };
        let (hip, knee, ankle) = (j("hip"), j("knee"), j("ankle"));
        let axes = model.joint_axes(hip);
        Leg {
            hip: model.joints[hip].offset,
            thigh: model.joints[knee].offset.length(),
            shin: model.joints[ankle].offset.length(),
            toe: model.joints[ankle].end_site.unwrap_or_default(),
            hip_axes: [axes[0], axes[1], axes[2]],
            knee_axis: model.joint_axes(knee)[0],
        }
    }
}

/// Inverse kinematics of one leg to its toe: the hip's three DOF angles and the knee angle
/// (radians) that put the toe at `toe` (world) for the pelvis at `pelvis` turned by `rot`.
/// humanoid24's ankle is rigid, so the hip–toe distance D depends on the knee angle κ alone:
/// with s the knee–toe vector (shin plus toe offset) at rest, D² = L₁² + |s|² + 2L₁|s|cos(κ − κ₀),
/// κ₀ = atan2(s_z, −s_y) (about 22°), solved on the branch κ ≥ κ₀ (knee forward; D beyond reach
/// gives κ₀, the leg pointing at the toe). The hip rotation takes the rest leg bent by κ onto
/// the hip–toe direction with the knee's plane through a yaw that, with `square`, is corrected
/// by fixed point ([`IK_ROUNDS`] rounds) until the foot points along `heading`.
fn leg_ik(
    leg: &Leg,
    pelvis: DVec3,
    rot: DQuat,
    toe: DVec3,
    heading: f64,
    square: bool,
) -> ([f64; 3], f64) {
    let hip = pelvis + rot * leg.hip;
    let inv = rot.inverse();
    let p = inv * (toe - hip);
    let s = DVec3::new(0.0, -leg.shin, 0.0) + leg.toe;
    let kappa0 = s.z.atan2(-s.y);
    let c = ((p.length_squared() - leg.thigh * leg.thigh - s.length_squared())
        / (2.0 * leg.thigh * s.length()))
    .clamp(-1.0, 1.0);
    let kappa = kappa0 + c.acos();
    let knee = DQuat::from_axis_angle(leg.knee_axis, kappa);
    let rest = DVec3::new(0.0, -leg.thigh, 0.0) + knee * s;
    let basis = |a: DVec3, f: DVec3| -> DMat3 {
        let u1 = a.normalize();
        let u2 = (f - f.dot(u1) * u1).normalize_or(DVec3::Z);
        DMat3::from_cols(u1, u2, u1.cross(u2))
    };
    let rest_basis = basis(rest, DVec3::Z).transpose();
    let dir = p.normalize_or(DVec3::NEG_Y);
    let mut plane = heading;
    let mut q = DQuat::IDENTITY;
    for _ in 0..IK_ROUNDS {
        let forward = inv * DVec3::new(plane.sin(), 0.0, plane.cos());
        q = DQuat::from_mat3(&(basis(dir, forward) * rest_basis)).normalize();
        if !square {
            break;
        }
        let f = rot * q * knee * leg.toe;
        let err = lerp_angle(f.x.atan2(f.z), heading, 1.0) - f.x.atan2(f.z);
        if err.abs() < 1e-10 {
            break;
        }
        plane += err;
    }
    let (axis, angle) = q.to_axis_angle();
    let w = axis * if angle > PI { angle - 2.0 * PI } else { angle };
    (
        [
            w.dot(leg.hip_axes[0]),
            w.dot(leg.hip_axes[1]),
            w.dot(leg.hip_axes[2]),
        ],
        kappa,
    )
}

/// A foot whose toe is lower than this (metres) is turned to its heading by [`leg_ik`].
const SQUARE_BELOW: f64 = 0.1;

/// Fixed-point rounds of [`leg_ik`].
const IK_ROUNDS: usize = 30;

/// How far the pelvis stands behind the weighted toes: over the ankles, metres.
const BEHIND: f64 = 0.19;

/// The pelvis stands this much lower than the planted toes' full reach (soft knees), metres.
const SLACK: f64 = 0.002;

/// The farthest a toe gets from its hip: the hip–toe distance depends on the knee angle alone,
/// and is largest, L₁ + |s| with s the knee–toe vector (shin plus toe offset), when the thigh
/// lines up with s (the knee bent about 22°, as the toe sits in front of the shin), metres.
fn full_reach(leg: &Leg) -> f64 {
    leg.thigh + (DVec3::new(0.0, -leg.shin, 0.0) + leg.toe).length()
}

/// Standing pelvis height of the model with the toes on the floor, metres.
fn standing_height(model: &Figure) -> f64 {
    let leg = Leg::of(model, "left");
    leg.thigh + leg.shin - leg.toe.y
}

/// Generates the dance (module docs). Errors: parameters out of range.
pub fn generate(p: &AuthoredDance) -> Result<Vec<AuthoredClip>, AuthoredError> {
    let bad = |name, value, expected| AuthoredError::Parameter {
        name,
        value,
        expected,
    };
    if !(p.bpm.is_finite() && (60.0..=180.0).contains(&p.bpm)) {
        return Err(bad("bpm", p.bpm, "60 to 180"));
    }
    if !(1..=64).contains(&p.clips) {
        return Err(bad("clips", p.clips as f64, "1 to 64"));
    }
    if !(1..=256).contains(&p.bars_per_clip) {
        return Err(bad("bars_per_clip", p.bars_per_clip as f64, "1 to 256"));
    }
    if !(p.fps.is_finite() && (10.0..=240.0).contains(&p.fps)) {
        return Err(bad("fps", p.fps, "10 to 240"));
    }
    if !(p.amplitude.is_finite() && (0.0..=1.5).contains(&p.amplitude)) {
        return Err(bad("amplitude", p.amplitude, "0 to 1.5"));
    }
    Ok((0..p.clips).map(|c| generate_clip(p, c)).collect())
}

/// Clip `c` of the dance.
fn generate_clip(p: &AuthoredDance, c: usize) -> AuthoredClip {
    let model = humanoid24();
    let plan = choreography(c, p.bars_per_clip);
    let poses = count_poses(&plan, p.amplitude);
    let beat = 60.0 / p.bpm;
    let counts = poses.len() - 1;
    // One more beat holding the last pose, so that the last bar is whole after its first beat.
    let frames = ((counts as f64 + 1.0) * beat * p.fps).ceil() as usize;
    let dofs = DanceDofs::of(&model);
    let legs = [Leg::of(&model, "left"), Leg::of(&model, "right")];
    let stand = standing_height(&model);
    let mut motion = FigureClip::with_capacity(model.clone(), 1.0 / p.fps, frames);
    for f in 0..frames {
        let t = f as f64 / p.fps;
        let x = t / beat;
        let k = (x.floor() as usize).min(counts);
        let pose = if k >= counts {
            poses[counts]
        } else {
            between(&poses[k], &poses[k + 1], x - k as f64)
        };
        let (pelvis, rot) = pelvis_place(&pose, &legs, stand);
        let angles = pose_angles(&pose, pelvis, rot, &legs, &dofs);
        motion.root_translation.push(pelvis);
        motion.root_rotation.push(rot);
        motion.angles.extend(angles);
    }
    AuthoredClip {
        name: format!("authored_{c}"),
        moves: plan.iter().map(|(m, _)| m.describe()).collect(),
        families: plan.iter().map(|(m, _)| m.family()).collect(),
        motion,
    }
}

/// Every count's pose of the moves `plan`: the first stands square at the origin, each move
/// adds its four from where the last left off.
fn count_poses(plan: &[(Move, Arms)], amplitude: f64) -> Vec<Pose> {
    let neutral = Pose {
        toes: [DVec3::new(STANCE, 0.0, 0.0), DVec3::new(-STANCE, 0.0, 0.0)],
        heading: [0.0; 2],
        weight: 0.5,
        yaw: 0.0,
        drop: SOFT,
        waist: [0.0; 2],
        arms: [arm(Arms::Low); 2],
    };
    let mut poses = vec![neutral];
    for &(m, end) in plan {
        let last = *poses.last().expect("one pose at least");
        let mid = 0.5 * (last.toes[0] + last.toes[1]);
        let place = Place {
            origin: DVec2::new(mid.x, mid.z),
            yaw: last.yaw,
        };
        poses.extend(move_poses(m, &last, place, amplitude, end));
    }
    poses
}

/// The humanoid24 DOFs a pose sets.
struct DanceDofs {
    /// All DOFs of the model.
    count: usize,
    /// Each leg's hip flexion, abduction and rotation and knee, `[left, right]`.
    legs: [[usize; 4]; 2],
    /// Each arm's shoulder flexion and abduction and elbow flexion, `[left, right]`.
    arms: [[usize; 3]; 2],
    /// The waist's flexion and lateral bend.
    waist: [usize; 2],
}

impl DanceDofs {
    fn of(model: &Figure) -> DanceDofs {
        let dof = |n: &str| model.dof_index(n).expect("humanoid24 DOF");
        DanceDofs {
            count: model.dofs.len(),
            legs: ["left", "right"].map(|s| {
                [
                    dof(&format!("{s}_hip_flexion")),
                    dof(&format!("{s}_hip_abduction")),
                    dof(&format!("{s}_hip_rotation")),
                    dof(&format!("{s}_knee")),
                ]
            }),
            arms: ["left", "right"].map(|s| {
                [
                    dof(&format!("{s}_shoulder_flexion")),
                    dof(&format!("{s}_shoulder_abduction")),
                    dof(&format!("{s}_elbow_flexion")),
                ]
            }),
            waist: [dof("waist_flexion"), dof("waist_lateral")],
        }
    }
}

/// The pelvis of `pose`: behind the weighted toes, as high as the planted toes' full reach
/// less the slack and the drop allow (standing height less the drop when none is planted),
/// turned to the pose's yaw.
fn pelvis_place(pose: &Pose, legs: &[Leg; 2], stand: f64) -> (DVec3, DQuat) {
    let rot = DQuat::from_rotation_y(pose.yaw);
    let over = pose.toes[0].lerp(pose.toes[1], pose.weight);
    let back = rot * DVec3::new(0.0, 0.0, -BEHIND);
    let mut pelvis = DVec3::new(over.x, 0.0, over.z) + back;
    // The pelvis height: the planted toes at their full reach less the slack and the drop.
    pelvis.y = f64::INFINITY;
    for (i, leg) in legs.iter().enumerate() {
        if pose.toes[i].y > 1e-9 {
            continue;
        }
        let hip = pelvis + rot * leg.hip;
        let flat = DVec2::new(hip.x - pose.toes[i].x, hip.z - pose.toes[i].z).length();
        let reach = full_reach(leg) - SLACK - pose.drop;
        pelvis.y = pelvis
            .y
            .min(pose.toes[i].y + (reach * reach - flat * flat).max(0.0).sqrt());
    }
    if !pelvis.y.is_finite() {
        pelvis.y = stand - pose.drop;
    }
    (pelvis, rot)
}

/// The joint angles of `pose` with the pelvis at `pelvis` turned by `rot`: the legs by
/// [`leg_ik`] to the toes, the arms and the waist as the pose has them.
fn pose_angles(
    pose: &Pose,
    pelvis: DVec3,
    rot: DQuat,
    legs: &[Leg; 2],
    dofs: &DanceDofs,
) -> Vec<f64> {
    let mut angles = vec![0.0; dofs.count];
    for (i, leg) in legs.iter().enumerate() {
        let square = pose.toes[i].y < SQUARE_BELOW;
        let (h, knee) = leg_ik(leg, pelvis, rot, pose.toes[i], pose.heading[i], square);
        for j in 0..3 {
            angles[dofs.legs[i][j]] = h[j];
        }
        angles[dofs.legs[i][3]] = knee;
    }
    for i in 0..2 {
        for j in 0..3 {
            angles[dofs.arms[i][j]] = pose.arms[i][j].to_radians();
        }
    }
    angles[dofs.waist[0]] = pose.waist[0].to_radians();
    angles[dofs.waist[1]] = pose.waist[1].to_radians();
    angles
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leg_ik_puts_the_toe_on_its_target() {
        let model = humanoid24();
        let clip = FigureClip {
            model: model.clone(),
            frame_time: 0.1,
            root_translation: vec![DVec3::new(0.05, 0.82, 0.02)],
            root_rotation: vec![DQuat::from_rotation_y(0.4)],
            angles: vec![0.0; model.dofs.len()],
        };
        for (side, target, heading, square) in [
            ("left", DVec3::new(0.2, 0.0, 0.25), 0.6, true),
            ("right", DVec3::new(-0.15, 0.0, 0.1), 0.1, true),
            ("right", DVec3::new(-0.1, 0.3, 0.5), 0.4, false),
        ] {
            let leg = Leg::of(&model, side);
            let (h, k) = leg_ik(
                &leg,
                clip.root_translation[0],
                clip.root_rotation[0],
                target,
                heading,
                square,
            );
            let mut c = clip.clone();
            for (j, n) in ["hip_flexion", "hip_abduction", "hip_rotation"]
                .iter()
                .enumerate()
            {
                c.angles[model.dof_index(&format!("{side}_{n}")).unwrap()] = h[j];
            }
            c.angles[model.dof_index(&format!("{side}_knee")).unwrap()] = k;
            let sk = c.model.skeleton();
            let names = sk.point_names();
            let toe = names
                .iter()
                .position(|n| n == &format!("{side}_ankle_end"))
                .unwrap();
            let ankle = names
                .iter()
                .position(|n| n == &format!("{side}_ankle"))
                .unwrap();
            let pts = &c.to_clip().point_frames()[0];
            assert!(
                (pts[toe] - target).length() < 1e-3,
                "{side}: {:?}",
                pts[toe]
            );
            let f = pts[toe] - pts[ankle];
            let yaw = f.x.atan2(f.z);
            if square {
                assert!((yaw - heading).abs() < 1e-3, "{side}: heading {yaw}");
            }
        }
    }

    /// Heights and horizontal speeds of both toes and ankles, per frame.
    fn feet(c: &FigureClip) -> Vec<[DVec3; 4]> {
        let names = c.model.skeleton().point_names();
        let idx: Vec<usize> = [
            "left_ankle",
            "left_ankle_end",
            "right_ankle",
            "right_ankle_end",
        ]
        .iter()
        .map(|n| names.iter().position(|m| m == n).unwrap())
        .collect();
        c.to_clip()
            .point_frames()
            .iter()
            .map(|p| [p[idx[0]], p[idx[1]], p[idx[2]], p[idx[3]]])
            .collect()
    }

    #[test]
    fn the_kinematic_beat_finds_the_tempo_and_feet_stay_on_the_floor() {
        for bpm in [96.0, 118.0, 137.5] {
            let p = AuthoredDance {
                bpm,
                ..AuthoredDance::default()
            };
            for clip in generate(&p).unwrap() {
                let b = crate::choreo::segments::kinematic_beat(&clip.motion, &clip.name, None)
                    .unwrap();
                eprintln!(
                    "{bpm} {}: {:.2} BPM, first beat {:.3} s",
                    clip.name, b.tempo_bpm, b.first_beat_s
                );
                assert!(
                    (b.tempo_bpm / bpm - 1.0).abs() < 0.01,
                    "{}: {}",
                    clip.name,
                    b.tempo_bpm
                );
                let fs = feet(&clip.motion);
                let lowest = fs
                    .iter()
                    .flatten()
                    .map(|p| p.y)
                    .fold(f64::INFINITY, f64::min);
                assert!(lowest > -1e-4, "{}: a foot at {lowest} m", clip.name);
                // A toe on the floor does not slide: its horizontal speed while within 1 mm of it.
                let dt = clip.motion.frame_time;
                let mut worst: f64 = 0.0;
                for w in fs.windows(2) {
                    for k in [1, 3] {
                        if w[0][k].y < 1e-3 && w[1][k].y < 1e-3 {
                            let v = DVec2::new(w[1][k].x - w[0][k].x, w[1][k].z - w[0][k].z)
                                .length()
                                / dt;
                            worst = worst.max(v);
                        }
                    }
                }
                eprintln!("  lowest {lowest:.4} m, planted toe speed {worst:.4} m/s");
                assert!(
                    worst < 0.05,
                    "{}: a planted toe slides at {worst} m/s",
                    clip.name
                );
            }
        }
    }

    #[test]
    fn written_as_bvh_the_database_finds_the_tempo() {
        let p = AuthoredDance {
            bpm: 107.0,
            clips: 2,
            ..AuthoredDance::default()
        };
        let clips = generate(&p).unwrap();
        let dir = std::env::temp_dir().join(format!("marionette-authored-{}", std::process::id()));
        let files = write_bvh_folder(&clips, &dir).unwrap();
        assert_eq!(files.len(), 2);
        let manifest = crate::choreo::database::Manifest::from_folder(&dir).unwrap();
        let db = crate::choreo::database::Database::build(
            &manifest,
            &crate::choreo::database::BuildParams::default(),
            crate::choreo::database::OnRefusal::Fail,
            |_, _| {},
        )
        .unwrap();
        for s in &db.sources {
            eprintln!("{}: {:.2} BPM", s.file, s.beat.tempo_bpm);
            assert!(
                (s.beat.tempo_bpm / 107.0 - 1.0).abs() < 0.01,
                "{}",
                s.beat.tempo_bpm
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn moves_are_distinct_by_eros() {
        use crate::choreo::database::{BuildParams, Database};
        use crate::choreo::eros::eros;
        let p = AuthoredDance::default();
        let clips = generate(&p).unwrap();
        let beat = crate::choreo::segments::Beat {
            tempo_bpm: p.bpm,
            first_beat_s: 0.0,
            source: crate::choreo::segments::TempoSource::Manifest,
        };
        let named: Vec<_> = clips
            .iter()
            .map(|c| (c.name.clone(), c.motion.clone(), Some(beat)))
            .collect();
        let db = Database::from_clips(&named, &BuildParams::default()).unwrap();
        assert_eq!(db.segments.len(), p.clips * p.bars_per_clip);
        let family = |i: usize| {
            let s = &db.segments[i];
            clips[s.clip].families[s.bar]
        };
        let sim =
            |i: usize, j: usize| eros(&db.segments[i].eros, &db.segments[j].eros, &db.eros_weights);
        // No two segments are as alike as a segment with itself (Eros 1): the database holds
        // real choices; segments of different move families are less alike still.
        let n = db.segments.len();
        let (mut any, mut across) = (0.0f64, 0.0f64);
        for i in 0..n {
            assert!((sim(i, i) - 1.0).abs() < 1e-9);
            for j in (0..n).filter(|&j| j != i) {
                any = any.max(sim(i, j));
                if family(j) != family(i) {
                    across = across.max(sim(i, j));
                }
            }
        }
        eprintln!("most alike: any two segments {any:.4}, of different moves {across:.4}");
        assert!(any < 0.99, "{any}");
        assert!(across < 0.95, "{across}");
    }

    #[test]
    fn bad_parameters_are_refused() {
        for p in [
            AuthoredDance {
                bpm: 20.0,
                ..AuthoredDance::default()
            },
            AuthoredDance {
                clips: 0,
                ..AuthoredDance::default()
            },
            AuthoredDance {
                fps: f64::NAN,
                ..AuthoredDance::default()
            },
        ] {
            assert!(generate(&p).is_err());
        }
    }
}
