//! The immutable kinematic tree (Featherstone's `model`: `parent`, `jtype`, `Xtree`, `I`),
//! apart from the scratch workspace [`Data`](super::data::Data) as in Pinocchio.
//!
//! Bodies are numbered depth-first, every parent before its children; body `i` is moved by joint
//! `i`. Configuration `q` (size `nq`) and velocity `v` (size `nv`) differ in size because ball
//! and free joints carry unit quaternions (4 numbers) for 3 rotational velocities.

use super::axis_rotation::{CoordAxis, JointAxes};
use super::data::Data;
use super::joint::JointType;
use super::spatial::ForceVec;
use super::spatial::{ArticulatedInertia, Inertia, SpatialTransform};
use glam::DVec3;
use thiserror::Error;

/// A joint-space inertia matrix that is not positive definite (a degenerate model).
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
#[error("joint-space inertia matrix is not positive definite at pivot {pivot} (value {value})")]
pub struct NotPositiveDefinite {
    /// Index of the failing pivot.
    pub pivot: usize,
    /// The pivot value found.
    pub value: f64,
}

/// An invalid model description (which body and what is wrong), or arguments that do not fit
/// the model.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ModelError {
    /// A body's parent index is not an earlier body.
    #[error(
        "body {body} ('{name}'): parent {parent} is not an earlier body (parents must precede children)"
    )]
    BadParent {
        /// Body index.
        body: usize,
        /// Body name.
        name: String,
        /// The offending parent index.
        parent: usize,
    },
    /// A floating base anywhere but at the root.
    #[error("body {body} ('{name}'): a free joint is only allowed on the root body 0")]
    FreeNotRoot {
        /// Body index.
        body: usize,
        /// Body name.
        name: String,
    },
    /// A joint axis is not a unit vector, or a ball's axes are not orthonormal.
    #[error("body {body} ('{name}'): joint axes must be unit length (and orthonormal for a ball)")]
    BadAxis {
        /// Body index.
        body: usize,
        /// Body name.
        name: String,
    },
    /// A non-positive or non-finite mass or an inertia that is not positive definite.
    #[error("body {body} ('{name}'): mass {mass} kg or its inertia is not positive/finite")]
    BadInertia {
        /// Body index.
        body: usize,
        /// Body name.
        name: String,
        /// The mass given.
        mass: f64,
    },
    /// The model has no bodies.
    #[error("the model has no bodies")]
    Empty,
    /// A vector passed to the kernel does not have the size the model gives it (`q`: nq,
    /// `v`/`tau`/`qdd`: nv, `f_ext`: one per body).
    #[error("{what} has {found} entries, the model needs {expected}")]
    SizeMismatch {
        /// Which argument (e.g. "q", "tau", "f_ext").
        what: &'static str,
        /// The size the model needs.
        expected: usize,
        /// The size given.
        found: usize,
    },
    /// The joint-space inertia matrix of a configuration is not positive definite.
    #[error(transparent)]
    NotPositiveDefinite(#[from] NotPositiveDefinite),
}

/// `Ok` when argument `what` has the `expected` size, else [`ModelError::SizeMismatch`].
#[inline]
pub fn check_size(what: &'static str, expected: usize, found: usize) -> Result<(), ModelError> {
    if found == expected {
        Ok(())
    } else {
        Err(ModelError::SizeMismatch {
            what,
            expected,
            found,
        })
    }
}

/// One body of the tree and the joint that connects it to its parent.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// Name (the link name, e.g. "torso").
    pub name: String,
    /// Name of the joint that moves this body (e.g. "waist").
    pub joint_name: String,
    /// Parent body index; `None` for the root (its joint connects to the fixed world frame).
    pub parent: Option<usize>,
    /// The joint type and axes.
    pub joint: JointType,
    /// `Xtree`: transform from the parent body frame to this joint's frame at `q = 0`.
    pub x_tree: SpatialTransform,
    /// Rigid-body inertia in the body frame.
    pub inertia: Inertia,
}

