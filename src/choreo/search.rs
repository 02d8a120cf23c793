//! Search with relevance feedback for the bar being edited: the dance-editing paper's eqs.
//! (1)–(4), after Dou et al. 2011.
//!
//! The next candidate is m_{n+1} = argmax_{m ∈ U \ S_n} ρ·rel(q, m) + (1 − ρ)·Φ(m, S_n, L_l)
//! (eq. 1), with Φ = τ·min_{m_i ∈ S_n} D(m, m_i) + (1 − τ)·max_{m_j ∈ L_l} Sim(m, m_j) (eq. 3):
//! U the database's segments, S_n the n segments already shown for this bar (over every round,
//! so a shown segment never comes back), L_l the ones the user liked, rel from
//! [`super::relevance`], Sim = Eros ∈ [0, 1] and D = √(2 − 2·Eros) ∈ [0, √2], its dissimilarity
//! ([`super::eros::eros_distance`]). Eq. (1) is incremental: the [`SearchParams::candidates`]
//! (six) of one round are chosen one after another, each added to S_n before the next, so each
//! new one is far from all shown before it, in earlier rounds and in this one. The paper leaves
//! the min over an empty S_n (the very first pick) and the max over an empty L_l undefined;
//! here both terms are 0 then, so the first candidate of a bar is the best match of intensity
//! alone (argmax rel) and the next five spread out from it. τ_k = decay·τ_{k−1} (eq. 4), so
//! τ_k = τ_0·decay^k with k the bar's round ([`SearchParams::tau`]); the paper's τ_0 = 1 and
//! decay = 0.95 are the defaults: round 0 is pure diversity and the likes weigh only 1 − 0.95
//! = 5 % of Φ in the first re-search. A smaller τ_0 (the editor's "explore ↔ follow my likes")
//! lets the likes steer from the first re-search on. τ is computed from the round, not kept,
//! so a τ_0 changed mid-search applies to the bar's next rounds. When U \ S_n runs out, a
//! round shows fewer candidates, and none once every segment was shown;
//! [`BarSearch::start_over`] empties S_n of all but the likes (which stay) so that the bar can
//! be searched again.
//!
//! Speed: a round over N segments is exact but does not compute N·|S_n| Eros values. The Eros
//! axes are packed once per database ([`SearchIndex`]); per bar a cache (in [`BarSearch`], not
//! serialised) keeps max Sim over L_l per segment, updated by one pass per new like, and min D
//! over S_n per segment as far as it has been brought up to date. Since adding to S_n can only
//! lower min D, a stale min D bounds the score from above, so the argmax is found lazily (the
//! "lazy greedy" of Minoux 1978): candidates in a heap by their bound, the top one brought up to
//! date, picked once its exact score still tops the heap. The result is the same as a full scan
//! (tested against one), ties going to the lower segment index.

use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;
use std::sync::atomic::{AtomicU64, Ordering as AtomicOrdering};

use serde::{Deserialize, Serialize};

use super::database::Database;
use super::relevance::{motion_intensity, rel};

/// Why a search round could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SearchError {
    /// Search parameters out of range.
    #[error("search parameters: {message}")]
    Params {
        /// What was wrong.
        message: String,
    },
    /// A bar intensity that is not a number.
    #[error("the bar's normalised music intensity must be a finite number, found {value}")]
    Intensity {
        /// The value given.
        value: f64,
    },
    /// A segment index in the search state past the database's end.
    #[error("segment {segment} is not in the database ({segments} segments)")]
    NoSuchSegment {
        /// The index.
        segment: usize,
        /// Segments in the database.
        segments: usize,
    },
}

/// The parameters of eq. (1) and (4). Every field has a default (serde), so a scene gives only
/// the ones it changes: `search: (tau0: 0.5)`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SearchParams {
    /// ρ ∈ [0, 1]: the weight of rel against Φ in eq. (1).
    pub rho: f64,
    /// Candidates shown per round (the paper's six), ≥ 1.
    pub candidates: usize,
    /// τ_0 ∈ [0, 1] of eq. (4): the weight of diversity against the likes in a bar's first
    /// round (the paper's 1; 0 follows the likes alone).
    pub tau0: f64,
    /// τ_k / τ_{k−1} of eq. (4) ∈ (0, 1] (the paper's 19/20).
    pub tau_decay: f64,
}

