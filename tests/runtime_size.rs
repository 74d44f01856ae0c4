//! Models of any size (issue 34): [`DynLinear`], the linear AEM stepper sized at run time,
//! against the const-generic [`Linear`] bit for bit at the sizes both serve, and at a size
//! no const-generic build serves (N = 37) against an independent average-acceleration
//! Newmark loop written here from the equations with nalgebra's dense LU.
#![cfg(feature = "std")]

use aemstep::{DynLinear, Error, Linear, Stepper};
use nalgebra::{DMatrix, DVector, SMatrix, SVector};

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
    let bits = |x: &[T]| x.iter().map(|x| x.as_f64().to_bits()).collect::<Vec<_>>();
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
        assert_eq!(
            bits(s.u().as_slice()),
            bits(d.u()),
            "u, N = {N}, step {step}"
        );
        assert_eq!(
            bits(s.v().as_slice()),
            bits(d.v()),
            "v, N = {N}, step {step}"
        );
        assert_eq!(
            bits(s.a().as_slice()),
            bits(d.a()),
            "a, N = {N}, step {step}"
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
