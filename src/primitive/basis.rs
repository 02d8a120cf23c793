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

/// Exponent beyond which a normalised kernel contributes less than e⁻²⁵ ≈ 1.4e−11 and is skipped.
const CUTOFF: f64 = 25.0;

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
    /// range outside which they are below 1.4e−11 (and written as 0). For repeated evaluation use
    /// [`Basis::kernels`].
    pub fn normalized(&self, x: f64, out: &mut [f64]) -> std::ops::Range<usize> {
        let k = self.kernels();
        let r = k.normalized(x, out);
        out[..r.start].fill(0.0);
        out[r.end..].fill(0.0);
        r
    }

    /// A fast evaluator of these kernels (precomputed 1/(2σ_i²)).
    pub fn kernels(&self) -> Kernels {
        let c = &self.centres;
        let direction = if c.windows(2).all(|w| w[0] < w[1]) {
            1
        } else if c.windows(2).all(|w| w[0] > w[1]) {
            -1
        } else {
            0
        };
        Kernels {
            centres: self.centres.clone(),
            half_inv_var: self.widths.iter().map(|s| 0.5 / (s * s)).collect(),
            direction,
        }
    }
}

/// The kernels of a [`Basis`] prepared for fast repeated evaluation.
#[derive(Clone, Debug, PartialEq)]
pub struct Kernels {
    centres: Vec<f64>,
    /// 1/(2σ_i²).
    half_inv_var: Vec<f64>,
    /// +1 if the centres increase strictly, −1 if they decrease strictly, 0 otherwise.
    direction: i8,
}

impl Kernels {
    /// Number of kernels.
    pub fn len(&self) -> usize {
        self.centres.len()
    }

    /// True if there are no kernels.
    pub fn is_empty(&self) -> bool {
        self.centres.is_empty()
    }

    /// Normalised activations ψ_i(x)/Σ_k ψ_k(x) for the kernels in the returned index range,
    /// written into `out[range]` (entries outside the range are left untouched: their
    /// activations are below 1.4e−11). Computed as exp(e_min − e_i), e_i = (x − c_i)²/(2σ_i²),
    /// which leaves the ratio unchanged and never divides 0 by 0, however far x is from every
    /// centre.
    ///
    /// With monotone centres (as [`Basis::even_in_time`] places them) the window is found by
    /// bisection and grown from the nearest centre until e_i − e_min exceeds the cut-off
    /// (neighbouring widths vary smoothly, so e grows away from x); otherwise all kernels are
    /// scanned.
    pub fn normalized(&self, x: f64, out: &mut [f64]) -> std::ops::Range<usize> {
        let n = self.centres.len();
        let e = |i: usize| {
            let d = x - self.centres[i];
            d * d * self.half_inv_var[i]
        };
        let (lo, hi, e_min) = if self.direction == 0 || n < 3 {
            let out = &mut out[..n];
            for (i, o) in out.iter_mut().enumerate() {
                *o = e(i);
            }
            let mut e_min = f64::INFINITY;
            for v in out.iter() {
                e_min = if *v < e_min { *v } else { e_min };
            }
            let lo = out.iter().position(|v| *v - e_min < CUTOFF).unwrap_or(0);
            let hi = n - out
                .iter()
                .rev()
                .position(|v| *v - e_min < CUTOFF)
                .unwrap_or(0);
            (lo, hi, e_min)
        } else {
            let j = if self.direction > 0 {
                self.centres.partition_point(|c| *c < x)
            } else {
                self.centres.partition_point(|c| *c > x)
            };
            let (mut lo, mut hi) = (j.saturating_sub(1), (j + 1).min(n));
            if lo >= hi {
                lo = hi - 1;
            }
            let mut e_min = f64::INFINITY;
            for (i, o) in out.iter_mut().enumerate().take(hi).skip(lo) {
                *o = e(i);
                e_min = if *o < e_min { *o } else { e_min };
            }
            while lo > 0 {
                let v = e(lo - 1);
                if v - e_min >= CUTOFF {
                    break;
                }
                lo -= 1;
                out[lo] = v;
                e_min = if v < e_min { v } else { e_min };
            }
            while hi < n {
                let v = e(hi);
                if v - e_min >= CUTOFF {
                    break;
                }
                out[hi] = v;
                e_min = if v < e_min { v } else { e_min };
                hi += 1;
            }
            (lo, hi, e_min)
        };
        let w = &mut out[lo..hi];
        // Inside the window 0 ≤ e_i − e_min < CUTOFF, within exp_neg's domain.
        for o in w.iter_mut() {
            *o = exp_neg(*o - e_min);
        }
        let sum: f64 = w.iter().sum();
        let inv = 1.0 / sum;
        for o in w.iter_mut() {
            *o *= inv;
        }
        lo..hi
    }
}

