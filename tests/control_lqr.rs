//! The discrete LQR (`aemstep::control::Lqr`) and its delayed design model, checked against
//! references written here from the equations: the scalar Riccati equation's closed-form
//! root, and the Riccati difference equation iterated in nalgebra to its limit (the
//! finite-horizon recursion) on a 3-storey shear building, with drift weighting and with
//! absolute-acceleration weighting (the cross term); and the closed-loop certificate's
//! independence of units on the trade-off scene's 5-storey designs
//! (`scenes/control/tradeoff.rs`), against nalgebra's eigenvalues.

#[path = "../scenes/control/tradeoff.rs"]
mod tradeoff;

use aemstep::control::{DesignModel, Lqr, Weights};
use aemstep::models::{self, storey_drifts};
use aemstep::nalgebra::{DMatrix, SMatrix, SVector};
use aemstep::observer::{Outputs, StateSpace};
use aemstep::{Error, Param};

type M6 = SMatrix<f64, 6, 6>;

/// The 3-storey shear building (1000 kg floors, 1 MN/m storeys, Rayleigh 2 % at its first
/// and third modes), an actuator force on floor 1, zero-order hold at `h`.
fn building(h: f64) -> StateSpace<3, 6, 1> {
    let (m, k) = models::shear_building([1.0e3; 3], [1.0e6; 3]);
    let w = models::natural_frequencies(&m, &k).unwrap();
    let (a0, a1) = models::rayleigh_coefficients(w[0], w[2], 0.02);
    let c = models::rayleigh(&m, &k, a0, a1);
    let mat = |r| models::matrix_of::<f64, 3>(&r);
    let b = SMatrix::<f64, 3, 1>::new(1.0, 0.0, 0.0);
    StateSpace::zero_order_hold(&mat(m), &mat(c), &mat(k), &b, h).unwrap()
}

/// The Riccati difference equation written from its definition,
/// `P' = Q + Φᵀ P Φ − (Φᵀ P Γ + S)(R + Γᵀ P Γ)⁻¹(Γᵀ P Φ + Sᵀ)`, iterated from `P = 0` (the
/// finite-horizon cost-to-go, backwards) until the update is below `4ε ‖P‖` for 20
/// iterations in a row. Returns `P`, its gain `(R + Γᵀ P Γ)⁻¹(Γᵀ P Φ + Sᵀ)`, the iterations
/// and the last relative update.
fn riccati_recursion<const S: usize>(
    phi: &SMatrix<f64, S, S>,
    g: &SMatrix<f64, S, 1>,
    q: &SMatrix<f64, S, S>,
    r: f64,
    s: &SMatrix<f64, S, 1>,
) -> (SMatrix<f64, S, S>, SMatrix<f64, 1, S>, usize, f64) {
    let mut p = SMatrix::<f64, S, S>::zeros();
    let mut calm = 0;
    let mut last = 0.0;
    for it in 0..400_000 {
        let gpg = (g.transpose() * p * g)[0] + r;
        let m = g.transpose() * p * phi + s.transpose();
        let next = q + phi.transpose() * p * phi - m.transpose() * m / gpg;
        let next = (next + next.transpose()) * 0.5;
        last = (next - p).amax() / next.amax();
        p = next;
        calm = if last <= 4.0 * f64::EPSILON {
            calm + 1
        } else {
            0
        };
        if calm == 20 {
            let k = (g.transpose() * p * phi + s.transpose()) / ((g.transpose() * p * g)[0] + r);
            return (p, k, it, last);
        }
    }
    panic!("the recursion did not settle ({last:e})");
}

/// The scalar DARE `p = a² p − (a b p + s)²/(r + b² p) + q` has the closed-form root of
/// `b² p² + (r − a² r + 2 a b s − q b²) p + s² − q r = 0` (the positive one);
/// `k = (a b p + s)/(r + b² p)`. An unstable plant (`a = 1.2`), with and without a cross
/// weight: `P` and `K` agree to a few ulps (the quadratic formula here and the doubling
/// each round at `ε`; measured 0 to 2 ulps, bound 16ε relative).
#[test]
fn scalar_riccati_closed_form() {
    let (a, b, q, r) = (1.2f64, 0.5, 2.0, 0.7);
    for s in [0.0, 0.3, -0.5] {
        let bb = r - a * a * r + 2.0 * a * b * s - q * b * b;
        let c = s * s - q * r;
        // Root without cancellation: c < 0, so the positive root is 2c/(−bb − √disc).
        let disc = (bb * bb - 4.0 * b * b * c).sqrt();
        let p = if bb > 0.0 {
            2.0 * c / (-bb - disc)
        } else {
            (-bb + disc) / (2.0 * b * b)
        };
        let k = (a * b * p + s) / (r + b * b * p);
        let lqr = Lqr::<1, 1>::from_parts(
            &DesignModel {
                phi: [[a]],
                gamma: [[b]],
            },
            &Weights {
                q: [[q]],
                r: [[r]],
                cross: [[s]],
            },
        )
        .unwrap();
        let (ep, ek) = (
            (lqr.cost[0][0] - p).abs() / p,
            (lqr.gain[0][0] - k).abs() / k.abs(),
        );
        println!("s = {s}: p = {p}, k = {k}, errors {ep:.1e}, {ek:.1e}");
        assert!(ep <= 16.0 * f64::EPSILON && ek <= 16.0 * f64::EPSILON);
        // The closed loop a − b k, certified.
        let pole = a - b * k;
        assert!(pole.abs() <= lqr.radius_bound && lqr.radius_bound < 1.0);
        assert!((lqr.closed_loop[0][0] - pole).abs() <= 4.0 * f64::EPSILON);
    }
}

