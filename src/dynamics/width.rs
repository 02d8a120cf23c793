//! The two widths the articulated-body algorithm runs at, each implementing the number family of
//! [`super::real`]: one body in `f64` (glam's `DVec3`, `DMat3` and [`super::spatial`]) and
//! [`LANES`] bodies in [`F4`] (the lane types of [`super::lanes`]). The ABA's passes
//! ([`super::aba`]) are written once over [`Real`]; each trait method is the width's own operation (the same IEEE operations in the same
//! order, [`super::lanes`]), so each width keeps the bits it has alone.

use super::axis_rotation::JointRotation;
use super::lanes::{F4, Force4, Inertia4, LANES, M3, Motion4, Rotation4, Transform4, V3};
use super::real::{
    ColumnsOps, ForceOps, InertiaOps, Mat3Ops, MotionOps, Real, TransformOps, Vec3Ops,
};
use super::spatial::{ArticulatedInertia, ForceVec, MotionVec, SpatialTransform};
use glam::{DMat3, DVec3};

/// The operations of one width whose types carry them as inherent methods of the same names:
/// each trait method is the type's own.
macro_rules! forward_ops {
    ($s:ty, $v3:ty, $m3:ty, $motion:ty, $force:ty, $inertia:ty, $transform:ty, $rotation:ty) => {
        impl Mat3Ops<$s> for $m3 {
            const ZERO: Self = <$m3>::ZERO;
            const IDENTITY: Self = <$m3>::IDENTITY;
            #[inline(always)]
            fn from_cols(x: $v3, y: $v3, z: $v3) -> Self {
                <$m3>::from_cols(x, y, z)
            }
            #[inline(always)]
            fn col(&self, j: usize) -> $v3 {
                <$m3>::col(self, j)
            }
            #[inline(always)]
            fn col_mut(&mut self, j: usize) -> &mut $v3 {
                <$m3>::col_mut(self, j)
            }
            #[inline(always)]
            fn row(&self, i: usize) -> $v3 {
                <$m3>::row(self, i)
            }
            #[inline(always)]
            fn inverse(&self) -> Self {
                <$m3>::inverse(self)
            }
            #[inline(always)]
            fn mul_vec3(&self, v: $v3) -> $v3 {
                <$m3>::mul_vec3(self, v)
            }
            #[inline(always)]
            fn mul_mat3(&self, b: &Self) -> Self {
                <$m3>::mul_mat3(self, b)
            }
            #[inline(always)]
            fn transpose(&self) -> Self {
                <$m3>::transpose(self)
            }
        }

        impl MotionOps<$s> for $motion {
            #[inline(always)]
            fn ang(&self) -> $v3 {
                self.ang
            }
            #[inline(always)]
            fn lin(&self) -> $v3 {
                self.lin
            }
            #[inline(always)]
            fn ang_mut(&mut self) -> &mut $v3 {
                &mut self.ang
            }
            #[inline(always)]
            fn dot(self, f: $force) -> $s {
                <$motion>::dot(self, f)
            }
        }

        impl ForceOps<$s> for $force {
            const ZERO: Self = <$force>::ZERO;
            #[inline(always)]
            fn new(ang: $v3, lin: $v3) -> Self {
                <$force>::new(ang, lin)
            }
            #[inline(always)]
            fn ang(&self) -> $v3 {
                self.ang
            }
        }

        impl InertiaOps<$s> for $inertia {
            #[inline(always)]
            fn m(&self) -> &$m3 {
                &self.m
            }
            #[inline(always)]
            fn h(&self) -> &$m3 {
                &self.h
            }
            #[inline(always)]
            fn apply(&self, v: $motion) -> $force {
                <$inertia>::apply(self, v)
            }
            #[inline(always)]
            fn apply_angular(&self, w: $v3) -> $force {
                <$inertia>::apply_angular(self, w)
            }
            #[inline(always)]
            fn sub_outer(&mut self, u: $force, inv_d: $s) {
                <$inertia>::sub_outer(self, u, inv_d)
            }
            #[inline(always)]
            fn sub_products<const N: usize>(&mut self, w: &[$force; N], u: &[$force; N]) {
                <$inertia>::sub_products(self, w, u)
            }
            #[inline(always)]
            fn sub_u_dinv_ut<const N: usize>(&mut self, u: &[$force; N], dinv: &$m3) {
                <$inertia>::sub_u_dinv_ut(self, u, dinv)
            }
            #[inline(always)]
            fn transform_to_parent_with(&self, x: &$transform, rotation: &$rotation) -> Self {
                <$inertia>::transform_to_parent_with(self, x, rotation)
            }
            #[inline(always)]
            fn solve(&self, f: $force) -> $motion {
                <$inertia>::solve(self, f)
            }
        }

        impl TransformOps<$s> for $transform {
            #[inline(always)]
            fn apply_motion(&self, m: $motion) -> $motion {
                <$transform>::apply_motion(self, m)
            }
            #[inline(always)]
            fn inv_apply_force(&self, f: $force) -> $force {
                <$transform>::inv_apply_force(self, f)
            }
        }
    };
}

