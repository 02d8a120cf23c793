//! Feet on the floor: an assembled dance's planted feet put on the floor (y = 0) and held still,
//! by two-bone leg inverse kinematics ([`crate::humanoid::leg_ik`]), the pelvis lowered where
//! the legs cannot reach the floor otherwise.
//!
//! Segments from different clips, time-resized to the song's bars and joined at seams, put the
//! feet a little in or above the floor and let a planted foot slide where its sources did not.
//! This puts them back, per leg:
//!
//! - **Sole height.** A foot point's sole height is its height minus its height in the model's
//!   rest pose standing on the floor (the toe End Site 0, the ankle joint its height above the
//!   sole, about 6 cm on humanoid24), and the foot's sole height s(f) the lowest of its points':
//!   0 when the foot stands on the floor, toe or heel down.
//! - **Contact.** A foot is in contact in the frames where [`ground_contacts_against`] finds it
//!   contact against the floor y = 0 and the model's rest heights: some point within
//!   [`ContactConfig::threshold_m`] of its rest height (debounced).
//! - **Ground.** A contact span is moved onto the floor, and a foot that stands in it is held
//!   there (with [`PlantParams::ground`]): c_y(f) = −L − w(f)·(s(f) − L), L the span's lowest
//!   sole. w = 1 where the sole rises or sinks slower than half the speed of a foot point at
//!   rest ([`ContactConfig::rest_speed_mps`]): the foot stands, its lowest point (toe or heel:
//!   a rigid foot rocks with the shin) on the floor in every frame. w = 0 from that speed on:
//!   the foot is lifting off or landing and keeps its own height above the span's floor (held
//!   down, it would drag along the floor). A smoothstep between. A foot the analysis calls in
//!   contact is within [`ContactConfig::threshold_m`] of the floor, so this moves it a few
//!   centimetres. The spans are found once, on the dance as assembled: lowering the pelvis does
//!   not change when a foot stands.
//! - **Lift.** Wherever else the sole is under the floor the foot is lifted onto it: c_y(f) ≥
//!   −s(f). Outside the spans and their fades nothing is pulled down: a swinging foot is not made
//!   to touch the floor (and skate on it).
//! - **Lock.** A contact span whose contact point (the foot point lowest relative to its rest
//!   height on average over the span) slides, its mean horizontal speed over the span above
//!   [`ContactConfig::rest_speed_mps`] (the speed under which the contact analysis calls a
//!   point at rest), is held still: c(f) = a − p(f) horizontally, a the contact point's mean
//!   horizontal position over the span. In the free frames next to it the correction fades to
//!   0 over [`PlantParams::blend_s`] along a cubic Hermite curve that leaves the span with the
//!   correction's own horizontal rate, so the foot lifts off and lands without a jolt (between
//!   two spans closer than two blends, the curve runs from the one's edge to the other's). The
//!   vertical rate starts at 0: the foot leaves the floor at its own speed.
//! - **Smoothing.** The corrections are smoothed over time by a Gaussian of σ =
//!   [`PlantParams::smooth_s`] (the sole's height switches between toe and heel as the foot
//!   rolls: a kink the knee would follow), then the lift is applied again as a floor.
//! - **Cap.** A leg is never asked to stretch further than the dancer stretched it: the
//!   hip–ankle distance of a target is at most the largest the leg had, as assembled, within
//!   [`PlantParams::blend_s`] of the frame (a target beyond is raised to that distance). A
//!   retargeted dancer whose pelvis is carried high for the new legs would otherwise have a
//!   knee snap straight to put a foot down.
//! - **Pelvis.** Where a foot in contact cannot reach its target within the cap, the pelvis is
//!   lowered by what is missing (with [`PlantParams::pelvis`]): the most over both feet in
//!   contact, held over ±`blend_s` and smoothed by a Gaussian of σ = `blend_s`/3, so it settles
//!   and rises as smoothly as a correction fades. The corrections are then found again for the
//!   lowered dance.
//! - **Reach.** The ankle is sent to its own position plus c(f) (within the cap) by the leg's
//!   IK, and the foot's residual (the foot turns a little with the shin, since humanoid24 has no
//!   ankle DOF) is added to the target again, [`IK_ROUNDS`] times at most. Where a standing
//!   foot is left more than [`FOOT_DOWN_M`] above its target (at the cap, the foot's turn asks
//!   for more than the ankle's target showed), the pelvis comes down by that shortfall too (held
//!   and smoothed as above) and the legs reach again, once.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::analysis::{
    ContactConfig, ContactReference, Contacts, PointRef, foot_points, ground_contacts_against,
};
use crate::humanoid::leg_ik::{Leg, chain_globals, frame_globals, reach_along, with_ancestors};
use crate::humanoid::{FOOT_DOWN_M, FigureClip};
use crate::skeleton::{Skeleton, Transform};

/// Most rounds of IK per frame and leg: the target corrected by the foot's residual each round
/// (about halved each round), until it is under 0.1 mm.
pub const IK_ROUNDS: usize = 8;

/// How feet are planted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlantParams {
    /// Plant the feet at all (false: the dance as assembled, feet wherever the segments put
    /// them).
    pub enabled: bool,
    /// Hold a planted foot's contact point still over its contact span (false: only heights
    /// are corrected).
    pub lock: bool,
    /// Put a standing foot on the floor: each contact span moved by one height, down as well
    /// as up, so its lowest sole is at y = 0 (false: a foot is only lifted out of the floor, and
    /// one in contact may hover).
    pub ground: bool,
    /// Lower the pelvis where a standing foot cannot reach the floor with its knee no
    /// straighter than the dancer's own (module docs, "Pelvis"); false: the pelvis stays where
    /// the dance puts it.
    pub pelvis: bool,
    /// Time over which a correction fades in and out around a contact span, seconds.
    pub blend_s: f64,
    /// σ of the Gaussian the corrections are smoothed with over time, seconds (0: none): the
    /// sole's height switches between the toe and the heel as the foot rolls, a kink the knee
    /// would follow.
    pub smooth_s: f64,
}

