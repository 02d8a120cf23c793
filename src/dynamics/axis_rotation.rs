//! Rotations about coordinate axes, the joints of a human model: a revolute joint whose axis is
//! `±e_k` and whose tree transform does not rotate turns its child by `R = R_k(φ)`, which mixes
//! only two coordinates. The kinematics and the articulated-body algorithm use that structure
//! where it holds ([`JointAxes`] per body, found once in the model) instead of general 3×3
//! products: `R A Rᵀ` costs 24 multiplications instead of 54, `A R` 12 instead of 27, `R v` 4
//! instead of 9.

use super::real::{Mat3Ops, Real, Vec3Ops};
use glam::{DMat3, DVec3};

/// A signed coordinate axis `sign · e_k` (`k` = 0, 1, 2 for x, y, z; `sign` = ±1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoordAxis {
    /// Coordinate index.
    pub k: usize,
    /// +1 or −1.
    pub sign: f64,
}

impl CoordAxis {
    /// The coordinate axis `a` is exactly, if it is one (`±e_x`, `±e_y`, `±e_z`).
    pub fn of(a: DVec3) -> Option<Self> {
        let v = a.to_array();
        let k = (0..3).find(|&k| v[k].abs() == 1.0)?;
        let others_zero = (0..3).all(|m| m == k || v[m] == 0.0);
        others_zero.then_some(Self { k, sign: v[k] })
    }
}

/// How a body's joint rotation `R` (child → parent coordinates) factors, found once per model:
/// into one or two rotations about coordinate axes (a pin or universal joint with such axes and a
/// tree transform without rotation), or not at all.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum JointAxes {
    /// `R` has no coordinate-axis structure used here (ball, free, fixed joints, general axes, or
    /// a rotating tree transform).
    General,
    /// `R = R_a(θ)`.
    One(CoordAxis),
    /// `R = R_a(θ₁) R_b(θ₂)`.
    Two(CoordAxis, CoordAxis),
}

/// The rotation by angle `φ` about coordinate axis `k` (`c = cos φ`, `s = sin φ`): with
/// `(i, j)` the next two coordinates in cyclic order, `R e_i = c e_i + s e_j`,
/// `R e_j = −s e_i + c e_j`, `R e_k = e_k`. `S` is the number type: `f64` for one body, or
/// [`F4`](super::lanes::F4) for the bodies of the lanes, which share the axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisRotation<S = f64> {
    /// The axis' coordinate index.
    pub k: usize,
    /// `cos φ`.
    pub c: S,
    /// `sin φ`.
    pub s: S,
}

impl AxisRotation {
    /// The rotation by `theta` (rad) about the signed axis `axis`.
    #[inline]
    pub fn new(axis: CoordAxis, theta: f64) -> Self {
        let (s, c) = super::trig::sin_cos(theta);
        Self::from_sin_cos(axis, s, c)
    }

    /// The rotation about the signed axis `axis` by the angle whose sine and cosine are `s`, `c`
    /// ([`trig::sin_cos_at`](super::trig::sin_cos_at) of a configuration).
    #[inline(always)]
    pub fn from_sin_cos(axis: CoordAxis, s: f64, c: f64) -> Self {
        Self {
            k: axis.k,
            c,
            s: axis.sign * s,
        }
    }

    /// `R` as a matrix.
    #[inline]
    pub fn matrix(&self) -> DMat3 {
        let (c, s) = (self.c, self.s);
        match self.k {
            0 => DMat3::from_cols(DVec3::X, DVec3::new(0.0, c, s), DVec3::new(0.0, -s, c)),
            1 => DMat3::from_cols(DVec3::new(c, 0.0, -s), DVec3::Y, DVec3::new(s, 0.0, c)),
            _ => DMat3::from_cols(DVec3::new(c, s, 0.0), DVec3::new(-s, c, 0.0), DVec3::Z),
        }
    }

    /// `R v`.
    #[inline]
    pub fn apply(&self, v: DVec3) -> DVec3 {
        match self.k {
            0 => rot::<f64, 1, 2>(self.c, self.s, v),
            1 => rot::<f64, 2, 0>(self.c, self.s, v),
            _ => rot::<f64, 0, 1>(self.c, self.s, v),
        }
    }

    /// `Rᵀ v`: the rotation by `−φ`.
    #[inline]
    pub fn apply_transpose(&self, v: DVec3) -> DVec3 {
        Self {
            s: -self.s,
            ..*self
        }
        .apply(v)
    }

