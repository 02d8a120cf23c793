//! Filling the bars the user did not pin (paper §3.2.1): the sequence of segments, one per bar,
//! of minimum summed transition cost Σ C (eqs. 5–8, [`super::transition`]) through every pinned
//! (bar, segment), before, between and after the pins, plus a music term: the path s_0 … s_{B−1}
//! costs Σ_k C(s_k → s_{k+1}) + λ Σ_k |p_music(k) − p_motion(s_k)|, the two intensities as
//! percentile ranks ([`super::relevance`]) and λ = κ·c̄ in units of the database's typical seam
//! cost c̄ ([`FillParams::intensity_weight`]), so that a loud bar takes an intense segment and a
//! quiet one a calm segment. λ = 0 ([`FillParams::paper`]) is the paper's fill. By default κ is
//! the largest of a halving ladder whose path keeps Σ C within a budget of the paper's fill's
//! ([`FillParams::seam_budget`]: the music may roughen the seams by so much and no more). The music term
//! is a weight on the nodes (bar k, segment s): both algorithms below add it where a path
//! enters a node, so they stay exact.
//!
//! The graph is layered: layer k holds bar k's choices (every segment of the database, or only
//! its pin), an edge joins each choice of bar k to each of bar k+1 with weight C(a → b) from the
//! [`TransitionTable`]; with [`FillParams::no_adjacent_repeat`] the edge a → a is left out
//! unless both bars are pinned (a repeat the user chose is kept). A source joins every choice
//! of bar 0 and every choice of the last bar joins the sink, both with weight 0.
//!
//! [`fill_dijkstra`] runs Dijkstra's algorithm on it (a binary heap, lazy deletion) with the consistent
//! potential h(k) = Σ_{j ≥ k} m_j, m_j the smallest weight between layers j and j+1, so that
//! nodes are settled in the order of d + h (Dijkstra on the reduced weights w − m_j ≥ 0, A*);
//! [`fill`] is the exact dynamic programme D_{k+1}(b) = min_a D_k(a) + C(a → b): each
//! D_{k+1}(b) is a minimum over the table's column b (contiguous in the table's column copy),
//! the columns in parallel with rayon, each minimum vectorised (the same IEEE sums at any
//! vector width, and a minimum does not depend on the order it is taken in, so the same bits on
//! any machine and thread count); the predecessors are recovered afterwards from the stored
//! D_k.
//!
//! A pinned bar has one choice, so the path splits there: the bars are cut at bar 0, at every
//! pin and at the last bar into runs (each from a cut to the next, sharing its pinned ends), and
//! each run's cheapest path is found on its own, with its sums starting from 0 at the run's
//! first bar; the fill is the runs' paths joined, its cost their sum. Both algorithms work run
//! by run; the DP advances every run's layer k in one pass over the table's columns, so a
//! column is read once for all the runs (with four pins the table is read about a third as
//! often as layer by layer). Both break ties the same way (at every node the
//! predecessor of smallest index among those of equal sum, and the end of smallest index among
//! equal totals), so they return the same path.

use std::cmp::Ordering;
use std::collections::{BTreeMap, BinaryHeap};

use serde::{Deserialize, Serialize};

use super::database::Database;
use super::relevance;
use super::transition::{
    Connection, TransitionError, TransitionParams, TransitionTable, connection,
};

/// Pins: bar index → segment index in the database.
pub type Pins = BTreeMap<usize, usize>;

/// Largest number of bars filled (graph nodes are bars × segments).
pub const MAX_BARS: usize = 100_000;

/// How bars are filled.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FillParams {
    /// The link weights of the connection score.
    #[serde(default)]
    pub transition: TransitionParams,
    /// No filled bar takes the segment of the bar before or after it (default true).
    #[serde(default = "yes")]
    pub no_adjacent_repeat: bool,
    /// κ, the weight of the music term: a path costs Σ C + λ Σ_k |p_music(k) − p_motion(s_k)|
    /// over its bars k and their segments s_k, both intensities as percentile ranks
    /// ([`super::relevance`]), with λ = κ·c̄, c̄ the database's typical seam cost
    /// ([`TransitionTable::typical_cost`]): a bar whose segment is the whole rank range off
    /// its music costs κ good seams, whatever the database's scale of C. 0 is the paper's fill
    /// (connection alone). With a [`FillParams::seam_budget`] it is the largest κ tried; the
    /// default is [`DEFAULT_INTENSITY_WEIGHT`].
    #[serde(default = "default_intensity_weight")]
    pub intensity_weight: f64,
    /// How much rougher than the paper's the seams may be for the music's sake: with `Some(b)`
    /// the fill takes the largest κ of `intensity_weight` · 2^−j (j = 0 … [`BUDGET_HALVINGS`])
    /// whose path's Σ C is at most b times the paper's fill's (κ = 0) through the same pins,
    /// else the paper's fill; the κ taken is [`Fill::intensity_weight`]. `None`: κ =
    /// `intensity_weight` as given. At least 1 (the paper's fill is the cheapest); default
    /// [`DEFAULT_SEAM_BUDGET`].
    #[serde(default = "default_seam_budget")]
    pub seam_budget: Option<f64>,
}

