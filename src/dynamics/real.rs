//! The numbers the articulated-body algorithm is written over ([`Real`]) and the operations
//! of their 3-vectors, 3×3 blocks and spatial quantities: traits only, so that the joint
//! rotations ([`super::axis_rotation`]) and the ABA ([`super::aba`]) build on them without
//! depending on the two widths that implement them ([`super::width`]: `f64` and the lanes'
//! `F4`).

use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

/// A number of the ABA: `f64` (one body) or `F4` (one `f64` per lane), with the 3-vectors,
/// 3×3 blocks and spatial quantities of that width.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
{
    /// A 3-vector.
    type V3: Vec3Ops<Self>;
    /// A 3×3 matrix, by columns.
    type M3: Mat3Ops<Self>;
    /// A motion vector `[ω; v]`.
    type Motion: MotionOps<Self>;
    /// A force vector `[n; f]`.
    type Force: ForceOps<Self>;
    /// An articulated inertia `[M H; Hᵀ L]`.
    type Inertia: InertiaOps<Self>;
    /// A Plücker transform `rot(E) xlt(r)`.
    type Transform: TransformOps<Self>;
    /// A joint rotation in the form its axes allow (`JointRotation`).
    type Rotation;
    /// A joint's motion-subspace columns (all rotational: their angular parts).
    type Columns: ColumnsOps<Self>;
    /// `x` in every lane.
    fn splat(x: f64) -> Self;
}

/// The operations of a 3-vector of numbers `S`.
pub trait Vec3Ops<S>:
    Copy + Add<Output = Self> + Sub<Output = Self> + AddAssign + Mul<S, Output = Self>
{
    /// Zero.
    const ZERO: Self;
    /// From components.
    fn new(x: S, y: S, z: S) -> Self;
    /// Component `k` (0 = x).
    fn get(&self, k: usize) -> S;
    /// Sets component `k`.
    fn set(&mut self, k: usize, x: S);
    /// `(x x' + y y') + z z'`.
    fn dot(self, o: Self) -> S;
}

/// The operations of a 3×3 matrix of numbers `S`.
pub trait Mat3Ops<S: Real>: Copy {
    /// Zero.
    const ZERO: Self;
    /// The identity.
    const IDENTITY: Self;
    /// From columns.
    fn from_cols(x: S::V3, y: S::V3, z: S::V3) -> Self;
    /// Column `j`.
    fn col(&self, j: usize) -> S::V3;
    /// Column `j`, mutable.
    fn col_mut(&mut self, j: usize) -> &mut S::V3;
    /// Row `i`.
    fn row(&self, i: usize) -> S::V3;
    /// The inverse (glam's: cross products of the columns over the determinant).
    fn inverse(&self) -> Self;
    /// `A v`.
    fn mul_vec3(&self, v: S::V3) -> S::V3;
    /// `A B` (glam's: each column of `B` through [`Mat3Ops::mul_vec3`]).
    fn mul_mat3(&self, b: &Self) -> Self;
    /// `Aᵀ`.
    fn transpose(&self) -> Self;
}

/// The operations of a motion vector.
pub trait MotionOps<S: Real>: Copy + Add<Output = Self> + Sub<Output = Self> {
    /// The angular part.
    fn ang(&self) -> S::V3;
    /// The linear part.
    fn lin(&self) -> S::V3;
    /// The angular part, mutable.
    fn ang_mut(&mut self) -> &mut S::V3;
    /// `m · f`.
    fn dot(self, f: S::Force) -> S;
}

/// The operations of a force vector.
pub trait ForceOps<S: Real>:
    Copy + Add<Output = Self> + Sub<Output = Self> + AddAssign + Mul<S, Output = Self>
{
    /// Zero.
    const ZERO: Self;
    /// `[ang; lin]`.
    fn new(ang: S::V3, lin: S::V3) -> Self;
    /// The moment.
    fn ang(&self) -> S::V3;
}

/// The operations of an articulated inertia (those of [`ArticulatedInertia`]).
pub trait InertiaOps<S: Real>: Copy + AddAssign {
    /// The angular block `M`.
    fn m(&self) -> &S::M3;
    /// The coupling block `H`.
    fn h(&self) -> &S::M3;
    /// `I v`.
    fn apply(&self, v: S::Motion) -> S::Force;
    /// `I [w; 0]`.
    fn apply_angular(&self, w: S::V3) -> S::Force;
    /// `I −= u d⁻¹ uᵀ`.
    fn sub_outer(&mut self, u: S::Force, inv_d: S);
    /// `I −= Σ_j w_j u_jᵀ` (a symmetric sum).
    fn sub_products<const N: usize>(&mut self, w: &[S::Force; N], u: &[S::Force; N]);
    /// `I −= U D⁻¹ Uᵀ` for `N` columns `U`.
    fn sub_u_dinv_ut<const N: usize>(&mut self, u: &[S::Force; N], dinv: &S::M3);
    /// `Xᵀ I X` with the joint's rotation in factored form.
    fn transform_to_parent_with(&self, x: &S::Transform, rotation: &S::Rotation) -> Self;
    /// `I⁻¹ f`.
    fn solve(&self, f: S::Force) -> S::Motion;
}

/// The operations of a Plücker transform.
pub trait TransformOps<S: Real> {
    /// `X m`.
    fn apply_motion(&self, m: S::Motion) -> S::Motion;
    /// `Xᵀ f`.
    fn inv_apply_force(&self, f: S::Force) -> S::Force;
}

/// A joint's rotational motion-subspace columns.
pub trait ColumnsOps<S: Real> {
    /// The axis (angular part) of column `k`.
    fn axis(&self, k: usize) -> S::V3;
}
