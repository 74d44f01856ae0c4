//! Observer loops (issue 11): the state-space form against the steppers, the steady-state
//! gain against independent computations, the Kalman filter's consistency (NEES), the
//! observer's rules (zero gain = open loop, missing samples, failed steps, typed errors).
//!
//! Every tolerance is derived in its test from the method's error or the rounding of the
//! computation; the measured values are printed (`-- --nocapture`).

#![allow(clippy::needless_range_loop)] // matrix and record indices read best explicitly

use aemstep::models::{self, base_excitation, storey_drifts};
use aemstep::observer::{Kalman, Observer, Outputs, Readout, StateSpace, SteadyState};
use aemstep::{Damping, Error, Exact, LinearInput, Modal, StepState, Stepper};
use nalgebra::{SMatrix, SVector};

#[path = "support/checks.rs"]
mod checks;
#[path = "../scenes/modal/elcentro.rs"]
mod elcentro;
#[path = "../scenes/detection/gauss.rs"]
mod gauss;
mod support;

use gauss::Gauss;
use support::{max_abs, riccati_residual, sm, spectral_radius};

const H: f64 = elcentro::DT;
const EPS: f64 = f64::EPSILON;
type Building = ([[f64; 5]; 5], [[f64; 5]; 5], [[f64; 5]; 5]);
const B: Building = models::five_storey_building();

/// The building's full model, ground acceleration in.
fn building() -> StateSpace<5, 10, 1> {
    StateSpace::from_rows_aem(B.0, B.1, B.2, base_excitation(&B.0), H).unwrap()
}

/// Absolute accelerations of floors 2 and 5 (DOFs 1 and 4).
fn accelerometers() -> Outputs<5, 1, 2> {
    Outputs::absolute_accelerations(Outputs::<5, 1, 2>::select([1, 4]), 0)
}

/// Unmodelled forces on every floor, white, `σ_f` (N): `Q = G σ_f² Gᵀ`.
fn force_noise(sigma_f: f64) -> SMatrix<f64, 10, 10> {
    let f = StateSpace::<5, 10, 5>::from_rows_aem(B.0, B.1, B.2, identity5(), H).unwrap();
    let qw: [[f64; 5]; 5] = core::array::from_fn(|i| {
        core::array::from_fn(|j| if i == j { sigma_f * sigma_f } else { 0.0 })
    });
    sm(&f.input_noise(&qw))
}

fn identity5() -> [[f64; 5]; 5] {
    core::array::from_fn(|i| core::array::from_fn(|j| if i == j { 1.0 } else { 0.0 }))
}

/// The bound on the difference of two f64 evaluations of the same stable linear recurrence
/// over `n` steps: each step adds at most `c ε |x|` of rounding (`c` = terms per row, with
/// a factor 4 for the rounding of the operators themselves, formed by solves and products
/// of a few terms each), and `‖Φ^k‖ ≤ 1` (stable, lightly damped) carries it forward
/// without growth: `|e_n| ≤ n c ε max|x|`.
fn recurrence_bound(n: usize, terms: usize, scale: f64) -> f64 {
    n as f64 * 4.0 * terms as f64 * EPS * scale
}