impl Default for SearchParams {
    /// ρ = 0.5 (the paper gives no value; intensity match and Φ weigh the same), six candidates,
    /// the paper's τ_0 = 1 and decay 0.95.
    fn default() -> SearchParams {
        SearchParams {
            rho: 0.5,
            candidates: 6,
            tau0: 1.0,
            tau_decay: 0.95,
        }
    }
}

impl SearchParams {
    /// Checks the ranges (ρ ∈ [0, 1], candidates ≥ 1, τ_0 ∈ [0, 1], decay ∈ (0, 1]).
    pub fn check(&self) -> Result<(), SearchError> {
        let message = if !(0.0..=1.0).contains(&self.rho) {
            format!("rho must lie in [0, 1], found {}", self.rho)
        } else if self.candidates == 0 {
            "candidates must be at least 1, found 0".to_string()
        } else if !(0.0..=1.0).contains(&self.tau0) {
            format!(
                "tau0 must lie in [0, 1] (1: diversity only, 0: likes only), found {}",
                self.tau0
            )
        } else if !(self.tau_decay > 0.0 && self.tau_decay <= 1.0) {
            format!("tau_decay must lie in (0, 1], found {}", self.tau_decay)
        } else {
            return Ok(());
        };
        Err(SearchError::Params { message })
    }

    /// τ_k = τ_0·decay^k of eq. (4): τ of a bar's round `k` (0 its first).
    pub fn tau(&self, k: usize) -> f64 {
        self.tau0 * self.tau_decay.powi(k.min(i32::MAX as usize) as i32)
    }
}

/// The search state of one bar: the round k (τ_k = [`SearchParams::tau`]`(k)`), S_n, L_l and
/// the candidates of the last round.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BarSearch {
    /// S_n: every segment shown for this bar, in the order shown (never shown again).
    pub shown: Vec<usize>,
    /// L_l: the shown segments the user liked, in the order liked (kept by
    /// [`BarSearch::start_over`]).
    pub liked: Vec<usize>,
    /// The candidates of the last round (empty before the first).
    pub current: Vec<usize>,
    /// Rounds run so far (the k of the next round).
    pub round: usize,
    /// Per-segment min D and max Sim (module docs); rebuilt when absent.
    #[serde(skip)]
    cache: Option<Cache>,
}

impl PartialEq for BarSearch {
    /// The same state (the cache, which only saves time, is ignored).
    fn eq(&self, o: &BarSearch) -> bool {
        self.shown == o.shown
            && self.liked == o.liked
            && self.current == o.current
            && self.round == o.round
    }
}

impl Default for BarSearch {
    /// Before the first round: nothing shown or liked.
    fn default() -> BarSearch {
        BarSearch {
            shown: vec![],
            liked: vec![],
            current: vec![],
            round: 0,
            cache: None,
        }
    }
}

impl BarSearch {
    /// A bar before its first round.
    pub fn new() -> BarSearch {
        BarSearch::default()
    }

    /// Adds `segment` to L_l (once) or, with `liked` false, takes it out.
    pub fn like(&mut self, segment: usize, liked: bool) {
        let at = self.liked.iter().position(|&s| s == segment);
        match (at, liked) {
            (None, true) => self.liked.push(segment),
            (Some(i), false) => {
                self.liked.remove(i);
            }
            _ => {}
        }
    }

    /// Starts the bar's search over: round 0 again (τ back to τ_0), no current candidates, and
    /// S_n emptied of everything but the likes, so that every segment not liked can come back.
    /// The likes L_l are kept: they are what the user chose, the editor keeps showing them in
    /// their own row, and they steer the new search as before (from round 0 when τ_0 < 1).
    /// They stay in S_n, as a liked segment always is, so the new rounds show only segments not
    /// liked: both what is like the likes and what differs from them.
    pub fn start_over(&mut self) {
        self.shown.clone_from(&self.liked);
        self.current.clear();
        self.round = 0;
        // The cache's min D was over the old S_n: a fresh one is taken at the next round.
        self.cache = None;
    }
}

