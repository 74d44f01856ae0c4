//! The zero-order-hold builder `StateSpace::zero_order_hold` (issue 31):
//!
//! - a single oscillator, damped and undamped, short and long steps, against `Φ` and `Γ`
//!   in closed form, and its output maps (`a = (w − c v − k u)/m`);
//! - the 5-storey building at 200 Hz and the paper's 3-DOF Example 4 (non-proportional
//!   sizes, every DOF loaded) against an independent computation written here:
//!   `Φ = e^{F h}` by nalgebra's own Padé exponential, `Γ = F⁻¹ (Φ − I) [0; M⁻¹] B`
//!   (no Van Loan block, no crate code), and a held force's response against the crate's
//!   first-order hold (`Γ₀ + Γ₁` of `StateSpace::exact`, the same input when it does not
//!   change over the step);
//! - typed errors.
//!
//! Tolerances are derived in each test; measured values are printed (`-- --nocapture`).

#![allow(clippy::needless_range_loop)] // matrix indices read best explicitly

use aemstep::Error;
use aemstep::models;
use aemstep::nalgebra::{DMatrix, SMatrix, matrix};
use aemstep::observer::{Outputs, StateSpace};

const EPS: f64 = f64::EPSILON;

/// `Φ` and `Γ` of `m u'' + c u' + k u = w`, `ω² = k/m`, `ζ = c/(2mω) < 1`, in closed form:
/// `Φ = e^{−ζωh} [[cos + (ζω/ω_d) sin, sin/ω_d], [−(ω²/ω_d) sin, cos − (ζω/ω_d) sin]]`
/// (`ω_d h` the argument), and the response to a unit force held from rest,
/// `Γ = [(1 − Φ_uu); −Φ_vu] / k` (the static displacement `1/k` less the free decay of
/// `−1/k`).
fn sdof_closed_form(m: f64, c: f64, k: f64, h: f64) -> ([[f64; 2]; 2], [f64; 2]) {
    let w = (k / m).sqrt();
    let z = c / (2.0 * m * w);
    let wd = w * (1.0 - z * z).sqrt();
    let (s, co) = (wd * h).sin_cos();
    let e = (-z * w * h).exp();
    let phi = [
        [e * (co + z * w / wd * s), e * s / wd],
        [-e * w * w / wd * s, e * (co - z * w / wd * s)],
    ];
    let gamma = [(1.0 - phi[0][0]) / k, -phi[1][0] / k];
    (phi, gamma)
}

#[test]
fn oscillator_matches_the_closed_form() {
    // Each entry of the closed form is a few correctly rounded elementary functions and
    // products (a few ε relative to its magnitude). The builder's exponential is a
    // degree-18 Taylor polynomial of F h / 2^s (remainder < 1e-22) squared s times: the
    // rounding of the scaled matrix is a relative error of a few ε in the rotation per
    // step, i.e. in the angle ω h / 2^s, and the squarings multiply it by 2^s — an error
    // of about ε · ω h in the phase, so in every entry of the rotation (|d cos|, |d sin|
    // ≤ 1), on top of the few ε of the polynomial itself (the balancing makes the u and v
    // rows of size 1). The entries are compared relative to their scale: ‖Φ‖ for Φ, the
    // static displacement 1/k for Γ_u (1 − Φ_uu cancels when ωh is small: the error is
    // relative to 1/k, not to Γ_u) and 1/√(km) for Γ_v. Bound 2 ε (1 + ω h); measured at
    // most 0.94 ε for ω h ≤ 1 (bound 4 ε) and 253 ε at ω h = 300 undamped (bound 602 ε).
    let cases = [
        // (m, c, k, h): undamped, lightly and heavily damped; ωh from 0.05 to 300.
        (2.0, 0.0, 50.0, 0.01),
        (2.0, 0.0, 50.0, 0.1),
        (1.0e5, 2.0e4, 1.0e8, 0.005),
        (3.0, 7.0, 12.0, 0.5),
        (1.0, 0.2, 1.0e4, 3.0),
        (0.5, 0.0, 4.5e4, 1.0),
    ];
    for (m, c, k, h) in cases {
        let ss = StateSpace::<1, 2, 1>::zero_order_hold(
            &matrix![m],
            &matrix![c],
            &matrix![k],
            &matrix![1.0],
            h,
        )
        .unwrap();
        let (phi, gamma) = sdof_closed_form(m, c, k, h);
        let nphi = phi.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
        let mut err = 0.0f64;
        for i in 0..2 {
            for j in 0..2 {
                err = err.max((ss.phi[i][j] - phi[i][j]).abs() / nphi);
            }
        }
        let scale_u = 1.0 / k;
        let scale_v = 1.0 / (k * m).sqrt(); // |Γ_v| ≤ e^{…}/(m ω_d) ~ 1/√(km)
        err = err.max((ss.gamma0[0][0] - gamma[0]).abs() / scale_u);
        err = err.max((ss.gamma0[1][0] - gamma[1]).abs() / scale_v);
        let wh = (k / m).sqrt() * h;
        let bound = 2.0 * EPS * (1.0 + wh);
        println!(
            "m {m:e} c {c:e} k {k:e} h {h}: ωh {wh:.3}, error {:.2} ε (bound {:.0} ε)",
            err / EPS,
            bound / EPS
        );
        assert!(err <= bound, "{:.1} ε", err / EPS);
        // Held input: nothing at the step's end.
        assert_eq!(ss.gamma1, [[0.0], [0.0]]);
        // The outputs: u, v, and a = (w − c v − k u)/m at t_n with the held sample w_n.
        assert_eq!((ss.dof_u, ss.dof_v), ([[1.0, 0.0]], [[0.0, 1.0]]));
        let a_ref = [-k / m, -c / m];
        for j in 0..2 {
            assert!((ss.dof_a[0][j] - a_ref[j]).abs() <= 2.0 * EPS * a_ref[j].abs());
        }
        assert!((ss.dof_a_input[0][0] - 1.0 / m).abs() <= 2.0 * EPS / m);
        let meas = ss
            .outputs(&Outputs::<1, 1, 1>::accelerations([[1.0]]))
            .unwrap();
        assert_eq!((meas.h, meas.d), (ss.dof_a, ss.dof_a_input));
    }
}

