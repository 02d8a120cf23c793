//! Articulated-body dynamics of the pushed fall (SPEC §3): spatial algebra, the kinematic tree,
//! the articulated-body algorithm (checked against RNEA and CRBA), integrators, joint limits,
//! floor contact, PD control, pushes, the fall21 human body, and the ECS wiring that runs falls
//! as parallel Worlds.
//!
//! Layout (after Featherstone's spatial_v2 and Pinocchio): an immutable [`Model`] (parents,
//! joint types, `Xtree`, inertias; `nq ≠ nv`) apart from a scratch [`Data`]; one algorithm per
//! file — [`aba()`] (forward dynamics, O(n), used to simulate), [`rnea()`] (inverse dynamics) and
//! [`crba()`] + Cholesky ([`forward_dynamics_crba`]) to check it. A fall:
//!
//! ```no_run
//! use marionette::dynamics::{FallConfig, simulate_fall};
//! use marionette::humanoid::ranges::AgeGroup;
//! let result = simulate_fall(&FallConfig::paper(AgeGroup::Elderly)).unwrap();
//! println!("damage {:.0} N, at rest: {}", result.damage, result.came_to_rest);
//! ```
//!
//! Many falls in parallel Worlds: [`ecs::run_parallel`]; one World: [`ecs::build_fall_world`] +
//! [`ecs::run_world`], systems ordered by [`ecs::FallSet`].

// The algorithms index bodies and DOFs as Featherstone's book does (`for i in 0..n`).
#![allow(clippy::needless_range_loop)]

pub mod aba;
pub mod crba;
pub mod data;
pub mod forces;
pub mod integrator;
pub mod joint;
pub mod kinematics;
pub mod model;
pub mod rnea;
pub mod spatial;

pub use aba::{aba, aba_passes};
pub use crba::{crba, forward_dynamics_crba};
pub use data::Data;
pub use integrator::{Dynamics, Integrator, IntegratorWorkspace};
pub use joint::JointType;
pub use kinematics::kinematics;
pub use model::{Body, Model, ModelError};
pub use rnea::rnea;
pub use spatial::{ArticulatedInertia, ForceVec, Inertia, MotionVec, SpatialTransform};
