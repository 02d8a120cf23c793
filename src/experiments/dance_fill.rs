//! The dance-editing paper's Fig. 5 in numbers: for the same pins, connection-aware fill (the
//! minimum-cost path of [`crate::choreo::fill`]) against connection-blind fills — random
//! segments, and segments chosen by intensity only — over many random pin sets: the mean and
//! spread of the seam jerk of the assembled dances and of the connection score S at their
//! seams.
//!
//! The intensity-only fill gives every unpinned bar the segment whose motion-intensity
//! percentile (its rank among the database's segments) is nearest the bar's music-intensity
//! percentile; the experiment has no song, so each pin set draws a music-intensity profile, a
//! seeded random walk of percentiles clamped to [0, 1]. Random and intensity-only fills keep
//! the no-adjacent-repeat rule when the fill does.
//!
//! [`generated_database`](crate::choreo::generated::generated_database) builds a database from
//! dance clips generated in code, so that the experiment also runs without the shared data.

use rand::{Rng, RngExt, SeedableRng};
use serde::{Deserialize, Serialize};

use crate::choreo::dance::{DanceError, DanceParams, Seam, assemble};
use crate::choreo::database::Database;
use crate::choreo::fill::{FillError, FillParams, Pins, check, fill_with_table};
use crate::choreo::metrics::seam_jerk;
use crate::choreo::music::Bar;
use crate::choreo::transition::{TransitionTable, connection};

/// How a fill is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Strategy {
    /// The minimum-cost path over C = 1/S ([`fill_with_table`]).
    ConnectionAware,
    /// Uniformly random segments.
    Random,
    /// The segment nearest the bar's music intensity (percentiles).
    IntensityOnly,
}

/// The strategies compared, in table order.
pub const STRATEGIES: [Strategy; 3] = [
    Strategy::ConnectionAware,
    Strategy::Random,
    Strategy::IntensityOnly,
];

/// The experiment's inputs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DanceFillConfig {
    /// Bars per dance.
    pub bars: usize,
    /// Random pin sets.
    pub pin_sets: usize,
    /// Pins per set (distinct bars).
    pub pins_per_set: usize,
    /// Bar length of the dances, seconds.
    pub bar_s: f64,
    /// The fill (link weights, no adjacent repeat).
    pub fill: FillParams,
    /// The assembly (fps, seam frames).
    pub dance: DanceParams,
    /// Seed of the pins, music profiles and random fills.
    pub seed: u64,
}

impl Default for DanceFillConfig {
    /// 16 bars of 2 s, 40 pin sets of 3 pins, 30 fps, 5 seam frames, the paper's uniform
    /// resize and seam spline (no beat warp: Fig. 5 measures the paper's assembly), seed 1.
    fn default() -> DanceFillConfig {
        DanceFillConfig {
            bars: 16,
            pin_sets: 40,
            pins_per_set: 3,
            bar_s: 2.0,
            fill: FillParams::paper(),
            dance: DanceParams {
                beat_warp: false,
                seam: Seam::Spline,
                ..DanceParams::default()
            },
            seed: 1,
        }
    }
}

/// Mean and spread of a quantity over the pin sets.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Spread {
    /// Mean.
    pub mean: f64,
    /// Standard deviation (population).
    pub sd: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
}

impl Spread {
    /// The spread of `v` (zeros for none).
    pub fn of(v: &[f64]) -> Spread {
        if v.is_empty() {
            return Spread::default();
        }
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
        Spread {
            mean,
            sd: var.sqrt(),
            min: v.iter().copied().fold(f64::INFINITY, f64::min),
            max: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }
}

/// One pin set's dance under one strategy.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Trial {
    /// The segment of every bar.
    pub segments: Vec<usize>,
    /// Mean angular jerk around the seams, rad/s³.
    pub seam_jerk_mean: f64,
    /// Peak angular jerk around the seams, rad/s³.
    pub seam_jerk_peak: f64,
    /// Mean angular jerk inside the segments, rad/s³.
    pub inside_jerk_mean: f64,
    /// Mean S over the seams.
    pub mean_s: f64,
    /// Σ C over the seams.
    pub total_cost: f64,
}