impl Default for PlantParams {
    /// Planted and locked, corrections fading over 0.2 s, smoothed with σ = 0.05 s.
    fn default() -> PlantParams {
        PlantParams {
            enabled: true,
            lock: true,
            ground: true,
            pelvis: true,
            blend_s: 0.2,
            smooth_s: 0.05,
        }
    }
}

/// What planting did.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Planting {
    /// Contact spans found (both feet).
    pub spans: usize,
    /// Contact spans whose sliding foot was held still.
    pub locked: usize,
    /// Frames × legs moved.
    pub leg_frames: usize,
    /// Largest correction asked of a foot, metres.
    pub max_correction_m: f64,
    /// Largest distance left between a foot and its target (out of the leg's reach), metres.
    pub max_residual_m: f64,
    /// Most the pelvis was lowered, metres (0 without [`PlantParams::pelvis`]).
    pub pelvis_drop_max_m: f64,
    /// Frames × feet standing: in a contact span, the sole neither lifting off nor landing
    /// (module docs, "Ground").
    pub planted_foot_frames: usize,
    /// Of those, the fraction whose sole ends within ±1 cm of the floor ([`FOOT_DOWN_M`]; the
    /// others are out of the leg's reach, or without [`PlantParams::ground`]); 0 when no foot
    /// stood.
    pub planted_on_floor_fraction: f64,
}

/// Sole height of every foot point: its height in the rest pose of `clip.model` standing on the
/// floor, `[left, right]` in [`foot_points`] order, metres.
pub fn rest_sole_heights(clip: &FigureClip) -> [Vec<f64>; 2] {
    let skeleton = clip.model.skeleton();
    let feet = foot_points(&skeleton);
    let mut g = vec![];
    let d = clip.dof_count();
    frame_globals(
        &clip.model,
        DVec3::ZERO,
        glam::DQuat::IDENTITY,
        &vec![0.0; d],
        &mut g,
    );
    let ys: [Vec<f64>; 2] =
        [0, 1].map(|s| feet[s].iter().map(|&p| point(&skeleton, &g, p).y).collect());
    let lowest = ys.iter().flatten().copied().fold(f64::INFINITY, f64::min);
    ys.map(|v| v.into_iter().map(|y| y - lowest).collect())
}

/// The global position of a foot point (a joint, or with `true` its End Site).
fn point(skeleton: &crate::skeleton::Skeleton, g: &[Transform], (j, end): (usize, bool)) -> DVec3 {
    if end {
        g[j].translation + g[j].rotation * skeleton.joints[j].end_site.unwrap_or_default()
    } else {
        g[j].translation
    }
}

/// The frames `[first, end)` of every run of `on`.
fn runs(on: &[bool]) -> Vec<(usize, usize)> {
    let mut out = vec![];
    let mut start = None;
    for (f, &x) in on.iter().chain(std::iter::once(&false)).enumerate() {
        match (x, start) {
            (true, None) => start = Some(f),
            (false, Some(s)) => {
                out.push((s, f));
                start = None;
            }
            _ => {}
        }
    }
    out
}

/// `x` smoothed by a Gaussian of σ = `sigma` frames (truncated at 3σ), the ends continued by
/// point reflection (x(−k) = 2x(0) − x(k)), so that a straight course is kept to the last
/// frame; `x` itself for σ under a tenth of a frame.
fn gaussian(x: &[DVec3], sigma: f64) -> Vec<DVec3> {
    let n = x.len();
    if sigma < 0.1 || n < 2 {
        return x.to_vec();
    }
    let r = (3.0 * sigma).ceil() as usize;
    let w: Vec<f64> = (0..=r)
        .map(|k| (-0.5 * (k as f64 / sigma).powi(2)).exp())
        .collect();
    let total = w[0] + 2.0 * w[1..].iter().sum::<f64>();
    let at = |i: isize| -> DVec3 {
        let last = n as isize - 1;
        if i < 0 {
            x[0] * 2.0 - x[((-i).min(last)) as usize]
        } else if i > last {
            x[n - 1] * 2.0 - x[((2 * last - i).max(0)) as usize]
        } else {
            x[i as usize]
        }
    };
    (0..n as isize)
        .map(|f| {
            let mut sum = at(f) * w[0];
            for (k, wk) in w.iter().enumerate().skip(1) {
                sum += (at(f - k as isize) + at(f + k as isize)) * *wk;
            }
            sum / total
        })
        .collect()
}

/// The cubic Hermite curve from `c0` (rate `v0` per frame) at frame 0 to `c1` (rate `v1`) at
/// frame `len`, at frame `at`: position and rate continuous at both ends.
fn hermite(c0: DVec3, v0: DVec3, c1: DVec3, v1: DVec3, len: usize, at: usize) -> DVec3 {
    let l = len.max(1) as f64;
    let u = (at as f64 / l).clamp(0.0, 1.0);
    let (u2, u3) = (u * u, u * u * u);
    c0 * (2.0 * u3 - 3.0 * u2 + 1.0)
        + v0 * (l * (u3 - 2.0 * u2 + u))
        + c1 * (-2.0 * u3 + 3.0 * u2)
        + v1 * (l * (u3 - u2))
}

