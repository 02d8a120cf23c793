//! Playing a primitive: a fixed-step integrator of all DOFs' transformation systems driven by the
//! one shared canonical phase.
//!
//! **Integrator.** Classical RK4 in normalised time u = t/τ. To reach a requested time the interval
//! Δu is cut into `ceil(Δu / h_max)` equal sub-steps with `h_max = min(1/500, 1/(4(N − 1)))`
//! (N kernels: at least four sub-steps per kernel spacing). The phase is evaluated exactly
//! ([`CanonicalSystem::phase`]) at each sub-step's start, middle and end, once for all DOFs; the
//! forcing of every DOF is then a dot product of its weights with the shared normalised
//! activations. Because steps are fixed in u, playing at τ′ = kτ and sampling at k·t performs
//! exactly the same arithmetic: the same path, k times slower.

use super::basis::Basis;
use super::canonical::CanonicalSystem;
use super::dmp::Formulation;
use super::error::{PrimitiveError, Result, require_finite};
use super::primitive::Primitive;

/// The state of every DOF at one instant: angle (rad, or m) and rate (rad/s, or m/s).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct DofState {
    /// θ per DOF.
    pub theta: Vec<f64>,
    /// θ̇ per DOF, per second.
    pub theta_dot: Vec<f64>,
}

/// A rollout sampled at requested times.
#[derive(Clone, Debug, PartialEq)]
pub struct Samples {
    /// Sample times, seconds from the primitive's start.
    pub times: Vec<f64>,
    /// DOF names.
    pub names: Vec<String>,
    /// `times × dofs` angles, row-major (rad, or m).
    pub values: Vec<f64>,
    /// `times × dofs` rates, row-major (rad/s, or m/s).
    pub velocities: Vec<f64>,
}

/// A primitive being played: its integration state (u, θ, z per DOF) and the data it needs.
/// Owns everything, so it can live in an ECS component.
#[derive(Clone, Debug)]
pub struct Rollout {
    formulation: Formulation,
    canonical: CanonicalSystem,
    basis: Basis,
    tau: f64,
    h_max: f64,
    nk: usize,
    /// dofs × kernels.
    weights: Vec<f64>,
    goal: Vec<f64>,
    start: Vec<f64>,
    /// Spatial scaling factor k per DOF.
    scale: Vec<f64>,
    u: f64,
    x_now: f64,
    theta: Vec<f64>,
    z: Vec<f64>,
    f_now: Vec<f64>,
    f_mid: Vec<f64>,
    f_end: Vec<f64>,
    psi: Vec<f64>,
}

/// Gated, scaled forcing of every DOF at normalised time u into `out`; returns the phase x.
#[allow(clippy::too_many_arguments)]
fn forcing(
    canonical: &CanonicalSystem,
    basis: &Basis,
    weights: &[f64],
    scale: &[f64],
    nk: usize,
    psi: &mut [f64],
    u: f64,
    out: &mut [f64],
) -> f64 {
    let p = canonical.phase(u);
    if p.gate == 0.0 {
        out.fill(0.0);
        return p.x;
    }
    let r = basis.normalized(p.x, psi);
    let act = &psi[r.clone()];
    for (j, o) in out.iter_mut().enumerate() {
        let w = &weights[j * nk + r.start..j * nk + r.end];
        let mut h = 0.0;
        for (a, b) in act.iter().zip(w) {
            h += a * b;
        }
        *o = p.gate * scale[j] * h;
    }
    p.x
}

impl Rollout {
    /// Starts playing `p` at t = 0 from the demonstrated start (θ = s, θ̇ = k·start_rate/τ with k
    /// the goal-scaling factor, so a new goal scales the whole demonstrated path), or from
    /// `start` (connect: θ and θ̇ of the previous motion). The start enters the spatial scaling
    /// k = (g − s)/A with s = the actual start angle.
    pub fn new(p: &Primitive, start: Option<&DofState>) -> Result<Rollout> {
        p.validate()?;
        let dofs = p.dofs.len();
        let nk = p.basis.len();
        let (theta0, rate0): (Vec<f64>, Vec<f64>) = match start {
            // The demonstrated start rate is part of the demonstrated path, so it scales with
            // the goal like the rest of it: θ(t) − s scales by k exactly.
            None => (
                p.dofs.iter().map(|d| d.start).collect(),
                p.dofs
                    .iter()
                    .map(|d| d.start_rate * d.scaling.factor(d.goal, d.start))
                    .collect(),
            ),
            Some(s) => {
                if s.theta.len() != dofs || s.theta_dot.len() != dofs {
                    return Err(PrimitiveError::DofMismatch {
                        what: format!(
                            "start state has {} angles and {} rates for {dofs} DOFs of `{}`",
                            s.theta.len(),
                            s.theta_dot.len(),
                            p.name
                        ),
                    });
                }
                require_finite("start.theta", &s.theta)?;
                require_finite("start.theta_dot", &s.theta_dot)?;
                (
                    s.theta.clone(),
                    s.theta_dot.iter().map(|v| v * p.duration).collect(),
                )
            }
        };
        let scale: Vec<f64> = p
            .dofs
            .iter()
            .zip(&theta0)
            .map(|(d, s)| d.scaling.factor(d.goal, *s))
            .collect();
        let mut weights = Vec::with_capacity(dofs * nk);
        for d in &p.dofs {
            weights.extend_from_slice(&d.weights);
        }
        let canonical = p.formulation.canonical();
        let mut r = Rollout {
            formulation: p.formulation,
            canonical,
            basis: p.basis.clone(),
            tau: p.duration,
            h_max: (1.0f64 / 500.0).min(0.25 / (nk.max(2) - 1) as f64),
            nk,
            weights,
            goal: p.dofs.iter().map(|d| d.goal).collect(),
            start: theta0.clone(),
            scale,
            u: 0.0,
            x_now: 0.0,
            theta: theta0,
            z: vec![0.0; dofs],
            f_now: vec![0.0; dofs],
            f_mid: vec![0.0; dofs],
            f_end: vec![0.0; dofs],
            psi: vec![0.0; nk],
        };
        r.x_now = forcing(
            &r.canonical,
            &r.basis,
            &r.weights,
            &r.scale,
            nk,
            &mut r.psi,
            0.0,
            &mut r.f_now,
        );
        let in_velocity = r.formulation.forcing_in_velocity();
        for ((z, rate), f) in r.z.iter_mut().zip(&rate0).zip(&r.f_now) {
            // θ′(0) = z(0) + F(0) for 2002, θ′(0) = z(0) otherwise.
            *z = if in_velocity { rate - f } else { *rate };
        }
        Ok(r)
    }

