//! Eros (Extended Frobenius norm; Yang & Shahabi 2004), the PCA-based similarity between two
//! multivariate time series that the dance-editing paper's search uses as Sim and D.
//!
//! Each series X (n frames × d variables, columns centred) has its covariance
//! C = XᵀX/(n − 1), with eigenvalues λ₁ ≥ … ≥ λ_d and unit eigenvectors v₁ … v_d (cyclic Jacobi).
//! With one weight per rank, w_i (Σ w_i = 1; over a database, the mean over its series of the
//! normalised eigenvalues λ_i / Σλ), Eros(A, B) = Σ_i w_i |⟨a_i, b_i⟩| ∈ [0, 1] (1 for the same
//! principal axes), and the dissimilarity is D(A, B) = √(2 − 2 Eros(A, B)).
//!
//! Why Eros rather than kWAS: Eros compares every principal axis, rank by rank, with weights
//! that are data (the database's eigenvalue spectrum), needs no choice of k, is bounded, and
//! does not depend on the series' lengths, so bar-long segments of any frame count compare; the
//! absolute value makes it blind to the arbitrary sign of an eigenvector. kWAS weighs the first
//! k axes by both series' own eigenvalues, so its result moves with the chosen k.

/// The principal axes of one series: eigenvalues (descending) and unit eigenvectors.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Pca {
    /// Eigenvalues of the covariance, λ₁ ≥ … ≥ λ_d ≥ 0.
    pub values: Vec<f64>,
    /// Eigenvectors, `vectors[i]` of length d belongs to `values[i]`.
    pub vectors: Vec<Vec<f64>>,
}

/// Eigen-decomposition of the symmetric d×d matrix `a` (row-major) by cyclic Jacobi rotations:
/// (eigenvalues descending, eigenvectors as rows).
pub fn symmetric_eigen(a: &[f64], d: usize) -> (Vec<f64>, Vec<Vec<f64>>) {
    let mut m = a.to_vec();
    let mut v = vec![0.0; d * d];
    for i in 0..d {
        v[i * d + i] = 1.0;
    }
    let scale: f64 = m
        .iter()
        .map(|x| x * x)
        .sum::<f64>()
        .sqrt()
        .max(f64::MIN_POSITIVE);
    for _sweep in 0..64 {
        let off: f64 = (0..d)
            .flat_map(|i| (0..d).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| m[i * d + j] * m[i * d + j])
            .sum::<f64>()
            .sqrt();
        if off <= 1e-14 * scale {
            break;
        }
        for p in 0..d {
            for q in p + 1..d {
                let apq = m[p * d + q];
                if apq.abs() <= 1e-300 {
                    continue;
                }
                let theta = (m[q * d + q] - m[p * d + p]) / (2.0 * apq);
                let t = theta.signum().max(0.0) * 2.0 - 1.0;
                let t = t / (theta.abs() + (theta * theta + 1.0).sqrt());
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..d {
                    let (mkp, mkq) = (m[k * d + p], m[k * d + q]);
                    m[k * d + p] = c * mkp - s * mkq;
                    m[k * d + q] = s * mkp + c * mkq;
                }
                for k in 0..d {
                    let (mpk, mqk) = (m[p * d + k], m[q * d + k]);
                    m[p * d + k] = c * mpk - s * mqk;
                    m[q * d + k] = s * mpk + c * mqk;
                }
                for k in 0..d {
                    let (vkp, vkq) = (v[k * d + p], v[k * d + q]);
                    v[k * d + p] = c * vkp - s * vkq;
                    v[k * d + q] = s * vkp + c * vkq;
                }
            }
        }
    }
    let mut order: Vec<usize> = (0..d).collect();
    order.sort_by(|&a, &b| m[b * d + b].total_cmp(&m[a * d + a]));
    let values = order.iter().map(|&i| m[i * d + i].max(0.0)).collect();
    let vectors = order
        .iter()
        .map(|&i| (0..d).map(|k| v[k * d + i]).collect())
        .collect();
    (values, vectors)
}