/// The building's gain against the Riccati recursion's limit, for drift weighting
/// (`S = 0`) and absolute-acceleration weighting (`Q = Cᵀ Q_y C`, `S = Cᵀ Q_y D`,
/// `R + Dᵀ Q_y D` written here from `H`, `D`). Tolerance from conditioning: the recursion
/// stops with its update at `ε ‖P‖` and contracts like `ρ²` (`ρ` the closed loop's
/// spectral radius), so it sits within about `ε/(1 − ρ²)` of its limit; the doubling's
/// solution is verified to a residual of rounding, amplified by the same `1/(1 − ρ²)`.
/// The bound is `64 ε/(1 − ρ²)` relative to `max|P|` (and to `max|K|`), measured about
/// `1e-14`–`1e-13`.
#[test]
fn building_gain_matches_the_riccati_recursion() {
    let ss = building(0.005);
    let design = DesignModel::from_state_space(&ss);
    let (phi, g) = (ss.phi_matrix(), ss.gamma0_matrix());
    // Drifts in cm² against force in kN².
    let drifts = ss
        .outputs(&Outputs::displacements(storey_drifts::<3>()))
        .unwrap();
    let qy = [[1.0e4, 0.0, 0.0], [0.0, 1.0e4, 0.0], [0.0, 0.0, 1.0e4]];
    let r = 1.0e-6;
    // Relative accelerations: the absolute ones less the ground's, which the control
    // does not move; D = M⁻¹ B feeds the force through.
    let accel = ss
        .outputs(&Outputs::accelerations(Outputs::<3, 1, 3>::select([
            0, 1, 2,
        ])))
        .unwrap();
    let qa = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for (name, meas, qy) in [("drifts", drifts, qy), ("accelerations", accel, qa)] {
        let w = Weights::outputs(&meas, &qy, &[[r]]);
        let lqr = Lqr::from_parts(&design, &w).unwrap();
        // The weights from their definition.
        let (c, d) = (meas.h_matrix(), meas.d_matrix());
        let qym = SMatrix::<f64, 3, 3>::from_fn(|i, j| qy[i][j]);
        let q = c.transpose() * qym * c;
        let s = c.transpose() * qym * d;
        let rt = r + (d.transpose() * qym * d)[0];
        let wq = SMatrix::<f64, 6, 6>::from_fn(|i, j| w.q[i][j]);
        assert!((wq - q).amax() <= 1e-15 * q.amax());
        assert!(
            (SMatrix::<f64, 6, 1>::from_fn(|i, _| w.cross[i][0]) - s).amax()
                <= 1e-15 * s.amax().max(1e-300)
        );
        assert!((w.r[0][0] - rt).abs() <= 1e-15 * rt);
        let (p, k, its, _) = riccati_recursion(&phi, &g, &q, rt, &s);
        // The closed loop of the recursion's gain, its eigenvalues by nalgebra.
        let moduli = |a: &M6| {
            let mut m: Vec<f64> = DMatrix::from_fn(6, 6, |i, j| a[(i, j)])
                .complex_eigenvalues()
                .iter()
                .map(|z| z.norm())
                .collect();
            m.sort_by(f64::total_cmp);
            m
        };
        let reference = moduli(&(phi - g * k));
        let rho = reference[5];
        // The host-only poles of the crate: the same moduli.
        #[cfg(feature = "std")]
        {
            let mut poles: Vec<f64> = lqr.poles().unwrap().iter().map(|z| z.norm()).collect();
            poles.sort_by(f64::total_cmp);
            for (a, b) in poles.iter().zip(&reference) {
                assert!((a - b).abs() <= 1e-9, "{a} {b}");
            }
        }
        let tol = 64.0 * f64::EPSILON / (1.0 - rho * rho);
        let ep = (lqr.cost_matrix() - p).amax() / p.amax();
        let ek = (lqr.gain_matrix() - k).amax() / k.amax();
        println!(
            "{name}: recursion {its} iterations, doubling {}; rho {rho:.6} (bound {:.6}, \
             {:.1e} above); P error {ep:.1e}, K error {ek:.1e} (tolerance {tol:.1e})",
            lqr.iterations,
            lqr.radius_bound,
            lqr.radius_bound - rho
        );
        assert!(ep <= tol && ek <= tol);
        // The certified bound is a bound, below 1, and tight to the bisection's
        // resolution (2^-30 relative; measured 3e-11 and 1e-10 above ρ). ρ here is the
        // recursion's gain's: within 1e-12 of the regulator's (K error 3e-13).
        assert!(rho <= lqr.radius_bound + 1.0e-12 && lqr.radius_bound < 1.0);
        assert!(lqr.radius_bound - rho <= RESOLUTION);
    }
}