/// The default largest κ of [`FillParams::intensity_weight`]: a bar whose segment is the whole
/// rank range off its music costs two good seams. The seam budget lowers it where the
/// database's seams cannot follow the music so cheaply.
pub const DEFAULT_INTENSITY_WEIGHT: f64 = 2.0;

/// The default [`FillParams::seam_budget`]: the music may make the seams' Σ C at most 1.2 times
/// the paper's fill's.
pub const DEFAULT_SEAM_BUDGET: f64 = 1.2;

/// Halvings of κ the seam budget tries after the largest (κ down to 1/64 of it) before it
/// takes the paper's fill.
pub const BUDGET_HALVINGS: i32 = 6;

fn default_seam_budget() -> Option<f64> {
    Some(DEFAULT_SEAM_BUDGET)
}

fn default_intensity_weight() -> f64 {
    DEFAULT_INTENSITY_WEIGHT
}

fn yes() -> bool {
    true
}

impl Default for FillParams {
    /// Unit link weights, no adjacent repeat, κ up to [`DEFAULT_INTENSITY_WEIGHT`] within the
    /// seam budget [`DEFAULT_SEAM_BUDGET`].
    fn default() -> FillParams {
        FillParams {
            transition: TransitionParams::default(),
            no_adjacent_repeat: true,
            intensity_weight: DEFAULT_INTENSITY_WEIGHT,
            seam_budget: Some(DEFAULT_SEAM_BUDGET),
        }
    }
}

impl FillParams {
    /// The paper's fill: connection cost alone (κ = 0), unit link weights, no adjacent repeat.
    pub fn paper() -> FillParams {
        FillParams {
            intensity_weight: 0.0,
            ..FillParams::default()
        }
    }
}

/// A filled dance: one segment per bar.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Fill {
    /// The segment of every bar (pins included).
    pub segments: Vec<usize>,
    /// The connection of every seam, bar k → k+1 (bars − 1 of them).
    pub connections: Vec<Connection>,
    /// Σ C over the seams.
    pub total_cost: f64,
    /// Σ_k |p_music(k) − p_motion(s_k)| over the bars: how far the segments' intensities are
    /// from the music's, in percentile ranks (the path's cost is total_cost + λ times this).
    #[serde(default)]
    pub intensity_mismatch: f64,
    /// The κ the path was found with ([`FillParams::intensity_weight`], lowered by the seam
    /// budget where it had to be; 0 for the paper's fill).
    #[serde(default)]
    pub intensity_weight: f64,
}

/// Why bars could not be filled.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FillError {
    /// A database without segments.
    #[error("the dance database has no segments to fill bars with")]
    EmptyDatabase,
    /// No bars to fill.
    #[error("no bars to fill: the song has no bar")]
    NoBars,
    /// More bars than [`MAX_BARS`].
    #[error("{bars} bars are more than the {MAX_BARS} a fill takes")]
    TooManyBars {
        /// The bars asked for.
        bars: usize,
    },
    /// A pin on a bar past the song's end.
    #[error("pin on bar {bar}: the song has {bars} bars (0 to {})", bars.saturating_sub(1))]
    PinPastEnd {
        /// The pinned bar.
        bar: usize,
        /// The song's bar count.
        bars: usize,
    },
    /// A pin to a segment that is not in the database.
    #[error("pin on bar {bar}: segment {segment} does not exist (the database has {segments}, 0 to {})", segments.saturating_sub(1))]
    NoSuchSegment {
        /// The pinned bar.
        bar: usize,
        /// The segment asked for.
        segment: usize,
        /// The database's segment count.
        segments: usize,
    },
    /// No sequence satisfies the pins without an adjacent repeat.
    #[error(
        "no sequence of segments fills the bars: with no adjacent repeat, a filled bar needs a \
         segment other than its neighbours' ({segments} segments in the database)"
    )]
    NoPath {
        /// The database's segment count.
        segments: usize,
    },
    /// A transition table made for another database.
    #[error("the transition table is for {table} segments, the database has {segments}")]
    TableMismatch {
        /// Segments of the table.
        table: usize,
        /// Segments of the database.
        segments: usize,
    },
    /// The transition table could not be built.
    #[error(transparent)]
    Transition(#[from] TransitionError),
    /// A bar's music intensity rank outside [0, 1], or λ not a number ≥ 0.
    #[error("{message}")]
    Intensity {
        /// What was wrong.
        message: String,
    },
}

