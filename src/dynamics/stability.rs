//! The largest stable time step of a body before it runs: every contact and joint stiffness is
//! a damped oscillator `ẍ = −ω²x − 2ζωẋ`, and the step must stay inside the scheme's stability
//! region for the stiffest of them.

use super::crba::{cholesky_factor, cholesky_solve, crba};
use super::data::Data;
use super::forces::contact::ContactModel;
use super::integrator::Integrator;
use super::model::Model;

/// The stable step bound for a damped oscillator `ẍ = −ω²x − 2ζωẋ`: semi-implicit Euler
/// `h ≤ 2(√(1+ζ²) − ζ)/ω`; linearly implicit Euler none (backward Euler on the linear
/// oscillator; the nonlinear remainder is watched by the step's runaway check); RK4 `h ≤ 2.5 / (ω(ζ + √(1+ζ²)))` (the real-axis limit is 2.78 and
/// the imaginary-axis limit 2.83 in units of `1/|λ|`).
pub fn stable_step(integrator: Integrator, omega: f64, zeta: f64) -> f64 {
    if omega <= 0.0 {
        return f64::INFINITY;
    }
    let s = (1.0 + zeta * zeta).sqrt();
    match integrator {
        Integrator::Rk4 => 2.5 / (omega * (zeta + s)),
        Integrator::SemiImplicitEuler { .. } => 2.0 * (s - zeta) / omega,
        // The linearised oscillator at θ ≥ ½: no bound.
        Integrator::LinearlyImplicitEuler | Integrator::LinearlyImplicitMidpoint => f64::INFINITY,
    }
}

/// The readable name of a scheme.
pub fn scheme_name(i: Integrator) -> &'static str {
    match i {
        Integrator::Rk4 => "RK4",
        Integrator::SemiImplicitEuler {
            implicit_damping: true,
        } => "semi-implicit Euler (implicit damping)",
        Integrator::SemiImplicitEuler { .. } => "semi-implicit Euler",
        Integrator::LinearlyImplicitEuler => "linearly implicit Euler",
        Integrator::LinearlyImplicitMidpoint => "linearly implicit midpoint",
    }
}

/// The mode that bounds the step most: its bound (s), what it is, the body index, `ω` (rad/s)
/// and `ζ`.
#[derive(Clone, Debug, PartialEq)]
pub struct StiffestMode {
    /// Largest stable step for this mode (s).
    pub bound_s: f64,
    /// `"contact"` or `"joint <dof>"`.
    pub what: String,
    /// Body index.
    pub body: usize,
    /// Natural frequency (rad/s).
    pub omega: f64,
    /// Damping ratio.
    pub zeta: f64,
}

/// One actuated DOF's stiffness for the bound: velocity index, body index, name, stiffness
/// (N·m/rad) and explicit damping (N·m·s/rad; zero when the scheme takes it implicitly).
#[derive(Clone, Debug, PartialEq)]
pub struct DofStiffness {
    /// Index in `v`.
    pub v: usize,
    /// Body the DOF moves.
    pub body: usize,
    /// DOF name.
    pub name: String,
    /// Stiffness (N·m/rad).
    pub stiffness: f64,
    /// Damping taken explicitly (N·m·s/rad).
    pub damping: f64,
}

/// The stiffest mode of a body at configuration `q`: per link the contact bound of
/// [`ContactModel::link_frequency`] (undamped, `ζ = 0`, when semi-implicit Euler takes the contact
/// damping implicitly, [`ContactParams::implicit_damping`](super::forces::contact::ContactParams::implicit_damping);
/// the undamped bound `2/ω` is then
/// conservative); per DOF `ω² = k (H⁻¹)_jj`, `2ζω = d (H⁻¹)_jj` with `H` the
/// joint-space inertia at `q`. `None` when there is nothing stiff.
pub fn stiffest_mode(
    model: &Model,
    q: &[f64],
    integrator: Integrator,
    contact: Option<&ContactModel>,
    dofs: &[DofStiffness],
) -> Result<Option<StiffestMode>, super::model::ModelError> {
    Ok(StiffnessBasis::new(model, q, integrator, contact)?.stiffest_mode(dofs))
}

/// What [`stiffest_mode`] finds that does not depend on the DOFs' gains, for checking many
/// gains at one configuration (the reactions of a GA batch): the stiffest contact mode and
/// `(H⁻¹)_jj` of every velocity index at `q`. [`StiffnessBasis::stiffest_mode`] then gives
/// [`stiffest_mode`]'s answer, bit for bit.
#[derive(Clone, Debug, PartialEq)]
pub struct StiffnessBasis {
    /// The scheme the bounds are for.
    integrator: Integrator,
    /// The contact mode with the smallest bound (the first such link), if any link has contact.
    contact: Option<StiffestMode>,
    /// `(H⁻¹)_jj` (1/(kg·m²) for a revolute DOF) for every velocity index `j`.
    inverse_inertia: Vec<f64>,
}

