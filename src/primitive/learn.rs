//! Learning the DMP weights of every DOF from a demonstration: the paper's locally weighted
//! regression and a regularised (ridge) least-squares fit of all kernels jointly.
//!
//! For each DOF the demonstration θ_d(u) (u = t/τ, τ = the clip's duration) gives the forcing
//! target F_target(u) of the formulation ([`Formulation::forcing_target`]; for 2002, z_demo is
//! integrated with [`integrate_z_demo`]). The model is F(u) = gate(u)·h(x(u)), h = Σψ_i w_i/Σψ_i,
//! with the gate and kernel coordinate from the shared canonical phase (weights at the
//! demonstration's amplitude, see [`super::dmp`]).
//!
//! - **LWR** (the paper): each kernel on its own,
//!   `w_i = Σ_t ψ_i(t) gate_t F_t / Σ_t ψ_i(t) gate_t²`.
//! - **Ridge**: all kernels jointly, minimising `Σ_t (F_t − Σ_i Φ_ti w_i)² + λ Σ_i (ΦᵀΦ)_ii w_i²`
//!   with `Φ_ti = gate_t ψ_i(t)/Σ_kψ_k(t)`; the penalty is scaled by each kernel's own energy
//!   so λ is dimensionless and late kernels (tiny gate) are not crushed. Solved by Cholesky, one
//!   factorisation for all DOFs.
//!
//! Derivatives of the demonstration are central differences in u (second-order one-sided at the
//! ends); a clip that starts mid-motion keeps its initial velocity as the DMP's initial state
//! (`start_rate` = θ′(0) = τθ̇(0)).

use serde::{Deserialize, Serialize};

use super::basis::Basis;
use super::definition::DofPrimitive;
use super::dmp::{Formulation, SpatialScaling, integrate_z_demo};
use super::error::{PrimitiveError, Result, require_positive};
use super::trajectory::Trajectory;

/// How many kernels a primitive gets.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum KernelCount {
    /// Exactly this many (≥ 2).
    Fixed(usize),
    /// `ceil(rate · duration)` kernels, at least `min` (≥ 2).
    PerSecond {
        /// Kernels per second of demonstration.
        rate: f64,
        /// Lower bound.
        min: usize,
    },
}

impl KernelCount {
    /// The kernel count for a demonstration lasting `duration` seconds.
    pub fn count(&self, duration: f64) -> Result<usize> {
        let n = match *self {
            KernelCount::Fixed(n) => n,
            KernelCount::PerSecond { rate, min } => {
                require_positive("kernels.rate", rate)?;
                ((rate * duration).ceil() as usize).max(min)
            }
        };
        if n < 2 {
            return Err(PrimitiveError::InvalidParameter {
                field: "kernels".into(),
                reason: format!("need at least 2 kernels, got {n}"),
            });
        }
        Ok(n)
    }
}

/// The regression used to fit the weights.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Regression {
    /// The paper's locally weighted regression, each kernel independently.
    LocallyWeighted,
    /// Ridge least squares over all kernels jointly; `lambda` is the relative penalty (≥ 0).
    Ridge {
        /// Penalty relative to each kernel's energy (ΦᵀΦ)_ii; 1e−6 is a light touch.
        lambda: f64,
    },
}

/// Everything learning needs besides the demonstration.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LearnConfig {
    /// DMP formulation (default: the paper's Ijspeert 2002).
    pub formulation: Formulation,
    /// Number of kernels (default 25 per second, at least 20).
    pub kernels: KernelCount,
    /// Height at which neighbouring kernels cross, in (0, 1) (default 0.5).
    pub overlap: f64,
    /// Regression (default ridge, λ = 1e−6).
    pub regression: Regression,
    /// A DOF with |g − s| < `degenerate_fraction` × (its demonstrated range) is learned unscaled
    /// (see [`SpatialScaling::Unscaled`]); default 0.1.
    pub degenerate_fraction: f64,
}

impl Default for LearnConfig {
    fn default() -> Self {
        LearnConfig {
            formulation: Formulation::default(),
            kernels: KernelCount::PerSecond {
                rate: 25.0,
                min: 20,
            },
            overlap: 0.5,
            regression: Regression::Ridge { lambda: 1e-6 },
            degenerate_fraction: 0.1,
        }
    }
}

