//! Spatial (6-D) vector algebra after Featherstone, *Rigid Body Dynamics Algorithms* (2008), ch. 2,
//! kept as pairs of 3-vectors and 3×3 blocks: no 6×6 matrix is ever formed.
//!
//! Ordering is Featherstone's: a motion vector is `[ω; v]` (angular; linear velocity of the body
//! point at the frame origin), a force vector is `[n; f]` (moment about the origin; force).
//! A [`SpatialTransform`] `X` from frame A to frame B is `rot(E)·xlt(r)`: `E` rotates A
//! coordinates into B coordinates and `r` is B's origin expressed in A.

use super::axis_rotation::JointRotation;
use glam::{DMat3, DVec3};
use serde::{Deserialize, Serialize};
use std::ops::{Add, AddAssign, Mul, Neg, Sub, SubAssign};

/// The cross-product matrix `[r]×` with `[r]× x = r × x`.
#[inline]
pub fn skew(r: DVec3) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(0.0, r.z, -r.y),
        DVec3::new(-r.z, 0.0, r.x),
        DVec3::new(r.y, -r.x, 0.0),
    )
}

/// `Aᵀ x` without forming the transpose.
#[inline]
pub fn transpose_mul(a: &DMat3, x: DVec3) -> DVec3 {
    DVec3::new(a.x_axis.dot(x), a.y_axis.dot(x), a.z_axis.dot(x))
}

/// The outer product `a bᵀ` as a 3×3 matrix.
#[inline]
pub fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// A spatial motion vector `[ω; v]` (rad/s; m/s), or an acceleration (rad/s², m/s²).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MotionVec {
    /// Angular part ω.
    pub ang: DVec3,
    /// Linear part v: velocity of the body-fixed point at the frame origin.
    pub lin: DVec3,
}

/// A spatial force vector `[n; f]` (N·m about the frame origin; N), or a momentum.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ForceVec {
    /// Moment n about the frame origin.
    pub ang: DVec3,
    /// Force f.
    pub lin: DVec3,
}

impl MotionVec {
    /// The zero motion.
    pub const ZERO: Self = Self {
        ang: DVec3::ZERO,
        lin: DVec3::ZERO,
    };

    /// Builds `[ang; lin]`.
    #[inline]
    pub const fn new(ang: DVec3, lin: DVec3) -> Self {
        Self { ang, lin }
    }

    /// The motion cross product `self ×m m` = `[ω×m_ω; ω×m_v + v×m_ω]` (Featherstone eq. 2.31).
    #[inline]
    pub fn cross_motion(self, m: MotionVec) -> MotionVec {
        MotionVec {
            ang: self.ang.cross(m.ang),
            lin: self.ang.cross(m.lin) + self.lin.cross(m.ang),
        }
    }

    /// The force cross product `self ×* f` = `[ω×n + v×f; ω×f]` (Featherstone eq. 2.32).
    #[inline]
    pub fn cross_force(self, f: ForceVec) -> ForceVec {
        ForceVec {
            ang: self.ang.cross(f.ang) + self.lin.cross(f.lin),
            lin: self.ang.cross(f.lin),
        }
    }

    /// The scalar product `m · f` (power, W, when m is a velocity and f a force).
    #[inline]
    pub fn dot(self, f: ForceVec) -> f64 {
        self.ang.dot(f.ang) + self.lin.dot(f.lin)
    }

    /// True if all six components are finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.ang.is_finite() && self.lin.is_finite()
    }
}

impl ForceVec {
    /// The zero force.
    pub const ZERO: Self = Self {
        ang: DVec3::ZERO,
        lin: DVec3::ZERO,
    };

    /// Builds `[ang; lin]`.
    #[inline]
    pub const fn new(ang: DVec3, lin: DVec3) -> Self {
        Self { ang, lin }
    }

    /// The force `f` (N) acting at point `p` (m, in this frame), as a spatial force `[p×f; f]`.
    #[inline]
    pub fn at_point(f: DVec3, p: DVec3) -> Self {
        Self {
            ang: p.cross(f),
            lin: f,
        }
    }

    /// True if all six components are finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.ang.is_finite() && self.lin.is_finite()
    }

    /// The scalar product `f · m`.
    #[inline]
    pub fn dot_motion(self, m: MotionVec) -> f64 {
        m.dot(self)
    }
}

