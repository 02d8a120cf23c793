//! The linearly implicit (semi-implicit, "Rosenbrock–Euler") step of stiff springs and dampers:
//! every force `f(q, v)` that is stiff — PD control, the joint model past its range and its
//! friction inside it, the floor's penalty springs and dampers on the corners that push and
//! the friction springs of the corners that stick — is
//! replaced by its linearisation at the step end,
//!
//! `f(q + h v', v') ≈ f(q, v) − K h v' − D (v' − v)`, with `K = −∂f/∂q`, `D = −∂f/∂v`,
//!
//! so that `H (v' − v) = h (f − C − K h v' − D (v' − v))`, i.e. with `q̈ = (v' − v)/h`:
//!
//! `(H + h D + h² K) q̈ = f − C − h K v`,   then `v' = v + h q̈`, `q' = q ⊞ h v'`.
//!
//! For a linear spring–damper this is backward Euler: stable at every step, with numerical
//! damping where `ω h` is large, instead of semi-implicit Euler's bound `ω h ≤ 2`.
//!
//! Nothing dense is solved. A joint force's `K` and `D` are diagonal in the DOFs: they enter the
//! articulated-body algorithm as an armature `h d + h² k` on the DOF and the torque correction
//! `−h k v` ([`joint`]). A floor corner's spring `k` and damper `c` act along the normal through
//! the corner's Jacobian `J = jᵀ J_b` (`j = [p × n; n]` the unit normal force at corner `p`,
//! `J_b` the body's Jacobian): `Jᵀ (h c + h² k) J` is an inertia `h (c + h k) j jᵀ` added to the
//! body in the ABA (the same O(n) device as the contact's implicit damping, exact in exact
//! arithmetic: the ABA solves `H + Σ J_bᵀ I_c J_b` as CRBA + Cholesky would), and the
//! force correction `−h k ż j` ([`corner`]). A sticking corner's friction spring and damper
//! are taken the same way along both tangents of the floor; a slipping corner's friction (the
//! cone's `μ f_n`) stays explicit.
//!
//! The force the step applies is the linearised one; the contact monitor and the damage keep
//! sampling the force law `f(q, v)` at the step starts, as with the explicit schemes.

use super::forces::limits::JointRanges;
use super::forces::pd::PdTargets;

/// The linearised step's terms for one DOF whose joint torque `tau` (N·m) has damping `d`
/// (N·m·s/rad) and stiffness `k` (N·m/rad) at velocity `v` (rad/s), step `h` (s), weight
/// `theta` (1 at the step end, ½ at its midpoint): the armature `θh (d + h k)` (N·m·s²) the
/// ABA adds to the DOF's inertia and the torque `tau − θh k v`.
#[inline(always)]
pub fn joint(h: f64, theta: f64, tau: f64, d: f64, k: f64, v: f64) -> (f64, f64) {
    let th = theta * h;
    (th * (d + h * k), tau - th * k * v)
}

/// The linearised step's terms for one pushing floor corner with spring `k` (N/m) and damper
/// `c` (N·s/m) moving along the normal at `zd` (m/s), step `h` (s), weight `theta`: the factor
/// `θh (c + h k)` of the corner's inertia `j jᵀ` and the normal-force correction `−θh k ż` (N).
#[inline(always)]
pub fn corner(h: f64, theta: f64, k: f64, c: f64, zd: f64) -> (f64, f64) {
    let th = theta * h;
    (th * (c + h * k), -th * k * zd)
}

/// The stiffness `−∂τ/∂θ` (N·m/rad) of DOF `d`'s PD torque `tau`: `k_p`, or 0 where the torque
/// is held at the DOF's strength (it no longer depends on θ).
#[inline(always)]
pub fn pd_stiffness(pd: &PdTargets, d: usize, tau: f64) -> f64 {
    if pd.saturates(d, tau) { 0.0 } else { pd.kp[d] }
}

