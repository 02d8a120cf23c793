//! Measurements on motions: ground contact and flight phases, and the plain signal helpers
//! they and the systems share ([`signal`]).

mod contact;
mod feet;
pub mod signal;

pub use contact::{
    ContactConfig, ContactReference, Contacts, Span, ground_contacts, ground_contacts_against,
};
pub use feet::{
    PointRef, clip_contacts, clip_contacts_against, clip_contacts_and_feet, clip_contacts_with,
    foot_points, point_tracks,
};
