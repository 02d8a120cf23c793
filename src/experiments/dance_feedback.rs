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
//! Whether the likes steer the search at all is measured against a twin of every trial with the
//! likes withheld: the same target and bar, the simulated user choosing the same way after every
//! round, but the search never told (L_l stays empty). The twins' round 0 is the same. For round
//! k ≥ 1 the measure is the likes' pull, the mean Eros similarity of the round's candidates C to
//! the set L of segments the user liked (or, in the twin, would have liked) after rounds 0 to
//! k − 1: (1 / |C||L|) Σ_{c ∈ C} Σ_{l ∈ L} Sim(c, l), averaged over the trials. The gain is the
//! trials' mean of the pull with likes minus the pull withheld (paired, the same seeds), given
//! with its standard error; [`RoundOutcome::changed`] counts the trials whose round showed other
//! candidates, or the same in another order, than its twin. Round 2 (after two rounds with
//! likes) is the one the editor's user meets first after liking twice.
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
    /// Mean over the trials of the likes' pull (module docs): the mean Eros similarity of the
    /// round's candidates to the segments liked after the earlier rounds (`None` in round 0).
    pub liked_similarity: Option<f64>,
    /// The same with the likes withheld from the search (the twin trials; `None` in round 0).
    pub liked_similarity_withheld: Option<f64>,
    /// Standard error of the paired gain `liked_similarity − liked_similarity_withheld` (the sd
    /// of the trials' differences over √trials; `None` in round 0).
    pub liked_gain_se: Option<f64>,
    /// Fraction of the trials whose candidates in this round differ, as a list in order, from
    /// those of the twin with the likes withheld.
    pub changed: f64,
}

impl RoundOutcome {
    /// The likes' paired gain in pull (with minus withheld) and its standard error, from round 1.
    pub fn liked_gain(&self) -> Option<(f64, f64)> {
        Some((
            self.liked_similarity? - self.liked_similarity_withheld?,
            self.liked_gain_se?,
        ))
    }
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
            "round  tau     eq.9 mean D (sd)     best Sim to target (sd)  mean Sim  target \
                     shown  pull of likes: with / withheld  gain (se)          changed\n"
                .to_string();
        for r in &self.rounds {
            let pull = match (
                r.liked_similarity,
                r.liked_similarity_withheld,
                r.liked_gain(),
            ) {
                (Some(a), Some(b), Some((g, se))) => {
                    format!("{a:.4} / {b:.4}                 {g:+.4} ({se:.4})")
                }
                _ => format!("{:<46}", "—"),
            };
            s += &format!(
                "{:>5}  {:.4}  {:.4} ({:.4})      {:.4} ({:.4})          {:.4}    {:>5.1} %     \
                 {pull}  {:>5.1} %\n",
                r.round,
                r.tau,
                r.mean_dissimilarity,
                r.sd_dissimilarity,
                r.target_similarity,
                r.sd_target_similarity,
                r.mean_target_similarity,
                100.0 * r.target_found,
                100.0 * r.changed
            );
        }
        s
    }
}

/// One round of one trial.
#[derive(Debug, Clone, Copy)]
struct Row {
    /// Eq. (9) of the candidates.
    spread: f64,
    /// Highest Sim of a candidate to the target.
    best: f64,
    /// Mean Sim of the candidates to the target.
    mean: f64,
    /// Whether the target was shown.
    found: bool,
    /// The likes' pull with likes and withheld (0 in round 0).
    pull: f64,
    pull_withheld: f64,
    /// Whether the candidates differ from the twin's.
    changed: bool,
}

/// One trial: a row per round.
type Trial = Vec<Row>;

/// Runs the experiment on `db` (module docs).
pub fn run(db: &Database, cfg: &FeedbackConfig) -> Result<FeedbackOutcome, FeedbackError> {
    check_config(db, cfg)?;
    let index = SearchIndex::new(db);
    let n = index.len();
    let trials: Vec<Trial> = (0..cfg.trials)
        .into_par_iter()
        .map(|t| run_trial(&index, cfg, t))
        .collect::<Result<_, SearchError>>()?;
    let rounds = (0..cfg.rounds)
        .map(|k| round_outcome(cfg, &trials, k))
        .collect();
    Ok(FeedbackOutcome {
        config: cfg.clone(),
        segments: n,
        rounds,
    })
}

/// The search's settings, at least one round, trial and bar, two candidates a round and
/// enough segments in `db` for every round's candidates.
fn check_config(db: &Database, cfg: &FeedbackConfig) -> Result<(), FeedbackError> {
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
    Ok(())
}