/// First and second derivatives of `dofs` signals sampled `h` apart, stored row-major
/// (`x[k * dofs + j]`, at least 4 frames): central differences inside, second-order one-sided
/// at the ends. Results use the same layout. All DOFs of a frame are processed together.
pub fn derivatives(x: &[f64], dofs: usize, h: f64, d1: &mut [f64], d2: &mut [f64]) {
    let n = x.len() / dofs;
    debug_assert!(n >= 4);
    let (i1, i2) = (0.5 / h, 1.0 / (h * h));
    let row = |k: usize| &x[k * dofs..(k + 1) * dofs];
    for k in 1..n - 1 {
        let (a, b, c) = (row(k - 1), row(k), row(k + 1));
        let o1 = &mut d1[k * dofs..(k + 1) * dofs];
        let o2 = &mut d2[k * dofs..(k + 1) * dofs];
        for j in 0..dofs {
            o1[j] = (c[j] - a[j]) * i1;
            o2[j] = (c[j] - 2.0 * b[j] + a[j]) * i2;
        }
    }
    for j in 0..dofs {
        let (x0, x1, x2, x3) = (row(0)[j], row(1)[j], row(2)[j], row(3)[j]);
        d1[j] = (-3.0 * x0 + 4.0 * x1 - x2) * i1;
        d2[j] = (2.0 * x0 - 5.0 * x1 + 4.0 * x2 - x3) * i2;
        let (y0, y1, y2, y3) = (row(n - 1)[j], row(n - 2)[j], row(n - 3)[j], row(n - 4)[j]);
        d1[(n - 1) * dofs + j] = (3.0 * y0 - 4.0 * y1 + y2) * i1;
        d2[(n - 1) * dofs + j] = (2.0 * y0 - 5.0 * y1 + 4.0 * y2 - y3) * i2;
    }
}

/// Learns one [`DofPrimitive`] per DOF of `demo` on `basis`: start s = first frame, goal g = last
/// frame, start rate θ′(0), spatial scaling (degenerate DOFs unscaled) and weights by the
/// configured regression. `demo` must have at least 4 frames.
pub fn learn_dofs(
    demo: &Trajectory,
    basis: &Basis,
    config: &LearnConfig,
) -> Result<Vec<DofPrimitive>> {
    check_learn(demo, config)?;
    let n = demo.frames();
    let f = config.formulation;
    let canonical = f.canonical();
    let nk = basis.len();
    let dofs = demo.dofs();
    let du = 1.0 / (n - 1) as f64;

    // Everything below is frames × dofs, row-major: each frame's DOFs are contiguous, so every
    // per-frame loop runs over all DOFs at once.
    let x = &demo.values;
    let mut d1 = vec![0.0; dofs * n];
    let mut d2 = vec![0.0; dofs * n];
    derivatives(x, dofs, du, &mut d1, &mut d2);
    let starts = &x[..dofs];
    let goals = &x[(n - 1) * dofs..];
    let (lo, hi) = dof_ranges(x, dofs);
    let mut zd = vec![0.0; dofs * n];
    if let Formulation::Ijspeert2002 {
        alpha_z, beta_z, ..
    } = f
    {
        integrate_z_demo(alpha_z, beta_z, goals, x, du, &d1[..dofs], &mut zd);
    }
    let phases: Vec<_> = (0..n).map(|k| canonical.phase(k as f64 * du)).collect();
    let mut targets = vec![0.0; dofs * n];
    for (k, p) in phases.iter().enumerate() {
        let r = k * dofs..(k + 1) * dofs;
        let (th, a, b, z, t) = (
            &x[r.clone()],
            &d1[r.clone()],
            &d2[r.clone()],
            &zd[r.clone()],
            &mut targets[r],
        );
        for j in 0..dofs {
            t[j] = f.forcing_target(th[j], a[j], b[j], z[j], goals[j], starts[j], p.x);
        }
    }
    let out: Vec<DofPrimitive> = (0..dofs)
        .map(|j| {
            let (s, g) = (starts[j], goals[j]);
            let range = hi[j] - lo[j];
            let scaling = if f.scales_with_goal()
                && (g - s).abs() >= (config.degenerate_fraction * range).max(1e-9)
            {
                SpatialScaling::GoalMinusStart { reference: g - s }
            } else {
                SpatialScaling::Unscaled
            };
            DofPrimitive {
                name: demo.names[j].clone(),
                start: s,
                goal: g,
                start_rate: d1[j],
                scaling,
                weights: vec![0.0; nk],
            }
        })
        .collect();

    let mut out = out;
    let weights = regress(config.regression, basis, &phases, &targets, dofs)?;
    for (j, d) in out.iter_mut().enumerate() {
        for (i, w) in d.weights.iter_mut().enumerate() {
            *w = weights[i * dofs + j];
        }
    }
    Ok(out)
}

