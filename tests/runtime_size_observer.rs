//! The run-time-sized observer (`DynStateSpace`, `DynSteadyState`, `DynObserver`,
//! `DynKalman`) against the const-generic one where both serve (bit for bit: model, gain,
//! covariance, every estimate, with a missing sample in the record), against an
//! independent dense reference written here from the equations at a size outside the
//! compiled list, and the same errors for the same bad input.
#![cfg(feature = "std")]

use aemstep::Error;
use aemstep::nalgebra::{DMatrix, SMatrix, SVector};
use aemstep::observer::{
    DynKalman, DynMeasurement, DynObserver, DynStateSpace, DynSteadyState, Kalman, Measurement,
    Observer, Outputs, StateSpace, SteadyState,
};

#[path = "../scenes/observer/any_size.rs"]
mod any_size;
use any_size::{building, ground, record};

/// Noise: unit white ground-acceleration-like forces (1e4 N on every floor) and
/// accelerometers of 0.1 m/s².
const SIGMA_F: f64 = 1.0e4;
const SIGMA_Y: f64 = 0.1;
const H: f64 = 0.02;

fn bits(a: &[f64]) -> Vec<u64> {
    a.iter().map(|v| v.to_bits()).collect()
}

/// The `N`-storey scene with `O` accelerometers at `dofs`, built both ways: the compiled
/// model (`S = 2N`) and its measurement, the run-time model and measurement, and the
/// run-time noise (white forces of `SIGMA_F` on every floor, accelerometers of `SIGMA_Y`).
struct Models<const N: usize, const S: usize, const O: usize> {
    /// `M, C, K` as compiled matrices.
    stiff: (SMatrix<f64, N, N>, SMatrix<f64, N, N>, SMatrix<f64, N, N>),
    ss: StateSpace<N, S, 1>,
    meas: Measurement<S, 1, O>,
    dss: DynStateSpace,
    dmeas: DynMeasurement,
    dq: DMatrix<f64>,
    dr: DMatrix<f64>,
}

/// The run-time scene of `n` storeys with accelerometers at `dofs`: the model, its
/// measurement, and the noise (white forces of `SIGMA_F` on every floor, accelerometers
/// of `SIGMA_Y`).
fn dyn_scene(
    n: usize,
    dofs: &[usize],
) -> (DynStateSpace, DynMeasurement, DMatrix<f64>, DMatrix<f64>) {
    let (m, c, k) = building(n);
    let dss = DynStateSpace::aem(&m, &c, &k, &ground(&m), H).unwrap();
    let dmeas = dss.absolute_accelerations(dofs, 0).unwrap();
    let forces = DynStateSpace::aem(&m, &c, &k, &DMatrix::identity(n, n), H).unwrap();
    let q = forces
        .input_noise(&(DMatrix::identity(n, n) * (SIGMA_F * SIGMA_F)))
        .unwrap();
    let r = DMatrix::identity(dofs.len(), dofs.len()) * (SIGMA_Y * SIGMA_Y);
    (dss, dmeas, q, r)
}

fn models<const N: usize, const S: usize, const O: usize>(dofs: [usize; O]) -> Models<N, S, O> {
    let (m, c, k) = building(N);
    let b = ground(&m);
    let sm = |a: &DMatrix<f64>| SMatrix::<f64, N, N>::from_fn(|i, j| a[(i, j)]);
    let (ms, cs, ks) = (sm(&m), sm(&c), sm(&k));
    let bs = SMatrix::<f64, N, 1>::from_fn(|i, _| b[(i, 0)]);
    let ss = StateSpace::<N, S, 1>::aem(&ms, &cs, &ks, &bs, H).unwrap();
    let meas = ss
        .outputs(&Outputs::absolute_accelerations(
            Outputs::<N, 1, O>::select(dofs),
            0,
        ))
        .unwrap();
    let (dss, dmeas, dq, dr) = dyn_scene(N, &dofs);
    Models {
        stiff: (ms, cs, ks),
        ss,
        meas,
        dss,
        dmeas,
        dq,
        dr,
    }
}