/// Plants the feet of `clip` (module docs); a model without two legs ([`Leg::of`]) or feet is
/// left as it is.
pub fn plant_feet(clip: &mut FigureClip, p: &PlantParams) -> Planting {
    let mut report = Planting::default();
    let n = clip.frame_count();
    let legs = [Leg::of(&clip.model, "left"), Leg::of(&clip.model, "right")];
    let skeleton = clip.model.skeleton();
    let feet = foot_points(&skeleton);
    if !p.enabled || n < 2 || feet.iter().any(Vec::is_empty) || legs.iter().any(Option::is_none) {
        return report;
    }
    let joints: Vec<usize> = feet.iter().flatten().map(|p| p.0).collect();
    let model = Feet {
        rest: rest_sole_heights(clip),
        chain: with_ancestors(&clip.model, &joints),
        skeleton,
        points: feet,
    };
    let legs = legs.map(|l| l.expect("checked above"));
    let blend = (p.blend_s / clip.frame_time).round().max(1.0) as usize;
    let (mut before, reach) = placed(clip, &legs, &model, blend);
    let config = ContactConfig::default();
    let contacts = floor_contacts(clip, &before, &model.rest, &config);
    let mut plan = self::plan(clip, &model, &before, &contacts, p, blend, &mut report);
    let mut dropped = vec![0.0; n];
    // Lowers the pelvis by `drop` more and plans again: lowering the root moves every joint by
    // as much, so the places are shifted, not placed again; the contact spans stay (lowering
    // the pelvis so a foot reaches the floor does not change when it stands).
    let mut lower = |clip: &mut FigureClip,
                     before: &mut Vec<[Vec<DVec3>; 2]>,
                     drop: &[f64],
                     report: &mut Planting| {
        for (f, r) in drop.iter().enumerate() {
            let down = DVec3::Y * *r;
            clip.root_translation[f] -= down;
            before[f].iter_mut().flatten().for_each(|x| *x -= down);
            dropped[f] += r;
        }
        *report = Planting {
            pelvis_drop_max_m: dropped.iter().copied().fold(0.0, f64::max),
            ..Planting::default()
        };
        self::plan(clip, &model, before, &contacts, p, blend, report)
    };
    if p.pelvis {
        let drop = pelvis_drop(&plan, &reach, blend);
        if drop.iter().any(|&d| d > 1e-6) {
            plan = lower(clip, &mut before, &drop, &mut report);
        }
    }
    let angles = clip.angles.clone();
    let mut reached = reach_targets(clip, &legs, &model, &before, &plan, &reach.cap);
    let short: Vec<f64> = reached.iter().map(|r| r.short).collect();
    if p.pelvis && short.iter().any(|&s| s > FOOT_DOWN_M) {
        // A standing foot the leg left short of the floor at its longest stretch (the foot
        // turns with the shin as the leg straightens, which the ankle's target alone does not
        // show): the pelvis comes down by the shortfall too, and the legs reach again from
        // the dance's own angles for the new plan.
        let drop = held_drop(&short, blend);
        clip.angles = angles;
        plan = lower(clip, &mut before, &drop, &mut report);
        reached = reach_targets(clip, &legs, &model, &before, &plan, &reach.cap);
    }
    tally(&reached, &mut report);
    report
}

/// What the legs of one frame did ([`reach_targets`]).
#[derive(Debug, Clone, Copy, Default)]
struct Reached {
    /// Legs moved.
    legs_moved: usize,
    /// The largest distance left between a foot and its target, metres.
    residual: f64,
    /// Feet standing.
    standing: usize,
    /// Feet standing with their sole within ±[`FOOT_DOWN_M`] of the floor.
    on_floor: usize,
    /// The most a standing foot's sole was left above its target, metres (0 if none).
    short: f64,
}

/// The report's figures of what the legs did, frame by frame.
fn tally(reached: &[Reached], report: &mut Planting) {
    let mut on_floor = 0;
    report.planted_foot_frames = 0;
    for r in reached {
        report.leg_frames += r.legs_moved;
        report.max_residual_m = report.max_residual_m.max(r.residual);
        report.planted_foot_frames += r.standing;
        on_floor += r.on_floor;
    }
    report.planted_on_floor_fraction = if report.planted_foot_frames == 0 {
        0.0
    } else {
        on_floor as f64 / report.planted_foot_frames as f64
    };
}

/// Where each foot is to go, per foot and frame.
struct Plan {
    /// The correction and the contact point it is measured on (`None`: nothing to do).
    targets: [Vec<Option<(DVec3, usize)>>; 2],
    /// In a contact span.
    on: [Vec<bool>; 2],
    /// Standing: in a contact span, neither lifting off nor landing (its sole put on the floor).
    stand: [Vec<bool>; 2],
}

/// The [`Plan`] of `clip`, whose foot points are at `before` and whose feet touch in
/// `contacts` (module docs: ground, lift, lock, smoothing).
fn plan(
    clip: &FigureClip,
    model: &Feet,
    before: &[[Vec<DVec3>; 2]],
    contacts: &Contacts,
    p: &PlantParams,
    blend: usize,
    report: &mut Planting,
) -> Plan {
    let n = clip.frame_count();
    let rest = &model.rest;
    let config = ContactConfig::default();
    let mut targets: [Vec<Option<(DVec3, usize)>>; 2] = [vec![None; n], vec![None; n]];
    let mut ons: [Vec<bool>; 2] = [vec![], vec![]];
    let mut stands: [Vec<bool>; 2] = [vec![], vec![]];
    for (side, spans) in [&contacts.left, &contacts.right].into_iter().enumerate() {
        let foot = FootTrack {
            before,
            side,
            rest: &rest[side],
            sole: before
                .iter()
                .map(|b| sole_height(&b[side], &rest[side]))
                .collect(),
            frame_time: clip.frame_time,
        };
        let on: Vec<bool> = (0..n)
            .map(|f| {
                let t = f as f64 * clip.frame_time;
                spans
                    .iter()
                    .any(|s| t >= s.start_s - 1e-9 && t < s.end_s - 1e-9)
            })
            .collect();
        let planted = runs(&on);
        report.spans += planted.len();
        let (mut corr, mut key, stand) = hold_spans(&foot, &planted, p, &config, report);
        fade_free_frames(&on, &planted, blend, &mut corr, &mut key);
        targets[side] = smooth_and_floor(&foot, &corr, &key, p, report);
        ons[side] = on;
        stands[side] = stand;
    }
    Plan {
        targets,
        on: ons,
        stand: stands,
    }
}

