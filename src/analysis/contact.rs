//! Ground contact and flight phases from the heights of a body's points.
//!
//! Definitions (all heights are measured from the floor found in the motion):
//! - a **foot point** (ankle, heel, toe joints, toe End Sites) has a *rest height*: the median
//!   height of the frames where it stands still (speed under [`ContactConfig::rest_speed_mps`])
//!   low down (under [`ContactConfig::max_rest_height_m`]). A mapped or simulated ankle stands
//!   0.06–0.12 m up; its rest height says so, so it touches while it is within
//!   [`ContactConfig::threshold_m`] of that height (or lower). A point that never rests low never
//!   touches.
//! - a **foot touches** while any of its points touches (toe or heel: tiptoe and flat foot);
//! - the **body touches** while any other point (pelvis, knees, elbows, head, …) is within
//!   [`ContactConfig::body_threshold_m`] of the floor: joint centres of a body lying, sitting or
//!   kneeling on the floor are that close, a jumping body's never are;
//! - a **flight** is a span where neither foot nor the body touches, at least
//!   [`ContactConfig::min_flight_s`] long. Lying on the floor is contact, not flight.
//!
//! Every on/off series is debounced: runs shorter than [`ContactConfig::debounce_s`] are taken
//! as noise and joined to their neighbours.

use glam::DVec3;
use serde::Serialize;

/// A time span `[start_s, end_s)`, seconds.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Span {
    /// Start, seconds.
    pub start_s: f64,
    /// End, seconds.
    pub end_s: f64,
}

impl Span {
    /// Length, seconds.
    pub fn duration(&self) -> f64 {
        self.end_s - self.start_s
    }
}

/// Settings of [`ground_contacts`]; the defaults suit human motion at any frame rate.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ContactConfig {
    /// A foot point touches while within this of its rest height, metres (default 0.03).
    pub threshold_m: f64,
    /// Shortest flight reported, seconds (default 0.1).
    pub min_flight_s: f64,
    /// Runs of contact or no contact shorter than this are noise, seconds (default 0.05).
    pub debounce_s: f64,
    /// A foot point slower than this is at rest, m/s (default 0.3).
    pub rest_speed_mps: f64,
    /// A foot point resting higher than this above the floor is not on it, metres (default 0.15).
    pub max_rest_height_m: f64,
    /// A point of the body other than the feet touches while this near the floor, metres
    /// (default 0.15).
    pub body_threshold_m: f64,
}

impl Default for ContactConfig {
    fn default() -> Self {
        ContactConfig {
            threshold_m: 0.03,
            min_flight_s: 0.1,
            debounce_s: 0.05,
            rest_speed_mps: 0.3,
            max_rest_height_m: 0.15,
            body_threshold_m: 0.15,
        }
    }
}

/// Contact phases of a motion.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Contacts {
    /// Floor height found in the motion (the 2nd percentile of the lowest foot point), metres.
    pub floor_y_m: f64,
    /// Height above its rest height under which a foot point counts as touching, metres.
    pub threshold_m: f64,
    /// Rest height above the floor of each foot point, `[left, right]`, metres (`None`: the
    /// point never rests on the floor).
    pub rest_heights_m: [Vec<Option<f64>>; 2],
    /// Spans where some point of the left foot touches.
    pub left: Vec<Span>,
    /// Spans where some point of the right foot touches.
    pub right: Vec<Span>,
    /// Spans where some other point of the body is on the floor (lying, sitting, kneeling).
    pub body: Vec<Span>,
    /// Spans where nothing touches (at least `min_flight_s` long).
    pub flights: Vec<Span>,
}

/// Heights (y) of every point of one group, point-major: `out[p][f]`.
fn heights(frames: &[Vec<DVec3>]) -> Vec<Vec<f64>> {
    let n = frames.first().map_or(0, Vec::len);
    (0..n)
        .map(|p| {
            frames
                .iter()
                .map(|fr| fr.get(p).map_or(f64::NAN, |v| v.y))
                .collect()
        })
        .collect()
}

/// Speed of point `p` at every frame (central differences), m/s.
fn speeds(frames: &[Vec<DVec3>], p: usize, frame_time: f64) -> Vec<f64> {
    let n = frames.len();
    (0..n)
        .map(|f| {
            let (a, b) = (f.saturating_sub(1), (f + 1).min(n - 1));
            if a == b {
                return 0.0;
            }
            (frames[b][p] - frames[a][p]).length() / ((b - a) as f64 * frame_time)
        })
        .collect()
}

/// The median of `v` (NaN-free), `None` when empty.
fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[v.len() / 2])
}

