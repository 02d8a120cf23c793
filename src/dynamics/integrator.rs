//! Time integration of `q̇ = v ⊕ …, v̇ = q̈(t, q, v)` on the configuration manifold.
//!
//! Both schemes move `q` by the retraction `q ⊞ z` (see [`JointType::retract`]), so quaternions
//! stay unit and no Euler angles are involved:
//! - classical 4th-order Runge–Kutta (as the paper), run in the chart `z` around `q_n` with the
//!   exact chart rate `ż = dexp⁻¹(z, ω)`, which keeps 4th order on SO(3) (Munthe-Kaas RKMK);
//! - semi-implicit Euler `v' = v + h q̈(q, v)`, `q' = q ⊞ h ż(q, v')`, optionally
//!   with joint damping taken implicitly: `(H + h·diag(d)) q̈ = τ(q, v) − C`, the linearly
//!   implicit step of `τ = −d v'`, so stiff friction and PD damping gains do not force tiny steps;
//! - linearly implicit Euler: the same update with the stiffness *and* damping of the PD, the
//!   joint model and the floor taken implicitly, `(H + h D + h² K) q̈ = f − C − h K v`
//!   ([`super::linearly_implicit`]), stable at steps the stiff springs forbid the others.
//!
//! Semi-implicit Euler is *not* symplectic here. It is symplectic for a separable Hamiltonian in
//! canonical coordinates (constant mass matrix, momentum `p` updated before `q`); this body steps
//! the velocity `v`, not the momentum `p = H(q) v`, with a configuration-dependent `H(q)` and the
//! Coriolis terms evaluated at the old state, and moves `q` through the retraction. The scheme is
//! first-order and its energy error is first order in `h`: on a free conservative articulated
//! body the energy drifts (upward at first in the cases measured) rather than oscillating
//! about the true value. In a fall the joint friction and contact damping remove far more
//! energy than the drift adds; for energy studies use RK4 or a smaller step.
//!
//! [`JointType::retract`]: super::joint::JointType::retract

use super::model::Model;
use serde::{Deserialize, Serialize};

/// The integration scheme.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Integrator {
    /// Classical 4th-order Runge–Kutta (4 dynamics evaluations per step).
    Rk4,
    /// Semi-implicit Euler (1 evaluation per step).
    SemiImplicitEuler {
        /// Take joint damping implicitly (solve with `H + h·diag(d)`).
        implicit_damping: bool,
    },
    /// Semi-implicit Euler with every stiff force linearised and taken implicitly:
    /// `(M + h D + h² K) Δv = h (f − h K v)` with `K`, `D` the stiffness and damping of the PD
    /// terms, of the joint limits past their range, of the joint friction and of the pushing
    /// (and sticking) floor corners (1 evaluation per step; `linearly_implicit`).
    LinearlyImplicitEuler,
    /// The same linearisation taken at the step's midpoint, `θ = ½`:
    /// `(M + ½h D + ½h² K) Δv = h (f − ½h K v)`, i.e. the stiff forces act at
    /// `(q + ½h v', ½(v + v'))`. Stable at every step like [`Self::LinearlyImplicitEuler`], with
    /// half its numerical damping (a spring of `ω` loses a factor `1/√(1 + θω²h²)` of its
    /// amplitude per step), so an impact's peak force is resolved at 2 ms where `θ = 1`
    /// under-reads it; the stiffest modes alternate instead of dying out.
    LinearlyImplicitMidpoint,
}

impl Integrator {
    /// The weight `θ` at which a linearly implicit scheme takes its stiff forces
    /// (`q + θh v'`, `v + θ(v' − v)`): 1 for [`Self::LinearlyImplicitEuler`], ½ for
    /// [`Self::LinearlyImplicitMidpoint`]; `None` for the explicit schemes.
    pub fn linearisation_weight(self) -> Option<f64> {
        match self {
            Integrator::LinearlyImplicitEuler => Some(1.0),
            Integrator::LinearlyImplicitMidpoint => Some(0.5),
            Integrator::Rk4 | Integrator::SemiImplicitEuler { .. } => None,
        }
    }
}

/// The acceleration function `q̈ = f(t, q, v)` a scheme integrates.
pub trait Dynamics {
    /// The error a dynamics evaluation can report (e.g. a non-finite state).
    type Error;
    /// Writes `q̈` (size nv) for time `t` (s), configuration `q` (nq) and velocity `v` (nv).
    /// With `implicit_dt = Some(h)` the implementation takes its joint damping `d`
    /// implicitly, i.e. solves `(H + h·diag(d)) q̈ = τ(q, v) − C`.
    fn acceleration(
        &mut self,
        t: f64,
        q: &[f64],
        v: &[f64],
        implicit_dt: Option<f64>,
        qdd: &mut [f64],
    ) -> Result<(), Self::Error>;

    /// The acceleration of a linearly implicit step of `h` seconds at weight `theta`: with the
    /// force's stiffness `K = −∂f/∂q` and damping `D = −∂f/∂v` at `(q, v)`, it solves
    /// `(H + θh D + θh² K) q̈ = f(q, v) − C − θh K v`, so that `v' = v + h q̈` is the velocity
    /// for which the linearised force `f(q + θh v', v + θ(v' − v))` acts
    /// (`linearly_implicit`). A dynamics that knows no stiffness takes its damping
    /// implicitly only (the default).
    fn acceleration_linearised(
        &mut self,
        t: f64,
        q: &[f64],
        v: &[f64],
        h: f64,
        theta: f64,
        qdd: &mut [f64],
    ) -> Result<(), Self::Error> {
        let _ = theta;
        self.acceleration(t, q, v, Some(h), qdd)
    }
}

