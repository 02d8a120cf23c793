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

pub(crate) mod augment;
pub(crate) mod authored;
pub(crate) mod dance;
pub(crate) mod database;
pub(crate) mod edit;
pub(crate) mod eros;
mod error;
pub(crate) mod features;
pub(crate) mod feet;
pub(crate) mod fill;
pub(crate) mod generated;
pub(crate) mod metrics;
pub mod music;
pub(crate) mod relevance;
pub(crate) mod search;
pub(crate) mod segments;
pub(crate) mod transition;
pub(crate) mod warp;

pub use augment::{augment, augment_with_variants};
pub use authored::{AuthoredDance, generate, write_bvh_folder};
pub use dance::{Dance, DanceParams, assemble};
pub use database::{
    BuildParams, ClipOutcome, Database, Manifest, ManifestClip, OnRefusal, Source, load_figure_clip,
};
pub use edit::Edit;
pub use eros::{eros, eros_distance, eros_weights, pca};
pub use features::{mean_motion_intensity, mirror_motion, mirror_partners, pose_rows};
pub use feet::{PlantParams, plant_feet, rest_sole_heights};
pub use fill::{
    BUDGET_HALVINGS, DEFAULT_SEAM_BUDGET, FillParams, Pins, fill, fill_dijkstra,
    fill_dijkstra_with_table, fill_with_table,
};
pub use generated::generated_database;
pub use metrics::{
    BAS_SIGMA_S, FootPenetration, beat_alignment_score, dance_metrics, floor_contacts,
    foot_penetration, foot_skating, motion_beats, seam_jerk, source_beat_alignment, spearman,
};
pub use relevance::{motion_intensity, percentile_ranks};
pub use search::{BarSearch, SearchIndex, SearchParams, search_round};
pub use segments::{
    BAR_FRAMES_RANGE, Beat, LEVEL_BPM, MAX_BPM, MIN_BPM, SegmentError, TempoSource, check_tempo,
    cut_segments, kinematic_beat, kinematic_tempo, speed_curve,
};
pub use transition::TransitionTable;
pub use warp::Warp;