    /// `A R`: columns `i` and `j` of `A` mixed.
    #[inline]
    pub fn mul_right(&self, a: &DMat3) -> DMat3 {
        match self.k {
            0 => mix_cols::<f64, 1, 2>(self.c, -self.s, a),
            1 => mix_cols::<f64, 2, 0>(self.c, -self.s, a),
            _ => mix_cols::<f64, 0, 1>(self.c, -self.s, a),
        }
    }
}

impl<S: Real> AxisRotation<S> {
    /// `R A Rᵀ`: `A Rᵀ` mixes columns `i` and `j`, then `R` rows `i` and `j`.
    #[inline(always)]
    pub fn conjugate(&self, a: &S::M3) -> S::M3 {
        match self.k {
            0 => conjugate::<S, 1, 2>(self.c, self.s, a),
            1 => conjugate::<S, 2, 0>(self.c, self.s, a),
            _ => conjugate::<S, 0, 1>(self.c, self.s, a),
        }
    }

    /// `R A Rᵀ` for a symmetric `A`, of which only the upper triangle is read: the six
    /// distinct entries (18 multiplications instead of 24), the result exactly symmetric.
    #[inline(always)]
    pub fn conjugate_symmetric(&self, a: &S::M3) -> S::M3 {
        match self.k {
            0 => conjugate_symmetric::<S, 0, 1, 2>(self.c, self.s, a),
            1 => conjugate_symmetric::<S, 1, 2, 0>(self.c, self.s, a),
            _ => conjugate_symmetric::<S, 2, 0, 1>(self.c, self.s, a),
        }
    }
}

/// Entry `(r, c)` of a symmetric `A` read from its upper triangle.
#[inline(always)]
fn upper<S: Real>(a: &S::M3, r: usize, c: usize) -> S {
    if r <= c {
        a.col(c).get(r)
    } else {
        a.col(r).get(c)
    }
}

/// `R A Rᵀ` for a symmetric `A` and the rotation `(c, s)` about axis `K` in the `I`–`J` plane,
/// with the products of [`conjugate`] for one entry of each mirrored pair.
#[inline(always)]
fn conjugate_symmetric<S: Real, const K: usize, const I: usize, const J: usize>(
    c: S,
    s: S,
    a: &S::M3,
) -> S::M3 {
    let (aii, ajj, aij) = (
        upper::<S>(a, I, I),
        upper::<S>(a, J, J),
        upper::<S>(a, I, J),
    );
    let (aki, akj, akk) = (
        upper::<S>(a, K, I),
        upper::<S>(a, K, J),
        upper::<S>(a, K, K),
    );
    // `B = A Rᵀ` (its `I`, `J` block), then `R B`.
    let (bii, bji) = (c * aii - s * aij, c * aij - s * ajj);
    let (bij, bjj) = (s * aii + c * aij, s * aij + c * ajj);
    let mut m = S::M3::ZERO;
    let mut set = |r: usize, col: usize, v: S| {
        m.col_mut(col).set(r, v);
        m.col_mut(r).set(col, v);
    };
    set(K, K, akk);
    set(K, I, c * aki - s * akj);
    set(K, J, s * aki + c * akj);
    set(I, I, c * bii - s * bji);
    set(J, J, s * bij + c * bjj);
    set(I, J, c * bij - s * bjj);
    m
}

/// `v` with components `I`, `J` rotated: `(c v_I − s v_J, s v_I + c v_J)`.
#[inline(always)]
fn rot<S: Real, const I: usize, const J: usize>(c: S, s: S, v: S::V3) -> S::V3 {
    let mut r = v;
    r.set(I, c * v.get(I) - s * v.get(J));
    r.set(J, s * v.get(I) + c * v.get(J));
    r
}

/// `A` with columns `I`, `J` mixed as `(c a_I − s a_J, s a_I + c a_J)`: `A Rᵀ` for the rotation
/// `(c, s)`, `A R` for `(c, −s)`.
#[inline(always)]
fn mix_cols<S: Real, const I: usize, const J: usize>(c: S, s: S, a: &S::M3) -> S::M3 {
    let mut m = *a;
    let (ai, aj) = (a.col(I), a.col(J));
    *m.col_mut(I) = ai * c - aj * s;
    *m.col_mut(J) = ai * s + aj * c;
    m
}

/// `R A Rᵀ` for the rotation `(c, s)` in the `I`–`J` plane.
#[inline(always)]
fn conjugate<S: Real, const I: usize, const J: usize>(c: S, s: S, a: &S::M3) -> S::M3 {
    let b = mix_cols::<S, I, J>(c, s, a);
    S::M3::from_cols(
        rot::<S, I, J>(c, s, b.col(0)),
        rot::<S, I, J>(c, s, b.col(1)),
        rot::<S, I, J>(c, s, b.col(2)),
    )
}