/// The per-bar cache: which index it belongs to, the S_n and L_l prefixes it accounts for, and
/// per segment min D (over the first `md_count[m]` of `shown`) and max Sim (over `liked`).
#[derive(Debug, Clone)]
struct Cache {
    index: u64,
    shown: Vec<usize>,
    md: Vec<f64>,
    md_count: Vec<u32>,
    liked: Vec<usize>,
    ms: Vec<f64>,
}

static NEXT_INDEX: AtomicU64 = AtomicU64::new(1);

/// A database packed for search: every segment's Eros axes in one flat array (segments × axes ×
/// dimensions, missing axes zero), the Eros weights, and each segment's normalised motion
/// intensity ([`super::relevance::motion_intensity`]). The axes are stored in single precision
/// (half the memory a pass over them streams; sums in double precision), so Sim is within
/// 1e-6 of [`super::eros::eros`].
#[derive(Debug, Clone)]
pub struct SearchIndex {
    id: u64,
    segments: usize,
    axes: usize,
    dims: usize,
    vectors: Vec<f32>,
    weights: Vec<f64>,
    /// rest[k] = Σ_{i≥k} w_i (rest[axes] = 0).
    rest: Vec<f64>,
    motion: Vec<f64>,
}

/// ⟨x, y⟩ with eight partial sums in single precision (so that it vectorises on any x86-64),
/// added up in double precision.
fn dot(x: &[f32], y: &[f32]) -> f64 {
    let mut acc = [0.0f32; 8];
    let (xc, yc) = (x.chunks_exact(8), y.chunks_exact(8));
    let (xr, yr) = (xc.remainder(), yc.remainder());
    for (a, b) in xc.zip(yc) {
        for k in 0..8 {
            acc[k] += a[k] * b[k];
        }
    }
    let tail: f64 = xr.iter().zip(yr).map(|(a, b)| *a as f64 * *b as f64).sum();
    acc.iter().map(|&a| a as f64).sum::<f64>() + tail
}

/// D = √(2 − 2 Sim).
fn distance(sim: f64) -> f64 {
    (2.0 - 2.0 * sim).max(0.0).sqrt()
}

/// A score with a total order, for the heap.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Score(f64);
impl Eq for Score {}
impl PartialOrd for Score {
    fn partial_cmp(&self, o: &Score) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Score {
    fn cmp(&self, o: &Score) -> Ordering {
        self.0.total_cmp(&o.0)
    }
}

impl SearchIndex {
    /// Packs `db` (its segments' Eros axes, its Eros weights, its motion intensities).
    pub fn new(db: &Database) -> SearchIndex {
        let segments = db.segments.len();
        let axes = db.eros_weights.len();
        let dims = db
            .segments
            .iter()
            .flat_map(|s| s.eros.vectors.first())
            .map(|v| v.len())
            .max()
            .unwrap_or(0);
        let mut vectors = vec![0.0f32; segments * axes * dims];
        for (k, s) in db.segments.iter().enumerate() {
            for (i, v) in s.eros.vectors.iter().take(axes).enumerate() {
                let at = (k * axes + i) * dims;
                for (x, y) in vectors[at..at + dims].iter_mut().zip(v) {
                    *x = *y as f32;
                }
            }
        }
        let mut rest = vec![0.0; axes + 1];
        for i in (0..axes).rev() {
            rest[i] = rest[i + 1] + db.eros_weights[i].max(0.0);
        }
        SearchIndex {
            rest,
            id: NEXT_INDEX.fetch_add(1, AtomicOrdering::Relaxed),
            segments,
            axes,
            dims,
            vectors,
            weights: db.eros_weights.clone(),
            motion: motion_intensity(db),
        }
    }

    /// Number of segments.
    pub fn len(&self) -> usize {
        self.segments
    }

    /// Whether the database had no segment.
    pub fn is_empty(&self) -> bool {
        self.segments == 0
    }

    /// Normalised motion intensity of every segment (percentile ranks, [`super::relevance`]).
    pub fn motion_intensity(&self) -> &[f64] {
        &self.motion
    }

    /// Sim(a, b) = Eros(a, b) ∈ [0, 1] ([`super::eros::eros`]) between segments `a` and `b`.
    pub fn sim(&self, a: usize, b: usize) -> f64 {
        self.sim_above(a, b, f64::NEG_INFINITY).unwrap_or(0.0)
    }

