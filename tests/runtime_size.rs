//! Models of any size (issue 34): [`DynLinear`], the linear AEM stepper sized at run time,
//! against the const-generic [`Linear`] bit for bit at the sizes both serve, and at a size
//! no const-generic build serves (N = 37) against an independent average-acceleration
//! Newmark loop written here from the equations with nalgebra's dense LU.
#![cfg(feature = "std")]

use aemstep::{DynLinear, Error, Linear, Stepper};
use nalgebra::{DMatrix, DVector, SMatrix, SVector};

/// `u`, `v`, `a` of the const-generic state (`fixed`) and the run-time one (`run`) equal
/// bit for bit at step `step` of an `n`-DOF run (`f32` compared through its exact `f64`).
fn same_uva<T: aemstep::Real>(fixed: [&[T]; 3], run: [&[T]; 3], n: usize, step: usize) {
    let bits = |x: &[T]| x.iter().map(|x| x.as_f64().to_bits()).collect::<Vec<_>>();
    for (name, (a, b)) in ["u", "v", "a"].into_iter().zip(fixed.into_iter().zip(run)) {
        assert_eq!(bits(a), bits(b), "{name}, N = {n}, step {step}");
    }
}

/// A deterministic, non-symmetric, well-conditioned test model of `n` degrees of freedom
/// (kg, N·s/m, N/m): a chain with a mass matrix that is not diagonal, a stiffness chain
/// plus a small coupling, and damping `0.1 M + 0.002 K` plus a small skew part.
fn model(n: usize) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let mut seed = 0x9e37_79b9_7f4a_7c15_u64 ^ n as u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let m = DMatrix::from_fn(n, n, |i, j| match i.abs_diff(j) {
        0 => 1.0 + 0.3 * (i % 3) as f64,
        1 => 0.05,
        _ => 0.0,
    });
    let mut k = DMatrix::from_fn(n, n, |i, j| match i.abs_diff(j) {
        0 => 2000.0 + 10.0 * i as f64,
        1 => -900.0,
        _ => 0.0,
    });
    for i in 0..n {
        for j in 0..n {
            k[(i, j)] += 5.0 * next();
        }
    }
    let skew = DMatrix::from_fn(n, n, |i, j| 0.01 * (i as f64 - j as f64));
    let c = &m * 0.1 + &k * 0.002 + skew;
    (m, c, k)
}

/// The load history `p(t_s)` (N) on every degree of freedom: not `f32`-exact, a few
/// frequencies.
fn load(n: usize, step: usize, h: f64) -> Vec<f64> {
    let t = step as f64 * h;
    (0..n)
        .map(|j| (7.3 * t + 0.7 * j as f64).sin() * (1.0 + 0.1 * j as f64) + 0.3)
        .collect()
}

const H: f64 = 0.01;
const STEPS: usize = 300;

/// `u`, `v`, `a` of both paths, every sample, compared by `to_bits`, in `T`.
fn same_histories<T: aemstep::Real, const N: usize>() {
    let (m, c, k) = model(N);
    let sm = |a: &DMatrix<f64>| SMatrix::<f64, N, N>::from_fn(|i, j| a[(i, j)]);
    let fixed = Linear::<T, N>::new(&sm(&m), &sm(&c), &sm(&k), H).unwrap();
    let dynamic = DynLinear::<T>::new(&m, &c, &k, H).unwrap();
    assert_eq!(dynamic.size(), N);
    assert_eq!(dynamic.condition().to_bits(), fixed.condition().to_bits());
    assert_eq!(dynamic.time_step().as_f64(), fixed.time_step().as_f64());
    let g = fixed.effective_inverse();
    let gd = dynamic.effective_inverse();
    for i in 0..N {
        for j in 0..N {
            assert_eq!(g[(i, j)].as_f64().to_bits(), gd[(i, j)].as_f64().to_bits());
        }
    }
    let t = |x: &[f64]| {
        x.iter()
            .map(|&x| T::from_f64_rounded(x))
            .collect::<Vec<T>>()
    };
    let sv = |x: &[T]| SVector::<T, N>::from_fn(|i, _| x[i]);
    let (u0, v0): (Vec<T>, Vec<T>) = (
        t(&(0..N).map(|j| 0.001 * j as f64).collect::<Vec<_>>()),
        t(&(0..N).map(|j| -0.01 + 0.003 * j as f64).collect::<Vec<_>>()),
    );
    let p0 = t(&load(N, 0, H));
    let mut s = fixed.start(&sv(&u0), &sv(&v0), &sv(&p0)).unwrap();
    let mut d = dynamic.start(&u0, &v0, &p0).unwrap();
    for step in 0..=STEPS {
        if step > 0 {
            let p = t(&load(N, step, H));
            if step % 2 == 0 {
                fixed.try_step(&mut s, &sv(&p)).unwrap();
                dynamic.try_step(&mut d, &p).unwrap();
            } else {
                fixed.step(&mut s, &sv(&p));
                dynamic.step(&mut d, &p).unwrap();
            }
        }
        same_uva(
            [s.u().as_slice(), s.v().as_slice(), s.a().as_slice()],
            [d.u(), d.v(), d.a()],
            N,
            step,
        );
        assert_eq!(s.steps(), d.steps());
    }
}