/// Joins runs shorter than `min_frames` (of either value) to their neighbours: first gaps in
/// contact are filled, then contact blips dropped.
fn debounce(on: &mut [bool], min_frames: usize) {
    if min_frames <= 1 {
        return;
    }
    for value in [false, true] {
        let mut f = 0;
        while f < on.len() {
            if on[f] != value {
                f += 1;
                continue;
            }
            let start = f;
            while f < on.len() && on[f] == value {
                f += 1;
            }
            // Only a run between two runs of the other value is noise; the clip's ends are kept.
            if start > 0 && f < on.len() && f - start < min_frames {
                on[start..f].iter_mut().for_each(|x| *x = !value);
            }
        }
    }
}

/// The spans where `on` holds, at least `min_s` long.
fn spans(on: &[bool], frame_time: f64, min_s: f64) -> Vec<Span> {
    let mut out = vec![];
    let mut start = None;
    for f in 0..=on.len() {
        let here = f < on.len() && on[f];
        match (here, start) {
            (true, None) => start = Some(f),
            (false, Some(s)) => {
                let span = Span {
                    start_s: s as f64 * frame_time,
                    end_s: f as f64 * frame_time,
                };
                if span.duration() >= min_s - 1e-9 {
                    out.push(span);
                }
                start = None;
            }
            _ => {}
        }
    }
    out
}

/// Where a motion's feet touch: the floor and each foot point's rest height, as
/// [`ground_contacts`] finds them. Passed to [`ground_contacts_against`], it measures other
/// motions of the same figure against the same floor and rest heights.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ContactReference {
    /// Floor height, metres.
    pub floor_y_m: f64,
    /// Rest height above the floor of each foot point, `[left, right]`, metres (`None`: the
    /// point never rests on the floor, so it never touches).
    pub rest_heights_m: [Vec<Option<f64>>; 2],
}

impl Contacts {
    /// The floor and rest heights these contacts were found with.
    pub fn reference(&self) -> ContactReference {
        ContactReference {
            floor_y_m: self.floor_y_m,
            rest_heights_m: self.rest_heights_m.clone(),
        }
    }
}

/// The floor of a motion: the 2nd percentile over its frames of the lowest foot point (0 with
/// no foot point), metres.
fn floor_of(hl: &[Vec<f64>], hr: &[Vec<f64>], frames: usize) -> f64 {
    let mut lowest: Vec<f64> = (0..frames)
        .map(|f| {
            hl.iter()
                .chain(hr)
                .map(|h| h[f])
                .fold(f64::INFINITY, f64::min)
        })
        .filter(|h| h.is_finite())
        .collect();
    lowest.sort_by(f64::total_cmp);
    if lowest.is_empty() {
        0.0
    } else {
        lowest[(lowest.len() - 1) * 2 / 100]
    }
}

/// Each point's rest height above `floor` (the median height of the frames where it is slower
/// than `rest_speed_mps` and lower than `max_rest_height_m`), metres.
fn rest_heights(
    frames_pts: &[Vec<DVec3>],
    h: &[Vec<f64>],
    floor: f64,
    frame_time: f64,
    config: &ContactConfig,
) -> Vec<Option<f64>> {
    (0..h.len())
        .map(|p| {
            let v = speeds(frames_pts, p, frame_time);
            let resting: Vec<f64> = (0..v.len().min(h[p].len()))
                .filter(|&f| {
                    v[f] < config.rest_speed_mps && h[p][f] - floor < config.max_rest_height_m
                })
                .map(|f| h[p][f] - floor)
                .filter(|x| x.is_finite())
                .collect();
            median(resting).map(|r| r.max(0.0))
        })
        .collect()
}

/// Finds ground contact and flight (see the module documentation): `left[f]` and `right[f]` are
/// the foot points of frame `f` (the same points, in the same order, every frame), `body[f]` the
/// other points of the body (may be empty). The floor is the 2nd percentile over the motion of
/// the lowest foot point, so the clip need not stand at y = 0.
pub fn ground_contacts(
    left: &[Vec<DVec3>],
    right: &[Vec<DVec3>],
    body: &[Vec<DVec3>],
    frame_time: f64,
    config: &ContactConfig,
) -> Contacts {
    let frames = left.len().min(right.len());
    let (hl, hr) = (heights(left), heights(right));
    let floor_y_m = floor_of(&hl, &hr, frames);
    let reference = ContactReference {
        floor_y_m,
        rest_heights_m: [
            rest_heights(left, &hl, floor_y_m, frame_time, config),
            rest_heights(right, &hr, floor_y_m, frame_time, config),
        ],
    };
    ground_contacts_against(left, right, body, frame_time, config, &reference)
}

