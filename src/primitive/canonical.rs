//! The shared canonical system: one phase for all DOFs of a primitive, as a closed-form function of
//! normalised time u = t/τ.
//!
//! - Second order (Ijspeert 2002, the paper's eq. 2), normalised so that x̃ runs from 0 to 1:
//!   `τ ṽ̇ = α_v(β_v(1 − x̃) − ṽ), τ x̃̇ = ṽ, x̃(0) = 0, ṽ(0) = 0`. The paper's per-DOF
//!   x = s + (g − s)x̃ and v = (g − s)ṽ satisfy its eq. 2 exactly, for any s and g.
//!   Kernels are placed on x̃ and the forcing is gated by the phase velocity ṽ.
//! - First order (Ijspeert 2013, Hoffmann 2009): `τ ṡ = −α_s s, s(0) = 1`. Kernels are placed on
//!   s and the forcing is gated by s.
//!
//! Both are linear ODEs with constant coefficients; they are evaluated from their exact solutions
//! (no integration error, and the phase is computed once per time for all DOFs). In u the second
//! order system reads `x̃'' + α_v x̃' + α_v β_v (x̃ − 1) = 0` (′ = d/du, so ṽ = x̃′).

use serde::{Deserialize, Serialize};

use super::error::{PrimitiveError, Result, require_positive};

/// A canonical system (the phase generator shared by all DOFs of a primitive).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum CanonicalSystem {
    /// Ijspeert 2002: second-order, `τ v̇ = α_v(β_v(1 − x̃) − v), τ x̃̇ = v`; must not be
    /// under-damped (β_v ≥ α_v/4) so that x̃ rises monotonically from 0 to 1.
    SecondOrder {
        /// α_v (dimensionless, per unit normalised time), the paper uses 25.
        alpha_v: f64,
        /// β_v; β_v = α_v/4 is critical damping.
        beta_v: f64,
    },
    /// Ijspeert 2013 / Hoffmann 2009: first-order decay `τ ṡ = −α_s s`, s from 1 towards 0.
    FirstOrder {
        /// α_s; s(τ) = exp(−α_s) at the end of the movement.
        alpha_s: f64,
    },
}

/// The canonical state at one instant, as the transformation systems use it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phase {
    /// The kernel coordinate: x̃ ∈ [0, 1) for the second-order system, s ∈ (0, 1] for the first.
    pub x: f64,
    /// The gate multiplying the forcing term: the phase velocity ṽ = dx̃/du (second order) or s
    /// (first order). It is 0 at u = 0 for the second-order system.
    pub gate: f64,
}

impl CanonicalSystem {
    /// Checks the parameters: all positive and finite; the second-order system not under-damped.
    pub fn validate(&self) -> Result<()> {
        match *self {
            CanonicalSystem::SecondOrder { alpha_v, beta_v } => {
                require_positive("alpha_v", alpha_v)?;
                require_positive("beta_v", beta_v)?;
                if alpha_v * alpha_v - 4.0 * alpha_v * beta_v > 1e-9 * alpha_v * alpha_v {
                    // Fine: over-damped.
                } else if 4.0 * alpha_v * beta_v - alpha_v * alpha_v > 1e-9 * alpha_v * alpha_v {
                    return Err(PrimitiveError::InvalidParameter {
                        field: "beta_v".into(),
                        reason: format!(
                            "under-damped canonical system (β_v = {beta_v} > α_v/4 = {}): the phase would oscillate and kernels could not be placed in time",
                            alpha_v / 4.0
                        ),
                    });
                }
                Ok(())
            }
            CanonicalSystem::FirstOrder { alpha_s } => require_positive("alpha_s", alpha_s),
        }
    }