/// Checks the sizes and pins against a database of `segments` segments.
pub fn check(segments: usize, bars: usize, pins: &Pins) -> Result<(), FillError> {
    if segments == 0 {
        return Err(FillError::EmptyDatabase);
    }
    if bars == 0 {
        return Err(FillError::NoBars);
    }
    if bars > MAX_BARS {
        return Err(FillError::TooManyBars { bars });
    }
    for (&bar, &segment) in pins {
        if bar >= bars {
            return Err(FillError::PinPastEnd { bar, bars });
        }
        if segment >= segments {
            return Err(FillError::NoSuchSegment {
                bar,
                segment,
                segments,
            });
        }
    }
    Ok(())
}

/// Fills the bars through `pins` by the exact dynamic programme (module docs), building the
/// transition table of `db` first. `music` holds one value per bar: its music intensity as a
/// percentile rank in [0, 1] ([`super::relevance::music_intensity`]), which the music term
/// λ Σ |p_music − p_motion| weighs ([`FillParams::intensity_weight`]).
pub fn fill(db: &Database, music: &[f64], pins: &Pins, p: &FillParams) -> Result<Fill, FillError> {
    check(db.segments.len(), music.len(), pins)?;
    let table = TransitionTable::new(db, &p.transition)?;
    fill_with_table(db, &table, music, pins, p)
}

/// [`fill`] on a prepared transition table of `db` built with `p.transition`: the table depends
/// only on the database and the weights, so an editor builds it once.
pub fn fill_with_table(
    db: &Database,
    table: &TransitionTable,
    music: &[f64],
    pins: &Pins,
    p: &FillParams,
) -> Result<Fill, FillError> {
    solve(db, table, music, pins, p, dp_many)
}

/// The same fill by Dijkstra's algorithm (module docs), building the transition table first:
/// an independent way to the same path, slower on a large database (it settles nearly every
/// node).
pub fn fill_dijkstra(
    db: &Database,
    music: &[f64],
    pins: &Pins,
    p: &FillParams,
) -> Result<Fill, FillError> {
    check(db.segments.len(), music.len(), pins)?;
    let table = TransitionTable::new(db, &p.transition)?;
    fill_dijkstra_with_table(db, &table, music, pins, p)
}

/// [`fill_dijkstra`] on a prepared transition table of `db` built with `p.transition`.
pub fn fill_dijkstra_with_table(
    db: &Database,
    table: &TransitionTable,
    music: &[f64],
    pins: &Pins,
    p: &FillParams,
) -> Result<Fill, FillError> {
    solve(db, table, music, pins, p, |gs| {
        gs.iter().map(|g| g.dijkstra()).collect()
    })
}