#[test]
fn aem_state_space_reproduces_linear_input() {
    let ss = building();
    let sys =
        LinearInput::<f64, 5, 1>::from_rows_f64(B.0, B.1, B.2, base_excitation(&B.0), H).unwrap();
    let ag = &elcentro::AG_F64;
    let z = SVector::<f64, 5>::zeros();
    let mut s = sys.start(&z, &z, &SVector::from([ag[0]])).unwrap();
    let (phi, g0, g1) = (ss.phi_matrix(), ss.gamma0_matrix(), ss.gamma1_matrix());
    let mut x = SVector::<f64, 10>::zeros();
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    // The acceleration read-out a = A_x x + A_w w against the stepper's a.
    let am = ss.outputs(&Outputs::accelerations(identity5())).unwrap();
    let (ax, aw) = (am.h_matrix(), am.d_matrix());
    let mut worst_a = 0.0f64;
    let mut worst_one = 0.0f64;
    for n in 1..ag.len() {
        let (w0, w1) = (SVector::from([ag[n - 1]]), SVector::from([ag[n]]));
        // One step from the stepper's own state: the two differ by the rounding of one
        // step, at most c ε (|Φ||x| + |Γ₀||w₀| + |Γ₁||w₁|) per row, c = 4 × 12 terms.
        let xs = SVector::<f64, 10>::from_fn(|i, _| if i < 5 { s.u()[i] } else { s.v()[i - 5] });
        let one = phi * xs + g0 * w0 + g1 * w1;
        let size = phi.abs() * xs.abs() + g0.abs() * w0.abs() + g1.abs() * w1.abs();
        sys.step(&mut s, &w1);
        for i in 0..10 {
            let got = if i < 5 { s.u()[i] } else { s.v()[i - 5] };
            let err = (one[i] - got).abs();
            worst_one = worst_one.max(err / (4.0 * 12.0 * EPS * size[i]));
        }
        x = phi * x + g0 * w0 + g1 * w1;
        for i in 0..5 {
            worst = worst
                .max((x[i] - s.u()[i]).abs())
                .max((x[5 + i] - s.v()[i]).abs());
            scale = scale.max(s.u()[i].abs()).max(s.v()[i].abs());
        }
        // The equation of motion read from the stepper's new (u, v): its a to the rounding
        // of both sides, each at most 4 × 12 ε times the size of the terms
        // |A_x||x| + |A_w||w| (the stepper's q sums terms no larger: G M_eff = I).
        let xn = SVector::<f64, 10>::from_fn(|i, _| if i < 5 { s.u()[i] } else { s.v()[i - 5] });
        let a = ax * xn + aw * w1;
        let size_a = ax.abs() * xn.abs() + aw.abs() * w1.abs();
        for i in 0..5 {
            worst_a = worst_a.max((a[i] - s.a()[i]).abs() / (2.0 * 4.0 * 12.0 * EPS * size_a[i]));
        }
    }
    println!(
        "AEM state space vs LinearInput, one step from the same state: max error / its rounding bound = {worst_one:.3}"
    );
    assert!(worst_one <= 1.0);
    let bound = recurrence_bound(ag.len(), 10 + 2, scale);
    println!(
        "AEM state space vs LinearInput: max |Δx| = {worst:.3e} (bound {bound:.3e}, max |x| = {scale:.3})"
    );
    assert!(worst <= bound, "{worst:e} > {bound:e}");
    println!(
        "  acceleration read-out from the same state: max error / its rounding bound = {worst_a:.3}"
    );
    assert!(worst_a <= 1.0);
}

#[test]
fn exact_state_space_reproduces_exact() {
    let (m, c, k) = (sm(&B.0), sm(&B.1), sm(&B.2));
    let b = sm(&base_excitation(&B.0));
    let ss = StateSpace::<5, 10, 1>::exact(&m, &c, &k, &b, H).unwrap();
    let sys = Exact::<f64, 5>::new(&m, &c, &k, H).unwrap();
    let ag = &elcentro::AG_F64;
    let z = SVector::<f64, 5>::zeros();
    let p = |a: f64| b * a;
    let mut s = sys.start(&z, &z, &p(ag[0])).unwrap();
    let (phi, g0, g1) = (ss.phi_matrix(), ss.gamma0_matrix(), ss.gamma1_matrix());
    let mut x = SVector::<f64, 10>::zeros();
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    for n in 1..ag.len() {
        sys.step_with_previous_input(&mut s, &p(ag[n - 1]), &p(ag[n]));
        x = phi * x + g0 * ag[n - 1] + g1 * ag[n];
        for i in 0..5 {
            worst = worst
                .max((x[i] - s.u()[i]).abs())
                .max((x[5 + i] - s.v()[i]).abs());
            scale = scale.max(s.u()[i].abs()).max(s.v()[i].abs());
        }
    }
    // The stepper forms P0 p with p = B w (N more terms a row than Γ w).
    let bound = recurrence_bound(ag.len(), 10 + 2 * 5, scale);
    println!("Exact state space vs Exact: max |Δx| = {worst:.3e} (bound {bound:.3e})");
    assert!(worst <= bound);
}

