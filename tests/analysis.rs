//! The `analysis` module against the closed forms of spec §4 and the known spectral
//! properties of each comparator scheme. The closed forms are written here, not taken
//! from the code under test.

use aemstep::analysis::{Scheme, amplification_matrix, sdof, spectral_radius};
use aemstep::{Linear, Newmark, Stepper};
use nalgebra::matrix;

const EPS: f64 = f64::EPSILON;

/// Logarithmic grid of s from 10^a to 10^b, `k` points per decade.
fn grid(a: i32, b: i32, k: i32) -> Vec<f64> {
    (a * k..=b * k)
        .map(|i| 10f64.powf(i as f64 / k as f64))
        .collect()
}

/// Spec §4: λ2 = [(4 − s²) + 4 i s √(1 − ξ²)] / (4 + s² + 4ξs).
fn aem_lambda(s: f64, xi: f64) -> (f64, f64) {
    let d = 4.0 + s * s + 4.0 * xi * s;
    ((4.0 - s * s) / d, 4.0 * s * (1.0 - xi * xi).sqrt() / d)
}

#[test]
fn aem_eigenvalues_match_closed_form() {
    // The computed pair comes from the characteristic polynomial of a matrix whose
    // entries are O(1) and carry a few ulps each: |λ|² = c has an absolute error of
    // ~8ε, and the imaginary part im = √(c − re²) an error of ~8ε/(2·im). Bounds below
    // follow from these with a factor of 2 to spare.
    for &xi in &[0.0, 0.05, 0.3] {
        for s in grid(-3, 3, 4) {
            let p = sdof(Scheme::Aem, s, xi).unwrap();
            let (re, im) = aem_lambda(s, xi);
            let r_exact = ((s * s + 4.0).powi(2) - 16.0 * xi * xi * s * s).sqrt()
                / (s * s + 4.0 + 4.0 * xi * s);
            assert!((re * re + im * im).sqrt() - r_exact < 4.0 * EPS);
            let (r, phi) = p.principal.unwrap();
            assert!(
                (r - r_exact).abs() <= 16.0 * EPS,
                "s={s} ξ={xi}: r={r} vs {r_exact}"
            );
            let phi_exact = im.atan2(re);
            let tol = 16.0 * EPS / im + 4.0 * EPS;
            assert!(
                (phi - phi_exact).abs() <= tol,
                "s={s} ξ={xi}: φ={phi} vs {phi_exact} (tol {tol:e})"
            );
            // λ1 = 0: the spectral radius is |λ2|, ≤ 1, = 1 iff ξ = 0.
            assert!((p.spectral_radius - r_exact).abs() <= 16.0 * EPS);
            if xi == 0.0 {
                assert!((p.spectral_radius - 1.0).abs() <= 4.0 * EPS);
            } else {
                assert!(p.spectral_radius < 1.0);
            }
        }
    }
}

#[test]
fn aem_period_elongation_closed_form_and_paper_values() {
    for s in grid(-2, 0, 8) {
        let p = sdof(Scheme::Aem, s, 0.0).unwrap();
        let pe = p.period_elongation().unwrap();
        // Exactly φ = 2 atan(s/2) per step, so PE = s/(2 atan(s/2)) − 1 = s²/12 − s⁴/180 + …
        let pe_exact = s / (2.0 * (s / 2.0).atan()) - 1.0;
        // Error of PE ≈ Δφ/φ with Δφ ≤ 16ε/s (see above): ≤ 16ε/s².
        assert!(
            (pe - pe_exact).abs() <= 16.0 * EPS / (s * s) + 4.0 * EPS,
            "s={s}"
        );
        assert!((pe - s * s / 12.0).abs() <= s.powi(4) / 180.0 + 16.0 * EPS / (s * s));
        // No amplitude decay without damping.
        assert!(p.amplitude_decay().unwrap().abs() <= 8.0 * EPS / s);
    }
    // Paper Example 1: ω = 5, PE = 0.02 % at h = 0.01 and 0.00021 % at h = 0.001.
    let pe1 = sdof(Scheme::Aem, 0.05, 0.0)
        .unwrap()
        .period_elongation()
        .unwrap();
    let pe2 = sdof(Scheme::Aem, 0.005, 0.0)
        .unwrap()
        .period_elongation()
        .unwrap();
    assert!((pe1 * 100.0 - 0.02083).abs() < 1e-5, "{}", pe1 * 100.0);
    assert!((pe2 * 100.0 - 0.000208).abs() < 1e-6, "{}", pe2 * 100.0);
}