/// The delayed model's blocks, and that it reproduces the plant driven by the previous
/// sample's command: `x_{k+1} = Φ x_k + Γ u_{k−1}` stepped by hand against the augmented
/// model's `z_{k+1} = Φ_z z_k + Γ_z u_k`, bit for bit (the same products, zeros added).
#[test]
fn delayed_model_is_the_plant_with_the_previous_command() {
    let ss = building(0.01);
    let plant = DesignModel::from_state_space(&ss);
    let z: DesignModel<7, 1> = plant.delayed().unwrap();
    assert_eq!(plant.delayed::<6>(), Err(Error::StateSizeMismatch));
    for i in 0..6 {
        assert_eq!(z.phi[i][..6], plant.phi[i][..]);
        assert_eq!(z.phi[i][6], plant.gamma[i][0]);
        assert_eq!(z.gamma[i][0], 0.0);
    }
    assert_eq!(z.phi[6], [0.0; 7]);
    assert_eq!(z.gamma[6][0], 1.0);
    let (phi, g) = (ss.phi_matrix(), ss.gamma0_matrix());
    let (phiz, gz) = (
        SMatrix::<f64, 7, 7>::from_fn(|i, j| z.phi[i][j]),
        SMatrix::<f64, 7, 1>::from_fn(|i, j| z.gamma[i][j]),
    );
    let mut x = SVector::<f64, 6>::zeros();
    let mut zz = SVector::<f64, 7>::zeros();
    let mut prev = 0.0;
    for k in 0..50 {
        let u = (0.3 * k as f64).sin() * 100.0;
        x = phi * x + g * prev;
        zz = phiz * zz + gz * u;
        prev = u;
        assert_eq!(zz.fixed_rows::<6>(0), x);
        assert_eq!(zz[6], u);
    }
    // The delayed design is stabilizing and certified.
    let drifts = ss
        .outputs(&Outputs::displacements(storey_drifts::<3>()))
        .unwrap();
    let w = Weights::outputs(
        &drifts,
        &[[1e4, 0.0, 0.0], [0.0, 1e4, 0.0], [0.0, 0.0, 1e4]],
        &[[1e-6]],
    );
    let lqr = Lqr::from_parts(&z, &w.delayed(&[[1e-9]]).unwrap()).unwrap();
    assert!(lqr.radius_bound < 1.0);
    assert_eq!(w.delayed::<8>(&[[1e-9]]), Err(Error::StateSizeMismatch));
}

/// An unstable mode the input cannot reach (`Φ = diag(1.1, 0.5)`, `Γ = [0; 1]`) has no
/// stabilizing Riccati solution: the doubling's `P` grows like `1.1^(2^(k+1))` and
/// overflows or never settles, so the solver reports [`Error::RiccatiNotConverged`]
/// before any gain is formed (`NotStabilizing` is the certificate's error, for a gain
/// the solver accepted). A stable uncontrollable mode is fine.
#[test]
fn unstabilizable_pair_is_refused() {
    let w = Weights::new(&[[1.0, 0.0], [0.0, 1.0]], &[[1.0]]);
    let bad = DesignModel {
        phi: [[1.1, 0.0], [0.0, 0.5]],
        gamma: [[0.0], [1.0]],
    };
    assert_eq!(Lqr::from_parts(&bad, &w), Err(Error::RiccatiNotConverged));
    let fine = DesignModel {
        phi: [[0.9, 0.0], [0.0, 1.5]],
        gamma: [[0.0], [1.0]],
    };
    let lqr = Lqr::from_parts(&fine, &w).unwrap();
    // The uncontrollable mode stays at 0.9; the certificate covers it.
    assert!(lqr.radius_bound >= 0.9 && lqr.radius_bound < 1.0);
}