macro_rules! vec_ops {
    ($t:ty) => {
        impl Add for $t {
            type Output = $t;
            #[inline]
            fn add(self, o: $t) -> $t {
                Self {
                    ang: self.ang + o.ang,
                    lin: self.lin + o.lin,
                }
            }
        }
        impl Sub for $t {
            type Output = $t;
            #[inline]
            fn sub(self, o: $t) -> $t {
                Self {
                    ang: self.ang - o.ang,
                    lin: self.lin - o.lin,
                }
            }
        }
        impl AddAssign for $t {
            #[inline]
            fn add_assign(&mut self, o: $t) {
                self.ang += o.ang;
                self.lin += o.lin;
            }
        }
        impl SubAssign for $t {
            #[inline]
            fn sub_assign(&mut self, o: $t) {
                self.ang -= o.ang;
                self.lin -= o.lin;
            }
        }
        impl Neg for $t {
            type Output = $t;
            #[inline]
            fn neg(self) -> $t {
                Self {
                    ang: -self.ang,
                    lin: -self.lin,
                }
            }
        }
        impl Mul<f64> for $t {
            type Output = $t;
            #[inline]
            fn mul(self, s: f64) -> $t {
                Self {
                    ang: self.ang * s,
                    lin: self.lin * s,
                }
            }
        }
    };
}
vec_ops!(MotionVec);
vec_ops!(ForceVec);

/// A Plücker transform `X = rot(E)·xlt(r)` from frame A to frame B (Featherstone §2.8).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpatialTransform {
    /// `E`: rotates A coordinates into B coordinates (the transpose of B's orientation in A).
    pub rot: DMat3,
    /// `r`: B's origin expressed in A coordinates (m).
    pub trans: DVec3,
}

impl Default for SpatialTransform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl SpatialTransform {
    /// The identity transform.
    pub const IDENTITY: Self = Self {
        rot: DMat3::IDENTITY,
        trans: DVec3::ZERO,
    };

    /// A pure translation `xlt(r)`: frame B is frame A moved to `r`.
    #[inline]
    pub fn translation(r: DVec3) -> Self {
        Self {
            rot: DMat3::IDENTITY,
            trans: r,
        }
    }

    /// A pure rotation `rot(E)`.
    #[inline]
    pub fn rotation(e: DMat3) -> Self {
        Self {
            rot: e,
            trans: DVec3::ZERO,
        }
    }

    /// `X m`: motion in A → motion in B: `[Eω; E(v − r×ω)]`.
    #[inline]
    pub fn apply_motion(&self, m: MotionVec) -> MotionVec {
        MotionVec {
            ang: self.rot * m.ang,
            lin: self.rot * (m.lin - self.trans.cross(m.ang)),
        }
    }

    /// `X* f`: force in A → force in B: `[E(n − r×f); Ef]`.
    #[inline]
    pub fn apply_force(&self, f: ForceVec) -> ForceVec {
        ForceVec {
            ang: self.rot * (f.ang - self.trans.cross(f.lin)),
            lin: self.rot * f.lin,
        }
    }

    /// `X⁻¹ m`: motion in B → motion in A: `[Eᵀω; Eᵀv + r×Eᵀω]`.
    #[inline]
    pub fn inv_apply_motion(&self, m: MotionVec) -> MotionVec {
        let ang = self.rot.transpose() * m.ang;
        MotionVec {
            ang,
            lin: self.rot.transpose() * m.lin + self.trans.cross(ang),
        }
    }

    /// `Xᵀ f` (= `(X*)⁻¹ f`): force in B → force in A: `[Eᵀn + r×Eᵀf; Eᵀf]`.
    #[inline]
    pub fn inv_apply_force(&self, f: ForceVec) -> ForceVec {
        let lin = self.rot.transpose() * f.lin;
        ForceVec {
            ang: self.rot.transpose() * f.ang + self.trans.cross(lin),
            lin,
        }
    }

    /// The inverse transform B → A.
    #[inline]
    pub fn inverse(&self) -> Self {
        Self {
            rot: self.rot.transpose(),
            trans: -(self.rot * self.trans),
        }
    }
}

impl Mul for SpatialTransform {
    type Output = SpatialTransform;
    /// Composition `X_BC · X_AB = X_AC`: `E = E_BC E_AB`, `r = r_AB + E_ABᵀ r_BC`.
    #[inline]
    fn mul(self, rhs: SpatialTransform) -> SpatialTransform {
        SpatialTransform {
            rot: self.rot * rhs.rot,
            trans: rhs.trans + rhs.rot.transpose() * self.trans,
        }
    }
}

/// A rigid-body spatial inertia: mass `m` (kg), centre of mass `c` (m, body frame) and rotational
/// inertia `I_c` about the centre of mass (kg·m², body axes). Featherstone eq. 2.63:
/// `I = [I_c + m[c]×[c]×ᵀ, m[c]×; m[c]×ᵀ, m1]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Inertia {
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass in the body frame (m).
    pub com: DVec3,
    /// Rotational inertia about the centre of mass, body axes (kg·m²).
    pub inertia_com: DMat3,
}

