//! Control laws: what a controller asks of a body, as plain functions over plain data (no
//! World, no human tables). The ECS systems of physical characters only call them:
//!
//! - [`gains`]: PD gains of one bandwidth for every DOF, scaled by the joint-space inertia;
//! - [`feedforward`]: the computed-torque feedforward of a desired motion (its inverse
//!   dynamics), and the free root's share of it as a world-frame wrench;
//! - [`assist`]: the root assistance ("hand of god"), a PD on the free root's pose that an
//!   external wrench at the root applies.
//!
//! The joint torques themselves (PD, clamped to strength) are a force of the step,
//! [`crate::dynamics::forces::pd`].

pub mod assist;
pub mod feedforward;
pub mod gains;

pub use assist::{RootAssistGains, RootTarget, Wrench, root_assist_wrench};
pub use feedforward::{ComputedTorque, root_share};
pub use gains::{inertia_scaled_gains, root_rotational_inertia};