#[test]
fn modal_state_space_reproduces_modal() {
    fn check<const R: usize, const S: usize>() {
        let ss = StateSpace::<5, S, 1>::from_rows_modal::<R>(
            B.0,
            B.2,
            Damping::Matrix(B.1),
            base_excitation(&B.0),
            aemstep::modal::lowest_modes(),
            H,
        )
        .unwrap();
        let sys = Modal::<f64, 5, R>::from_rows_f64(
            B.0,
            B.2,
            Damping::Matrix(B.1),
            base_excitation(&B.0),
            storey_drifts::<5>()[..1].try_into().unwrap(),
            H,
        )
        .unwrap();
        // Block diagonal: mode r couples only η_r and η'_r.
        for i in 0..S {
            for j in 0..S {
                if i % R != j % R {
                    assert_eq!(ss.phi[i][j], 0.0, "Φ[{i}][{j}]");
                }
            }
        }
        let ag = &elcentro::AG_F64;
        let mut s = sys.start_at_rest(&SVector::from([ag[0]])).unwrap();
        let mut x = SVector::<f64, S>::zeros();
        let (phi, g0, g1) = (ss.phi_matrix(), ss.gamma0_matrix(), ss.gamma1_matrix());
        let (mut worst, mut scale) = (0.0f64, 0.0f64);
        for n in 1..ag.len() {
            sys.step(&mut s, &SVector::from([ag[n]]));
            x = phi * x + g0 * ag[n - 1] + g1 * ag[n];
            for r in 0..R {
                worst = worst
                    .max((x[r] - s.eta()[r]).abs())
                    .max((x[R + r] - s.eta_velocity()[r]).abs());
                scale = scale.max(s.eta()[r].abs()).max(s.eta_velocity()[r].abs());
            }
        }
        let bound = recurrence_bound(ag.len(), 2 + 2, scale);
        println!(
            "Modal state space (R = {R}) vs Modal: max |Δx| = {worst:.3e} (bound {bound:.3e})"
        );
        assert!(worst <= bound);
        // Reconstruction: u = U x agrees with the stepper's full state.
        let full = sys.full_state(&s);
        let u = SMatrix::<f64, 5, S>::from_fn(|i, j| ss.dof_u[i][j]) * x;
        assert!(max_abs((u - full.u()).iter()) <= bound * 5.0);
        // And back: the modal coordinates of (u, v) = (U x, V x) are x.
        let v = SMatrix::<f64, 5, S>::from_fn(|i, j| ss.dof_v[i][j]) * x;
        let back = ss.modal_coordinates(&sm(&B.0), &u, &v);
        assert!(max_abs((back - x).iter()) <= bound * 5.0);
    }
    check::<2, 4>();
    check::<5, 10>();
}

#[test]
fn state_size_must_match() {
    let e = StateSpace::<5, 9, 1>::from_rows_aem(B.0, B.1, B.2, base_excitation(&B.0), H);
    assert_eq!(e, Err(Error::StateSizeMismatch));
    let e = StateSpace::<5, 5, 1>::from_rows_modal::<2>(
        B.0,
        B.2,
        Damping::None,
        base_excitation(&B.0),
        [0, 1],
        H,
    );
    assert_eq!(e, Err(Error::StateSizeMismatch));
    let (m, c, k) = (sm(&B.0), sm(&B.1), sm(&B.2));
    let b = sm(&base_excitation(&B.0));
    assert_eq!(
        StateSpace::<5, 11, 1>::exact(&m, &c, &k, &b, H),
        Err(Error::StateSizeMismatch)
    );
    // Other data errors come through from the scheme's checks.
    let mut bad = B.0;
    bad[0][0] = f64::NAN;
    assert_eq!(
        StateSpace::<5, 10, 1>::from_rows_aem(bad, B.1, B.2, base_excitation(&B.0), H),
        Err(Error::NonFiniteInput)
    );
    assert_eq!(
        StateSpace::<5, 10, 1>::from_rows_aem(B.0, B.1, B.2, base_excitation(&B.0), -1.0),
        Err(Error::InvalidTimeStep)
    );
    assert_eq!(
        StateSpace::<5, 10, 1>::from_rows_aem([[0.0; 5]; 5], B.1, B.2, base_excitation(&B.0), H),
        Err(Error::SingularMass)
    );
}

/// The scene's noise: forces `σ_f` on every floor, accelerometer noise `σ_y`.
const SIGMA_F: f64 = 2.0e4;
const SIGMA_Y: f64 = 0.1;

static CONST_GAIN: SteadyState<10, 2> = {
    const SS: StateSpace<5, 10, 1> =
        match StateSpace::from_rows_aem(B.0, B.1, B.2, base_excitation(&B.0), H) {
            Ok(s) => s,
            Err(e) => panic!("{}", e.as_str()),
        };
    const F: StateSpace<5, 10, 5> = match StateSpace::from_rows_aem(
        B.0,
        B.1,
        B.2,
        {
            let mut b = [[0.0; 5]; 5];
            let mut i = 0;
            while i < 5 {
                b[i][i] = 1.0;
                i += 1;
            }
            b
        },
        H,
    ) {
        Ok(s) => s,
        Err(e) => panic!("{}", e.as_str()),
    };
    const QW: [[f64; 5]; 5] = {
        let mut q = [[0.0; 5]; 5];
        let mut i = 0;
        while i < 5 {
            q[i][i] = SIGMA_F * SIGMA_F;
            i += 1;
        }
        q
    };
    match SS.outputs(&Outputs::absolute_accelerations(
        Outputs::<5, 1, 2>::select([1, 4]),
        0,
    )) {
        Ok(meas) => match SteadyState::from_parts(
            &SS,
            &meas,
            &F.input_noise(&QW),
            &[[SIGMA_Y * SIGMA_Y, 0.0], [0.0, SIGMA_Y * SIGMA_Y]],
        ) {
            Ok(k) => k,
            Err(e) => panic!("{}", e.as_str()),
        },
        Err(e) => panic!("{}", e.as_str()),
    }
};

