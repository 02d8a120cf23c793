//! Articulated-body dynamics of the pushed fall (SPEC §3): spatial algebra, the kinematic tree,
//! the articulated-body algorithm (checked against RNEA and CRBA), integrators, joint limits,
//! floor contact, PD control, pushes, the fall21 human body, and the ECS wiring that runs falls
//! as parallel Worlds.

// The algorithms index bodies and DOFs as Featherstone's book does (`for i in 0..n`).
#![allow(clippy::needless_range_loop)]

pub mod aba;
pub mod contact;
pub mod crba;
pub mod data;
pub mod ecs;
pub mod fall;
pub mod human;
pub mod integrator;
pub mod joint;
pub mod kinematics;
pub mod limits;
pub mod model;
pub mod pd;
pub mod push;
pub mod rnea;
pub mod spatial;

pub use aba::{aba, aba_passes};
pub use crba::{crba, forward_dynamics_crba};
pub use data::Data;
pub use fall::{FallConfig, FallFrame, FallResult, SimError, simulate_fall};
pub use integrator::{Dynamics, Integrator, IntegratorWorkspace};
pub use joint::JointType;
pub use kinematics::kinematics;
pub use model::{Body, Model, ModelError};
pub use rnea::rnea;
pub use spatial::{ArticulatedInertia, ForceVec, Inertia, MotionVec, SpatialTransform};
