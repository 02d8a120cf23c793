//! Static balance of a body standing at rest: where the floor carries it, and the joint torques
//! that hold its pose.
//!
//! At rest (`v = 0`) the equations of motion read `H(q) q̈ = τ(q) − g(q) + Σ Jᵢᵀ fᵢ(q)`: every
//! velocity term (PD and joint damping, contact damping, Coriolis) vanishes, and with the
//! friction anchors held every remaining force is a function of `q` alone (PD and limit
//! springs, the floor's normal and stick springs, gravity). Call `F(q) = H(q) q̈(q, 0)` the
//! generalized force imbalance. The body is in equilibrium exactly where `F = 0`.
//!
//! The six rows of an unactuated free base are the net wrench of gravity and contact on the
//! whole body (no joint torque enters them): only placing the body can zero them.
//! [`balance_base`] does so by Newton's method on the base coordinates in the tangent chart
//! `q ⊞ z` ([`Model::retract`]): `J Δz = −F_base` with `J = ∂F_base/∂z` by central differences
//! (step `ε`), backtracking on `‖F_base‖₂` when a step crosses a kink of the force model (a
//! corner touching or leaving the floor). A balanced state then has its friction anchors
//! brought to it (a corner whose stick spring would leave the friction cone slips, one that
//! left the floor lets go); if that moved an anchor, the forces changed and Newton runs again.
//!
//! The joint rows are what the actuators must add to hold the pose where it is:
//! [`holding_torques`] `τ_hold = −F_joints`. With them added to the joint torques,
//! `F(q) = 0`: the state is an exact static equilibrium (`q̈ = 0` to rounding).

use std::ops::Range;

use super::crba::crba;
use super::data::Data;
use super::forces::contact::ContactSample;
use super::model::Model;
use super::pipeline::{Forces, State, StepError, StepWorkspace, acceleration};
use super::spatial::ForceVec;

/// How the base is balanced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BalanceSettings {
    /// Largest residual component of the base's wrench accepted (N or N·m).
    pub tolerance: f64,
    /// Most Newton iterations (over all anchor passes).
    pub max_iterations: usize,
    /// Central-difference step `ε` in the tangent chart (m or rad).
    pub difference_step: f64,
    /// Most times the anchors are brought to a balanced state and Newton repeated.
    pub max_anchor_passes: usize,
}

impl Default for BalanceSettings {
    fn default() -> Self {
        Self {
            tolerance: 1e-6,
            max_iterations: 50,
            difference_step: 1e-7,
            max_anchor_passes: 8,
        }
    }
}

/// A balanced base: Newton iterations taken, anchor passes, and the largest residual
/// component of the base's wrench left (N or N·m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Balance {
    /// Newton iterations over all passes.
    pub iterations: usize,
    /// Times the anchors were brought to a balanced state.
    pub anchor_passes: usize,
    /// Largest `|F_k|` of the base rows at the solution (N or N·m).
    pub residual: f64,
}

/// Why the body could not be balanced.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EquilibriumError {
    /// Newton did not bring the residual below the tolerance.
    #[error(
        "the floor does not balance the body: after {iterations} Newton iterations the net \
         wrench on its base is still {residual:.3e} (tolerance {tolerance:.1e})"
    )]
    NoConvergence {
        /// Iterations taken.
        iterations: usize,
        /// Largest residual component left.
        residual: f64,
        /// The tolerance asked for.
        tolerance: f64,
    },
    /// The linearised floor forces do not determine a step (the base rests on too few points).
    #[error("the floor does not hold the body: its stiffness is singular in base coordinate {dof}")]
    Singular {
        /// Base coordinate of the pivot that vanished.
        dof: usize,
    },
    /// A force evaluation failed.
    #[error(transparent)]
    Step(#[from] StepError),
}

fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m, a| m.max(a.abs()))
}

fn norm2(x: &[f64]) -> f64 {
    x.iter().map(|a| a * a).sum::<f64>().sqrt()
}

/// Solves `a x = b` in place (`a` n × n row-major, overwritten) by Gaussian elimination with
/// partial pivoting; `b` becomes `x`.
fn lu_solve(a: &mut [f64], n: usize, b: &mut [f64]) -> Result<(), EquilibriumError> {
    let scale = max_abs(a).max(f64::MIN_POSITIVE);
    for c in 0..n {
        let p = (c..n)
            .max_by(|&i, &j| a[i * n + c].abs().total_cmp(&a[j * n + c].abs()))
            .unwrap_or(c);
        if a[p * n + c].abs() <= 1e-14 * scale {
            return Err(EquilibriumError::Singular { dof: c });
        }
        if p != c {
            for k in 0..n {
                a.swap(p * n + k, c * n + k);
            }
            b.swap(p, c);
        }
        let d = a[c * n + c];
        for i in c + 1..n {
            let f = a[i * n + c] / d;
            if f != 0.0 {
                for k in c..n {
                    a[i * n + k] -= f * a[c * n + k];
                }
                b[i] -= f * b[c];
            }
        }
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= a[i * n + k] * b[k];
        }
        b[i] = s / a[i * n + i];
    }
    Ok(())
}

