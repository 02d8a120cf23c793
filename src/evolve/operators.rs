//! The textbook real-coded GA operators (Deb & Agrawal 1995; Deb 2001, *Multi-Objective
//! Optimization using Evolutionary Algorithms*, §4.2): tournament selection, simulated binary
//! crossover (SBX) and polynomial mutation, both in their bounded forms, so children never leave
//! the box. Lower fitness is better (it is the damage).

// Genes are indexed as in the textbook (`for i in 0..n`), bounds beside them.
#![allow(clippy::needless_range_loop)]

use rand::RngExt;

use super::genome::{Bounds, Genome};

/// The index of the winner of a tournament of `size` individuals drawn uniformly with
/// replacement: the lowest fitness; a tie goes to the lower index. `None` fitness (a failed
/// evaluation) loses to every value.
pub fn tournament<R: RngExt + ?Sized>(rng: &mut R, fitness: &[Option<f64>], size: usize) -> usize {
    let n = fitness.len();
    let mut best = rng.random_range(0..n);
    for _ in 1..size.max(1) {
        let c = rng.random_range(0..n);
        if better(fitness[c], c, fitness[best], best) {
            best = c;
        }
    }
    best
}

/// True when `(fa, a)` ranks before `(fb, b)`: lower fitness first, failures last, then index.
pub fn better(fa: Option<f64>, a: usize, fb: Option<f64>, b: usize) -> bool {
    match (fa, fb) {
        (Some(x), Some(y)) if x != y => x < y,
        (Some(_), None) => true,
        (None, Some(_)) => false,
        _ => a < b,
    }
}

/// The spread factor `β_q` of bounded SBX for a uniform `u` and `α = 2 − β^−(η+1)`.
fn betaq(u: f64, beta: f64, eta: f64) -> f64 {
    let alpha = 2.0 - beta.powf(-(eta + 1.0));
    let e = 1.0 / (eta + 1.0);
    if u <= 1.0 / alpha {
        (u * alpha).powf(e)
    } else {
        (1.0 / (2.0 - u * alpha)).powf(e)
    }
}

/// Simulated binary crossover with distribution index `eta` (η_c): each gene is crossed with
/// probability ½; for parents `y₁ < y₂` in `[lo, hi]`,
/// `c₁ = ½[(y₁+y₂) − β_q(y₂−y₁)]`, `c₂ = ½[(y₁+y₂) + β_q(y₂−y₁)]`, with `β` taken from the
/// distance to the nearer bound so the children stay inside it; the children swap sides with
/// probability ½.
pub fn sbx<R: RngExt + ?Sized>(
    rng: &mut R,
    a: &[f64],
    b: &[f64],
    bounds: &Bounds,
    eta: f64,
) -> (Genome, Genome) {
    let mut c1 = a.to_vec();
    let mut c2 = b.to_vec();
    for i in 0..a.len() {
        if rng.random::<f64>() > 0.5 {
            continue;
        }
        let (x1, x2) = (a[i], b[i]);
        if (x1 - x2).abs() <= 1e-14 {
            continue;
        }
        let (y1, y2) = if x1 < x2 { (x1, x2) } else { (x2, x1) };
        let (lo, hi) = (bounds.lo[i], bounds.hi[i]);
        let u = rng.random::<f64>();
        let d = y2 - y1;
        let bq1 = betaq(u, 1.0 + 2.0 * (y1 - lo) / d, eta);
        let bq2 = betaq(u, 1.0 + 2.0 * (hi - y2) / d, eta);
        let v1 = (0.5 * ((y1 + y2) - bq1 * d)).clamp(lo, hi);
        let v2 = (0.5 * ((y1 + y2) + bq2 * d)).clamp(lo, hi);
        if rng.random::<f64>() <= 0.5 {
            c1[i] = v2;
            c2[i] = v1;
        } else {
            c1[i] = v1;
            c2[i] = v2;
        }
    }
    (c1, c2)
}