/// Checks, then finds the path with `paths_of` (the paths of several graphs on one table): at κ = `p.intensity_weight`, or within the seam
/// budget ([`FillParams::seam_budget`]) at the largest κ of the halving ladder that keeps it.
fn solve(
    db: &Database,
    table: &TransitionTable,
    music: &[f64],
    pins: &Pins,
    p: &FillParams,
    paths_of: fn(&[&Graph<'_>]) -> Vec<Option<Vec<usize>>>,
) -> Result<Fill, FillError> {
    check(db.segments.len(), music.len(), pins)?;
    if table.n != db.segments.len() {
        return Err(FillError::TableMismatch {
            table: table.n,
            segments: db.segments.len(),
        });
    }
    let kappa = p.intensity_weight;
    if !(kappa.is_finite() && kappa >= 0.0) {
        return Err(FillError::Intensity {
            message: format!("fill.intensity_weight is {kappa}: expected a number ≥ 0"),
        });
    }
    if let Some(b) = p.seam_budget.filter(|b| !(b.is_finite() && *b >= 1.0)) {
        return Err(FillError::Intensity {
            message: format!(
                "fill.seam_budget is {b}: expected a number ≥ 1 (the paper's fill is the \
                 cheapest), or None"
            ),
        });
    }
    if let Some((k, v)) = music
        .iter()
        .enumerate()
        .find(|(_, v)| !(0.0..=1.0).contains(*v))
    {
        return Err(FillError::Intensity {
            message: format!(
                "bar {k}: music intensity rank {v}, expected a percentile rank in [0, 1]"
            ),
        });
    }
    let motion = relevance::motion_intensity(db);
    let graph = |kappa: f64| {
        let mut g = Graph::new(table, music.len(), pins, p.no_adjacent_repeat);
        if kappa > 0.0 {
            g.music = Some(Music {
                music,
                motion: &motion,
                lambda: kappa * table.typical_cost,
            });
        }
        g
    };
    // The fills at `kappas`, found together (one pass over the table for the DP).
    let fills = |kappas: &[f64]| -> Result<Vec<Fill>, FillError> {
        let graphs: Vec<Graph<'_>> = kappas.iter().map(|&k| graph(k)).collect();
        let refs: Vec<&Graph<'_>> = graphs.iter().collect();
        paths_of(&refs)
            .into_iter()
            .zip(kappas)
            .map(|(path, &kappa)| {
                let path = path.ok_or(FillError::NoPath { segments: table.n })?;
                let mut f = finish(db, path, &p.transition, music, &motion);
                f.intensity_weight = kappa;
                Ok(f)
            })
            .collect()
    };
    let Some(budget) = p.seam_budget.filter(|_| kappa > 0.0) else {
        return Ok(fills(&[kappa])?.remove(0));
    };
    // Σ C of the optimum never falls as κ grows (the parametric optimum of C + λM), so the
    // first κ from the top that keeps the budget is the largest of the ladder that does. The
    // paper's fill and the top rung are found together.
    let mut both = fills(&[0.0, kappa])?;
    let top = both.pop().expect("two fills");
    let paper = both.pop().expect("two fills");
    let within = |f: &Fill| f.total_cost <= budget * paper.total_cost;
    if within(&top) {
        return Ok(top);
    }
    for j in 1..=BUDGET_HALVINGS {
        let f = fills(&[kappa * 2f64.powi(-j)])?.remove(0);
        if within(&f) {
            return Ok(f);
        }
    }
    Ok(paper)
}

/// The fill of a path: its connections and their summed cost, and its intensity mismatch.
fn finish(
    db: &Database,
    segments: Vec<usize>,
    p: &TransitionParams,
    music: &[f64],
    motion: &[f64],
) -> Fill {
    let connections: Vec<Connection> = segments
        .windows(2)
        .map(|w| connection(&db.segments[w[0]], &db.segments[w[1]], p))
        .collect();
    let total_cost = connections.iter().fold(0.0, |s, c| s + c.cost);
    let intensity_mismatch = segments
        .iter()
        .zip(music)
        .fold(0.0, |s, (&m, &q)| s + (q - motion[m]).abs());
    Fill {
        segments,
        connections,
        total_cost,
        intensity_mismatch,
        intensity_weight: 0.0,
    }
}

/// The music term of a graph: λ |p_music(k) − p_motion(s)| at node (k, s).
#[derive(Clone, Copy)]
struct Music<'a> {
    /// p_music of every bar of the graph.
    music: &'a [f64],
    /// p_motion of every segment.
    motion: &'a [f64],
    /// λ.
    lambda: f64,
}

/// The layered graph of a fill.
struct Graph<'a> {
    table: &'a TransitionTable,
    bars: usize,
    /// The pin of every bar.
    pin: Vec<Option<usize>>,
    no_repeat: bool,
    /// The music term of the nodes (none: the paper's fill).
    music: Option<Music<'a>>,
}

