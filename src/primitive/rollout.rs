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

use super::basis::Kernels;
use super::canonical::CanonicalSystem;
use super::dmp::{Formulation, deriv_2002, deriv_2013, deriv_hoffmann};
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
    kernels: Kernels,
    tau: f64,
    h_max: f64,
    /// kernels × dofs (kernel-major: one kernel's weights for all DOFs are contiguous).
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
/// F_j = gate · k_j · Σ_i ψ̂_i w_ij with ψ̂ the normalised activations (one evaluation for all DOFs).
#[allow(clippy::too_many_arguments)]
fn forcing(
    canonical: &CanonicalSystem,
    kernels: &Kernels,
    weights: &[f64],
    scale: &[f64],
    psi: &mut [f64],
    u: f64,
    out: &mut [f64],
) -> f64 {
    let p = canonical.phase(u);
    out.fill(0.0);
    if p.gate == 0.0 {
        return p.x;
    }
    let d = out.len();
    let r = kernels.normalized(p.x, psi);
    for i in r {
        let a = psi[i];
        for (o, w) in out.iter_mut().zip(&weights[i * d..(i + 1) * d]) {
            *o += a * w;
        }
    }
    for (o, k) in out.iter_mut().zip(scale) {
        *o *= p.gate * k;
    }
    p.x
}

/// One classical RK4 step of size h for every DOF of the linear transformation system
/// (θ′, z′) = deriv(θ, z, g, s, x, F), with F and x at the step's start, middle and end.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn rk4_all<D: Fn(f64, f64, f64, f64, f64, f64) -> (f64, f64)>(
    deriv: D,
    h: f64,
    x: [f64; 3],
    theta: &mut [f64],
    z: &mut [f64],
    goal: &[f64],
    start: &[f64],
    f0: &[f64],
    fm: &[f64],
    f1: &[f64],
) {
    let hh = 0.5 * h;
    let h6 = h / 6.0;
    for j in 0..theta.len() {
        let (th, zz, g, s) = (theta[j], z[j], goal[j], start[j]);
        let k1 = deriv(th, zz, g, s, x[0], f0[j]);
        let k2 = deriv(th + hh * k1.0, zz + hh * k1.1, g, s, x[1], fm[j]);
        let k3 = deriv(th + hh * k2.0, zz + hh * k2.1, g, s, x[1], fm[j]);
        let k4 = deriv(th + h * k3.0, zz + h * k3.1, g, s, x[2], f1[j]);
        theta[j] = th + h6 * (k1.0 + 2.0 * (k2.0 + k3.0) + k4.0);
        z[j] = zz + h6 * (k1.1 + 2.0 * (k2.1 + k3.1) + k4.1);
    }
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
        let mut weights = vec![0.0; nk * dofs];
        for (j, d) in p.dofs.iter().enumerate() {
            for (i, w) in d.weights.iter().enumerate() {
                weights[i * dofs + j] = *w;
            }
        }
        let canonical = p.formulation.canonical();
        let mut r = Rollout {
            formulation: p.formulation,
            canonical,
            kernels: p.basis.kernels(),
            tau: p.duration,
            h_max: (1.0f64 / 500.0).min(0.25 / (nk.max(2) - 1) as f64),
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
            &r.kernels,
            &r.weights,
            &r.scale,
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
        let xm = forcing(
            &self.canonical,
            &self.kernels,
            &self.weights,
            &self.scale,
            &mut self.psi,
            a + 0.5 * h,
            &mut self.f_mid,
        );
        let x1 = forcing(
            &self.canonical,
            &self.kernels,
            &self.weights,
            &self.scale,
            &mut self.psi,
            b,
            &mut self.f_end,
        );
        let x = [self.x_now, xm, x1];
        let (th, z) = (&mut self.theta, &mut self.z);
        let (g, s) = (&self.goal, &self.start);
        let (f0, fm, f1) = (&self.f_now, &self.f_mid, &self.f_end);
        // The formulation is matched once per step, not per DOF.
        match self.formulation {
            Formulation::Ijspeert2002 {
                alpha_z, beta_z, ..
            } => rk4_all(
                |th, z, g, _s, _x, f| deriv_2002(alpha_z, beta_z, th, z, g, f),
                h,
                x,
                th,
                z,
                g,
                s,
                f0,
                fm,
                f1,
            ),
            Formulation::Ijspeert2013 {
                alpha_z, beta_z, ..
            } => rk4_all(
                |th, z, g, _s, _x, f| deriv_2013(alpha_z, beta_z, th, z, g, f),
                h,
                x,
                th,
                z,
                g,
                s,
                f0,
                fm,
                f1,
            ),
            Formulation::Hoffmann2009 { k, d, .. } => rk4_all(
                |th, z, g, s, x, f| deriv_hoffmann(k, d, th, z, g, s, x, f),
                h,
                x,
                th,
                z,
                g,
                s,
                f0,
                fm,
                f1,
            ),
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
