//! Computed-torque feedforward (the inverse dynamics of a desired motion): the generalised
//! force `τ_ff = RNEA(q_d, q̇_d, q̈_d)` that moves the body along `(q_d, q̇_d)` with no contact
//! and no other external force, `q̈_d` the backward difference of `q̇_d` over one control step.
//! A floating body's share at its free root ([`root_share`]) is what no joint can supply; an
//! external wrench at the root (the root assistance) can.

use glam::{DQuat, DVec3};

use super::assist::Wrench;
use crate::dynamics::data::Data;
use crate::dynamics::model::{Model, ModelError};
use crate::dynamics::rnea;
use crate::dynamics::spatial::ForceVec;

/// The feedforward of a motion sampled once per control step: it keeps the previous desired
/// velocity for the backward difference and the RNEA's buffers.
#[derive(Clone, Debug, Default)]
pub struct ComputedTorque {
    previous_velocity: Option<Vec<f64>>,
    acceleration: Vec<f64>,
    data: Option<Data>,
}

impl ComputedTorque {
    /// `τ_ff = RNEA(q_d, q̇_d, q̈_d)` (N·m per hinge, `nv` entries, the free root's first) of
    /// `model` at the desired configuration `q_d` and velocity `v_d`, with
    /// `q̈_d = (q̇_d − q̇_d,prev) / dt` from the previous call's `v_d` (`dt` in s; zero at the
    /// first call). A `q_d` or `v_d` of another size than the model's is a
    /// [`ModelError::SizeMismatch`].
    pub fn torques(
        &mut self,
        model: &Model,
        q_d: &[f64],
        v_d: Vec<f64>,
        dt: f64,
    ) -> Result<&[f64], ModelError> {
        model.check_state(q_d, &v_d)?;
        self.acceleration.resize(v_d.len(), 0.0);
        if let Some(prev) = &self.previous_velocity {
            for ((a, v), p) in self.acceleration.iter_mut().zip(&v_d).zip(prev) {
                *a = (v - p) / dt;
            }
        }
        let data = self.data.get_or_insert_with(|| Data::new(model));
        let f_ext = vec![ForceVec::ZERO; model.nbodies()];
        let tau = rnea(model, data, q_d, &v_d, &self.acceleration, &f_ext)?;
        self.previous_velocity = Some(v_d);
        Ok(tau)
    }
}

/// The free root's share of a generalised force `tau` as a world-frame wrench about the root
/// origin: the root's entry `[n; f]` (root coordinates, N·m and N) turned by the root
/// orientation `R` of the configuration `q` (`q[3..7]` a unit quaternion `x, y, z, w`):
/// `T = R n`, `F = R f`.
pub fn root_share(q: &[f64], tau: &[f64]) -> Wrench {
    let rot = DQuat::from_xyzw(q[3], q[4], q[5], q[6]);
    Wrench {
        torque: rot * DVec3::new(tau[0], tau[1], tau[2]),
        force: rot * DVec3::new(tau[3], tau[4], tau[5]),
    }
}