/// At N = 1, 2, 3, 5, 8, 12, 20, in `f64` and `f32`: the same operators (`G`, `κ`) and
/// the same `u`, `v`, `a` at every one of 301 samples, bit for bit.
#[test]
fn bit_identical_to_const_generic_linear() {
    macro_rules! sizes { ($($n:literal)*) => { $(
        same_histories::<f64, $n>();
        same_histories::<f32, $n>();
    )* } }
    sizes!(1 2 3 5 8 12 20);
}

/// Average-acceleration Newmark written from the equations (β = 1/4, γ = 1/2), solving
/// `(M + (h/2) C + (h²/4) K) a_n = p_n − C (v + (h/2) a) − K (u + h v + (h²/4) a)` with
/// nalgebra's LU each step; `a_0` from `M a_0 = p_0 − C v_0 − K u_0`. Returns `u` at
/// every sample.
fn reference(
    m: &DMatrix<f64>,
    c: &DMatrix<f64>,
    k: &DMatrix<f64>,
    u0: &DVector<f64>,
    v0: &DVector<f64>,
) -> Vec<DVector<f64>> {
    let n = m.nrows();
    let p = |s: usize| DVector::from_vec(load(n, s, H));
    let (mut u, mut v) = (u0.clone(), v0.clone());
    let mut a = m.clone().lu().solve(&(p(0) - c * &v - k * &u)).unwrap();
    let eff = (m + c * (H / 2.0) + k * (H * H / 4.0)).lu();
    let mut out = vec![u.clone()];
    for s in 1..=STEPS {
        let vh = &v + &a * (H / 2.0);
        let uh = &u + &v * H + &a * (H * H / 4.0);
        let an = eff.solve(&(p(s) - c * &vh - k * &uh)).unwrap();
        u = uh + &an * (H * H / 4.0);
        v = vh + &an * (H / 2.0);
        a = an;
        out.push(u.clone());
    }
    out
}

/// N = 37, a size no const-generic build of the Python package serves: `DynLinear<f64>`
/// against the independent loop. Both compute the same recurrence in `f64` by different
/// operations (precomputed `G, GC, GK` against a solve per step), so they differ by
/// rounding only: each step's rows are sums of `3N` rounded products (a few `N ε`
/// relative), accumulating as a random walk over the steps of a stable recurrence with a
/// well-conditioned `M_eff`: bound `√steps · N · ε` = 1.4e-13 of the largest
/// displacement. Measured: 4.7e-15.
#[test]
fn size_37_matches_independent_newmark() {
    let n = 37;
    let (m, c, k) = model(n);
    let u0 = DVector::from_fn(n, |j, _| 0.001 * j as f64);
    let v0 = DVector::from_fn(n, |j, _| -0.01 + 0.003 * j as f64);
    let want = reference(&m, &c, &k, &u0, &v0);
    let sys = DynLinear::<f64>::new(&m, &c, &k, H).unwrap();
    let mut s = sys
        .start(u0.as_slice(), v0.as_slice(), &load(n, 0, H))
        .unwrap();
    let scale = want.iter().map(|u| u.amax()).fold(0.0, f64::max);
    let mut worst = 0.0f64;
    for (step, w) in want.iter().enumerate() {
        if step > 0 {
            sys.try_step(&mut s, &load(n, step, H)).unwrap();
        }
        for j in 0..n {
            worst = worst.max((s.u()[j] - w[j]).abs() / scale);
        }
    }
    eprintln!("N = 37: largest |u − u_ref| / max|u_ref| = {worst:.2e}");
    let bound = (STEPS as f64).sqrt() * n as f64 * f64::EPSILON;
    assert!(worst < bound, "{worst:e} ≥ {bound:e}");
    assert!(
        worst > 0.0,
        "different operations should differ by rounding"
    );
}

