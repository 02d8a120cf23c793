//! Choreography (SPEC §2, the dance-editing paper): music analysis of a song (beats, bars, each
//! bar's intensity) that a dance is cut to.
//!
//! - [`music`]: the music kernel over a plain sample buffer (onset envelope, tempo, beats, bars,
//!   bar intensity), song decoding behind the `audio` feature, and a drum-track synthesizer with
//!   exact ground truth;
//! - [`eros`]: the eigen-analysis (PCA) similarity between motion segments (Eros);
//! - [`features`]: per-frame motion intensity W(f) and the features of a segment for Eros;
//! - [`segments`]: dance clips cut into bars of 4 counts (tempo from a manifest or the kinematic
//!   beat), each resampled, with intensity, Eros features and boundary links;
//! - [`database`]: the segment database file and what it was built from;
//! - [`transition`]: the connection score S = S_pose + S_move of two segments (eqs. 5–8) and
//!   the transition cost C = 1/S, one pair or a whole database's table;
//! - [`fill`]: the unpinned bars filled by the minimum-cost path (Dijkstra, and the exact
//!   dynamic programme that gives the same path);
//! - [`dance`]: the chosen segments assembled at the song's bar timing, root carried on, seams
//!   rewritten by cubic interpolation;
//! - [`feet`]: the dance's planted feet put on the floor and held still by leg IK;
//! - [`warp`]: the beat warp of a bar, a monotone cubic time map that puts a segment's own
//!   beats (speed minima) on the song's beats, C¹ at the bar lines;
//! - [`metrics`]: beat alignment score, seam jerk, foot skating, transition cost of a dance;
//! - [`augment`]: a larger database from a real one by mirror images and time offsets;
//! - [`relevance`]: rel(q, m), music intensity against motion intensity, both as percentile ranks;
//! - [`search`]: the relevance-feedback search of eqs. (1)–(4), six candidates per round;
//! - [`edit`]: the stateful edit a server holds (pins, per-bar search, undo/redo, generate);
//! - [`authored`]: the project's own dance, generated in code at a known tempo;
//! - [`generated`]: a database of dance clips generated in code (no shared data needed).

pub mod augment;
pub mod authored;
pub mod dance;
pub mod database;
pub mod edit;
pub mod eros;
mod error;
pub mod features;
pub mod feet;
pub mod fill;
pub mod generated;
pub mod metrics;
pub mod music;
pub mod relevance;
pub mod search;
pub mod segments;
pub mod transition;
pub mod warp;