/// The principal axes of a series of `frames`, each a row of the same length d ≥ 1 (at least two
/// frames; fewer give zero eigenvalues and the unit axes).
pub fn pca(frames: &[Vec<f64>]) -> Pca {
    let d = frames.first().map_or(0, |f| f.len());
    let n = frames.len();
    let mut mean = vec![0.0; d];
    for f in frames {
        for (m, x) in mean.iter_mut().zip(f) {
            *m += x / n as f64;
        }
    }
    let mut c = vec![0.0; d * d];
    for f in frames {
        for i in 0..d {
            let xi = f[i] - mean[i];
            for j in i..d {
                c[i * d + j] += xi * (f[j] - mean[j]);
            }
        }
    }
    let norm = (n.max(2) - 1) as f64;
    for i in 0..d {
        for j in i..d {
            c[i * d + j] /= norm;
            c[j * d + i] = c[i * d + j];
        }
    }
    let (values, vectors) = symmetric_eigen(&c, d);
    Pca { values, vectors }
}

/// Eros weights from a set of series' principal axes: the mean over them of the normalised
/// eigenvalues λ_i / Σλ, normalised to sum 1 (uniform when every series is constant).
pub fn eros_weights(all: &[&Pca]) -> Vec<f64> {
    let d = all.first().map_or(0, |p| p.values.len());
    let mut w = vec![0.0; d];
    for p in all {
        let s: f64 = p.values.iter().sum();
        if s > 0.0 {
            for (wi, v) in w.iter_mut().zip(&p.values) {
                *wi += v / s;
            }
        }
    }
    let total: f64 = w.iter().sum();
    if total > 0.0 {
        w.iter_mut().for_each(|x| *x /= total);
    } else if d > 0 {
        w.iter_mut().for_each(|x| *x = 1.0 / d as f64);
    }
    w
}

/// Eros(A, B) = Σ_i w_i |⟨a_i, b_i⟩| (see the module docs).
pub fn eros(a: &Pca, b: &Pca, weights: &[f64]) -> f64 {
    weights
        .iter()
        .zip(a.vectors.iter().zip(&b.vectors))
        .map(|(w, (x, y))| w * x.iter().zip(y).map(|(p, q)| p * q).sum::<f64>().abs())
        .sum::<f64>()
        .min(1.0)
}

/// The Eros dissimilarity D = √(2 − 2 Eros).
pub fn eros_distance(a: &Pca, b: &Pca, weights: &[f64]) -> f64 {
    (2.0 - 2.0 * eros(a, b, weights)).max(0.0).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jacobi_diagonalises_a_known_matrix() {
        // [[2, 1], [1, 2]]: eigenvalues 3 and 1, axes (1, 1)/√2 and (1, −1)/√2.
        let (v, e) = symmetric_eigen(&[2.0, 1.0, 1.0, 2.0], 2);
        assert!(
            (v[0] - 3.0).abs() < 1e-12 && (v[1] - 1.0).abs() < 1e-12,
            "{v:?}"
        );
        assert!((e[0][0].abs() - 0.5f64.sqrt()).abs() < 1e-12);
        assert!((e[0][0] - e[0][1]).abs() < 1e-12);
        // A 6×6 random symmetric matrix: A v = λ v for every pair.
        let d = 6;
        let mut a = vec![0.0; d * d];
        let mut s = 3u64;
        for i in 0..d {
            for j in i..d {
                s = s.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
                let x = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                a[i * d + j] = x;
                a[j * d + i] = x;
            }
        }
        let (vals, vecs) = symmetric_eigen(&a, d);
        for (l, v) in vals.iter().zip(&vecs) {
            for i in 0..d {
                let av: f64 = (0..d).map(|j| a[i * d + j] * v[j]).sum();
                // Negative eigenvalues are clamped to 0 in `values`; check the positive ones.
                if *l > 0.0 {
                    assert!((av - l * v[i]).abs() < 1e-9, "{av} vs {}", l * v[i]);
                }
            }
        }
    }

    #[test]
    fn eros_is_one_for_the_same_series_and_symmetric() {
        let a: Vec<Vec<f64>> = (0..50)
            .map(|t| {
                let t = t as f64 * 0.1;
                vec![t.sin(), 0.5 * t.cos(), 0.1 * (3.0 * t).sin()]
            })
            .collect();
        let b: Vec<Vec<f64>> = a.iter().map(|f| vec![f[1], f[0], f[2]]).collect();
        let (pa, pb) = (pca(&a), pca(&b));
        let w = eros_weights(&[&pa, &pb]);
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!((eros(&pa, &pa, &w) - 1.0).abs() < 1e-9);
        assert!((eros(&pa, &pb, &w) - eros(&pb, &pa, &w)).abs() < 1e-12);
        assert!(eros(&pa, &pb, &w) < 0.9, "{}", eros(&pa, &pb, &w));
        assert!(eros_distance(&pa, &pa, &w) < 1e-4);
    }
}