/// e^{−d} for 0 ≤ d ≤ 700, to within 2 ulp: d·log₂e is split into an integer k and a remainder
/// r ∈ [−ln2/2, ln2/2] (round-to-nearest by the 1.5·2⁵² trick), e^r by its degree-12 Taylor
/// polynomial (truncation < 2e−16), and 2^k put into the exponent bits. Branch-free, so a loop
/// of it vectorises.
#[inline(always)]
pub fn exp_neg(d: f64) -> f64 {
    const MAGIC: f64 = 6_755_399_441_055_744.0; // 1.5·2⁵²
    const LN2_HI: f64 = 0.693_147_180_369_123_8;
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    let x = -d;
    let t = x * std::f64::consts::LOG2_E + MAGIC;
    let k = t - MAGIC;
    let ki = (t.to_bits() as i64).wrapping_sub(MAGIC.to_bits() as i64);
    let r = (x - k * LN2_HI) - k * LN2_LO;
    let mut p = 1.0 / 479_001_600.0;
    p = p * r + 1.0 / 39_916_800.0;
    p = p * r + 1.0 / 3_628_800.0;
    p = p * r + 1.0 / 362_880.0;
    p = p * r + 1.0 / 40_320.0;
    p = p * r + 1.0 / 5_040.0;
    p = p * r + 1.0 / 720.0;
    p = p * r + 1.0 / 120.0;
    p = p * r + 1.0 / 24.0;
    p = p * r + 1.0 / 6.0;
    p = p * r + 0.5;
    p = p * r + 1.0;
    p = p * r + 1.0;
    p * f64::from_bits(((ki + 1023) as u64) << 52)
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
    fn windowed_activations_equal_a_full_scan() {
        for sys in [
            CanonicalSystem::SecondOrder {
                alpha_v: 25.0,
                beta_v: 6.25,
            },
            CanonicalSystem::FirstOrder { alpha_s: 4.6 },
        ] {
            let b = Basis::even_in_time(&sys, 40, 0.5).unwrap();
            let fast = b.kernels();
            let mut full = fast.clone();
            full.direction = 0;
            let (mut p, mut q) = (vec![0.0; 40], vec![0.0; 40]);
            for k in 0..=3000 {
                let x = sys.phase(k as f64 / 2000.0).x;
                let r1 = fast.normalized(x, &mut p);
                let r2 = full.normalized(x, &mut q);
                assert_eq!(r1, r2, "x={x}");
                for i in r1 {
                    assert!((p[i] - q[i]).abs() < 1e-15);
                }
            }
        }
    }

    #[test]
    fn fast_exp_matches_std_exp() {
        let mut worst = 0.0f64;
        for i in 0..=700_000 {
            let d = i as f64 * 1e-3;
            let (a, b) = (exp_neg(d), (-d).exp());
            worst = worst.max(((a - b) / b).abs());
        }
        assert!(worst < 5e-16, "relative error {worst}");
        assert_eq!(exp_neg(0.0), 1.0);
    }

    #[test]
    fn rejects_bad_counts_and_overlaps() {
        let sys = CanonicalSystem::FirstOrder { alpha_s: 4.6 };
        assert!(Basis::even_in_time(&sys, 1, 0.5).is_err());
        assert!(Basis::even_in_time(&sys, 10, 1.0).is_err());
        assert!(Basis::even_in_time(&sys, 10, 0.0).is_err());
    }
}
