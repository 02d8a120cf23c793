//! Measurements on motions: ground contact and flight phases.

mod contact;
mod feet;

pub use contact::{Contacts, Span, ground_contacts};
pub use feet::{PointRef, clip_contacts, foot_points};
