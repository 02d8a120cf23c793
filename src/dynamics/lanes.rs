//! Lane algebra: the 3-vectors, 3×3 blocks and spatial quantities of [`super::spatial`] for
//! [`LANES`] bodies at once, one `f64` per body in each lane, so that one instruction of a
//! processor's vector unit (AVX2: four `f64`) advances every body.
//!
//! Every operation is the scalar one of glam and [`super::spatial`] applied lane by lane, the
//! same IEEE operations in the same order (`a·b + c` is a product then a sum; Rust never fuses
//! them), so lane `k` of a result has the bits of the scalar computation on the lane-`k`
//! inputs. The lane kernels ([`super::aba_lanes`]) rely on it and their tests check it.

use super::axis_rotation::{AxisRotation, JointRotation};
use super::spatial::{ArticulatedInertia, ForceVec, Inertia, MotionVec, SpatialTransform};
use glam::{DMat3, DVec3};
use std::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};

/// Bodies advanced together: four, the `f64` width of AVX2.
pub const LANES: usize = 4;

/// One `f64` per lane.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct F4(pub [f64; LANES]);

impl F4 {
    /// Every lane zero.
    pub const ZERO: Self = Self([0.0; LANES]);

    /// `x` in every lane.
    #[inline(always)]
    pub const fn splat(x: f64) -> Self {
        Self([x; LANES])
    }

    /// Lane `k` of `f(k)`.
    #[inline(always)]
    pub fn from_fn(f: impl FnMut(usize) -> f64) -> Self {
        Self(std::array::from_fn(f))
    }
}

macro_rules! f4_op {
    ($tr:ident, $f:ident, $op:tt, $tra:ident, $fa:ident) => {
        impl $tr for F4 {
            type Output = F4;
            #[inline(always)]
            fn $f(self, o: F4) -> F4 {
                let (a, b) = (self.0, o.0);
                F4([a[0] $op b[0], a[1] $op b[1], a[2] $op b[2], a[3] $op b[3]])
            }
        }
        impl $tr<f64> for F4 {
            type Output = F4;
            #[inline(always)]
            fn $f(self, o: f64) -> F4 {
                self $op F4::splat(o)
            }
        }
        impl $tra for F4 {
            #[inline(always)]
            fn $fa(&mut self, o: F4) {
                *self = *self $op o;
            }
        }
    };
}
f4_op!(Add, add, +, AddAssign, add_assign);
f4_op!(Sub, sub, -, SubAssign, sub_assign);
f4_op!(Mul, mul, *, MulAssign, mul_assign);
f4_op!(Div, div, /, DivAssign, div_assign);

impl Neg for F4 {
    type Output = F4;
    #[inline(always)]
    fn neg(self) -> F4 {
        let a = self.0;
        F4([-a[0], -a[1], -a[2], -a[3]])
    }
}

/// A 3-vector per lane (glam's `DVec3`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct V3 {
    /// x of every lane.
    pub x: F4,
    /// y of every lane.
    pub y: F4,
    /// z of every lane.
    pub z: F4,
}

impl V3 {
    /// Zero in every lane.
    pub const ZERO: Self = Self::splat(DVec3::ZERO);

    /// From components.
    #[inline(always)]
    pub const fn new(x: F4, y: F4, z: F4) -> Self {
        Self { x, y, z }
    }

    /// `v` in every lane.
    #[inline(always)]
    pub const fn splat(v: DVec3) -> Self {
        Self::new(F4::splat(v.x), F4::splat(v.y), F4::splat(v.z))
    }

