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
//!
//! Everything is used from here (`marionette::dynamics::Inertia`); the files stay private:
//! `spatial` (motion and force vectors, transforms, inertias, [`outer`]), `joint`
//! ([`JointType`]), `model` and `data`, `kinematics`, `aba`, `rnea`, `crba` (with its Cholesky
//! solve), `integrator` (the [`Integrator`] schemes; its step is re-exported as [`integrate`]),
//! `linearly_implicit` (the one-DOF implicit updates the linearised schemes use), `stability`
//! (the stable step of a stiffness, [`stable_step`]), `equilibrium` (a body balanced on the
//! floor, [`balance_base`]) and the four-lane versions of the tree walk (`aba_lanes`, `lanes`,
//! `trig`: [`aba_passes_lanes`] over [`LANES`] bodies at once). Three folders are concepts of
//! their own and stay namespaces: [`forces`], [`control`] and [`pipeline`].

// The algorithms index bodies and DOFs as Featherstone's book does (`for i in 0..n`).
#![allow(clippy::needless_range_loop)]

mod aba;
#[cfg(test)]
mod aba_book;
mod aba_lanes;
mod axis_rotation;
pub mod control;
mod crba;
mod data;
mod equilibrium;
pub mod forces;
mod integrator;
mod joint;
mod kinematics;
mod lanes;
mod linearly_implicit;
mod model;
pub mod pipeline;
mod real;
mod rnea;
mod spatial;
mod stability;
mod trig;
mod width;

// What the private files give the crate's users, as `dynamics::X`.
pub use aba::{aba, aba_passes};
pub use aba_lanes::{LaneData, LaneInput, aba_passes_lanes};
pub use crba::{crba, forward_dynamics_crba};
pub use data::Data;
pub use equilibrium::{
    Balance, BalanceSettings, EquilibriumError, balance_base, holding_torques, imbalance,
};
pub use integrator::{Dynamics, Integrator, IntegratorWorkspace, step as integrate};
pub use joint::JointType;
pub use kinematics::{kinematics, mechanical_energy, world_point, world_point_velocity};
pub use lanes::LANES;
pub use model::{Body, Model, ModelError, NotPositiveDefinite};
pub use pipeline::{
    Forces, State, StepError, StepMonitor, StepRefinement, StepSettings, StepWorkspace,
};
pub use rnea::rnea;
pub use spatial::{ArticulatedInertia, ForceVec, Inertia, MotionVec, SpatialTransform, outer};
pub use stability::{
    DofStiffness, StiffestMode, StiffnessBasis, inverse_joint_inertia, scheme_name, stable_step,
    stiffest_mode,
};
