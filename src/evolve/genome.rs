//! A real-coded genome and the box its genes live in.

use serde::{Deserialize, Serialize};

/// Lower and upper bound of every gene (`lo[i] ≤ x_i ≤ hi[i]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Bounds {
    /// Lower bounds.
    pub lo: Vec<f64>,
    /// Upper bounds.
    pub hi: Vec<f64>,
}

/// Why bounds are unusable.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum BoundsError {
    /// `lo` and `hi` differ in length, or there are no genes.
    #[error("bounds need as many lower as upper values and at least one gene (lo {lo}, hi {hi})")]
    Length {
        /// Lower bounds given.
        lo: usize,
        /// Upper bounds given.
        hi: usize,
    },
    /// A gene whose interval is empty or not finite.
    #[error("gene {index}: bounds [{lo}, {hi}] are not a finite interval with lo ≤ hi")]
    Interval {
        /// Gene index.
        index: usize,
        /// Lower bound.
        lo: f64,
        /// Upper bound.
        hi: f64,
    },
}

impl Bounds {
    /// Checked bounds.
    pub fn new(lo: Vec<f64>, hi: Vec<f64>) -> Result<Self, BoundsError> {
        if lo.len() != hi.len() || lo.is_empty() {
            return Err(BoundsError::Length {
                lo: lo.len(),
                hi: hi.len(),
            });
        }
        for (index, (&l, &h)) in lo.iter().zip(&hi).enumerate() {
            if !(l.is_finite() && h.is_finite() && l <= h) {
                return Err(BoundsError::Interval {
                    index,
                    lo: l,
                    hi: h,
                });
            }
        }
        Ok(Self { lo, hi })
    }

    /// Number of genes.
    pub fn len(&self) -> usize {
        self.lo.len()
    }

    /// True when there are no genes.
    pub fn is_empty(&self) -> bool {
        self.lo.is_empty()
    }

    /// True when every gene of `x` lies inside its interval.
    pub fn contains(&self, x: &[f64]) -> bool {
        x.len() == self.len()
            && x.iter()
                .zip(self.lo.iter().zip(&self.hi))
                .all(|(v, (l, h))| *v >= *l && *v <= *h)
    }

    /// `x` clamped into the box.
    pub fn clamp(&self, x: &mut [f64]) {
        for (v, (l, h)) in x.iter_mut().zip(self.lo.iter().zip(&self.hi)) {
            *v = v.clamp(*l, *h);
        }
    }

    /// Width `hi − lo` of gene `i`.
    pub fn width(&self, i: usize) -> f64 {
        self.hi[i] - self.lo[i]
    }
}

/// One individual's genes.
pub type Genome = Vec<f64>;