/// The generalized force imbalance `F = H(q) q̈(q, v)` of `state` under `forces` (size nv; at
/// rest, module docs), with its friction anchors as they are; `h` is scratch for `H`.
pub fn imbalance(
    model: &Model,
    forces: &Forces,
    state: &State,
    ws: &mut StepWorkspace,
    h: &mut Data,
    out: &mut [f64],
) -> Result<(), StepError> {
    let nv = model.nv;
    let mut qdd = vec![0.0; nv];
    acceleration(model, forces, state, ws, &mut qdd)?;
    let hm = crba(model, h, &state.q)?;
    for (i, o) in out.iter_mut().enumerate() {
        *o = (0..nv).map(|k| hm[i * nv + k] * qdd[k]).sum();
    }
    Ok(())
}

/// Brings the friction anchors of `state` to its configuration; true if one changed.
fn reseat_anchors(
    model: &Model,
    forces: &Forces,
    state: &mut State,
    ws: &mut StepWorkspace,
) -> bool {
    let Some(cm) = forces.contact else {
        return false;
    };
    let before = state.anchors.clone();
    ws.eval.kinematics_at_step = None;
    let data = ws.kinematics_of(model, state);
    let mut f_ext = vec![ForceVec::ZERO; model.nbodies()];
    let mut sample = ContactSample::new(model.nbodies());
    cm.update_and_apply(data, &mut state.anchors, &mut f_ext, &mut sample);
    ws.eval.kinematics_at_step = None;
    state.anchors != before
}

/// Places the free base of `state` (velocity indices `base`, the base's rows of `F`) where
/// gravity and the floor balance on it, the joints held where they are; sets the velocity to
/// zero and brings the friction anchors to the result (module docs).
pub fn balance_base(
    model: &Model,
    forces: &Forces,
    state: &mut State,
    ws: &mut StepWorkspace,
    base: Range<usize>,
    settings: BalanceSettings,
) -> Result<Balance, EquilibriumError> {
    let nv = model.nv;
    let nb = base.len();
    state.v.iter_mut().for_each(|x| *x = 0.0);
    let mut h = Data::new(model);
    let mut full = vec![0.0; nv];
    let mut eval = |state: &State, ws: &mut StepWorkspace, out: &mut [f64]| {
        imbalance(model, forces, state, ws, &mut h, &mut full)?;
        out.copy_from_slice(&full[base.clone()]);
        Ok::<_, StepError>(())
    };
    let (mut r, mut r_try) = (vec![0.0; nb], vec![0.0; nb]);
    let mut jac = vec![0.0; nb * nb];
    let mut q_base = state.q.clone();
    let (mut iterations, mut passes) = (0, 0);
    let no_convergence = |iterations, r: &[f64]| EquilibriumError::NoConvergence {
        iterations,
        residual: max_abs(r),
        tolerance: settings.tolerance,
    };
    loop {
        eval(state, ws, &mut r)?;
        while max_abs(&r) > settings.tolerance {
            if iterations >= settings.max_iterations {
                return Err(no_convergence(iterations, &r));
            }
            iterations += 1;
            q_base.copy_from_slice(&state.q);
            let probe = BaseProbe {
                model,
                base: &base,
                q_base: &q_base,
            };
            probe.jacobian(settings.difference_step, state, ws, &mut eval, &mut jac)?;
            let mut dz: Vec<f64> = r.iter().map(|x| -x).collect();
            lu_solve(&mut jac, nb, &mut dz)?;
            let n0 = norm2(&r);
            probe.backtrack(&dz, n0, state, ws, &mut eval, &mut r_try)?;
            if norm2(&r_try) >= n0 {
                state.q.copy_from_slice(&q_base);
                return Err(no_convergence(iterations, &r));
            }
            r.copy_from_slice(&r_try);
        }
        passes += 1;
        let moved = reseat_anchors(model, forces, state, ws);
        if !moved || passes >= settings.max_anchor_passes {
            eval(state, ws, &mut r)?;
            if max_abs(&r) > settings.tolerance {
                return Err(no_convergence(iterations, &r));
            }
            return Ok(Balance {
                iterations,
                anchor_passes: passes,
                residual: max_abs(&r),
            });
        }
    }
}