/// Bad weights by category give typed errors.
#[test]
fn bad_weights_are_typed_errors() {
    let ss = building(0.01);
    let design = DesignModel::from_state_space(&ss);
    let mut q = [[0.0; 6]; 6];
    for (i, row) in q.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    let good = Weights::new(&q, &[[1e-6]]);
    assert!(Lqr::from_parts(&design, &good).is_ok());
    let weight = Err(Error::InvalidParameter(Param::Weight));
    // Non-finite.
    let mut w = good;
    w.q[2][2] = f64::NAN;
    assert_eq!(Lqr::from_parts(&design, &w), Err(Error::NonFiniteInput));
    let mut w = good;
    w.cross[0][0] = f64::INFINITY;
    assert_eq!(Lqr::from_parts(&design, &w), Err(Error::NonFiniteInput));
    let mut d = design;
    d.gamma[3][0] = f64::NAN;
    assert_eq!(Lqr::from_parts(&d, &good), Err(Error::NonFiniteInput));
    // Q not positive semidefinite; not symmetric.
    let mut w = good;
    w.q[1][1] = -1e-3;
    assert_eq!(Lqr::from_parts(&design, &w), weight);
    let mut w = good;
    w.q[0][1] = 0.5;
    assert_eq!(Lqr::from_parts(&design, &w), weight);
    // R not positive definite.
    for r in [0.0, -1.0] {
        let mut w = good;
        w.r[0][0] = r;
        assert_eq!(Lqr::from_parts(&design, &w), weight);
    }
    // The joint weight [Q S; Sᵀ R] not positive semidefinite: S² > Q R.
    let mut w = good;
    w.cross[0][0] = 2e-3;
    assert_eq!(Lqr::from_parts(&design, &w), weight);
    // Run time: the same.
    assert_eq!(Lqr::new(&ss.phi_matrix(), &ss.gamma0_matrix(), &w), weight);
}

/// The regulator in `const fn`: a gain computed by the compiler equals the run-time one bit
/// for bit.
#[test]
fn const_gain_equals_run_time() {
    const W: Weights<2, 1> = Weights::new(&[[1.0, 0.0], [0.0, 0.1]], &[[0.5]]);
    const D: DesignModel<2, 1> = DesignModel {
        phi: [[1.0, 0.01], [-0.1, 0.99]],
        gamma: [[0.0], [0.01]],
    };
    static LQR: Lqr<2, 1> = match Lqr::from_parts(&D, &W) {
        Ok(l) => l,
        Err(e) => panic!("{}", e.as_str()),
    };
    let run = Lqr::new(
        &SMatrix::<f64, 2, 2>::new(1.0, 0.01, -0.1, 0.99),
        &SMatrix::<f64, 2, 1>::new(0.0, 0.01),
        &W,
    )
    .unwrap();
    assert_eq!(LQR, run);
}

/// The sampled-data weights of a scalar system against the integrals written out:
/// `x(τ) = e^{aτ} x + b (e^{aτ} − 1)/a u`, so `Q_d = q (e^{2ah} − 1)/(2a)`,
/// `S_d = (q b/a) [(e^{2ah} − 1)/(2a) − (e^{ah} − 1)/a]`,
/// `R_d = r h + (q b²/a²) [(e^{2ah} − 1)/(2a) − 2 (e^{ah} − 1)/a + h]`, and
/// `Φ = e^{ah}`, `Γ = b (e^{ah} − 1)/a`. The bracket of `R_d` cancels down to `(ah)³/(3a)`
/// from terms of size `h`: its rounding is about `ε/(ah)²` relative (`3e-15` at `ah = −0.2`);
/// the exponential's Taylor polynomial is good to `2e-23`. Bound `5e-14` relative (about
/// ten times that, for the squarings' rounding); measured at most `5.4e-15`.
#[test]
fn sampled_weights_match_the_integrals() {
    let (a, b, q, r, h) = (-2.0f64, 3.0, 5.0, 0.7, 0.1);
    let (model, w) =
        Weights::<1, 1>::sampled::<2>(&Weights::new(&[[q]], &[[r]]), &[[a]], &[[b]], h).unwrap();
    let (e1, e2) = ((a * h).exp(), (2.0 * a * h).exp());
    let qd = q * (e2 - 1.0) / (2.0 * a);
    let sd = q * b / a * ((e2 - 1.0) / (2.0 * a) - (e1 - 1.0) / a);
    let rd = r * h + q * b * b / (a * a) * ((e2 - 1.0) / (2.0 * a) - 2.0 * (e1 - 1.0) / a + h);
    let rel = |x: f64, y: f64| (x - y).abs() / y.abs();
    let errs = [
        rel(model.phi[0][0], e1),
        rel(model.gamma[0][0], b * (e1 - 1.0) / a),
        rel(w.q[0][0], qd),
        rel(w.cross[0][0], sd),
        rel(w.r[0][0], rd),
    ];
    println!("Phi, Gamma, Q_d, S_d, R_d relative errors {errs:?}");
    assert!(errs.iter().all(|&e| e <= 5e-14));
    assert_eq!(
        Weights::<1, 1>::sampled::<3>(&Weights::new(&[[q]], &[[r]]), &[[a]], &[[b]], h),
        Err(Error::StateSizeMismatch)
    );
    assert_eq!(
        Weights::<1, 1>::sampled::<2>(&Weights::new(&[[q]], &[[r]]), &[[a]], &[[b]], 0.0),
        Err(Error::InvalidTimeStep)
    );
    assert_eq!(
        Weights::<1, 1>::sampled::<2>(&Weights::new(&[[f64::NAN]], &[[r]]), &[[a]], &[[b]], h),
        Err(Error::NonFiniteInput)
    );
}

