//! `models::natural_frequencies` (issue 31) against closed forms: the uniform shear
//! building's `ω_j = 2 √(k/m) sin((2j − 1) π / (2(2N + 1)))`, and the 2-DOF characteristic
//! polynomial `det(K − λ M) = 0` solved by the quadratic formula (non-diagonal `M`
//! included); its use in a `const` feeding `rayleigh_coefficients`; the typed errors.

#![allow(clippy::needless_range_loop)]

use aemstep::models::{self, Rows};
use aemstep::{Error, unwrap_const};

const EPS: f64 = f64::EPSILON;

/// The uniform `N`-storey shear building of storey mass `m` and stiffness `k`: largest
/// relative error of the computed frequencies against the closed form.
fn uniform_error<const N: usize>(m: f64, k: f64) -> f64 {
    let (mm, kk) = models::shear_building([m; N], [k; N]);
    let w = models::natural_frequencies(&mm, &kk).unwrap();
    let pi = core::f64::consts::PI;
    let mut err = 0.0f64;
    for j in 1..=N {
        let exact =
            2.0 * (k / m).sqrt() * ((2 * j - 1) as f64 * pi / (2 * (2 * N + 1)) as f64).sin();
        err = err.max((w[j - 1] - exact).abs() / exact);
    }
    for j in 1..N {
        assert!(w[j] > w[j - 1], "ascending");
    }
    err
}

/// The closed form's own rounding is a few ulps (`sin` and `√` correctly rounded to
/// ≤ 1 ulp each); the solver's error on `λ_j` is `O(ε λ_max)`, so `ω_j` is off by about
/// `ε λ_max / (2 λ_j)` relative, `λ_max/λ_1 = sin²(Nπ/(2N+1)) / sin²(π/(2N+1))` (≈ 63
/// at N = 12). Measured (printed): ≤ 2.8e-15 at every N here (the largest at N = 8, 12);
/// bound `8 ε λ_max/λ_1` (5.2e-14 at N = 8).
#[test]
fn uniform_shear_building_matches_the_closed_form() {
    fn check<const N: usize>(m: f64, k: f64) {
        let err = uniform_error::<N>(m, k);
        let pi = core::f64::consts::PI;
        let s = |j: usize| ((2 * j - 1) as f64 * pi / (2 * (2 * N + 1)) as f64).sin();
        let spread = (s(N) / s(1)).powi(2);
        eprintln!("N = {N}, m = {m:e}, k = {k:e}: {err:.2e}");
        assert!(err <= 8.0 * EPS * spread, "N = {N}: {err:e}");
    }
    check::<1>(1.0e5, 1.0e8);
    check::<2>(1.0e5, 1.0e8);
    check::<3>(2.0e5, 4.0e8);
    check::<5>(models::FIVE_STOREY_MASS, models::FIVE_STOREY_STIFFNESS);
    check::<8>(3.0e4, 7.0e7);
    check::<12>(1.0, 1.0);
    // Units far from 1: the exact power-of-two scaling gives the same relative accuracy.
    check::<5>(1.0e-200, 1.0e-100);
    check::<5>(1.0e150, 1.0e200);
}

/// `λ` of `det(K − λ M) = 0` for 2×2 symmetric `M, K`: `a λ² − b λ + c = 0`,
/// `a = det M`, `b = k11 m22 + k22 m11 − 2 k12 m12`, `c = det K`; the larger root by the
/// formula, the smaller as `c / (a λ₊)` (no cancellation).
fn two_dof_exact(m: &Rows<2>, k: &Rows<2>) -> [f64; 2] {
    let a = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let b = k[0][0] * m[1][1] + k[1][1] * m[0][0] - 2.0 * k[0][1] * m[0][1];
    let c = k[0][0] * k[1][1] - k[0][1] * k[1][0];
    let hi = (b + (b * b - 4.0 * a * c).sqrt()) / (2.0 * a);
    let lo = c / (a * hi);
    [lo.sqrt(), hi.sqrt()]
}

/// Two storeys of unequal mass and stiffness, a consistent (non-diagonal) mass matrix, and
/// a widely split pair (stiff top storey, `λ₂/λ₁ ≈ 4·10⁴`). The closed form has a few ε of
/// its own rounding; the solver's error on `ω₁` grows as `ε λ₂/λ₁`. Measured (printed):
/// ≤ 3.3e-16 relative, except 1.8e-13 on the stiff top's `ω₁`; bound `4 ε (1 + λ₂/λ₁)`
/// per case (3.6e-11 there, 1.8e-15 for the uncoupled pair).
#[test]
fn two_dof_matches_the_characteristic_polynomial() {
    let cases: [(&str, Rows<2>, Rows<2>); 4] = [
        (
            "shear, unequal",
            models::shear_building([2.0e5, 1.0e5], [3.0e8, 1.0e8]).0,
            models::shear_building([2.0e5, 1.0e5], [3.0e8, 1.0e8]).1,
        ),
        (
            "consistent mass",
            [[4.0, 1.0], [1.0, 2.0]],
            [[30.0, -10.0], [-10.0, 10.0]],
        ),
        (
            "stiff top",
            models::shear_building([1.0, 1.0], [1.0, 1.0e4]).0,
            models::shear_building([1.0, 1.0], [1.0, 1.0e4]).1,
        ),
        (
            "uncoupled",
            [[1.0, 0.0], [0.0, 3.0]],
            [[9.0, 0.0], [0.0, 3.0]],
        ),
    ];
    for (name, m, k) in cases {
        let w = models::natural_frequencies(&m, &k).unwrap();
        let exact = two_dof_exact(&m, &k);
        let spread = (exact[1] / exact[0]).powi(2);
        for r in 0..2 {
            let err = (w[r] - exact[r]).abs() / exact[r];
            eprintln!("{name}, mode {r}: {err:.2e}");
            assert!(
                err <= 64.0 * EPS * spread,
                "{name}, mode {r}: {} vs {}",
                w[r],
                exact[r]
            );
        }
    }
}