/// Compiled size `N` (`S = 2N`) with `O` sensors at `dofs`: model, gain, covariance and
/// 200 estimates bit for bit, `f64`; the first 50 estimates in `f32` too.
fn same_at<const N: usize, const S: usize, const O: usize>(dofs: [usize; O]) {
    let Models {
        stiff: (ms, cs, ks),
        ss,
        meas,
        dss,
        dmeas,
        dq,
        dr,
    } = models::<N, S, O>(dofs);
    let forces = StateSpace::<N, S, N>::aem(&ms, &cs, &ks, &SMatrix::identity(), H).unwrap();
    let qw: [[f64; N]; N] = core::array::from_fn(|i| {
        core::array::from_fn(|j| if i == j { SIGMA_F * SIGMA_F } else { 0.0 })
    });
    let q = SMatrix::<f64, S, S>::from_fn(|i, j| forces.input_noise(&qw)[i][j]);
    let r = SMatrix::<f64, O, O>::identity() * (SIGMA_Y * SIGMA_Y);
    let kf = SteadyState::new(&ss, &meas, &q, &r).unwrap();
    let obs = Observer::<f64, S, 1, O>::new(&ss, &meas, &kf.gain_matrix()).unwrap();

    let dkf = DynSteadyState::new(&dss, &dmeas, &dq, &dr).unwrap();
    let dobs = DynObserver::<f64>::new(&dss, &dmeas, &dkf.gain_matrix()).unwrap();

    let flat = |a: &[[f64; S]]| a.iter().flatten().copied().collect::<Vec<_>>();
    assert_eq!(
        bits(dss.phi_matrix().transpose().as_slice()),
        bits(&flat(&ss.phi)),
        "Φ, N = {N}"
    );
    let g = |a: DMatrix<f64>| bits(a.transpose().as_slice());
    assert_eq!(
        g(dss.gamma0_matrix()),
        bits(ss.gamma0.as_flattened()),
        "Γ₀, N = {N}"
    );
    assert_eq!(
        g(dss.gamma1_matrix()),
        bits(ss.gamma1.as_flattened()),
        "Γ₁, N = {N}"
    );
    assert_eq!(
        g(dmeas.h_matrix()),
        bits(meas.h.as_flattened()),
        "H, N = {N}"
    );
    assert_eq!(
        g(dmeas.d_matrix()),
        bits(meas.d.as_flattened()),
        "D, N = {N}"
    );
    assert_eq!(bits(dq.as_slice()), bits(q.as_slice()), "Q, N = {N}");
    assert_eq!(dkf.gain(), kf.gain.as_flattened(), "L, N = {N}");
    assert_eq!(
        bits(dkf.gain()),
        bits(kf.gain.as_flattened()),
        "L bits, N = {N}"
    );
    assert_eq!(
        g(dkf.covariance_matrix()),
        bits(kf.covariance.as_flattened()),
        "P, N = {N}"
    );
    assert_eq!(dkf.iterations(), kf.iterations);

    let (ag, y) = record(200, O);
    let mut e = obs.start_at_rest(&SVector::from([ag[0]])).unwrap();
    let mut de = dobs.start_at_rest(&[ag[0]]).unwrap();
    for n in 1..ag.len() {
        obs.try_step(
            &mut e,
            &SVector::from([ag[n]]),
            &SVector::from_column_slice(&y[n]),
        )
        .unwrap();
        dobs.try_step(&mut de, &[ag[n]], &y[n]).unwrap();
        assert_eq!(
            bits(de.x()),
            bits(e.x().as_slice()),
            "x̂, N = {N}, sample {n}"
        );
    }
    assert_eq!((de.steps(), de.missing()), (e.steps(), e.missing()));
    assert_eq!(de.missing(), 1);

    // f32: rounded once, the same rows.
    let obs32 = Observer::<f32, S, 1, O>::new(&ss, &meas, &kf.gain_matrix()).unwrap();
    let dobs32 = DynObserver::<f32>::new(&dss, &dmeas, &dkf.gain_matrix()).unwrap();
    let mut e = obs32.start_at_rest(&SVector::from([ag[0] as f32])).unwrap();
    let mut de = dobs32.start_at_rest(&[ag[0] as f32]).unwrap();
    for n in 1..50 {
        let y32: Vec<f32> = y[n].iter().map(|&v| v as f32).collect();
        obs32
            .try_step(
                &mut e,
                &SVector::from([ag[n] as f32]),
                &SVector::from_column_slice(&y32),
            )
            .unwrap();
        dobs32.try_step(&mut de, &[ag[n] as f32], &y32).unwrap();
        let b32 = |a: &[f32]| a.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            b32(de.x()),
            b32(e.x().as_slice()),
            "f32 x̂, N = {N}, sample {n}"
        );
    }
}