/// [`learn_dofs`]'s checks: a valid demonstration of at least 4 frames, a valid formulation
/// and a degenerate fraction ≥ 0.
fn check_learn(demo: &Trajectory, config: &LearnConfig) -> Result<()> {
    demo.validate()?;
    let n = demo.frames();
    if n < 4 {
        return Err(PrimitiveError::InvalidTrajectory {
            what: format!("need at least 4 frames to learn, got {n}"),
        });
    }
    config.formulation.validate()?;
    if !(config.degenerate_fraction >= 0.0 && config.degenerate_fraction.is_finite()) {
        return Err(PrimitiveError::InvalidParameter {
            field: "degenerate_fraction".into(),
            reason: format!("must be ≥ 0 and finite, got {}", config.degenerate_fraction),
        });
    }
    Ok(())
}

/// The lowest and highest value of each DOF over the frames of `x` (frames × dofs).
fn dof_ranges(x: &[f64], dofs: usize) -> (Vec<f64>, Vec<f64>) {
    let starts = &x[..dofs];
    let mut lo = starts.to_vec();
    let mut hi = starts.to_vec();
    for row in x.chunks_exact(dofs) {
        for j in 0..dofs {
            lo[j] = if row[j] < lo[j] { row[j] } else { lo[j] };
            hi[j] = if row[j] > hi[j] { row[j] } else { hi[j] };
        }
    }
    (lo, hi)
}

/// The weights (kernels × dofs) that fit the forcing `targets` (frames × dofs) at `phases` by
/// `regression`. Errors: a ridge λ that is negative or not finite, or normal equations that are
/// not positive definite.
fn regress(
    regression: Regression,
    basis: &Basis,
    phases: &[super::canonical::Phase],
    targets: &[f64],
    dofs: usize,
) -> Result<Vec<f64>> {
    Ok(match regression {
        Regression::LocallyWeighted => lwr(basis, phases, targets, dofs),
        Regression::Ridge { lambda } => {
            if !(lambda >= 0.0 && lambda.is_finite()) {
                return Err(PrimitiveError::InvalidParameter {
                    field: "regression.lambda".into(),
                    reason: format!("must be ≥ 0 and finite, got {lambda}"),
                });
            }
            ridge(basis, phases, targets, dofs, lambda)?
        }
    })
}

/// The paper's LWR: `w_i = Σ_t ψ_i gate F / Σ_t ψ_i gate²` per kernel and DOF. `targets` is
/// frames × dofs; returns kernels × dofs.
fn lwr(
    basis: &Basis,
    phases: &[super::canonical::Phase],
    targets: &[f64],
    dofs: usize,
) -> Vec<f64> {
    let nk = basis.len();
    let mut num = vec![0.0; nk * dofs];
    let mut den = vec![0.0; nk];
    let mut psi = vec![0.0; nk];
    for (k, p) in phases.iter().enumerate() {
        basis.activations(p.x, &mut psi);
        let row = &targets[k * dofs..(k + 1) * dofs];
        for i in 0..nk {
            let a = psi[i] * p.gate;
            if a == 0.0 {
                continue;
            }
            den[i] += a * p.gate;
            for (x, t) in num[i * dofs..(i + 1) * dofs].iter_mut().zip(row) {
                *x += a * t;
            }
        }
    }
    for i in 0..nk {
        let inv = if den[i] > 1e-300 { 1.0 / den[i] } else { 0.0 };
        for x in &mut num[i * dofs..(i + 1) * dofs] {
            *x *= inv;
        }
    }
    num
}