impl StiffnessBasis {
    /// The contact modes of every link and the inverse joint inertia at `q`.
    pub fn new(
        model: &Model,
        q: &[f64],
        integrator: Integrator,
        contact: Option<&ContactModel>,
    ) -> Result<Self, super::model::ModelError> {
        // Contact damping taken implicitly in semi-implicit Euler leaves the undamped bound 2/ω.
        let implicit_damping = contact.is_some_and(|cm| {
            cm.params.implicit_damping && matches!(integrator, Integrator::SemiImplicitEuler { .. })
        });
        let mut worst: Option<StiffestMode> = None;
        if let Some(cm) = contact {
            for i in 0..model.nbodies() {
                let (omega, zeta) = cm.link_frequency(i, &model.bodies[i].inertia);
                let zeta = if implicit_damping { 0.0 } else { zeta };
                let bound = stable_step(integrator, omega, zeta);
                if worst.as_ref().is_none_or(|w| bound < w.bound_s) {
                    worst = Some(StiffestMode {
                        bound_s: bound,
                        what: "contact".to_string(),
                        body: i,
                        omega,
                        zeta,
                    });
                }
            }
        }
        let all: Vec<usize> = (0..model.nv).collect();
        Ok(Self {
            integrator,
            contact: worst,
            inverse_inertia: inverse_joint_inertia(model, q, &all)?,
        })
    }

    /// The stiffest mode with the DOF stiffnesses `dofs` (their `v` within the model's): the
    /// contact mode unless a DOF's bound is smaller (the first such DOF).
    pub fn stiffest_mode(&self, dofs: &[DofStiffness]) -> Option<StiffestMode> {
        let mut worst = self.contact.clone();
        for d in dofs {
            let w = self.inverse_inertia[d.v];
            let omega = (d.stiffness * w).sqrt();
            let zeta = if omega > 0.0 {
                d.damping * w / (2.0 * omega)
            } else {
                0.0
            };
            let bound = stable_step(self.integrator, omega, zeta);
            if worst.as_ref().is_none_or(|m| bound < m.bound_s) {
                worst = Some(StiffestMode {
                    bound_s: bound,
                    what: format!("joint {}", d.name),
                    body: d.body,
                    omega,
                    zeta,
                });
            }
        }
        worst
    }
}

/// The inverse effective inertia `(H⁻¹)_jj` (1/(kg·m²) for a revolute DOF) of each velocity
/// index `j` of `vs` at configuration `q`, with `H` the joint-space inertia of the free tree
/// (CRBA): the DOF's `ω² = k (H⁻¹)_jj` under a spring `k`.
pub fn inverse_joint_inertia(
    model: &Model,
    q: &[f64],
    vs: &[usize],
) -> Result<Vec<f64>, super::model::ModelError> {
    let nv = model.nv;
    let mut data = Data::new(model);
    crba(model, &mut data, q)?;
    let mut h = data.h.clone();
    cholesky_factor(&mut h, nv)?;
    let mut e = vec![0.0; nv];
    Ok(vs
        .iter()
        .map(|&j| {
            e.fill(0.0);
            e[j] = 1.0;
            cholesky_solve(&h, nv, &mut e);
            e[j]
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::integrator::Integrator;

    /// Largest |x| after `n` steps of `ẍ = −ω²x − 2ζωẋ` from x = 1 with the given scheme.
    fn oscillate(integrator: Integrator, omega: f64, zeta: f64, h: f64, n: usize) -> f64 {
        let f = |x: f64, v: f64| -omega * omega * x - 2.0 * zeta * omega * v;
        let (mut x, mut v) = (1.0f64, 0.0f64);
        let mut peak: f64 = 0.0;
        for _ in 0..n {
            match integrator {
                Integrator::SemiImplicitEuler { .. } => {
                    v += h * f(x, v);
                    x += h * v;
                }
                Integrator::LinearlyImplicitEuler | Integrator::LinearlyImplicitMidpoint => {
                    let th = integrator.linearisation_weight().unwrap_or(1.0) * h;
                    let (k, c) = (omega * omega, 2.0 * zeta * omega);
                    v += h * (f(x, v) - th * k * v) / (1.0 + th * c + th * h * k);
                    x += h * v;
                }
                Integrator::Rk4 => {
                    let (k1x, k1v) = (v, f(x, v));
                    let (k2x, k2v) = (v + 0.5 * h * k1v, f(x + 0.5 * h * k1x, v + 0.5 * h * k1v));
                    let (k3x, k3v) = (v + 0.5 * h * k2v, f(x + 0.5 * h * k2x, v + 0.5 * h * k2v));
                    let (k4x, k4v) = (v + h * k3v, f(x + h * k3x, v + h * k3v));
                    x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
                    v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
                }
            }
            peak = peak.max(x.abs());
        }
        peak
    }

    #[test]
    fn the_step_bound_separates_stable_from_unstable() {
        let euler = Integrator::SemiImplicitEuler {
            implicit_damping: false,
        };
        for zeta in [0.0, 0.3, 1.0, 3.0] {
            let b = stable_step(euler, 100.0, zeta);
            assert!(
                oscillate(euler, 100.0, zeta, 0.99 * b, 20_000) < 10.0,
                "ζ={zeta}"
            );
            assert!(
                oscillate(euler, 100.0, zeta, 1.02 * b, 20_000) > 1e3,
                "ζ={zeta}"
            );
            // RK4's bound is conservative: stable at it.
            let r = stable_step(Integrator::Rk4, 100.0, zeta);
            assert!(
                oscillate(Integrator::Rk4, 100.0, zeta, r, 20_000) <= 1.0 + 1e-9,
                "ζ={zeta}"
            );
        }
    }
}
