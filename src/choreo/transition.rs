//! The connection score between two dance segments (paper §3.2.1, eqs. 5–8) and its transition
//! cost C = 1/S, from the last frame i of segment A to the first frame j of segment B.
//!
//! Per body link l (parent point → point, pelvis excluded, in humanoid24's point order, as
//! [`Segment::first_directions`] stores them), with v_l the link direction in the pelvis heading
//! frame and h the unit vector:
//!
//! - S_pose = Σ_l β_l h(v_l(i))·h(v_l(j))                                                  (5)
//! - S_move = Σ_l β_l g[h(v_l(j) − v_l(i))·h(v̇_l(i))] · g[h(v_l(j) − v_l(i))·h(v̇_l(j))]  (6)
//! - g[x] = max(x, 0)                                                                        (7)
//! - S = S_pose + S_move                                                                     (8)
//!
//! v̇_l is the rate of the link direction in the original motion. The segments store each
//! point's velocity relative to the pelvis in the heading frame ([`Segment::last_velocities`]),
//! so the link vector's rate is ẋ_point − ẋ_parent, and the rate of its unit direction u is that
//! minus its component along u, over the link length: h(v̇_l) = h(ẋ_point − ẋ_parent −
//! ((ẋ_point − ẋ_parent)·u) u) (the length drops out of h). h(0) = 0, so a link at rest, or one
//! whose direction does not change across the seam, adds nothing to S_move. The products of
//! eq. 6 are evaluated as g[d·w_i] g[d·w_j] / |d|² with d = u_j − u_i, the same number without a
//! square root.
//!
//! S lies in [−Σβ, 2Σβ]. The cost is C = 1/S for S ≥ ε = 10⁻³ Σβ; below ε (a connection at
//! least as bad as a nearly perpendicular pose) it continues along the tangent of 1/S at ε,
//! C = (2ε − S)/ε², so C is positive, finite and strictly decreasing in S everywhere: every
//! connection orders the same way as its S, and Dijkstra's non-negative edge weights hold.

use std::sync::LazyLock;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::database::Database;
use super::segments::Segment;
use crate::humanoid::humanoid24;

/// The link weights β_l of eqs. 5–6.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TransitionParams {
    /// One weight per link of [`Segment::first_directions`] (humanoid24 point order, pelvis
    /// excluded); missing weights count 1. Weights must be finite and ≥ 0.
    #[serde(default)]
    pub beta: Vec<f64>,
}

impl TransitionParams {
    /// β_l of link `l` (1 when not given).
    pub fn beta_of(&self, l: usize) -> f64 {
        self.beta.get(l).copied().unwrap_or(1.0)
    }

    /// Σ_l β_l over `links` links.
    pub fn beta_sum(&self, links: usize) -> f64 {
        (0..links).map(|l| self.beta_of(l)).sum()
    }
}

/// The connection of A's last frame to B's first frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Connection {
    /// Posture similarity S_pose, eq. 5 (in [−Σβ, Σβ]).
    pub s_pose: f64,
    /// Movement similarity S_move, eq. 6 (in [0, Σβ]).
    pub s_move: f64,
    /// S = S_pose + S_move, eq. 8.
    pub s: f64,
    /// Transition cost C = 1/S (continued linearly below ε, module docs), > 0.
    pub cost: f64,
}

/// The (point, parent point) of every link of humanoid24, in the order of
/// [`Segment::first_directions`].
pub static HUMANOID24_LINKS: LazyLock<Vec<(usize, usize)>> = LazyLock::new(|| {
    humanoid24()
        .skeleton()
        .point_parents()
        .iter()
        .enumerate()
        .filter_map(|(i, p)| p.map(|q| (i, q)))
        .collect()
});

/// The number of drawable points of humanoid24 (velocities per boundary frame).
pub fn humanoid24_points() -> usize {
    HUMANOID24_LINKS.len() + 1
}