/// Ridge least squares over all kernels (see module docs). `targets` is frames × dofs; returns
/// kernels × dofs. ΦᵀΦ is banded (each frame touches only the kernels near its phase), so it is
/// accumulated in band storage and factorised by a banded Cholesky: memory and time grow
/// linearly with the number of kernels.
fn ridge(
    basis: &Basis,
    phases: &[super::canonical::Phase],
    targets: &[f64],
    dofs: usize,
    lambda: f64,
) -> Result<Vec<f64>> {
    let nk = basis.len();
    let DesignRows { rows, acts, band } = design_rows(basis, phases);
    // Pass 2: ΦᵀΦ in upper band storage, ab[a·band + (b − a)] for a ≤ b < a + band, and ΦᵀF.
    let mut ab = vec![0.0; nk * band];
    let mut atb = vec![0.0; nk * dofs]; // kernels × dofs
    for (k, a0, r) in &rows {
        let act = &acts[r.clone()];
        let row = &targets[k * dofs..(k + 1) * dofs];
        for (ia, pa) in act.iter().enumerate() {
            let a = a0 + ia;
            for (x, y) in ab[a * band..a * band + (act.len() - ia)]
                .iter_mut()
                .zip(&act[ia..])
            {
                *x += pa * y;
            }
            for (x, t) in atb[a * dofs..(a + 1) * dofs].iter_mut().zip(row) {
                *x += pa * t;
            }
        }
    }
    let max_diag = (0..nk).map(|i| ab[i * band]).fold(0.0f64, f64::max);
    if max_diag <= 0.0 {
        return Ok(vec![0.0; dofs * nk]);
    }
    for i in 0..nk {
        ab[i * band] += lambda * ab[i * band] + 1e-12 * max_diag;
    }
    let l = banded_cholesky(&ab, nk, band).ok_or_else(|| PrimitiveError::InvalidParameter {
        field: "regression.lambda".into(),
        reason: "normal equations not positive definite; increase lambda".into(),
    })?;
    Ok(banded_solve(&l, nk, band, dofs, atb))
}

/// Solves L Lᵀ W = B for all `dofs` columns of B (`b`, `nk` rows, contiguous) at once, L the
/// banded Cholesky factor of [`banded_cholesky`] (band `band`).
fn banded_solve(l: &[f64], nk: usize, band: usize, dofs: usize, b: Vec<f64>) -> Vec<f64> {
    let bw = band - 1;
    // L in lower band storage: l[i·band + (i − j)] for i − bw ≤ j ≤ i.
    let lij = |i: usize, j: usize| l[i * band + (i - j)];
    let mut w = b;
    for i in 0..nk {
        let (done, rest) = w.split_at_mut(i * dofs);
        let wi = &mut rest[..dofs];
        for m in i.saturating_sub(bw)..i {
            let c = lij(i, m);
            for (x, y) in wi.iter_mut().zip(&done[m * dofs..(m + 1) * dofs]) {
                *x -= c * y;
            }
        }
        let inv = 1.0 / lij(i, i);
        for x in wi.iter_mut() {
            *x *= inv;
        }
    }
    for i in (0..nk).rev() {
        let (head, tail) = w.split_at_mut((i + 1) * dofs);
        let wi = &mut head[i * dofs..];
        for m in i + 1..(i + 1 + bw).min(nk) {
            let c = lij(m, i);
            let off = (m - i - 1) * dofs;
            for (x, y) in wi.iter_mut().zip(&tail[off..off + dofs]) {
                *x -= c * y;
            }
        }
        let inv = 1.0 / lij(i, i);
        for x in wi.iter_mut() {
            *x *= inv;
        }
    }
    w
}

/// The design rows Φ_t· (gated normalised activations) of every frame with a non-zero gate,
/// compactly.
struct DesignRows {
    /// (frame, first kernel of its window, its activations in `acts`).
    rows: Vec<(usize, usize, std::ops::Range<usize>)>,
    acts: Vec<f64>,
    /// The widest window: the band of ΦᵀΦ.
    band: usize,
}

