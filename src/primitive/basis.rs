//! Gaussian kernels ψ_i(x) = exp(−(x − c_i)²/(2σ_i²)) on the canonical phase, placed evenly in time.
//!
//! Centres: c_i = x(u_i) with u_i = i/(N − 1) evenly spaced in normalised time u = t/τ and mapped
//! through the canonical phase, so the kernels are even in time although the phase is not.
//! Widths from the overlap: neighbours cross at height h, ψ_i(c_i ± Δ_i) = h, i.e.
//! σ_i = Δ_i / √(2 ln(1/h)), with Δ_i the mean distance to the two neighbours (the one
//! neighbour's distance at the ends).

use serde::{Deserialize, Serialize};

use super::canonical::CanonicalSystem;
use super::error::{PrimitiveError, Result, require_finite};

/// Exponent beyond which a normalised kernel contributes less than e⁻³⁷ ≈ 1e−16 and is skipped.
const CUTOFF: f64 = 37.0;

/// A set of Gaussian kernels on the phase coordinate (shared by all DOFs of a primitive).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Basis {
    /// Centres c_i in phase coordinates (x̃ or s).
    pub centres: Vec<f64>,
    /// Widths σ_i in phase coordinates (> 0).
    pub widths: Vec<f64>,
}

impl Basis {
    /// N kernels evenly spaced in time over the movement (see the module docs); `overlap` is the
    /// height h ∈ (0, 1) at which neighbouring kernels cross.
    pub fn even_in_time(canonical: &CanonicalSystem, n: usize, overlap: f64) -> Result<Basis> {
        if n < 2 {
            return Err(PrimitiveError::InvalidParameter {
                field: "kernels".into(),
                reason: format!("need at least 2 kernels, got {n}"),
            });
        }
        if !(overlap > 0.0 && overlap < 1.0) {
            return Err(PrimitiveError::InvalidParameter {
                field: "overlap".into(),
                reason: format!("crossing height must be in (0, 1), got {overlap}"),
            });
        }
        canonical.validate()?;
        let centres: Vec<f64> = (0..n)
            .map(|i| canonical.phase(i as f64 / (n - 1) as f64).x)
            .collect();
        let k = (2.0 * (1.0 / overlap).ln()).sqrt();
        let widths: Vec<f64> = (0..n)
            .map(|i| {
                let d = if i == 0 {
                    (centres[1] - centres[0]).abs()
                } else if i == n - 1 {
                    (centres[n - 1] - centres[n - 2]).abs()
                } else {
                    0.5 * (centres[i + 1] - centres[i - 1]).abs()
                };
                d / k
            })
            .collect();
        let b = Basis { centres, widths };
        b.validate()?;
        Ok(b)
    }

    /// Number of kernels N.
    pub fn len(&self) -> usize {
        self.centres.len()
    }

    /// True if there are no kernels.
    pub fn is_empty(&self) -> bool {
        self.centres.is_empty()
    }

    /// Checks: at least one kernel, as many widths as centres, all finite, widths > 0.
    pub fn validate(&self) -> Result<()> {
        if self.centres.is_empty() {
            return Err(PrimitiveError::InvalidParameter {
                field: "basis.centres".into(),
                reason: "no kernels".into(),
            });
        }
        if self.widths.len() != self.centres.len() {
            return Err(PrimitiveError::InvalidParameter {
                field: "basis.widths".into(),
                reason: format!(
                    "{} widths for {} centres",
                    self.widths.len(),
                    self.centres.len()
                ),
            });
        }
        require_finite("basis.centres", &self.centres)?;
        require_finite("basis.widths", &self.widths)?;
        if let Some(i) = self.widths.iter().position(|w| *w <= 0.0) {
            return Err(PrimitiveError::InvalidParameter {
                field: format!("basis.widths[{i}]"),
                reason: "kernel width must be > 0".into(),
            });
        }
        Ok(())
    }

    /// Raw activations ψ_i(x) = exp(−(x − c_i)²/(2σ_i²)) written into `out` (length N).
    pub fn activations(&self, x: f64, out: &mut [f64]) {
        for ((o, c), s) in out.iter_mut().zip(&self.centres).zip(&self.widths) {
            let d = (x - c) / s;
            *o = (-0.5 * d * d).exp();
        }
    }

    /// Normalised activations ψ_i(x)/Σ_k ψ_k(x) written into `out` (length N); returns the index
    /// range outside which they are below 1e−16 (and written as 0).
    ///
    /// Computed as exp(e_min − e_i) with e_i = (x − c_i)²/(2σ_i²), which leaves the ratio unchanged
    /// and never divides 0 by 0, however far x is from every centre.
    pub fn normalized(&self, x: f64, out: &mut [f64]) -> std::ops::Range<usize> {
        let mut e_min = f64::INFINITY;
        for ((o, c), s) in out.iter_mut().zip(&self.centres).zip(&self.widths) {
            let d = (x - c) / s;
            *o = 0.5 * d * d;
            e_min = e_min.min(*o);
        }
        let (mut lo, mut hi) = (usize::MAX, 0);
        let mut sum = 0.0;
        for (i, o) in out.iter_mut().enumerate() {
            let d = *o - e_min;
            if d < CUTOFF {
                *o = (-d).exp();
                sum += *o;
                lo = lo.min(i);
                hi = i + 1;
            } else {
                *o = 0.0;
            }
        }
        let inv = 1.0 / sum;
        for o in &mut out[lo..hi] {
            *o *= inv;
        }
        lo..hi
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbours_cross_at_the_requested_height_in_first_order_phase() {
        let sys = CanonicalSystem::FirstOrder { alpha_s: 4.6 };
        let b = Basis::even_in_time(&sys, 20, 0.5).unwrap();
        // Centres are the phase at evenly spaced times.
        for (i, c) in b.centres.iter().enumerate() {
            assert!((c - sys.phase(i as f64 / 19.0).x).abs() < 1e-15);
        }
        // At the first centre's right neighbour, kernel 0 has height 0.5 (its width uses that spacing).
        let mut psi = vec![0.0; 20];
        b.activations(b.centres[1], &mut psi);
        assert!((psi[0] - 0.5).abs() < 1e-12, "{}", psi[0]);
    }

    #[test]
    fn normalized_is_a_partition_of_unity_even_far_away() {
        let sys = CanonicalSystem::SecondOrder {
            alpha_v: 25.0,
            beta_v: 6.25,
        };
        let b = Basis::even_in_time(&sys, 30, 0.5).unwrap();
        let mut psi = vec![0.0; 30];
        for x in [-5.0, 0.0, 0.3, 0.999_99, 1.0, 40.0] {
            let r = b.normalized(x, &mut psi);
            let s: f64 = psi.iter().sum();
            assert!((s - 1.0).abs() < 1e-12, "x={x}: sum {s}");
            assert!(!r.is_empty());
            assert!(psi.iter().all(|p| p.is_finite()));
        }
    }

    #[test]
    fn rejects_bad_counts_and_overlaps() {
        let sys = CanonicalSystem::FirstOrder { alpha_s: 4.6 };
        assert!(Basis::even_in_time(&sys, 1, 0.5).is_err());
        assert!(Basis::even_in_time(&sys, 10, 1.0).is_err());
        assert!(Basis::even_in_time(&sys, 10, 0.0).is_err());
    }
}