/// A body's joint rotation `R` (child → parent) at the current configuration, in the form
/// [`JointAxes`] allows: `E = Rᵀ` is the rotation of the body's `Xup`.
/// `S` is the number type, as in [`AxisRotation`] (the lanes share the variant and the axes).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum JointRotation<S = f64> {
    /// Only the matrix in `Xup` is known.
    #[default]
    General,
    /// `R = R₁`.
    One(AxisRotation<S>),
    /// `R = R₁ R₂`.
    Two(AxisRotation<S>, AxisRotation<S>),
}

impl<S: Real> JointRotation<S> {
    /// `Eᵀ A E` for the rotation `e` (= `Rᵀ`) of `Xup`: `R A Rᵀ`, through the factors when known.
    #[inline(always)]
    pub fn conjugate(&self, e: &S::M3, a: &S::M3) -> S::M3 {
        match self {
            JointRotation::General => e.transpose().mul_mat3(a).mul_mat3(e),
            JointRotation::One(r) => r.conjugate(a),
            JointRotation::Two(r1, r2) => r1.conjugate(&r2.conjugate(a)),
        }
    }

    /// [`JointRotation::conjugate`] of a symmetric `A` (through the factors only its upper
    /// triangle is read and the result is exactly symmetric).
    #[inline(always)]
    pub fn conjugate_symmetric(&self, e: &S::M3, a: &S::M3) -> S::M3 {
        match self {
            JointRotation::General => e.transpose().mul_mat3(a).mul_mat3(e),
            JointRotation::One(r) => r.conjugate_symmetric(a),
            JointRotation::Two(r1, r2) => r1.conjugate_symmetric(&r2.conjugate_symmetric(a)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn a() -> DMat3 {
        DMat3::from_cols(
            DVec3::new(0.3, -1.2, 0.7),
            DVec3::new(2.1, 0.4, -0.9),
            DVec3::new(-0.5, 1.6, 0.8),
        )
    }

    fn close(x: DMat3, y: DMat3) -> bool {
        (x - y).to_cols_array().iter().all(|e| e.abs() < 1e-14)
    }

    #[test]
    fn axis_rotation_matches_the_general_rotation_about_that_axis() {
        for (axis, k, sign) in [
            (DVec3::X, 0, 1.0),
            (DVec3::NEG_X, 0, -1.0),
            (DVec3::Y, 1, 1.0),
            (DVec3::NEG_Y, 1, -1.0),
            (DVec3::Z, 2, 1.0),
            (DVec3::NEG_Z, 2, -1.0),
        ] {
            let ax = CoordAxis::of(axis).unwrap();
            assert_eq!(ax, CoordAxis { k, sign });
            let theta = 0.83;
            let r = AxisRotation::new(ax, theta);
            let g = DMat3::from_axis_angle(axis, theta);
            assert!(close(r.matrix(), g), "{axis}");
            let v = DVec3::new(0.4, -1.1, 2.3);
            assert!((r.apply(v) - g * v).length() < 1e-14);
            assert!((r.apply_transpose(v) - g.transpose() * v).length() < 1e-14);
            assert!(close(r.mul_right(&a()), a() * g));
            assert!(close(r.conjugate(&a()), g * a() * g.transpose()));
            let sym = a() + a().transpose();
            let rs = r.conjugate_symmetric(&sym);
            assert!(close(rs, g * sym * g.transpose()));
            assert_eq!(rs, rs.transpose());
            let e = g.transpose();
            let r2 = AxisRotation::new(CoordAxis::of(DVec3::Y).unwrap(), -0.4);
            let g2 = DMat3::from_axis_angle(DVec3::Y, -0.4);
            let two = JointRotation::Two(r, r2).conjugate(&(g * g2).transpose(), &a());
            assert!(close(two, g * g2 * a() * (g * g2).transpose()));
            assert!(close(
                JointRotation::<f64>::General.conjugate(&e, &a()),
                g * a() * g.transpose()
            ));
        }
    }

    #[test]
    fn only_exact_coordinate_axes_qualify() {
        assert!(CoordAxis::of(DVec3::new(0.6, 0.8, 0.0)).is_none());
        assert!(CoordAxis::of(DVec3::new(1.0, 1e-17, 0.0)).is_none());
        assert!(CoordAxis::of(DVec3::ZERO).is_none());
    }
}