#[test]
fn run_time_sizes_are_bit_identical_to_the_compiled_ones() {
    same_at::<1, 2, 1>([0]);
    same_at::<2, 4, 2>([0, 1]);
    same_at::<3, 6, 2>([0, 2]);
    same_at::<5, 10, 2>([1, 4]);
    same_at::<8, 16, 3>([0, 3, 7]);
    same_at::<12, 24, 2>([5, 11]);
}

/// `N = 20` (`S = 40`): the largest compiled size (release: its Riccati solve in debug
/// takes a few seconds).
#[test]
#[ignore]
fn run_time_size_20_is_bit_identical_to_the_compiled_one() {
    same_at::<20, 40, 3>([4, 11, 19]);
}

/// The average-acceleration (AEM) model written from the equations: the trapezoidal rule on
/// `x' = F x + G w`, `F = [0 I; −M⁻¹K −M⁻¹C]`, `G = [0; M⁻¹B]` (Newmark β = 1/4, γ = 1/2
/// is the trapezoidal rule on `u` and `v`): `Φ = (I − hF/2)⁻¹ (I + hF/2)`,
/// `Γ₀ = Γ₁ = (I − hF/2)⁻¹ G h/2`; and the absolute accelerations of `dofs`,
/// `H = E [−M⁻¹K −M⁻¹C]`, `D = E M⁻¹B + 1`.
fn reference_model(
    m: &DMatrix<f64>,
    c: &DMatrix<f64>,
    k: &DMatrix<f64>,
    b: &DMatrix<f64>,
    dofs: &[usize],
) -> [DMatrix<f64>; 4] {
    let n = m.nrows();
    let minv = m.clone().try_inverse().unwrap();
    let mut f = DMatrix::zeros(2 * n, 2 * n);
    f.view_mut((0, n), (n, n))
        .copy_from(&DMatrix::identity(n, n));
    f.view_mut((n, 0), (n, n)).copy_from(&(-&minv * k));
    f.view_mut((n, n), (n, n)).copy_from(&(-&minv * c));
    let mut g = DMatrix::zeros(2 * n, 1);
    g.view_mut((n, 0), (n, 1)).copy_from(&(&minv * b));
    let eye = DMatrix::<f64>::identity(2 * n, 2 * n);
    let left = (&eye - &f * (H / 2.0)).try_inverse().unwrap();
    let phi = &left * (&eye + &f * (H / 2.0));
    let gamma = &left * &g * (H / 2.0);
    let e = DMatrix::from_fn(dofs.len(), n, |r, j| if dofs[r] == j { 1.0 } else { 0.0 });
    let hm = &e * f.view((n, 0), (n, 2 * n));
    let d = &e * (&minv * b) + DMatrix::from_element(dofs.len(), 1, 1.0);
    [phi, gamma, hm, d]
}

fn rel(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).amax() / b.amax()
}