/// The same bad inputs give the same errors (and a failed step leaves the state as it
/// was) through both paths, at N = 3.
#[test]
fn same_errors_as_const_generic_linear() {
    const N: usize = 3;
    let (m, c, k) = model(N);
    let sm = |a: &DMatrix<f64>| SMatrix::<f64, N, N>::from_fn(|i, j| a[(i, j)]);
    let both = |m: &DMatrix<f64>, c: &DMatrix<f64>, k: &DMatrix<f64>, h: f64| {
        (
            Linear::<f32, N>::new(&sm(m), &sm(c), &sm(k), h).err(),
            DynLinear::<f32>::new(m, c, k, h).err(),
        )
    };
    let mut nan = m.clone();
    nan[(1, 2)] = f64::NAN;
    let zero = DMatrix::zeros(N, N);
    let huge = &k * 1e300;
    let tiny = &m * 1e-300;
    let cases = [
        (both(&nan, &c, &k, H), Error::NonFiniteInput),
        (both(&m, &c, &k, 0.0), Error::InvalidTimeStep),
        (both(&m, &c, &k, -H), Error::InvalidTimeStep),
        (both(&m, &c, &k, f64::NAN), Error::InvalidTimeStep),
        (both(&m, &c, &k, 1e58), Error::InvalidTimeStep),
        (both(&zero, &zero, &zero, H), Error::SingularEffectiveMatrix),
        // G = M_eff⁻¹ ~ 1e-300·(h²/4)⁻¹ is zero in f32.
        (both(&m, &c, &huge, H), Error::OperatorUnderflow),
        // M⁻¹ ~ 1e300 does not fit f32.
        (both(&tiny, &zero, &zero, H), Error::OperatorOverflow),
        (both(&m, &huge, &zero, 1.0), Error::OperatorUnderflow),
    ];
    for (i, ((fixed, dynamic), want)) in cases.into_iter().enumerate() {
        assert_eq!(dynamic, fixed, "case {i}");
        assert_eq!(fixed, Some(want), "case {i}");
    }
    // Singular M, regular M_eff: built, but no start from a load.
    let fixed = Linear::<f64, N>::new(&sm(&zero), &sm(&c), &sm(&k), H).unwrap();
    let dynamic = DynLinear::<f64>::new(&zero, &c, &k, H).unwrap();
    let z = SVector::<f64, N>::zeros();
    assert_eq!(fixed.start(&z, &z, &z).err(), Some(Error::SingularMass));
    assert_eq!(
        dynamic.start(&[0.0; N], &[0.0; N], &[0.0; N]).err(),
        Some(Error::SingularMass)
    );
    let fs = fixed.start_with_acceleration(&z, &z, &z).unwrap();
    let ds = dynamic
        .start_with_acceleration(&[0.0; N], &[0.0; N], &[0.0; N])
        .unwrap();
    assert_eq!(fs.u().as_slice(), ds.u());
    // Non-finite start and step inputs; the failed step leaves the state unchanged.
    let fixed = Linear::<f64, N>::new(&sm(&m), &sm(&c), &sm(&k), H).unwrap();
    let dynamic = DynLinear::<f64>::new(&m, &c, &k, H).unwrap();
    let bad = [0.0, f64::INFINITY, 0.0];
    assert_eq!(
        fixed.start(&z, &z, &SVector::from_row_slice(&bad)).err(),
        Some(Error::NonFiniteInput)
    );
    assert_eq!(
        dynamic.start(&[0.0; N], &[0.0; N], &bad).err(),
        Some(Error::NonFiniteInput)
    );
    let mut fs = fixed.start(&z, &z, &z).unwrap();
    let mut ds = dynamic.start(&[0.0; N], &[0.0; N], &[0.0; N]).unwrap();
    fixed.step(&mut fs, &SVector::from_element(1.0));
    dynamic.step(&mut ds, &[1.0; N]).unwrap();
    let before = ds.clone();
    assert_eq!(
        fixed
            .try_step(&mut fs, &SVector::from_row_slice(&bad))
            .err(),
        Some(Error::NonFiniteInput)
    );
    assert_eq!(
        dynamic.try_step(&mut ds, &bad).err(),
        Some(Error::NonFiniteInput)
    );
    assert_eq!(ds, before);
    // A finite state and load whose next state overflows (K û ~ 2000 · 1e306).
    let big = [1e306; N];
    let mut fb = fixed
        .start_with_acceleration(&SVector::from_row_slice(&big), &z, &z)
        .unwrap();
    let mut db = dynamic
        .start_with_acceleration(&big, &[0.0; N], &[0.0; N])
        .unwrap();
    let kept = db.clone();
    assert_eq!(
        fixed.try_step(&mut fb, &z).err(),
        Some(Error::NonFiniteState)
    );
    assert_eq!(
        dynamic.try_step(&mut db, &[0.0; N]).err(),
        Some(Error::NonFiniteState)
    );
    assert_eq!(db, kept);
    // Sizes the const-generic types make unrepresentable.
    let two = DMatrix::zeros(2, 2);
    let wide = DMatrix::zeros(N, N + 1);
    for (m_, c_) in [(&m, &two), (&wide, &c), (&two, &two)] {
        assert_eq!(
            DynLinear::<f64>::new(m_, c_, &k, H).err(),
            Some(Error::StateSizeMismatch)
        );
    }
    assert_eq!(
        DynLinear::<f64>::new(
            &DMatrix::zeros(0, 0),
            &DMatrix::zeros(0, 0),
            &DMatrix::zeros(0, 0),
            H
        )
        .err(),
        Some(Error::StateSizeMismatch)
    );
    assert_eq!(
        dynamic.start(&[0.0; 2], &[0.0; N], &[0.0; N]).err(),
        Some(Error::StateSizeMismatch)
    );
    assert_eq!(
        dynamic.try_step(&mut ds, &[0.0; 2]).err(),
        Some(Error::StateSizeMismatch)
    );
    assert_eq!(
        dynamic.step(&mut ds, &[0.0; 4]).err(),
        Some(Error::StateSizeMismatch)
    );
    let other = DynLinear::<f64>::new(&two, &two, &DMatrix::identity(2, 2), H).unwrap();
    let small = other.start(&[0.0; 2], &[0.0; 2], &[0.0; 2]);
    assert_eq!(small.as_ref().err(), Some(&Error::SingularMass));
    let mut small = other
        .start_with_acceleration(&[0.0; 2], &[0.0; 2], &[0.0; 2])
        .unwrap();
    assert_eq!(
        dynamic.step(&mut small, &[0.0; N]).err(),
        Some(Error::StateSizeMismatch)
    );
    assert_eq!(ds, before);
}

