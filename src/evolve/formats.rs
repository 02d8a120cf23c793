//! The versions and limits of what the GA writes and reads: the checkpoint's format and the
//! JSON-lines worker protocol ([`super::evaluator::JsonLines`]). At the bottom of `evolve`, so
//! that its errors can name them.

/// The format this version writes and reads (1: the bare state, before versions and checksums).
pub const FORMAT_VERSION: u32 = 2;

/// The protocol's name and version.
/// Version 2 added `refine`; a version-1 worker would ignore it and answer at the problem's
/// own resolution, so the version is checked.
/// Version 3 tagged each message by its key and refuses unknown fields (a version-2 line is
/// refused as an unknown message).
pub const PROTOCOL: &str = "marionette-eval/3";

/// Longest protocol line accepted (bytes).
pub const MAX_LINE: usize = 1 << 20;

/// Largest refinement a worker accepts (a fall at 1/64 of its step already takes 64 times as
/// long).
pub const MAX_REFINE: u32 = 64;