fn r_matrix() -> SMatrix<f64, 2, 2> {
    SMatrix::<f64, 2, 2>::identity() * (SIGMA_Y * SIGMA_Y)
}

#[test]
fn steady_state_gain_solves_the_riccati_equation_and_is_the_limit_of_the_recursion() {
    let ss = building();
    let meas = ss.outputs(&accelerometers()).unwrap();
    let (q, r) = (force_noise(SIGMA_F), r_matrix());
    let kf = SteadyState::new(&ss, &meas, &q, &r).unwrap();
    // The compiler's solution (a `static`) is the run-time one, bit for bit.
    assert_eq!(kf, CONST_GAIN);
    let (phi, h, p) = (ss.phi_matrix(), meas.h_matrix(), kf.covariance_matrix());
    let res = riccati_residual(&phi, &h, &q, &r, &p);
    println!(
        "DARE: {} doubling iterations, relative residual {res:.3e}",
        kf.iterations
    );
    assert!(res <= 1e-10, "residual {res:e}");
    // The gain is L = P Hᵀ (H P Hᵀ + R)⁻¹.
    let l = p * h.transpose() * (h * p * h.transpose() + r).try_inverse().unwrap();
    let gl = kf.gain_matrix();
    let dl = max_abs((l - gl).iter()) / max_abs(l.iter());
    assert!(dl <= 1e3 * EPS, "gain {dl:e}");

    // Independent: iterate the Riccati difference equation (Joseph form, written here) from
    // P = 0 until it stops moving.
    let mut pm = SMatrix::<f64, 10, 10>::zeros();
    let mut iters = 0;
    loop {
        let k = pm * h.transpose() * (h * pm * h.transpose() + r).try_inverse().unwrap();
        let ikh = SMatrix::<f64, 10, 10>::identity() - k * h;
        let post = ikh * pm * ikh.transpose() + k * r * k.transpose();
        let next = phi * post * phi.transpose() + q;
        let next = (next + next.transpose()) * 0.5;
        let change = max_abs((next - pm).iter());
        pm = next;
        iters += 1;
        if change <= 4.0 * EPS * max_abs(pm.iter()) || iters == 200_000 {
            break;
        }
    }
    // Both are fixed points of the same map to their residuals; the map contracts with
    // rate ρ² near P (ρ: spectral radius of the closed loop (I − LH)Φ... here Φ(I − LH)),
    // so |P_rec − P| ≤ (res_rec + res) ‖P‖ / (1 − ρ²).
    let rho = spectral_radius(&(phi * (SMatrix::<f64, 10, 10>::identity() - gl * h)));
    let res_rec = riccati_residual(&phi, &h, &q, &r, &pm);
    let bound = (res_rec + res) / (1.0 - rho * rho);
    let diff = max_abs((pm - p).iter()) / max_abs(p.iter());
    println!(
        "Riccati recursion: {iters} steps, |P_rec − P_dare| / |P| = {diff:.3e} (bound {bound:.3e}, closed-loop ρ = {rho:.5}, residual of P_rec {res_rec:.3e})"
    );
    assert!(rho < 1.0);
    assert!(diff <= bound, "{diff:e} > {bound:e}");

    // The library's full Kalman filter: its predicted covariance converges to P too.
    let kal = Kalman::<f64, 10, 1, 2>::new(&ss, &meas, &q, &r).unwrap();
    let mut s = kal
        .start(&SVector::zeros(), &SMatrix::zeros(), &SVector::from([0.0]))
        .unwrap();
    for _ in 0..iters {
        kal.try_step(&mut s, &SVector::from([0.0]), &SVector::from([0.0, 0.0]))
            .unwrap();
    }
    let pk = kal.predicted_covariance(&s);
    let res_k = riccati_residual(&phi, &h, &q, &r, &pk);
    let diff_k = max_abs((pk - p).iter()) / max_abs(p.iter());
    let bound_k = (res_k + res) / (1.0 - rho * rho);
    println!(
        "Kalman filter after {iters} steps: |P⁻ − P_dare| / |P| = {diff_k:.3e} (bound {bound_k:.3e})"
    );
    assert!(diff_k <= bound_k);
}