impl Inertia {
    /// A body of `mass` with centre `com` and rotational inertia `inertia_com` about it.
    pub fn new(mass: f64, com: DVec3, inertia_com: DMat3) -> Self {
        Self {
            mass,
            com,
            inertia_com,
        }
    }

    /// A solid box of `mass` and full edge lengths `size` (m) centred at `com`.
    pub fn solid_box(mass: f64, com: DVec3, size: DVec3) -> Self {
        let s2 = size * size;
        let d = DVec3::new(s2.y + s2.z, s2.x + s2.z, s2.x + s2.y) * (mass / 12.0);
        Self::new(mass, com, DMat3::from_diagonal(d))
    }

    /// `I v`: the momentum `[I_c ω + c×h; h]` with `h = m(v − c×ω)`.
    #[inline]
    pub fn apply(&self, v: MotionVec) -> ForceVec {
        let h = (v.lin - self.com.cross(v.ang)) * self.mass;
        ForceVec {
            ang: self.inertia_com * v.ang + self.com.cross(h),
            lin: h,
        }
    }

    /// The same inertia as 3×3 blocks (`[M H; Hᵀ L]`), the form the articulated-body algorithm uses.
    #[inline]
    pub fn to_blocks(&self) -> ArticulatedInertia {
        let cx = skew(self.com);
        ArticulatedInertia {
            m: self.inertia_com - cx * cx * self.mass,
            h: cx * self.mass,
            l: DMat3::from_diagonal(DVec3::splat(self.mass)),
        }
    }

    /// Kinetic energy `½ vᵀ I v` (J) of a body moving with spatial velocity `v`.
    #[inline]
    pub fn kinetic_energy(&self, v: MotionVec) -> f64 {
        0.5 * v.dot(self.apply(v))
    }
}

/// A symmetric 6×6 spatial inertia (rigid or articulated) stored as 3×3 blocks `[M H; Hᵀ L]`
/// (M, L symmetric). Units: kg·m², kg·m, kg.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ArticulatedInertia {
    /// Angular–angular block M.
    pub m: DMat3,
    /// Angular–linear coupling block H.
    pub h: DMat3,
    /// Linear–linear block L.
    pub l: DMat3,
}

impl ArticulatedInertia {
    /// The zero inertia.
    pub const ZERO: Self = Self {
        m: DMat3::ZERO,
        h: DMat3::ZERO,
        l: DMat3::ZERO,
    };

    /// `I v = [Mω + Hv; Hᵀω + Lv]`.
    #[inline]
    pub fn apply(&self, v: MotionVec) -> ForceVec {
        ForceVec {
            ang: self.m * v.ang + self.h * v.lin,
            lin: transpose_mul(&self.h, v.ang) + self.l * v.lin,
        }
    }

    /// `I [ω; 0] = [Mω; Hᵀω]`: the product with a pure rotation (a revolute joint's column).
    #[inline]
    pub fn apply_angular(&self, w: DVec3) -> ForceVec {
        ForceVec {
            ang: self.m * w,
            lin: transpose_mul(&self.h, w),
        }
    }

    /// `I − (1/d) U Uᵀ` for a force vector `U` (the rank-one update of a 1-DOF joint in ABA);
    /// `M` and `L` stay exactly symmetric.
    #[inline]
    pub fn sub_outer(&mut self, u: ForceVec, inv_d: f64) {
        self.sub_products(&[u * inv_d], &[u]);
    }

    /// `I − Σ_j W_j U_jᵀ` for force columns `W`, `U` whose sum is symmetric (`W = U D⁻¹` with a
    /// symmetric `D`): `H` in full, the six distinct entries of `M` and `L` from their upper
    /// triangles, mirrored so they stay exactly symmetric.
    #[inline(always)]
    pub fn sub_products<const N: usize>(&mut self, w: &[ForceVec; N], u: &[ForceVec; N]) {
        for j in 0..N {
            self.h -= outer(w[j].ang, u[j].lin);
        }
        let wa: [DVec3; N] = std::array::from_fn(|j| w[j].ang);
        let ua: [DVec3; N] = std::array::from_fn(|j| u[j].ang);
        let wl: [DVec3; N] = std::array::from_fn(|j| w[j].lin);
        let ul: [DVec3; N] = std::array::from_fn(|j| u[j].lin);
        sub_symmetric(&mut self.m, &wa, &ua);
        sub_symmetric(&mut self.l, &wl, &ul);
    }