/// The immutable kinematic tree, built and validated by [`Model::new`]. Its fields are read
/// through accessors; the derived ones (offsets, sizes, inertia blocks, joint axes) always
/// agree with the bodies because a changed model is a rebuilt one ([`Model::with_gravity`],
/// or [`Model::new`] on edited [`Model::bodies`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Model {
    /// Bodies in depth-first order, parents first.
    pub(super) bodies: Vec<Body>,
    /// Gravity acceleration in world coordinates (m/s²), e.g. `(0, −9.81, 0)`.
    pub(super) gravity: DVec3,
    /// Offset of each joint's block in `q`.
    pub(super) q_idx: Vec<usize>,
    /// Offset of each joint's block in `v`.
    pub(super) v_idx: Vec<usize>,
    /// Size of the configuration vector.
    pub(super) nq: usize,
    /// Size of the velocity vector (degrees of freedom).
    pub(super) nv: usize,
    /// Each body's rigid inertia as 3×3 blocks, derived from `bodies` (the articulated-body
    /// algorithm starts from these).
    pub(super) inertia_blocks: Vec<ArticulatedInertia>,
    /// How each body's joint rotation factors into rotations about coordinate axes, derived
    /// from `bodies` (the kinematics and the ABA take the cheaper products where it does).
    pub(super) joint_axes: Vec<JointAxes>,
    /// The entries of `q` that are angles of such coordinate-axis joints (one per pin, two per
    /// universal), whose sines and cosines the kinematics takes four at a time.
    pub(super) axis_angles: Vec<usize>,
}

/// The coordinate-axis structure of body `b`'s joint rotation: a pin or universal joint whose
/// axes are coordinate axes and whose tree transform does not rotate.
fn joint_axes(b: &Body) -> JointAxes {
    if b.x_tree.rot != glam::DMat3::IDENTITY {
        return JointAxes::General;
    }
    match b.joint {
        JointType::Pin { axis } => CoordAxis::of(axis).map_or(JointAxes::General, JointAxes::One),
        JointType::Universal { axis1, axis2 } => match (CoordAxis::of(axis1), CoordAxis::of(axis2))
        {
            (Some(a), Some(b)) => JointAxes::Two(a, b),
            _ => JointAxes::General,
        },
        _ => JointAxes::General,
    }
}

impl Model {
    /// Builds and validates a model from bodies in depth-first order.
    pub fn new(bodies: Vec<Body>, gravity: DVec3) -> Result<Self, ModelError> {
        if bodies.is_empty() {
            return Err(ModelError::Empty);
        }
        let mut q_idx = Vec::with_capacity(bodies.len());
        let mut v_idx = Vec::with_capacity(bodies.len());
        let (mut nq, mut nv) = (0, 0);
        for (i, b) in bodies.iter().enumerate() {
            if let Some(p) = b.parent
                && p >= i
            {
                return Err(ModelError::BadParent {
                    body: i,
                    name: b.name.clone(),
                    parent: p,
                });
            }
            if matches!(b.joint, JointType::Free) && (i != 0 || b.parent.is_some()) {
                return Err(ModelError::FreeNotRoot {
                    body: i,
                    name: b.name.clone(),
                });
            }
            if !b.joint.axes_valid() {
                return Err(ModelError::BadAxis {
                    body: i,
                    name: b.name.clone(),
                });
            }
            let ic = b.inertia.inertia_com;
            let sym = (ic - ic.transpose())
                .abs()
                .to_cols_array()
                .iter()
                .sum::<f64>()
                < 1e-9;
            let pd = ic.x_axis.x > 0.0
                && ic.x_axis.x * ic.y_axis.y - ic.x_axis.y * ic.y_axis.x > 0.0
                && ic.determinant() > 0.0;
            let ok = b.inertia.mass.is_finite()
                && b.inertia.mass > 0.0
                && sym
                && pd
                && b.inertia.com.is_finite();
            if !ok {
                return Err(ModelError::BadInertia {
                    body: i,
                    name: b.name.clone(),
                    mass: b.inertia.mass,
                });
            }
            q_idx.push(nq);
            v_idx.push(nv);
            nq += b.joint.nq();
            nv += b.joint.nv();
        }
        let inertia_blocks = bodies.iter().map(|b| b.inertia.to_blocks()).collect();
        let joint_axes: Vec<JointAxes> = bodies.iter().map(joint_axes).collect();
        let axis_angles = joint_axes
            .iter()
            .zip(&q_idx)
            .flat_map(|(axes, &iq)| match axes {
                JointAxes::General => iq..iq,
                JointAxes::One(_) => iq..iq + 1,
                JointAxes::Two(..) => iq..iq + 2,
            })
            .collect();
        Ok(Self {
            inertia_blocks,
            joint_axes,
            axis_angles,
            bodies,
            gravity,
            q_idx,
            v_idx,
            nq,
            nv,
        })
    }