/// `N = 23`, outside the compiled sizes: the model against the dense reference written
/// from the equations, the gain solving the DARE with a stable closed loop, and the
/// estimates against a plain observer loop on the reference matrices.
#[test]
fn a_size_outside_the_list_matches_the_reference_written_from_the_equations() {
    let (n, dofs) = (23, [4usize, 13, 22]);
    let (m, c, k) = building(n);
    let b = ground(&m);
    let ss = DynStateSpace::aem(&m, &c, &k, &b, H).unwrap();
    let meas = ss.absolute_accelerations(&dofs, 0).unwrap();
    let [phi, gamma, hm, d] = reference_model(&m, &c, &k, &b, &dofs);
    let errs = [
        rel(&ss.phi_matrix(), &phi),
        rel(&ss.gamma0_matrix(), &gamma),
        rel(&ss.gamma1_matrix(), &gamma),
        rel(&meas.h_matrix(), &hm),
        // D is zero here (M⁻¹B = −ι): compared absolutely.
        (meas.d_matrix() - &d).amax(),
    ];
    println!(
        "N = 23 model vs the trapezoidal reference (relative to max): {:?}",
        errs.map(|e| format!("{e:.2e}"))
    );
    // Two different eliminations of 46×46 systems with κ ≈ 10: rounding of order
    // S κ ε ≈ 1e-13 (measured 1.2e-14).
    assert!(errs.iter().all(|&e| e < 1e-13), "{errs:?}");

    let (_, _, q, r) = dyn_scene(n, &dofs);
    let kf = DynSteadyState::new(&ss, &meas, &q, &r).unwrap();
    let (p, l) = (kf.covariance_matrix(), kf.gain_matrix());
    // The DARE on the reference matrices: P = Φ (P − P Hᵀ Σ⁻¹ H P) Φᵀ + Q, L = P Hᵀ Σ⁻¹.
    let sigma = &hm * &p * hm.transpose() + &r;
    let si = sigma.clone().try_inverse().unwrap();
    let lref = &p * hm.transpose() * &si;
    let post = &p - &p * hm.transpose() * &si * &hm * &p;
    let res = &phi * &post * phi.transpose() + &q - &p;
    let (res_rel, l_rel) = (res.amax() / p.amax(), rel(&l, &lref));
    // The closed loop Φ (I − L H) of the a-priori error is stable.
    let acl = &phi * (DMatrix::identity(2 * n, 2 * n) - &l * &hm);
    let rho = acl
        .complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max);
    println!(
        "N = 23 DARE residual {res_rel:.2e} (relative to max P), gain vs P Hᵀ Σ⁻¹ {l_rel:.2e}, closed-loop spectral radius {rho:.6}, {} doubling iterations",
        kf.iterations()
    );
    // Rounding of the S = 46 products of P (measured 4e-13 and 1e-13).
    assert!(res_rel < 5e-12 && l_rel < 5e-12 && rho < 1.0);

    // The estimates against a plain loop on the reference matrices and the crate's gain.
    let obs = DynObserver::<f64>::new(&ss, &meas, &l).unwrap();
    let (ag, y) = record(300, 3);
    let mut e = obs.start_at_rest(&[ag[0]]).unwrap();
    let mut x = DMatrix::<f64>::zeros(2 * n, 1);
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    for i in 1..ag.len() {
        obs.try_step(&mut e, &[ag[i]], &y[i]).unwrap();
        let xp = &phi * &x + &gamma * (ag[i - 1] + ag[i]);
        let yv = DMatrix::from_column_slice(3, 1, &y[i]);
        x = if yv.iter().all(|v| v.is_finite()) {
            let nu = yv - &hm * &xp - &d * ag[i];
            &xp + &l * nu
        } else {
            xp
        };
        let xd = DMatrix::from_column_slice(2 * n, 1, e.x());
        worst = worst.max((&xd - &x).amax());
        scale = scale.max(x.amax());
    }
    println!(
        "N = 23 estimates vs the reference loop: {:.2e} of max |x̂|",
        worst / scale
    );
    // Rounding of the two models' matrices, carried by the stable loop (measured 7.5e-14).
    assert!(worst / scale < 1e-12, "{}", worst / scale);
    assert_eq!(e.missing(), 1);
}