#[test]
fn aem_forms_and_newmark_average_acceleration_share_one_matrix() {
    for &xi in &[0.0, 0.05] {
        for s in grid(-3, 3, 2) {
            let a = sdof(Scheme::Aem, s, xi).unwrap().matrix;
            let b = sdof(Scheme::AemAForm, s, xi).unwrap().matrix;
            let c = sdof(
                Scheme::Newmark {
                    beta: 0.25,
                    gamma: 0.5,
                },
                s,
                xi,
            )
            .unwrap()
            .matrix;
            // Generalized-α with ρ∞ = 1 has the same oscillatory pair but a spurious root
            // −1 instead of 0 (its acceleration is an average, not an equilibrium value):
            // compare the principal roots only, and only for s ≤ 10: beyond, the pair
            // closes in on the spurious root −1 and the (near-triple) root is
            // ill-conditioned.
            if s > 10.0 {
                continue;
            }
            let pa = sdof(Scheme::Aem, s, xi).unwrap().principal.unwrap();
            let pd = sdof(Scheme::GeneralizedAlpha { rho_inf: 1.0 }, s, xi)
                .unwrap()
                .principal
                .unwrap();
            assert!((pa.0 - pd.0).abs() <= 16.0 * EPS, "s={s}");
            assert!((pa.1 - pd.1).abs() <= 32.0 * EPS / pa.1.min(1.0), "s={s}");
            for i in 0..3 {
                for j in 0..3 {
                    // Newmark-AA is bit-identical to the eliminated AEM form.
                    assert_eq!(a[i][j], c[i][j]);
                    // A-form and ρ∞ = 1 generalized-α: same numbers through other
                    // roundings; entries are O(1) in these coordinates.
                    assert!((a[i][j] - b[i][j]).abs() <= 8.0 * EPS, "{a:?} {b:?}");
                }
            }
        }
    }
}

#[test]
fn amplification_matrix_matches_a_form_blocks() {
    // Independent route: the paper's A (blocks ordered q, v, u) from `a_form`, reordered
    // to (u, v, a) and scaled to (u, h v, h² a) here.
    let (w, xi, h) = (3.0f64, 0.1, 0.07);
    let lin =
        Linear::<f64, _>::new(&matrix![1.0], &matrix![2.0 * xi * w], &matrix![w * w], h).unwrap();
    let f = lin.a_form();
    let ours = amplification_matrix(&lin);
    let order = [2usize, 1, 0]; // (u, v, a) ← (q=0, v=1, u=2)
    let d = [1.0, 1.0 / h, 1.0 / (h * h)];
    for i in 0..3 {
        for j in 0..3 {
            let blk = f.a_block(order[i], order[j]).unwrap()[(0, 0)];
            let scaled = blk * d[j] / d[i];
            assert!((scaled - ours[i][j]).abs() <= 8.0 * EPS, "({i},{j})");
        }
    }
}