/// Polynomial mutation with distribution index `eta` (η_m): each gene mutates with
/// probability `p`; with `δ₁ = (x−lo)/(hi−lo)`, `δ₂ = (hi−x)/(hi−lo)` and uniform `u`,
/// `δ_q = [2u + (1−2u)(1−δ₁)^(η+1)]^(1/(η+1)) − 1` for `u < ½`, else
/// `δ_q = 1 − [2(1−u) + 2(u−½)(1−δ₂)^(η+1)]^(1/(η+1))`, and `x ← x + δ_q (hi − lo)`.
pub fn polynomial_mutation<R: RngExt + ?Sized>(
    rng: &mut R,
    x: &mut [f64],
    bounds: &Bounds,
    p: f64,
    eta: f64,
) {
    let e = 1.0 / (eta + 1.0);
    for i in 0..x.len() {
        if rng.random::<f64>() >= p {
            continue;
        }
        let (lo, hi) = (bounds.lo[i], bounds.hi[i]);
        let w = hi - lo;
        if w <= 0.0 {
            continue;
        }
        let d1 = (x[i] - lo) / w;
        let d2 = (hi - x[i]) / w;
        let u = rng.random::<f64>();
        let dq = if u < 0.5 {
            let v = 2.0 * u + (1.0 - 2.0 * u) * (1.0 - d1).powf(eta + 1.0);
            v.powf(e) - 1.0
        } else {
            let v = 2.0 * (1.0 - u) + 2.0 * (u - 0.5) * (1.0 - d2).powf(eta + 1.0);
            1.0 - v.powf(e)
        };
        x[i] = (x[i] + dq * w).clamp(lo, hi);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_pcg::Pcg64;

    fn bounds() -> Bounds {
        Bounds::new(vec![-1.0, 0.0, 10.0, 5.0], vec![1.0, 0.001, 20.0, 5.0]).unwrap()
    }

    #[test]
    fn bounds_hold_through_crossover_and_mutation() {
        let b = bounds();
        let mut rng = Pcg64::seed_from_u64(3);
        let mut pop: Vec<Genome> = (0..20)
            .map(|_| {
                (0..4)
                    .map(|i| b.lo[i] + rng.random::<f64>() * b.width(i))
                    .collect()
            })
            .collect();
        // Parents at the bounds are the hardest case.
        pop[0] = b.lo.clone();
        pop[1] = b.hi.clone();
        for _ in 0..5000 {
            let i = rng.random_range(0..pop.len());
            let j = rng.random_range(0..pop.len());
            let (mut c1, mut c2) = sbx(&mut rng, &pop[i], &pop[j], &b, 15.0);
            polynomial_mutation(&mut rng, &mut c1, &b, 0.5, 20.0);
            polynomial_mutation(&mut rng, &mut c2, &b, 0.5, 20.0);
            assert!(b.contains(&c1) && b.contains(&c2), "{c1:?} {c2:?}");
            pop[i] = c1;
            pop[j] = c2;
        }
    }

    #[test]
    fn sbx_children_are_centred_on_the_parents_and_mutation_moves_genes() {
        let b = Bounds::new(vec![-10.0], vec![10.0]).unwrap();
        let mut rng = Pcg64::seed_from_u64(9);
        let (mut sum, mut n, mut spread) = (0.0, 0, 0.0f64);
        for _ in 0..20000 {
            let (c1, c2) = sbx(&mut rng, &[-1.0], &[1.0], &b, 2.0);
            sum += c1[0] + c2[0];
            spread = spread.max(c1[0].abs()).max(c2[0].abs());
            n += 2;
        }
        // SBX conserves the parents' mean (up to the bound clamp, far away here).
        assert!((sum / n as f64).abs() < 0.02, "mean {}", sum / n as f64);
        assert!(spread > 1.5, "children reach beyond the parents: {spread}");
        let mut x = [0.0];
        let mut moved = 0;
        for _ in 0..1000 {
            x[0] = 0.0;
            polynomial_mutation(&mut rng, &mut x, &b, 1.0, 20.0);
            moved += usize::from(x[0] != 0.0);
        }
        assert!(moved > 990);
    }

    #[test]
    fn tournaments_prefer_lower_damage_and_never_pick_failures_over_values() {
        let f = [Some(5.0), None, Some(1.0), Some(3.0)];
        let mut rng = Pcg64::seed_from_u64(1);
        let mut wins = [0usize; 4];
        for _ in 0..4000 {
            wins[tournament(&mut rng, &f, 2)] += 1;
        }
        assert!(wins[2] > wins[3] && wins[3] > wins[0]);
        assert!(wins[1] < wins[0], "{wins:?}");
        assert!(better(Some(1.0), 5, None, 0));
        assert!(better(Some(1.0), 0, Some(1.0), 1));
    }
}