/// The continuous regulator by Newton–Kleinman, written here: from a stabilizing `K₀`,
/// solve the Lyapunov equation `A_kᵀ P + P A_k + Q + K_kᵀ R K_k = 0` (`A_k = F − G K_k`) by
/// its Kronecker form `(I ⊗ A_kᵀ + A_kᵀ ⊗ I) vec P = −vec(…)`, then `K_{k+1} = R⁻¹ Gᵀ P`;
/// 30 iterations (quadratic convergence).
fn continuous_lqr(
    f: &SMatrix<f64, 2, 2>,
    g: &SMatrix<f64, 2, 1>,
    q: &SMatrix<f64, 2, 2>,
    r: f64,
) -> (SMatrix<f64, 2, 2>, SMatrix<f64, 1, 2>) {
    let mut k = SMatrix::<f64, 1, 2>::zeros();
    let mut p = SMatrix::<f64, 2, 2>::zeros();
    for _ in 0..30 {
        let a = f - g * k;
        let rhs = -(q + k.transpose() * k * r);
        let id = SMatrix::<f64, 2, 2>::identity();
        let kron = id.kronecker(&a.transpose()) + a.transpose().kronecker(&id);
        let v = SVector::<f64, 4>::from_column_slice(rhs.as_slice());
        let x = kron.lu().solve(&v).unwrap();
        p = SMatrix::<f64, 2, 2>::from_column_slice(x.as_slice());
        p = (p + p.transpose()) * 0.5;
        k = g.transpose() * p / r;
    }
    (p, k)
}

/// A continuous design reproduced by the discrete one as `h → 0`: the scalar CARE's
/// closed form (`2ap − b²p²/r + q = 0`, `K = bp/r`, an unstable `a`) and a damped
/// oscillator's (Newton–Kleinman above). The sampled-data gain is the optimum over held
/// inputs, which differ from the continuous ones by `O(h)` (a hold lags by `h/2`): the
/// claim is the order, the error falling by about ten for each tenfold smaller step
/// (measured ratios 9.6–10.0). Its constant scales with the closed loop's fastest
/// continuous pole `|λ|` (measured `0.50 |λ| h` scalar, `1.6 |λ| h` oscillator); the bound
/// `2 |λ| h` is a regression pin on it.
#[test]
fn sampled_design_converges_to_the_continuous_regulator() {
    // Scalar.
    let (a, b, q, r) = (0.5f64, 1.0, 1.0, 0.1);
    let pc = (a * r + (a * a * r * r + b * b * q * r).sqrt()) / (b * b);
    let kc = b * pc / r;
    // Oscillator: ω = 2π, ζ = 2 %, force input.
    let w0 = 2.0 * std::f64::consts::PI;
    let f2 = SMatrix::<f64, 2, 2>::new(0.0, 1.0, -w0 * w0, -2.0 * 0.02 * w0);
    let g2 = SMatrix::<f64, 2, 1>::new(0.0, 1.0);
    let q2 = SMatrix::<f64, 2, 2>::new(w0 * w0, 0.0, 0.0, 1.0);
    let r2 = 0.01;
    let (pc2, kc2) = continuous_lqr(&f2, &g2, &q2, r2);
    // The reference solves its Riccati equation.
    let res = f2.transpose() * pc2 + pc2 * f2 - pc2 * g2 * g2.transpose() * pc2 / r2 + q2;
    assert!(res.amax() <= 1e-10 * pc2.amax());
    // The closed loops' fastest continuous poles (1/s).
    let lam1 = (a - b * kc).abs();
    let lam2 = (f2 - g2 * kc2)
        .complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max);
    println!("continuous closed-loop poles up to {lam1:.2} and {lam2:.2} 1/s");
    let mut last: Option<(f64, f64)> = None;
    for h in [1e-2, 1e-3, 1e-4] {
        let (m1, w1) =
            Weights::<1, 1>::sampled::<2>(&Weights::new(&[[q]], &[[r]]), &[[a]], &[[b]], h)
                .unwrap();
        let e1 = (Lqr::from_parts(&m1, &w1).unwrap().gain[0][0] - kc).abs() / kc;
        let f2r = [[f2[(0, 0)], f2[(0, 1)]], [f2[(1, 0)], f2[(1, 1)]]];
        let q2r = [[q2[(0, 0)], 0.0], [0.0, q2[(1, 1)]]];
        let (m2, w2) =
            Weights::<2, 1>::sampled::<3>(&Weights::new(&q2r, &[[r2]]), &f2r, &[[0.0], [1.0]], h)
                .unwrap();
        let l2 = Lqr::from_parts(&m2, &w2).unwrap();
        let e2 = (l2.gain_matrix() - kc2).amax() / kc2.amax();
        println!("h = {h:e}: scalar gain error {e1:.2e}, oscillator {e2:.2e} (relative)");
        assert!(e1 <= 2.0 * lam1 * h && e2 <= 2.0 * lam2 * h);
        if let Some((p1, p2)) = last {
            let (r1, r2) = (p1 / e1, p2 / e2);
            println!("  ratios {r1:.2}, {r2:.2}");
            assert!((8.0..12.0).contains(&r1) && (8.0..12.0).contains(&r2));
        }
        last = Some((e1, e2));
    }
}

