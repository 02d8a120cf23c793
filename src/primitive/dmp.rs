//! The one-DOF transformation system and the three DMP formulations.
//!
//! All equations are written in normalised time u = t/τ (′ = d/du = τ d/dt). With the gated,
//! scaled forcing `F(u) = gate(u) · k · h(x(u))`, `h(x) = Σψ_i w_i / Σψ_i` ([`super::basis`]):
//!
//! - **Ijspeert 2002** (the paper, default): `z′ = α_z(β_z(g − θ) − z)`, `θ′ = z + F`; gate = ṽ, the
//!   shared phase velocity, so `F = ṽ(g − s) Σψw/Σψ` is the paper's `f = Σψ w v/Σψ` with
//!   v = (g − s)ṽ.
//! - **Ijspeert 2013**: `z′ = α_z(β_z(g − θ) − z) + F`, `θ′ = z`; gate = s (first-order phase),
//!   forcing scaled by (g − θ₀).
//! - **Hoffmann 2009**: `z′ = K(g − θ) − D z − K(g − θ₀)s + K F`, `θ′ = z`; gate = s; the forcing is
//!   not scaled by the goal, so a goal change never mirrors the motion.
//!
//! **Weights are stored at the demonstration's amplitude.** For the goal-scaled formulations the
//! per-DOF factor is k = (g − s)/A with A = g_d − s_d of the demonstration
//! ([`SpatialScaling::GoalMinusStart`]), so the stored w_i equal the paper's w_i · A; k = 1 reproduces
//! the demonstration. If |A| is tiny or zero (g = s) the paper's weights would be huge or undefined:
//! such a DOF is learned [`SpatialScaling::Unscaled`] (k = 1 always), follows its demonstration, and a
//! goal change then shifts its end point through the attractor instead of rescaling the forcing.
//!
//! **Goal change that flips the sign of g − s** (2002, 2013): k < 0 and the forcing is mirrored, so the
//! whole motion is mirrored about s (a knee that bent on the way to its goal now hyper-extends).
//! Hoffmann 2009 is the non-mirroring option: its forcing does not change with the goal.

use serde::{Deserialize, Serialize};

use super::canonical::CanonicalSystem;
use super::error::{Result, require_positive};

/// A DMP formulation with its gains (dimensionless, per unit normalised time). Named in saved files.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Formulation {
    /// Ijspeert et al. 2002 (the paper): second-order canonical system, forcing gated by the phase
    /// velocity and added to the velocity equation.
    Ijspeert2002 {
        /// α_z (25 in the paper).
        alpha_z: f64,
        /// β_z (α_z/4: critically damped).
        beta_z: f64,
        /// α_v of the canonical system (25).
        alpha_v: f64,
        /// β_v of the canonical system (α_v/4).
        beta_v: f64,
    },
    /// Ijspeert et al. 2013: first-order phase, forcing gated by s, scaled by (g − θ₀), added to
    /// the acceleration equation.
    Ijspeert2013 {
        /// α_z.
        alpha_z: f64,
        /// β_z.
        beta_z: f64,
        /// α_s of the phase `τ ṡ = −α_s s`.
        alpha_s: f64,
    },
    /// Hoffmann et al. 2009: `τ v̇ = K(g − x) − Dv − K(g − x₀)s + K f(s) s`; no goal scaling.
    Hoffmann2009 {
        /// Stiffness K.
        k: f64,
        /// Damping D (2√K: critically damped).
        d: f64,
        /// α_s of the phase.
        alpha_s: f64,
    },
}

/// α_s such that the first-order phase has decayed to 1 % at the end of the movement: ln 100.
pub const DEFAULT_ALPHA_S: f64 = 4.605_170_185_988_092;

impl Default for Formulation {
    /// The paper's: Ijspeert 2002 with α_z = α_v = 25, β = α/4.
    fn default() -> Self {
        Formulation::Ijspeert2002 {
            alpha_z: 25.0,
            beta_z: 6.25,
            alpha_v: 25.0,
            beta_v: 6.25,
        }
    }
}

impl Formulation {
    /// Ijspeert 2013 with α_z = 25, β_z = α_z/4, α_s = ln 100.
    pub fn ijspeert2013() -> Self {
        Formulation::Ijspeert2013 {
            alpha_z: 25.0,
            beta_z: 6.25,
            alpha_s: DEFAULT_ALPHA_S,
        }
    }

    /// Hoffmann 2009 with K = 25²/4, D = 25 (critically damped, the same dynamics as α_z = 25),
    /// α_s = ln 100.
    pub fn hoffmann2009() -> Self {
        Formulation::Hoffmann2009 {
            k: 156.25,
            d: 25.0,
            alpha_s: DEFAULT_ALPHA_S,
        }
    }