/// The cost of a connection score `s` with Σβ = `beta_sum` (module docs): 1/S for S ≥ ε =
/// 10⁻³ Σβ, the tangent (2ε − S)/ε² below.
pub fn cost_of(s: f64, beta_sum: f64) -> f64 {
    let eps = 1e-3 * beta_sum.max(f64::MIN_POSITIVE.sqrt());
    if s >= eps {
        1.0 / s
    } else {
        (2.0 * eps - s) / (eps * eps)
    }
}

/// The unit rate of every link direction, h(v̇_l), at one boundary frame: `dirs` the unit link
/// directions, `vel` the point velocities (module docs).
pub fn direction_rates(dirs: &[DVec3], vel: &[DVec3]) -> Vec<DVec3> {
    HUMANOID24_LINKS
        .iter()
        .zip(dirs)
        .map(|(&(p, q), u)| match (vel.get(p), vel.get(q)) {
            (Some(a), Some(b)) => {
                let r = *a - *b;
                (r - r.dot(*u) * *u).normalize_or_zero()
            }
            _ => DVec3::ZERO,
        })
        .collect()
}

/// Link `l`'s terms of eqs. 5 and 6: (u_i·u_j, g[d·w_i] g[d·w_j] / |d|²), d = u_j − u_i, from
/// the unit directions u and unit rates w at A's last frame (i) and B's first frame (j).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn link_terms(
    uix: f64,
    uiy: f64,
    uiz: f64,
    wix: f64,
    wiy: f64,
    wiz: f64,
    ujx: f64,
    ujy: f64,
    ujz: f64,
    wjx: f64,
    wjy: f64,
    wjz: f64,
) -> (f64, f64) {
    let pose = uix * ujx + uiy * ujy + uiz * ujz;
    let (dx, dy, dz) = (ujx - uix, ujy - uiy, ujz - uiz);
    let d2 = dx * dx + dy * dy + dz * dz;
    let a = (dx * wix + dy * wiy + dz * wiz).max(0.0);
    let b = (dx * wjx + dy * wjy + dz * wjz).max(0.0);
    let mv = if d2 > 0.0 { a * b / d2 } else { 0.0 };
    (pose, mv)
}

/// The connection from A's last frame to B's first frame (eqs. 5–8; module docs).
pub fn connection(a: &Segment, b: &Segment, p: &TransitionParams) -> Connection {
    let wa = direction_rates(&a.last_directions, &a.last_velocities);
    let wb = direction_rates(&b.first_directions, &b.first_velocities);
    let links = a.last_directions.len().min(b.first_directions.len());
    let (mut s_pose, mut s_move) = (0.0, 0.0);
    for l in 0..links {
        let (ui, uj) = (a.last_directions[l], b.first_directions[l]);
        let (wi, wj) = (
            wa.get(l).copied().unwrap_or_default(),
            wb.get(l).copied().unwrap_or_default(),
        );
        let (pose, mv) = link_terms(
            ui.x, ui.y, ui.z, wi.x, wi.y, wi.z, uj.x, uj.y, uj.z, wj.x, wj.y, wj.z,
        );
        let beta = p.beta_of(l);
        s_pose += beta * pose;
        s_move += beta * mv;
    }
    let s = s_pose + s_move;
    Connection {
        s_pose,
        s_move,
        s,
        cost: cost_of(s, p.beta_sum(links)),
    }
}

/// Why a transition table could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TransitionError {
    /// A link weight that is negative or not finite.
    #[error("link weight β[{link}] = {value}: every β_l must be a finite number ≥ 0")]
    Beta {
        /// The link.
        link: usize,
        /// Its weight.
        value: f64,
    },
    /// Every link weight is 0, so every connection scores S = 0.
    #[error("every link weight β_l is 0: the connection score S would be 0 for every pair")]
    ZeroBeta,
    /// A segment whose boundary data does not have humanoid24's links and points.
    #[error(
        "segment {segment}: its boundary has {directions} link directions and {velocities} point \
         velocities, humanoid24 has {links} links and {points} points"
    )]
    Boundary {
        /// The segment.
        segment: usize,
        /// Link directions found (first and last frame together: the smaller count).
        directions: usize,
        /// Point velocities found (the smaller count).
        velocities: usize,
        /// Links expected.
        links: usize,
        /// Points expected.
        points: usize,
    },
    /// A table too large to allocate (segments² costs).
    #[error("{segments} segments need a {segments}² transition table, more than {MAX_TABLE} costs")]
    TooLarge {
        /// The segment count.
        segments: usize,
    },
}

