//! Playing a primitive: a fixed-step integrator of all DOFs' transformation systems driven by the
//! one shared canonical phase.
//!
//! **Integrator.** In normalised time u = t/τ every formulation's transformation system is linear
//! with constant coefficients in e = θ − g and z:
//! `(e, z)′ = A (e, z) + B F̃(u)`, `A = [[0, 1], [−K, −D]]`
//! (K = α_zβ_z, D = α_z for Ijspeert 2002/2013; K, D for Hoffmann 2009), with the input
//! B F̃ = (F, 0) for 2002 (forcing in the velocity equation), (0, F) for 2013 and
//! (0, K(F − (g − θ₀)s)) for Hoffmann. To reach a requested time, the interval Δu is cut into
//! `ceil(Δu / h_max)` equal sub-steps, `h_max = min(1/500, 1/(4(N − 1)))` (N kernels: at least
//! four sub-steps per kernel spacing), and each sub-step is integrated **exactly** for an input
//! that is linear across the sub-step (first-order hold):
//! `x₁ = Φx₀ + (Ψ₁ − Ψ₂/h)B F̃₀ + (Ψ₂/h)B F̃₁`, with `Φ = e^{Ah}`, `Ψ₁ = ∫₀ʰe^{Aσ}dσ`,
//! `Ψ₂ = ∫₀ʰe^{A(h−σ)}σ dσ` read off one 6 × 6 matrix exponential (Van Loan) and cached per step
//! size. The only approximation is the linear hold of F̃ over a sub-step (its error telescopes to
//! O(h²) overall); the forcing is evaluated once per sub-step end, for all DOFs at once from the
//! shared phase. Because steps are fixed in u, playing at τ′ = kτ and sampling at k·t performs
//! the same arithmetic: the same path, k times slower.

use super::basis::Kernels;
use super::canonical::CanonicalSystem;
use super::definition::Primitive;
use super::dmp::Formulation;
use super::error::{PrimitiveError, Result, require_finite};

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
    f_end: Vec<f64>,
    psi: Vec<f64>,
    /// Cached discretisation for the last sub-step size.
    disc: Option<Discrete>,
}

/// The exact first-order-hold discretisation of (e, z)′ = A(e, z) + B F̃ over one step h.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Discrete {
    h: f64,
    phi: [[f64; 2]; 2],
    /// Weight vector of F̃ at the step's start: (Ψ₁ − Ψ₂/h)B.
    g0: [f64; 2],
    /// Weight vector of F̃ at the step's end: (Ψ₂/h)B.
    g1: [f64; 2],
}

impl Discrete {
    /// Builds the discretisation from the 6 × 6 Van Loan exponential
    /// exp([[A, I, 0], [0, 0, I], [0, 0, 0]]·h) = [[Φ, Ψ₁, Ψ₂], …].
    fn new(k: f64, d: f64, b: [f64; 2], h: f64) -> Discrete {
        let mut m = [[0.0; 6]; 6];
        m[0][1] = h;
        m[1][0] = -k * h;
        m[1][1] = -d * h;
        for i in 0..2 {
            m[i][i + 2] = h;
            m[i + 2][i + 4] = h;
        }
        let e = expm6(&m);
        let phi = [[e[0][0], e[0][1]], [e[1][0], e[1][1]]];
        let mut g0 = [0.0; 2];
        let mut g1 = [0.0; 2];
        for i in 0..2 {
            for j in 0..2 {
                let psi1 = e[i][j + 2];
                let psi2 = e[i][j + 4] / h;
                g0[i] += (psi1 - psi2) * b[j];
                g1[i] += psi2 * b[j];
            }
        }
        Discrete { h, phi, g0, g1 }
    }
}