    /// The formulation's name as written in files and reports.
    pub fn name(&self) -> &'static str {
        match self {
            Formulation::Ijspeert2002 { .. } => "Ijspeert2002",
            Formulation::Ijspeert2013 { .. } => "Ijspeert2013",
            Formulation::Hoffmann2009 { .. } => "Hoffmann2009",
        }
    }

    /// The canonical system this formulation drives its kernels with.
    pub fn canonical(&self) -> CanonicalSystem {
        match *self {
            Formulation::Ijspeert2002 {
                alpha_v, beta_v, ..
            } => CanonicalSystem::SecondOrder { alpha_v, beta_v },
            Formulation::Ijspeert2013 { alpha_s, .. }
            | Formulation::Hoffmann2009 { alpha_s, .. } => CanonicalSystem::FirstOrder { alpha_s },
        }
    }

    /// Checks that every gain is finite and positive and the canonical system is valid.
    pub fn validate(&self) -> Result<()> {
        match *self {
            Formulation::Ijspeert2002 {
                alpha_z, beta_z, ..
            }
            | Formulation::Ijspeert2013 {
                alpha_z, beta_z, ..
            } => {
                require_positive("alpha_z", alpha_z)?;
                require_positive("beta_z", beta_z)?;
            }
            Formulation::Hoffmann2009 { k, d, .. } => {
                require_positive("k", k)?;
                require_positive("d", d)?;
            }
        }
        self.canonical().validate()
    }

    /// True if the forcing is scaled by (g − s) (2002, 2013); false for Hoffmann 2009.
    pub fn scales_with_goal(&self) -> bool {
        !matches!(self, Formulation::Hoffmann2009 { .. })
    }

    /// True if the forcing enters the velocity equation θ′ = z + F (2002); otherwise θ′ = z.
    pub fn forcing_in_velocity(&self) -> bool {
        matches!(self, Formulation::Ijspeert2002 { .. })
    }

    /// The state derivative (θ′, z′) in normalised time, for goal `g`, start `s`, first-order
    /// phase value `phase_x` (used by Hoffmann's `−K(g − θ₀)s`) and gated, scaled forcing `f`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn derivative(
        &self,
        theta: f64,
        z: f64,
        g: f64,
        s: f64,
        phase_x: f64,
        f: f64,
    ) -> (f64, f64) {
        match *self {
            Formulation::Ijspeert2002 {
                alpha_z, beta_z, ..
            } => deriv_2002(alpha_z, beta_z, theta, z, g, f),
            Formulation::Ijspeert2013 {
                alpha_z, beta_z, ..
            } => deriv_2013(alpha_z, beta_z, theta, z, g, f),
            Formulation::Hoffmann2009 { k, d, .. } => {
                deriv_hoffmann(k, d, theta, z, g, s, phase_x, f)
            }
        }
    }

    /// The forcing target F_target at one demonstration sample, from θ, θ′, θ″ (derivatives in
    /// normalised time), the integrated `z_demo` (2002 only), goal, start and phase value:
    /// 2002: `θ′ − z_demo`; 2013: `θ″ − α_z(β_z(g − θ) − θ′)`;
    /// Hoffmann: `(θ″ + Dθ′)/K − (g − θ) + (g − θ₀)s`.
    #[allow(clippy::too_many_arguments)]
    pub fn forcing_target(
        &self,
        theta: f64,
        d1: f64,
        d2: f64,
        z_demo: f64,
        g: f64,
        s: f64,
        phase_x: f64,
    ) -> f64 {
        match *self {
            Formulation::Ijspeert2002 { .. } => d1 - z_demo,
            Formulation::Ijspeert2013 {
                alpha_z, beta_z, ..
            } => d2 - alpha_z * (beta_z * (g - theta) - d1),
            Formulation::Hoffmann2009 { k, d, .. } => {
                (d2 + d * d1) / k - (g - theta) + (g - s) * phase_x
            }
        }
    }
}

/// Ijspeert 2002: (θ′, z′) = (z + F, α_z(β_z(g − θ) − z)).
#[inline(always)]
pub fn deriv_2002(alpha_z: f64, beta_z: f64, theta: f64, z: f64, g: f64, f: f64) -> (f64, f64) {
    (z + f, alpha_z * (beta_z * (g - theta) - z))
}

/// Ijspeert 2013: (θ′, z′) = (z, α_z(β_z(g − θ) − z) + F).
#[inline(always)]
pub fn deriv_2013(alpha_z: f64, beta_z: f64, theta: f64, z: f64, g: f64, f: f64) -> (f64, f64) {
    (z, alpha_z * (beta_z * (g - theta) - z) + f)
}

/// Hoffmann 2009: (θ′, z′) = (z, K(g − θ) − Dz − K(g − θ₀)s + K F), with s the phase.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn deriv_hoffmann(
    k: f64,
    d: f64,
    theta: f64,
    z: f64,
    g: f64,
    s0: f64,
    s: f64,
    f: f64,
) -> (f64, f64) {
    (z, k * (g - theta) - d * z - k * (g - s0) * s + k * f)
}