    /// Sim(a, b), or `None` once the axes summed so far show that it is at most `floor`: the
    /// terms w_i·|⟨a_i, b_i⟩| of the axes not yet summed are each at most w_i (unit axes), so
    /// after axis k, Sim ≤ Σ_{i≤k} + Σ_{i>k} w_i (plus a margin for the single-precision axes).
    /// Eros weights fall fast with the rank, so most comparisons that cannot change a min D or
    /// a max Sim stop after a few axes; a `Some` is the full sum, the same as [`Self::sim`].
    fn sim_above(&self, a: usize, b: usize, floor: f64) -> Option<f64> {
        let n = self.axes * self.dims;
        let (x, y) = (
            &self.vectors[a * n..(a + 1) * n],
            &self.vectors[b * n..(b + 1) * n],
        );
        let mut s = 0.0;
        for (i, w) in self.weights.iter().enumerate() {
            let r = i * self.dims..(i + 1) * self.dims;
            s += w * dot(&x[r.clone()], &y[r]).abs();
            if s + self.rest[i + 1] + 1e-5 <= floor {
                return None;
            }
        }
        Some(s.min(1.0))
    }

    /// D(a, b) = √(2 − 2 Eros(a, b)) ∈ [0, √2] ([`super::eros::eros_distance`]).
    pub fn dissimilarity(&self, a: usize, b: usize) -> f64 {
        distance(self.sim(a, b))
    }

    /// The mean pairwise dissimilarity of a set of segments, the paper's eq. (9)
    /// (1/15 Σ_{i<j} D(m_i, m_j) for six); 0 for fewer than two.
    pub fn mean_dissimilarity(&self, set: &[usize]) -> f64 {
        let mut sum = 0.0;
        let mut pairs = 0usize;
        for (i, &a) in set.iter().enumerate() {
            for &b in &set[i + 1..] {
                sum += self.dissimilarity(a, b);
                pairs += 1;
            }
        }
        if pairs == 0 { 0.0 } else { sum / pairs as f64 }
    }

    /// The objective of eq. (1) for a segment with normalised intensity `motion`, min D over S_n
    /// `md` and max Sim over L_l `ms` (both 0 for an empty set).
    pub fn objective(bar_intensity: f64, motion: f64, md: f64, ms: f64, tau: f64, rho: f64) -> f64 {
        rho * rel(bar_intensity, motion) + (1.0 - rho) * (tau * md + (1.0 - tau) * ms)
    }

    /// One round of eq. (1) for a bar of normalised music intensity `bar_intensity` (its
    /// percentile rank among the song's bars, [`super::relevance::music_intensity`]): up to
    /// `p.candidates` segments, each added to `state.shown` as chosen, at τ = `p.tau(k)` for
    /// the state's round k; then `state.current` is the round's candidates and the round count
    /// grows (so τ decays). With nothing left to show it
    /// returns no candidate and leaves the state as it was.
    pub fn round(
        &self,
        bar_intensity: f64,
        state: &mut BarSearch,
        p: &SearchParams,
    ) -> Result<Vec<usize>, SearchError> {
        self.check_round(bar_intensity, state, p)?;
        let n = self.segments;
        let mut cache = self.take_cache(state);
        self.add_likes(&mut cache, &state.liked);
        let (tau, rho) = (p.tau(state.round), p.rho);
        let mut is_shown = vec![false; n];
        for &s in &state.shown {
            is_shown[s] = true;
        }
        let score = |m: usize, md: f64, ms: f64| {
            Self::objective(bar_intensity, self.motion[m], md, ms, tau, rho)
        };
        let mut picks = vec![];
        let mut heap = BinaryHeap::new();
        let mut heap_stale = true;
        while picks.len() < p.candidates {
            if heap_stale {
                // Bounds from the cached min D; a segment never compared with S_n (none shown yet
                // when it was cached) is brought up to date first.
                let shown = &state.shown;
                heap = (0..n)
                    .filter(|&m| !is_shown[m])
                    .map(|m| {
                        if cache.md_count[m] == 0 && !shown.is_empty() {
                            self.bring_up_to_date(&mut cache, m, shown);
                        }
                        (Score(score(m, cache.md[m], cache.ms[m])), Reverse(m))
                    })
                    .collect();
                heap_stale = false;
            }
            let Some((_, Reverse(m))) = heap.pop() else {
                break;
            };
            if (cache.md_count[m] as usize) < state.shown.len() {
                self.bring_up_to_date(&mut cache, m, &state.shown);
                heap.push((Score(score(m, cache.md[m], cache.ms[m])), Reverse(m)));
                continue;
            }
            // Exact and still on top: the argmax of eq. (1) (ties to the lower index).
            let first = state.shown.is_empty();
            state.shown.push(m);
            cache.shown.push(m);
            is_shown[m] = true;
            picks.push(m);
            // From an empty S_n to one member, every min D rises from 0: rebuild the bounds.
            heap_stale = first;
        }
        state.cache = Some(cache);
        if !picks.is_empty() {
            state.current = picks.clone();
            state.round += 1;
        }
        Ok(picks)
    }