// ---------------------------------------------------------------------------------------
// The yielding shear building at a run-time size: `DynShearBuilding` stepped by
// `DynNonlinear` against `ShearBuilding` stepped by `Nonlinear<T, N>`.

mod building {
    use aemstep::hysteresis::EnergyAccount;
    use aemstep::hysteresis::ShearBuilding;
    use aemstep::hysteresis::{Bilinear, BoucWen, Friction, HistoryModel, Law, Parallel};
    use aemstep::{
        DynEnergyAccount, DynNonlinear, DynShearBuilding, Error, NewtonSettings, Nonlinear, Real,
    };
    use nalgebra::{DMatrix, DVector, SVector};

    pub const H: f64 = 0.005;
    pub const STEPS: usize = 400;

    /// Floor masses (kg), ground storey first.
    pub fn masses(n: usize) -> Vec<f64> {
        (0..n).map(|i| 1e5 * (1.0 + 0.1 * (i % 3) as f64)).collect()
    }

    /// Storey stiffness (N/m), tapering up the building.
    pub fn stiffness(i: usize, n: usize) -> f64 {
        2e8 * (1.0 - 0.5 * i as f64 / n as f64)
    }

    /// Storey yield force (N): about the storey's share of the weight above at 3 m/s², so
    /// the ground motion below yields the building.
    pub fn yield_force(i: usize, n: usize) -> f64 {
        3.0e5 * (n - i) as f64
    }

    /// The initial storey stiffness matrix `K` (N/m), tridiagonal.
    pub fn k_matrix(n: usize) -> DMatrix<f64> {
        DMatrix::from_fn(n, n, |r, c| {
            let k = |i: usize| if i < n { stiffness(i, n) } else { 0.0 };
            match r.abs_diff(c) {
                0 => k(r) + k(r + 1),
                1 => -k(r.max(c)),
                _ => 0.0,
            }
        })
    }

    /// Damping (N·s/m): `0.3 M + 0.002 K` (Rayleigh, tridiagonal: the `L D Lᵀ` path), or
    /// that plus a small full symmetric part (`full`: the dense path).
    pub fn damping(n: usize, full: bool) -> DMatrix<f64> {
        let m = masses(n);
        let k = k_matrix(n);
        DMatrix::from_fn(n, n, |r, c| {
            let rayleigh = 0.002 * k[(r, c)] + if r == c { 0.3 * m[r] } else { 0.0 };
            let extra = if full {
                1e3 / (1.0 + r.abs_diff(c) as f64)
            } else {
                0.0
            };
            rayleigh + extra
        })
    }

    /// Ground acceleration (m/s²) at step `s`: two sines, up to about 7 m/s².
    pub fn ground(s: usize) -> f64 {
        let t = s as f64 * H;
        5.0 * (9.0 * t).sin() + 2.0 * (23.0 * t).sin()
    }

    pub fn bilinear<T: Real>(i: usize, n: usize) -> Bilinear<T> {
        Bilinear::new(stiffness(i, n), yield_force(i, n), 0.05).unwrap()
    }

    pub fn bouc_wen<T: Real>(i: usize, n: usize) -> BoucWen<T> {
        BoucWen::new(stiffness(i, n), yield_force(i, n), 0.05, 0.5, 0.5, 2.0).unwrap()
    }

    pub fn bilinear_friction<T: Real>(i: usize, n: usize) -> Parallel<Bilinear<T>, Friction<T>> {
        Parallel(
            bilinear(i, n),
            Friction::new(0.1 * yield_force(i, n), 0.01).unwrap(),
        )
    }