/// One strategy over every pin set.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StrategyRow {
    /// The strategy.
    pub strategy: Strategy,
    /// Mean seam jerk per dance, over the pin sets, rad/s³.
    pub seam_jerk_mean: Spread,
    /// Peak seam jerk per dance, rad/s³.
    pub seam_jerk_peak: Spread,
    /// Mean jerk inside the segments per dance (the scale), rad/s³.
    pub inside_jerk_mean: Spread,
    /// Mean S per dance.
    pub mean_s: Spread,
    /// Σ C per dance.
    pub total_cost: Spread,
    /// Every trial, pin set by pin set.
    pub trials: Vec<Trial>,
}

/// The outcome: one row per strategy, and how often connection-aware fill wins.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DanceFillOutcome {
    /// Segments in the database.
    pub segments: usize,
    /// The pins of every set.
    pub pins: Vec<Pins>,
    /// One row per strategy ([`STRATEGIES`] order).
    pub rows: Vec<StrategyRow>,
    /// Fraction of pin sets where connection-aware fill has a lower mean seam jerk than random
    /// fill.
    pub aware_beats_random_jerk: f64,
    /// The same against intensity-only fill.
    pub aware_beats_intensity_jerk: f64,
}

impl DanceFillOutcome {
    /// The row of `s`.
    pub fn row(&self, s: Strategy) -> &StrategyRow {
        self.rows
            .iter()
            .find(|r| r.strategy == s)
            .expect("every strategy has a row")
    }

    /// The table as text: one line per strategy, mean ± sd.
    pub fn table(&self) -> String {
        let mut out = format!(
            "{} pin sets over {} segments: mean ± sd over the pin sets\n{:<17} {:>24} {:>24} {:>24} {:>16} {:>16}\n",
            self.pins.len(),
            self.segments,
            "fill",
            "seam jerk mean rad/s³",
            "seam jerk peak rad/s³",
            "inside jerk rad/s³",
            "mean S",
            "Σ C"
        );
        for r in &self.rows {
            let f = |s: &Spread| format!("{:.0} ± {:.0}", s.mean, s.sd);
            out.push_str(&format!(
                "{:<17} {:>24} {:>24} {:>24} {:>16} {:>16}\n",
                format!("{:?}", r.strategy),
                f(&r.seam_jerk_mean),
                f(&r.seam_jerk_peak),
                f(&r.inside_jerk_mean),
                format!("{:.2} ± {:.2}", r.mean_s.mean, r.mean_s.sd),
                format!("{:.3} ± {:.3}", r.total_cost.mean, r.total_cost.sd),
            ));
        }
        out.push_str(&format!(
            "connection-aware seam jerk lower than random in {:.0} % of pin sets, than \
             intensity-only in {:.0} %\n",
            100.0 * self.aware_beats_random_jerk,
            100.0 * self.aware_beats_intensity_jerk
        ));
        out
    }
}