/// Largest transition table built (costs): 6,000 segments (two copies of 144 MB).
pub const MAX_TABLE: usize = 36_000_000;

/// One boundary frame of every segment, structure of arrays: for link l and segment s, entry
/// `l * n + s` of each array (unit directions u and unit direction rates w, weighted by β_l for
/// the side that carries the weights).
#[derive(Debug, Clone, Default)]
struct Side {
    ux: Vec<f64>,
    uy: Vec<f64>,
    uz: Vec<f64>,
    wx: Vec<f64>,
    wy: Vec<f64>,
    wz: Vec<f64>,
}

impl Side {
    fn new(db: &Database, pick: impl Fn(&Segment) -> (&[DVec3], &[DVec3]), links: usize) -> Side {
        let n = db.segments.len();
        let mut s = Side {
            ux: vec![0.0; links * n],
            uy: vec![0.0; links * n],
            uz: vec![0.0; links * n],
            wx: vec![0.0; links * n],
            wy: vec![0.0; links * n],
            wz: vec![0.0; links * n],
        };
        for (k, seg) in db.segments.iter().enumerate() {
            let (dirs, vel) = pick(seg);
            let w = direction_rates(dirs, vel);
            for l in 0..links {
                let i = l * n + k;
                (s.ux[i], s.uy[i], s.uz[i]) = (dirs[l].x, dirs[l].y, dirs[l].z);
                (s.wx[i], s.wy[i], s.wz[i]) = (w[l].x, w[l].y, w[l].z);
            }
        }
        s
    }
}

/// Every connection of a database, precomputed: the costs C(a → b) of A = segment a's last
/// frame to B = segment b's first frame, a dense `n × n` table, each the cost of
/// [`connection`] rounded to single precision (relative error ≤ 2⁻²⁴ ≈ 6·10⁻⁸). It is kept
/// twice: by rows (every C(a → ·), for Dijkstra's relaxations) and by columns (every C(· → b),
/// for the fill's dynamic programme, a minimum over a contiguous column). The fill's graph
/// weights are these rounded costs; for 2,000 segments each copy is 16 MB, which stays in the
/// processor's cache while the fill sweeps it once per bar.
#[derive(Debug, Clone)]
pub struct TransitionTable {
    /// Number of segments.
    pub n: usize,
    /// Σβ over the links.
    pub beta_sum: f64,
    /// Costs, row-major: `cost[a * n + b]` = C(a → b).
    pub cost: Vec<f32>,
    /// The same costs, column-major: `cost_to[b * n + a]` = C(a → b).
    pub cost_to: Vec<f32>,
    /// The smallest cost in the table.
    pub min_cost: f64,
    /// The smallest cost off the diagonal (a ≠ b); +∞ for a single segment.
    pub min_cost_off_diagonal: f64,
    /// The cost of a good seam in this database: the mean over segments a of their cheapest
    /// transition to another segment, (1/n) Σ_a min_{b ≠ a} C(a → b) (min_b C(a → b) for a
    /// single segment). The fill's music term is weighed in these units.
    pub typical_cost: f64,
}

