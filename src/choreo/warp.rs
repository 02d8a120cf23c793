//! The beat warp of one bar: where a segment's own beats are, and the monotone time map that
//! moves them onto the song's beats.
//!
//! - **The segment's beats** ([`count_minima`]). A segment is one bar of
//!   [`BEATS_PER_BAR`](super::segments::BEATS_PER_BAR) counts cut so that count 1 is at phase 0,
//!   so its beats belong at the phases c / counts. The beat of an inner count c (1 ≤ c < counts)
//!   is the lowest sample of the speed curve v(f) = Σ_i |ẋ_i(f)| within ±[`COUNT_WINDOW`] of a
//!   bar around c / counts, refined by the parabola through it and its two neighbours
//!   (offset ½ (v₋ − v₊) / (v₋ − 2v₀ + v₊) frames). A count has no beat when its minimum is not
//!   clear: the lowest sample lies on the window's edge (the curve only falls or only rises
//!   there), or it is not [`MIN_DIP`] (a fraction) below the highest sample on each side of it
//!   within the window.
//! - **The warp** ([`Warp`]). A map from song phase u ∈ [0, 1] of the bar to segment phase w(u),
//!   through the knots (0, 0), (u_k, w_k) …, (1, 1): the monotone piecewise cubic Hermite
//!   w(u) = h₀₀(t) w_k + h₁₀(t) h m_k + h₀₁(t) w_{k+1} + h₁₁(t) h m_{k+1} on [u_k, u_{k+1}],
//!   h = u_{k+1} − u_k, t = (u − u_k) / h, h₀₀ = 2t³ − 3t² + 1, h₁₀ = t³ − 2t² + t,
//!   h₀₁ = −2t³ + 3t², h₁₁ = t³ − t². The end tangents are m = 1, the rate of the uniform
//!   resize, so consecutive bars join C¹ (the warp adds no jump of speed at a bar line). The
//!   inner tangents are those of the C² cubic spline through the knots with end slopes 1
//!   ([`clamped_spline_slopes`]), each then limited to [max(δ₀, δ₁) / 2, 2 min(δ₀, δ₁)] of its
//!   two secants δ (the Fritsch–Carlson box, as [`crate::clips::pchip`] keeps monotone):
//!   where no limit bites the warp is C², so its rate w′ has no kink at a knot and the motion
//!   no jump of acceleration there (a C¹-only tangent, such as the harmonic mean, jumps w″ at a
//!   knot: a jump of acceleration, a spike of jerk).
//! - **The rate bound.** Every secant δ_k = (w_{k+1} − w_k) / (u_{k+1} − u_k) lies in
//!   [[`MIN_RATE`], [`MAX_RATE`]] = [⅔, 3⁄2]: of the knots given, the warp keeps the most that
//!   allow it (fewest dropped; among as many, the least Σ |ln δ_k|), by a longest-chain dynamic
//!   programme from (0, 0) to (1, 1). With every tangent within [½, 2] × its pieces' secants
//!   (the end tangent 1 is, as δ ∈ [⅔, 3⁄2]), a piece's rate is δ · g(t) with g between ½ and 2
//!   (g is linear in the tangent ratios, and at their four extreme pairs it stays within
//!   [½, 2]), so the local rate w′(u) stays within [⅓, 3], and w is strictly increasing
//!   (Fritsch–Carlson: tangent ratios within 3 keep a piece monotone). Why 3⁄2: a motion played
//!   r times faster has r³ times its jerk. On `scenes/dance_salsa.ron` secants up to 2 raised
//!   the dance's peak jerk inside the bars 2.5-fold (a snap of one segment sped up 1.7×); up to
//!   3⁄2 they leave it below the uniform resize's and keep most of the beat alignment gained
//!   (0.56 against 0.61, from 0.33).
//! - Outside [0, 1] the warp continues with slope 1 (w = u), as the uniform resize.