/// How a DOF's forcing follows a change of goal or start.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum SpatialScaling {
    /// k = (g − s)/reference, `reference` = g_d − s_d of the demonstration (2002, 2013 when
    /// |g_d − s_d| is large enough). A sign flip of g − s mirrors the motion.
    GoalMinusStart {
        /// g − s of the demonstration (radians or metres), |reference| above the degeneracy threshold.
        reference: f64,
    },
    /// k = 1: the forcing is the demonstration's whatever the goal (Hoffmann 2009, and degenerate
    /// DOFs with g ≈ s under 2002/2013).
    Unscaled,
}

impl SpatialScaling {
    /// The forcing factor k for goal `g` and start `s`.
    #[inline]
    pub fn factor(&self, g: f64, s: f64) -> f64 {
        match *self {
            SpatialScaling::GoalMinusStart { reference } => (g - s) / reference,
            SpatialScaling::Unscaled => 1.0,
        }
    }
}

/// The paper's learning state z_demo for `goals.len()` DOFs at once: integrates
/// `z′ = α_z(β_z(g − θ_demo(u)) − z)`, z(0) = `z0`, along demonstration samples `theta`
/// (frames × dofs, row-major) spaced `du` apart in normalised time; `out` has the same layout.
/// Between samples θ is taken linear, for which the step is exact:
/// `z_{k+1} = e^{−a h} z_k + b[(g − θ_k)(1 − e^{−ah})/a − (θ_{k+1} − θ_k)(h/a − (1 − e^{−ah})/a²)/h]`
/// with a = α_z, b = α_zβ_z, h = du.
pub fn integrate_z_demo(
    alpha_z: f64,
    beta_z: f64,
    goals: &[f64],
    theta: &[f64],
    du: f64,
    z0: &[f64],
    out: &mut [f64],
) {
    let dofs = goals.len();
    let n = theta.len() / dofs;
    let a = alpha_z;
    let b = alpha_z * beta_z;
    let e = (-a * du).exp();
    let i0 = b * (1.0 - e) / a;
    let i1 = b * (du / a - (1.0 - e) / (a * a)) / du;
    out[..dofs].copy_from_slice(z0);
    for k in 0..n - 1 {
        let (done, rest) = out.split_at_mut((k + 1) * dofs);
        let z = &done[k * dofs..];
        let next = &mut rest[..dofs];
        let th = &theta[k * dofs..(k + 1) * dofs];
        let th1 = &theta[(k + 1) * dofs..(k + 2) * dofs];
        for j in 0..dofs {
            next[j] = e * z[j] + (goals[j] - th[j]) * i0 - (th1[j] - th[j]) * i1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn z_demo_integration_is_exact_for_piecewise_linear_theta() {
        // θ(u) = 0.3 + 0.7u (linear): compare with a fine RK4 of the same ODE.
        let (a, bz, g) = (25.0, 6.25, 1.2);
        let n = 11;
        let du = 0.1;
        let theta: Vec<f64> = (0..n).map(|k| 0.3 + 0.7 * k as f64 * du).collect();
        let mut z = vec![0.0; n];
        integrate_z_demo(a, bz, &[g], &theta, du, &[0.4], &mut z);
        let f = |u: f64, z: f64| a * (bz * (g - (0.3 + 0.7 * u)) - z);
        let (mut zz, h) = (0.4, 1e-4);
        for step in 0..10_000 {
            let u = step as f64 * h;
            let k1 = f(u, zz);
            let k2 = f(u + 0.5 * h, zz + 0.5 * h * k1);
            let k3 = f(u + 0.5 * h, zz + 0.5 * h * k2);
            let k4 = f(u + h, zz + h * k3);
            zz += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        assert!((z[10] - zz).abs() < 1e-9, "{} vs {zz}", z[10]);
    }

    #[test]
    fn hoffmann_does_not_scale_with_goal() {
        assert!(Formulation::default().scales_with_goal());
        assert!(Formulation::ijspeert2013().scales_with_goal());
        assert!(!Formulation::hoffmann2009().scales_with_goal());
        let s = SpatialScaling::GoalMinusStart { reference: 0.5 };
        assert!((s.factor(-0.5, 0.0) + 1.0).abs() < 1e-15);
        assert_eq!(SpatialScaling::Unscaled.factor(-0.5, 0.0), 1.0);
    }

    #[test]
    fn each_formulation_rests_at_its_goal_without_forcing() {
        for f in [
            Formulation::default(),
            Formulation::ijspeert2013(),
            Formulation::hoffmann2009(),
        ] {
            f.validate().unwrap();
            let (dth, dz) = f.derivative(0.7, 0.0, 0.7, 0.7, 0.3, 0.0);
            assert_eq!((dth, dz), (0.0, 0.0), "{}", f.name());
        }
    }
}