/// The independent `Φ`, `Γ` of `M u'' + C u' + K u = B w` held over `h`: `F` formed here,
/// `Φ` by nalgebra's `exp` (Padé, its own scaling and squaring), `Γ = F⁻¹ (Φ − I) G`,
/// `G = [0; M⁻¹ B]` (`F` is invertible when `K` and `M` are).
fn independent<const N: usize, const S: usize, const I: usize>(
    m: &SMatrix<f64, N, N>,
    c: &SMatrix<f64, N, N>,
    k: &SMatrix<f64, N, N>,
    b: &SMatrix<f64, N, I>,
    h: f64,
) -> (SMatrix<f64, S, S>, SMatrix<f64, S, I>) {
    let mi = m.try_inverse().unwrap();
    let mut f = DMatrix::<f64>::zeros(S, S);
    let mut g = DMatrix::<f64>::zeros(S, I);
    f.view_mut((0, N), (N, N)).fill_with_identity();
    f.view_mut((N, 0), (N, N)).copy_from(&(-mi * k));
    f.view_mut((N, N), (N, N)).copy_from(&(-mi * c));
    g.view_mut((N, 0), (N, I)).copy_from(&(mi * b));
    let phi = (&f * h).exp();
    let gamma = f.try_inverse().unwrap() * (&phi - DMatrix::<f64>::identity(S, S)) * g;
    (
        SMatrix::from_column_slice(phi.as_slice()),
        SMatrix::from_column_slice(gamma.as_slice()),
    )
}

/// The condition number (∞-norm) of `F h` balanced as the comparison is (u rows in m,
/// v rows in m/s: `diag(1, 1/ω)` with `ω = √‖M⁻¹K‖`), which the solve of `Γ` meets.
fn cond<const N: usize>(
    m: &SMatrix<f64, N, N>,
    c: &SMatrix<f64, N, N>,
    k: &SMatrix<f64, N, N>,
    h: f64,
) -> f64 {
    let mi = m.try_inverse().unwrap();
    let w = (mi * k).norm().sqrt();
    let mut f = DMatrix::<f64>::zeros(2 * N, 2 * N);
    f.view_mut((0, N), (N, N)).fill_with_identity();
    f.view_mut((0, N), (N, N)).scale_mut(w * h);
    f.view_mut((N, 0), (N, N)).copy_from(&(-mi * k * (h / w)));
    f.view_mut((N, N), (N, N)).copy_from(&(-mi * c * h));
    let norm = |a: &DMatrix<f64>| {
        (0..a.nrows())
            .map(|i| a.row(i).iter().map(|v| v.abs()).sum::<f64>())
            .fold(0.0, f64::max)
    };
    norm(&f) * norm(&f.clone().try_inverse().unwrap())
}