/// [`ridge`]'s pass 1: the design rows of the frames at `phases`.
fn design_rows(basis: &Basis, phases: &[super::canonical::Phase]) -> DesignRows {
    let kernels = basis.kernels();
    let mut phi = vec![0.0; basis.len()];
    let mut rows: Vec<(usize, usize, std::ops::Range<usize>)> = Vec::with_capacity(phases.len());
    let mut acts: Vec<f64> = Vec::with_capacity(phases.len() * 16);
    let mut band = 1usize;
    for (k, p) in phases.iter().enumerate() {
        if p.gate == 0.0 {
            continue;
        }
        let r = kernels.normalized(p.x, &mut phi);
        band = band.max(r.end - r.start);
        let at = acts.len();
        acts.extend(phi[r.clone()].iter().map(|v| v * p.gate));
        rows.push((k, r.start, at..acts.len()));
    }
    DesignRows { rows, acts, band }
}

/// Cholesky A = L Lᵀ of a symmetric positive-definite n × n matrix given in upper band storage
/// (`ab[a·band + (b − a)]` = A_ab for a ≤ b < a + band). Returns L in lower band storage
/// (`l[i·band + (i − j)]` = L_ij for i − band < j ≤ i), or `None` if A is not positive definite.
fn banded_cholesky(ab: &[f64], n: usize, band: usize) -> Option<Vec<f64>> {
    let bw = band - 1;
    let mut l = vec![0.0; n * band];
    for i in 0..n {
        let lo_i = i.saturating_sub(bw);
        for j in lo_i..=i {
            let mut s = ab[j * band + (i - j)];
            for k in lo_i.max(j.saturating_sub(bw))..j {
                s -= l[i * band + (i - k)] * l[j * band + (j - k)];
            }
            if i == j {
                if s <= 0.0 || !s.is_finite() {
                    return None;
                }
                l[i * band] = s.sqrt();
            } else {
                l[i * band + (i - j)] = s / l[j * band];
            }
        }
    }
    Some(l)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derivatives_are_exact_for_cubics() {
        let h = 0.01;
        let x: Vec<f64> = (0..50)
            .map(|k| (k as f64 * h).powi(2) * 3.0 + k as f64 * h)
            .collect();
        let (mut d1, mut d2) = (vec![0.0; 50], vec![0.0; 50]);
        derivatives(&x, 1, h, &mut d1, &mut d2);
        for k in 0..50 {
            let u = k as f64 * h;
            assert!((d1[k] - (6.0 * u + 1.0)).abs() < 1e-9, "k={k}");
            assert!((d2[k] - 6.0).abs() < 1e-6, "k={k}: {}", d2[k]);
        }
    }

    #[test]
    fn banded_cholesky_factors_a_tridiagonal_matrix() {
        // A = L Lᵀ with L = [[2,0,0],[1,√2,0],[0,1,1]] → A = [[4,2,0],[2,3,√2],[0,√2,2]].
        let r2 = 2f64.sqrt();
        // Upper band storage, band 2: rows (A_aa, A_a,a+1).
        let ab = vec![4.0, 2.0, 3.0, r2, 2.0, 0.0];
        let l = banded_cholesky(&ab, 3, 2).unwrap();
        // Lower band storage: rows (L_ii, L_i,i−1).
        let expect = [2.0, 0.0, r2, 1.0, 1.0, 1.0];
        for (x, y) in l.iter().zip(&expect) {
            assert!((x - y).abs() < 1e-14, "{l:?}");
        }
        // [[1, 2], [2, 1]] is not positive definite.
        assert!(banded_cholesky(&[1.0, 2.0, 1.0, 0.0], 2, 2).is_none());
    }

    #[test]
    fn kernel_count_follows_duration() {
        let k = KernelCount::PerSecond {
            rate: 10.0,
            min: 10,
        };
        assert_eq!(k.count(0.5).unwrap(), 10);
        assert_eq!(k.count(8.325).unwrap(), 84);
        assert!(KernelCount::Fixed(1).count(1.0).is_err());
    }
}