    /// `I − U D⁻¹ Uᵀ` for `n ≤ 3` force columns `U` and the inverse `D⁻¹` (n×n block of `dinv`).
    #[inline(always)]
    pub fn sub_u_dinv_ut(&mut self, u: &[ForceVec], dinv: &DMat3) {
        // Inlined, with loops rather than `array::from_fn`: out of line, the physics step's
        // AVX2 copy would call it compiled without AVX2.
        #[inline(always)]
        fn go<const N: usize>(ia: &mut ArticulatedInertia, u: &[ForceVec], dinv: &DMat3) {
            let mut cols = [ForceVec::ZERO; N];
            cols.copy_from_slice(&u[..N]);
            // w_j = Σ_k U_k D⁻¹_kj
            let mut w = [ForceVec::ZERO; N];
            for (j, wj) in w.iter_mut().enumerate() {
                for (k, uk) in cols.iter().enumerate() {
                    *wj += *uk * dinv.col(j)[k];
                }
            }
            ia.sub_products(&w, &cols);
        }
        match u.len() {
            0 => {}
            1 => go::<1>(self, u, dinv),
            2 => go::<2>(self, u, dinv),
            _ => go::<3>(self, u, dinv),
        }
    }

    /// `Xᵀ I X`: an inertia given in frame B (child) expressed in frame A (parent), for `X`: A → B.
    /// With `M' = EᵀME` etc. and `R = [r]×`: `M_A = M' − H'R + RH'ᵀ − RL'R`, `H_A = H' + RL'`,
    /// `L_A = L'`.
    #[inline]
    pub fn transform_to_parent(&self, x: &SpatialTransform) -> Self {
        self.transform_to_parent_with(x, &JointRotation::General)
    }

    /// [`ArticulatedInertia::transform_to_parent`] with `x`'s rotation also given as its
    /// coordinate-axis factors (`rotation`, from the kinematics): `EᵀAE = R A Rᵀ` per block
    /// through them. `M` and `L` are symmetric, so only their six distinct entries are formed
    /// (the result's `M` and `L` are exactly symmetric).
    #[inline(always)]
    pub fn transform_to_parent_with(&self, x: &SpatialTransform, rotation: &JointRotation) -> Self {
        let e = x.rot;
        let m1 = rotation.conjugate_symmetric(&e, &self.m);
        let h1 = rotation.conjugate(&e, &self.h);
        let l1 = rotation.conjugate_symmetric(&e, &self.l);
        // The products with R = [r]× as cross products: `R A` has columns `r × a_j`, and
        // `(A R)_ij` is `a_i1 r_z − a_i2 r_y`, `a_i2 r_x − a_i0 r_z`, `a_i0 r_y − a_i1 r_x` for
        // j = 0, 1, 2 (the products with `skew(r)` without its zero entries).
        let r = x.trans;
        let cross_cols =
            |a: DMat3| DMat3::from_cols(r.cross(a.x_axis), r.cross(a.y_axis), r.cross(a.z_axis));
        let rl = cross_cols(l1);
        let rh = cross_cols(h1.transpose());
        // `(R L R)_ij` from row i of `R L`, for the upper entries.
        let rlr = |row: DVec3, j: usize| match j {
            0 => row.y * r.z - row.z * r.y,
            1 => row.z * r.x - row.x * r.z,
            _ => row.x * r.y - row.y * r.x,
        };
        let rows = [rl.row(0), rl.row(1), rl.row(2)];
        // `M_A = M' + R H'ᵀ + (R H'ᵀ)ᵀ − R L' R`.
        let m = symmetric(|i, j| m1.col(j)[i] + rh.col(j)[i] + rh.col(i)[j] - rlr(rows[i], j));
        Self {
            m,
            h: h1 + rl,
            l: l1,
        }
    }

    /// Solves `I a = f` for a symmetric positive definite `I` by the Schur complement of `L`:
    /// `(M − H L⁻¹ Hᵀ) ω = n − H L⁻¹ f_lin`, `v = L⁻¹(f_lin − Hᵀ ω)`.
    #[inline(always)]
    pub fn solve(&self, f: ForceVec) -> MotionVec {
        let linv = self.l.inverse();
        let hl = self.h * linv;
        let schur = self.m - hl * self.h.transpose();
        let ang = schur.inverse() * (f.ang - hl * f.lin);
        let lin = linv * (f.lin - self.h.transpose() * ang);
        MotionVec { ang, lin }
    }
}