/// The legs as the dance puts them (before any pelvis drop): per frame and leg, the hip's and
/// ankle's places, and the cap on the hip–ankle distance (the leg's straightest within a blend of the frame, so that
/// no foot is put down by a knee straighter than the dancer's own nearby).
struct LegReach {
    hip: Vec<[DVec3; 2]>,
    ankle: Vec<[DVec3; 2]>,
    cap: Vec<[f64; 2]>,
}

/// The foot points of `clip` at every frame ([`Feet::positions`]) and its [`LegReach`], the
/// cap taken over ±`blend` frames.
fn placed(
    clip: &FigureClip,
    legs: &[Leg; 2],
    model: &Feet,
    blend: usize,
) -> (Vec<[Vec<DVec3>; 2]>, LegReach) {
    use rayon::prelude::*;
    let n = clip.frame_count();
    type Placed = ([Vec<DVec3>; 2], ([DVec3; 2], [DVec3; 2]));
    let placed: Vec<Placed> = (0..n)
        .into_par_iter()
        .map_init(Vec::new, |g, f| {
            let feet = model.positions(clip, f, g);
            let legs = (
                legs.map(|l| g[l.hip].translation),
                legs.map(|l| g[l.ankle].translation),
            );
            (feet, legs)
        })
        .collect();
    let (before, legs): (Vec<_>, Vec<_>) = placed.into_iter().unzip();
    let (hip, ankle): (Vec<_>, Vec<_>) = legs.into_iter().unzip();
    let [left, right] = [0, 1].map(|s| {
        let length: Vec<f64> = (0..n).map(|f| (ankle[f][s] - hip[f][s]).length()).collect();
        window_max(&length, blend)
    });
    let cap = left.into_iter().zip(right).map(|(l, r)| [l, r]).collect();
    (before, LegReach { hip, ankle, cap })
}

/// The largest of `x` over frames f − `w` ..= f + `w` (within the clip) at every frame f, by a
/// monotone queue of the window's candidates: O(n) whatever `w`.
fn window_max(x: &[f64], w: usize) -> Vec<f64> {
    let n = x.len();
    let mut out = Vec::with_capacity(n);
    let mut queue = std::collections::VecDeque::new();
    let mut next = 0;
    for f in 0..n {
        // Take in frames up to f + w, dropping the candidates they outdo.
        while next < n && next <= f + w {
            while queue.back().is_some_and(|&j: &usize| x[j] <= x[next]) {
                queue.pop_back();
            }
            queue.push_back(next);
            next += 1;
        }
        while queue.front().is_some_and(|&j| j + w < f) {
            queue.pop_front();
        }
        out.push(x[*queue.front().expect("frame f is in its own window")]);
    }
    out
}

/// `target` (an ankle's place) raised, where the leg would have to reach further than `cap`
/// from the hip at `hip`, to the lowest place at that distance straight above or below it.
fn within_reach(target: DVec3, hip: DVec3, cap: f64) -> DVec3 {
    let d = target - hip;
    let across = d.x * d.x + d.z * d.z;
    if d.length_squared() > cap * cap && cap * cap > across {
        DVec3::new(target.x, hip.y - (cap * cap - across).sqrt(), target.z)
    } else {
        target
    }
}

/// How far to lower the pelvis at each frame (module docs, "Pelvis"): the most a foot in
/// contact must come down beyond its leg's cap, spread over ±`blend` frames and smoothed, so
/// that the pelvis settles and rises as smoothly as a correction fades.
fn pelvis_drop(plan: &Plan, reach: &LegReach, blend: usize) -> Vec<f64> {
    let n = reach.cap.len();
    let need: Vec<f64> = (0..n)
        .map(|f| {
            (0..2)
                .filter(|&s| plan.on[s][f])
                .filter_map(|s| {
                    let (c, _) = plan.targets[s][f]?;
                    let target = reach.ankle[f][s] + c;
                    let reachable = within_reach(target, reach.hip[f][s], reach.cap[f][s]);
                    Some(reachable.y - target.y)
                })
                .fold(0.0, f64::max)
        })
        .collect();
    held_drop(&need, blend)
}

/// A pelvis drop that gives every frame at least `need` (metres): the most over ±`blend`
/// frames, smoothed by a Gaussian of σ = `blend`/3, never negative.
fn held_drop(need: &[f64], blend: usize) -> Vec<f64> {
    let held: Vec<DVec3> = window_max(need, blend)
        .into_iter()
        .map(|most| DVec3::Y * most)
        .collect();
    gaussian(&held, blend as f64 / 3.0)
        .into_iter()
        .map(|c| c.y.max(0.0))
        .collect()
}

/// The model's feet: its skeleton, each foot's points ([`foot_points`]) and their rest sole
/// heights ([`rest_sole_heights`]), `[left, right]`, and the joints that place them (the foot
/// points' joints and their ancestors).
struct Feet {
    skeleton: Skeleton,
    points: [Vec<PointRef>; 2],
    rest: [Vec<f64>; 2],
    chain: Vec<usize>,
}

impl Feet {
    /// The foot points of both feet at frame `f` of `clip`, world space.
    fn positions(&self, clip: &FigureClip, f: usize, g: &mut Vec<Transform>) -> [Vec<DVec3>; 2] {
        let (t, q) = (clip.root_translation[f], clip.root_rotation[f]);
        chain_globals(&clip.model, &self.chain, t, q, clip.frame_angles(f), g);
        self.points_in(g)
    }

