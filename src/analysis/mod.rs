//! Measurements on motions: ground contact and flight phases.

mod contact;
mod feet;

pub use contact::{ContactConfig, Contacts, Span, ground_contacts};
pub use feet::{PointRef, clip_contacts, clip_contacts_with, foot_points, point_tracks};