/// Trial `t`: a target segment and a bar drawn from the trial's seed, then the rounds of the
/// search told the likes of the candidates closest to the target, beside its twin never told.
fn run_trial(index: &SearchIndex, cfg: &FeedbackConfig, t: usize) -> Result<Trial, SearchError> {
    let mut rng = Pcg64::seed_from_u64(
        cfg.seed
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .wrapping_add(t as u64),
    );
    let target = rng.random_range(0..index.len());
    let bar = rng.random_range(0..cfg.bars);
    let q = if cfg.bars == 1 {
        0.5
    } else {
        bar as f64 / (cfg.bars - 1) as f64
    };
    // The trial, and its twin whose likes the search is never told.
    let (mut state, mut twin) = (BarSearch::new(), BarSearch::new());
    let mut would_like = vec![];
    let mut rows = Vec::with_capacity(cfg.rounds);
    for _ in 0..cfg.rounds {
        let shown = index.round(q, &mut state, &cfg.search)?;
        let withheld = index.round(q, &mut twin, &cfg.search)?;
        let sims: Vec<f64> = shown.iter().map(|&m| index.sim(m, target)).collect();
        let best = sims.iter().copied().fold(0.0, f64::max);
        let mean = sims.iter().sum::<f64>() / sims.len() as f64;
        rows.push(Row {
            spread: index.mean_dissimilarity(&shown),
            best,
            mean,
            found: shown.contains(&target),
            pull: pull(index, &shown, &state.liked),
            pull_withheld: pull(index, &withheld, &would_like),
            changed: shown != withheld,
        });
        for m in closest(index, &shown, target, cfg.liked_per_round) {
            state.like(m, true);
        }
        would_like.extend(closest(index, &withheld, target, cfg.liked_per_round));
    }
    Ok(rows)
}

/// Round `k` over the trials: each figure's mean and standard deviation.
fn round_outcome(cfg: &FeedbackConfig, trials: &[Trial], k: usize) -> RoundOutcome {
    let stats = |f: &dyn Fn(&Row) -> f64, k: usize| -> (f64, f64) {
        let xs: Vec<f64> = trials.iter().map(|t| f(&t[k])).collect();
        let m = xs.iter().sum::<f64>() / xs.len() as f64;
        let v = xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (xs.len().max(2) - 1) as f64;
        (m, v.sqrt())
    };
    let (mean_dissimilarity, sd_dissimilarity) = stats(&|r| r.spread, k);
    let (target_similarity, sd_target_similarity) = stats(&|r| r.best, k);
    let (mean_target_similarity, _) = stats(&|r| r.mean, k);
    let (target_found, _) = stats(&|r| if r.found { 1.0 } else { 0.0 }, k);
    let (changed, _) = stats(&|r| if r.changed { 1.0 } else { 0.0 }, k);
    let after_likes = k > 0 && cfg.liked_per_round > 0;
    let (with, withheld, gain) = (
        stats(&|r| r.pull, k).0,
        stats(&|r| r.pull_withheld, k).0,
        stats(&|r| r.pull - r.pull_withheld, k).1 / (cfg.trials as f64).sqrt(),
    );
    RoundOutcome {
        round: k,
        tau: cfg.search.tau(k),
        mean_dissimilarity,
        sd_dissimilarity,
        target_similarity,
        sd_target_similarity,
        mean_target_similarity,
        target_found,
        liked_similarity: after_likes.then_some(with),
        liked_similarity_withheld: after_likes.then_some(withheld),
        liked_gain_se: after_likes.then_some(gain),
        changed,
    }
}

/// The likes' pull: the mean Sim of `shown` to `liked` over every pair (0 for an empty set).
fn pull(index: &SearchIndex, shown: &[usize], liked: &[usize]) -> f64 {
    if shown.is_empty() || liked.is_empty() {
        return 0.0;
    }
    let sum: f64 = shown
        .iter()
        .flat_map(|&c| liked.iter().map(move |&l| index.sim(c, l)))
        .sum();
    sum / (shown.len() * liked.len()) as f64
}

/// The `n` of `shown` most similar (Eros) to `target`, the most similar first (ties to the
/// earlier shown): what the simulated user likes.
fn closest(index: &SearchIndex, shown: &[usize], target: usize, n: usize) -> Vec<usize> {
    let sims: Vec<f64> = shown.iter().map(|&m| index.sim(m, target)).collect();
    let mut by_sim: Vec<usize> = (0..shown.len()).collect();
    by_sim.sort_by(|&a, &b| sims[b].total_cmp(&sims[a]).then(a.cmp(&b)));
    by_sim.iter().take(n).map(|&k| shown[k]).collect()
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
        // Round 0 is the same with and without likes; later rounds measure their pull.
        assert_eq!(a.rounds[0].changed, 0.0);
        assert_eq!(a.rounds[0].liked_gain(), None);
        assert!(a.rounds[1..].iter().all(|r| r.liked_gain().is_some()));
        // Following the likes alone (τ_0 = 0), they change round 1 in most trials and pull it
        // toward them by far more than the noise.
        let follow = FeedbackConfig {
            search: SearchParams {
                tau0: 0.0,
                ..SearchParams::default()
            },
            ..cfg.clone()
        };
        let f = run(&db, &follow).unwrap();
        let (gain, se) = f.rounds[1].liked_gain().unwrap();
        assert!(f.rounds[1].changed > 0.5, "{}", f.table());
        assert!(gain > 3.0 * se && gain > 0.0, "{}", f.table());
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