fn sm<const R: usize, const C: usize>(a: &[[f64; C]; R]) -> SMatrix<f64, R, C> {
    SMatrix::from_fn(|i, j| a[i][j])
}

/// The largest difference of two matrices relative to the larger's largest entry, per
/// block row `u` (rows `0..N`) and `v` (rows `N..2N`): the two halves have different
/// units (m and m/s).
fn rel_rows<const S: usize, const C: usize>(a: &SMatrix<f64, S, C>, b: &SMatrix<f64, S, C>) -> f64 {
    let n = S / 2;
    let mut worst = 0.0f64;
    for r in [0..n, n..S] {
        let (mut d, mut s) = (0.0f64, 0.0f64);
        for i in r {
            for j in 0..C {
                d = d.max((a[(i, j)] - b[(i, j)]).abs());
                s = s.max(a[(i, j)].abs()).max(b[(i, j)].abs());
            }
        }
        worst = worst.max(d / s);
    }
    worst
}

#[test]
fn buildings_match_an_independent_exponential() {
    // Two exponentials by different algorithms (the crate's balanced Taylor polynomial,
    // nalgebra's Padé approximant), each with a few ε of its balanced norm per squaring
    // (s ≤ 4 here, ‖Fh‖ ≤ 1.3): Φ to 1e-14 relative per block row (45 ε; measured 9.5e-16
    // and 4.5e-16). Γ by the solve with F amplifies the rounding of Φ − I by the
    // conditioning of F relative to the block rows' scales, computed here (κ∞ of F
    // balanced by the rows' units); bound 8 ε κ (printed with the measured values).
    let (m5, c5, k5) = models::five_storey_building();
    let (m, c, k) = (sm(&m5), sm(&c5), sm(&k5));
    let b = SMatrix::<f64, 5, 1>::from_column_slice(&[0.0, 0.0, 0.0, 0.0, 1.0]);
    let h = 0.005;
    let ss = StateSpace::<5, 10, 1>::zero_order_hold(&m, &c, &k, &b, h).unwrap();
    let (phi, gamma) = independent::<5, 10, 1>(&m, &c, &k, &b, h);
    let (dphi, dgamma) = (
        rel_rows(&ss.phi_matrix(), &phi),
        rel_rows(&ss.gamma0_matrix(), &gamma),
    );
    let kappa = cond(&m, &c, &k, h);
    println!(
        "5-storey, 200 Hz: Φ {dphi:.2e}, Γ {dgamma:.2e} (bound 8 ε κ = {:.2e})",
        8.0 * EPS * kappa
    );
    assert!(dphi <= 1e-14 && dgamma <= 8.0 * EPS * kappa);
    assert_eq!(ss.gamma1_matrix(), SMatrix::<f64, 10, 1>::zeros());

    // Example 4 of the AEM paper: fully populated, non-symmetric-looking data (Caughey
    // damping), every DOF loaded, a long step (ω_max h ≈ 1).
    let m3 = matrix![52.0, 10.0, 20.0; 10.0, 150.0, 30.0; 20.0, 30.0, 441.0];
    let k3 = matrix![1472.0, 407.0, 5553.0; 407.0, 1001.0, 4154.0; 5553.0, 4154.0, 43516.0];
    let c3 =
        matrix![34.3199, 27.9975, 89.4615; 27.9975, 172.1296, 50.4249; 89.4615, 50.4249, 770.3077];
    let b3 = matrix![1.0, 0.0; 0.5, 2.0; 0.0, -1.0];
    let h3 = 0.1;
    let ss3 = StateSpace::<3, 6, 2>::zero_order_hold(&m3, &c3, &k3, &b3, h3).unwrap();
    let (phi3, gamma3) = independent::<3, 6, 2>(&m3, &c3, &k3, &b3, h3);
    let (dphi3, dgamma3) = (
        rel_rows(&ss3.phi_matrix(), &phi3),
        rel_rows(&ss3.gamma0_matrix(), &gamma3),
    );
    let kappa3 = cond(&m3, &c3, &k3, h3);
    println!(
        "Example 4, h = 0.1: Φ {dphi3:.2e}, Γ {dgamma3:.2e} (bound 8 ε κ = {:.2e})",
        8.0 * EPS * kappa3
    );
    assert!(dphi3 <= 1e-14 && dgamma3 <= 8.0 * EPS * kappa3);

    // The output maps: a = M⁻¹ (B w − C v − K u), computed here.
    let mi = m3.try_inverse().unwrap();
    let (au, av, aw) = (-mi * k3, -mi * c3, mi * b3);
    let ax = sm(&ss3.dof_a);
    let da = (ax.fixed_view::<3, 3>(0, 0) - au).amax() / au.amax();
    let dv = (ax.fixed_view::<3, 3>(0, 3) - av).amax() / av.amax();
    let dw = (sm(&ss3.dof_a_input) - aw).amax() / aw.amax();
    println!("Example 4 outputs: A_u {da:.2e}, A_v {dv:.2e}, A_w {dw:.2e}");
    // A solve with M (κ(M) ≈ 20) against an explicit inverse: 1e-14.
    assert!(da <= 1e-14 && dv <= 1e-14 && dw <= 1e-14);
}

