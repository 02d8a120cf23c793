//! External forces: a world-frame force applied at a point of a body (and a world-frame torque)
//! during
//! `[start, start + duration)` ([`ExternalForce`], what the step reads), and the scene-level
//! description of a push by link name ([`Push`]; the paper: 1000 N on the torso from the front
//! for 0.1 s).

use crate::dynamics::data::Data;
use crate::dynamics::spatial::ForceVec;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// A push. A field left out of a scene takes the paper's push ([`Push::default`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
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

impl Default for Push {
    /// The paper's push on a 1.70 m figure: 1000 N on the chest from the front for 0.1 s from
    /// t = 0.1 s.
    fn default() -> Self {
        paper_push(0.1, 0.16 * 1.70)
    }
}

impl Push {
    /// True while the push acts at time `t` (s).
    #[inline]
    pub fn active(&self, t: f64) -> bool {
        t >= self.start_s && t < self.start_s + self.duration_s
    }

    /// This push as a force on body `body` (the index of [`Push::link`] in the model).
    pub fn to_force(&self, body: usize) -> ExternalForce {
        ExternalForce {
            body,
            point: self.point,
            force: self.direction.normalize_or_zero() * self.force_n,
            torque: DVec3::ZERO,
            start_s: self.start_s,
            duration_s: self.duration_s,
        }
    }
}

/// A force `F` (world frame, N) applied at `point` (body frame, m) of body `body`, plus a pure
/// torque `T` (world frame, N·m), while `start_s ≤ t < start_s + duration_s`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExternalForce {
    /// Body index in the model.
    pub body: usize,
    /// Point of application in the body frame (m).
    pub point: DVec3,
    /// Force in world coordinates (N).
    pub force: DVec3,
    /// Pure torque in world coordinates (N·m); zero for a push.
    pub torque: DVec3,
    /// Start time (s).
    pub start_s: f64,
    /// Duration (s); `f64::INFINITY` for a force that stays.
    pub duration_s: f64,
}

impl ExternalForce {
    /// True while the force acts at time `t` (s).
    #[inline]
    pub fn active(&self, t: f64) -> bool {
        t >= self.start_s && t < self.start_s + self.duration_s
    }

    /// The spatial force in body coordinates after kinematics: `f = Rᵀ F`, `n = p × f + Rᵀ T`.
    #[inline]
    pub fn body_force(&self, data: &Data) -> ForceVec {
        let rt = data.rot[self.body].transpose();
        let mut f = ForceVec::at_point(rt * self.force, self.point);
        if self.torque != DVec3::ZERO {
            f.ang += rt * self.torque;
        }
        f
    }
}

/// Adds every force of `forces` active at time `t` (s) to `f_ext` (body coordinates).
#[inline(always)]
pub fn apply_external(data: &Data, forces: &[ExternalForce], t: f64, f_ext: &mut [ForceVec]) {
    for f in forces {
        if f.active(t) {
            f_ext[f.body] += f.body_force(data);
        }
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