/// Why the experiment could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DanceFillError {
    /// Filling failed.
    #[error(transparent)]
    Fill(#[from] FillError),
    /// Assembling failed.
    #[error(transparent)]
    Dance(#[from] DanceError),
    /// A configuration that cannot run.
    #[error("dance-fill experiment: {0}")]
    Config(String),
}

/// Runs the experiment on `db` (module docs).
pub fn run(db: &Database, cfg: &DanceFillConfig) -> Result<DanceFillOutcome, DanceFillError> {
    let n = db.segments.len();
    check_config(n, cfg)?;
    let table = TransitionTable::new(db, &cfg.fill.transition).map_err(FillError::from)?;
    let bars: Vec<Bar> = (0..cfg.bars)
        .map(|k| Bar {
            start_s: k as f64 * cfg.bar_s,
            end_s: (k + 1) as f64 * cfg.bar_s,
            rms: 0.0,
            rms_db: f64::NEG_INFINITY,
        })
        .collect();
    let percentile = intensity_percentiles(db);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(cfg.seed);
    let mut all_pins = vec![];
    let mut trials: Vec<Vec<Trial>> = vec![vec![]; STRATEGIES.len()];
    for _ in 0..cfg.pin_sets {
        let pins = random_pins(&mut rng, cfg.bars, cfg.pins_per_set, n);
        let music = music_profile(&mut rng, cfg.bars);
        for (i, s) in STRATEGIES.iter().enumerate() {
            let segments = match s {
                Strategy::ConnectionAware => {
                    fill_with_table(db, &table, &music, &pins, &cfg.fill)?.segments
                }
                Strategy::Random => {
                    blind_fill(cfg.bars, &pins, n, cfg.fill.no_adjacent_repeat, |_, _| {
                        rng.random_range(0..n)
                    })?
                }
                Strategy::IntensityOnly => blind_fill(
                    cfg.bars,
                    &pins,
                    n,
                    cfg.fill.no_adjacent_repeat,
                    |bar, skip| nearest_percentile(&percentile, music[bar], skip),
                )?,
            };
            trials[i].push(trial(db, &segments, &bars, cfg)?);
        }
        all_pins.push(pins);
    }
    let wins = |other: usize| -> f64 {
        let w = trials[0]
            .iter()
            .zip(&trials[other])
            .filter(|(a, b)| a.seam_jerk_mean < b.seam_jerk_mean)
            .count();
        w as f64 / cfg.pin_sets.max(1) as f64
    };
    let (aware_beats_random_jerk, aware_beats_intensity_jerk) = (wins(1), wins(2));
    let rows = STRATEGIES
        .iter()
        .zip(trials)
        .map(|(&strategy, t)| strategy_row(strategy, t))
        .collect();
    Ok(DanceFillOutcome {
        segments: n,
        pins: all_pins,
        rows,
        aware_beats_random_jerk,
        aware_beats_intensity_jerk,
    })
}

/// A fill of `cfg.bars` bars from `n` segments is possible, with at most one pin per bar
/// and bars of positive length.
fn check_config(n: usize, cfg: &DanceFillConfig) -> Result<(), DanceFillError> {
    check(n, cfg.bars, &Pins::new())?;
    if cfg.pins_per_set > cfg.bars {
        return Err(DanceFillError::Config(format!(
            "{} pins per set on {} bars",
            cfg.pins_per_set, cfg.bars
        )));
    }
    if !(cfg.bar_s.is_finite() && cfg.bar_s > 0.0) {
        return Err(DanceFillError::Config(format!(
            "bar length {} s must be positive",
            cfg.bar_s
        )));
    }
    Ok(())
}

/// A strategy's row: the spread of each seam figure over its trials.
fn strategy_row(strategy: Strategy, t: Vec<Trial>) -> StrategyRow {
    let col = |f: fn(&Trial) -> f64| Spread::of(&t.iter().map(f).collect::<Vec<_>>());
    StrategyRow {
        strategy,
        seam_jerk_mean: col(|t| t.seam_jerk_mean),
        seam_jerk_peak: col(|t| t.seam_jerk_peak),
        inside_jerk_mean: col(|t| t.inside_jerk_mean),
        mean_s: col(|t| t.mean_s),
        total_cost: col(|t| t.total_cost),
        trials: t,
    }
}

/// The dance of `segments` and its seam numbers.
fn trial(
    db: &Database,
    segments: &[usize],
    bars: &[Bar],
    cfg: &DanceFillConfig,
) -> Result<Trial, DanceFillError> {
    // The bars have no song: their beats are the quarters of each bar.
    let beats: Vec<f64> = bars
        .iter()
        .flat_map(|b| (0..4).map(move |c| b.start_s + 0.25 * c as f64 * (b.end_s - b.start_s)))
        .collect();
    let dance = assemble(db, segments, bars, &beats, &cfg.dance)?;
    let (seam, inside) = seam_jerk(&dance);
    let connections: Vec<_> = segments
        .windows(2)
        .map(|w| connection(&db.segments[w[0]], &db.segments[w[1]], &cfg.fill.transition))
        .collect();
    let seams = connections.len().max(1) as f64;
    Ok(Trial {
        segments: segments.to_vec(),
        seam_jerk_mean: seam.mean_rad_s3,
        seam_jerk_peak: seam.peak_rad_s3,
        inside_jerk_mean: inside.mean_rad_s3,
        mean_s: connections.iter().map(|c| c.s).sum::<f64>() / seams,
        total_cost: connections.iter().map(|c| c.cost).sum(),
    })
}

/// `count` pins on distinct random bars, each to a random segment.
fn random_pins(rng: &mut impl Rng, bars: usize, count: usize, n: usize) -> Pins {
    let mut pins = Pins::new();
    while pins.len() < count {
        pins.insert(rng.random_range(0..bars), rng.random_range(0..n));
    }
    pins
}

/// A music-intensity profile in percentiles: a random walk from a random start, steps of up to
/// ±0.25, clamped to [0, 1].
fn music_profile(rng: &mut impl Rng, bars: usize) -> Vec<f64> {
    let mut x: f64 = rng.random_range(0.0..1.0);
    (0..bars)
        .map(|_| {
            let v = x;
            x = (x + rng.random_range(-0.25..0.25)).clamp(0.0, 1.0);
            v
        })
        .collect()
}

/// Every segment's motion-intensity percentile: its rank over n − 1 (0 the calmest, 1 the most
/// intense; ties by index).
pub fn intensity_percentiles(db: &Database) -> Vec<f64> {
    let n = db.segments.len();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| {
        db.segments[a]
            .intensity
            .total_cmp(&db.segments[b].intensity)
            .then(a.cmp(&b))
    });
    let mut p = vec![0.0; n];
    for (rank, &s) in order.iter().enumerate() {
        p[s] = if n > 1 {
            rank as f64 / (n - 1) as f64
        } else {
            0.5
        };
    }
    p
}