#[test]
fn covariance_and_gain_errors_are_typed() {
    let ss = building();
    let meas = ss.outputs(&accelerometers()).unwrap();
    let q = force_noise(SIGMA_F);
    let r = r_matrix();
    let mut bad_q = q;
    bad_q[(0, 0)] = f64::NAN;
    assert_eq!(
        SteadyState::new(&ss, &meas, &bad_q, &r),
        Err(Error::InvalidCovariance)
    );
    // Negative definite.
    assert_eq!(
        SteadyState::new(&ss, &meas, &(-q), &r),
        Err(Error::InvalidCovariance)
    );
    let neg = SMatrix::<f64, 10, 10>::identity() * -1e-6;
    assert_eq!(
        SteadyState::new(&ss, &meas, &neg, &r),
        Err(Error::InvalidCovariance)
    );
    // Not symmetric.
    let mut asym = q;
    asym[(0, 1)] += 1e-3 * max_abs(q.iter());
    assert_eq!(
        SteadyState::new(&ss, &meas, &asym, &r),
        Err(Error::InvalidCovariance)
    );
    // R singular or indefinite.
    assert_eq!(
        SteadyState::new(&ss, &meas, &q, &SMatrix::zeros()),
        Err(Error::InvalidCovariance)
    );
    let ind = SMatrix::<f64, 2, 2>::new(1.0, 0.0, 0.0, -1.0);
    assert_eq!(
        SteadyState::new(&ss, &meas, &q, &ind),
        Err(Error::InvalidCovariance)
    );
    assert_eq!(
        Kalman::<f64, 10, 1, 2>::new(&ss, &meas, &q, &ind).err(),
        Some(Error::InvalidCovariance)
    );
    // Q = 0 is a valid covariance (semidefinite): a perfect model needs no correction.
    let zero = SteadyState::new(&ss, &meas, &SMatrix::zeros(), &r).unwrap();
    assert!(max_abs(zero.gain_matrix().iter()) <= 1e-12);
    // A gain that does not fit f32, a non-finite gain.
    let mut g = SMatrix::<f64, 10, 2>::zeros();
    g[(0, 0)] = 1e300;
    assert_eq!(
        Observer::<f32, 10, 1, 2>::new(&ss, &meas, &g).err(),
        Some(Error::OperatorOverflow)
    );
    g[(0, 0)] = f64::INFINITY;
    assert_eq!(
        Observer::<f64, 10, 1, 2>::new(&ss, &meas, &g).err(),
        Some(Error::NonFiniteInput)
    );
    // A model with an unmeasured, undriven, undamped mode: no stabilizing solution.
    let (m, k) = models::shear_building([1.0, 1.0], [100.0, 100.0]);
    let und =
        StateSpace::<2, 4, 1>::from_rows_aem(m, [[0.0; 2]; 2], k, [[1.0], [0.0]], 0.01).unwrap();
    let meas1 = und.outputs(&Outputs::displacements([[0.0, 0.0]])).unwrap();
    assert_eq!(
        SteadyState::new(
            &und,
            &meas1,
            &SMatrix::<f64, 4, 4>::identity(),
            &SMatrix::<f64, 1, 1>::identity()
        )
        .err(),
        Some(Error::RiccatiNotConverged)
    );
}

#[test]
fn zero_gain_observer_is_the_open_loop_stepper() {
    let ss = building();
    let meas = ss.outputs(&accelerometers()).unwrap();
    let obs = Observer::<f64, 10, 1, 2>::new(&ss, &meas, &SMatrix::zeros()).unwrap();
    let sys =
        LinearInput::<f64, 5, 1>::from_rows_f64(B.0, B.1, B.2, base_excitation(&B.0), H).unwrap();
    let ag = &elcentro::AG_F64;
    let z = SVector::<f64, 5>::zeros();
    let mut s = sys.start(&z, &z, &SVector::from([ag[0]])).unwrap();
    let mut e = obs.start_at_rest(&SVector::from([ag[0]])).unwrap();
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    for n in 1..ag.len() {
        let w = SVector::from([ag[n]]);
        sys.step(&mut s, &w);
        // Any measurement: the zero gain ignores it.
        obs.try_step(&mut e, &w, &SVector::from([1.0, -1.0]))
            .unwrap();
        for i in 0..5 {
            worst = worst
                .max((e.x()[i] - s.u()[i]).abs())
                .max((e.x()[5 + i] - s.v()[i]).abs());
            scale = scale.max(s.u()[i].abs()).max(s.v()[i].abs());
        }
    }
    let bound = recurrence_bound(ag.len(), 10 + 2, scale);
    println!("zero-gain observer vs LinearInput: max |Δx| = {worst:.3e} (bound {bound:.3e})");
    assert!(worst <= bound);
    assert_eq!(e.missing(), 0);
    assert_eq!(e.steps(), (ag.len() - 1) as u64);
}

