//! Jump events found automatically on plain data (the paper's Start, Bend, Leap, Land):
//!
//! 1. the root height (and optional foot heights) are smoothed by a Gaussian of standard
//!    deviation `smoothing` seconds (weights renormalised at the clip's ends);
//! 2. **Leap** = the frame where the smoothed root is highest (hips highest);
//! 3. **Bend** = the lowest smoothed root height before Leap (deepest crouch before take-off);
//!    it must lie at least `onset_threshold` below the standing height (the median of the first
//!    `baseline_window` seconds);
//! 4. **Start** = going back from Bend, the first frame within `onset_threshold` of the standing
//!    height (motion onset; frame 0 if the clip starts already moving);
//! 5. take-off = the frame of highest upward root velocity between Bend and Leap;
//! 6. **Land** = the first instant after Leap when the lowest smoothed foot comes within
//!    `foot_contact_margin` of its standing level; without feet, when the root falls back to its
//!    take-off height (a ballistic flight is symmetric), interpolated between frames.

use serde::{Deserialize, Serialize};

use super::error::{PrimitiveError, Result, require_finite, require_positive};
pub use crate::signal::gaussian_smooth;
use crate::signal::median;

/// Parameters of the jump-event detector.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EventConfig {
    /// Gaussian smoothing σ, seconds (default 0.025).
    pub smoothing: f64,
    /// Height change that counts as motion, metres (default 0.01).
    pub onset_threshold: f64,
    /// Length of the standing window at the clip's start, seconds (default 0.2).
    pub baseline_window: f64,
    /// Foot height above its standing level that still counts as contact, metres (default 0.03).
    pub foot_contact_margin: f64,
}

impl Default for EventConfig {
    fn default() -> Self {
        EventConfig {
            smoothing: 0.025,
            onset_threshold: 0.01,
            baseline_window: 0.2,
            foot_contact_margin: 0.03,
        }
    }
}

/// Times of the events, seconds from the clip's first frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct JumpEvents {
    /// Motion onset.
    pub start: f64,
    /// Deepest crouch before take-off (root height minimum).
    pub bend: f64,
    /// Highest upward root velocity between Bend and Leap.
    pub take_off: f64,
    /// Hips highest.
    pub leap: f64,
    /// First contact after the flight.
    pub land: f64,
}
/// [`find_jump_events`]'s checks: positive step and configuration, finite root heights, at
/// least 8 frames.
fn check_event_inputs(root_y: &[f64], dt: f64, config: &EventConfig) -> Result<()> {
    require_positive("dt", dt)?;
    require_positive("smoothing", config.smoothing)?;
    require_positive("onset_threshold", config.onset_threshold)?;
    require_positive("baseline_window", config.baseline_window)?;
    require_positive("foot_contact_margin", config.foot_contact_margin)?;
    require_finite("root_y", root_y)?;
    let n = root_y.len();
    if n < 8 {
        return Err(PrimitiveError::InvalidTrajectory {
            what: format!("root height has {n} frames; need at least 8"),
        });
    }
    Ok(())
}

/// The lowest of the foot heights `feet` (each of `n` finite frames, smoothed by a Gaussian of
/// σ = `sigma` frames) in every frame.
fn lowest_foot(feet: &[Vec<f64>], n: usize, sigma: f64) -> Result<Vec<f64>> {
    for (f, h) in feet.iter().enumerate() {
        if h.len() != n {
            return Err(PrimitiveError::InvalidTrajectory {
                what: format!("foot {f} has {} frames, root has {n}", h.len()),
            });
        }
        require_finite(&format!("feet[{f}]"), h)?;
    }
    let smoothed: Vec<Vec<f64>> = feet.iter().map(|h| gaussian_smooth(h, sigma)).collect();
    Ok((0..n)
        .map(|k| smoothed.iter().map(|h| h[k]).fold(f64::INFINITY, f64::min))
        .collect())
}