/// A modal design: the 5-storey building's two lowest modes (`StateSpace::from_rows_modal`,
/// `x = [η; η']`, 4 states; the AEM's two-ended input held over the step, `Γ₀ + Γ₁`), an
/// actuator on floor 1, the roof drift weighted through the modal `H`. Against the Riccati
/// recursion's limit as for the full model (same tolerance, from conditioning).
#[test]
fn modal_design_matches_the_riccati_recursion() {
    let (m, _, k) = models::five_storey_building();
    let ss = StateSpace::<5, 4, 1>::from_rows_modal(
        m,
        k,
        aemstep::Damping::Ratios([0.02; 5]),
        [[1.0], [0.0], [0.0], [0.0], [0.0]],
        [0, 1],
        0.01,
    )
    .unwrap();
    let design = DesignModel::from_state_space(&ss);
    let roof = ss
        .outputs(&Outputs::displacements([[0.0, 0.0, 0.0, -1.0, 1.0]]))
        .unwrap();
    let w = Weights::outputs(&roof, &[[1.0e6]], &[[1.0e-9]]);
    let lqr = Lqr::from_parts(&design, &w).unwrap();
    let phi = SMatrix::<f64, 4, 4>::from_fn(|i, j| design.phi[i][j]);
    let g = SMatrix::<f64, 4, 1>::from_fn(|i, _| design.gamma[i][0]);
    let q = SMatrix::<f64, 4, 4>::from_fn(|i, j| w.q[i][j]);
    let (p, kr, its, _) = riccati_recursion(&phi, &g, &q, w.r[0][0], &SMatrix::zeros());
    let rho = DMatrix::from_fn(4, 4, |i, j| (phi - g * kr)[(i, j)])
        .complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max);
    let tol = 64.0 * f64::EPSILON / (1.0 - rho * rho);
    let ep = (lqr.cost_matrix() - p).amax() / p.amax();
    let ek = (lqr.gain_matrix() - kr).amax() / kr.amax();
    println!(
        "modal: recursion {its} iterations; rho {rho:.6} (bound {:.6}, {:.1e} above); \
         P error {ep:.1e}, K error {ek:.1e} (tolerance {tol:.1e})",
        lqr.radius_bound,
        lqr.radius_bound - rho
    );
    assert!(ep <= tol && ek <= tol);
    // As for the full model: ρ of the recursion's gain, within 1e-12 of the regulator's.
    assert!(rho <= lqr.radius_bound + 1.0e-12 && lqr.radius_bound < 1.0);
    assert!(lqr.radius_bound - rho <= RESOLUTION);
}

/// The force units (N per unit) and length units (m per unit) of the certificate's
/// unit tests: N, kN, MN × m, mm.
const UNITS: [(f64, f64); 6] = [
    (1.0, 1.0),
    (1.0e3, 1.0),
    (1.0e6, 1.0),
    (1.0, 1.0e-3),
    (1.0e3, 1.0e-3),
    (1.0e6, 1.0e-3),
];

/// `2^-30`: the relative resolution of the certificate's bisection on `β`
/// (`DesignModel::radius_bound`).
const RESOLUTION: f64 = 9.313225746154785e-10;