/// Half-width of the window a count's speed minimum is looked for in, in bars: half a count of
/// four.
pub const COUNT_WINDOW: f64 = 0.125;

/// How far a count's minimum must lie below the highest speed on each side of it within its
/// window, as a fraction of that speed, to be clear.
pub const MIN_DIP: f64 = 0.1;

/// The slowest secant rate of a warp, segment phase per song phase.
pub const MIN_RATE: f64 = 2.0 / 3.0;

/// The fastest secant rate of a warp, segment phase per song phase.
pub const MAX_RATE: f64 = 1.5;

/// The phase (0 to 1) of the speed minimum of every inner count c = 1 … counts − 1 of a bar
/// whose speed curve `speed` is sampled at the phases f / speed.len(); `None` for a count whose
/// minimum is not clear (module docs).
pub fn count_minima(speed: &[f64], counts: usize) -> Vec<Option<f64>> {
    let m = speed.len();
    (1..counts)
        .map(|c| {
            let centre = c as f64 / counts as f64 * m as f64;
            let half = COUNT_WINDOW * m as f64;
            let lo = (centre - half).ceil().max(0.0) as usize;
            let hi = ((centre + half).floor() as usize).min(m.checked_sub(1)?);
            if hi < lo + 2 || !speed[lo..=hi].iter().all(|v| v.is_finite()) {
                return None;
            }
            let i = (lo..=hi).min_by(|&a, &b| speed[a].total_cmp(&speed[b]))?;
            if i == lo || i == hi {
                return None;
            }
            let v = speed[i];
            let left = speed[lo..i].iter().copied().fold(f64::MIN, f64::max);
            let right = speed[i + 1..=hi].iter().copied().fold(f64::MIN, f64::max);
            if v > (1.0 - MIN_DIP) * left.min(right) {
                return None;
            }
            let (a, b, d) = (speed[i - 1], v, speed[i + 1]);
            let denom = a - 2.0 * b + d;
            let offset = if denom > 1e-15 {
                (0.5 * (a - d) / denom).clamp(-0.5, 0.5)
            } else {
                0.0
            };
            Some((i as f64 + offset) / m as f64)
        })
        .collect()
}

/// The knot slopes of the C² cubic spline with end slopes 1 through knots of spacings `h` and
/// secants `d`: m₀ = m_n = 1 and h_i m_{i−1} + 2(h_{i−1} + h_i) m_i + h_{i−1} m_{i+1} =
/// 3(h_i δ_{i−1} + h_{i−1} δ_i) inside (Thomas algorithm).
fn clamped_spline_slopes(h: &[f64], d: &[f64]) -> Vec<f64> {
    let n = h.len() + 1;
    let mut m = vec![1.0; n];
    if n < 3 {
        return m;
    }
    // Unknowns m_1 … m_{n−2}: forward sweep, then back substitution.
    let (mut c, mut r) = (vec![0.0; n], vec![0.0; n]);
    for i in 1..n - 1 {
        let (lower, diag, upper) = (h[i], 2.0 * (h[i - 1] + h[i]), h[i - 1]);
        let mut rhs = 3.0 * (h[i] * d[i - 1] + h[i - 1] * d[i]);
        if i == 1 {
            rhs -= lower * m[0];
        }
        if i == n - 2 {
            rhs -= upper * m[n - 1];
        }
        let (cp, rp) = if i == 1 {
            (0.0, 0.0)
        } else {
            (c[i - 1], r[i - 1])
        };
        let den = diag - lower * cp;
        c[i] = if i == n - 2 { 0.0 } else { upper / den };
        r[i] = (rhs - lower * rp) / den;
    }
    for i in (1..n - 1).rev() {
        m[i] = r[i] - if i + 1 < n - 1 { c[i] * m[i + 1] } else { 0.0 };
    }
    m
}