    /// The same model under gravity `gravity` (world coordinates, m/s²).
    pub fn with_gravity(self, gravity: DVec3) -> Self {
        Self { gravity, ..self }
    }

    /// Number of bodies.
    #[inline]
    pub fn nbodies(&self) -> usize {
        self.bodies.len()
    }

    /// The bodies in depth-first order, parents first (body `i` is moved by joint `i`).
    #[inline]
    pub fn bodies(&self) -> &[Body] {
        &self.bodies
    }

    /// Body `i`.
    #[inline]
    pub fn body(&self, i: usize) -> &Body {
        &self.bodies[i]
    }

    /// Gravity acceleration in world coordinates (m/s²).
    #[inline]
    pub fn gravity(&self) -> DVec3 {
        self.gravity
    }

    /// Size of the configuration vector `q`.
    #[inline]
    pub fn nq(&self) -> usize {
        self.nq
    }

    /// Size of the velocity vector `v` (the degrees of freedom).
    #[inline]
    pub fn nv(&self) -> usize {
        self.nv
    }

    /// Offset of joint `i`'s block in `q` (its size is `body(i).joint.nq()`).
    #[inline]
    pub fn q_offset(&self, i: usize) -> usize {
        self.q_idx[i]
    }

    /// Offset of joint `i`'s block in `v` (its size is `body(i).joint.nv()`).
    #[inline]
    pub fn v_offset(&self, i: usize) -> usize {
        self.v_idx[i]
    }

    /// Each body's rigid inertia as 3×3 blocks (body coordinates; kg, kg·m, kg·m²).
    #[inline]
    pub fn inertia_blocks(&self) -> &[ArticulatedInertia] {
        &self.inertia_blocks
    }

    /// How each body's joint rotation factors into rotations about coordinate axes.
    #[inline]
    pub fn joint_axes(&self) -> &[JointAxes] {
        &self.joint_axes
    }

    /// The entries of `q` that are angles of coordinate-axis pin and universal joints.
    #[inline]
    pub fn axis_angles(&self) -> &[usize] {
        &self.axis_angles
    }

    /// `Ok` when `q` has size nq and `v` size nv, else [`ModelError::SizeMismatch`].
    #[inline]
    pub fn check_state(&self, q: &[f64], v: &[f64]) -> Result<(), ModelError> {
        check_size("q", self.nq, q.len())?;
        check_size("v", self.nv, v.len())
    }

    /// `Ok` when joint forces `tau` have size nv and external forces `f_ext` one entry per
    /// body, else [`ModelError::SizeMismatch`].
    #[inline]
    pub fn check_forces(&self, tau: &[f64], f_ext: &[ForceVec]) -> Result<(), ModelError> {
        check_size("tau", self.nv, tau.len())?;
        check_size("f_ext", self.nbodies(), f_ext.len())
    }

    /// `Ok` when `data` was allocated for a model of this size ([`Data::new`]), else
    /// [`ModelError::SizeMismatch`].
    #[inline]
    pub fn check_data(&self, data: &Data) -> Result<(), ModelError> {
        check_size("data (bodies)", self.nbodies(), data.xup.len())?;
        check_size("data (nq)", self.nq, data.q_sin_cos.0.len())?;
        check_size("data (nv)", self.nv, data.qdd.len())
    }

    /// The neutral configuration: zero angles, identity quaternions, free base at the origin.
    pub fn neutral(&self) -> Vec<f64> {
        let mut q = vec![0.0; self.nq];
        for (i, b) in self.bodies.iter().enumerate() {
            b.joint
                .neutral(&mut q[self.q_idx[i]..self.q_idx[i] + b.joint.nq()]);
        }
        q
    }