impl<'a> Graph<'a> {
    fn new(table: &'a TransitionTable, bars: usize, pins: &Pins, no_repeat: bool) -> Graph<'a> {
        let mut pin = vec![None; bars];
        for (&b, &s) in pins {
            pin[b] = Some(s);
        }
        Graph {
            table,
            bars,
            pin,
            no_repeat,
            music: None,
        }
    }

    /// The node weight of segment s at bar k: λ |p_music(k) − p_motion(s)|, 0 without music.
    #[inline]
    fn node(&self, k: usize, s: usize) -> f64 {
        match self.music {
            Some(m) => m.lambda * (m.music[k] - m.motion[s]).abs(),
            None => 0.0,
        }
    }

    /// Whether the edge a (bar k) → b (bar k+1) exists.
    #[inline]
    fn edge(&self, k: usize, a: usize, b: usize) -> bool {
        !(self.no_repeat && a == b && (self.pin[k].is_none() || self.pin[k + 1].is_none()))
    }

    /// Whether segment s is a choice of bar k.
    #[inline]
    fn allowed(&self, k: usize, s: usize) -> bool {
        self.pin[k].is_none_or(|p| p == s)
    }

    /// The smallest weight between layers k and k+1.
    fn min_weight(&self, k: usize) -> f64 {
        let t = self.table;
        let n = t.n;
        match (self.pin[k], self.pin[k + 1]) {
            (Some(a), Some(b)) => t.cost(a, b),
            (Some(a), None) => (0..n)
                .filter(|&b| self.edge(k, a, b))
                .map(|b| t.cost(a, b))
                .fold(f64::INFINITY, f64::min),
            (None, Some(b)) => (0..n)
                .filter(|&a| self.edge(k, a, b))
                .map(|a| t.cost(a, b))
                .fold(f64::INFINITY, f64::min),
            (None, None) if self.no_repeat => t.min_cost_off_diagonal,
            (None, None) => t.min_cost,
        }
    }

    /// The potential h(k) = Σ_{j ≥ k} m_j of every layer (0 at the last; +∞ once a layer pair
    /// has no edge).
    fn potential(&self) -> Vec<f64> {
        let mut h = vec![0.0; self.bars];
        for k in (0..self.bars.saturating_sub(1)).rev() {
            h[k] = h[k + 1] + self.min_weight(k);
        }
        h
    }

    /// Dijkstra's algorithm with the potential (module docs) on the whole graph; `None`
    /// without a path. [`Graph::dijkstra`] runs it on each run.
    fn dijkstra_run(&self) -> Option<Vec<usize>> {
        let (n, bars) = (self.table.n, self.bars);
        let h = self.potential();
        if !h[0].is_finite() {
            return None;
        }
        let mut dist = vec![f64::INFINITY; n * bars];
        let mut pred = vec![u32::MAX; n * bars];
        let mut done = vec![false; n * bars];
        let mut heap = BinaryHeap::new();
        for s in (0..n).filter(|&s| self.allowed(0, s)) {
            dist[s] = self.node(0, s);
            heap.push(Node {
                f: dist[s] + h[0],
                k: 0,
                s: s as u32,
            });
        }
        while let Some(Node { k, s, .. }) = heap.pop() {
            let (k, s) = (k as usize, s as usize);
            let u = k * n + s;
            if done[u] {
                continue;
            }
            done[u] = true;
            if k + 1 == bars {
                let mut path = vec![s; bars];
                let mut v = u;
                for kk in (1..bars).rev() {
                    let a = pred[v] as usize;
                    path[kk - 1] = a;
                    v = (kk - 1) * n + a;
                }
                return Some(path);
            }
            let d = dist[u];
            let row = self.table.row(s);
            let next = (k + 1) * n;
            let mut relax = |t: usize| {
                if !self.edge(k, s, t) || done[next + t] {
                    return;
                }
                let nd = d + f64::from(row[t]) + self.node(k + 1, t);
                let v = next + t;
                if nd < dist[v] {
                    dist[v] = nd;
                    pred[v] = s as u32;
                    heap.push(Node {
                        f: nd + h[k + 1],
                        k: (k + 1) as u32,
                        s: t as u32,
                    });
                } else if nd == dist[v] && (s as u32) < pred[v] {
                    pred[v] = s as u32;
                }
            };
            match self.pin[k + 1] {
                Some(t) => relax(t),
                None => (0..n).for_each(relax),
            }
        }
        None
    }

    /// The runs of the fill: the inclusive bar ranges between consecutive cuts, the cuts being
    /// bar 0, every pinned bar and the last bar (one run [0, 0] for a single bar). A path
    /// through the pins is the runs' paths joined at their pinned ends, and its cost their
    /// costs' sum, so each run is solved on its own (module docs).
    fn runs(&self) -> Vec<(usize, usize)> {
        let mut cuts = vec![0];
        cuts.extend((0..self.bars).filter(|&k| self.pin[k].is_some()));
        cuts.push(self.bars - 1);
        cuts.dedup();
        if cuts.len() == 1 {
            return vec![(0, 0)];
        }
        cuts.windows(2).map(|w| (w[0], w[1])).collect()
    }

    /// The graph of bars `first..=last` alone (their pins, the same table and rule).
    fn run(&self, (first, last): (usize, usize)) -> Graph<'a> {
        Graph {
            table: self.table,
            bars: last - first + 1,
            pin: self.pin[first..=last].to_vec(),
            no_repeat: self.no_repeat,
            music: self.music.map(|m| Music {
                music: &m.music[first..=last],
                ..m
            }),
        }
    }

    /// The runs' paths, in order, joined at their shared pinned bars; `None` if a run has none.
    fn joined(&self, paths: impl IntoIterator<Item = Option<Vec<usize>>>) -> Option<Vec<usize>> {
        let mut path = Vec::with_capacity(self.bars);
        for p in paths {
            let p = p?;
            let skip = usize::from(!path.is_empty());
            path.extend_from_slice(&p[skip..]);
        }
        Some(path)
    }

    /// Dijkstra's algorithm ([`Graph::dijkstra_run`]) on each run, joined.
    fn dijkstra(&self) -> Option<Vec<usize>> {
        self.joined(self.runs().into_iter().map(|r| self.run(r).dijkstra_run()))
    }

    /// The exact dynamic programme (module docs) on every run; `None` without a path.
    #[cfg(test)]
    fn dp(&self) -> Option<Vec<usize>> {
        dp_many(&[self]).pop().flatten()
    }