    /// Lane `k` is `f(k)`.
    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> DVec3) -> Self {
        let v: [DVec3; LANES] = std::array::from_fn(&mut f);
        Self::new(
            F4::from_fn(|k| v[k].x),
            F4::from_fn(|k| v[k].y),
            F4::from_fn(|k| v[k].z),
        )
    }

    /// Lane `k`.
    #[inline(always)]
    pub fn lane(&self, k: usize) -> DVec3 {
        DVec3::new(self.x.0[k], self.y.0[k], self.z.0[k])
    }

    /// Component `i` (0 = x).
    #[inline(always)]
    pub fn get(&self, i: usize) -> F4 {
        match i {
            0 => self.x,
            1 => self.y,
            _ => self.z,
        }
    }

    /// Sets component `i` (0 = x).
    #[inline(always)]
    pub fn set(&mut self, i: usize, v: F4) {
        match i {
            0 => self.x = v,
            1 => self.y = v,
            _ => self.z = v,
        }
    }

    /// glam's `dot`: `(x x' + y y') + z z'`.
    #[inline(always)]
    pub fn dot(self, o: Self) -> F4 {
        (self.x * o.x) + (self.y * o.y) + (self.z * o.z)
    }

    /// glam's `cross`.
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        Self::new(
            self.y * o.z - o.y * self.z,
            self.z * o.x - o.z * self.x,
            self.x * o.y - o.x * self.y,
        )
    }
}

macro_rules! v3_op {
    ($tr:ident, $f:ident, $op:tt, $tra:ident, $fa:ident) => {
        impl $tr for V3 {
            type Output = V3;
            #[inline(always)]
            fn $f(self, o: V3) -> V3 {
                V3::new(self.x $op o.x, self.y $op o.y, self.z $op o.z)
            }
        }
        impl $tra for V3 {
            #[inline(always)]
            fn $fa(&mut self, o: V3) {
                *self = *self $op o;
            }
        }
    };
}
v3_op!(Add, add, +, AddAssign, add_assign);
v3_op!(Sub, sub, -, SubAssign, sub_assign);

impl Mul<F4> for V3 {
    type Output = V3;
    #[inline(always)]
    fn mul(self, s: F4) -> V3 {
        V3::new(self.x * s, self.y * s, self.z * s)
    }
}

impl Mul<f64> for V3 {
    type Output = V3;
    #[inline(always)]
    fn mul(self, s: f64) -> V3 {
        self * F4::splat(s)
    }
}

impl Neg for V3 {
    type Output = V3;
    #[inline(always)]
    fn neg(self) -> V3 {
        V3::new(-self.x, -self.y, -self.z)
    }
}

/// A 3×3 matrix per lane, by columns (glam's `DMat3`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct M3 {
    /// First column.
    pub x_axis: V3,
    /// Second column.
    pub y_axis: V3,
    /// Third column.
    pub z_axis: V3,
}

impl M3 {
    /// Zero in every lane.
    pub const ZERO: Self = Self::splat(&DMat3::ZERO);

    /// The identity in every lane.
    pub const IDENTITY: Self = Self::splat(&DMat3::IDENTITY);

    /// From columns.
    #[inline(always)]
    pub const fn from_cols(x_axis: V3, y_axis: V3, z_axis: V3) -> Self {
        Self {
            x_axis,
            y_axis,
            z_axis,
        }
    }

    /// `m` in every lane.
    #[inline(always)]
    pub const fn splat(m: &DMat3) -> Self {
        Self::from_cols(
            V3::splat(m.x_axis),
            V3::splat(m.y_axis),
            V3::splat(m.z_axis),
        )
    }