/// The segment whose percentile is nearest `target`, other than those in `skip` (ties by index).
fn nearest_percentile(p: &[f64], target: f64, skip: &[usize]) -> usize {
    (0..p.len())
        .filter(|s| !skip.contains(s))
        .min_by(|&a, &b| {
            (p[a] - target)
                .abs()
                .total_cmp(&(p[b] - target).abs())
                .then(a.cmp(&b))
        })
        .unwrap_or(0)
}

/// A connection-blind fill: pins kept, every other bar from `choose(bar, segments to avoid)`,
/// drawn again (up to 64 times) while it repeats a neighbour under `no_repeat`.
fn blind_fill(
    bars: usize,
    pins: &Pins,
    n: usize,
    no_repeat: bool,
    mut choose: impl FnMut(usize, &[usize]) -> usize,
) -> Result<Vec<usize>, FillError> {
    let mut out: Vec<Option<usize>> = (0..bars).map(|b| pins.get(&b).copied()).collect();
    for b in 0..bars {
        if out[b].is_some() {
            continue;
        }
        let skip: Vec<usize> = if no_repeat {
            [
                b.checked_sub(1).and_then(|p| out[p]),
                out.get(b + 1).copied().flatten(),
            ]
            .into_iter()
            .flatten()
            .collect()
        } else {
            vec![]
        };
        let mut s = choose(b, &skip);
        let mut tries = 0;
        while skip.contains(&s) {
            tries += 1;
            if tries > 64 || skip.len() >= n {
                return Err(FillError::NoPath { segments: n });
            }
            s = choose(b, &skip);
        }
        out[b] = Some(s);
    }
    Ok(out.into_iter().map(|s| s.unwrap_or(0)).collect())
}
