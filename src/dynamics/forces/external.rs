//! External pushes: a force of given magnitude and world direction applied at a point of a link
//! during `[start, start + duration)` (the paper: 1000 N on the torso from the front for 0.1 s).

use crate::dynamics::data::Data;
use crate::dynamics::spatial::ForceVec;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// A push.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Push {
    /// Link that is pushed (e.g. "torso").
    pub link: String,
    /// Point of application in the link frame (m).
    pub point: DVec3,
    /// Direction of the force in world coordinates (normalised on use); a push from the
    /// front of a figure facing +Z is `(0, 0, −1)`.
    pub direction: DVec3,
    /// Magnitude (N).
    pub force_n: f64,
    /// Start time (s).
    pub start_s: f64,
    /// Duration (s).
    pub duration_s: f64,
}

impl Push {
    /// True while the push acts at time `t` (s).
    #[inline]
    pub fn active(&self, t: f64) -> bool {
        t >= self.start_s && t < self.start_s + self.duration_s
    }

    /// The spatial force in the body coordinates of `link` (index `i`) after kinematics:
    /// `f = Rᵀ F`, `n = p × f`.
    #[inline]
    pub fn body_force(&self, data: &Data, i: usize) -> ForceVec {
        let f_world = self.direction.normalize_or_zero() * self.force_n;
        ForceVec::at_point(data.rot[i].transpose() * f_world, self.point)
    }
}

/// The paper's push: 1000 N on the torso from the front, for 0.1 s from `start_s`, at chest
/// height `chest_y` (m above the waist joint).
pub fn paper_push(start_s: f64, chest_y: f64) -> Push {
    Push {
        link: "torso".into(),
        point: DVec3::new(0.0, chest_y, 0.0),
        direction: DVec3::new(0.0, 0.0, -1.0),
        force_n: 1000.0,
        start_s,
        duration_s: 0.1,
    }
}