    /// [`round`](Self::round)'s checks: valid parameters, a finite bar intensity, and shown and
    /// liked segments of this index.
    fn check_round(
        &self,
        bar_intensity: f64,
        state: &BarSearch,
        p: &SearchParams,
    ) -> Result<(), SearchError> {
        p.check()?;
        if !bar_intensity.is_finite() {
            return Err(SearchError::Intensity {
                value: bar_intensity,
            });
        }
        let n = self.segments;
        if let Some(&segment) = state.shown.iter().chain(&state.liked).find(|&&s| s >= n) {
            return Err(SearchError::NoSuchSegment {
                segment,
                segments: n,
            });
        }
        Ok(())
    }

    /// Max Sim over L_l (`liked`): one pass over the segments for the likes the cache has not
    /// yet accounted for.
    fn add_likes(&self, cache: &mut Cache, liked: &[usize]) {
        let new_likes = &liked[cache.liked.len()..];
        if !new_likes.is_empty() {
            for (m, ms) in cache.ms.iter_mut().enumerate() {
                for &l in new_likes {
                    if let Some(x) = self.sim_above(m, l, *ms) {
                        *ms = ms.max(x);
                    }
                }
            }
            cache.liked.extend_from_slice(new_likes);
        }
    }

    /// The state's cache if it belongs to this index and its S_n and L_l are prefixes of the
    /// state's, else a fresh one.
    fn take_cache(&self, state: &mut BarSearch) -> Cache {
        let n = self.segments;
        let fresh = || Cache {
            index: self.id,
            shown: vec![],
            md: vec![0.0; n],
            md_count: vec![0; n],
            liked: vec![],
            ms: vec![0.0; n],
        };
        let mut c = match state.cache.take() {
            Some(c) if c.index == self.id && state.shown.starts_with(&c.shown) => c,
            _ => fresh(),
        };
        if !state.liked.starts_with(&c.liked) {
            c.liked.clear();
            c.ms.iter_mut().for_each(|x| *x = 0.0);
        }
        // The cache's S_n is the state's from here on (later members are taken lazily).
        c.shown = state.shown.clone();
        c
    }