    /// The foot points of both feet where the chain's global transforms `g` place them.
    fn points_in(&self, g: &[Transform]) -> [Vec<DVec3>; 2] {
        [0, 1].map(|s| {
            self.points[s]
                .iter()
                .map(|&q| point(&self.skeleton, g, q))
                .collect()
        })
    }
}

/// A foot's sole height: the lowest of its points' heights above their rest heights.
fn sole_height(pts: &[DVec3], rest: &[f64]) -> f64 {
    pts.iter()
        .zip(rest)
        .map(|(x, r)| x.y - r)
        .fold(f64::INFINITY, f64::min)
}

/// Both feet's contact spans against the floor y = 0 and the rest heights `rest`.
fn floor_contacts(
    clip: &FigureClip,
    before: &[[Vec<DVec3>; 2]],
    rest: &[Vec<f64>; 2],
    config: &ContactConfig,
) -> Contacts {
    let reference = ContactReference {
        floor_y_m: 0.0,
        rest_heights_m: rest.clone().map(|v| v.into_iter().map(Some).collect()),
    };
    let side_track =
        |s: usize| -> Vec<Vec<DVec3>> { before.iter().map(|b| b[s].clone()).collect() };
    let (left, right) = (side_track(0), side_track(1));
    ground_contacts_against(&left, &right, &[], clip.frame_time, config, &reference)
}

/// One foot's points over the clip as assembled, with their rest heights.
struct FootTrack<'a> {
    /// Foot points of both feet, per frame.
    before: &'a [[Vec<DVec3>; 2]],
    /// Which foot: 0 left, 1 right.
    side: usize,
    /// Rest sole height of each of this foot's points.
    rest: &'a [f64],
    /// The foot's sole height at each frame ([`sole_height`]).
    sole: Vec<f64>,
    /// Seconds per frame.
    frame_time: f64,
}

impl FootTrack<'_> {
    /// Point `i` of the foot at frame `f`.
    fn at(&self, f: usize, i: usize) -> DVec3 {
        self.before[f][self.side][i]
    }

    /// The contact point of span `[a, b)`: the point lowest relative to its rest height on
    /// average over the span.
    fn contact_point(&self, a: usize, b: usize) -> usize {
        (0..self.rest.len())
            .min_by(|&i, &j| {
                let mean = |i: usize| -> f64 {
                    (a..b).map(|f| self.at(f, i).y - self.rest[i]).sum::<f64>()
                };
                mean(i).total_cmp(&mean(j))
            })
            .expect("a foot has points")
    }
}

/// How much a foot stands in each frame of a contact span whose sole heights are `sole` (module
/// docs, "Ground"): 1 while its sole rises or sinks slower than half the speed of a foot point
/// at rest ([`ContactConfig::rest_speed_mps`]), 0 from that speed on (lifting off or landing),
/// a smoothstep between; the rate by central differences inside the span.
fn standing_weights(sole: &[f64], frame_time: f64, config: &ContactConfig) -> Vec<f64> {
    let n = sole.len();
    let (fast, slow) = (config.rest_speed_mps, 0.5 * config.rest_speed_mps);
    (0..n)
        .map(|f| {
            let (lo, hi) = (f.saturating_sub(1), (f + 1).min(n - 1));
            if hi == lo {
                return 1.0;
            }
            let rate = (sole[hi] - sole[lo]).abs() / ((hi - lo) as f64 * frame_time);
            let x = ((fast - rate) / (fast - slow)).clamp(0.0, 1.0);
            x * x * (3.0 - 2.0 * x)
        })
        .collect()
}

/// The corrections inside the contact spans `planted` (module docs: ground and lock), each
/// frame's contact point, and the frames the foot stands in (its sole put on the floor);
/// `None` outside the spans.
fn hold_spans(
    foot: &FootTrack,
    planted: &[(usize, usize)],
    p: &PlantParams,
    config: &ContactConfig,
    report: &mut Planting,
) -> (Vec<Option<DVec3>>, Vec<usize>, Vec<bool>) {
    let n = foot.before.len();
    let mut corr: Vec<Option<DVec3>> = vec![None; n];
    let mut key = vec![0usize; n];
    let mut stand = vec![false; n];
    for &(a, b) in planted {
        let k = foot.contact_point(a, b);
        let anchor = (a..b)
            .map(|f| foot.at(f, k) * DVec3::new(1.0, 0.0, 1.0))
            .sum::<DVec3>()
            / (b - a) as f64;
        // Locked only when the contact point slides: faster on average over the span than
        // a foot point at rest moves.
        let path: f64 = (a + 1..b)
            .map(|f| {
                let d = foot.at(f, k) - foot.at(f - 1, k);
                DVec3::new(d.x, 0.0, d.z).length()
            })
            .sum();
        let slides = path / ((b - a) as f64 * foot.frame_time) > config.rest_speed_mps;
        if slides && p.lock {
            report.locked += 1;
        }
        let low = foot.sole[a..b]
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let standing = standing_weights(&foot.sole[a..b], foot.frame_time, config);
        for f in a..b {
            key[f] = k;
            stand[f] = standing[f - a] == 1.0;
            let pt = foot.at(f, k);
            let horizontal = if p.lock && slides {
                DVec3::new(anchor.x - pt.x, 0.0, anchor.z - pt.z)
            } else {
                DVec3::ZERO
            };
            // On the floor: the span's lowest sole put at y = 0, and a standing foot's sole
            // (module docs, "Ground") put there in every frame (the leg's cap and the pelvis
            // keep the knee from straightening to get there).
            let down = if p.ground {
                let w = standing[f - a];
                -low - w * (foot.sole[f] - low)
            } else {
                0.0
            };
            corr[f] = Some(horizontal + DVec3::Y * down);
        }
    }
    (corr, key, stand)
}