/// Buffers of the integrators, sized once from the model (no allocation per step).
#[derive(Clone, Debug)]
pub struct IntegratorWorkspace {
    z: Vec<f64>,
    q_stage: Vec<f64>,
    v_stage: Vec<f64>,
    kz: [Vec<f64>; 4],
    kv: [Vec<f64>; 4],
}

impl IntegratorWorkspace {
    /// The buffer semi-implicit Euler takes its acceleration `q̈` from (size nv).
    #[inline(always)]
    pub fn acceleration_mut(&mut self) -> &mut [f64] {
        &mut self.kv[0]
    }

    /// Allocates buffers for `model`.
    pub fn new(model: &Model) -> Self {
        let nv = model.nv;
        let vz = || vec![0.0; nv];
        Self {
            z: vz(),
            q_stage: vec![0.0; model.nq],
            v_stage: vz(),
            kz: [vz(), vz(), vz(), vz()],
            kv: [vz(), vz(), vz(), vz()],
        }
    }
}

/// Advances `(q, v)` from time `t` by `h` seconds with `scheme`.
#[inline(always)]
pub fn step<D: Dynamics>(
    scheme: Integrator,
    model: &Model,
    ws: &mut IntegratorWorkspace,
    dynamics: &mut D,
    t: f64,
    h: f64,
    (q, v): (&mut [f64], &mut [f64]),
) -> Result<(), D::Error> {
    match scheme {
        Integrator::Rk4 => rk4_step(model, ws, dynamics, t, h, (q, v)),
        Integrator::SemiImplicitEuler { implicit_damping } => {
            let implicit = implicit_damping.then_some(h);
            semi_implicit_euler_step(model, ws, dynamics, t, implicit, h, (q, v))
        }
        Integrator::LinearlyImplicitEuler | Integrator::LinearlyImplicitMidpoint => {
            let theta = scheme.linearisation_weight().unwrap_or(1.0);
            dynamics.acceleration_linearised(t, q, v, h, theta, &mut ws.kv[0])?;
            semi_implicit_euler_advance(model, ws, h, (q, v));
            Ok(())
        }
    }
}

/// One classical Runge–Kutta step in the chart around `q_n`:
/// `k_i = (ż, q̈)` at stage `i`, `z_{n+1} = h/6 (k₁ + 2k₂ + 2k₃ + k₄)`, `q_{n+1} = q_n ⊞ z_{n+1}`.
pub fn rk4_step<D: Dynamics>(
    model: &Model,
    ws: &mut IntegratorWorkspace,
    dynamics: &mut D,
    t: f64,
    h: f64,
    (q, v): (&mut [f64], &mut [f64]),
) -> Result<(), D::Error> {
    let nv = model.nv;
    const C: [f64; 4] = [0.0, 0.5, 0.5, 1.0];
    for s in 0..4 {
        if s == 0 {
            ws.z.fill(0.0);
            ws.q_stage.copy_from_slice(q);
            ws.v_stage.copy_from_slice(v);
        } else {
            let c = C[s] * h;
            for k in 0..nv {
                ws.z[k] = c * ws.kz[s - 1][k];
                ws.v_stage[k] = v[k] + c * ws.kv[s - 1][k];
            }
            model.retract(q, &ws.z, &mut ws.q_stage);
        }
        dynamics.acceleration(t + C[s] * h, &ws.q_stage, &ws.v_stage, None, &mut ws.kv[s])?;
        model.chart_rate(&ws.q_stage, &ws.z, &ws.v_stage, &mut ws.kz[s]);
    }
    let w = h / 6.0;
    for k in 0..nv {
        ws.z[k] = w * (ws.kz[0][k] + 2.0 * ws.kz[1][k] + 2.0 * ws.kz[2][k] + ws.kz[3][k]);
        v[k] += w * (ws.kv[0][k] + 2.0 * ws.kv[1][k] + 2.0 * ws.kv[2][k] + ws.kv[3][k]);
    }
    ws.q_stage.copy_from_slice(q);
    model.retract(&ws.q_stage, &ws.z, q);
    Ok(())
}

/// One semi-implicit Euler step: `v ← v + h q̈(q, v)`, then `q ← q ⊞ h ż(q, v)`; with
/// `implicit = Some(h)` the joint damping is taken implicitly in `q̈`.
#[inline(always)]
pub fn semi_implicit_euler_step<D: Dynamics>(
    model: &Model,
    ws: &mut IntegratorWorkspace,
    dynamics: &mut D,
    t: f64,
    implicit: Option<f64>,
    h: f64,
    (q, v): (&mut [f64], &mut [f64]),
) -> Result<(), D::Error> {
    dynamics.acceleration(t, q, v, implicit, &mut ws.kv[0])?;
    semi_implicit_euler_advance(model, ws, h, (q, v));
    Ok(())
}

/// The update of [`semi_implicit_euler_step`] once its acceleration `q̈` is in
/// [`IntegratorWorkspace::acceleration_mut`]: `v ← v + h q̈`, then `q ← q ⊞ h ż(q, v)`.
#[inline(always)]
pub fn semi_implicit_euler_advance(
    model: &Model,
    ws: &mut IntegratorWorkspace,
    h: f64,
    (q, v): (&mut [f64], &mut [f64]),
) {
    let nv = model.nv;
    for k in 0..nv {
        v[k] += h * ws.kv[0][k];
    }
    ws.z.fill(0.0);
    model.chart_rate(q, &ws.z, v, &mut ws.kz[0]);
    for k in 0..nv {
        ws.z[k] = h * ws.kz[0][k];
    }
    ws.q_stage.copy_from_slice(q);
    model.retract(&ws.q_stage, &ws.z, q);
}