impl TransitionTable {
    /// Checks `db`'s boundary data and `p`'s weights, then computes every connection (rows in
    /// parallel with rayon; the same bits on any number of threads).
    pub fn new(db: &Database, p: &TransitionParams) -> Result<TransitionTable, TransitionError> {
        let links = HUMANOID24_LINKS.len();
        let points = humanoid24_points();
        for (l, &b) in p.beta.iter().enumerate().take(links) {
            if !b.is_finite() || b < 0.0 {
                return Err(TransitionError::Beta { link: l, value: b });
            }
        }
        let beta_sum = p.beta_sum(links);
        if beta_sum <= 0.0 {
            return Err(TransitionError::ZeroBeta);
        }
        let n = db.segments.len();
        if n.checked_mul(n).is_none_or(|c| c > MAX_TABLE) {
            return Err(TransitionError::TooLarge { segments: n });
        }
        for (k, s) in db.segments.iter().enumerate() {
            let d = s.first_directions.len().min(s.last_directions.len());
            let v = s.first_velocities.len().min(s.last_velocities.len());
            let dmax = s.first_directions.len().max(s.last_directions.len());
            let vmax = s.first_velocities.len().max(s.last_velocities.len());
            if d != links || dmax != links || v != points || vmax != points {
                return Err(TransitionError::Boundary {
                    segment: k,
                    directions: d,
                    velocities: v,
                    links,
                    points,
                });
            }
        }
        let last = Side::new(db, |s| (&s.last_directions, &s.last_velocities), links);
        let first = Side::new(db, |s| (&s.first_directions, &s.first_velocities), links);
        let beta: Vec<f64> = (0..links).map(|l| p.beta_of(l)).collect();
        let mut cost = vec![0.0f32; n * n];
        use rayon::prelude::*;
        cost.par_chunks_mut(n.max(1)).enumerate().for_each_init(
            || (vec![0.0; n], vec![0.0; n]),
            |(pose, mv), (a, row)| {
                table_row(a, n, &beta, &last, &first, pose, mv);
                for (c, (sp, sm)) in row.iter_mut().zip(pose.iter().zip(mv.iter())) {
                    *c = cost_of(sp + sm, beta_sum) as f32;
                }
            },
        );
        Ok(TransitionTable::from_costs(n, beta_sum, cost))
    }

    /// The table of the row-major costs `cost` (`n × n`, `cost[a * n + b]` = C(a → b)) of
    /// links summing to `beta_sum`: their column-major copy and their minima.
    ///
    /// # Panics
    /// If `cost` does not hold `n²` costs.
    pub fn from_costs(n: usize, beta_sum: f64, cost: Vec<f32>) -> TransitionTable {
        assert_eq!(
            cost.len(),
            n * n,
            "a transition table of {n} segments holds {n}² costs"
        );
        let mut cost_to = vec![0.0f32; n * n];
        use rayon::prelude::*;
        // Blocks of 64 columns: each row's 64 costs are read at once, each column written in
        // order.
        const BLOCK: usize = 64;
        cost_to
            .par_chunks_mut((n * BLOCK).max(1))
            .enumerate()
            .for_each(|(k, cols)| {
                let b0 = k * BLOCK;
                let width = cols.len() / n.max(1);
                for a in 0..n {
                    let row = &cost[a * n + b0..a * n + b0 + width];
                    for (j, &c) in row.iter().enumerate() {
                        cols[j * n + a] = c;
                    }
                }
            });
        let mut min_cost = f64::INFINITY;
        let mut min_cost_off_diagonal = f64::INFINITY;
        let mut best_sum = 0.0;
        for a in 0..n {
            let mut best = f64::INFINITY;
            for b in 0..n {
                let c = f64::from(cost[a * n + b]);
                min_cost = min_cost.min(c);
                if a != b || n == 1 {
                    best = best.min(c);
                }
                if a != b {
                    min_cost_off_diagonal = min_cost_off_diagonal.min(c);
                }
            }
            best_sum += best;
        }
        let typical_cost = if n > 0 { best_sum / n as f64 } else { 0.0 };
        TransitionTable {
            n,
            beta_sum,
            cost,
            cost_to,
            min_cost,
            min_cost_off_diagonal,
            typical_cost,
        }
    }

    /// C(a → b) (the single-precision cost, widened).
    #[inline]
    pub fn cost(&self, a: usize, b: usize) -> f64 {
        f64::from(self.cost[a * self.n + b])
    }

    /// Row a: C(a → b) for every b, single precision.
    #[inline]
    pub fn row(&self, a: usize) -> &[f32] {
        &self.cost[a * self.n..(a + 1) * self.n]
    }

