//! The dance-editing paper's Fig. 4 (§4.1): how the spread of the six candidates shown for a bar
//! narrows as the user re-searches with relevance feedback.
//!
//! A trial draws a bar of a song and a hidden target segment. A simulated user searches the bar
//! ([`crate::choreo::search`], eqs. 1–4) and, after every round, likes the
//! [`FeedbackConfig::liked_per_round`] candidates of that round most similar (Eros) to the target,
//! then searches again. Per round k = 0, 1, … (k = 0 the first search, k ≥ 1 the k-th
//! re-search) it records the mean pairwise dissimilarity of the candidates shown, the paper's
//! eq. (9), (1/15) Σ_{i<j} D(m_i, m_j) for six, and how similar the shown set is to the target
//! (the highest Eros of a candidate with it). Each outcome averages over the trials.
//!
//! A bar's music enters the search only through its normalised intensity, the percentile rank of
//! its RMS among the song's bars ([`crate::choreo::relevance`]): a song of B bars with distinct
//! levels has the ranks 0, 1/(B − 1), …, 1, so a random bar is a random one of those.
//! Trials are independent and seeded one by one from the configuration's seed, so the outcome
//! is the same on any number of threads.

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use rayon::prelude::*;

use crate::choreo::database::Database;
use crate::choreo::search::{BarSearch, SearchError, SearchIndex, SearchParams};

/// Why the experiment could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FeedbackError {
    /// A configuration value out of range.
    #[error("dance feedback experiment: {message}")]
    Config {
        /// What was wrong.
        message: String,
    },
    /// A database too small for the rounds asked for.
    #[error(
        "dance feedback experiment: {rounds} rounds of {candidates} candidates need {needed} \
         segments, the database has {segments}"
    )]
    TooFewSegments {
        /// Rounds asked for.
        rounds: usize,
        /// Candidates per round.
        candidates: usize,
        /// Segments needed.
        needed: usize,
        /// Segments in the database.
        segments: usize,
    },
    /// The search.
    #[error(transparent)]
    Search(#[from] SearchError),
}

/// The experiment's configuration.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FeedbackConfig {
    /// Rounds per trial (the first search and `rounds − 1` re-searches).
    pub rounds: usize,
    /// Trials (random target and bar each).
    pub trials: usize,
    /// Candidates the simulated user likes after each round (the closest to the target).
    pub liked_per_round: usize,
    /// Bars of the song the bar is drawn from.
    pub bars: usize,
    /// The search.
    pub search: SearchParams,
    /// Seed of the trials.
    pub seed: u64,
}

impl Default for FeedbackConfig {
    /// Seven rounds (0–6), 400 trials, two likes per round, a song of 64 bars, the default
    /// search, seed 1.
    fn default() -> FeedbackConfig {
        FeedbackConfig {
            rounds: 7,
            trials: 400,
            liked_per_round: 2,
            bars: 64,
            search: SearchParams::default(),
            seed: 1,
        }
    }
}

/// What one round gave, over the trials.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RoundOutcome {
    /// The round (0 the first search, k the k-th re-search).
    pub round: usize,
    /// τ used in that round (eq. 4).
    pub tau: f64,
    /// Mean over the trials of eq. (9), the mean pairwise D of the candidates shown.
    pub mean_dissimilarity: f64,
    /// Its standard deviation over the trials.
    pub sd_dissimilarity: f64,
    /// Mean over the trials of the highest Eros similarity of a shown candidate to the target.
    pub target_similarity: f64,
    /// Its standard deviation over the trials.
    pub sd_target_similarity: f64,
    /// Mean over the trials of the mean Eros similarity of the shown candidates to the target.
    pub mean_target_similarity: f64,
    /// Fraction of the trials whose target was among the candidates shown in this round.
    pub target_found: f64,
}

/// The experiment's outcome: one row per round.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FeedbackOutcome {
    /// The configuration run.
    pub config: FeedbackConfig,
    /// Segments in the database.
    pub segments: usize,
    /// Per round.
    pub rounds: Vec<RoundOutcome>,
}

impl FeedbackOutcome {
    /// The outcome as a text table (one line per round).
    pub fn table(&self) -> String {
        let mut s =
            "round  tau     eq.9 mean D (sd)     best Sim to target (sd)  mean Sim  target shown\n"
                .to_string();
        for r in &self.rounds {
            s += &format!(
                "{:>5}  {:.4}  {:.4} ({:.4})      {:.4} ({:.4})          {:.4}    {:>5.1} %\n",
                r.round,
                r.tau,
                r.mean_dissimilarity,
                r.sd_dissimilarity,
                r.target_similarity,
                r.sd_target_similarity,
                r.mean_target_similarity,
                100.0 * r.target_found
            );
        }
        s
    }
}

/// One round of one trial: eq. (9), best Sim, mean Sim, whether the target was shown.
type Row = (f64, f64, f64, bool);

