//! Sines and cosines of four angles at once. The kinematics rotates every coordinate-axis joint
//! through `sin q` and `cos q` at each pass; evaluated four lanes at a time with plain `f64`
//! arithmetic, the same code compiles to one AVX2 instruction per operation inside the AVX2 copy
//! of the step and to two-wide SSE2 elsewhere, with the same bits (no fused multiply–add).
//!
//! The method is the classic one of Cephes (`sin.c`, S. L. Moshier): the angle is reduced by
//! the nearest multiple `y` of π/2 with π/2 in three parts (Cody–Waite: `r = ((|x| − y·P₁) −
//! y·P₂) − y·P₃`; `P₁`, `P₂` have 25 and 24 significant bits, so `y·P₁` and `y·P₂` are exact
//! while `y < 2²⁸`), `sin r ≈ r + r³·S(r²)` and `cos r ≈ 1 − r²/2 + r⁴·C(r²)` with Cephes'
//! degree-5 minimax polynomials on `|r| ≤ π/4`, and the quadrant `y mod 4` swaps and signs them.
//! Within 2 ulp of the C library's values (tested over ±10 turns) for `|x| ≤`
//! [`REDUCED_LIMIT`]; beyond it (never a joint angle), and for infinities and NaN, a lane takes
//! the C library's `sin_cos` instead, in the batch and alone alike.

/// Angles up to this magnitude (rad) take the polynomial; larger ones the C library.
pub const REDUCED_LIMIT: f64 = 1.0e6;

/// Angles evaluated together: four, the `f64` width of AVX2.
const LANES: usize = 4;

// π/2 in three parts (Cephes' DP1..DP3 doubled).
const PIO2_1: f64 = 1.5707963109016418;
const PIO2_2: f64 = 1.5893254712295857e-08;
const PIO2_3: f64 = 6.123233995736766e-17;
const TWO_OVER_PI: f64 = std::f64::consts::FRAC_2_PI;
const TWO_52: f64 = 4_503_599_627_370_496.0;
// Cephes sin.c: sin r = r + r³ (S0 + S1 r² + … + S5 r¹⁰), cos r = 1 − r²/2 + r⁴ (C0 + … + C5 r¹⁰).
const S: [f64; 6] = [
    -0.1666666666666663,
    0.008333333333322118,
    -0.0001984126982958954,
    2.7557313621385722e-06,
    -2.5050747762857807e-08,
    1.5896230157654656e-10,
];
const C: [f64; 6] = [
    0.041666666666666595,
    -0.0013888888888873056,
    2.4801587288851704e-05,
    -2.755731417929674e-07,
    2.087570084197473e-09,
    -1.1358536521387682e-11,
];

/// Lane by lane `f` of `a`, written out so that the compiler emits one vector instruction.
#[inline(always)]
fn map4<T: Copy, U>(a: [T; LANES], f: impl Fn(T) -> U) -> [U; LANES] {
    [f(a[0]), f(a[1]), f(a[2]), f(a[3])]
}

/// Lane by lane `f` of `a` and `b`.
#[inline(always)]
fn zip4<T: Copy, U: Copy, V>(a: [T; LANES], b: [U; LANES], f: impl Fn(T, U) -> V) -> [V; LANES] {
    [f(a[0], b[0]), f(a[1], b[1]), f(a[2], b[2]), f(a[3], b[3])]
}

/// `(sin x, cos x)` of four angles (rad), lane by lane.
#[inline(always)]
pub fn sin_cos4(x: [f64; LANES]) -> ([f64; LANES], [f64; LANES]) {
    let xa = map4(x, f64::abs);
    // `y`, the nearest integer to `|x|·2/π` (ties to even), through `+ 2⁵² − 2⁵²`, exact below
    // 2⁵¹; the sum also holds `y mod 4` in its low mantissa bits.
    let t = map4(xa, |a| a * TWO_OVER_PI + TWO_52);
    let y = map4(t, |t| t - TWO_52);
    let r = zip4(xa, y, |a, y| ((a - y * PIO2_1) - y * PIO2_2) - y * PIO2_3);
    let poly = |p: &[f64; 6]| {
        map4(r, |r| {
            let z = r * r;
            ((((z * p[5] + p[4]) * z + p[3]) * z + p[2]) * z + p[1]) * z + p[0]
        })
    };
    let s = zip4(r, poly(&S), |r, p| r + r * (r * r) * p);
    let c = zip4(r, poly(&C), |r, p| {
        let z = r * r;
        (1.0 - z * 0.5) + z * z * p
    });
    let q = map4(t, |v| v.to_bits() & 3);
    // Odd quadrants swap sine and cosine: a lane's mask is all ones there.
    let swap = map4(q, |q| 0u64.wrapping_sub(q & 1));
    let (sb, cb) = (map4(s, f64::to_bits), map4(c, f64::to_bits));
    let pick = |a: [u64; LANES], b: [u64; LANES]| {
        zip4(zip4(a, b, |a, b| (a, b)), swap, |(a, b), m| {
            (a & !m) | (b & m)
        })
    };
    let (sv, cv) = (pick(sb, cb), pick(cb, sb));
    let sin_sign = zip4(q, map4(x, f64::to_bits), |q, xb| {
        ((q >> 1) << 63) ^ (xb & (1 << 63))
    });
    let cos_sign = map4(q, |q| (((q + 1) >> 1) & 1) << 63);
    let sin = map4(zip4(sv, sin_sign, |v, m| v ^ m), f64::from_bits);
    let cos = map4(zip4(cv, cos_sign, |v, m| v ^ m), f64::from_bits);
    let near = map4(xa, |a| a <= REDUCED_LIMIT);
    if near[0] & near[1] & near[2] & near[3] {
        (sin, cos)
    } else {
        far_lanes(x, sin, cos)
    }
}