    /// The path of a run from its layers' D (row-major): the end of smallest total (smallest
    /// index among equal totals), then back layer by layer, the predecessor of smallest index
    /// whose sum gives the node's D exactly; `None` when no end is reached.
    fn backtrack(&self, dist: &[f64]) -> Option<Vec<usize>> {
        let (n, bars) = (self.table.n, self.bars);
        let last = &dist[(bars - 1) * n..];
        let mut end = None;
        for (s, &v) in last.iter().enumerate() {
            if v.is_finite() && end.is_none_or(|(_, b)| v < b) {
                end = Some((s, v));
            }
        }
        let (mut s, _) = end?;
        let mut path = vec![s; bars];
        for k in (1..bars).rev() {
            let target = dist[k * n + s];
            let d = &dist[(k - 1) * n..k * n];
            let col = self.table.column(s);
            let node = self.node(k, s);
            s = (0..n)
                .find(|&a| {
                    d[a].is_finite()
                        && self.edge(k - 1, a, s)
                        && d[a] + f64::from(col[a]) + node == target
                })
                .expect("a finite D has a predecessor that gives it");
            path[k - 1] = s;
        }
        Some(path)
    }

    /// D_{k+1}(b) = min_a D_k(a) + C(a → b) over the edges into b (+∞ without one).
    fn column_min(&self, k: usize, d: &[f64], b: usize) -> f64 {
        let col = self.table.column(b);
        if self.edge(k, b, b) {
            min_plus(d, col)
        } else {
            min_plus(&d[..b], &col[..b]).min(min_plus(&d[b + 1..], &col[b + 1..]))
        }
    }
}

/// The exact dynamic programme on every run of every graph of `graphs` (on one table) at
/// once, a path (or `None`) per graph. Round j advances layer j of every run still going:
/// the free layers of all runs are computed in one pass over the table's columns, so each
/// column is read once per round however many runs and graphs use it.
fn dp_many<'a>(graphs: &[&Graph<'a>]) -> Vec<Option<Vec<usize>>> {
    let Some(first) = graphs.first() else {
        return vec![];
    };
    let n = first.table.n;
    let owner: Vec<(usize, Graph<'a>)> = graphs
        .iter()
        .enumerate()
        .flat_map(|(i, g)| g.runs().into_iter().map(move |r| (i, g.run(r))))
        .collect();
    let runs: Vec<&Graph<'a>> = owner.iter().map(|(_, g)| g).collect();
    // D_k(s) of every layer of every run, row-major: the backtrack recovers the
    // predecessors.
    let mut dist: Vec<Vec<f64>> = runs
        .iter()
        .map(|g| {
            let mut d = vec![f64::INFINITY; n * g.bars];
            for (s, v) in d[..n].iter_mut().enumerate() {
                if g.allowed(0, s) {
                    *v = g.node(0, s);
                }
            }
            d
        })
        .collect();
    let rounds = runs.iter().map(|g| g.bars).max().unwrap_or(1) - 1;
    let mut free = Vec::new();
    let mut block = Vec::new();
    for k in 0..rounds {
        free.clear();
        for (r, g) in runs.iter().enumerate() {
            if k + 1 >= g.bars {
                continue;
            }
            let (done, rest) = dist[r].split_at_mut((k + 1) * n);
            let d = &done[k * n..];
            let next = &mut rest[..n];
            match (g.pin[k], g.pin[k + 1]) {
                (_, Some(b)) => next[b] = g.column_min(k, d, b) + g.node(k + 1, b),
                (Some(a), None) => {
                    let row = first.table.row(a);
                    for (b, nb) in next.iter_mut().enumerate() {
                        if g.edge(k, a, b) {
                            *nb = d[a] + f64::from(row[b]) + g.node(k + 1, b);
                        }
                    }
                }
                (None, None) => free.push(r),
            }
        }
        if free.is_empty() {
            continue;
        }
        // The free layers: column b of every such run side by side in `block`.
        let m = free.len();
        block.clear();
        block.resize(n * m, f64::INFINITY);
        {
            use rayon::prelude::*;
            let (runs, dist, free) = (&runs, &dist, &free);
            block
                .par_chunks_mut(DP_COLUMNS * m)
                .enumerate()
                .for_each(|(c, out)| {
                    for (j, o) in out.chunks_exact_mut(m).enumerate() {
                        let b = c * DP_COLUMNS + j;
                        for (o, &r) in o.iter_mut().zip(free) {
                            let g = &runs[r];
                            *o =
                                g.column_min(k, &dist[r][k * n..(k + 1) * n], b) + g.node(k + 1, b);
                        }
                    }
                });
        }
        for (i, &r) in free.iter().enumerate() {
            let next = &mut dist[r][(k + 1) * n..(k + 2) * n];
            for (b, v) in next.iter_mut().enumerate() {
                *v = block[b * m + i];
            }
        }
    }
    let mut paths: Vec<Vec<Option<Vec<usize>>>> = vec![vec![]; graphs.len()];
    for ((i, g), d) in owner.iter().zip(&dist) {
        paths[*i].push(g.backtrack(d));
    }
    graphs.iter().zip(paths).map(|(g, p)| g.joined(p)).collect()
}

/// Columns per rayon task of the DP (each a minimum over a whole column).
const DP_COLUMNS: usize = 32;

/// min_a d(a) + c(a) (+∞ when empty), with AVX2 where the processor has it.
#[inline]
fn min_plus(d: &[f64], c: &[f32]) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if crate::cpu::has_avx2() {
        // SAFETY: the processor supports AVX2 (checked just above).
        return unsafe { min_plus_avx2(d, c) };
    }
    min_plus_plain(d, c)
}