/// The trade-off scene's delayed design model at 200 Hz and its weights for the force
/// weight `r` (1/MN²): drifts by `Q_y = I`, the command as computed by `10⁻³ R`. In the
/// scene's units: force in `tradeoff::FORCE_UNIT` N, state in m and m/s.
fn tradeoff_design(r: f64) -> (DesignModel<11, 1>, Weights<11, 1>) {
    let (ss, _) = tradeoff::zoh(1.0, 0.005);
    let drifts = ss
        .outputs(&Outputs::displacements(storey_drifts::<5>()))
        .unwrap();
    // R per the scene's force unit (the sweep is per MN²).
    let per_mn = tradeoff::FORCE_UNIT / 1.0e6;
    let r = r * per_mn * per_mn;
    let w = Weights::outputs(&drifts, &models::diagonal([tradeoff::QY; 5]), &[[r]]);
    let design = DesignModel::from_state_space(&ss).delayed::<11>().unwrap();
    (design, w.delayed(&[[tradeoff::DECISION * r]]).unwrap())
}

/// The scaling `z' = T z` of the delayed state `z = [x; f_{k−1}]` from the scene's units
/// to the force in `force` N and the displacements (velocities) in `length` m (m/s) per
/// unit, and the input's `u' = s u`: `(T, s)`.
fn unit_change(force: f64, length: f64) -> ([f64; 11], f64) {
    let s = tradeoff::FORCE_UNIT / force;
    let mut t = [1.0 / length; 11];
    t[10] = s;
    (t, s)
}

/// The design model and weights in other units, written from the change of variables:
/// `Φ' = T Φ T⁻¹`, `Γ' = T Γ / s`, `Q' = T⁻¹ Q T⁻¹`, `R' = R / s²` (the same cost).
fn in_units(
    d: &DesignModel<11, 1>,
    w: &Weights<11, 1>,
    t: &[f64; 11],
    s: f64,
) -> (DesignModel<11, 1>, Weights<11, 1>) {
    let mut d2 = *d;
    let mut w2 = *w;
    for i in 0..11 {
        for j in 0..11 {
            d2.phi[i][j] = d.phi[i][j] * t[i] / t[j];
            w2.q[i][j] = w.q[i][j] / (t[i] * t[j]);
        }
        d2.gamma[i][0] = d.gamma[i][0] * t[i] / s;
        w2.cross[i][0] = w.cross[i][0] / (t[i] * s);
    }
    w2.r[0][0] = w.r[0][0] / (s * s);
    (d2, w2)
}

/// A gain of the scene's units in other units: `u' = s u = −s K T⁻¹ z'`.
fn gain_in_units(k: &[[f64; 11]; 1], t: &[f64; 11], s: f64) -> [[f64; 11]; 1] {
    [core::array::from_fn(|j| s * k[0][j] / t[j])]
}

/// The spectral radius of `Φ − Γ K` (of a model and gain in the units `T`), by nalgebra's
/// eigenvalues of the loop mapped back to the scene's units (`T⁻¹ (Φ' − Γ' K') T`): the
/// Schur form is not balanced, and in newtons its error on the raw loop reaches 1.4e-8.
fn spectral_radius(d: &DesignModel<11, 1>, k: &[[f64; 11]; 1], t: &[f64; 11]) -> f64 {
    let phi = SMatrix::<f64, 11, 11>::from_fn(|i, j| d.phi[i][j]);
    let g = SMatrix::<f64, 11, 1>::from_fn(|i, _| d.gamma[i][0]);
    let kk = SMatrix::<f64, 1, 11>::from_fn(|_, j| k[0][j]);
    let a = phi - g * kk;
    DMatrix::from_fn(11, 11, |i, j| a[(i, j)] * t[j] / t[i])
        .complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
}

/// The closed-loop certificate does not depend on units: the trade-off scene's 10 delayed
/// 5-storey designs (`tradeoff::SWEEP`), each solved in newtons, kN and MN and with the
/// state in metres and millimetres (the model and weights rescaled here from the change
/// of variables). Every design whose spectral radius (nalgebra's eigenvalues, in the
/// scene's units) is below `1 − 10⁻⁶` is accepted in every unit system — before the
/// certificate balanced the loop, 9 of the 10 were refused in newtons — and its bounds lie
/// within the bisection's resolution `2^-30` of the spectral radius: measured 2e-11 to
/// 4.3e-10 above it (the certificate's rounding where `β` meets `ρ`), so within `2^-30`
/// of each other. Bound `ρ ≤ b + 10⁻¹²`: nalgebra's eigenvalues, the loop's rounding in
/// each system's units and the mapping back to the scene's (measured `b − ρ ≥ 2e-11`).
#[test]
fn certificate_is_independent_of_units() {
    let mut worst = (0.0f64, 0.0f64);
    for &r in &tradeoff::SWEEP {
        let (design, w) = tradeoff_design(r);
        let mut bounds = Vec::new();
        for &(force, length) in &UNITS {
            let (t, s) = unit_change(force, length);
            let (d, wu) = in_units(&design, &w, &t, s);
            let lqr = Lqr::from_parts(&d, &wu);
            let rho = match &lqr {
                Ok(l) => spectral_radius(&d, &l.gain, &t),
                Err(e) => panic!("R = {r:e}, force {force:e} N, length {length:e} m: {e:?}"),
            };
            let b = lqr.unwrap().radius_bound;
            assert!(rho < 1.0 - 1.0e-6, "R = {r:e}: ρ = {rho}");
            assert!(rho <= b + 1.0e-12 && b - rho <= RESOLUTION, "{b} for {rho}");
            // The public certificate of the same gain is the regulator's own.
            assert_eq!(d.radius_bound(&lqr.unwrap().gain), Ok(b));
            worst.0 = worst.0.max(b - rho);
            bounds.push(b);
        }
        let spread = bounds.iter().fold(0.0f64, |m, &b| m.max(b))
            - bounds.iter().fold(1.0f64, |m, &b| m.min(b));
        worst.1 = worst.1.max(spread);
        assert!(spread <= RESOLUTION, "R = {r:e}: bounds {bounds:?}");
    }
    println!(
        "largest bound − ρ {:.2e}, largest spread of a design's bounds over units {:.2e} \
         (tolerance {RESOLUTION:.2e})",
        worst.0, worst.1
    );
}