#[test]
fn missing_samples_are_skipped_and_failed_steps_change_nothing() {
    let ss = building();
    let meas = ss.outputs(&accelerometers()).unwrap();
    let kf = SteadyState::new(&ss, &meas, &force_noise(SIGMA_F), &r_matrix()).unwrap();
    let obs = Observer::<f32, 10, 1, 2>::new(&ss, &meas, &kf.gain_matrix()).unwrap();
    let open = Observer::<f32, 10, 1, 2>::new(&ss, &meas, &SMatrix::zeros()).unwrap();
    let mut e = obs.start_at_rest(&SVector::from([0.0])).unwrap();
    obs.try_step(&mut e, &SVector::from([1.0]), &SVector::from([0.3, -0.2]))
        .unwrap();
    // A NaN measurement: predict only (the open-loop step, bit for bit), counted.
    let mut p = e;
    open.step(&mut p, &SVector::from([0.5]), &SVector::from([0.0, 0.0]));
    obs.try_step(
        &mut e,
        &SVector::from([0.5]),
        &SVector::from([f32::NAN, 0.1]),
    )
    .unwrap();
    assert_eq!(e.x(), p.x());
    assert_eq!(e.missing(), 1);
    assert_eq!(e.steps(), 2);
    // A NaN input: an error, the estimate bit-identical.
    let before = e;
    assert_eq!(
        obs.try_step(
            &mut e,
            &SVector::from([f32::NAN]),
            &SVector::from([0.0, 0.0])
        ),
        Err(Error::NonFiniteInput)
    );
    assert_eq!(e, before);
    // An overflow (a huge state: H x̂⁻ overflows f32): an error, the estimate bit-identical.
    let mut big = obs
        .start(&SVector::from_element(f32::MAX), &SVector::from([0.0]))
        .unwrap();
    let before_big = big;
    assert_eq!(
        obs.try_step(&mut big, &SVector::from([0.0]), &SVector::from([0.0, 0.0])),
        Err(Error::NonFiniteState)
    );
    assert_eq!(big, before_big);
    assert!(big.is_finite());
    // Start: non-finite rejected.
    assert_eq!(
        obs.start(&SVector::from_element(f32::NAN), &SVector::from([0.0]))
            .err(),
        Some(Error::NonFiniteInput)
    );

    // The Kalman filter: the same rules.
    let kal = Kalman::<f64, 10, 1, 2>::new(&ss, &meas, &force_noise(SIGMA_F), &r_matrix()).unwrap();
    let mut s = kal
        .start(
            &SVector::zeros(),
            &SMatrix::identity(),
            &SVector::from([0.0]),
        )
        .unwrap();
    kal.try_step(
        &mut s,
        &SVector::from([1.0]),
        &SVector::from([f64::NAN, 0.0]),
    )
    .unwrap();
    assert_eq!(s.estimate().missing(), 1);
    let before = s;
    assert_eq!(
        kal.try_step(
            &mut s,
            &SVector::from([f64::INFINITY]),
            &SVector::from([0.0, 0.0])
        ),
        Err(Error::NonFiniteInput)
    );
    assert_eq!(s, before);
    let neg = -SMatrix::<f64, 10, 10>::identity();
    assert_eq!(
        kal.start(&SVector::zeros(), &neg, &SVector::from([0.0]))
            .err(),
        Some(Error::InvalidCovariance)
    );
}

#[test]
fn f32_observer_from_the_compiler_is_bit_identical_to_run_time() {
    static OBS: Observer<f32, 10, 1, 2> = {
        const SS: StateSpace<5, 10, 1> =
            match StateSpace::from_rows_aem(B.0, B.1, B.2, base_excitation(&B.0), H) {
                Ok(s) => s,
                Err(e) => panic!("{}", e.as_str()),
            };
        match SS.outputs(&Outputs::absolute_accelerations(
            Outputs::<5, 1, 2>::select([1, 4]),
            0,
        )) {
            Ok(meas) => {
                match Observer::<f32, 10, 1, 2>::from_parts_f32(&SS, &meas, &CONST_GAIN.gain) {
                    Ok(o) => o,
                    Err(e) => panic!("{}", e.as_str()),
                }
            }
            Err(e) => panic!("{}", e.as_str()),
        }
    };
    let ss = building();
    let meas = ss.outputs(&accelerometers()).unwrap();
    let kf = SteadyState::new(&ss, &meas, &force_noise(SIGMA_F), &r_matrix()).unwrap();
    let run = Observer::<f32, 10, 1, 2>::new(&ss, &meas, &kf.gain_matrix()).unwrap();
    assert_eq!(OBS, run);
}

/// Chi-square quantile (Wilson–Hilferty; relative error below 1e-3 for k ≥ 100).
fn chi2_quantile(k: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + z * a.sqrt()).powi(3)
}