/// [`min_plus`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn min_plus_avx2(d: &[f64], c: &[f32]) -> f64 {
    min_plus_plain(d, c)
}

/// Lanes of [`min_plus_plain`]'s independent minima (four vectors of four doubles).
const LANES: usize = 16;

/// [`min_plus`] as plain loops the compiler vectorises: [`LANES`] running minima, then their
/// minimum. Every sum is the IEEE sum d(a) + c(a) widened, and a minimum of such sums is the
/// same whatever the order, so the result is bit for bit the sequential one. No NaN reaches
/// here (D and C are finite or +∞).
#[inline(always)]
fn min_plus_plain(d: &[f64], c: &[f32]) -> f64 {
    let mut acc = [f64::INFINITY; LANES];
    let (dc, cc) = (d.chunks_exact(LANES), c.chunks_exact(LANES));
    let (dr, cr) = (dc.remainder(), cc.remainder());
    for (x, y) in dc.zip(cc) {
        for i in 0..LANES {
            let v = x[i] + f64::from(y[i]);
            acc[i] = if v < acc[i] { v } else { acc[i] };
        }
    }
    let mut m = f64::INFINITY;
    for (&x, &y) in dr.iter().zip(cr) {
        let v = x + f64::from(y);
        m = if v < m { v } else { m };
    }
    acc.iter().fold(m, |m, &a| if a < m { a } else { m })
}

/// A heap entry of Dijkstra: d + h, then the layer, then the segment, smallest first.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Node {
    f: f64,
    k: u32,
    s: u32,
}

impl Eq for Node {}

impl Ord for Node {
    fn cmp(&self, o: &Node) -> Ordering {
        // BinaryHeap is a max-heap: the smallest key is the greatest.
        o.f.total_cmp(&self.f)
            .then(o.k.cmp(&self.k))
            .then(o.s.cmp(&self.s))
    }
}

impl PartialOrd for Node {
    fn partial_cmp(&self, o: &Node) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::choreo::transition::TransitionTable;
    use rand::{RngExt, SeedableRng};

    /// A table of random costs (no database needed for the graph algorithms).
    fn random_table(n: usize, seed: u64, levels: Option<u32>) -> TransitionTable {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let cost: Vec<f32> = (0..n * n)
            .map(|_| match levels {
                // Few distinct values: many exact ties.
                Some(l) => 1.0 + rng.random_range(0..l) as f32,
                None => rng.random_range(0.05..2.0),
            })
            .collect();
        TransitionTable::from_costs(n, 1.0, cost)
    }

    /// Every path by brute force: the cheapest total, and the paths reaching it.
    fn brute(g: &Graph) -> Option<f64> {
        let (n, bars) = (g.table.n, g.bars);
        let mut best: Option<f64> = None;
        let mut path = vec![0usize; bars];
        loop {
            let ok = (0..bars).all(|k| g.allowed(k, path[k]))
                && (0..bars - 1).all(|k| g.edge(k, path[k], path[k + 1]));
            if ok {
                let c = cost_of(g, &path);
                best = Some(best.map_or(c, |b: f64| b.min(c)));
            }
            let mut i = 0;
            loop {
                if i == bars {
                    return best;
                }
                path[i] += 1;
                if path[i] < n {
                    break;
                }
                path[i] = 0;
                i += 1;
            }
        }
    }

    fn cost_of(g: &Graph, p: &[usize]) -> f64 {
        let edges = p.windows(2).fold(0.0, |s, w| s + g.table.cost(w[0], w[1]));
        edges
            + p.iter()
                .enumerate()
                .map(|(k, &s)| g.node(k, s))
                .sum::<f64>()
    }