/// A monotone time warp of one bar: song phase u → segment phase w(u) (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Warp {
    /// Knot song phases, from 0 to 1, increasing.
    u: Vec<f64>,
    /// Knot segment phases, from 0 to 1, increasing.
    w: Vec<f64>,
    /// Tangent dw/du at every knot.
    m: Vec<f64>,
}

impl Warp {
    /// The identity w(u) = u: the uniform resize.
    pub fn identity() -> Warp {
        Warp {
            u: vec![0.0, 1.0],
            w: vec![0.0, 1.0],
            m: vec![1.0, 1.0],
        }
    }

    /// The warp through (0, 0), the `pairs` (song phase, segment phase) it can keep within the
    /// rate bound, and (1, 1) (module docs). Pairs outside (0, 1) or not finite are dropped.
    pub fn through(pairs: &[(f64, f64)]) -> Warp {
        let mut p: Vec<(f64, f64)> = pairs
            .iter()
            .copied()
            .filter(|&(u, w)| u > 0.0 && u < 1.0 && w > 0.0 && w < 1.0)
            .collect();
        p.sort_by(|a, b| a.0.total_cmp(&b.0));
        // Nodes: (0, 0), the pairs, (1, 1).
        let mut nodes = Vec::with_capacity(p.len() + 2);
        nodes.push((0.0, 0.0));
        nodes.extend(p);
        nodes.push((1.0, 1.0));
        let n = nodes.len();
        let secant = |a: usize, b: usize| -> Option<f64> {
            let (ua, wa) = nodes[a];
            let (ub, wb) = nodes[b];
            let d = (wb - wa) / (ub - ua);
            (ub > ua && (MIN_RATE..=MAX_RATE).contains(&d)).then_some(d)
        };
        // The longest chain from node 0 to each node: (knots kept, Σ |ln δ|, predecessor).
        let mut best: Vec<Option<(usize, f64, usize)>> = vec![None; n];
        best[0] = Some((0, 0.0, 0));
        for j in 1..n {
            for i in 0..j {
                let (Some((count, cost, _)), Some(d)) = (best[i], secant(i, j)) else {
                    continue;
                };
                let c = (count + usize::from(j + 1 < n), cost + d.ln().abs());
                let better = match best[j] {
                    None => true,
                    Some((bc, bcost, _)) => c.0 > bc || (c.0 == bc && c.1 < bcost),
                };
                if better {
                    best[j] = Some((c.0, c.1, i));
                }
            }
        }
        let mut chain = vec![n - 1];
        let mut j = n - 1;
        while j != 0 {
            j = best[j].map_or(0, |b| b.2);
            chain.push(j);
        }
        chain.reverse();
        let u: Vec<f64> = chain.iter().map(|&k| nodes[k].0).collect();
        let w: Vec<f64> = chain.iter().map(|&k| nodes[k].1).collect();
        let k = u.len();
        let d: Vec<f64> = (0..k - 1)
            .map(|i| (w[i + 1] - w[i]) / (u[i + 1] - u[i]))
            .collect();
        let h: Vec<f64> = (0..k - 1).map(|i| u[i + 1] - u[i]).collect();
        let mut m = clamped_spline_slopes(&h, &d);
        for i in 1..k - 1 {
            let (d0, d1) = (d[i - 1], d[i]);
            m[i] = m[i].clamp(0.5 * d0.max(d1), 2.0 * d0.min(d1));
        }
        Warp { u, w, m }
    }

    /// The knots kept, (song phase, segment phase), from (0, 0) to (1, 1).
    pub fn knots(&self) -> Vec<(f64, f64)> {
        self.u.iter().copied().zip(self.w.iter().copied()).collect()
    }

    /// Whether the warp is the identity (no inner knot).
    pub fn is_identity(&self) -> bool {
        self.u.len() == 2
    }

    /// The piece holding `u` in [0, 1]: its index, width and t ∈ [0, 1].
    fn piece(&self, u: f64) -> (usize, f64, f64) {
        let i = (self.u.partition_point(|&x| x <= u).max(1) - 1).min(self.u.len() - 2);
        let h = self.u[i + 1] - self.u[i];
        (i, h, (u - self.u[i]) / h)
    }