/// [`ground_contacts`] against a given floor and given rest heights (those of another motion of
/// the same figure, [`Contacts::reference`]) instead of the motion's own: a foot point touches
/// while within `threshold_m` of its reference rest height. Motions compared with one another
/// (a jump and a variation of it) are so measured by one standard; estimated per motion, a
/// point resting just under [`ContactConfig::max_rest_height_m`] in one and just over it in the
/// other would touch in one only. A point with no reference rest height never touches.
pub fn ground_contacts_against(
    left: &[Vec<DVec3>],
    right: &[Vec<DVec3>],
    body: &[Vec<DVec3>],
    frame_time: f64,
    config: &ContactConfig,
    reference: &ContactReference,
) -> Contacts {
    let frames = left.len().min(right.len());
    let (hl, hr, hb) = (heights(left), heights(right), heights(body));
    let floor = reference.floor_y_m;
    let debounce_frames = (config.debounce_s / frame_time).round().max(1.0) as usize;
    // Per foot: the frames where some point is within the threshold of its rest height.
    let foot = |h: &[Vec<f64>], rests: &[Option<f64>]| -> Vec<bool> {
        let mut on = vec![false; frames];
        for (hp, rest) in h.iter().zip(rests) {
            if let Some(r) = rest {
                for f in 0..frames {
                    on[f] |= hp[f] - floor < r + config.threshold_m;
                }
            }
        }
        debounce(&mut on, debounce_frames);
        on
    };
    let [rest_l, rest_r] = &reference.rest_heights_m;
    let (on_l, on_r) = (foot(&hl, rest_l), foot(&hr, rest_r));
    let mut on_body: Vec<bool> = (0..frames)
        .map(|f| {
            hb.iter().any(|h| {
                h.get(f)
                    .is_some_and(|y| y - floor < config.body_threshold_m)
            })
        })
        .collect();
    debounce(&mut on_body, debounce_frames);
    let air: Vec<bool> = (0..frames)
        .map(|f| !on_l[f] && !on_r[f] && !on_body[f])
        .collect();
    Contacts {
        floor_y_m: floor,
        threshold_m: config.threshold_m,
        rest_heights_m: reference.rest_heights_m.clone(),
        left: spans(&on_l, frame_time, 0.0),
        right: spans(&on_r, frame_time, 0.0),
        body: spans(&on_body, frame_time, 0.0),
        flights: spans(&air, frame_time, config.min_flight_s),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ballistic height of a flight from `t0` to `t1`, metres above the take-off height.
    fn ballistic(t: f64, t0: f64, t1: f64) -> f64 {
        if t > t0 && t < t1 {
            0.5 * 9.81 * (t - t0) * (t1 - t)
        } else {
            0.0
        }
    }

    /// One foot: an ankle `ankle_m` up with a toe 0.2 m ahead at `toe_m`, lifted by `lift`.
    fn foot(x: f64, ankle_m: f64, toe_m: f64, lift: f64) -> Vec<DVec3> {
        vec![
            DVec3::new(x, ankle_m + lift, 0.0),
            DVec3::new(x, toe_m + lift, 0.2),
        ]
    }

    #[test]
    fn finds_a_ballistic_flight_from_a_raised_ankle_and_a_swinging_toe() {
        // The mapped-ankle case: ankles stand 0.10–0.12 m up, toes sway 0–4 cm (a foot rigid
        // with the shank), one flight from 1.0 s to 1.4 s.
        let dt = 1.0 / 120.0;
        let (mut l, mut r, mut b) = (vec![], vec![], vec![]);
        for f in 0..360 {
            let t = f as f64 * dt;
            let sway = 0.02 + 0.02 * (t * 3.0).sin();
            let lift = ballistic(t, 1.0, 1.4);
            l.push(foot(0.1, 0.11 + 0.01 * (t * 2.0).sin(), sway, lift));
            r.push(foot(-0.1, 0.10, sway, lift));
            b.push(vec![DVec3::new(0.0, 0.5 + lift, 0.0)]);
        }
        let c = ground_contacts(&l, &r, &b, dt, &ContactConfig::default());
        assert_eq!(c.flights.len(), 1, "{:?}", c.flights);
        let fl = c.flights[0];
        assert!(
            (fl.start_s - 1.0).abs() < 0.05 && (fl.end_s - 1.4).abs() < 0.05,
            "{fl:?}"
        );
        let ankle_rest = c.rest_heights_m[1][0].unwrap();
        assert!((ankle_rest - 0.10).abs() < 0.01, "{ankle_rest}");
        assert_eq!(c.left.len(), 2);
        assert!(c.body.is_empty());
    }

    #[test]
    fn lying_on_the_floor_is_not_flight() {
        // Standing 0.5 s, falling, then lying 2 s with the feet (toes up) off the floor and the
        // pelvis and elbows on it.
        let dt = 0.01;
        let (mut l, mut r, mut b) = (vec![], vec![], vec![]);
        for f in 0..300 {
            let t = f as f64 * dt;
            let down = ((t - 0.5) / 0.5).clamp(0.0, 1.0);
            let toe = 0.25 * down;
            l.push(foot(0.1, 0.07 + 0.05 * down, toe, 0.0));
            r.push(foot(-0.1, 0.07 + 0.05 * down, toe, 0.0));
            b.push(vec![
                DVec3::new(0.0, 1.0 - 0.9 * down, 0.0),
                DVec3::new(0.3, 1.0 - 0.92 * down, 0.0),
            ]);
        }
        let c = ground_contacts(&l, &r, &b, dt, &ContactConfig::default());
        assert!(c.flights.is_empty(), "{:?}", c.flights);
        assert_eq!(c.body.len(), 1);
        assert!(
            c.body[0].start_s > 0.6 && c.body[0].end_s > 2.99,
            "{:?}",
            c.body
        );
    }

    #[test]
    fn debouncing_joins_short_runs() {
        let mut on = vec![
            true, true, true, false, true, true, true, true, false, false,
        ];
        debounce(&mut on, 2);
        assert_eq!(
            on,
            [true, true, true, true, true, true, true, true, false, false]
        );
        let mut on = vec![false, false, false, true, false, false, false];
        debounce(&mut on, 2);
        assert!(on.iter().all(|x| !x));
        // A short run at an end of the clip is kept: the clip may start in the air.
        let mut on = vec![false, true, true, true];
        debounce(&mut on, 3);
        assert_eq!(on, [false, true, true, true]);
    }

    #[test]
    fn a_flickering_foot_gives_one_flight() {
        // A toe that touches for single frames inside a flight (noise) does not split it.
        let dt = 0.01;
        let (mut l, mut r) = (vec![], vec![]);
        for f in 0..200 {
            let t = f as f64 * dt;
            let mut lift = ballistic(t, 0.5, 1.0);
            if f == 70 || f == 80 {
                lift = 0.0;
            }
            l.push(foot(0.1, 0.08, 0.0, lift));
            r.push(foot(-0.1, 0.08, 0.0, lift));
        }
        let c = ground_contacts(&l, &r, &[], dt, &ContactConfig::default());
        assert_eq!(c.flights.len(), 1, "{:?}", c.flights);
    }

    #[test]
    fn against_a_reference_a_motion_is_measured_by_the_reference_s_rest_heights() {
        // One flight 1.0–1.4 s; motion B stands its feet 2 cm higher than motion A.
        let dt = 1.0 / 120.0;
        let motion = |stand: f64| {
            let (mut l, mut r) = (vec![], vec![]);
            for f in 0..240 {
                let lift = ballistic(f as f64 * dt, 1.0, 1.4);
                l.push(foot(0.1, 0.10 + stand, stand, lift));
                r.push(foot(-0.1, 0.10 + stand, stand, lift));
            }
            (l, r)
        };
        let config = ContactConfig::default();
        let (al, ar) = motion(0.0);
        let a = ground_contacts(&al, &ar, &[], dt, &config);
        // Against its own reference a motion gives its own contacts.
        assert_eq!(
            ground_contacts_against(&al, &ar, &[], dt, &config, &a.reference()),
            a
        );
        // B's own estimate finds its floor 2 cm up, so its flight is A's; measured against A's
        // floor its feet stand 2 cm up, leave the 3 cm band when 1 cm higher still (about
        // 10 ms sooner) and come back that much later.
        let (bl, br) = motion(0.02);
        let own = ground_contacts(&bl, &br, &[], dt, &config).flights[0];
        let fa = a.flights[0];
        assert!(
            (own.duration() - fa.duration()).abs() < 2.0 * dt,
            "{own:?} {fa:?}"
        );
        let against = ground_contacts_against(&bl, &br, &[], dt, &config, &a.reference());
        assert_eq!(against.rest_heights_m, a.rest_heights_m);
        let fb = against.flights[0];
        assert!(fb.duration() > own.duration() + dt, "{fb:?} vs own {own:?}");
        // A point with no reference rest height never touches.
        let none = ContactReference {
            floor_y_m: a.floor_y_m,
            rest_heights_m: [vec![None; 2], vec![None; 2]],
        };
        let c = ground_contacts_against(&al, &ar, &[], dt, &config, &none);
        assert!(c.left.is_empty() && c.right.is_empty(), "{c:?}");
        assert_eq!(c.flights.len(), 1);
        assert!((c.flights[0].duration() - 240.0 * dt).abs() < 1e-9);
    }
}