/// The stiffness `−∂τ/∂θ` (N·m/rad) of DOF `d`'s joint model at angle `theta`: its limit spring
/// past the range, 0 inside.
#[inline(always)]
pub fn limit_stiffness(limits: &JointRanges, d: usize, theta: f64) -> f64 {
    let (lo, hi) = limits.ranges[d];
    if theta > hi || theta < lo {
        limits.limit(d).0
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Steps `ẍ = −ω² x − 2ζω ẋ` (unit mass) `n` times by the linearised step at weight
    /// `theta`; the largest |x| after the first step.
    fn oscillate_at(theta: f64, omega: f64, zeta: f64, h: f64, n: usize) -> f64 {
        let (k, c) = (omega * omega, 2.0 * zeta * omega);
        let (mut x, mut v) = (1.0f64, 0.0f64);
        let mut peak: f64 = 0.0;
        for _ in 0..n {
            let (arm, f) = joint(h, theta, -k * x - c * v, c, k, v);
            let a = f / (1.0 + arm);
            v += h * a;
            x += h * v;
            peak = peak.max(x.abs());
        }
        peak
    }

    fn oscillate(omega: f64, zeta: f64, h: f64, n: usize) -> f64 {
        oscillate_at(1.0, omega, zeta, h, n)
    }

    #[test]
    fn at_the_midpoint_an_undamped_spring_loses_the_predicted_amplitude_and_stays_bounded() {
        // Per step the map (x, v) → (x', v') has determinant 1/(1 + θ ω²h²): the energy of an
        // undamped spring shrinks by that factor each step, half as fast at θ = ½ as at θ = 1
        // to first order, and no step makes it grow.
        let (omega, h, n) = (300.0, 0.002, 200i32);
        let a = (omega * h) * (omega * h);
        for theta in [0.5, 1.0] {
            let (k, mut x, mut v) = (omega * omega, 1.0f64, 0.0f64);
            for _ in 0..n {
                let (arm, f) = joint(h, theta, -k * x, 0.0, k, v);
                v += h * f / (1.0 + arm);
                x += h * v;
            }
            // The energy's geometric mean decay: |det|^n, up to the ellipse's phase.
            let energy = 0.5 * (k * x * x + v * v) / (0.5 * k);
            let predicted = (1.0 + theta * a).powi(-n);
            let ratio = energy / predicted;
            assert!(
                ratio > 0.3 && ratio < 3.0,
                "θ = {theta}: {energy:e} vs {predicted:e}"
            );
        }
        // Stable far past the explicit bound (ω h = 2), without decay to speak of at ω h = 20:
        // the stiffest modes alternate.
        assert!(oscillate_at(0.5, 10_000.0, 0.0, 0.002, 2000) <= 1.0 + 1e-12);
        // With its damper it settles: after 0.4 s (ζω t = 60) nothing is left.
        let (k, c, h) = (9e4, 300.0, 0.002);
        let (mut x, mut v) = (1.0f64, 0.0f64);
        for _ in 0..200 {
            let (arm, f) = joint(h, 0.5, -k * x - c * v, c, k, v);
            v += h * f / (1.0 + arm);
            x += h * v;
        }
        assert!(x.abs() < 1e-6 && v.abs() < 1e-3, "x = {x}, v = {v}");
    }

    #[test]
    fn a_linear_oscillator_is_backward_euler_and_stable_far_past_the_explicit_bound() {
        // ω h = 20 (ten times semi-implicit Euler's bound of 2), undamped: it decays.
        assert!(oscillate(1000.0, 0.0, 0.02, 2000) < 1.0);
        // The step is backward Euler: x' = x + h v', v' = v + h(−k x' − c v').
        let (k, c, h) = (400.0, 3.0, 0.01);
        let (x, v) = (0.2, -1.5);
        let (arm, f) = joint(h, 1.0, -k * x - c * v, c, k, v);
        let v1 = v + h * f / (1.0 + arm);
        let x1 = x + h * v1;
        assert!((v1 - (v + h * (-k * x1 - c * v1))).abs() < 1e-12);
        // At a small step it follows the exact motion x = cos ωt to first order.
        let (omega, h) = (10.0, 1e-5);
        let (mut x, mut v) = (1.0f64, 0.0f64);
        for _ in 0..(0.1 / h) as usize {
            let (arm, f) = joint(h, 1.0, -omega * omega * x, 0.0, omega * omega, v);
            v += h * f / (1.0 + arm);
            x += h * v;
        }
        assert!((x - (omega * 0.1).cos()).abs() < 1e-3, "x = {x}");
    }

    #[test]
    fn saturated_pd_and_joints_inside_their_range_have_no_stiffness() {
        let pd = PdTargets::hold(vec![1.0], vec![100.0], vec![10.0])
            .with_torque_limits(vec![(-30.0, 50.0)]);
        assert_eq!(pd_stiffness(&pd, 0, pd.torque(0, 0.0, 0.0).0), 0.0);
        assert_eq!(pd_stiffness(&pd, 0, pd.torque(0, 0.9, 0.0).0), 100.0);
        let l = JointRanges {
            ranges: vec![(-0.5, 1.0)],
            params: Default::default(),
            limit_gains: vec![(700.0, 5.0)],
        };
        assert_eq!(limit_stiffness(&l, 0, 0.2), 0.0);
        assert_eq!(limit_stiffness(&l, 0, 1.1), 700.0);
        assert_eq!(limit_stiffness(&l, 0, -0.6), 700.0);
        assert_eq!(
            corner(0.002, 1.0, 1e5, 100.0, -0.5),
            (0.002 * (100.0 + 200.0), 100.0)
        );
    }
}