/// Finds Start, Bend, Leap and Land of a jump in the root height `root_y` (metres, one per frame
/// every `dt` seconds) and, optionally, foot heights (`feet[f][k]`, metres). See the module docs.
pub fn find_jump_events(
    root_y: &[f64],
    dt: f64,
    feet: Option<&[Vec<f64>]>,
    config: &EventConfig,
) -> Result<JumpEvents> {
    check_event_inputs(root_y, dt, config)?;
    let n = root_y.len();
    let y = gaussian_smooth(root_y, config.smoothing / dt);
    let leap = (0..n).max_by(|a, b| y[*a].total_cmp(&y[*b])).unwrap_or(0);
    if leap == 0 || leap == n - 1 {
        return Err(PrimitiveError::EventsNotFound {
            reason: format!(
                "the root is highest at the clip's {} frame: no flight peak",
                if leap == 0 { "first" } else { "last" }
            ),
        });
    }
    let bend = (0..leap)
        .min_by(|a, b| y[*a].total_cmp(&y[*b]))
        .unwrap_or(0);
    let nb = ((config.baseline_window / dt).round() as usize).clamp(1, n);
    let stand = median(&y[..nb]);
    if stand - y[bend] < config.onset_threshold {
        return Err(PrimitiveError::EventsNotFound {
            reason: format!(
                "no crouch before the highest point: the root drops {:.4} m below standing, less than onset_threshold {} m",
                stand - y[bend],
                config.onset_threshold
            ),
        });
    }
    let start = (0..=bend)
        .rev()
        .find(|&k| (y[k] - stand).abs() <= config.onset_threshold)
        .unwrap_or(0);
    let vel = |k: usize| (y[(k + 1).min(n - 1)] - y[k.saturating_sub(1)]) / dt;
    let take_off = (bend + 1..=leap)
        .max_by(|a, b| vel(*a).total_cmp(&vel(*b)))
        .unwrap_or(leap);

    // Land: first crossing after Leap of a contact level, linearly interpolated.
    let crossing = |s: &[f64], level: f64| -> Option<f64> {
        (leap..n - 1).find_map(|k| {
            (s[k] > level && s[k + 1] <= level)
                .then(|| (k as f64 + (s[k] - level) / (s[k] - s[k + 1])) * dt)
        })
    };
    let land = match feet {
        Some(feet) if !feet.is_empty() => {
            let lowest = lowest_foot(feet, n, config.smoothing / dt)?;
            let level = median(&lowest[..nb]) + config.foot_contact_margin;
            if lowest[leap] <= level {
                return Err(PrimitiveError::EventsNotFound {
                    reason: "a foot is on the ground when the hips are highest: no flight".into(),
                });
            }
            crossing(&lowest, level)
        }
        _ => crossing(&y, y[take_off]),
    }
    .ok_or_else(|| PrimitiveError::EventsNotFound {
        reason: "no landing after the highest point (the clip ends in the air?)".into(),
    })?;
    Ok(JumpEvents {
        start: start as f64 * dt,
        bend: bend as f64 * dt,
        take_off: take_off as f64 * dt,
        leap: leap as f64 * dt,
        land,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smoothing_keeps_constants_and_lines() {
        let c = vec![2.0; 30];
        assert!(
            gaussian_smooth(&c, 3.0)
                .iter()
                .all(|v| (v - 2.0).abs() < 1e-12)
        );
        let l: Vec<f64> = (0..40).map(|k| k as f64).collect();
        let s = gaussian_smooth(&l, 2.0);
        for k in 10..30 {
            assert!((s[k] - l[k]).abs() < 1e-9);
        }
    }

    #[test]
    fn standing_still_has_no_jump() {
        let y = vec![0.95; 200];
        let mut y2 = y.clone();
        y2[100] = 0.96; // a highest point, but no crouch
        assert!(find_jump_events(&y2, 0.01, None, &EventConfig::default()).is_err());
    }
}