/// The same bad input gives the same error variant as the const-generic path, and a
/// refused step leaves the estimate unchanged.
#[test]
fn bad_input_gives_the_compiled_paths_errors() {
    const N: usize = 3;
    let (m, c, k) = building(N);
    let b = ground(&m);
    let sm = |a: &DMatrix<f64>| SMatrix::<f64, N, N>::from_fn(|i, j| a[(i, j)]);
    let bs = SMatrix::<f64, N, 1>::from_fn(|i, _| b[(i, 0)]);
    let cst =
        |m: &DMatrix<f64>, h: f64| StateSpace::<N, 6, 1>::aem(&sm(m), &sm(&c), &sm(&k), &bs, h);
    let dynm = |m: &DMatrix<f64>, h: f64| DynStateSpace::aem(m, &c, &k, &b, h);
    for (mm, h) in [
        (m.clone(), -1.0),
        (m.clone(), f64::NAN),
        (m.clone() * 0.0, H),
    ] {
        let (a, d) = (cst(&mm, h).map(|_| ()), dynm(&mm, h).map(|_| ()));
        assert!(a.is_err());
        assert_eq!(a, d, "h = {h}");
    }
    let mut mnan = m.clone();
    mnan[(1, 1)] = f64::NAN;
    assert_eq!(cst(&mnan, H).map(|_| ()), dynm(&mnan, H).map(|_| ()));
    assert_eq!(
        DynStateSpace::aem(&m, &c, &DMatrix::zeros(2, 2), &b, H),
        Err(Error::StateSizeMismatch)
    );

    let ss = cst(&m, H).unwrap();
    let meas = ss
        .outputs(&Outputs::absolute_accelerations(
            Outputs::<N, 1, 2>::select([0, 2]),
            0,
        ))
        .unwrap();
    let dss = dynm(&m, H).unwrap();
    let dmeas = dss.absolute_accelerations(&[0, 2], 0).unwrap();
    let q = SMatrix::<f64, 6, 6>::identity() * 1e-8;
    let r = SMatrix::<f64, 2, 2>::identity() * 0.01;
    let dq = DMatrix::from_fn(6, 6, |i, j| q[(i, j)]);
    let dr = DMatrix::from_fn(2, 2, |i, j| r[(i, j)]);
    let same = |q: SMatrix<f64, 6, 6>, r: SMatrix<f64, 2, 2>| {
        let a = SteadyState::new(&ss, &meas, &q, &r).map(|_| ());
        let d = DynSteadyState::new(
            &dss,
            &dmeas,
            &DMatrix::from_fn(6, 6, |i, j| q[(i, j)]),
            &DMatrix::from_fn(2, 2, |i, j| r[(i, j)]),
        )
        .map(|_| ());
        assert_eq!(a, d);
        a
    };
    let mut qa = q;
    qa[(0, 1)] = 1.0; // not symmetric
    assert_eq!(same(qa, r), Err(Error::InvalidCovariance));
    assert_eq!(same(q, -r), Err(Error::InvalidCovariance));
    assert_eq!(same(q * f64::NAN, r), Err(Error::InvalidCovariance));
    assert_eq!(same(q, r), Ok(()));
    // An undamped model driven by no noise: no stabilizing solution to certify.
    let z = SMatrix::<f64, N, N>::zeros();
    let ss0 = StateSpace::<N, 6, 1>::aem(&sm(&m), &z, &sm(&k), &bs, H).unwrap();
    let meas0 = ss0
        .outputs(&Outputs::absolute_accelerations(
            Outputs::<N, 1, 2>::select([0, 2]),
            0,
        ))
        .unwrap();
    let dss0 = DynStateSpace::aem(&m, &DMatrix::zeros(N, N), &k, &b, H).unwrap();
    let dmeas0 = dss0.absolute_accelerations(&[0, 2], 0).unwrap();
    let zq = SMatrix::<f64, 6, 6>::zeros();
    let a = SteadyState::new(&ss0, &meas0, &zq, &r).map(|_| ());
    let d = DynSteadyState::new(&dss0, &dmeas0, &DMatrix::zeros(6, 6), &dr).map(|_| ());
    println!("undamped, Q = 0: {a:?}");
    assert_eq!(a, d);
    assert!(a.is_err());
    assert_eq!(
        DynSteadyState::new(&dss, &dmeas, &DMatrix::zeros(5, 5), &dr),
        Err(Error::StateSizeMismatch)
    );

    // A non-finite gain, then steps refused with the estimate unchanged.
    let kf = DynSteadyState::new(&dss, &dmeas, &dq, &dr).unwrap();
    let mut bad = kf.gain_matrix();
    bad[(0, 0)] = f64::INFINITY;
    let cbad = SMatrix::<f64, 6, 2>::from_fn(|i, j| bad[(i, j)]);
    assert_eq!(
        Observer::<f64, 6, 1, 2>::new(&ss, &meas, &cbad).map(|_| ()),
        DynObserver::<f64>::new(&dss, &dmeas, &bad).map(|_| ())
    );
    let obs = DynObserver::<f64>::new(&dss, &dmeas, &kf.gain_matrix()).unwrap();
    let cobs = Observer::<f64, 6, 1, 2>::new(
        &ss,
        &meas,
        &SMatrix::from_fn(|i, j| kf.gain_matrix()[(i, j)]),
    )
    .unwrap();
    let mut e = obs.start_at_rest(&[0.0]).unwrap();
    let mut ce = cobs.start_at_rest(&SVector::from([0.0])).unwrap();
    obs.try_step(&mut e, &[0.3], &[0.1, 0.2]).unwrap();
    cobs.try_step(&mut ce, &SVector::from([0.3]), &SVector::from([0.1, 0.2]))
        .unwrap();
    let before = e.clone();
    let xb = bits(e.x());
    for (w, y) in [(f64::NAN, 0.0), (f64::INFINITY, 0.0)] {
        let d = obs.try_step(&mut e, &[w], &[y, y]);
        let cb = ce;
        let c = cobs.try_step(&mut ce, &SVector::from([w]), &SVector::from([y, y]));
        assert_eq!(d, c, "w = {w}");
        assert!(d.is_err());
        assert_eq!(e, before);
        assert_eq!(bits(e.x()), xb);
        assert_eq!(ce, cb);
    }
    assert_eq!(
        obs.try_step(&mut e, &[0.0, 1.0], &[0.1, 0.2]),
        Err(Error::StateSizeMismatch)
    );
    // A correction that overflows: NonFiniteState, the estimate unchanged.
    let huge = DMatrix::from_element(6, 2, 1e300);
    let obs_big = DynObserver::<f64>::new(&dss, &dmeas, &huge).unwrap();
    let cobs_big =
        Observer::<f64, 6, 1, 2>::new(&ss, &meas, &SMatrix::from_element(1e300)).unwrap();
    let mut e = obs_big.start_at_rest(&[0.0]).unwrap();
    let mut ce = cobs_big.start_at_rest(&SVector::from([0.0])).unwrap();
    let (d, c) = (
        obs_big.try_step(&mut e, &[0.0], &[1e10, 1e10]),
        cobs_big.try_step(&mut ce, &SVector::from([0.0]), &SVector::from([1e10, 1e10])),
    );
    assert_eq!(
        (d, c),
        (Err(Error::NonFiniteState), Err(Error::NonFiniteState))
    );
    assert_eq!((e.steps(), bits(e.x())), (0, vec![0; 6]));
    assert_eq!(
        obs.start(&[0.0; 5], &[0.0]).map(|_| ()),
        Err(Error::StateSizeMismatch)
    );
    assert_eq!(
        obs.start(&[f64::NAN; 6], &[0.0]).map(|_| ()),
        Err(Error::NonFiniteInput)
    );
}