/// Moves of the base coordinates `base` of `model` about the configuration `q_base`, with
/// `eval` the base's imbalance `F` at `state` (see [`balance_base`]).
struct BaseProbe<'a> {
    model: &'a Model,
    base: &'a Range<usize>,
    q_base: &'a [f64],
}

impl BaseProbe<'_> {
    /// `state.q = q_base ⊞ z`, `z` zero outside the base and `step(k)` on base coordinate `k`.
    fn retract_base(&self, state: &mut State, step: impl Fn(usize) -> f64) {
        let mut z = vec![0.0; self.model.nv];
        for k in 0..self.base.len() {
            z[self.base.start + k] = step(k);
        }
        self.model.retract(self.q_base, &z, &mut state.q);
    }

    /// The Jacobian by central differences, `J[:, k] = (F(q ⊞ ε e_k) − F(q ⊞ −ε e_k)) / 2ε`
    /// over the base coordinates, into `jac` (row-major, nb × nb).
    fn jacobian(
        &self,
        eps: f64,
        state: &mut State,
        ws: &mut StepWorkspace,
        eval: &mut impl FnMut(&State, &mut StepWorkspace, &mut [f64]) -> Result<(), StepError>,
        jac: &mut [f64],
    ) -> Result<(), StepError> {
        let nb = self.base.len();
        let (mut col_p, mut col_m) = (vec![0.0; nb], vec![0.0; nb]);
        for k in 0..nb {
            self.retract_base(state, |j| if j == k { eps } else { 0.0 });
            eval(state, ws, &mut col_p)?;
            self.retract_base(state, |j| if j == k { -eps } else { 0.0 });
            eval(state, ws, &mut col_m)?;
            for i in 0..nb {
                jac[i * nb + k] = (col_p[i] - col_m[i]) / (2.0 * eps);
            }
        }
        Ok(())
    }

    /// Backtracking along the Newton step `dz`: the full step unless it raises the residual
    /// norm `n0`, halved until it does not (or below 1e-6); `r_try` holds the residual there.
    fn backtrack(
        &self,
        dz: &[f64],
        n0: f64,
        state: &mut State,
        ws: &mut StepWorkspace,
        eval: &mut impl FnMut(&State, &mut StepWorkspace, &mut [f64]) -> Result<(), StepError>,
        r_try: &mut [f64],
    ) -> Result<(), StepError> {
        let mut t = 1.0;
        loop {
            self.retract_base(state, |k| t * dz[k]);
            eval(state, ws, r_try)?;
            if norm2(r_try) < n0 || t < 1e-6 {
                return Ok(());
            }
            t *= 0.5;
        }
    }
}

