//! A dance for a song, generated once for both front doors (the `Dance` scene and the editor):
//! the unpinned bars filled by the minimum-cost path ([`fill::fill`]), the segments assembled
//! at the song's bar timing with each bar's beats warped onto the song's
//! ([`dance::assemble`]), the feet put on the floor ([`plant_feet`]), and the figures an
//! animator looks at ([`figures`]).

use serde::Serialize;

use crate::choreo::dance::{self, DanceError, DanceParams};
use crate::choreo::database::Database;
use crate::choreo::feet::{PlantParams, Planting, plant_feet};
use crate::choreo::fill::{self, Fill, FillError, FillParams, Pins};
use crate::choreo::metrics;
use crate::choreo::music::Bar;
use crate::choreo::relevance;

/// Why a dance could not be generated.
#[derive(Debug, thiserror::Error)]
pub enum GenerateError {
    /// Filling the unpinned bars.
    #[error(transparent)]
    Fill(#[from] FillError),
    /// Assembling the dance.
    #[error(transparent)]
    Dance(#[from] DanceError),
}

/// The dance of `segments` (one per bar of `bars`, the song's beats at `beats_s`): assembled
/// at the bars' timing, each bar's beats warped onto the song's ([`dance::assemble`] with
/// `params`), then its feet put on the floor ([`plant_feet`] with `feet`).
pub fn perform(
    db: &Database,
    segments: &[usize],
    bars: &[Bar],
    beats_s: &[f64],
    params: &DanceParams,
    feet: &PlantParams,
) -> Result<(dance::Dance, Planting), DanceError> {
    let mut d = dance::assemble(db, segments, bars, beats_s, params)?;
    let planting = plant_feet(&mut d.clip, feet);
    Ok((d, planting))
}

/// What an animator looks at in a dance (the report's and the editor's figures): its metrics
/// ([`metrics::dance_metrics`]: beat alignment, seam jerk, skating, foot penetration), its
/// danced segments' own skating and beat alignment ([`metrics::source_metrics`]), and the
/// Spearman correlation of the bars' music and motion intensity.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DanceFigures {
    /// The dance's metrics.
    pub metrics: metrics::DanceMetrics,
    /// The danced segments, each alone at its own timing.
    pub sources: metrics::SourceMetrics,
    /// Spearman's ρ of music and motion intensity over the bars.
    pub intensity_spearman: f64,
    /// Every bar's music intensity as a percentile rank among the bars.
    #[serde(skip)]
    pub music_rank: Vec<f64>,
    /// Every bar's segment's motion intensity as a percentile rank in the database.
    #[serde(skip)]
    pub motion_rank: Vec<f64>,
}

/// The [`DanceFigures`] of dance `d` filled as `filled` to `bars` (song beats `beats_s`).
pub fn figures(
    d: &dance::Dance,
    db: &Database,
    filled: &Fill,
    bars: &[Bar],
    beats_s: &[f64],
) -> DanceFigures {
    let music_rank = relevance::music_intensity(bars);
    let motion_rank_db = relevance::motion_intensity(db);
    let motion_rank: Vec<f64> = filled.segments.iter().map(|&s| motion_rank_db[s]).collect();
    DanceFigures {
        metrics: metrics::dance_metrics(d, beats_s, filled),
        sources: metrics::source_metrics(db, &filled.segments, 1.0 / d.clip.frame_time),
        intensity_spearman: metrics::spearman(&music_rank, &motion_rank),
        music_rank,
        motion_rank,
    }
}

/// A generated dance: the fill, the dance performed from it, how its feet were planted, and
/// its figures.
#[derive(Debug, Clone)]
pub struct Generated {
    /// The segment of every bar and the connections at the seams.
    pub fill: Fill,
    /// The dance.
    pub dance: dance::Dance,
    /// How its feet were put on the floor.
    pub planting: Planting,
    /// Its figures.
    pub figures: DanceFigures,
}

/// The dance of `db` to `bars` (the song's beats at `beats_s`) with `pins` kept: filled with
/// `fill_params` against the bars' music intensity, performed with `params` and `feet`
/// ([`perform`]) and measured ([`figures`]).
pub fn generate(
    db: &Database,
    bars: &[Bar],
    beats_s: &[f64],
    pins: &Pins,
    fill_params: &FillParams,
    params: &DanceParams,
    feet: &PlantParams,
) -> Result<Generated, GenerateError> {
    let filled = fill::fill(db, &relevance::music_intensity(bars), pins, fill_params)?;
    let (d, planting) = perform(db, &filled.segments, bars, beats_s, params, feet)?;
    let figures = figures(&d, db, &filled, bars, beats_s);
    Ok(Generated {
        fill: filled,
        dance: d,
        planting,
        figures,
    })
}