    /// Movement duration τ, seconds.
    pub fn duration(&self) -> f64 {
        self.tau
    }

    /// Time since the start, seconds.
    pub fn time(&self) -> f64 {
        self.u * self.tau
    }

    /// Normalised time u = t/τ (1 at the end of the movement; it may run past 1).
    pub fn normalized_time(&self) -> f64 {
        self.u
    }

    /// Current θ per DOF.
    pub fn theta(&self) -> &[f64] {
        &self.theta
    }

    /// Current θ̇ per DOF (per second) into `out`: θ′/τ with θ′ = z + F (2002) or z.
    pub fn theta_dot_into(&self, out: &mut [f64]) {
        let in_velocity = self.formulation.forcing_in_velocity();
        for (j, o) in out.iter_mut().enumerate() {
            let d = if in_velocity {
                self.z[j] + self.f_now[j]
            } else {
                self.z[j]
            };
            *o = d / self.tau;
        }
    }

    /// The current state (θ, θ̇).
    pub fn state(&self) -> DofState {
        let mut v = vec![0.0; self.theta.len()];
        self.theta_dot_into(&mut v);
        DofState {
            theta: self.theta.clone(),
            theta_dot: v,
        }
    }

    /// Advances by `dt` seconds (≥ 0).
    pub fn advance(&mut self, dt: f64) {
        let t = self.time() + dt.max(0.0);
        self.advance_to(t);
    }

    /// Integrates forward to time `t` seconds (no-op if `t` is not after the current time).
    pub fn advance_to(&mut self, t: f64) {
        let target = t / self.tau;
        let du = target - self.u;
        if du.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return;
        }
        let n = (du / self.h_max).ceil().max(1.0) as usize;
        let h = du / n as f64;
        let u0 = self.u;
        for i in 0..n {
            let a = u0 + i as f64 * h;
            let b = if i + 1 == n { target } else { a + h };
            self.step(a, b);
        }
    }

    /// One RK4 step from u = a to u = b.
    fn step(&mut self, a: f64, b: f64) {
        let h = b - a;
        let nk = self.nk;
        let xm = forcing(
            &self.canonical,
            &self.basis,
            &self.weights,
            &self.scale,
            nk,
            &mut self.psi,
            a + 0.5 * h,
            &mut self.f_mid,
        );
        let x1 = forcing(
            &self.canonical,
            &self.basis,
            &self.weights,
            &self.scale,
            nk,
            &mut self.psi,
            b,
            &mut self.f_end,
        );
        let x0 = self.x_now;
        let f = self.formulation;
        let hh = 0.5 * h;
        for j in 0..self.theta.len() {
            let (th, z, g, s) = (self.theta[j], self.z[j], self.goal[j], self.start[j]);
            let k1 = f.derivative(th, z, g, s, x0, self.f_now[j]);
            let k2 = f.derivative(th + hh * k1.0, z + hh * k1.1, g, s, xm, self.f_mid[j]);
            let k3 = f.derivative(th + hh * k2.0, z + hh * k2.1, g, s, xm, self.f_mid[j]);
            let k4 = f.derivative(th + h * k3.0, z + h * k3.1, g, s, x1, self.f_end[j]);
            self.theta[j] = th + h / 6.0 * (k1.0 + 2.0 * (k2.0 + k3.0) + k4.0);
            self.z[j] = z + h / 6.0 * (k1.1 + 2.0 * (k2.1 + k3.1) + k4.1);
        }
        std::mem::swap(&mut self.f_now, &mut self.f_end);
        self.x_now = x1;
        self.u = b;
    }
}

impl Samples {
    /// Number of DOFs.
    pub fn dofs(&self) -> usize {
        self.names.len()
    }

    /// Angle of DOF `j` at sample `k`.
    pub fn value(&self, k: usize, j: usize) -> f64 {
        self.values[k * self.names.len() + j]
    }

    /// Rate of DOF `j` at sample `k`.
    pub fn velocity(&self, k: usize, j: usize) -> f64 {
        self.velocities[k * self.names.len() + j]
    }
}