    /// Both paths over the record, every step compared bit for bit: `u`, `v`, `a`, the
    /// history, and the Newton report (iterations, residual, correction, branch changes),
    /// or the same error. Returns the Newton iterations summed (so the caller knows Newton
    /// worked) and whether some storey yielded.
    pub fn same<T: Real + Bits, L: Law<T> + Copy, const N: usize>(
        law: impl Fn(usize, usize) -> L,
        full: bool,
        settings: NewtonSettings<T>,
    ) -> (u32, bool)
    where
        L::History: PartialEq + core::fmt::Debug,
    {
        let c = damping(N, full);
        let rows: [[f64; N]; N] = core::array::from_fn(|i| core::array::from_fn(|j| c[(i, j)]));
        let m: [f64; N] = core::array::from_fn(|i| masses(N)[i]);
        let laws: [L; N] = core::array::from_fn(|i| law(i, N));
        let fixed = ShearBuilding::<T, L, N>::new(m, laws, &rows).unwrap();
        let dynamic = DynShearBuilding::<T, L>::new(&masses(N), laws.to_vec(), &c).unwrap();
        let stepper = Nonlinear::<T, N>::new(H, settings).unwrap();
        let dyn_stepper = DynNonlinear::<T>::new(H, settings).unwrap();
        assert_eq!(
            dyn_stepper.time_step().to_bits_u64(),
            stepper.time_step().to_bits_u64()
        );
        let zero = SVector::<T, N>::zeros();
        let ag = |s: usize| T::from_f64_rounded(ground(s));
        let (mut s, mut history) = stepper
            .start_with_history(
                &fixed,
                &zero,
                &zero,
                &fixed.ground_load(ag(0)),
                &fixed.initial_history(),
            )
            .unwrap();
        let mut p = vec![T::zero(); N];
        dynamic.ground_load(ag(0), &mut p);
        assert_eq!(p.as_slice(), fixed.ground_load(ag(0)).as_slice());
        let mut d = dyn_stepper
            .start(&dynamic, zero.as_slice(), zero.as_slice(), &p)
            .unwrap();
        let mut account = EnergyAccount::start(&fixed, &s, &history, &fixed.ground_load(ag(0)));
        let mut dyn_account = DynEnergyAccount::start(&dynamic, &d, &p);
        let energies = |e: [T; 6]| e.map(|x| x.as_f64());
        let mut total = 0;
        for step in 0..=STEPS {
            if step > 0 {
                let pf = fixed.ground_load(ag(step));
                dynamic.ground_load(ag(step), &mut p);
                let previous = history;
                let a = stepper.try_step_with_history(&fixed, &mut s, &mut history, &pf);
                let b = dyn_stepper.try_step(&dynamic, &mut d, &p);
                match (a, b) {
                    (Ok(a), Ok(b)) => {
                        assert_eq!(a.iterations, b.iterations, "N = {N}, step {step}");
                        assert_eq!(a.residual.to_bits_u64(), b.residual.to_bits_u64());
                        assert_eq!(a.correction.to_bits_u64(), b.correction.to_bits_u64());
                        assert_eq!(
                            (a.converged, a.branch_changes),
                            (b.converged, b.branch_changes)
                        );
                        total += a.iterations;
                        account.step(&fixed, &previous, &s, &history, &pf);
                        dyn_account.step(&dynamic, &d, &p);
                    }
                    (a, b) => assert_eq!(a.err(), b.err(), "N = {N}, step {step}"),
                }
            }
            super::same_uva(
                [s.u().as_slice(), s.v().as_slice(), s.a().as_slice()],
                [d.u(), d.v(), d.a()],
                N,
                step,
            );
            assert_eq!(
                history.as_slice(),
                d.history(),
                "history, N = {N}, step {step}"
            );
            assert_eq!(s.steps(), d.steps());
            // The energy account, bit for bit at every size (at N = 2, 3, 4 nalgebra sums
            // fixed-size dot products in its own order, and the run-time account does too).
            let e = |a: &EnergyAccount<T, N>| {
                energies([
                    a.input,
                    a.kinetic,
                    a.recoverable,
                    a.viscous,
                    a.hysteretic,
                    a.balance_error(),
                ])
            };
            let f = |a: &DynEnergyAccount<T, L::History>| {
                let a = a.totals();
                energies([
                    a.input,
                    a.kinetic,
                    a.recoverable,
                    a.viscous,
                    a.hysteretic,
                    a.balance_error(),
                ])
            };
            let (want, got) = (e(&account), f(&dyn_account));
            assert_eq!(
                want.map(f64::to_bits),
                got.map(f64::to_bits),
                "energy N = {N}, step {step}"
            );
        }
        let yielded = history != fixed.initial_history();
        (total, yielded)
    }

    /// The bits of a `T` as a `u64`, for comparisons in either precision.
    pub trait Bits {
        fn to_bits_u64(self) -> u64;
    }
    impl Bits for f64 {
        fn to_bits_u64(self) -> u64 {
            self.to_bits()
        }
    }
    impl Bits for f32 {
        fn to_bits_u64(self) -> u64 {
            u64::from(self.to_bits())
        }
    }