/// A closed loop that is truly unstable is refused in every unit system, and one just
/// stable is certified in each: the chosen design's gain (`R = 3·10⁻⁴`) with its sign
/// flipped (ρ = 1.0097), and scaled by `c` past the loop's stability limit (a high gain
/// against the one-sample delay), `c` found by bisection on nalgebra's eigenvalues so that
/// `ρ = 1 + 10⁻⁵`, and its stable twin `ρ = 1 − 10⁻⁵` (certified within `2^-30`, as the
/// sweep's designs).
#[test]
fn unstable_hand_gain_is_refused_in_every_unit_system() {
    let (design, w) = tradeoff_design(tradeoff::R_CHOSEN);
    let k = Lqr::from_parts(&design, &w).unwrap().gain;
    let scaled = |c: f64| [k[0].map(|v| c * v)];
    let one = [1.0; 11];
    // The scale at which ρ(c) = target, between c = 20 (stable) and 50 (unstable).
    let scale_for = |target: f64| {
        let (mut lo, mut hi) = (20.0f64, 50.0f64);
        assert!(spectral_radius(&design, &scaled(lo), &one) < target);
        assert!(spectral_radius(&design, &scaled(hi), &one) > target);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if spectral_radius(&design, &scaled(mid), &one) < target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    };
    let (c_stable, c_unstable) = (scale_for(1.0 - 1.0e-5), scale_for(1.0 + 1.0e-5));
    let flipped = scaled(-1.0);
    let (stable, unstable) = (scaled(c_stable), scaled(c_unstable));
    let rho = [&flipped, &unstable, &stable].map(|g| spectral_radius(&design, g, &one));
    println!("hand gains: ρ = {rho:?} (c = {c_unstable}, {c_stable})");
    assert!(rho[0] > 1.0 + 1.0e-6 && rho[1] > 1.0 + 1.0e-6 && rho[2] < 1.0 - 1.0e-6);
    for &(force, length) in &UNITS {
        let (t, s) = unit_change(force, length);
        let (d, _) = in_units(&design, &w, &t, s);
        for g in [&flipped, &unstable] {
            assert_eq!(
                d.radius_bound(&gain_in_units(g, &t, s)),
                Err(Error::NotStabilizing)
            );
        }
        let b = d.radius_bound(&gain_in_units(&stable, &t, s)).unwrap();
        let rho_u = spectral_radius(&d, &gain_in_units(&stable, &t, s), &t);
        assert!(
            rho_u <= b + 1.0e-12 && b - rho_u <= RESOLUTION && b < 1.0,
            "{b} for {rho_u}"
        );
    }
    // Bad input: a typed error.
    let mut bad = stable;
    bad[0][3] = f64::NAN;
    assert_eq!(design.radius_bound(&bad), Err(Error::NonFiniteInput));
}

/// Found by the control fuzz target: a marginal loop (Φ = 1, an input 1e-17 strong) whose
/// certified bound rounded up to 1.0000000000000002 was accepted; the bound is promised
/// below 1, so it is refused.
#[test]
fn bound_that_rounds_up_to_one_is_refused() {
    let model = DesignModel::<1, 1> {
        phi: [[1.0]],
        gamma: [[-8.985290527343751e-18]],
    };
    let w = Weights::new(&[[0.10941138105771858]], &[[1e-6]]);
    match Lqr::from_parts(&model, &w) {
        Ok(l) => panic!("accepted with radius bound {}", l.radius_bound),
        Err(e) => assert!(
            matches!(e, Error::NotStabilizing | Error::RiccatiNotConverged),
            "{e:?}"
        ),
    }
}