/// The lanes of [`sin_cos4`] beyond [`REDUCED_LIMIT`] (or not finite) from the C library; out of
/// line, so that the common case stays one straight run of vector instructions.
#[cold]
#[inline(never)]
fn far_lanes(
    x: [f64; LANES],
    mut sin: [f64; LANES],
    mut cos: [f64; LANES],
) -> ([f64; LANES], [f64; LANES]) {
    for k in 0..LANES {
        // False beyond the limit, for infinities and for NaN.
        let near = x[k].abs() <= REDUCED_LIMIT;
        if !near {
            (sin[k], cos[k]) = x[k].sin_cos();
        }
    }
    (sin, cos)
}

/// `(sin x, cos x)` of one angle (rad): the bits of its lane in [`sin_cos4`].
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    let (s, c) = sin_cos4([x; LANES]);
    (s[0], c[0])
}

/// Groups of four angles [`sin_cos_at`] evaluates between its gather and its scatter.
const BLOCK: usize = 8;

/// `sin[i] = sin x[i]`, `cos[i] = cos x[i]` (rad) for every index `i` of `idx` (the joint
/// angles of a configuration), four at a time; `sin` and `cos` are as long as `x` and keep
/// their other entries. The angles are gathered into groups of four first and scattered after,
/// so that each group's evaluation is one straight run of vector instructions.
#[inline(always)]
pub fn sin_cos_at(x: &[f64], idx: &[usize], sin: &mut [f64], cos: &mut [f64]) {
    for block in idx.chunks(LANES * BLOCK) {
        let mut lanes = [[0.0; LANES]; BLOCK];
        for (k, &i) in block.iter().enumerate() {
            lanes[k / LANES][k % LANES] = x[i];
        }
        let (mut s, mut c) = ([[0.0; LANES]; BLOCK], [[0.0; LANES]; BLOCK]);
        for g in 0..block.len().div_ceil(LANES) {
            (s[g], c[g]) = sin_cos4(lanes[g]);
        }
        for (k, &i) in block.iter().enumerate() {
            sin[i] = s[k / LANES][k % LANES];
            cos[i] = c[k / LANES][k % LANES];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ulps(a: f64, b: f64) -> u64 {
        (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs()
    }

    /// Within 2 ulp of the C library over ±10 turns and at zero, tiny angles and π/2; exact at
    /// ±0.
    #[test]
    fn within_two_ulp_of_the_c_library() {
        let mut worst = (0, 0);
        for i in 0..400_001 {
            let x = -63.0 + 3.15e-4 * i as f64 + 1e-9;
            let (s, c) = sin_cos(x);
            let (s0, c0) = x.sin_cos();
            worst = (worst.0.max(ulps(s, s0)), worst.1.max(ulps(c, c0)));
        }
        assert!(worst.0 <= 2 && worst.1 <= 2, "ulps (sin, cos) {worst:?}");
        for x in [
            0.0,
            -0.0,
            1e-300,
            -1e-300,
            1e-8,
            std::f64::consts::FRAC_PI_2,
        ] {
            let (s, c) = sin_cos(x);
            let (s0, c0) = x.sin_cos();
            assert!(
                ulps(s, s0) <= 2 && ulps(c, c0) <= 2,
                "{x}: {s} {c} vs {s0} {c0}"
            );
        }
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        assert_eq!(sin_cos(-0.0).0.to_bits(), (-0.0f64).to_bits());
    }

    /// Beyond the reduction's range, and for infinities and NaN, the C library's values.
    #[test]
    fn large_and_non_finite_angles_take_the_c_library() {
        for x in [
            2e6,
            -3.5e9,
            1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ] {
            let (s, c) = sin_cos(x);
            let (s0, c0) = x.sin_cos();
            assert_eq!(s.to_bits(), s0.to_bits(), "{x}");
            assert_eq!(c.to_bits(), c0.to_bits(), "{x}");
        }
    }

    /// A batch has the bits of each angle alone, wherever it sits in its group of four, and
    /// leaves the entries not asked for alone.
    #[test]
    fn the_batch_has_the_bits_of_each_angle_alone() {
        let x: Vec<f64> = (0..11).map(|i| 0.37 * i as f64 - 1.9).collect();
        let idx = [0, 2, 3, 5, 6, 7, 10];
        let (mut s, mut c) = (vec![9.0; 11], vec![9.0; 11]);
        sin_cos_at(&x, &idx, &mut s, &mut c);
        for i in 0..11 {
            if idx.contains(&i) {
                let (s1, c1) = sin_cos(x[i]);
                assert_eq!(
                    (s[i].to_bits(), c[i].to_bits()),
                    (s1.to_bits(), c1.to_bits())
                );
            } else {
                assert_eq!((s[i], c[i]), (9.0, 9.0));
            }
        }
    }
}