    #[test]
    fn dijkstra_and_dp_give_the_same_path_and_the_brute_force_optimum() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        for case in 0..300 {
            let n = rng.random_range(1..6);
            let bars = rng.random_range(1..6);
            let levels = if case % 2 == 0 { Some(3) } else { None };
            let table = random_table(n, case, levels);
            let mut pins = Pins::new();
            for _ in 0..rng.random_range(0..3) {
                pins.insert(rng.random_range(0..bars), rng.random_range(0..n));
            }
            let no_repeat = case % 3 != 0;
            let mut g = Graph::new(&table, bars, &pins, no_repeat);
            // Half the cases with the music term, its ranks on a coarse grid (ties).
            let music: Vec<f64> = (0..bars)
                .map(|_| rng.random_range(0..5) as f64 / 4.0)
                .collect();
            let motion: Vec<f64> = (0..n)
                .map(|_| rng.random_range(0..5) as f64 / 4.0)
                .collect();
            if case % 2 == 1 {
                g.music = Some(Music {
                    music: &music,
                    motion: &motion,
                    lambda: rng.random_range(0.1..3.0),
                });
            }
            let (a, b) = (g.dijkstra(), g.dp());
            assert_eq!(a, b, "case {case}: n {n}, bars {bars}, pins {pins:?}");
            match (a, brute(&g)) {
                (Some(p), Some(best)) => {
                    assert!((cost_of(&g, &p) - best).abs() < 1e-9, "case {case}");
                    for (&bar, &s) in &pins {
                        assert_eq!(p[bar], s, "pin kept");
                    }
                    if no_repeat {
                        for k in 0..bars - 1 {
                            let both = pins.contains_key(&k) && pins.contains_key(&(k + 1));
                            assert!(both || p[k] != p[k + 1], "case {case}: {p:?}");
                        }
                    }
                }
                (None, None) => {}
                (p, best) => panic!("case {case}: {p:?} vs brute force {best:?}"),
            }
        }
    }

    #[test]
    fn large_random_instances_agree() {
        for seed in 0..6 {
            let n = 150;
            let table = random_table(n, 100 + seed, if seed % 2 == 0 { Some(4) } else { None });
            let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
            let bars = 24;
            let mut pins = Pins::new();
            for _ in 0..4 {
                pins.insert(rng.random_range(0..bars), rng.random_range(0..n));
            }
            let music: Vec<f64> = (0..bars).map(|_| rng.random_range(0.0..1.0)).collect();
            let motion: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..1.0)).collect();
            let mut g = Graph::new(&table, bars, &pins, true);
            if seed >= 3 {
                g.music = Some(Music {
                    music: &music,
                    motion: &motion,
                    lambda: 0.7,
                });
            }
            let (a, b) = (g.dijkstra().unwrap(), g.dp().unwrap());
            assert_eq!(a, b, "seed {seed}");
        }
    }

    #[test]
    fn several_column_blocks_agree() {
        // Three rayon tasks of the DP, the last one partial, columns not a multiple of the
        // vector lanes, with ties and without.
        let n = 2 * DP_COLUMNS + 3 * LANES + 5;
        for (seed, levels) in [(1, Some(2)), (2, None), (3, Some(1))] {
            let table = random_table(n, seed, levels);
            let pins = Pins::from([(3, 7), (4, 7), (9, n - 1)]);
            for no_repeat in [true, false] {
                let g = Graph::new(&table, 12, &pins, no_repeat);
                let (a, b) = (g.dijkstra().unwrap(), g.dp().unwrap());
                assert_eq!(a, b, "seed {seed}, no repeat {no_repeat}");
            }
        }
    }

    #[test]
    fn a_lone_segment_cannot_fill_two_bars_without_a_repeat() {
        let table = random_table(1, 1, None);
        let g = Graph::new(&table, 2, &Pins::new(), true);
        assert_eq!(g.dijkstra(), None);
        assert_eq!(g.dp(), None);
        let g = Graph::new(&table, 2, &Pins::new(), false);
        assert_eq!(g.dijkstra(), Some(vec![0, 0]));
        // Two pinned bars may repeat: the user chose it.
        let pins = Pins::from([(0, 0), (1, 0)]);
        let g = Graph::new(&table, 2, &pins, true);
        assert_eq!(g.dp(), Some(vec![0, 0]));
    }

    #[test]
    fn bad_pins_are_named() {
        assert_eq!(check(0, 4, &Pins::new()), Err(FillError::EmptyDatabase));
        assert_eq!(check(3, 0, &Pins::new()), Err(FillError::NoBars));
        assert_eq!(
            check(3, 4, &Pins::from([(4, 0)])),
            Err(FillError::PinPastEnd { bar: 4, bars: 4 })
        );
        assert_eq!(
            check(3, 4, &Pins::from([(1, 3)])),
            Err(FillError::NoSuchSegment {
                bar: 1,
                segment: 3,
                segments: 3
            })
        );
        let e = check(3, 4, &Pins::from([(1, 3)])).unwrap_err().to_string();
        assert!(e.contains("segment 3 does not exist"), "{e}");
    }
}