    /// Lane `k` is `f(k)`.
    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> DMat3) -> Self {
        let m: [DMat3; LANES] = std::array::from_fn(&mut f);
        Self::from_cols(
            V3::from_fn(|k| m[k].x_axis),
            V3::from_fn(|k| m[k].y_axis),
            V3::from_fn(|k| m[k].z_axis),
        )
    }

    /// Lane `k`.
    #[inline(always)]
    pub fn lane(&self, k: usize) -> DMat3 {
        DMat3::from_cols(
            self.x_axis.lane(k),
            self.y_axis.lane(k),
            self.z_axis.lane(k),
        )
    }

    /// Column `j`.
    #[inline(always)]
    pub fn col(&self, j: usize) -> V3 {
        match j {
            0 => self.x_axis,
            1 => self.y_axis,
            _ => self.z_axis,
        }
    }

    /// Column `j`, mutable.
    #[inline(always)]
    pub fn col_mut(&mut self, j: usize) -> &mut V3 {
        match j {
            0 => &mut self.x_axis,
            1 => &mut self.y_axis,
            _ => &mut self.z_axis,
        }
    }

    /// Row `i`.
    #[inline(always)]
    pub fn row(&self, i: usize) -> V3 {
        V3::new(self.x_axis.get(i), self.y_axis.get(i), self.z_axis.get(i))
    }

    /// The transpose.
    #[inline(always)]
    pub fn transpose(&self) -> Self {
        Self::from_cols(self.row(0), self.row(1), self.row(2))
    }

    /// glam's `mul_vec3`: `(x_axis v.x + y_axis v.y) + z_axis v.z`.
    #[inline(always)]
    pub fn mul_vec3(&self, v: V3) -> V3 {
        let mut r = self.x_axis * v.x;
        r += self.y_axis * v.y;
        r + self.z_axis * v.z
    }

    /// glam's `mul_mat3`: each column of `o` through [`M3::mul_vec3`].
    #[inline(always)]
    pub fn mul_mat3(&self, o: &Self) -> Self {
        Self::from_cols(
            self.mul_vec3(o.x_axis),
            self.mul_vec3(o.y_axis),
            self.mul_vec3(o.z_axis),
        )
    }

    /// `Aᵀ x` as dot products with the columns ([`super::spatial::transpose_mul`]).
    #[inline(always)]
    pub fn transpose_mul(&self, x: V3) -> V3 {
        V3::new(self.x_axis.dot(x), self.y_axis.dot(x), self.z_axis.dot(x))
    }

    /// glam's `inverse` (columns' cross products over the determinant, transposed).
    #[inline(always)]
    pub fn inverse(&self) -> Self {
        let tmp0 = self.y_axis.cross(self.z_axis);
        let tmp1 = self.z_axis.cross(self.x_axis);
        let tmp2 = self.x_axis.cross(self.y_axis);
        let inv_det = F4::splat(1.0) / self.x_axis.dot(tmp0);
        Self::from_cols(tmp0 * inv_det, tmp1 * inv_det, tmp2 * inv_det).transpose()
    }
}

impl Add for M3 {
    type Output = M3;
    #[inline(always)]
    fn add(self, o: M3) -> M3 {
        M3::from_cols(
            self.x_axis + o.x_axis,
            self.y_axis + o.y_axis,
            self.z_axis + o.z_axis,
        )
    }
}

impl Sub for M3 {
    type Output = M3;
    #[inline(always)]
    fn sub(self, o: M3) -> M3 {
        M3::from_cols(
            self.x_axis - o.x_axis,
            self.y_axis - o.y_axis,
            self.z_axis - o.z_axis,
        )
    }
}

impl AddAssign for M3 {
    #[inline(always)]
    fn add_assign(&mut self, o: M3) {
        *self = *self + o;
    }
}

impl SubAssign for M3 {
    #[inline(always)]
    fn sub_assign(&mut self, o: M3) {
        *self = *self - o;
    }
}

/// `outer(a, b) = a bᵀ` by columns `a b_j` ([`super::spatial::outer`]).
#[inline(always)]
pub fn outer(a: V3, b: V3) -> M3 {
    M3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// A motion vector `[ω; v]` per lane ([`MotionVec`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion4 {
    /// Angular part.
    pub ang: V3,
    /// Linear part.
    pub lin: V3,
}

/// A force vector `[n; f]` per lane ([`ForceVec`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Force4 {
    /// Moment.
    pub ang: V3,
    /// Force.
    pub lin: V3,
}