    /// Column b: C(a → b) for every a, single precision.
    #[inline]
    pub fn column(&self, b: usize) -> &[f32] {
        &self.cost_to[b * self.n..(b + 1) * self.n]
    }
}

/// S_pose and S_move of segment a's last frame against every segment's first frame, summed link
/// by link in the order of [`connection`] (so the same bits), into `pose` and `mv`.
fn table_row(
    a: usize,
    n: usize,
    beta: &[f64],
    last: &Side,
    first: &Side,
    pose: &mut [f64],
    mv: &mut [f64],
) {
    pose.fill(0.0);
    mv.fill(0.0);
    for (l, &bl) in beta.iter().enumerate() {
        let i = l * n + a;
        let (uix, uiy, uiz) = (last.ux[i], last.uy[i], last.uz[i]);
        let (wix, wiy, wiz) = (last.wx[i], last.wy[i], last.wz[i]);
        let r = l * n..(l + 1) * n;
        let (ux, uy, uz) = (
            &first.ux[r.clone()],
            &first.uy[r.clone()],
            &first.uz[r.clone()],
        );
        let (wx, wy, wz) = (&first.wx[r.clone()], &first.wy[r.clone()], &first.wz[r]);
        for b in 0..n {
            let (p, m) = link_terms(
                uix, uiy, uiz, wix, wiy, wiz, ux[b], uy[b], uz[b], wx[b], wy[b], wz[b],
            );
            pose[b] += bl * p;
            mv[b] += bl * m;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A segment whose boundary links all point along `dir` and move along `rate`.
    pub(crate) fn flat_segment(first: (DVec3, DVec3), last: (DVec3, DVec3)) -> Segment {
        let links = HUMANOID24_LINKS.len();
        let points = humanoid24_points();
        // Velocities: each point moves by `rate` more than its parent (a chain from the pelvis).
        let vel = |rate: DVec3| -> Vec<DVec3> {
            let mut v = vec![DVec3::ZERO; points];
            for &(p, q) in HUMANOID24_LINKS.iter() {
                v[p] = v[q] + rate;
            }
            v
        };
        Segment {
            clip: 0,
            bar: 0,
            start_s: 0.0,
            end_s: 2.0,
            root_translation: vec![],
            root_rotation: vec![],
            angles: vec![],
            intensity: 0.0,
            eros: crate::choreo::eros::Pca {
                values: vec![],
                vectors: vec![],
            },
            first_directions: vec![first.0.normalize(); links],
            last_directions: vec![last.0.normalize(); links],
            first_velocities: vel(first.1),
            last_velocities: vel(last.1),
        }
    }

    #[test]
    fn identical_poses_score_sigma_beta_and_opposite_ones_are_worst() {
        let l = HUMANOID24_LINKS.len() as f64;
        let y = DVec3::Y;
        let a = flat_segment((y, DVec3::X), (y, DVec3::X));
        let c = connection(&a, &a, &TransitionParams::default());
        assert!((c.s_pose - l).abs() < 1e-12);
        assert_eq!(c.s_move, 0.0, "no change of direction: h(0) = 0");
        assert!((c.cost - 1.0 / l).abs() < 1e-12);
        let b = flat_segment((-y, DVec3::X), (-y, DVec3::X));
        let o = connection(&a, &b, &TransitionParams::default());
        assert!((o.s_pose + l).abs() < 1e-12);
        assert!(o.cost > c.cost && o.cost.is_finite() && o.cost > 0.0);
    }

    #[test]
    fn s_move_rewards_a_seam_that_continues_the_motion() {
        // A's links point up and swing towards +X; B's point a little to +X.
        let l = HUMANOID24_LINKS.len() as f64;
        let a = flat_segment((DVec3::Y, DVec3::X), (DVec3::Y, DVec3::X));
        let tilt = DVec3::new(0.2, 1.0, 0.0);
        let along = flat_segment((tilt, DVec3::X), (tilt, DVec3::X));
        let back = flat_segment((tilt, -DVec3::X), (tilt, -DVec3::X));
        let p = TransitionParams::default();
        let (go, stop) = (connection(&a, &along, &p), connection(&a, &back, &p));
        // d = u_j − u_i; A's links move along X, B's along X without its part along B's links.
        let t = tilt.normalize();
        let d = (t - DVec3::Y).normalize();
        let wb = (DVec3::X - DVec3::X.dot(t) * t).normalize();
        let expected = l * d.x.max(0.0) * d.dot(wb).max(0.0);
        assert!(expected > 0.5 * l);
        assert!(
            (go.s_move - expected).abs() < 1e-9,
            "{} {expected}",
            go.s_move
        );
        assert_eq!(stop.s_move, 0.0, "B moves back: g cuts it");
        assert!(go.cost < stop.cost);
        assert_eq!(go.s_pose, stop.s_pose);
    }

    #[test]
    fn cost_is_positive_finite_and_decreasing_in_s() {
        let sb = 23.0;
        let mut prev = f64::INFINITY;
        for k in 0..=3000 {
            let s = -sb + 3.0 * sb * k as f64 / 3000.0;
            let c = cost_of(s, sb);
            assert!(c > 0.0 && c.is_finite());
            assert!(c < prev, "{s}: {c} ≥ {prev}");
            prev = c;
        }
        // Continuous at ε.
        let eps = 1e-3 * sb;
        assert!((cost_of(eps * (1.0 - 1e-12), sb) - 1.0 / eps).abs() < 1e-6);
    }

    #[test]
    fn a_link_rate_loses_its_radial_part() {
        let dirs = vec![DVec3::Y; HUMANOID24_LINKS.len()];
        let mut vel = vec![DVec3::ZERO; humanoid24_points()];
        let (p, q) = HUMANOID24_LINKS[0];
        vel[p] = vel[q] + DVec3::new(0.0, 5.0, 3.0);
        let w = direction_rates(&dirs, &vel);
        assert!((w[0] - DVec3::Z).length() < 1e-12, "{:?}", w[0]);
    }
}

#[cfg(test)]
mod table_tests {
    use super::*;
    use crate::choreo::generated::generated_database;

    #[test]
    fn the_table_has_the_costs_of_connection_rounded_to_single_precision() {
        let db = generated_database(11, 3, 5).unwrap();
        let p = TransitionParams {
            beta: (0..HUMANOID24_LINKS.len())
                .map(|l| 0.5 + (l % 3) as f64)
                .collect(),
        };
        let t = TransitionTable::new(&db, &p).unwrap();
        let n = db.segments.len();
        for a in 0..n {
            for b in 0..n {
                let c = connection(&db.segments[a], &db.segments[b], &p);
                assert_eq!(t.cost(a, b), f64::from(c.cost as f32), "{a} → {b}");
            }
        }
        // Consecutive bars of one clip connect better than the typical pair.
        let mean = t.cost.iter().map(|&c| f64::from(c)).sum::<f64>() / (n * n) as f64;
        let next: Vec<f64> = (0..n - 1)
            .filter(|&a| db.segments[a].clip == db.segments[a + 1].clip)
            .map(|a| t.cost(a, a + 1))
            .collect();
        let next_mean = next.iter().sum::<f64>() / next.len() as f64;
        assert!(next_mean < mean, "{next_mean} vs {mean}");
    }

    #[test]
    fn bad_weights_and_boundaries_are_refused() {
        let db = generated_database(2, 1, 3).unwrap();
        let neg = TransitionParams {
            beta: vec![1.0, -1.0],
        };
        assert!(matches!(
            TransitionTable::new(&db, &neg),
            Err(TransitionError::Beta { link: 1, .. })
        ));
        let zero = TransitionParams {
            beta: vec![0.0; HUMANOID24_LINKS.len()],
        };
        assert_eq!(
            TransitionTable::new(&db, &zero).unwrap_err(),
            TransitionError::ZeroBeta
        );
        let mut bad = db.clone();
        bad.segments[1].first_directions.pop();
        assert!(matches!(
            TransitionTable::new(&bad, &TransitionParams::default()),
            Err(TransitionError::Boundary { segment: 1, .. })
        ));
    }
}