/// The full Kalman filter at compiled size `N` with `O` sensors at `dofs`: `DynKalman`
/// against `Kalman`, every estimate and covariance bit for bit over 120 steps (sample 7 of
/// sensor 0 missing), in `f64` and in `f32`.
fn kalman_same_at<const N: usize, const S: usize, const O: usize>(dofs: [usize; O]) {
    let Models {
        ss,
        meas,
        dss,
        dmeas,
        dq,
        dr,
        ..
    } = models::<N, S, O>(dofs);
    let q = SMatrix::<f64, S, S>::from_fn(|i, j| dq[(i, j)]);
    let r = SMatrix::<f64, O, O>::from_fn(|i, j| dr[(i, j)]);
    let (ag, y) = record(120, O);

    macro_rules! compare {
        ($t:ty) => {{
            let t = |v: f64| v as $t;
            let kf = Kalman::<$t, S, 1, O>::new(&ss, &meas, &q, &r).unwrap();
            let dkf = DynKalman::<$t>::new(&dss, &dmeas, &dq, &dr).unwrap();
            let p0 = SMatrix::<$t, S, S>::identity() * t(1e-6);
            let mut st = kf
                .start(&SVector::zeros(), &p0, &SVector::from([t(ag[0])]))
                .unwrap();
            let dp0 = DMatrix::from_column_slice(S, S, p0.as_slice());
            let mut dst = dkf.start(&[t(0.0); S], &dp0, &[t(ag[0])]).unwrap();
            let bits = |a: &[$t]| {
                a.iter()
                    .map(|v| f64::from(*v).to_bits())
                    .collect::<Vec<_>>()
            };
            for n in 1..ag.len() {
                let w = SVector::from([t(ag[n])]);
                let yv = SVector::<$t, O>::from_fn(|s, _| t(y[n][s]));
                kf.try_step(&mut st, &w, &yv).unwrap();
                dkf.try_step(&mut dst, &[t(ag[n])], yv.as_slice()).unwrap();
                assert_eq!(
                    bits(dst.estimate().x()),
                    bits(st.estimate().x().as_slice()),
                    "x̂, N = {N}, sample {n}"
                );
                assert_eq!(
                    bits(dst.covariance_matrix().as_slice()),
                    bits(st.covariance().as_slice()),
                    "P, N = {N}, sample {n}"
                );
            }
            assert_eq!((dst.estimate().steps(), dst.estimate().missing()), (119, 1));
        }};
    }
    compare!(f64);
    compare!(f32);
}