    /// The reference: the average-acceleration Newmark step (β = 1/4, γ = 1/2, the AEM's
    /// kinematics) with Newton on the acceleration, written from the equations on dense
    /// nalgebra matrices, and the bilinear storey law with linear kinematic hardening by
    /// the return mapping (Simo & Hughes 1998, *Computational Inelasticity*, §1.4):
    /// trial `f = k (δ − δ_p)`, `ξ = f − H δ_p` with `H = α k / (1 − α)`; if
    /// `|ξ| > f_y`: `Δγ = (|ξ| − f_y)/(k + H)`, `δ_p += Δγ sgn ξ`, `f = k (δ − δ_p)`,
    /// tangent `k H / (k + H) = α k`. Newton until the correction is below `1e-15` of the
    /// acceleration (or 50 iterations). Returns `u` at every sample.
    pub fn reference(n: usize, c: &DMatrix<f64>) -> Vec<DVector<f64>> {
        let m = DMatrix::from_diagonal(&DVector::from_vec(masses(n)));
        let ks: Vec<f64> = (0..n).map(|i| stiffness(i, n)).collect();
        let fy: Vec<f64> = (0..n).map(|i| yield_force(i, n)).collect();
        let alpha = 0.05;
        let hard: Vec<f64> = ks.iter().map(|k| alpha * k / (1.0 - alpha)).collect();
        // Storey forces and tangents at floor displacements `u` from plastic drifts `dp`.
        let storeys = |u: &DVector<f64>, dp: &[f64]| {
            let mut f = vec![0.0; n];
            let mut kt = vec![0.0; n];
            let mut dp_new = dp.to_vec();
            for i in 0..n {
                let drift = u[i] - if i == 0 { 0.0 } else { u[i - 1] };
                let trial = ks[i] * (drift - dp[i]);
                let xi = trial - hard[i] * dp[i];
                if xi.abs() > fy[i] {
                    let gamma = (xi.abs() - fy[i]) / (ks[i] + hard[i]);
                    dp_new[i] = dp[i] + gamma * xi.signum();
                    f[i] = ks[i] * (drift - dp_new[i]);
                    kt[i] = ks[i] * hard[i] / (ks[i] + hard[i]);
                } else {
                    f[i] = trial;
                    kt[i] = ks[i];
                }
            }
            (f, kt, dp_new)
        };
        // Internal force F_s and tangent K_t of the chain.
        let assemble = |f: &[f64], kt: &[f64]| {
            let mut fs = DVector::zeros(n);
            let mut k = DMatrix::zeros(n, n);
            for i in 0..n {
                fs[i] += f[i];
                k[(i, i)] += kt[i];
                if i > 0 {
                    fs[i - 1] -= f[i];
                    k[(i - 1, i - 1)] += kt[i];
                    k[(i, i - 1)] -= kt[i];
                    k[(i - 1, i)] -= kt[i];
                }
            }
            (fs, k)
        };
        let p = |s: usize| -DVector::from_vec(masses(n)) * ground(s);
        let (mut u, mut v) = (DVector::zeros(n), DVector::zeros(n));
        let mut dp = vec![0.0; n];
        let mut a = m.clone().lu().solve(&p(0)).unwrap();
        let mut out = vec![u.clone()];
        for s in 1..=STEPS {
            let vh = &v + &a * (H / 2.0);
            let uh = &u + &v * H + &a * (H * H / 4.0);
            let mut q = a.clone();
            let mut accepted = dp.clone();
            for _ in 0..50 {
                let (un, vn) = (&uh + &q * (H * H / 4.0), &vh + &q * (H / 2.0));
                let (f, kt, dp_new) = storeys(&un, &dp);
                let (fs, k) = assemble(&f, &kt);
                let r = &m * &q + c * &vn + fs - p(s);
                let j = &m + c * (H / 2.0) + k * (H * H / 4.0);
                let delta = j.lu().solve(&r).unwrap();
                q -= &delta;
                accepted = dp_new;
                if delta.amax() <= 1e-15 * q.amax() {
                    break;
                }
            }
            u = &uh + &q * (H * H / 4.0);
            v = &vh + &q * (H / 2.0);
            a = q;
            // The plastic drifts of the accepted iterate (the last evaluated one: its
            // correction was below the rounding of `q`, so `u` moved by less than an ulp).
            dp = storeys(&u, &dp).2;
            let _ = accepted;
            out.push(u.clone());
        }
        out
    }

    /// The error variant of each path for the same call, at size `N`.
    pub fn dyn_errors<L: Law<f64> + Copy>(
        laws: Vec<L>,
        c: &DMatrix<f64>,
        masses: &[f64],
        h: f64,
        settings: NewtonSettings<f64>,
    ) -> Option<Error> {
        let building = match DynShearBuilding::<f64, L>::new(masses, laws, c) {
            Ok(b) => b,
            Err(e) => return Some(e),
        };
        DynNonlinear::<f64>::new(h, settings)
            .and_then(|s| {
                let zero = vec![0.0; building.size()];
                s.start(&building, &zero, &zero, &zero).map(|_| ())
            })
            .err()
    }
}

/// Bit-identical histories and energy accounts, run-time against const-generic, at
/// N = 1, 2, 3, 5, 8, 12, 20 (and 4) for the bilinear and Bouc–Wen storeys with Rayleigh damping (the `L D Lᵀ` path), the
/// bilinear frame with a friction damper at three sizes, the dense path (a full `C`) at
/// N = 3 and 8, and the bilinear building in `f32`. Each run yields (else the law's
/// inelastic branch would not be exercised) and Newton iterates.
#[test]
fn building_bit_identical_to_const_generic() {
    use aemstep::NewtonSettings;
    use building::{bilinear, bilinear_friction, bouc_wen, same};
    let s64 = NewtonSettings::<f64>::default();
    let runs: Vec<(&str, (u32, bool))> = vec![
        ("bilinear 1", same::<f64, _, 1>(bilinear, false, s64)),
        ("bilinear 2", same::<f64, _, 2>(bilinear, false, s64)),
        ("bilinear 3", same::<f64, _, 3>(bilinear, false, s64)),
        ("bilinear 4", same::<f64, _, 4>(bilinear, false, s64)),
        ("bilinear 5", same::<f64, _, 5>(bilinear, false, s64)),
        ("bilinear 8", same::<f64, _, 8>(bilinear, false, s64)),
        ("bilinear 12", same::<f64, _, 12>(bilinear, false, s64)),
        ("bilinear 20", same::<f64, _, 20>(bilinear, false, s64)),
        ("bouc_wen 1", same::<f64, _, 1>(bouc_wen, false, s64)),
        ("bouc_wen 2", same::<f64, _, 2>(bouc_wen, false, s64)),
        ("bouc_wen 3", same::<f64, _, 3>(bouc_wen, false, s64)),
        ("bouc_wen 5", same::<f64, _, 5>(bouc_wen, false, s64)),
        ("bouc_wen 8", same::<f64, _, 8>(bouc_wen, false, s64)),
        ("bouc_wen 12", same::<f64, _, 12>(bouc_wen, false, s64)),
        ("bouc_wen 20", same::<f64, _, 20>(bouc_wen, false, s64)),
        (
            "friction 2",
            same::<f64, _, 2>(bilinear_friction, false, s64),
        ),
        (
            "friction 5",
            same::<f64, _, 5>(bilinear_friction, false, s64),
        ),
        (
            "friction 12",
            same::<f64, _, 12>(bilinear_friction, false, s64),
        ),
        ("dense bilinear 3", same::<f64, _, 3>(bilinear, true, s64)),
        ("dense bouc_wen 8", same::<f64, _, 8>(bouc_wen, true, s64)),
        (
            "f32 bilinear 5",
            same::<f32, _, 5>(bilinear, false, NewtonSettings::default()),
        ),
        (
            "f32 bouc_wen 12",
            same::<f32, _, 12>(bouc_wen, false, NewtonSettings::default()),
        ),
    ];
    for (name, (iterations, yielded)) in runs {
        eprintln!("{name}: {iterations} Newton iterations, yielded: {yielded}");
        assert!(yielded, "{name}: the record should yield the building");
        assert!(
            iterations as usize >= building::STEPS,
            "{name}: Newton iterated"
        );
    }
}

