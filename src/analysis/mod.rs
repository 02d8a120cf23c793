//! Measurements on motions: ground contact and flight phases.

mod contact;

pub use contact::{Contacts, Span, ground_contacts};