#[test]
fn run_time_kalman_is_bit_identical_to_the_compiled_one() {
    kalman_same_at::<1, 2, 1>([0]);
    kalman_same_at::<2, 4, 2>([0, 1]);
    kalman_same_at::<3, 6, 3>([0, 1, 2]);
    kalman_same_at::<5, 10, 2>([1, 4]);
    kalman_same_at::<10, 20, 3>([2, 5, 9]);
}

/// `N = 23`, 4 sensors (neither a compiled size nor a compiled sensor count): `DynKalman`
/// against a Kalman filter written here from the equations on the reference model
/// (`P⁻ = Φ P Φᵀ + Q`, `K = P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹` by an explicit inverse, Joseph form),
/// 300 steps with a missing sample.
#[test]
fn run_time_kalman_outside_the_list_matches_a_filter_written_from_the_equations() {
    let (n, dofs) = (23, [4usize, 9, 13, 22]);
    let (m, c, k) = building(n);
    let b = ground(&m);
    let ss = DynStateSpace::aem(&m, &c, &k, &b, H).unwrap();
    let meas = ss.absolute_accelerations(&dofs, 0).unwrap();
    let [phi, gamma, hm, d] = reference_model(&m, &c, &k, &b, &dofs);
    let (_, _, q, r) = dyn_scene(n, &dofs);
    let kf = DynKalman::<f64>::new(&ss, &meas, &q, &r).unwrap();
    let (ag, y) = record(300, 4);
    let s2 = 2 * n;
    let mut st = kf
        .start(&vec![0.0; s2], &DMatrix::zeros(s2, s2), &[ag[0]])
        .unwrap();
    let eye = DMatrix::<f64>::identity(s2, s2);
    let (mut x, mut p) = (DMatrix::<f64>::zeros(s2, 1), DMatrix::<f64>::zeros(s2, s2));
    let (mut wx, mut sx, mut wp) = (0.0f64, 0.0f64, 0.0f64);
    for i in 1..ag.len() {
        kf.try_step(&mut st, &[ag[i]], &y[i]).unwrap();
        let xp = &phi * &x + &gamma * (ag[i - 1] + ag[i]);
        let pm = &phi * &p * phi.transpose() + &q;
        let yv = DMatrix::from_column_slice(4, 1, &y[i]);
        (x, p) = if yv.iter().all(|v| v.is_finite()) {
            let sigma = &hm * &pm * hm.transpose() + &r;
            let gain = &pm * hm.transpose() * sigma.try_inverse().unwrap();
            let ikh = &eye - &gain * &hm;
            let nu = yv - &hm * &xp - &d * ag[i];
            (
                &xp + &gain * nu,
                &ikh * &pm * ikh.transpose() + &gain * &r * gain.transpose(),
            )
        } else {
            (xp, pm)
        };
        let xd = DMatrix::from_column_slice(s2, 1, st.estimate().x());
        wx = wx.max((&xd - &x).amax());
        sx = sx.max(x.amax());
        wp = wp.max(rel(&st.covariance_matrix(), &p));
    }
    println!(
        "N = 23, 4 sensors: DynKalman vs the filter from the equations: x̂ {:.2e} of max |x̂|, P {wp:.2e} of max |P|",
        wx / sx
    );
    // The models differ by rounding (1e-14, above); two orders of products and a Cholesky
    // solve vs an explicit inverse of the 4×4 Σ carry it through a stable recursion
    // (measured 7.2e-14 for x̂, 4.5e-13 for P).
    assert!(wx / sx < 1e-12 && wp < 5e-12, "{} {wp}", wx / sx);
    assert_eq!((st.estimate().steps(), st.estimate().missing()), (299, 1));
}