/// Matrix exponential of a 6 × 6 matrix: scaling and squaring with an 18-term Taylor series
/// (the norms met here, ‖Ah‖ ≲ 1, need at most a few squarings; accuracy ~1e−16 relative).
fn expm6(m: &[[f64; 6]; 6]) -> [[f64; 6]; 6] {
    let norm = m
        .iter()
        .map(|r| r.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let mut s = 0;
    let mut scale = 1.0;
    while norm * scale > 0.5 {
        scale *= 0.5;
        s += 1;
    }
    let mul = |a: &[[f64; 6]; 6], b: &[[f64; 6]; 6]| {
        let mut c = [[0.0; 6]; 6];
        for i in 0..6 {
            for k in 0..6 {
                if a[i][k] != 0.0 {
                    for j in 0..6 {
                        c[i][j] += a[i][k] * b[k][j];
                    }
                }
            }
        }
        c
    };
    let mut a = *m;
    for r in a.iter_mut() {
        for v in r.iter_mut() {
            *v *= scale;
        }
    }
    let mut result = [[0.0; 6]; 6];
    let mut term = [[0.0; 6]; 6];
    for i in 0..6 {
        result[i][i] = 1.0;
        term[i][i] = 1.0;
    }
    for n in 1..=18 {
        term = mul(&term, &a);
        for r in term.iter_mut() {
            for v in r.iter_mut() {
                *v /= n as f64;
            }
        }
        for i in 0..6 {
            for j in 0..6 {
                result[i][j] += term[i][j];
            }
        }
    }
    for _ in 0..s {
        result = mul(&result, &result);
    }
    result
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

impl Rollout {
    /// Starts playing `p` at t = 0 from the demonstrated start (θ = s, θ̇ = k·start_rate/τ with k
    /// the goal-scaling factor, so a new goal scales the whole demonstrated path), or from
    /// `start` (connect: θ and θ̇ of the previous motion). The spatial scaling k = (g − s)/A
    /// keeps the primitive's own s: a connected primitive starting elsewhere follows its own
    /// course, and the transformation system's spring–damper pulls the state onto it (the
    /// paper's connection), instead of rescaling the whole motion by how far the hand-over
    /// state is from s (which, for a DOF whose g − s is small, would blow the motion up).
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
            .map(|d| d.scaling.factor(d.goal, d.start))
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
            f_end: vec![0.0; dofs],
            psi: vec![0.0; nk],
            disc: None,
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

    /// Current θ̈ per DOF (per second²) into `out`: θ″/τ² with θ″ = z′ + F′ (2002, F′ = dF/du
    /// by a central difference of the forcing, step 10⁻⁶ in u, one-sided at u < 10⁻⁶) or z′, and
    /// z′ the transformation system's ([`Formulation::derivative`]).
    pub fn theta_ddot_into(&self, out: &mut [f64]) {
        const DU: f64 = 1e-6;
        let in_velocity = self.formulation.forcing_in_velocity();
        let dofs = self.theta.len();
        let mut rate = vec![0.0; dofs];
        if in_velocity {
            let (mut hi, mut lo) = (vec![0.0; dofs], vec![0.0; dofs]);
            let mut psi = vec![0.0; self.psi.len()];
            let (ua, ub) = if self.u >= DU {
                (self.u - DU, self.u + DU)
            } else {
                (self.u, self.u + DU)
            };
            let eval = |u: f64, out: &mut [f64], psi: &mut [f64]| {
                forcing(
                    &self.canonical,
                    &self.kernels,
                    &self.weights,
                    &self.scale,
                    psi,
                    u,
                    out,
                );
            };
            eval(ub, &mut hi, &mut psi);
            eval(ua, &mut lo, &mut psi);
            for j in 0..dofs {
                rate[j] = (hi[j] - lo[j]) / (ub - ua);
            }
        }
        let tau2 = self.tau * self.tau;
        for (j, o) in out.iter_mut().enumerate() {
            let (_, dz) = self.formulation.derivative(
                self.theta[j],
                self.z[j],
                self.goal[j],
                self.start[j],
                self.x_now,
                self.f_now[j],
            );
            *o = (dz + rate[j]) / tau2;
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

    /// One exact first-order-hold step from u = a to u = b (see the module docs).
    fn step(&mut self, a: f64, b: f64) {
        let h = b - a;
        let (k, d, bvec) = match self.formulation {
            Formulation::Ijspeert2002 {
                alpha_z, beta_z, ..
            } => (alpha_z * beta_z, alpha_z, [1.0, 0.0]),
            Formulation::Ijspeert2013 {
                alpha_z, beta_z, ..
            } => (alpha_z * beta_z, alpha_z, [0.0, 1.0]),
            Formulation::Hoffmann2009 { k, d, .. } => (k, d, [0.0, k]),
        };
        let disc = match self.disc {
            // Step sizes that differ only by rounding (relative 1e−9) share one discretisation.
            Some(c) if (c.h - h).abs() <= 1e-9 * h => c,
            _ => {
                let c = Discrete::new(k, d, bvec, h);
                self.disc = Some(c);
                c
            }
        };
        let x1 = forcing(
            &self.canonical,
            &self.kernels,
            &self.weights,
            &self.scale,
            &mut self.psi,
            b,
            &mut self.f_end,
        );
        let hoffmann = matches!(self.formulation, Formulation::Hoffmann2009 { .. });
        let (x0, [[p00, p01], [p10, p11]], g0, g1) = (self.x_now, disc.phi, disc.g0, disc.g1);
        for j in 0..self.theta.len() {
            let g = self.goal[j];
            // Hoffmann's input is F − (g − θ₀)s (times K, which B carries).
            let (u0, u1) = if hoffmann {
                let c = g - self.start[j];
                (self.f_now[j] - c * x0, self.f_end[j] - c * x1)
            } else {
                (self.f_now[j], self.f_end[j])
            };
            let e = self.theta[j] - g;
            let z = self.z[j];
            self.theta[j] = g + p00 * e + p01 * z + g0[0] * u0 + g1[0] * u1;
            self.z[j] = p10 * e + p11 * z + g0[1] * u0 + g1[1] * u1;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_discretisation_matches_fine_rk4_for_a_linear_input() {
        // 2002 gains; input F(u) = 1 + 3u over one step h = 0.01, from e = 0.2, z = −0.5.
        let (k, d, h) = (156.25, 25.0, 0.01);
        for b in [[1.0, 0.0], [0.0, 1.0]] {
            let disc = Discrete::new(k, d, b, h);
            let (e0, z0) = (0.2, -0.5);
            let e1 = disc.phi[0][0] * e0
                + disc.phi[0][1] * z0
                + disc.g0[0] * 1.0
                + disc.g1[0] * (1.0 + 3.0 * h);
            let z1 = disc.phi[1][0] * e0
                + disc.phi[1][1] * z0
                + disc.g0[1] * 1.0
                + disc.g1[1] * (1.0 + 3.0 * h);
            let f = |u: f64, e: f64, z: f64| {
                let inp = 1.0 + 3.0 * u;
                (z + b[0] * inp, -k * e - d * z + b[1] * inp)
            };
            let (mut e, mut z) = (e0, z0);
            let n = 10_000;
            let s = h / n as f64;
            for i in 0..n {
                let u = i as f64 * s;
                let k1 = f(u, e, z);
                let k2 = f(u + 0.5 * s, e + 0.5 * s * k1.0, z + 0.5 * s * k1.1);
                let k3 = f(u + 0.5 * s, e + 0.5 * s * k2.0, z + 0.5 * s * k2.1);
                let k4 = f(u + s, e + s * k3.0, z + s * k3.1);
                e += s / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
                z += s / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
            }
            assert!((e1 - e).abs() < 1e-13, "{b:?}: e {e1} vs {e}");
            assert!((z1 - z).abs() < 1e-12, "{b:?}: z {z1} vs {z}");
        }
    }
}