/// `A − Σ_j x_j y_jᵀ` for a symmetric result: the upper entries, mirrored.
#[inline(always)]
fn sub_symmetric<const N: usize>(a: &mut DMat3, x: &[DVec3; N], y: &[DVec3; N]) {
    *a = symmetric(|r, c| {
        let mut e = a.col(c)[r];
        for j in 0..N {
            e -= x[j][r] * y[j][c];
        }
        e
    });
}

/// The symmetric matrix whose entries on and above the diagonal are `entry(r, c)` (`r ≤ c`,
/// six calls), mirrored below it.
#[inline(always)]
fn symmetric(entry: impl Fn(usize, usize) -> f64) -> DMat3 {
    let (m00, m11, m22) = (entry(0, 0), entry(1, 1), entry(2, 2));
    let (m01, m02, m12) = (entry(0, 1), entry(0, 2), entry(1, 2));
    DMat3::from_cols(
        DVec3::new(m00, m01, m02),
        DVec3::new(m01, m11, m12),
        DVec3::new(m02, m12, m22),
    )
}

impl Add for ArticulatedInertia {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Self {
            m: self.m + o.m,
            h: self.h + o.h,
            l: self.l + o.l,
        }
    }
}

impl AddAssign for ArticulatedInertia {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        self.m += o.m;
        self.h += o.h;
        self.l += o.l;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DQuat;

    fn xf() -> SpatialTransform {
        let q = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, -0.5).normalize(), 0.7);
        SpatialTransform {
            rot: DMat3::from_quat(q).transpose(),
            trans: DVec3::new(0.3, -0.2, 0.5),
        }
    }

    fn mv() -> MotionVec {
        MotionVec::new(DVec3::new(0.1, -0.4, 0.9), DVec3::new(1.2, 0.3, -0.7))
    }

    fn fv() -> ForceVec {
        ForceVec::new(DVec3::new(-0.6, 0.2, 0.4), DVec3::new(0.5, 1.1, -0.3))
    }

    #[test]
    fn power_is_invariant_under_change_of_frame() {
        let x = xf();
        let p_a = mv().dot(fv());
        let p_b = x.apply_motion(mv()).dot(x.apply_force(fv()));
        assert!((p_a - p_b).abs() < 1e-14);
    }

    #[test]
    fn inverse_round_trips() {
        let x = xf();
        let m = x.inv_apply_motion(x.apply_motion(mv()));
        let f = x.inv_apply_force(x.apply_force(fv()));
        assert!((m - mv()).ang.length() + (m - mv()).lin.length() < 1e-14);
        assert!((f - fv()).ang.length() + (f - fv()).lin.length() < 1e-14);
        let mi = x.inverse().apply_motion(x.apply_motion(mv()));
        assert!((mi - mv()).lin.length() < 1e-14);
    }

    #[test]
    fn composition_matches_sequential_application() {
        let a = xf();
        let b = SpatialTransform {
            rot: DMat3::from_rotation_z(0.4),
            trans: DVec3::new(-0.1, 0.7, 0.2),
        };
        let m1 = (b * a).apply_motion(mv());
        let m2 = b.apply_motion(a.apply_motion(mv()));
        assert!((m1 - m2).ang.length() + (m1 - m2).lin.length() < 1e-14);
    }

    #[test]
    fn blocks_and_transform_agree_with_rigid_inertia() {
        let i = Inertia::new(
            2.5,
            DVec3::new(0.1, 0.2, -0.05),
            DMat3::from_diagonal(DVec3::new(0.3, 0.2, 0.1)),
        );
        let b = i.to_blocks();
        let f1 = i.apply(mv());
        let f2 = b.apply(mv());
        assert!((f1 - f2).ang.length() + (f1 - f2).lin.length() < 1e-13);
        // Xᵀ I_B X v = Xᵀ (I_B (X v)).
        let x = xf();
        let ia = b.transform_to_parent(&x);
        let lhs = ia.apply(mv());
        let rhs = x.inv_apply_force(b.apply(x.apply_motion(mv())));
        assert!((lhs - rhs).ang.length() + (lhs - rhs).lin.length() < 1e-13);
        // Solve round trip.
        let a = ia.solve(lhs);
        assert!((a - mv()).ang.length() + (a - mv()).lin.length() < 1e-12);
    }

    #[test]
    fn cross_products_are_dual() {
        // (v ×m m)·f = −m·(v ×* f)
        let v = MotionVec::new(DVec3::new(0.3, 0.1, -0.2), DVec3::new(0.0, 0.5, 0.4));
        let l = v.cross_motion(mv()).dot(fv());
        let r = -mv().dot(v.cross_force(fv()));
        assert!((l - r).abs() < 1e-14);
    }
}