#[test]
fn kalman_filter_is_consistent_nees_in_its_95_percent_band() {
    // Model = truth: the truth is the model driven by the process noise the filter assumes
    // (random forces on every floor) and measured with the noise it assumes.
    let ss = building();
    let meas = ss.outputs(&accelerometers()).unwrap();
    let q = force_noise(SIGMA_F);
    let r = r_matrix();
    let kal = Kalman::<f64, 10, 1, 2>::new(&ss, &meas, &q, &r).unwrap();
    let f = StateSpace::<5, 10, 5>::from_rows_aem(B.0, B.1, B.2, identity5(), H).unwrap();
    let gf = f.gamma0_matrix() + f.gamma1_matrix();
    let kf = SteadyState::new(&ss, &meas, &q, &r).unwrap();
    // Truth starts at x0 ~ N(0, P0) and the filter at x̂0 = 0 with P0: P0 = the Riccati P.
    let p0 = kf.covariance_matrix();
    let l0 = p0.cholesky().expect("P is positive definite").l();
    let (phi, g0, g1, h, d) = (
        ss.phi_matrix(),
        ss.gamma0_matrix(),
        ss.gamma1_matrix(),
        meas.h_matrix(),
        meas.d_matrix(),
    );
    let ag = &elcentro::AG_F64;
    const RUNS: usize = 20;
    let steps = ag.len();
    let mut nees = vec![0.0; steps];
    for run in 0..RUNS {
        let mut g = Gauss::new(1000 + run as u64);
        let mut x = l0 * SVector::<f64, 10>::from_fn(|_, _| g.next());
        let mut s = kal
            .start(&SVector::zeros(), &p0, &SVector::from([ag[0]]))
            .unwrap();
        for n in 0..steps {
            if n > 0 {
                let f = SVector::<f64, 5>::from_fn(|_, _| SIGMA_F * g.next());
                x = phi * x + g0 * ag[n - 1] + g1 * ag[n] + gf * f;
                let y = h * x + d * ag[n] + SVector::<f64, 2>::from_fn(|_, _| SIGMA_Y * g.next());
                kal.try_step(&mut s, &SVector::from([ag[n]]), &y).unwrap();
            }
            let e = x - s.estimate().x();
            let pe = nalgebra::Cholesky::new(*s.covariance()).unwrap().solve(&e);
            nees[n] += e.dot(&pe) / RUNS as f64;
        }
    }
    // The run-averaged NEES at each step is χ²(RUNS·S)/RUNS if the filter is consistent.
    let k = (RUNS * 10) as f64;
    let (lo, hi) = (
        chi2_quantile(k, -1.959964) / RUNS as f64,
        chi2_quantile(k, 1.959964) / RUNS as f64,
    );
    let inside = nees.iter().filter(|&&v| v >= lo && v <= hi).count() as f64 / steps as f64;
    let mean = nees.iter().sum::<f64>() / steps as f64;
    println!(
        "NEES over {steps} steps, {RUNS} runs: 95 % band [{lo:.3}, {hi:.3}] (S = 10), {:.1} % of steps inside, mean {mean:.3}",
        100.0 * inside
    );
    // 95 % expected; the steps are correlated in time, so the fraction scatters more than a
    // binomial: require 90 %. The mean over the record must sit inside the band.
    assert!(inside >= 0.90, "{inside}");
    assert!(mean >= lo && mean <= hi, "mean NEES {mean}");
}

// ---------------------------------------------------------------------------------------
// The scene (xtask/src/bin/observer_building.rs) and the firmware (examples/firmware/qemu_observer.rs).

#[path = "../scenes/observer/reference.rs"]
mod reference;
#[path = "../scenes/observer/scene.rs"]
mod scene;

/// Every how many steps the firmware checks its estimate against the host's (0.2 s).
const EVERY: usize = 10;

/// The truth's accelerations a_n (relative) at every step, f64 — the firmware steps the same
/// `LinearInput<f64, 5, 1>` in soft-float f64 (IEEE: bit-identical).
fn truth_measurements() -> (Vec<[f64; 2]>, [f64; 2]) {
    let (m, c, k) = scene::TRUTH;
    let sys =
        LinearInput::<f64, 5, 1>::from_rows_f64(m, c, k, base_excitation(&m), scene::H).unwrap();
    let ag = &elcentro::AG_F64;
    let z = SVector::zeros();
    let mut s = sys.start(&z, &z, &SVector::from([ag[0]])).unwrap();
    let mut noise = scene::Noise::new();
    let mut y = vec![[f64::NAN; 2]];
    let mut peak = [0.0f64; 2];
    for &a in &ag[1..] {
        sys.step(&mut s, &SVector::from([a]));
        let acc: [f64; 5] = (*s.a()).into();
        y.push(scene::measure(&acc, a, &mut noise));
        for (p, &dof) in peak.iter_mut().zip(&scene::SENSORS) {
            *p = p.max((acc[dof] + a).abs());
        }
    }
    (y, peak)
}