/// The free frames (not `on`): the contact point of the nearer neighbouring span, and the
/// corrections of the neighbouring spans faded out over `blend` frames (module docs).
fn fade_free_frames(
    on: &[bool],
    planted: &[(usize, usize)],
    blend: usize,
    corr: &mut [Option<DVec3>],
    key: &mut [usize],
) {
    // The first span starting after f; a free frame's previous span is the one before it.
    let mut after = 0;
    for f in 0..on.len() {
        while after < planted.len() && planted[after].0 <= f {
            after += 1;
        }
        if on[f] {
            continue;
        }
        let prev = after.checked_sub(1).map(|i| &planted[i]);
        let next = planted.get(after);
        key[f] = match (prev, next) {
            (Some(&(_, pe)), Some(&(ns, _))) => key[if f + 1 - pe <= ns - f { pe - 1 } else { ns }],
            (Some(&(_, pe)), None) => key[pe - 1],
            (None, Some(&(ns, _))) => key[ns],
            (None, None) => 0,
        };
        let c = faded_correction(f, prev.map(|s| s.1), next.map(|s| s.0), on, corr, blend);
        if c.length_squared() > 0.0 {
            corr[f] = Some(c);
        }
    }
}

/// The correction of free frame `f` between the span ending at `prev_end` and the one
/// starting at `next_start`: a Hermite curve from the one's edge to the other's when they are
/// closer than two blends, else each edge's correction faded to 0 over `blend` frames.
fn faded_correction(
    f: usize,
    prev_end: Option<usize>,
    next_start: Option<usize>,
    on: &[bool],
    corr: &[Option<DVec3>],
    blend: usize,
) -> DVec3 {
    let n = on.len();
    // The correction and its horizontal rate (per frame) at the span edges next to f. The
    // vertical rate is left out: inside a span the vertical correction cancels the foot's own
    // rise (the sole held at the floor), and carried on past the edge it would hold the foot
    // down as it lifts off; without it the foot leaves (and lands) at its own speed.
    let level = |v: DVec3| DVec3::new(v.x, 0.0, v.z);
    let edge_out = |pe: usize| -> (DVec3, DVec3) {
        let c = corr[pe - 1].unwrap_or_default();
        let v = if pe >= 2 && on[pe - 2] {
            level(c - corr[pe - 2].unwrap_or_default())
        } else {
            DVec3::ZERO
        };
        (c, v)
    };
    let edge_in = |ns: usize| -> (DVec3, DVec3) {
        let c = corr[ns].unwrap_or_default();
        let v = if ns + 1 < n && on[ns + 1] {
            level(corr[ns + 1].unwrap_or_default() - c)
        } else {
            DVec3::ZERO
        };
        (c, v)
    };
    match (prev_end, next_start) {
        (Some(pe), Some(ns)) if ns - pe <= 2 * blend => {
            // From the one span's edge to the other's, position and rate matched.
            let ((c0, v0), (c1, v1)) = (edge_out(pe), edge_in(ns));
            hermite(c0, v0, c1, v1, ns + 1 - pe, f + 1 - pe)
        }
        _ => {
            let out = prev_end.map_or(DVec3::ZERO, |pe| {
                let (c0, v0) = edge_out(pe);
                if f + 1 - pe > blend {
                    DVec3::ZERO
                } else {
                    hermite(c0, v0, DVec3::ZERO, DVec3::ZERO, blend + 1, f + 1 - pe)
                }
            });
            let inn = next_start.map_or(DVec3::ZERO, |ns| {
                let (c1, v1) = edge_in(ns);
                if ns - f > blend {
                    DVec3::ZERO
                } else {
                    hermite(
                        DVec3::ZERO,
                        DVec3::ZERO,
                        c1,
                        v1,
                        blend + 1,
                        blend + 1 - (ns - f),
                    )
                }
            });
            out + inn
        }
    }
}

/// The lift out of the floor added to the corrections, the whole smoothed over time (a
/// Gaussian of σ = smooth_s), then no sole under the floor: each frame's final correction and
/// contact point, `None` where there is nothing to do.
fn smooth_and_floor(
    foot: &FootTrack,
    corr: &[Option<DVec3>],
    key: &[usize],
    p: &PlantParams,
    report: &mut Planting,
) -> Vec<Option<(DVec3, usize)>> {
    let n = corr.len();
    let mut corr = corr.to_vec();
    // The least vertical correction that keeps the sole out of the floor: −s(f).
    let floor: Vec<f64> = foot.sole.iter().map(|s| -s).collect();
    for f in 0..n {
        let c = corr[f].unwrap_or_default();
        if floor[f] > c.y {
            corr[f] = Some(DVec3::new(c.x, floor[f], c.z));
        }
    }
    let raw: Vec<DVec3> = corr.iter().map(|c| c.unwrap_or_default()).collect();
    let smooth = gaussian(&raw, p.smooth_s / foot.frame_time);
    let mut targets = vec![None; n];
    for f in 0..n {
        if corr[f].is_none() && smooth[f].length_squared() < 1e-12 {
            continue;
        }
        let mut c = smooth[f];
        // No sole under the floor.
        c.y = c.y.max(floor[f]);
        report.max_correction_m = report.max_correction_m.max(c.length());
        targets[f] = Some((c, key[f]));
    }
    targets
}