macro_rules! spatial_ops {
    ($t:ident, $s:ident) => {
        impl $t {
            /// Zero in every lane.
            pub const ZERO: Self = Self {
                ang: V3::ZERO,
                lin: V3::ZERO,
            };

            /// From parts.
            #[inline(always)]
            pub const fn new(ang: V3, lin: V3) -> Self {
                Self { ang, lin }
            }

            /// Lane `k` is `f(k)`.
            #[inline(always)]
            pub fn from_fn(mut f: impl FnMut(usize) -> $s) -> Self {
                let v: [$s; LANES] = std::array::from_fn(&mut f);
                Self::new(V3::from_fn(|k| v[k].ang), V3::from_fn(|k| v[k].lin))
            }

            /// Lane `k`.
            #[inline(always)]
            pub fn lane(&self, k: usize) -> $s {
                $s::new(self.ang.lane(k), self.lin.lane(k))
            }
        }
        impl Add for $t {
            type Output = $t;
            #[inline(always)]
            fn add(self, o: $t) -> $t {
                $t::new(self.ang + o.ang, self.lin + o.lin)
            }
        }
        impl Sub for $t {
            type Output = $t;
            #[inline(always)]
            fn sub(self, o: $t) -> $t {
                $t::new(self.ang - o.ang, self.lin - o.lin)
            }
        }
        impl AddAssign for $t {
            #[inline(always)]
            fn add_assign(&mut self, o: $t) {
                *self = *self + o;
            }
        }
        impl SubAssign for $t {
            #[inline(always)]
            fn sub_assign(&mut self, o: $t) {
                *self = *self - o;
            }
        }
        impl Mul<F4> for $t {
            type Output = $t;
            #[inline(always)]
            fn mul(self, s: F4) -> $t {
                $t::new(self.ang * s, self.lin * s)
            }
        }
    };
}
spatial_ops!(Motion4, MotionVec);
spatial_ops!(Force4, ForceVec);

impl Motion4 {
    /// `v ×* f` ([`MotionVec::cross_force`]).
    #[inline(always)]
    pub fn cross_force(self, f: Force4) -> Force4 {
        Force4::new(
            self.ang.cross(f.ang) + self.lin.cross(f.lin),
            self.ang.cross(f.lin),
        )
    }

    /// `m · f` ([`MotionVec::dot`]).
    #[inline(always)]
    pub fn dot(self, f: Force4) -> F4 {
        self.ang.dot(f.ang) + self.lin.dot(f.lin)
    }
}

/// A spatial transform per lane ([`SpatialTransform`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform4 {
    /// `E`.
    pub rot: M3,
    /// `r`.
    pub trans: V3,
}

impl Transform4 {
    /// Lane `k` is `x[k]`.
    #[inline(always)]
    pub fn gather(x: [&SpatialTransform; LANES]) -> Self {
        Self {
            rot: M3::from_fn(|k| x[k].rot),
            trans: V3::from_fn(|k| x[k].trans),
        }
    }

    /// `X m` ([`SpatialTransform::apply_motion`]).
    #[inline(always)]
    pub fn apply_motion(&self, m: Motion4) -> Motion4 {
        Motion4::new(
            self.rot.mul_vec3(m.ang),
            self.rot.mul_vec3(m.lin - self.trans.cross(m.ang)),
        )
    }

    /// `Xᵀ f` ([`SpatialTransform::inv_apply_force`]).
    #[inline(always)]
    pub fn inv_apply_force(&self, f: Force4) -> Force4 {
        let rt = self.rot.transpose();
        let lin = rt.mul_vec3(f.lin);
        Force4::new(rt.mul_vec3(f.ang) + self.trans.cross(lin), lin)
    }
}

/// `I v` for one rigid inertia shared by every lane ([`Inertia::apply`]).
#[inline(always)]
pub fn rigid_apply(inertia: &Inertia, v: Motion4) -> Force4 {
    let com = V3::splat(inertia.com);
    let h = (v.lin - com.cross(v.ang)) * inertia.mass;
    Force4::new(
        M3::splat(&inertia.inertia_com).mul_vec3(v.ang) + com.cross(h),
        h,
    )
}

/// An articulated inertia `[M H; Hᵀ L]` per lane ([`ArticulatedInertia`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inertia4 {
    /// `M`.
    pub m: M3,
    /// `H`.
    pub h: M3,
    /// `L`.
    pub l: M3,
}