#[test]
fn newmark_stability_limits() {
    // Central difference (β = 0): undamped, |λ| = 1 for s ≤ 2; beyond, the real root
    // λ = 1 − s²/2 − √((1 − s²/2)² − 1) has modulus > 1.
    let cd = Scheme::Newmark {
        beta: 0.0,
        gamma: 0.5,
    };
    for s in [0.1, 1.0, 1.9] {
        assert!((sdof(cd, s, 0.0).unwrap().spectral_radius - 1.0).abs() < 1e-14);
    }
    for s in [2.1f64, 5.0, 100.0] {
        let b = 1.0 - s * s / 2.0;
        let expect = b.abs() + (b * b - 1.0).sqrt();
        let got = sdof(cd, s, 0.0).unwrap().spectral_radius;
        assert!(
            (got - expect).abs() <= 1e-12 * expect,
            "s={s}: {got} vs {expect}"
        );
    }
    // Linear acceleration (β = 1/6): stable up to s = 2√3 ≈ 3.464.
    let la = Scheme::Newmark {
        beta: 1.0 / 6.0,
        gamma: 0.5,
    };
    assert!(sdof(la, 3.4, 0.0).unwrap().spectral_radius <= 1.0 + 1e-14);
    assert!(sdof(la, 3.6, 0.0).unwrap().spectral_radius > 1.0 + 1e-3);
    // γ > 1/2 dissipates: |λ| < 1 for ξ = 0.
    let diss = Scheme::Newmark {
        beta: 0.3025,
        gamma: 0.6,
    };
    assert!(sdof(diss, 1.0, 0.0).unwrap().spectral_radius < 1.0 - 1e-3);
    // Newmark-LA period error: PE ≈ −s²/24 + … wait: LA shortens less than CD; the
    // closed form of its phase is cos φ = 1 − s²/(2(1 + s²/6)) (undamped).
    for s in [0.01f64, 0.1, 1.0, 3.0] {
        let (_, phi) = sdof(la, s, 0.0).unwrap().principal.unwrap();
        let exact = (1.0 - s * s / (2.0 * (1.0 + s * s / 6.0))).acos();
        assert!(
            (phi - exact).abs() <= 32.0 * EPS / s,
            "s={s}: {phi} vs {exact}"
        );
    }
}

#[test]
fn generalized_alpha_spectral_radius_at_infinity_and_hht() {
    // Chung–Hulbert: ρ(s → ∞) = ρ∞. The approach is O(1/s) for ρ∞ > 0 (measured 8e-5 at
    // s = 1e6 for ρ∞ = 0.8) and O(s^{-2/3}) for ρ∞ = 0, where the limit is a triple root
    // at 0 (measured 1.0e-4 = (1e-12)^{1/3}): bound 2e-4.
    for rho in [0.0, 0.3, 0.5, 0.8, 1.0] {
        let got = sdof(Scheme::GeneralizedAlpha { rho_inf: rho }, 1e6, 0.0)
            .unwrap()
            .spectral_radius;
        assert!((got - rho).abs() < 2e-4, "ρ∞ = {rho}: {got}");
        // Unconditionally stable. (ρ∞ = 1 is left out: there the roots approach a triple
        // root at −1 as s grows, which no eigenvalue routine resolves to a few ulps; it is
        // the AEM pair, checked above.)
        if rho == 1.0 {
            continue;
        }
        for s in grid(-3, 6, 2) {
            let r = sdof(Scheme::GeneralizedAlpha { rho_inf: rho }, s, 0.0)
                .unwrap()
                .spectral_radius;
            assert!(r <= 1.0 + 4.0 * EPS, "ρ∞ = {rho}, s = {s}: {r}");
        }
    }
    // HHT: ρ∞ = (1 + α)/(1 − α).
    for alpha in [-1.0 / 3.0, -0.1, -0.05] {
        let got = sdof(Scheme::Hht { alpha }, 1e6, 0.0)
            .unwrap()
            .spectral_radius;
        let expect = (1.0 + alpha) / (1.0 - alpha);
        assert!(
            (got - expect).abs() < 1e-4,
            "α = {alpha}: {got} vs {expect}"
        );
    }
}