/// The legs sent to their targets: each foot moved by its correction, the ankle reached by IK
/// and the foot's residual added to the ankle's target, [`IK_ROUNDS`] times at most.
fn reach_targets(
    clip: &mut FigureClip,
    legs: &[Leg; 2],
    model: &Feet,
    before: &[[Vec<DVec3>; 2]],
    plan: &Plan,
    cap: &[[f64; 2]],
) -> Vec<Reached> {
    use rayon::prelude::*;
    let d = clip.dof_count();
    let rest = &model.rest;
    let (roots, rotations) = (&clip.root_translation, &clip.root_rotation);
    let skeleton = &clip.model;
    let targets = &plan.targets;
    // Frames are independent: each moves only its own angles.
    clip.angles
        .par_chunks_mut(d)
        .enumerate()
        .map_init(Vec::new, |g, (f, angles)| {
            let (t, q) = (roots[f], rotations[f]);
            let mut out = Reached::default();
            for side in 0..2 {
                let planted = plan.stand[side][f];
                out.standing += usize::from(planted);
                let target = targets[side][f].filter(|(c, _)| c.length() >= 1e-6);
                let Some((c, k)) = target else {
                    let c = targets[side][f].map_or(DVec3::ZERO, |t| t.0);
                    let sole = sole_height(&before[f][side], &rest[side]) + c.y;
                    out.on_floor += usize::from(planted && sole.abs() <= FOOT_DOWN_M);
                    continue;
                };
                out.legs_moved += 1;
                let leg = legs[side];
                // The foot's place to reach, its points each moved by c: its key point's
                // horizontal place and its sole height.
                let moved = before[f][side].iter().map(|x| *x + c);
                let want_sole = moved
                    .zip(&rest[side])
                    .map(|(x, r)| x.y - r)
                    .fold(f64::INFINITY, f64::min);
                let key = before[f][side][k] + c;
                let wanted = DVec3::new(key.x, want_sole, key.z);
                chain_globals(skeleton, &model.chain, t, q, angles, g);
                // Never further from the hip than the leg's cap.
                let (hip, cap) = (g[leg.hip].translation, cap[f][side]);
                let mut ankle_target = within_reach(g[leg.ankle].translation + c, hip, cap);
                let mut residual = 0.0;
                let mut sole = f64::NAN;
                for _ in 0..IK_ROUNDS {
                    // `g` holds the chain for `angles`, before and after the reach.
                    reach_along(skeleton, leg, &model.chain, g, (t, q), angles, ankle_target);
                    let now = &model.points_in(g)[side];
                    let place = DVec3::new(now[k].x, sole_height(now, &rest[side]), now[k].z);
                    let r = wanted - place;
                    sole = place.y;
                    residual = r.length();
                    if residual < 1e-4 {
                        break;
                    }
                    let next = within_reach(ankle_target + r, hip, cap);
                    if (next - ankle_target).length_squared() < 1e-8 {
                        // Capped: the leg can come no closer.
                        break;
                    }
                    ankle_target = next;
                }
                out.residual = out.residual.max(residual);
                out.on_floor += usize::from(planted && sole.abs() <= FOOT_DOWN_M);
                if planted {
                    out.short = out.short.max(sole - want_sole);
                }
            }
            out
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::humanoid::{humanoid24, leg_ik};

    /// humanoid24 for `frames` frames at 60 fps, knees bent `knee` rad (hips flexed to keep the
    /// shins upright), its sole `sole` m off the floor (negative: in it), the pelvis gliding
    /// along x at `speed` m/s.
    fn stance(knee: f64, sole: f64, speed: f64, frames: usize) -> FigureClip {
        let model = humanoid24();
        let d = model.dofs.len();
        let mut pose = vec![0.0; d];
        for side in ["left", "right"] {
            pose[model.dof_index(&format!("{side}_knee")).unwrap()] = knee;
            pose[model.dof_index(&format!("{side}_hip_flexion")).unwrap()] = knee;
        }
        let mut clip = FigureClip {
            model,
            frame_time: 1.0 / 60.0,
            root_translation: vec![DVec3::ZERO; frames],
            root_rotation: vec![glam::DQuat::IDENTITY; frames],
            angles: pose.repeat(frames),
        };
        // Where the sole is with the pelvis at 0: lift the pelvis so it is at `sole`.
        let feet = foot_points(&clip.model.skeleton());
        let rest = rest_sole_heights(&clip);
        let mut g = vec![];
        leg_ik::frame_globals(
            &clip.model,
            DVec3::ZERO,
            glam::DQuat::IDENTITY,
            &pose,
            &mut g,
        );
        let skeleton = clip.model.skeleton();
        let low = feet[0]
            .iter()
            .zip(&rest[0])
            .map(|(&q, r)| point(&skeleton, &g, q).y - r)
            .fold(f64::INFINITY, f64::min);
        for (f, t) in clip.root_translation.iter_mut().enumerate() {
            *t = DVec3::new(speed * f as f64 / 60.0, sole - low, 0.0);
        }
        clip
    }

    fn foot_tracks(clip: &FigureClip) -> [Vec<Vec<DVec3>>; 2] {
        let c = clip.to_clip();
        let [l, r] = foot_points(&c.skeleton);
        [
            crate::analysis::point_tracks(&c, &l),
            crate::analysis::point_tracks(&c, &r),
        ]
    }

    #[test]
    fn feet_in_the_floor_are_lifted_onto_it_and_a_standing_figure_is_left_alone() {
        let mut on = stance(0.5, 0.0, 0.0, 120);
        let before = on.clone();
        let r = plant_feet(&mut on, &PlantParams::default());
        assert!(r.max_correction_m < 1e-9, "{r:?}");
        for (a, b) in on.angles.iter().zip(&before.angles) {
            assert!((a - b).abs() < 1e-9);
        }
        let mut sunk = stance(0.5, -0.04, 0.0, 120);
        let r = plant_feet(&mut sunk, &PlantParams::default());
        let lowest = foot_tracks(&sunk)
            .iter()
            .flatten()
            .flatten()
            .map(|p| p.y)
            .fold(f64::INFINITY, f64::min);
        assert!(
            lowest.abs() < 1e-3,
            "lowest foot point at {lowest} m: {r:?}"
        );
        // The pelvis stays where it was: the legs bent to lift the feet.
        assert_eq!(
            sunk.root_translation,
            stance(0.5, -0.04, 0.0, 120).root_translation
        );
    }

    #[test]
    fn a_standing_foot_that_hovers_is_put_down_on_the_floor() {
        // Standing 2 cm above the floor (in contact: within the analysis's 3 cm), knees as bent
        // throughout: the legs may not stretch further, so the pelvis comes down 2 cm and the
        // soles with it, the knees kept. Without `pelvis` the feet stay up (the legs are
        // capped at their own stretch), and without `ground` the figure is left alone.
        let lowest = |clip: &FigureClip| {
            let rest = rest_sole_heights(clip);
            let tracks = foot_tracks(clip);
            (0..2)
                .flat_map(|s| tracks[s].iter().map(move |pts| (s, pts)))
                .map(|(s, pts)| sole_height(pts, &rest[s]))
                .fold(f64::INFINITY, f64::min)
        };
        let original = stance(0.5, 0.02, 0.0, 120);
        let knee = original.model.dof_index("left_knee").unwrap();
        let mut hover = original.clone();
        let r = plant_feet(&mut hover, &PlantParams::default());
        assert!(lowest(&hover).abs() < 1e-3, "{} m: {r:?}", lowest(&hover));
        assert!((r.pelvis_drop_max_m - 0.02).abs() < 1e-3, "{r:?}");
        for f in 0..120 {
            let dropped = original.root_translation[f].y - hover.root_translation[f].y;
            assert!((dropped - 0.02).abs() < 1e-3, "frame {f}: {dropped} m");
            let bend = hover.frame_angles(f)[knee] - original.frame_angles(f)[knee];
            assert!(bend.abs() < 0.01, "frame {f}: knee moved {bend} rad");
        }
        let mut kept = original.clone();
        plant_feet(
            &mut kept,
            &PlantParams {
                pelvis: false,
                ..PlantParams::default()
            },
        );
        assert_eq!(kept.root_translation, original.root_translation);
        assert!((lowest(&kept) - 0.02).abs() < 1e-3, "{}", lowest(&kept));
        let mut left = original.clone();
        let only_lift = PlantParams {
            ground: false,
            ..PlantParams::default()
        };
        plant_feet(&mut left, &only_lift);
        assert!((lowest(&left) - 0.02).abs() < 1e-9, "{}", lowest(&left));
    }

    #[test]
    fn a_foot_that_bobs_while_it_stands_is_held_on_the_floor_in_every_frame() {
        // Standing with the whole figure bobbing 0–2 cm off the floor (within the analysis's
        // 3 cm: in contact throughout): moving the span by one height would leave the feet
        // hovering up to 2 cm; each frame's sole is put on the floor instead.
        let mut bob = stance(0.5, 0.0, 0.0, 120);
        for (f, t) in bob.root_translation.iter_mut().enumerate() {
            let phase = std::f64::consts::TAU * f as f64 / 60.0;
            t.y += 0.01 * (1.0 - phase.cos());
        }
        let r = plant_feet(&mut bob, &PlantParams::default());
        assert_eq!(r.planted_foot_frames, 2 * 120, "{r:?}");
        assert_eq!(r.planted_on_floor_fraction, 1.0, "{r:?}");
        let rest = rest_sole_heights(&bob);
        let tracks = foot_tracks(&bob);
        for (s, track) in tracks.iter().enumerate() {
            for (f, pts) in track.iter().enumerate() {
                let sole = sole_height(pts, &rest[s]);
                assert!(
                    sole.abs() < 2e-3,
                    "foot {s} frame {f}: sole at {sole} m, {r:?}"
                );
            }
        }
    }

    #[test]
    fn the_window_maximum_is_the_plain_one() {
        let x: Vec<f64> = (0..200).map(|i| ((i * 37 % 101) as f64).sin()).collect();
        for w in [0, 1, 5, 12, 300] {
            let plain: Vec<f64> = (0..x.len())
                .map(|f| {
                    x[f.saturating_sub(w)..(f + w + 1).min(x.len())]
                        .iter()
                        .copied()
                        .fold(f64::NEG_INFINITY, f64::max)
                })
                .collect();
            assert_eq!(window_max(&x, w), plain, "w = {w}");
        }
    }

    #[test]
    fn a_sliding_planted_foot_is_held_still() {
        // Feet on the floor while the pelvis glides 0.5 m/s for 0.6 s: the feet slide with it,
        // faster than a foot at rest moves.
        let mut clip = stance(1.0, 0.0, 0.5, 36);
        let r = plant_feet(&mut clip, &PlantParams::default());
        assert_eq!(r.locked, 2, "{r:?}");
        let [l, _] = foot_tracks(&clip);
        // The foot stands flat, toe and ankle on their rest heights: the ankle (the first
        // point, as low as the toe relative to its rest height) is its contact point, and stays
        // within a few millimetres of its anchor.
        let ankle = l.iter().map(|p| p[0]).collect::<Vec<_>>();
        let span = ankle
            .iter()
            .map(|p| (p.x - ankle[18].x).abs())
            .fold(0.0, f64::max);
        assert!(
            span < 0.005,
            "the ankle moves {span} m (it slid 0.3 m): {r:?}"
        );
        let unlocked = PlantParams {
            lock: false,
            ..PlantParams::default()
        };
        let mut free = stance(1.0, 0.0, 0.5, 36);
        assert_eq!(plant_feet(&mut free, &unlocked).locked, 0);
    }
}