impl Inertia4 {
    /// `a` in every lane.
    #[inline(always)]
    pub fn splat(a: &ArticulatedInertia) -> Self {
        Self {
            m: M3::splat(&a.m),
            h: M3::splat(&a.h),
            l: M3::splat(&a.l),
        }
    }

    /// Lane `k`.
    #[inline(always)]
    pub fn lane(&self, k: usize) -> ArticulatedInertia {
        ArticulatedInertia {
            m: self.m.lane(k),
            h: self.h.lane(k),
            l: self.l.lane(k),
        }
    }

    /// `I v` ([`ArticulatedInertia::apply`]).
    #[inline(always)]
    pub fn apply(&self, v: Motion4) -> Force4 {
        Force4::new(
            self.m.mul_vec3(v.ang) + self.h.mul_vec3(v.lin),
            self.h.transpose_mul(v.ang) + self.l.mul_vec3(v.lin),
        )
    }

    /// `I [w; 0]` ([`ArticulatedInertia::apply_angular`]).
    #[inline(always)]
    pub fn apply_angular(&self, w: V3) -> Force4 {
        Force4::new(self.m.mul_vec3(w), self.h.transpose_mul(w))
    }

    /// `I −= Σ_j w_j u_jᵀ` ([`ArticulatedInertia::sub_products`]).
    #[inline(always)]
    pub fn sub_products<const N: usize>(&mut self, w: &[Force4; N], u: &[Force4; N]) {
        for j in 0..N {
            self.h -= outer(w[j].ang, u[j].lin);
        }
        let wa: [V3; N] = std::array::from_fn(|j| w[j].ang);
        let ua: [V3; N] = std::array::from_fn(|j| u[j].ang);
        let wl: [V3; N] = std::array::from_fn(|j| w[j].lin);
        let ul: [V3; N] = std::array::from_fn(|j| u[j].lin);
        sub_symmetric(&mut self.m, &wa, &ua);
        sub_symmetric(&mut self.l, &wl, &ul);
    }

    /// `I −= u d⁻¹ uᵀ` ([`ArticulatedInertia::sub_outer`]).
    #[inline(always)]
    pub fn sub_outer(&mut self, u: Force4, inv_d: F4) {
        self.sub_products(&[u * inv_d], &[u]);
    }

    /// `I −= U D⁻¹ Uᵀ` for `N` columns ([`ArticulatedInertia::sub_u_dinv_ut`]).
    #[inline(always)]
    pub fn sub_u_dinv_ut<const N: usize>(&mut self, u: &[Force4; N], dinv: &M3) {
        // Loops, not `array::from_fn`: its closure left out of line would run without AVX2.
        let mut w = [Force4::ZERO; N];
        for (j, wj) in w.iter_mut().enumerate() {
            for (k, uk) in u.iter().enumerate() {
                *wj += *uk * dinv.col(j).get(k);
            }
        }
        self.sub_products(&w, u);
    }

    /// `Xᵀ I X` with the joint's rotation structure
    /// ([`ArticulatedInertia::transform_to_parent_with`]).
    #[inline(always)]
    pub fn transform_to_parent_with(&self, x: &Transform4, rotation: &Rotation4) -> Self {
        let e = &x.rot;
        let m1 = rotation.conjugate_symmetric(e, &self.m);
        let h1 = rotation.conjugate(e, &self.h);
        let l1 = rotation.conjugate_symmetric(e, &self.l);
        let r = x.trans;
        let rl = cross_cols(r, l1);
        let rh = cross_cols(r, h1.transpose());
        let rlr = |row: V3, j: usize| match j {
            0 => row.y * r.z - row.z * r.y,
            1 => row.z * r.x - row.x * r.z,
            _ => row.x * r.y - row.y * r.x,
        };
        let rows = [rl.row(0), rl.row(1), rl.row(2)];
        let m = symmetric(|i, j| {
            m1.col(j).get(i) + rh.col(j).get(i) + rh.col(i).get(j) - rlr(rows[i], j)
        });
        Self {
            m,
            h: h1 + rl,
            l: l1,
        }
    }