forward_ops!(
    f64,
    DVec3,
    DMat3,
    MotionVec,
    ForceVec,
    ArticulatedInertia,
    SpatialTransform,
    JointRotation
);
forward_ops!(F4, V3, M3, Motion4, Force4, Inertia4, Transform4, Rotation4);

impl Real for f64 {
    type V3 = DVec3;
    type M3 = DMat3;
    type Motion = MotionVec;
    type Force = ForceVec;
    type Inertia = ArticulatedInertia;
    type Transform = SpatialTransform;
    type Rotation = JointRotation;
    type Columns = [MotionVec; 3];
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
}

impl Vec3Ops<f64> for DVec3 {
    const ZERO: Self = DVec3::ZERO;
    #[inline(always)]
    fn new(x: f64, y: f64, z: f64) -> Self {
        DVec3::new(x, y, z)
    }
    #[inline(always)]
    fn get(&self, k: usize) -> f64 {
        self[k]
    }
    #[inline(always)]
    fn set(&mut self, k: usize, x: f64) {
        self[k] = x;
    }
    #[inline(always)]
    fn dot(self, o: Self) -> f64 {
        DVec3::dot(self, o)
    }
}

impl ColumnsOps<f64> for [MotionVec; 3] {
    #[inline(always)]
    fn axis(&self, k: usize) -> DVec3 {
        self[k].ang
    }
}

impl Real for F4 {
    type V3 = V3;
    type M3 = M3;
    type Motion = Motion4;
    type Force = Force4;
    type Inertia = Inertia4;
    type Transform = Transform4;
    type Rotation = Rotation4;
    type Columns = [V3; 3];
    #[inline(always)]
    fn splat(x: f64) -> Self {
        F4::splat(x)
    }
}

impl Vec3Ops<F4> for V3 {
    const ZERO: Self = V3::ZERO;
    #[inline(always)]
    fn new(x: F4, y: F4, z: F4) -> Self {
        V3::new(x, y, z)
    }
    #[inline(always)]
    fn get(&self, k: usize) -> F4 {
        V3::get(self, k)
    }
    #[inline(always)]
    fn set(&mut self, k: usize, x: F4) {
        V3::set(self, k, x)
    }
    #[inline(always)]
    fn dot(self, o: Self) -> F4 {
        V3::dot(self, o)
    }
}

impl ColumnsOps<F4> for [V3; 3] {
    #[inline(always)]
    fn axis(&self, k: usize) -> V3 {
        self[k]
    }
}

/// The joint forces and armature the ABA reads, by velocity DOF, at width `S`.
pub trait JointForces<S> {
    /// `τ` of DOF `dof`.
    fn tau(&self, dof: usize) -> S;
    /// The armature of DOF `dof` (0 without armature).
    fn armature(&self, dof: usize) -> S;
}

/// One body's joint forces (nv) and optional armature (nv).
impl JointForces<f64> for (&[f64], Option<&[f64]>) {
    #[inline(always)]
    fn tau(&self, dof: usize) -> f64 {
        self.0[dof]
    }
    #[inline(always)]
    fn armature(&self, dof: usize) -> f64 {
        self.1.map_or(0.0, |a| a[dof])
    }
}

/// Each lane's joint forces and optional armature.
impl JointForces<F4> for (&[&[f64]; LANES], &[Option<&[f64]>; LANES]) {
    #[inline(always)]
    fn tau(&self, dof: usize) -> F4 {
        F4::from_fn(|l| self.0[l][dof])
    }
    #[inline(always)]
    fn armature(&self, dof: usize) -> F4 {
        F4::from_fn(|l| self.1[l].map_or(0.0, |a| a[dof]))
    }
}

/// Where the ABA writes `q̈`, by velocity DOF, at width `S`.
pub trait Accelerations<S> {
    /// Sets `q̈` of DOF `dof`.
    fn put(&mut self, dof: usize, x: S);
}

impl Accelerations<f64> for [f64] {
    #[inline(always)]
    fn put(&mut self, dof: usize, x: f64) {
        self[dof] = x;
    }
}

impl Accelerations<F4> for [&mut [f64]; LANES] {
    #[inline(always)]
    fn put(&mut self, dof: usize, x: F4) {
        for (q, x) in self.iter_mut().zip(x.0) {
            q[dof] = x;
        }
    }
}