    /// Brings segment `m`'s min D over S_n up to date with `shown`.
    fn bring_up_to_date(&self, cache: &mut Cache, m: usize, shown: &[usize]) {
        let from = cache.md_count[m] as usize;
        let mut md = if from == 0 {
            f64::INFINITY
        } else {
            cache.md[m]
        };
        for &s in &shown[from..] {
            // D(m, s) < md only if Sim(m, s) > 1 − md²/2.
            if let Some(x) = self.sim_above(m, s, 1.0 - 0.5 * md * md) {
                md = md.min(distance(x));
            }
        }
        cache.md[m] = if shown.is_empty() { 0.0 } else { md };
        cache.md_count[m] = shown.len() as u32;
    }
}

/// One round of eq. (1) on `db` ([`SearchIndex::round`]; this packs the database for the one
/// call: hold a [`SearchIndex`] to search repeatedly).
pub fn search_round(
    db: &Database,
    bar_intensity: f64,
    state: &mut BarSearch,
    p: &SearchParams,
) -> Result<Vec<usize>, SearchError> {
    SearchIndex::new(db).round(bar_intensity, state, p)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::choreo::eros::{Pca, eros, eros_distance};
    use crate::choreo::segments::Segment;
    use glam::{DQuat, DVec3};

    /// A database of `n` segments with random Eros axes (orthonormal in 6 dimensions, 3 kept)
    /// and random intensities: search needs nothing else.
    pub(crate) fn random_db(n: usize, seed: u64) -> Database {
        let mut s = seed.wrapping_mul(2_862_933_555_777_941_757).wrapping_add(7);
        let mut next = move || {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let segments = (0..n)
            .map(|k| {
                let rows: Vec<Vec<f64>> = (0..20)
                    .map(|_| (0..6).map(|j| (next() - 0.5) * (1.0 + j as f64)).collect())
                    .collect();
                let mut p = crate::choreo::eros::pca(&rows);
                p.values.truncate(3);
                p.vectors.truncate(3);
                Segment {
                    clip: 0,
                    bar: k,
                    start_s: 0.0,
                    end_s: 1.0,
                    root_translation: vec![DVec3::ZERO; 2],
                    root_rotation: vec![DQuat::IDENTITY; 2],
                    angles: vec![],
                    intensity: next() * 3.0,
                    eros: p,
                    first_directions: vec![],
                    last_directions: vec![],
                    first_velocities: vec![],
                    last_velocities: vec![],
                }
            })
            .collect::<Vec<_>>();
        let pcas: Vec<&Pca> = segments.iter().map(|s| &s.eros).collect();
        Database {
            format_version: 1,
            model: "humanoid24".into(),
            params: Default::default(),
            sources: vec![],
            skipped: vec![],
            eros_weights: crate::choreo::eros::eros_weights(&pcas),
            segments,
        }
    }

    /// Eq. (1) by a full scan over U \ S_n, every min and max recomputed.
    fn naive_round(
        db: &Database,
        index: &SearchIndex,
        q: f64,
        state: &mut BarSearch,
        p: &SearchParams,
    ) -> Vec<usize> {
        let mut picks = vec![];
        for _ in 0..p.candidates {
            let best = (0..db.segments.len())
                .filter(|m| !state.shown.contains(m))
                .map(|m| {
                    let md = state
                        .shown
                        .iter()
                        .map(|&s| index.dissimilarity(m, s))
                        .fold(f64::INFINITY, f64::min);
                    let md = if state.shown.is_empty() { 0.0 } else { md };
                    let ms = state
                        .liked
                        .iter()
                        .map(|&l| index.sim(m, l))
                        .fold(0.0, f64::max);
                    let tau = p.tau(state.round);
                    let s = SearchIndex::objective(q, index.motion[m], md, ms, tau, p.rho);
                    (m, s)
                })
                .fold(None, |b: Option<(usize, f64)>, (m, s)| match b {
                    Some((_, bs)) if bs >= s => b,
                    _ => Some((m, s)),
                });
            let Some((m, _)) = best else { break };
            state.shown.push(m);
            picks.push(m);
        }
        if !picks.is_empty() {
            state.current = picks.clone();
            state.round += 1;
        }
        picks
    }

    #[test]
    fn packed_eros_is_the_eros_of_the_module() {
        let db = random_db(12, 1);
        let index = SearchIndex::new(&db);
        for a in 0..12 {
            for b in 0..12 {
                let (x, y) = (&db.segments[a].eros, &db.segments[b].eros);
                let e = eros(x, y, &db.eros_weights);
                assert!((index.sim(a, b) - e).abs() < 1e-6);
                let d = eros_distance(x, y, &db.eros_weights);
                assert!((index.dissimilarity(a, b) - d).abs() < 2e-3);
            }
            assert!(index.dissimilarity(a, a) < 2e-3);
        }
    }

    #[test]
    fn lazy_rounds_are_the_full_scan_and_never_repeat() {
        let db = random_db(300, 2);
        let index = SearchIndex::new(&db);
        for (rho, q, tau0) in [
            (0.5, 0.8, 1.0),
            (0.0, 0.1, 1.0),
            (1.0, 0.5, 0.3),
            (0.2, 0.33, 0.5),
        ] {
            let p = SearchParams {
                rho,
                tau0,
                ..SearchParams::default()
            };
            let (mut fast, mut slow) = (BarSearch::new(), BarSearch::new());
            for round in 0..8 {
                let a = index.round(q, &mut fast, &p).unwrap();
                let b = naive_round(&db, &index, q, &mut slow, &p);
                assert_eq!(a, b, "rho {rho} round {round}");
                assert_eq!(fast, slow);
                assert_eq!(a.len(), 6);
                // The user likes the first and the fourth; unlikes an old like now and then.
                for s in [&mut fast, &mut slow] {
                    s.like(a[0], true);
                    s.like(a[3], true);
                    if round == 4 {
                        let old = s.liked[1];
                        s.like(old, false);
                    }
                }
            }
            let mut seen = fast.shown.clone();
            seen.sort();
            seen.dedup();
            assert_eq!(seen.len(), 48, "a shown segment came back");
            assert_eq!(fast.round, 8);
            // A state restored without its cache gives the same next round.
            let mut restored: BarSearch =
                serde_json::from_str(&serde_json::to_string(&fast).unwrap()).unwrap();
            assert_eq!(restored, fast);
            let a = index.round(q, &mut fast, &p).unwrap();
            assert_eq!(index.round(q, &mut restored, &p).unwrap(), a);
        }
    }

    #[test]
    fn tau_k_is_tau0_times_decay_to_the_k_and_out_of_range_is_refused() {
        let p = SearchParams {
            tau0: 0.4,
            tau_decay: 0.8,
            ..SearchParams::default()
        };
        let mut t = 0.4;
        for k in 0..12 {
            assert!(
                (p.tau(k) - t).abs() < 1e-15,
                "round {k}: {} vs {t}",
                p.tau(k)
            );
            t *= 0.8;
        }
        assert_eq!(SearchParams::default().tau(0), 1.0);
        assert_eq!(SearchParams::default().tau(1), 0.95);
        // The round runs at τ_k of the state's round: with τ_0 = 0 and ρ = 0 the first pick
        // after a like is the most similar to it (the liked one itself is already shown).
        let db = random_db(80, 6);
        let index = SearchIndex::new(&db);
        let follow = SearchParams {
            rho: 0.0,
            tau0: 0.0,
            ..SearchParams::default()
        };
        let mut s = BarSearch::new();
        let first = index.round(0.5, &mut s, &follow).unwrap();
        s.like(first[2], true);
        let next = index.round(0.5, &mut s, &follow).unwrap();
        let nearest = (0..80)
            .filter(|m| !first.contains(m))
            .max_by(|&a, &b| {
                index
                    .sim(a, first[2])
                    .total_cmp(&index.sim(b, first[2]))
                    .then(b.cmp(&a))
            })
            .unwrap();
        assert_eq!(next[0], nearest);
        // Out of range: a clear error naming the field.
        for (tau0, tau_decay) in [(1.5, 0.95), (-0.1, 0.95), (f64::NAN, 0.95), (0.5, 0.0)] {
            let bad = SearchParams {
                tau0,
                tau_decay,
                ..SearchParams::default()
            };
            let e = bad.check().unwrap_err().to_string();
            let field = if tau_decay == 0.0 {
                "tau_decay"
            } else {
                "tau0"
            };
            assert!(e.contains(field), "{e}");
        }
        // Old scenes without tau0 still read, with the paper's τ_0 = 1.
        let old: SearchParams =
            serde_json::from_str(r#"{"rho": 0.5, "candidates": 6, "tau_decay": 0.9}"#).unwrap();
        assert_eq!((old.tau0, old.tau_decay), (1.0, 0.9));
        // And as a scene writes them (RON): the old field set, or only the new field.
        let old: SearchParams =
            ron::from_str("(rho: 0.5, candidates: 6, tau_decay: 0.95)").unwrap();
        assert_eq!(old, SearchParams::default());
        let new: SearchParams = ron::from_str("(tau0: 0.5)").unwrap();
        assert_eq!((new.tau0, new.tau_decay, new.candidates), (0.5, 0.95, 6));
        assert!(
            ron::from_str::<SearchParams>("(tau_0: 0.5)").is_err(),
            "a misspelt field"
        );
    }

    #[test]
    fn start_over_shows_every_segment_again_and_keeps_the_likes() {
        let db = random_db(20, 8);
        let index = SearchIndex::new(&db);
        let p = SearchParams::default();
        let mut s = BarSearch::new();
        let first = index.round(0.5, &mut s, &p).unwrap();
        s.like(first[1], true);
        while !index.round(0.5, &mut s, &p).unwrap().is_empty() {}
        assert_eq!(s.shown.len(), 20);
        s.start_over();
        // Round 0, no candidate, S_n only the likes, the likes kept.
        assert_eq!((s.round, s.current.len()), (0, 0));
        assert_eq!(s.liked, vec![first[1]]);
        assert_eq!(s.shown, s.liked);
        // Every segment but the liked one comes back over the new rounds, none twice.
        let mut again = vec![];
        loop {
            let c = index.round(0.5, &mut s, &p).unwrap();
            if c.is_empty() {
                break;
            }
            again.extend(c);
        }
        again.sort();
        let others: Vec<usize> = (0..20).filter(|&m| m != first[1]).collect();
        assert_eq!(again, others);
        // The rounds after a start over are those of a fresh state holding the likes as shown
        // (the cache of the old S_n is not used), at τ_0 < 1 too.
        let follow = SearchParams {
            tau0: 0.3,
            ..SearchParams::default()
        };
        s.start_over();
        let mut fresh = BarSearch::new();
        fresh.shown.push(first[1]);
        fresh.like(first[1], true);
        for _ in 0..3 {
            assert_eq!(
                index.round(0.7, &mut s, &follow).unwrap(),
                index.round(0.7, &mut fresh, &follow).unwrap()
            );
        }
    }

    #[test]
    fn the_first_pick_matches_intensity_and_the_rest_spread() {
        let db = random_db(200, 3);
        let index = SearchIndex::new(&db);
        let mut s = BarSearch::new();
        let q = 0.9;
        let picks = index.round(q, &mut s, &SearchParams::default()).unwrap();
        let best_rel = (0..200)
            .max_by(|&a, &b| {
                rel(q, index.motion[a])
                    .total_cmp(&rel(q, index.motion[b]))
                    .then(b.cmp(&a))
            })
            .unwrap();
        assert_eq!(picks[0], best_rel);
        // ρ = 0: pure diversity; the six are more spread than six random ones.
        let mut s = BarSearch::new();
        let p = SearchParams {
            rho: 0.0,
            ..SearchParams::default()
        };
        let diverse = index.round(q, &mut s, &p).unwrap();
        let plain: Vec<usize> = (0..6).map(|k| k * 31).collect();
        assert!(index.mean_dissimilarity(&diverse) > index.mean_dissimilarity(&plain));
    }

    #[test]
    fn running_out_gives_fewer_then_none() {
        let db = random_db(10, 4);
        let index = SearchIndex::new(&db);
        let mut s = BarSearch::new();
        let p = SearchParams::default();
        assert_eq!(index.round(0.5, &mut s, &p).unwrap().len(), 6);
        assert_eq!(index.round(0.5, &mut s, &p).unwrap().len(), 4);
        let before = s.clone();
        assert!(index.round(0.5, &mut s, &p).unwrap().is_empty());
        assert_eq!(s, before);
        assert_eq!(s.current.len(), 4);
        // Bad input: clear errors.
        let bad = SearchParams {
            rho: 1.5,
            ..SearchParams::default()
        };
        assert!(matches!(
            index.round(0.5, &mut s, &bad),
            Err(SearchError::Params { .. })
        ));
        assert!(matches!(
            index.round(f64::NAN, &mut s, &p),
            Err(SearchError::Intensity { .. })
        ));
        let mut wrong = BarSearch::new();
        wrong.shown.push(10);
        assert_eq!(
            index.round(0.5, &mut wrong, &p),
            Err(SearchError::NoSuchSegment {
                segment: 10,
                segments: 10
            })
        );
        // An empty database shows nothing.
        let empty = SearchIndex::new(&random_db(0, 5));
        assert!(
            empty
                .round(0.5, &mut BarSearch::new(), &p)
                .unwrap()
                .is_empty()
        );
    }
}
