//! The exact upper tail of the χ² distribution, independent of the crate's Wilson–Hilferty
//! quantile: the reference of `tests/detection.rs` and of the false-alarm table of
//! `xtask/src/bin/detection_building.rs`.

/// `ln Γ(a)` for `a = k/2`, `k ≥ 1` an integer, exactly from the recurrences
/// `Γ(a + 1) = a Γ(a)`, `Γ(1) = 1`, `Γ(½) = √π` (a sum of logarithms).
pub fn ln_gamma_half(k: u64) -> f64 {
    let mut s = if k.is_multiple_of(2) {
        0.0
    } else {
        0.5 * std::f64::consts::PI.ln()
    };
    let mut a = if k.is_multiple_of(2) { 1.0 } else { 0.5 };
    while a < k as f64 / 2.0 - 1e-9 {
        s += a.ln();
        a += 1.0;
    }
    s
}

/// The upper tail `P(χ²_k > x)` = `Q(k/2, x/2)`, from the series of the lower regularized
/// gamma function `P(a, y) = y^a e^{−y} / Γ(a + 1) · Σ_n y^n / ((a + 1)…(a + n))`
/// (Abramowitz & Stegun 6.5.29), summed until the terms stop changing the sum. For the
/// quantiles here (`y ≤ a + 10√a`) the terms fall geometrically once `n > y − a`; `1 − P`
/// loses `log₁₀(1/Q)` digits, at most 5 of 16 for `Q ≥ 10⁻⁵`.
pub fn chi2_upper_tail(k: u64, x: f64) -> f64 {
    let a = k as f64 / 2.0;
    let y = x / 2.0;
    let (mut term, mut sum, mut n) = (1.0f64, 1.0f64, 1.0f64);
    loop {
        term *= y / (a + n);
        sum += term;
        if term < 1e-17 * sum {
            break;
        }
        n += 1.0;
    }
    // ln Γ(a + 1) = ln a + ln Γ(a).
    let lp = a * y.ln() - y - (a.ln() + ln_gamma_half(k)) + sum.ln();
    1.0 - lp.exp()
}