#[test]
fn generalized_alpha_is_second_order_with_third_order_damping() {
    // Chung–Hulbert 1993: PE = O(s²) and ξ̄ = O(s³) for ρ∞ < 1. Observed orders from
    // s = 0.02 → 0.01 must be 2 and 3 within ±0.1 (higher-order terms at s = 0.02 are
    // ~s² relative, 4e-4).
    for rho in [0.0, 0.5, 0.8] {
        let sch = Scheme::GeneralizedAlpha { rho_inf: rho };
        let (a, b) = (sdof(sch, 0.02, 0.0).unwrap(), sdof(sch, 0.01, 0.0).unwrap());
        let pe_order = (a.period_elongation().unwrap() / b.period_elongation().unwrap()).log2();
        let xi_order = (a.algorithmic_damping().unwrap() / b.algorithmic_damping().unwrap()).log2();
        assert!(
            (pe_order - 2.0).abs() < 0.1,
            "ρ∞={rho}: PE order {pe_order}"
        );
        assert!((xi_order - 3.0).abs() < 0.1, "ρ∞={rho}: ξ̄ order {xi_order}");
    }
}

#[test]
fn exact_scheme_has_no_period_or_amplitude_error() {
    // For s below π (no aliasing) the exact flow: λ = exp((−ξ ± i√(1−ξ²)) s).
    for &xi in &[0.0, 0.05, 0.3] {
        for s in grid(-1, 0, 4).into_iter().chain([2.0, 3.0]) {
            let p = sdof(Scheme::Exact, s, xi).unwrap();
            let (r, phi) = p.principal.unwrap();
            let (r_ex, phi_ex) = ((-xi * s).exp(), s * (1.0 - xi * xi).sqrt());
            // Rounding of the Taylor/squaring exponential and of the characteristic
            // polynomial: a few hundred ε at most for these s (measured ≤ 1e-15).
            assert!(
                (r - r_ex).abs() <= 64.0 * EPS,
                "s={s} ξ={xi}: r {r} vs {r_ex}"
            );
            assert!(
                (phi - phi_ex).abs() <= 64.0 * EPS / phi_ex.min(1.0),
                "s={s} ξ={xi}"
            );
            assert!(p.period_elongation().unwrap().abs() <= 1e-13);
            assert!(p.amplitude_decay().unwrap().abs() <= 1e-13);
        }
    }
}

#[test]
fn spectral_radius_of_known_matrices() {
    // Rotation by θ in a plane plus a real eigenvalue 0.5, in a non-orthogonal basis.
    let t: f64 = 0.3;
    let b = [
        [t.cos(), -t.sin(), 0.0],
        [t.sin(), t.cos(), 0.0],
        [0.0, 0.0, 0.5],
    ];
    let s = [[1.0, 2.0, 0.0], [0.0, 1.0, 3.0], [1.0, 0.0, 1.0]];
    let si = nalgebra::Matrix3::from_fn(|i, j| s[i][j])
        .try_inverse()
        .unwrap();
    let bm = nalgebra::Matrix3::from_fn(|i, j| b[i][j]);
    let sm = nalgebra::Matrix3::from_fn(|i, j| s[i][j]);
    let a = sm * bm * si;
    let arr = [
        [a[(0, 0)], a[(0, 1)], a[(0, 2)]],
        [a[(1, 0)], a[(1, 1)], a[(1, 2)]],
        [a[(2, 0)], a[(2, 1)], a[(2, 2)]],
    ];
    assert!((spectral_radius(&arr) - 1.0).abs() < 1e-14);
    // Three real roots: diag(0.9, −0.7, 0.2).
    let d = [[0.9, 0.0, 0.0], [0.0, -0.7, 0.0], [0.0, 0.0, 0.2]];
    assert!((spectral_radius(&d) - 0.9).abs() < 1e-15);
    // A 1-DOF Newmark stepper's matrix equals the one `sdof` builds.
    let nm = Newmark::<f64, _>::new(&matrix![1.0], &matrix![0.0], &matrix![1.0], 0.5, 0.25, 0.5)
        .unwrap();
    assert_eq!(nm.time_step(), 0.5);
    assert_eq!(
        amplification_matrix(&nm),
        sdof(
            Scheme::Newmark {
                beta: 0.25,
                gamma: 0.5
            },
            0.5,
            0.0
        )
        .unwrap()
        .matrix
    );
}