/// `DynKalman` refuses what `Kalman` refuses, with the same variant, and a refused step
/// leaves the state unchanged.
#[test]
fn run_time_kalman_gives_the_compiled_paths_errors() {
    let (m, c, k) = building(3);
    let b = ground(&m);
    let ss = DynStateSpace::aem(&m, &c, &k, &b, H).unwrap();
    let meas = ss.absolute_accelerations(&[0, 2], 0).unwrap();
    let q = DMatrix::identity(6, 6) * 1e-8;
    let r = DMatrix::identity(2, 2) * 0.01;
    let mut bad_r = r.clone();
    bad_r[(1, 1)] = -1.0;
    assert_eq!(
        DynKalman::<f64>::new(&ss, &meas, &q, &bad_r),
        Err(Error::InvalidCovariance)
    );
    assert_eq!(
        DynKalman::<f64>::new(&ss, &meas, &DMatrix::identity(5, 5), &r),
        Err(Error::StateSizeMismatch)
    );
    let big = DMatrix::identity(6, 6) * 1e300;
    assert_eq!(
        DynKalman::<f32>::new(&ss, &meas, &big, &r),
        Err(Error::OperatorOverflow)
    );
    let kf = DynKalman::<f64>::new(&ss, &meas, &q, &r).unwrap();
    let mut asym = DMatrix::identity(6, 6);
    asym[(0, 1)] = 0.5;
    assert_eq!(
        kf.start(&[0.0; 6], &asym, &[0.0]).err(),
        Some(Error::InvalidCovariance)
    );
    let mut st = kf.start(&[0.0; 6], &DMatrix::zeros(6, 6), &[0.0]).unwrap();
    kf.try_step(&mut st, &[0.1], &[0.2, 0.1]).unwrap();
    let before = (st.estimate().clone(), st.covariance_matrix());
    assert_eq!(
        kf.try_step(&mut st, &[f64::NAN], &[0.2, 0.1]),
        Err(Error::NonFiniteInput)
    );
    assert_eq!(
        kf.try_step(&mut st, &[0.1], &[0.2]),
        Err(Error::StateSizeMismatch)
    );
    // A state of another filter (2 storeys, 4 states).
    let (m2, c2, k2) = building(2);
    let ss2 = DynStateSpace::aem(&m2, &c2, &k2, &ground(&m2), H).unwrap();
    let meas2 = ss2.absolute_accelerations(&[0, 1], 0).unwrap();
    let other = DynKalman::<f64>::new(&ss2, &meas2, &DMatrix::identity(4, 4), &r).unwrap();
    let mut st4 = other
        .start(&[0.0; 4], &DMatrix::zeros(4, 4), &[0.0])
        .unwrap();
    assert_eq!(
        kf.try_step(&mut st4, &[0.1], &[0.2, 0.1]),
        Err(Error::StateSizeMismatch)
    );
    assert_eq!(before, (st.estimate().clone(), st.covariance_matrix()));
}

/// `DynSteadyState::new_with_stop` looks at its flag before every piece of the solve (more
/// looks than doubling iterations), gives `new`'s gain bit for bit when the flag stays
/// down, and `InvalidParameter(Cancelled)` when it is raised part-way, at any piece.
#[test]
fn the_gain_solve_answers_a_stop_flag_between_its_pieces() {
    use aemstep::Param;
    let n = 23;
    let (dss, dmeas, q, r) = dyn_scene(n, &[0, n - 1]);
    let plain = DynSteadyState::new(&dss, &dmeas, &q, &r).unwrap();
    let mut looks = 0u32;
    let polled = DynSteadyState::new_with_stop(&dss, &dmeas, &q, &r, &mut || {
        looks += 1;
        false
    })
    .unwrap();
    assert_eq!(bits(polled.gain()), bits(plain.gain()));
    assert_eq!(
        bits(polled.covariance_matrix().as_slice()),
        bits(plain.covariance_matrix().as_slice())
    );
    // One look a doubling iteration, then at least a verification pass and its Stein
    // squarings, then the end.
    assert!(
        looks > plain.iterations() + 2,
        "{looks} looks, {} iterations",
        plain.iterations()
    );
    for at in [1, 2, plain.iterations() + 1, looks] {
        let mut seen = 0u32;
        let stopped = DynSteadyState::new_with_stop(&dss, &dmeas, &q, &r, &mut || {
            seen += 1;
            seen >= at
        });
        assert_eq!(
            stopped.err(),
            Some(Error::InvalidParameter(Param::Cancelled)),
            "stopped at look {at}"
        );
        assert_eq!(seen, at);
    }
}