/// N = 37 (no const-generic build serves it): the bilinear building with Rayleigh damping
/// against the independent Newton–Newmark loop (`building::reference`, dense nalgebra,
/// the law from the return mapping). The bilinear storeys are piecewise linear with their
/// exact tangent, so a Newton iterate whose branches are those of the solution solves the
/// step's equations up to rounding: the crate (relative residual `1e-12`, far above that
/// floor) stops on the first such iterate, the reference iterates to a correction of
/// `1e-15`. The two differ by rounding (sums of `3N` terms a row, different operations:
/// banded `L D Lᵀ` against dense LU), accumulating over a stable recurrence as in the
/// linear test: bound `√steps · N · ε` = 1.6e-13 of the largest displacement. Measured:
/// 2.1e-15 (14 of the 37 storeys yield).
#[test]
fn building_size_37_matches_independent_newton_newmark() {
    use aemstep::hysteresis::Bilinear;
    use aemstep::{DynNonlinear, DynShearBuilding, NewtonSettings};
    use building::{STEPS, bilinear, damping, ground, masses, reference};
    let n = 37;
    let c = damping(n, false);
    let want = reference(n, &c);
    let laws: Vec<Bilinear<f64>> = (0..n).map(|i| bilinear(i, n)).collect();
    let b = DynShearBuilding::<f64, _>::new(&masses(n), laws, &c).unwrap();
    let tol = 1e-12;
    let stepper = DynNonlinear::<f64>::new(building::H, NewtonSettings::up_to(30, tol)).unwrap();
    let (zero, mut p) = (vec![0.0; n], vec![0.0; n]);
    b.ground_load(ground(0), &mut p);
    let mut s = stepper.start(&b, &zero, &zero, &p).unwrap();
    let scale = want.iter().map(|u| u.amax()).fold(0.0, f64::max);
    let mut worst = 0.0f64;
    for (step, w) in want.iter().enumerate() {
        if step > 0 {
            b.ground_load(ground(step), &mut p);
            stepper.try_step(&b, &mut s, &p).unwrap();
        }
        for j in 0..n {
            worst = worst.max((s.u()[j] - w[j]).abs() / scale);
        }
    }
    let yielded = s.history().iter().filter(|h| h.plastic != 0.0).count();
    eprintln!(
        "N = 37: largest |u − u_ref| / max|u_ref| = {worst:.2e} (max |u| = {scale:.3e} m, \
         {yielded} storeys yielded)"
    );
    assert!(yielded > 0, "the record should yield the building");
    let bound = (STEPS as f64).sqrt() * n as f64 * f64::EPSILON;
    assert!(worst < bound, "{worst:e} ≥ {bound:e}");
}