    /// `I⁻¹ f` by the Schur complement of `L` ([`ArticulatedInertia::solve`]).
    #[inline(always)]
    pub fn solve(&self, f: Force4) -> Motion4 {
        let linv = self.l.inverse();
        let hl = self.h.mul_mat3(&linv);
        let schur = self.m - hl.mul_mat3(&self.h.transpose());
        let ang = schur.inverse().mul_vec3(f.ang - hl.mul_vec3(f.lin));
        let lin = linv.mul_vec3(f.lin - self.h.transpose().mul_vec3(ang));
        Motion4::new(ang, lin)
    }
}

impl AddAssign for Inertia4 {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        self.m += o.m;
        self.h += o.h;
        self.l += o.l;
    }
}

/// `A − Σ_j x_j y_jᵀ` on the upper entries, mirrored (the scalar `sub_symmetric`).
#[inline(always)]
fn sub_symmetric<const N: usize>(a: &mut M3, x: &[V3; N], y: &[V3; N]) {
    *a = symmetric(|r, c| {
        let mut e = a.col(c).get(r);
        for j in 0..N {
            e -= x[j].get(r) * y[j].get(c);
        }
        e
    });
}

/// `[r]× A`, column by column (a function, not a closure: inlined into the AVX2 step, where
/// a closure left out of line ran without AVX2).
#[inline(always)]
fn cross_cols(r: V3, a: M3) -> M3 {
    M3::from_cols(r.cross(a.x_axis), r.cross(a.y_axis), r.cross(a.z_axis))
}

/// The symmetric matrix of the upper entries `entry(r, c)`, `r ≤ c`.
#[inline(always)]
fn symmetric(entry: impl Fn(usize, usize) -> F4) -> M3 {
    let (m00, m11, m22) = (entry(0, 0), entry(1, 1), entry(2, 2));
    let (m01, m02, m12) = (entry(0, 1), entry(0, 2), entry(1, 2));
    M3::from_cols(
        V3::new(m00, m01, m02),
        V3::new(m01, m11, m12),
        V3::new(m02, m12, m22),
    )
}

/// A joint's rotation per lane ([`JointRotation`] of [`F4`]; the variant and the axes are the
/// model's, the same in every lane).
pub type Rotation4 = JointRotation<F4>;

impl JointRotation<F4> {
    /// Lane `k` is `r[k]`; `None` unless every lane has the variant and axes of lane 0.
    #[inline(always)]
    pub fn gather(r: [&JointRotation; LANES]) -> Option<Self> {
        let same = |a: &AxisRotation, b: &AxisRotation| a.k == b.k;
        Some(match r[0] {
            JointRotation::General => {
                if !r.iter().all(|x| matches!(x, JointRotation::General)) {
                    return None;
                }
                JointRotation::General
            }
            JointRotation::One(a0) => {
                let mut lanes = [a0; LANES];
                for (l, x) in r.iter().enumerate() {
                    match x {
                        JointRotation::One(a) if same(a, a0) => lanes[l] = a,
                        _ => return None,
                    }
                }
                JointRotation::One(gather_axis(lanes))
            }
            JointRotation::Two(a0, b0) => {
                let mut firsts = [a0; LANES];
                let mut seconds = [b0; LANES];
                for (l, x) in r.iter().enumerate() {
                    match x {
                        JointRotation::Two(a, b) if same(a, a0) && same(b, b0) => {
                            firsts[l] = a;
                            seconds[l] = b;
                        }
                        _ => return None,
                    }
                }
                JointRotation::Two(gather_axis(firsts), gather_axis(seconds))
            }
        })
    }
}

/// The lanes' rotations about one axis (that of lane 0).
#[inline(always)]
fn gather_axis(r: [&AxisRotation; LANES]) -> AxisRotation<F4> {
    AxisRotation {
        k: r[0].k,
        c: F4::from_fn(|l| r[l].c),
        s: F4::from_fn(|l| r[l].s),
    }
}