/// The torques (N·m or N, one per entry of `dofs`, their velocity indices) the actuators must
/// add to the joint torques of `forces` to hold `state` at rest where it is:
/// `τ_hold = −F_dofs` (module docs).
pub fn holding_torques(
    model: &Model,
    forces: &Forces,
    state: &State,
    ws: &mut StepWorkspace,
    dofs: &[usize],
) -> Result<Vec<f64>, StepError> {
    let mut rest = state.clone();
    rest.v.iter_mut().for_each(|x| *x = 0.0);
    let mut h = Data::new(model);
    let mut full = vec![0.0; model.nv];
    imbalance(model, forces, &rest, ws, &mut h, &mut full)?;
    Ok(dofs.iter().map(|&k| -full[k]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::Integrator;
    use crate::dynamics::forces::contact::{ContactGains, ContactModel, ContactParams, LinkBox};
    use crate::dynamics::forces::pd::PdTargets;
    use crate::dynamics::joint::JointType;
    use crate::dynamics::model::Body;
    use crate::dynamics::pipeline::{self, StepMonitor, StepSettings};
    use crate::dynamics::spatial::{Inertia, SpatialTransform};
    use glam::DVec3;

    /// A 10 kg block on the floor with a 2 kg arm on a pin at its top edge, held out sideways
    /// by a PD too weak to hold it level on its own.
    fn block_with_arm() -> (Model, ContactModel, PdTargets) {
        let block = DVec3::new(0.4, 0.2, 0.3);
        let model = Model::new(
            vec![
                Body {
                    name: "block".into(),
                    joint_name: "free".into(),
                    parent: None,
                    joint: JointType::Free,
                    x_tree: SpatialTransform::IDENTITY,
                    inertia: Inertia::solid_box(10.0, DVec3::ZERO, block),
                },
                Body {
                    name: "arm".into(),
                    joint_name: "pin".into(),
                    parent: Some(0),
                    joint: JointType::Pin { axis: DVec3::Z },
                    x_tree: SpatialTransform::translation(DVec3::new(0.2, 0.1, 0.0)),
                    inertia: Inertia::solid_box(
                        2.0,
                        DVec3::new(0.25, 0.0, 0.0),
                        DVec3::new(0.5, 0.05, 0.05),
                    ),
                },
            ],
            DVec3::new(0.0, -9.81, 0.0),
        )
        .unwrap();
        let boxes = [
            LinkBox {
                center: DVec3::ZERO,
                half: block * 0.5,
            },
            // Far from the floor: the arm never touches.
            LinkBox {
                center: DVec3::new(0.25, 0.0, 0.0),
                half: DVec3::splat(0.01),
            },
        ];
        let gains = [
            ContactGains {
                stiffness_n_per_m: 4.0e4,
                damping_n_s_per_m: 400.0,
            },
            ContactGains {
                stiffness_n_per_m: 1.0e3,
                damping_n_s_per_m: 10.0,
            },
        ];
        let cm = ContactModel::new(&boxes, &[10.0, 2.0], &gains, ContactParams::default());
        let pd = PdTargets::hold(vec![0.0], vec![20.0], vec![2.0]);
        (model, cm, pd)
    }

    #[test]
    fn a_balanced_base_with_its_holding_torques_stays_at_rest() {
        let (model, cm, pd) = block_with_arm();
        let dofs = [6];
        let mut q = model.neutral();
        // Resting on its bottom face, the springs not yet compressed.
        q[1] = 0.1 - 1e-4;
        let mut state = State::new(q, vec![0.0; model.nv], 2);
        let mut ws = StepWorkspace::new(&model);
        let forces = Forces {
            dofs: &dofs,
            pd: Some(&pd),
            limits: None,
            contact: Some(&cm),
            external: &[],
        };
        // The first contact evaluation anchors the corners where they are.
        reseat_anchors(&model, &forces, &mut state, &mut ws);
        let b = balance_base(
            &model,
            &forces,
            &mut state,
            &mut ws,
            0..6,
            BalanceSettings::default(),
        )
        .unwrap();
        assert!(b.residual <= 1e-6, "{b:?}");
        // The arm (2 kg, 0.25 m out) needs about m g l = 4.9 N·m to stay level.
        let hold = holding_torques(&model, &forces, &state, &mut ws, &dofs).unwrap();
        assert!((hold[0] - 2.0 * 9.81 * 0.25).abs() < 0.05, "{hold:?}");
        let mut held = pd.clone();
        held.feedforward = hold;
        let forces = Forces {
            pd: Some(&held),
            ..forces
        };
        let mut qdd = vec![0.0; model.nv];
        pipeline::acceleration(&model, &forces, &state, &mut ws, &mut qdd).unwrap();
        assert!(max_abs(&qdd) < 1e-6, "{qdd:?}");
        // Stepped for a second, it does not move.
        let q0 = state.q.clone();
        let mut monitor = StepMonitor::new(2, 1);
        let settings = StepSettings {
            integrator: Integrator::SemiImplicitEuler {
                implicit_damping: true,
            },
            dt: 5e-4,
        };
        for _ in 0..2000 {
            pipeline::step(&model, settings, &forces, &mut state, &mut ws, &mut monitor).unwrap();
        }
        let moved = state
            .q
            .iter()
            .zip(&q0)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(moved < 1e-6, "moved {moved}");
        assert!((monitor.sample.normal[0] - 12.0 * 9.81).abs() < 1e-6);
    }

    #[test]
    fn gaussian_elimination_solves_a_system_that_needs_pivoting() {
        // [[0, 2, 1], [1, 1, 0], [3, 0, 1]] x = b for x = (1, −2, 3).
        let mut a = vec![0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0];
        let mut b = vec![-1.0, -1.0, 6.0];
        lu_solve(&mut a, 3, &mut b).unwrap();
        for (x, e) in b.iter().zip([1.0, -2.0, 3.0]) {
            assert!((x - e).abs() < 1e-12, "{b:?}");
        }
        let mut s = vec![1.0, 2.0, 2.0, 4.0];
        assert!(matches!(
            lu_solve(&mut s, 2, &mut [1.0, 1.0]),
            Err(EquilibriumError::Singular { dof: 1 })
        ));
    }
}