/// One trial: a row per round.
type Trial = Vec<Row>;

/// Runs the experiment on `db` (module docs).
pub fn run(db: &Database, cfg: &FeedbackConfig) -> Result<FeedbackOutcome, FeedbackError> {
    cfg.search.check()?;
    let config = |message: String| Err(FeedbackError::Config { message });
    if cfg.rounds == 0 || cfg.trials == 0 || cfg.bars == 0 {
        return config(format!(
            "rounds, trials and bars must be at least 1, found {}, {} and {}",
            cfg.rounds, cfg.trials, cfg.bars
        ));
    }
    if cfg.search.candidates < 2 {
        return config(format!(
            "eq. (9) needs at least two candidates per round, found {}",
            cfg.search.candidates
        ));
    }
    let needed = cfg.rounds * cfg.search.candidates;
    if db.segments.len() < needed {
        return Err(FeedbackError::TooFewSegments {
            rounds: cfg.rounds,
            candidates: cfg.search.candidates,
            needed,
            segments: db.segments.len(),
        });
    }
    let index = SearchIndex::new(db);
    let n = index.len();
    let trials: Vec<Trial> = (0..cfg.trials)
        .into_par_iter()
        .map(|t| {
            let mut rng = Pcg64::seed_from_u64(
                cfg.seed
                    .wrapping_mul(0x9E37_79B9_7F4A_7C15)
                    .wrapping_add(t as u64),
            );
            let target = rng.random_range(0..n);
            let bar = rng.random_range(0..cfg.bars);
            let q = if cfg.bars == 1 {
                0.5
            } else {
                bar as f64 / (cfg.bars - 1) as f64
            };
            let mut state = BarSearch::new();
            let mut rows = Vec::with_capacity(cfg.rounds);
            for _ in 0..cfg.rounds {
                let shown = index.round(q, &mut state, &cfg.search)?;
                let sims: Vec<f64> = shown.iter().map(|&m| index.sim(m, target)).collect();
                let best = sims.iter().copied().fold(0.0, f64::max);
                let mean = sims.iter().sum::<f64>() / sims.len() as f64;
                rows.push((
                    index.mean_dissimilarity(&shown),
                    best,
                    mean,
                    shown.contains(&target),
                ));
                let mut by_sim: Vec<usize> = (0..shown.len()).collect();
                by_sim.sort_by(|&a, &b| sims[b].total_cmp(&sims[a]).then(a.cmp(&b)));
                for &k in by_sim.iter().take(cfg.liked_per_round) {
                    state.like(shown[k], true);
                }
            }
            Ok(rows)
        })
        .collect::<Result<_, SearchError>>()?;
    let stats = |f: &dyn Fn(&Row) -> f64, k: usize| -> (f64, f64) {
        let xs: Vec<f64> = trials.iter().map(|t| f(&t[k])).collect();
        let m = xs.iter().sum::<f64>() / xs.len() as f64;
        let v = xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (xs.len().max(2) - 1) as f64;
        (m, v.sqrt())
    };
    let rounds = (0..cfg.rounds)
        .map(|k| {
            let (mean_dissimilarity, sd_dissimilarity) = stats(&|r| r.0, k);
            let (target_similarity, sd_target_similarity) = stats(&|r| r.1, k);
            let (mean_target_similarity, _) = stats(&|r| r.2, k);
            let (target_found, _) = stats(&|r| if r.3 { 1.0 } else { 0.0 }, k);
            RoundOutcome {
                round: k,
                tau: cfg.search.tau_decay.powi(k as i32),
                mean_dissimilarity,
                sd_dissimilarity,
                target_similarity,
                sd_target_similarity,
                mean_target_similarity,
                target_found,
            }
        })
        .collect();
    Ok(FeedbackOutcome {
        config: cfg.clone(),
        segments: n,
        rounds,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::choreo::search::tests::random_db;

    #[test]
    fn the_same_seed_gives_the_same_table_and_bad_configs_are_refused() {
        let db = random_db(120, 11);
        let cfg = FeedbackConfig {
            rounds: 4,
            trials: 30,
            ..FeedbackConfig::default()
        };
        let a = run(&db, &cfg).unwrap();
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| run(&db, &cfg).unwrap());
        assert_eq!(a, one);
        assert_eq!(a.rounds.len(), 4);
        assert!(a.table().lines().count() == 5);
        for r in &a.rounds {
            assert!(r.mean_dissimilarity > 0.0 && r.mean_dissimilarity <= 2f64.sqrt());
            assert!((0.0..=1.0).contains(&r.target_similarity));
        }
        let small = random_db(20, 1);
        assert!(matches!(
            run(&small, &cfg),
            Err(FeedbackError::TooFewSegments { needed: 24, .. })
        ));
        let zero = FeedbackConfig {
            trials: 0,
            ..cfg.clone()
        };
        assert!(matches!(run(&db, &zero), Err(FeedbackError::Config { .. })));
    }
}