    /// The segment phase w(u) at song phase `u` (slope 1 outside [0, 1]).
    pub fn at(&self, u: f64) -> f64 {
        if self.is_identity() || !(0.0..=1.0).contains(&u) {
            return u;
        }
        let (i, h, t) = self.piece(u);
        let (t2, t3) = (t * t, t * t * t);
        (2.0 * t3 - 3.0 * t2 + 1.0) * self.w[i]
            + (t3 - 2.0 * t2 + t) * h * self.m[i]
            + (-2.0 * t3 + 3.0 * t2) * self.w[i + 1]
            + (t3 - t2) * h * self.m[i + 1]
    }

    /// The rate w′(u), segment phase per song phase (1 outside [0, 1]).
    pub fn rate(&self, u: f64) -> f64 {
        if self.is_identity() || !(0.0..=1.0).contains(&u) {
            return 1.0;
        }
        let (i, h, t) = self.piece(u);
        let t2 = t * t;
        ((6.0 * t2 - 6.0 * t) * self.w[i]
            + (3.0 * t2 - 4.0 * t + 1.0) * h * self.m[i]
            + (-6.0 * t2 + 6.0 * t) * self.w[i + 1]
            + (3.0 * t2 - 2.0 * t) * h * self.m[i + 1])
            / h
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pseudo-random numbers in [0, 1) (a fixed LCG, so the test is the same every run).
    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn the_warp_maps_its_knots_exactly_and_keeps_slope_one_at_the_bar_lines() {
        let pairs = [(0.25, 0.3), (0.5, 0.47), (0.75, 0.8)];
        let w = Warp::through(&pairs);
        assert_eq!(w.knots().len(), 5);
        for &(u, s) in &pairs {
            assert!((w.at(u) - s).abs() < 1e-15, "{u}: {}", w.at(u));
        }
        assert_eq!(w.at(0.0), 0.0);
        assert!((w.at(1.0) - 1.0).abs() < 1e-15);
        assert!((w.rate(0.0) - 1.0).abs() < 1e-12);
        assert!((w.rate(1.0) - 1.0).abs() < 1e-12);
        // The derivative by differences agrees with rate() (and so is 1 at the ends).
        for u in [1e-6, 0.1, 0.3, 0.6, 0.9, 1.0 - 1e-6] {
            let fd = (w.at(u + 1e-7) - w.at(u - 1e-7)) / 2e-7;
            assert!((fd - w.rate(u)).abs() < 1e-5, "{u}: {fd} vs {}", w.rate(u));
        }
        // Slope 1 on both sides of the bar lines: C¹ with the next bar.
        let right = (w.at(1e-7) - w.at(0.0)) / 1e-7;
        let left = (w.at(1.0) - w.at(1.0 - 1e-7)) / 1e-7;
        assert!((right - 1.0).abs() < 1e-5 && (left - 1.0).abs() < 1e-5);
    }

    #[test]
    fn the_warp_has_no_kink_of_rate_at_a_knot_where_the_limits_do_not_bite() {
        let w = Warp::through(&[(0.25, 0.3), (0.5, 0.47), (0.75, 0.8)]);
        let curvature = |u: f64| (w.rate(u + 1e-6) - w.rate(u)) / 1e-6;
        for &(u, _) in &w.knots()[1..4] {
            let (left, right) = (curvature(u - 2e-6), curvature(u + 1e-6));
            assert!((left - right).abs() < 1e-3, "{u}: w'' {left} | {right}");
        }
        // The curvature itself changes along the warp: the check above can see a change.
        assert!((curvature(0.1) - curvature(0.2)).abs() > 0.1);
    }

    #[test]
    fn beats_that_already_match_give_the_identity() {
        let w = Warp::through(&[(0.25, 0.25), (0.5, 0.5), (0.75, 0.75)]);
        for i in 0..=1000 {
            let u = i as f64 / 1000.0;
            assert!((w.at(u) - u).abs() < 1e-15, "{u}");
            assert!((w.rate(u) - 1.0).abs() < 1e-12, "{u}");
        }
        assert!(Warp::through(&[]).is_identity());
        assert_eq!(Warp::through(&[]).at(0.37), 0.37);
    }

    #[test]
    fn random_warps_are_monotone_and_within_the_rate_bound() {
        let mut seed = 7u64;
        for _ in 0..2000 {
            let k = 1 + (lcg(&mut seed) * 4.0) as usize;
            let pairs: Vec<(f64, f64)> = (0..k)
                .map(|c| {
                    let u = (c as f64 + 0.2 + 0.6 * lcg(&mut seed)) / k as f64;
                    (
                        u,
                        (u + 0.4 * (lcg(&mut seed) - 0.5) / k as f64).clamp(0.01, 0.99),
                    )
                })
                .collect();
            let w = Warp::through(&pairs);
            let knots = w.knots();
            for p in knots.windows(2) {
                let d = (p[1].1 - p[0].1) / (p[1].0 - p[0].0);
                assert!((MIN_RATE..=MAX_RATE).contains(&d), "{pairs:?}: secant {d}");
            }
            // Every pair kept is mapped exactly.
            for &(u, s) in &pairs {
                if knots.iter().any(|k| k.0 == u) {
                    assert!((w.at(u) - s).abs() < 1e-12);
                }
            }
            let mut last = -1.0;
            for i in 0..=2000 {
                let u = i as f64 / 2000.0;
                let v = w.at(u);
                assert!(v > last, "{pairs:?}: not increasing at {u}");
                last = v;
                let r = w.rate(u);
                assert!(
                    (0.25 - 1e-9..=4.0 + 1e-9).contains(&r),
                    "{pairs:?}: rate {r} at {u}"
                );
            }
        }
    }

    #[test]
    fn a_knot_that_needs_too_fast_a_rate_is_dropped_and_the_others_kept() {
        // (0.3, 0.05) would need a secant of 1/6 from (0, 0): dropped; the others stay.
        let w = Warp::through(&[(0.3, 0.05), (0.5, 0.55), (0.75, 0.72)]);
        assert_eq!(
            w.knots(),
            vec![(0.0, 0.0), (0.5, 0.55), (0.75, 0.72), (1.0, 1.0)]
        );
        // Two knots that cannot both stay: the one that bends the warp less is kept.
        let w = Warp::through(&[(0.5, 0.4), (0.52, 0.6)]);
        assert_eq!(w.knots(), vec![(0.0, 0.0), (0.52, 0.6), (1.0, 1.0)]);
    }

    #[test]
    fn count_minima_find_the_dips_near_the_counts_and_skip_unclear_ones() {
        let m = 64;
        // Dips at phases 0.27 and 0.48; near ¾ the curve only rises.
        let speed: Vec<f64> = (0..m)
            .map(|f| {
                let x = f as f64 / m as f64;
                let dip = |c: f64| 1.0 - 0.8 * (-((x - c) / 0.04).powi(2)).exp();
                if x < 0.62 {
                    2.0 + dip(0.27).min(dip(0.48))
                } else {
                    3.0 + 4.0 * (x - 0.62)
                }
            })
            .collect();
        let c = count_minima(&speed, 4);
        assert_eq!(c.len(), 3);
        assert!((c[0].unwrap() - 0.27).abs() < 0.004, "{c:?}");
        assert!((c[1].unwrap() - 0.48).abs() < 0.004, "{c:?}");
        assert_eq!(c[2], None);
        // A flat curve has no clear minimum anywhere.
        assert_eq!(count_minima(&[1.0; 32], 4), vec![None; 3]);
    }
}