    /// Index of the body named `name`.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// `out = q ⊞ z` joint by joint (see [`JointType::retract`]); `z` has size nv.
    #[inline(always)]
    pub fn retract(&self, q: &[f64], z: &[f64], out: &mut [f64]) {
        debug_assert!(q.len() == self.nq && z.len() == self.nv && out.len() == self.nq);
        for (i, b) in self.bodies.iter().enumerate() {
            let (iq, iv) = (self.q_idx[i], self.v_idx[i]);
            // Angle joints inline (the same sums as `JointType::retract`).
            if let Some(n) = b.joint.angle_dofs() {
                out[iq] = q[iq] + z[iv];
                if n == 2 {
                    out[iq + 1] = q[iq + 1] + z[iv + 1];
                }
                continue;
            }
            let (nq, nv) = (b.joint.nq(), b.joint.nv());
            b.joint
                .retract(&q[iq..iq + nq], &z[iv..iv + nv], &mut out[iq..iq + nq]);
        }
    }

    /// The chart rate `ż` at `q_stage = q₀ ⊞ z` under velocity `v` (see
    /// [`JointType::chart_rate`]); all vectors but `q_stage` have size nv.
    #[inline(always)]
    pub fn chart_rate(&self, q_stage: &[f64], z: &[f64], v: &[f64], zdot: &mut [f64]) {
        debug_assert!(q_stage.len() == self.nq && z.len() == self.nv && zdot.len() == self.nv);
        for (i, b) in self.bodies.iter().enumerate() {
            let (iq, iv) = (self.q_idx[i], self.v_idx[i]);
            // Angle joints inline: their chart rate is the velocity.
            if let Some(n) = b.joint.angle_dofs() {
                zdot[iv] = v[iv];
                if n == 2 {
                    zdot[iv + 1] = v[iv + 1];
                }
                continue;
            }
            let (nq, nv) = (b.joint.nq(), b.joint.nv());
            b.joint.chart_rate(
                &q_stage[iq..iq + nq],
                &z[iv..iv + nv],
                &v[iv..iv + nv],
                &mut zdot[iv..iv + nv],
            );
        }
    }

    /// The anatomical angle of every velocity DOF (rad; zeros for a free joint), size nv.
    #[inline(always)]
    pub fn angles(&self, q: &[f64], out: &mut [f64]) {
        debug_assert!(q.len() == self.nq && out.len() == self.nv);
        for (i, b) in self.bodies.iter().enumerate() {
            let (iq, iv) = (self.q_idx[i], self.v_idx[i]);
            b.joint
                .angles(&q[iq..iq + b.joint.nq()], &mut out[iv..iv + b.joint.nv()]);
        }
    }

    /// The angles as [`Model::angles`], every ball joint read nearest `reference` (size nv; see
    /// [`JointType::angles_near`]).
    #[inline(always)]
    pub fn angles_near(&self, q: &[f64], reference: &[f64], out: &mut [f64]) {
        debug_assert!(q.len() == self.nq && reference.len() == self.nv && out.len() == self.nv);
        for (i, b) in self.bodies.iter().enumerate() {
            let (iq, iv) = (self.q_idx[i], self.v_idx[i]);
            // Angle joints inline: their angles are their coordinates.
            if let Some(n) = b.joint.angle_dofs() {
                out[iv] = q[iq];
                if n == 2 {
                    out[iv + 1] = q[iq + 1];
                }
                continue;
            }
            let nv = b.joint.nv();
            b.joint.angles_near(
                &q[iq..iq + b.joint.nq()],
                &reference[iv..iv + nv],
                &mut out[iv..iv + nv],
            );
        }
    }

    /// The joint velocities of angles `angles` moving at rates `rates` (all size nv; see
    /// [`JointType::velocity_from_rates`]); a free joint's entries of `v` are left as they are.
    pub fn velocity_from_rates(&self, angles: &[f64], rates: &[f64], v: &mut [f64]) {
        debug_assert!(angles.len() == self.nv && rates.len() == self.nv && v.len() == self.nv);
        for (i, b) in self.bodies.iter().enumerate() {
            let iv = self.v_idx[i];
            let nv = b.joint.nv();
            b.joint.velocity_from_rates(
                &angles[iv..iv + nv],
                &rates[iv..iv + nv],
                &mut v[iv..iv + nv],
            );
        }
    }

    /// Total mass (kg).
    pub fn total_mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.inertia.mass).sum()
    }
}