#[test]
fn a_held_input_is_the_first_order_hold_of_a_constant() {
    // The crate's first-order hold with p_{n−1} = p_n = p is the zero-order hold of p:
    // Γ₀ + Γ₁ of `exact` is Γ of `zero_order_hold`, the same Φ. Both from the same kind
    // of exponential; the first-order hold's Γ₀ = Γ₁ᵉ − Γ₂ᵉ/h and Γ₁ = Γ₂ᵉ/h are
    // rounded separately, and Γ₂ᵉ/h is a few times Γ₁ᵉ at 200 Hz (the cancellation is
    // mild): a few ε of the block rows' scale; bound 8 ε (measured 8e-19, far below:
    // the same exponential, and at this step Γ₂ᵉ/h rounds almost exactly).
    let (m5, c5, k5) = models::five_storey_building();
    let (m, c, k) = (sm(&m5), sm(&c5), sm(&k5));
    let b = SMatrix::<f64, 5, 2>::from_fn(|i, j| if i == 4 * j { 1.0 } else { 0.0 });
    let zoh = StateSpace::<5, 10, 2>::zero_order_hold(&m, &c, &k, &b, 0.005).unwrap();
    let foh = StateSpace::<5, 10, 2>::exact(&m, &c, &k, &b, 0.005).unwrap();
    let dphi = rel_rows(&zoh.phi_matrix(), &foh.phi_matrix());
    let dg = rel_rows(
        &zoh.gamma0_matrix(),
        &(foh.gamma0_matrix() + foh.gamma1_matrix()),
    );
    println!("ZOH vs FOH of a held input: Φ {dphi:.2e}, Γ {dg:.2e}");
    assert!(dphi <= 8.0 * EPS && dg <= 8.0 * EPS);
    assert_eq!(
        (zoh.dof_a, zoh.dof_a_input, zoh.dof_u, zoh.dof_v),
        (foh.dof_a, foh.dof_a_input, foh.dof_u, foh.dof_v)
    );
    // A displacement and an acceleration output: D only on the acceleration.
    let mut out = Outputs::<5, 2, 2>::zero();
    out.u[0][4] = 1.0;
    out.a[1][4] = 1.0;
    let meas = zoh.outputs(&out).unwrap();
    assert_eq!(meas.d[0], [0.0, 0.0]);
    assert_eq!(meas.d[1], [0.0, 1e-5]); // 1 / (1e5 kg) on the roof force
}

#[test]
fn typed_errors() {
    let (m, c, k, b) = (matrix![1.0], matrix![0.1], matrix![4.0], matrix![1.0]);
    assert_eq!(
        StateSpace::<1, 3, 1>::zero_order_hold(&m, &c, &k, &b, 0.1).err(),
        Some(Error::StateSizeMismatch)
    );
    assert_eq!(
        StateSpace::<1, 2, 1>::zero_order_hold(&m, &c, &k, &matrix![f64::NAN], 0.1).err(),
        Some(Error::NonFiniteInput)
    );
    assert_eq!(
        StateSpace::<1, 2, 1>::zero_order_hold(&m, &matrix![f64::INFINITY], &k, &b, 0.1).err(),
        Some(Error::NonFiniteInput)
    );
    for h in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        assert_eq!(
            StateSpace::<1, 2, 1>::zero_order_hold(&m, &c, &k, &b, h).err(),
            Some(Error::InvalidTimeStep)
        );
    }
    assert_eq!(
        StateSpace::<1, 2, 1>::zero_order_hold(&matrix![0.0], &c, &k, &b, 0.1).err(),
        Some(Error::SingularMass)
    );
    // A step so long that the exponential of a growing mode (negative stiffness)
    // overflows.
    assert_eq!(
        StateSpace::<1, 2, 1>::zero_order_hold(&m, &c, &matrix![-1e4], &b, 10.0).err(),
        Some(Error::OperatorOverflow)
    );
}
