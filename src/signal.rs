//! Plain signal helpers shared by the measurements and the systems (jump events, the kinematic
//! beat): the median and a Gaussian smoother renormalised at the ends.

/// Gaussian smoothing with σ = `sigma` samples, truncated at 4σ, renormalised at the ends.
pub fn gaussian_smooth(x: &[f64], sigma: f64) -> Vec<f64> {
    if sigma <= 0.0 {
        return x.to_vec();
    }
    let r = (4.0 * sigma).ceil() as isize;
    let w: Vec<f64> = (-r..=r)
        .map(|i| (-0.5 * (i as f64 / sigma).powi(2)).exp())
        .collect();
    let n = x.len() as isize;
    (0..n)
        .map(|k| {
            let (mut s, mut ws) = (0.0, 0.0);
            for i in -r..=r {
                let m = k + i;
                if (0..n).contains(&m) {
                    let wi = w[(i + r) as usize];
                    s += wi * x[m as usize];
                    ws += wi;
                }
            }
            s / ws
        })
        .collect()
}

/// The median of `v` (the mean of the middle two for an even count).
pub fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let m = s.len() / 2;
    if s.len() % 2 == 1 {
        s[m]
    } else {
        0.5 * (s[m - 1] + s[m])
    }
}
