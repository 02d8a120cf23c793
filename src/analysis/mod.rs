//! Measurements on motions: ground contact and flight phases, found on a skeleton's feet (its
//! ankles named by [`crate::mapping`]). The plain signal helpers they share live at the bottom
//! of the crate ([`crate::signal`]).

mod contact;
mod feet;

pub use contact::{
    ContactConfig, ContactReference, Contacts, Span, ground_contacts, ground_contacts_against,
};
pub use feet::{
    PointRef, clip_contacts, clip_contacts_against, clip_contacts_and_feet, clip_contacts_with,
    foot_points, point_tracks,
};