    /// The phase at normalised time `u = t/τ ≥ 0` (exact solution of the canonical ODE).
    ///
    /// Second order, critically damped (ω = α_v/2): `1 − x̃ = (1 + ωu)e^{−ωu}`, `ṽ = ω²u e^{−ωu}`;
    /// over-damped with roots r₁ ≠ r₂: `1 − x̃ = (r₂e^{r₁u} − r₁e^{r₂u})/(r₂ − r₁)`,
    /// `ṽ = −r₁r₂(e^{r₁u} − e^{r₂u})/(r₂ − r₁)`. First order: `s = e^{−α_s u}`, gate s.
    pub fn phase(&self, u: f64) -> Phase {
        let u = u.max(0.0);
        match *self {
            CanonicalSystem::SecondOrder { alpha_v, beta_v } => {
                let disc = alpha_v * alpha_v - 4.0 * alpha_v * beta_v;
                if disc.abs() <= 1e-9 * alpha_v * alpha_v {
                    let w = 0.5 * alpha_v;
                    let e = (-w * u).exp();
                    Phase {
                        x: 1.0 - (1.0 + w * u) * e,
                        gate: w * w * u * e,
                    }
                } else {
                    // Over-damped (validate() rejects under-damped parameters).
                    let sq = disc.max(0.0).sqrt();
                    let r1 = 0.5 * (-alpha_v + sq);
                    let r2 = 0.5 * (-alpha_v - sq);
                    let (e1, e2) = ((r1 * u).exp(), (r2 * u).exp());
                    Phase {
                        x: 1.0 - (r2 * e1 - r1 * e2) / (r2 - r1),
                        gate: -r1 * r2 * (e1 - e2) / (r2 - r1),
                    }
                }
            }
            CanonicalSystem::FirstOrder { alpha_s } => {
                let s = (-alpha_s * u).exp();
                Phase { x: s, gate: s }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// RK4 integration of the canonical ODE in normalised time, for comparison with the closed form.
    fn integrate(sys: &CanonicalSystem, u_end: f64, steps: usize) -> (f64, f64) {
        let h = u_end / steps as f64;
        match *sys {
            CanonicalSystem::SecondOrder { alpha_v, beta_v } => {
                let f = |x: f64, v: f64| (v, alpha_v * (beta_v * (1.0 - x) - v));
                let (mut x, mut v) = (0.0, 0.0);
                for _ in 0..steps {
                    let k1 = f(x, v);
                    let k2 = f(x + 0.5 * h * k1.0, v + 0.5 * h * k1.1);
                    let k3 = f(x + 0.5 * h * k2.0, v + 0.5 * h * k2.1);
                    let k4 = f(x + h * k3.0, v + h * k3.1);
                    x += h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
                    v += h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
                }
                (x, v)
            }
            CanonicalSystem::FirstOrder { alpha_s } => {
                let mut s = 1.0;
                for _ in 0..steps {
                    let k1 = -alpha_s * s;
                    let k2 = -alpha_s * (s + 0.5 * h * k1);
                    let k3 = -alpha_s * (s + 0.5 * h * k2);
                    let k4 = -alpha_s * (s + h * k3);
                    s += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
                }
                (s, s)
            }
        }
    }

    #[test]
    fn closed_form_matches_numerical_integration() {
        for sys in [
            CanonicalSystem::SecondOrder {
                alpha_v: 25.0,
                beta_v: 6.25,
            },
            CanonicalSystem::SecondOrder {
                alpha_v: 25.0,
                beta_v: 4.0,
            },
            CanonicalSystem::FirstOrder { alpha_s: 4.6 },
        ] {
            sys.validate().unwrap();
            for u in [0.05, 0.3, 1.0, 1.7] {
                let p = sys.phase(u);
                let (x, g) = integrate(&sys, u, 20_000);
                assert!((p.x - x).abs() < 1e-10, "{sys:?} u={u}: {} vs {x}", p.x);
                assert!(
                    (p.gate - g).abs() < 1e-9,
                    "{sys:?} u={u}: {} vs {g}",
                    p.gate
                );
            }
        }
    }

    #[test]
    fn second_order_phase_starts_at_rest_and_reaches_one() {
        let sys = CanonicalSystem::SecondOrder {
            alpha_v: 25.0,
            beta_v: 6.25,
        };
        let p0 = sys.phase(0.0);
        assert_eq!((p0.x, p0.gate), (0.0, 0.0));
        assert!(1.0 - sys.phase(1.0).x < 1e-4);
        // Monotone.
        let mut last = -1.0;
        for k in 0..=1000 {
            let x = sys.phase(k as f64 / 500.0).x;
            assert!(x >= last);
            last = x;
        }
    }

    #[test]
    fn under_damped_is_rejected() {
        let sys = CanonicalSystem::SecondOrder {
            alpha_v: 25.0,
            beta_v: 10.0,
        };
        assert!(matches!(
            sys.validate(),
            Err(PrimitiveError::InvalidParameter { .. })
        ));
    }
}
