//! Ground contact and flight phases from foot heights.

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

/// Contact phases of a motion.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Contacts {
    /// Floor height found in the motion (the 2nd percentile of the lowest foot point), metres.
    pub floor_y_m: f64,
    /// Height above the floor under which a foot point counts as touching, metres.
    pub threshold_m: f64,
    /// Spans where some point of the left foot touches.
    pub left: Vec<Span>,
    /// Spans where some point of the right foot touches.
    pub right: Vec<Span>,
    /// Spans where no foot point touches (at least `min_flight_s` long).
    pub flights: Vec<Span>,
}

/// Finds ground contact and flight from per-frame foot points: `left[f]` and `right[f]` are the
/// foot points (ankle, toe, …) of frame `f`; a foot touches while its lowest point is within
/// `threshold_m` of the floor (the floor is the 2nd percentile of the lowest point over the
/// motion, so the clip need not stand at y = 0). Flights shorter than `min_flight_s` are noise
/// and dropped.
pub fn ground_contacts(
    left: &[Vec<DVec3>],
    right: &[Vec<DVec3>],
    frame_time: f64,
    threshold_m: f64,
    min_flight_s: f64,
) -> Contacts {
    let low = |pts: &Vec<DVec3>| pts.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
    let hl: Vec<f64> = left.iter().map(low).collect();
    let hr: Vec<f64> = right.iter().map(low).collect();
    let mut lowest: Vec<f64> = hl.iter().zip(&hr).map(|(a, b)| a.min(*b)).collect();
    lowest.sort_by(f64::total_cmp);
    let floor = if lowest.is_empty() {
        0.0
    } else {
        lowest[(lowest.len() - 1) * 2 / 100]
    };
    let spans = |touch: &dyn Fn(usize) -> bool, min_s: f64| -> Vec<Span> {
        let mut out = vec![];
        let mut start = None;
        for f in 0..=hl.len() {
            let on = f < hl.len() && touch(f);
            match (on, start) {
                (true, None) => start = Some(f),
                (false, Some(s)) => {
                    let span = Span {
                        start_s: s as f64 * frame_time,
                        end_s: f as f64 * frame_time,
                    };
                    if span.duration() >= min_s {
                        out.push(span);
                    }
                    start = None;
                }
                _ => {}
            }
        }
        out
    };
    let l_touch = |f: usize| hl[f] - floor < threshold_m;
    let r_touch = |f: usize| hr[f] - floor < threshold_m;
    Contacts {
        floor_y_m: floor,
        threshold_m,
        left: spans(&l_touch, 0.0),
        right: spans(&r_touch, 0.0),
        flights: spans(&|f| !l_touch(f) && !r_touch(f), min_flight_s),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_a_ballistic_flight() {
        // Both feet at y = 0.1 except a parabolic flight from 1.0 s to 1.4 s.
        let dt = 0.01;
        let mut l = vec![];
        let mut r = vec![];
        for f in 0..300 {
            let t = f as f64 * dt;
            let y = 0.1
                + if t > 1.0 && t < 1.4 {
                    0.5 * 9.81 * (t - 1.0) * (1.4 - t)
                } else {
                    0.0
                };
            l.push(vec![DVec3::new(0.1, y, 0.0)]);
            r.push(vec![DVec3::new(-0.1, y, 0.0)]);
        }
        let c = ground_contacts(&l, &r, dt, 0.02, 0.1);
        assert!((c.floor_y_m - 0.1).abs() < 1e-12);
        assert_eq!(c.flights.len(), 1);
        let fl = c.flights[0];
        // y − floor reaches 2 cm after t ≈ 0.0052 s of a 0.4 s flight.
        assert!(
            (fl.start_s - 1.01).abs() < 0.015 && (fl.end_s - 1.40).abs() < 0.015,
            "{fl:?}"
        );
        assert_eq!(c.left.len(), 2);
    }
}
