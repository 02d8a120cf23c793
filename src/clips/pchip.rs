//! Monotone piecewise-cubic Hermite interpolation (Fritsch–Carlson, PCHIP): smooth (C¹) through
//! the keys and never overshooting them, so keyframed angles do not swing past their keys.

/// Interpolates keys `(t_k, y_k)` (strictly increasing `t`) at `t`; constant outside the keys.
/// Tangents: the weighted harmonic mean of neighbouring secants, zero where they change sign
/// (Fritsch & Carlson 1980; the endpoint rule of Moler's `pchip`).
pub fn pchip(ts: &[f64], ys: &[f64], t: f64) -> f64 {
    let n = ts.len();
    match n {
        0 => return 0.0,
        1 => return ys[0],
        _ => {}
    }
    if t <= ts[0] {
        return ys[0];
    }
    if t >= ts[n - 1] {
        return ys[n - 1];
    }
    let i = ts.partition_point(|&x| x <= t) - 1;
    let h = ts[i + 1] - ts[i];
    let s = |k: usize| (ys[k + 1] - ys[k]) / (ts[k + 1] - ts[k]);
    let slope = |k: usize| -> f64 {
        if k == 0 || k == n - 1 {
            // One-sided three-point estimate, clipped to keep monotonicity.
            if n == 2 {
                return s(0);
            }
            let (k0, k1) = if k == 0 { (0, 1) } else { (n - 2, n - 3) };
            let (h0, h1) = (ts[k0 + 1] - ts[k0], ts[k1 + 1] - ts[k1]);
            let (d0, d1) = (s(k0), s(k1));
            let d = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
            if d.signum() != d0.signum() {
                0.0
            } else if d0.signum() != d1.signum() && d.abs() > 3.0 * d0.abs() {
                3.0 * d0
            } else {
                d
            }
        } else {
            let (d0, d1) = (s(k - 1), s(k));
            if d0 * d1 <= 0.0 {
                0.0
            } else {
                let (h0, h1) = (ts[k] - ts[k - 1], ts[k + 1] - ts[k]);
                let (w1, w2) = (2.0 * h1 + h0, h1 + 2.0 * h0);
                (w1 + w2) / (w1 / d0 + w2 / d1)
            }
        }
    };
    let (m0, m1) = (slope(i), slope(i + 1));
    let u = (t - ts[i]) / h;
    let (u2, u3) = (u * u, u * u * u);
    (2.0 * u3 - 3.0 * u2 + 1.0) * ys[i]
        + (u3 - 2.0 * u2 + u) * h * m0
        + (-2.0 * u3 + 3.0 * u2) * ys[i + 1]
        + (u3 - u2) * h * m1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passes_through_keys_and_never_overshoots() {
        let ts = [0.0, 0.5, 0.8, 1.5, 2.0];
        let ys = [0.0, 110.0, 110.0, 5.0, 0.0];
        for (t, y) in ts.iter().zip(ys) {
            assert!((pchip(&ts, &ys, *t) - y).abs() < 1e-9);
        }
        for i in 0..=2000 {
            let t = i as f64 * 0.001;
            let v = pchip(&ts, &ys, t);
            assert!((-1e-9..=110.0 + 1e-9).contains(&v), "t={t}: {v}");
        }
        // Flat between two equal keys.
        assert!((pchip(&ts, &ys, 0.65) - 110.0).abs() < 1e-9);
    }

    #[test]
    fn reproduces_a_line() {
        let ts = [0.0, 1.0, 3.0];
        let ys = [1.0, 3.0, 7.0];
        assert!((pchip(&ts, &ys, 2.2) - 5.4).abs() < 1e-12);
    }
}
