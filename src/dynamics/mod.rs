//! The rigid-body kernel: spatial algebra, the kinematic tree, the articulated-body algorithm
//! (checked against RNEA and CRBA), integrators on the configuration manifold, the forces a
//! body feels ([`forces`]: PD, joint model, floor contact, external), the control laws that set
//! them ([`control`]: gains, feedforward, root assistance) and the step as a pipeline of named
//! stages ([`pipeline`]). Nothing here knows humans, experiments or the ECS.
//!
//! Layout (after Featherstone's spatial_v2 and Pinocchio): an immutable [`Model`] (parents,
//! joint types, `Xtree`, inertias; `nq ≠ nv`) apart from a scratch [`Data`]; one algorithm per
//! file — [`aba()`] (forward dynamics, O(n), used to simulate), [`rnea()`] (inverse dynamics) and
//! [`crba()`] + Cholesky ([`forward_dynamics_crba`]) to check it. A simulated body advances by
//! [`pipeline::step`] from a [`State`] under [`Forces`]; the pushed fall of the falling paper is
//! an experiment above it (`marionette::experiments::fall`).

// The algorithms index bodies and DOFs as Featherstone's book does (`for i in 0..n`).
#![allow(clippy::needless_range_loop)]

pub mod aba;
#[cfg(test)]
mod aba_book;
pub mod aba_lanes;
pub mod axis_rotation;
pub mod control;
pub mod crba;
pub mod data;
pub mod equilibrium;
pub mod forces;
pub mod integrator;
pub mod joint;
pub mod kinematics;
pub mod lanes;
pub mod linearly_implicit;
pub mod model;
pub mod pipeline;
mod real;
pub mod rnea;
pub mod spatial;
pub mod stability;
pub mod trig;
mod width;

pub use aba::{aba, aba_passes};
pub use crba::{crba, forward_dynamics_crba};
pub use data::Data;
pub use integrator::{Dynamics, Integrator, IntegratorWorkspace};
pub use joint::JointType;
pub use kinematics::kinematics;
pub use model::{Body, Model, ModelError};
pub use pipeline::{
    Forces, State, StepError, StepMonitor, StepRefinement, StepSettings, StepWorkspace,
};
pub use rnea::rnea;
pub use spatial::{ArticulatedInertia, ForceVec, Inertia, MotionVec, SpatialTransform};
