//! The papers' experiments as library functions above the kernels: a typed configuration in, a
//! typed outcome out, no files and no pictures (a scene file is only the front door that reads a
//! configuration, calls one of these and writes its outputs).
//!
//! - [`active`]: a physical character that plays primitives under PD control with root
//!   assistance, is pushed and falls (issue 13);
//! - [`fall`]: the falling paper's pushed figure (SPEC §3), one fall or many in parallel Worlds;
//! - [`evolve_fall`]: the falling paper's GA over both age groups and several seeds (§5–6);
//! - [`high_jump`]: the motor-primitive paper's high jump by extrapolation (§4.1);
//! - [`knee_kick`]: its jumping knee kick, blended and connected (§4.2);
//! - [`dance`]: a dance for a song (fill, assemble, feet, figures), for the `Dance` scene and
//!   the editor alike;
//! - [`dance_feedback`]: the dance-editing paper's Fig. 4, the spread of the six candidates
//!   over re-searches with a simulated user (§4.1);
//! - [`dance_fill`]: the dance-editing paper's Fig. 5, connection-aware against connection-blind
//!   fill over random pin sets.

pub mod active;
pub mod dance;
pub mod dance_feedback;
pub mod dance_fill;
pub mod evolve_fall;
pub mod fall;
pub mod high_jump;
pub mod jump_figures;
pub mod knee_kick;