/// The reason the function is `const`: the benchmark building's Rayleigh damping computed
/// from its frequencies in a `const`, equal to `five_storey_building`'s (whose two
/// frequencies are written out from the closed form) to rounding: the coefficients differ
/// by the frequencies' error (a few ε), so `C` by a few ulps of its largest entry. Measured
/// 7.3e-16 of it (printed); bound 16 ε (3.6e-15).
#[test]
fn frequencies_in_a_const_feed_rayleigh_coefficients() {
    const B: (Rows<5>, Rows<5>, Rows<5>) = models::five_storey_building();
    const W: [f64; 5] = unwrap_const!(models::natural_frequencies(&B.0, &B.2));
    const AB: (f64, f64) = models::rayleigh_coefficients(W[0], W[1], models::FIVE_STOREY_DAMPING);
    const C: Rows<5> = models::rayleigh(&B.0, &B.2, AB.0, AB.1);
    let big = B.1.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
    let mut err = 0.0f64;
    for i in 0..5 {
        for j in 0..5 {
            err = err.max((C[i][j] - B.1[i][j]).abs());
        }
    }
    eprintln!(
        "C against five_storey_building: {:.2e} of its largest entry",
        err / big
    );
    assert!(err <= 16.0 * EPS * big, "{err:e}");
    // T₁ ≈ 0.70 s, as `five_storey_building` documents.
    assert!((2.0 * core::f64::consts::PI / W[0] - 0.698).abs() < 1e-3);
}

/// A free-free pair (two masses joined by one spring): a rigid-body mode, `ω = 0` (its
/// `λ` is rounding around zero, clamped), and `ω² = k (1/m₁ + 1/m₂)`.
#[test]
fn rigid_body_mode_is_zero() {
    let (k, m1, m2) = (5.0e7, 2.0e5, 3.0e5);
    let w = models::natural_frequencies(&[[m1, 0.0], [0.0, m2]], &[[k, -k], [-k, k]]).unwrap();
    let exact = (k * (1.0 / m1 + 1.0 / m2)).sqrt();
    assert!(w[0] <= 1e-6 * exact, "{}", w[0]);
    assert!(
        (w[1] - exact).abs() <= 8.0 * EPS * exact,
        "{} vs {exact}",
        w[1]
    );
}

#[test]
fn bad_models_are_typed_errors() {
    let one: Rows<2> = [[1.0, 0.0], [0.0, 1.0]];
    let nan: Rows<2> = [[1.0, f64::NAN], [f64::NAN, 1.0]];
    assert_eq!(
        models::natural_frequencies(&nan, &one),
        Err(Error::NonFiniteInput)
    );
    assert_eq!(
        models::natural_frequencies(&one, &nan),
        Err(Error::NonFiniteInput)
    );
    let inf: Rows<2> = [[f64::INFINITY, 0.0], [0.0, 1.0]];
    assert_eq!(
        models::natural_frequencies(&one, &inf),
        Err(Error::NonFiniteInput)
    );
    // M indefinite, or not symmetric.
    let m_bad: Rows<2> = [[1.0, 2.0], [2.0, 1.0]];
    assert_eq!(
        models::natural_frequencies(&m_bad, &one),
        Err(Error::MassNotSpd)
    );
    let m_asym: Rows<2> = [[1.0, 0.5], [0.0, 1.0]];
    assert_eq!(
        models::natural_frequencies(&m_asym, &one),
        Err(Error::MassNotSpd)
    );
    // K not symmetric; K with a negative eigenvalue (a storey of negative stiffness).
    let k_asym: Rows<2> = [[2.0, -1.0], [0.0, 1.0]];
    assert_eq!(
        models::natural_frequencies(&one, &k_asym),
        Err(Error::StiffnessNotSymmetric)
    );
    let (_, k_neg) = models::shear_building([1.0, 1.0], [1.0, -0.5]);
    assert_eq!(
        models::natural_frequencies(&one, &k_neg),
        Err(Error::StiffnessIndefinite)
    );
    assert_eq!(
        models::natural_frequencies(&one, &[[-1e-3, 0.0], [0.0, 1.0]]),
        Err(Error::StiffnessIndefinite)
    );
    // The error names itself in a `const` build: the text `unwrap_const!` panics with.
    assert!(
        Error::StiffnessIndefinite
            .as_str()
            .contains("positive semidefinite")
    );
}