/// A step that fails (NotConverged, a one-iteration budget on a yielding step) leaves the
/// run-time state and history bit-identical, as the const-generic path does, and the same
/// bad inputs give the same error variants through both paths (N = 5).
#[test]
fn building_same_errors_as_const_generic() {
    use aemstep::hysteresis::{Bilinear, HistoryModel, ShearBuilding};
    use aemstep::{DynNonlinear, DynShearBuilding, Error, NewtonSettings, Nonlinear};
    use building::{bilinear, damping, dyn_errors, ground, masses};
    const N: usize = 5;
    let c = damping(N, false);
    let rows: [[f64; N]; N] = core::array::from_fn(|i| core::array::from_fn(|j| c[(i, j)]));
    let m: [f64; N] = core::array::from_fn(|i| masses(N)[i]);
    let laws: [Bilinear<f64>; N] = core::array::from_fn(|i| bilinear(i, N));
    let fixed = ShearBuilding::new(m, laws, &rows).unwrap();
    let dynamic = DynShearBuilding::new(&masses(N), laws.to_vec(), &c).unwrap();
    let once = NewtonSettings::up_to(1, 1e-10);
    let (stepper, dyn_stepper) = (
        Nonlinear::<f64, N>::new(building::H, once).unwrap(),
        DynNonlinear::<f64>::new(building::H, once).unwrap(),
    );
    let zero = SVector::<f64, N>::zeros();
    let (mut s, mut history) = stepper
        .start_with_history(
            &fixed,
            &zero,
            &zero,
            &fixed.ground_load(0.0),
            &fixed.initial_history(),
        )
        .unwrap();
    let mut d = dyn_stepper
        .start(&dynamic, zero.as_slice(), zero.as_slice(), &[0.0; N])
        .unwrap();
    // One Newton iteration solves an elastic step (the equations are then linear) but not
    // the first step on which a storey yields: step with the one-iteration budget until
    // that step, which both paths refuse.
    let mut p = vec![0.0; N];
    let mut pf = fixed.ground_load(0.0);
    let mut refused = None;
    for step in 1..=building::STEPS {
        pf = fixed.ground_load(3.0 * ground(step));
        dynamic.ground_load(3.0 * ground(step), &mut p);
        let before = d.clone();
        let (s0, h0) = (s, history);
        let a = stepper.try_step_with_history(&fixed, &mut s, &mut history, &pf);
        let b = dyn_stepper.try_step(&dynamic, &mut d, &p);
        assert_eq!(a.err(), b.err(), "step {step}");
        if let Err(e) = b {
            assert_eq!(e, Error::NotConverged);
            assert_eq!((s, history), (s0, h0));
            assert_eq!(d, before);
            refused = Some(step);
            break;
        }
    }
    let step = refused.expect("a yielding step refused with one iteration");
    eprintln!("one-iteration budget: step {step} refused on both paths");
    let before = d.clone();
    let bits = |x: &[f64]| x.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(d.u()), bits(s.u().as_slice()));
    assert_eq!(bits(d.a()), bits(s.a().as_slice()));
    // A non-finite load, a load of the wrong size: refused, the state unchanged.
    let mut nan = p.clone();
    nan[2] = f64::NAN;
    let mut nan_f = pf;
    nan_f[2] = f64::NAN;
    assert_eq!(
        stepper
            .try_step_with_history(&fixed, &mut s, &mut history, &nan_f)
            .err(),
        dyn_stepper.try_step(&dynamic, &mut d, &nan).err()
    );
    assert_eq!(
        dyn_stepper.try_step(&dynamic, &mut d, &nan).err(),
        Some(Error::NonFiniteInput)
    );
    assert_eq!(
        dyn_stepper.try_step(&dynamic, &mut d, &p[..4]).err(),
        Some(Error::StateSizeMismatch)
    );
    assert_eq!(d, before);
    // With a normal budget the same step then succeeds on both paths, bit for bit.
    let ok = NewtonSettings::default();
    let (stepper, dyn_stepper) = (
        Nonlinear::<f64, N>::new(building::H, ok).unwrap(),
        DynNonlinear::<f64>::new(building::H, ok).unwrap(),
    );
    let pf = fixed.ground_load(3.0 * ground(step));
    dynamic.ground_load(3.0 * ground(step), &mut p);
    stepper
        .try_step_with_history(&fixed, &mut s, &mut history, &pf)
        .unwrap();
    dyn_stepper.try_step(&dynamic, &mut d, &p).unwrap();
    assert_eq!(bits(s.u().as_slice()), bits(d.u()));
    // Construction errors, in ShearBuilding::new's and Nonlinear::new's order.
    let settings = NewtonSettings::default();
    let fixed_errors = |m: [f64; N], c: &DMatrix<f64>, h: f64, settings| {
        let rows: [[f64; N]; N] = core::array::from_fn(|i| core::array::from_fn(|j| c[(i, j)]));
        ShearBuilding::<f64, _, N>::new(m, laws, &rows)
            .err()
            .or_else(|| Nonlinear::<f64, N>::new(h, settings).err())
    };
    let mut bad_mass = m;
    bad_mass[1] = -1.0;
    let mut nan_mass = m;
    nan_mass[3] = f64::NAN;
    let mut nan_c = c.clone();
    nan_c[(0, 4)] = f64::INFINITY;
    let huge_c = c.map(|x| x * 1e300 * 1e10);
    type Case = ([f64; N], DMatrix<f64>, f64, NewtonSettings<f64>);
    let cases: Vec<Case> = vec![
        (bad_mass, c.clone(), building::H, settings),
        (nan_mass, c.clone(), building::H, settings),
        (m, nan_c, building::H, settings),
        (m, huge_c, building::H, settings),
        ([1e-320; N], c.clone(), building::H, settings),
        (m, c.clone(), 0.0, settings),
        (m, c.clone(), f64::NAN, settings),
        (m, c.clone(), building::H, NewtonSettings::up_to(0, 1e-10)),
        (m, c.clone(), building::H, NewtonSettings::up_to(5, -1.0)),
    ];
    for (m, c, h, settings) in cases {
        let want = fixed_errors(m, &c, h, settings);
        assert!(want.is_some());
        assert_eq!(
            dyn_errors(laws.to_vec(), &c, &m, h, settings),
            want,
            "{m:?} {h}"
        );
    }
    // Sizes that do not match: refused before anything else.
    assert_eq!(
        DynShearBuilding::<f64, _>::new(&masses(N), laws[..4].to_vec(), &c).err(),
        Some(Error::StateSizeMismatch)
    );
    assert_eq!(
        DynShearBuilding::<f64, Bilinear<f64>>::new(&[], vec![], &DMatrix::zeros(0, 0)).err(),
        Some(Error::StateSizeMismatch)
    );
}