/// Drift estimates of the scene's fixed-gain observer in `T`, every step, from the
/// measurements rounded to `T` (the firmware's computation for `f32`).
fn observer_drifts<T: aemstep::Real>(y: &[[f64; 2]]) -> Vec<[f64; 5]> {
    let obs = Observer::<T, 10, 1, 2>::new(&scene::MODEL_SS, &scene::MEAS, &sm(&scene::GAIN.gain))
        .unwrap();
    let drift = Readout::<T, 10, 1, 5>::new(&scene::DRIFT_OUT).unwrap();
    let r = T::from_f64_rounded;
    let ag = &elcentro::AG_F64;
    let mut e = obs.start_at_rest(&SVector::from([r(ag[0])])).unwrap();
    let mut out = vec![[0.0; 5]];
    for n in 1..ag.len() {
        let w = SVector::from([r(ag[n])]);
        obs.step(&mut e, &w, &SVector::from([r(y[n][0]), r(y[n][1])]));
        let z = drift.read(e.x(), &w);
        out.push(core::array::from_fn(|i| z[i].as_f64()));
    }
    out
}

fn generate_reference(drifts: &[[f64; 5]], bound: f64) -> String {
    let mut s = String::from(
        "//! Generated by `AEMSTEP_WRITE_REFERENCE=1 cargo test --release --test observer`\n\
         //! (tests/observer.rs) — do not edit. The observer scene (scenes/observer/scene.rs):\n\
         //! the f64 fixed-gain observer's estimate of every storey drift (m) at every `EVERY`-th\n\
         //! step from step 0, and the bound (m) the firmware's f32 estimate must stay within\n\
         //! (measured on the host in that test).\n\
         #![allow(dead_code)]\n\n",
    );
    s.push_str(&format!(
        "/// Steps between two reference samples.\npub const EVERY: usize = {EVERY};\n"
    ));
    s.push_str(&format!("/// Max |f32 estimate − f64 estimate| allowed, any storey (m).\npub const BOUND: f64 = {bound:?};\n"));
    let rows: Vec<&[f64; 5]> = drifts.iter().step_by(EVERY).collect();
    s.push_str(&format!(
        "/// f64 observer drift estimates (m) at steps 0, EVERY, 2·EVERY, …\npub static DRIFTS: [[f64; 5]; {}] = [\n",
        rows.len()
    ));
    // The layout rustfmt keeps (the file is formatted with the examples that include it):
    // a row on one line if it fits in 100 columns, else one value a line.
    for r in rows {
        let line = format!(
            "    [{:?}, {:?}, {:?}, {:?}, {:?}],",
            r[0], r[1], r[2], r[3], r[4]
        );
        if line.chars().count() <= 100 {
            s.push_str(&line);
            s.push('\n');
        } else {
            s.push_str("    [\n");
            for x in r {
                s.push_str(&format!("        {x:?},\n"));
            }
            s.push_str("    ],\n");
        }
    }
    s.push_str("];\n");
    s
}

#[test]
fn scene_constants_and_firmware_reference_are_current() {
    let (y, peak) = truth_measurements();
    // The noise is 3 % of the peaks the scene quotes (rounded to 4 digits).
    for i in 0..2 {
        assert!(
            (peak[i] - scene::PEAK[i]).abs() <= 5e-4 * scene::PEAK[i],
            "peak {i}: {}",
            peak[i]
        );
    }
    let d64 = observer_drifts::<f64>(&y);
    let d32 = observer_drifts::<f32>(&y);
    // The bound: what the f32 run (bit for bit the firmware's) measures against the f64 run
    // at the checked steps, with 50 % room; the tightened firmware variant (÷ 100) must fail.
    let measured = d64
        .iter()
        .zip(&d32)
        .step_by(EVERY)
        .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
        .fold(0.0f64, f64::max);
    let bound = format!("{:.2e}", 1.5 * measured).parse::<f64>().unwrap();
    let peak_drift = d64.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    println!(
        "firmware reference: f32 vs f64 observer, max |Δ drift| = {measured:.3e} m ({:.2e} of the {peak_drift:.4} m peak), bound {bound:e} m",
        measured / peak_drift
    );
    checks::reference_is_current(
        "scenes/observer/reference.rs",
        &generate_reference(&d64, bound),
    );
    assert_eq!(reference::EVERY, EVERY);
    // f32 against f64: a few f32 ulps of the drift scale, amplified by the observer's
    // memory (closed-loop ρ ≈ 0.94 per step: ~1/(1 − ρ) ≈ 16 steps of accumulation).
    assert!(
        measured <= 16.0 * 10.0 * f32::EPSILON as f64 * peak_drift,
        "{measured:e}"
    );
    println!(
        "host f32 storey-1 drift at the last step, f32 bits = {:#010x}",
        (d32.last().unwrap()[0] as f32).to_bits()
    );
}
