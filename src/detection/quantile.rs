//! The χ² quantile in `const fn`: Wilson–Hilferty's cube-root normal approximation with
//! Acklam's rational approximation of the inverse normal, and the `const` logarithm they
//! need.

use crate::linalg::sqrt;

/// `ln x` in `const` (`NaN` for `x < 0` or NaN, `−∞` at 0, `∞` at `∞`): `x = m·2^e` split
/// from the bits, `m ∈ [√½, √2)`, and `ln m = 2 atanh t = 2 (t + t³/3 + t⁵/5 + …)`,
/// `t = (m − 1)/(m + 1)`, `|t| ≤ 0.172`: 20 terms leave `t⁴¹/41 < 1e-32`. A few ulp.
pub(crate) const fn ln(x: f64) -> f64 {
    if x.is_nan() || x < 0.0 {
        return f64::NAN;
    }
    if x == 0.0 {
        return f64::NEG_INFINITY;
    }
    if x == f64::INFINITY {
        return f64::INFINITY;
    }
    let (mut x, mut e) = (x, 0i64);
    if x < f64::MIN_POSITIVE {
        // Subnormal: scale by 2^54 (exact).
        x *= 18_014_398_509_481_984.0;
        e = -54;
    }
    let bits = x.to_bits();
    e += ((bits >> 52) & 0x7ff) as i64 - 1023;
    let mut m = f64::from_bits((bits & ((1u64 << 52) - 1)) | (1023u64 << 52));
    if m > core::f64::consts::SQRT_2 {
        m *= 0.5;
        e += 1;
    }
    let t = (m - 1.0) / (m + 1.0);
    let t2 = t * t;
    let (mut term, mut sum, mut k) = (t, 0.0, 1.0);
    let mut i = 0;
    while i < 20 {
        sum += term / k;
        term *= t2;
        k += 2.0;
        i += 1;
    }
    e as f64 * core::f64::consts::LN_2 + 2.0 * sum
}

/// The lower-tail standard normal quantile `Φ⁻¹(p)`, `0 < p < 1` (`NaN` outside), by
/// Acklam's rational approximation: relative error below `1.15·10⁻⁹` over `(0, 1)`.
/// `const fn`; about 15 multiply-adds, a logarithm and a square root in the tails.
pub const fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    const P_LOW: f64 = 0.02425;
    if !(p > 0.0 && p < 1.0) {
        return f64::NAN;
    }
    // The tails: q = √(−2 ln p) of the nearer tail (1 − p is exact for p ≥ ½).
    const fn tail(q: f64) -> f64 {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    }
    if p < P_LOW {
        tail(sqrt(-2.0 * ln(p)))
    } else if p > 1.0 - P_LOW {
        -tail(sqrt(-2.0 * ln(1.0 - p)))
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

/// The upper-tail χ² quantile: the `x` with `P(χ²_k > x) = alpha` for `k ≥ 1` degrees of
/// freedom and `0 < alpha < 1` (`NaN` otherwise), by the Wilson–Hilferty approximation
/// (`(χ²_k / k)^(1/3)` is nearly normal with mean `1 − 2/(9k)` and variance `2/(9k)`):
///
/// ```text
/// x = k (1 − 2/(9k) + z √(2/(9k)))³,     z = −Φ⁻¹(alpha)   (0 if the bracket is negative)
/// ```
///
/// Its relative error is at most `0.01 (1 + z²)/k` for `alpha ∈ [10⁻⁵, 0.05]`
/// (Cornish–Fisher: terms of order `1/k` in `z`; the constant measured against exact
/// quantiles in `tests/detection.rs`): 2 % at `k = 10`, `α = 10⁻⁵`; 0.13 % at `k = 150`;
/// the tail probability of the threshold is within 1 % of `alpha` at `k = 150`,
/// `alpha = 0.01`. The inverse normal adds a relative `1.2·10⁻⁹` to `z`. `const fn`: a detector's threshold is
/// computed by the compiler.
pub const fn chi_square_quantile(k: u64, alpha: f64) -> f64 {
    if k == 0 || !(alpha > 0.0 && alpha < 1.0) {
        return f64::NAN;
    }
    let z = -normal_quantile(alpha);
    let kf = k as f64;
    let v = 2.0 / (9.0 * kf);
    let c = 1.0 - v + z * sqrt(v);
    if c <= 0.0 { 0.0 } else { kf * c * c * c }
}
