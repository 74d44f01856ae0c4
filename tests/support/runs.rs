//! Runs of the crate's linear and time-varying steppers on the paper's examples and on
//! random systems, measured against the references of `support` (exact solutions, the
//! independent Newmark loop). Shared by `tests/linear.rs` and `tests/varying.rs` (which
//! assert bounds on these numbers) and `xtask/src/bin/verification.rs` (which prints them), so
//! the page and the tests measure the same runs.
#![allow(dead_code, clippy::needless_range_loop, clippy::type_complexity)]

use aemstep::{AForm, Coefficients, Linear, Real, State, Stepper, TimeVarying, Varying};
use nalgebra::{DMatrix, DVector, SMatrix, SVector, matrix, vector};

use super::support::{
    ModalExact, Rng, example4, max_abs, newmark_aa, random_system, sdof_exact, test_load,
};

/// `u'' + 2ξω u' + ω² u = p` at step `h`, built in `f64` and rounded once to `T`.
pub fn sdof<T: Real>(w: f64, xi: f64, h: f64) -> Linear<T, 1> {
    let c = |x: f64| SMatrix::<f64, 1, 1>::new(x);
    Linear::new(&c(1.0), &c(2.0 * xi * w), &c(w * w), h).unwrap()
}

/// `x` rounded to `T`, as a 1-vector.
pub fn vec1<T: Real>(x: f64) -> SVector<T, 1> {
    vector![T::from_f64_rounded(x)]
}

// ------------------------------------------------------------------ paper examples 1, 2, 4

/// Numerical period of paper Example 1 (u'' + 25u = 0, u0 = 1, v0 = 0) from the mean
/// spacing of upward zero crossings (linearly interpolated) over `t_end`.
pub fn example1_period(h: f64, t_end: f64) -> f64 {
    let sys = sdof::<f64>(5.0, 0.0, h);
    let mut s = sys
        .start(&vector![1.0], &vector![0.0], &vector![0.0])
        .unwrap();
    let mut crossings = Vec::new();
    let steps = (t_end / h).round() as u64;
    for _ in 0..steps {
        let (t0, u0) = (s.time(h), s.u()[0]);
        sys.step(&mut s, &vector![0.0]);
        let u1 = s.u()[0];
        if u0 < 0.0 && u1 >= 0.0 {
            crossings.push(t0 + h * (-u0) / (u1 - u0));
        }
    }
    (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64
}

/// Paper Example 2 (ω = 2, ξ = 0.07, u0 = 1, v0 = 20, step load p) at h = 1/(500k) over
/// [0, 25]: the trajectory u_n, n = 1..=12 500 k.
pub fn example2_run<T: Real>(p: f64, k: u32) -> Vec<f64> {
    let h = 1.0 / (500.0 * k as f64);
    let sys = sdof::<T>(2.0, 0.07, h);
    let mut s = sys.start(&vec1(1.0), &vec1(20.0), &vec1(p)).unwrap();
    (0..25 * 500 * k)
        .map(|_| {
            sys.step(&mut s, &vec1(p));
            s.u()[0].as_f64()
        })
        .collect()
}

/// Max |u_n − u_exact(t_n)| of an [`example2_run`].
pub fn example2_error(us: &[f64], p: f64, k: u32) -> f64 {
    let h = 1.0 / (500.0 * k as f64);
    us.iter()
        .enumerate()
        .map(|(i, u)| (u - sdof_exact(2.0, 0.07, 1.0, 20.0, p, (i + 1) as f64 * h).0).abs())
        .fold(0.0, f64::max)
}

/// Paper Example 4 (3-DOF, Caughey damping) against exact modal superposition:
/// (max error over [0, 5], max |u|) at step h.
pub fn example4_error<T: Real>(h: f64) -> (f64, f64) {
    let (m, k, xi, u0, v0, p) = example4();
    let exact = ModalExact::new(&m, &k, xi, &u0, &v0, &p);
    let sys = Linear::<T, 3>::new(&m, &exact.c, &k, h).unwrap();
    let vv = |a: &SVector<f64, 3>| a.map(T::from_f64_rounded);
    let mut s = sys.start(&vv(&u0), &vv(&v0), &vv(&p)).unwrap();
    let (mut err, mut umax) = (0.0f64, 0.0f64);
    for n in 1..=(5.0 / h).round() as u64 {
        sys.step(&mut s, &vv(&p));
        let ue = exact.u(n as f64 * h);
        for i in 0..3 {
            err = err.max((s.u()[i].as_f64() - ue[i]).abs());
            umax = umax.max(ue[i].abs());
        }
    }
    (err, umax)
}

// ------------------------------------------------------------------ extremes

/// `n` steps of the undamped `u'' + ω² u = 0` at step `h` from u0 = 1, v0 = 0: the final
/// state.
pub fn free_vibration<T: Real>(w: f64, h: f64, n: u64) -> State<T, 1> {
    let sys = sdof::<T>(w, 0.0, h);
    let z = vec1::<T>(0.0);
    let mut s = sys.start(&vec1(1.0), &z, &z).unwrap();
    for _ in 0..n {
        sys.step(&mut s, &z);
    }
    s
}

/// `n` undamped steps of u'' + ω² u = 0, ω = 2π, h = 0.01 (s ≈ 0.063), u0 = 1, v0 = 0.
/// Returns (max |E/E0 − 1|, final |E/E0 − 1|, max |u − cos(nφ)| over every 1000th step)
/// with φ the phase per step of the operators as rounded to `T`, from the analysis module
/// (its own rounding is f64), so that operator rounding is not counted as drift and the
/// last figure is pure rounding.
pub fn undamped_drift<T: Real>(n: u64) -> (f64, f64, f64) {
    let w = 2.0 * core::f64::consts::PI;
    let h = 0.01;
    let sys = sdof::<T>(w, 0.0, h);
    let z = vec1::<T>(0.0);
    let mut s = sys.start(&vec1(1.0), &z, &z).unwrap();
    let a = aemstep::analysis::amplification_matrix(&sys);
    let (_, phi) = aemstep::analysis::SdofProperties::from_matrix(a, w * h, 0.0)
        .principal
        .unwrap();
    let (mut emax, mut umax) = (0.0f64, 0.0f64);
    let mut e = 0.0;
    for i in 1..=n {
        sys.step(&mut s, &z);
        let (u, v) = (s.u()[0].as_f64(), s.v()[0].as_f64());
        e = u * u + v * v / (w * w) - 1.0;
        emax = emax.max(e.abs());
        if i % 1000 == 0 {
            umax = umax.max((u - (i as f64 * phi).cos()).abs());
        }
    }
    (emax, e.abs(), umax)
}

// ------------------------------------------------------------------ paper example 3

/// Paper Example 3, `(1 + t²) u'' + t u' + e^{1/(1+t)} u = p(t)`: coefficients computed in
/// `f64` and rounded once to `T`.
pub struct Example3;

impl<T: Real> TimeVarying<T, 1> for Example3 {
    fn coefficients(&self, t: T) -> Coefficients<T, 1> {
        let t = t.as_f64();
        let r = T::from_f64_rounded;
        Coefficients {
            mass: matrix![r(1.0 + t * t)],
            damping: matrix![r(t)],
            stiffness: matrix![r((1.0 / (1.0 + t)).exp())],
        }
    }
}

/// `u = e^{−0.1t} cos t`, `u' = e^{−0.1t}(−0.1 cos t − sin t)`,
/// `u'' = e^{−0.1t}(−0.99 cos t + 0.2 sin t)`.
pub fn example3_exact(t: f64) -> (f64, f64, f64) {
    let e = (-0.1 * t).exp();
    let (s, c) = t.sin_cos();
    (e * c, e * (-0.1 * c - s), e * (-0.99 * c + 0.2 * s))
}

/// The load, by substituting the exact solution into the equation.
pub fn example3_load(t: f64) -> f64 {
    let (u, v, a) = example3_exact(t);
    (1.0 + t * t) * a + t * v + (1.0 / (1.0 + t)).exp() * u
}

/// `Varying<T>` on Example 3 from its exact initial state: the state at `t = 0`.
pub fn example3_start<T: Real>(st: &Varying<T, 1>) -> State<T, 1> {
    st.start(
        &Example3,
        &vec1(1.0),
        &vec1(-0.1),
        &vec1(example3_load(0.0)),
    )
    .unwrap()
}

/// Max |u − u_exact| of `Varying<T>` on Example 3 at step `h` over (0, t_end].
pub fn example3_error<T: Real>(h: f64, t_end: f64) -> f64 {
    let st = Varying::<T, 1>::new(h).unwrap();
    let mut s = example3_start(&st);
    let mut err = 0.0f64;
    for n in 1..=(t_end / h).round() as u64 {
        let t = n as f64 * h;
        st.try_step(&Example3, &mut s, &vec1(example3_load(t)))
            .unwrap();
        err = err.max((s.u()[0].as_f64() - example3_exact(t).0).abs());
    }
    err
}

// ------------------------------------------------------------------ random systems

/// Runs `sys` for `steps` steps under `test_load` from fixed initial conditions: every
/// state, in `f64`.
pub fn trajectory<
    T: Real,
    const N: usize,
    S: Stepper<T, N, Input = SVector<T, N>, State = State<T, N>>,
>(
    sys: &S,
    steps: usize,
) -> Vec<State<f64, N>> {
    let h = sys.time_step().as_f64();
    let load = |t: f64| SVector::<T, N>::from_fn(|i, _| T::from_f64_rounded(test_load(i, t)));
    let u0 = SVector::<T, N>::from_fn(|i, _| T::from_f64_rounded(0.1 * (i as f64 + 1.0)));
    let v0 = SVector::<T, N>::from_fn(|i, _| T::from_f64_rounded(-0.2 + 0.05 * i as f64));
    let mut s = sys.start(&u0, &v0, &load(0.0)).unwrap();
    let f = |s: &State<T, N>| {
        let c = |x: &SVector<T, N>| x.map(|y| y.as_f64());
        State::restore(c(s.u()), c(s.v()), c(s.a()), s.steps()).expect("a finite state")
    };
    let mut out = vec![f(&s)];
    for n in 1..=steps {
        sys.step(&mut s, &load(n as f64 * h));
        out.push(f(&s));
    }
    out
}

/// max |x − y| / max |y| over u, v, a separately; the worst of the three.
pub fn rel_diff<const N: usize>(x: &[State<f64, N>], y: &[State<f64, N>]) -> f64 {
    let parts: [fn(&State<f64, N>) -> &SVector<f64, N>; 3] = [|s| s.u(), |s| s.v(), |s| s.a()];
    parts
        .iter()
        .map(|f| {
            let scale = max_abs(y.iter().flat_map(|s| f(s).iter()));
            let d = x.iter().zip(y).map(|(a, b)| (f(a) - f(b)).amax());
            d.fold(0.0, f64::max) / scale
        })
        .fold(0.0, f64::max)
}

/// `a` as a dynamic matrix (the independent references' type).
pub fn dm<const N: usize>(a: &SMatrix<f64, N, N>) -> DMatrix<f64> {
    DMatrix::from_fn(N, N, |i, j| a[(i, j)])
}

/// Random system N (seed N), 10⁴ steps at h = 0.01 under `test_load`: the fast form, its
/// A-form, the independent Newmark-AA loop and the fast form in `f32`, each as a
/// [`trajectory`].
pub struct CrossCheck<const N: usize> {
    pub m: SMatrix<f64, N, N>,
    pub c: SMatrix<f64, N, N>,
    pub k: SMatrix<f64, N, N>,
    pub h: f64,
    pub aform: AForm<f64, N>,
    /// Fast form, A-form, Newmark-AA, fast form in `f32`.
    pub tf: Vec<State<f64, N>>,
    pub ta: Vec<State<f64, N>>,
    pub tn: Vec<State<f64, N>>,
    pub t32: Vec<State<f64, N>>,
}

pub fn cross_check<const N: usize>() -> CrossCheck<N> {
    let mut rng = Rng::new(N as u64);
    let (m, c, k) = random_system::<N>(&mut rng);
    let (h, steps) = (0.01, 10_000);
    let fast = Linear::<f64, N>::new(&m, &c, &k, h).unwrap();
    let aform = fast.a_form();
    let nm = newmark_aa(
        &dm(&m),
        &dm(&c),
        &dm(&k),
        h,
        &DVector::from_fn(N, |i, _| 0.1 * (i as f64 + 1.0)),
        &DVector::from_fn(N, |i, _| -0.2 + 0.05 * i as f64),
        |t| DVector::from_fn(N, |i, _| test_load(i, t)),
        steps,
    );
    let sv = |x: &DVector<f64>| SVector::<f64, N>::from_fn(|i, _| x[i]);
    let tn = nm
        .iter()
        .enumerate()
        .map(|(n, (u, v, a))| {
            State::restore(sv(u), sv(v), sv(a), n as u64).expect("a finite reference")
        })
        .collect();
    CrossCheck {
        tf: trajectory(&fast, steps),
        ta: trajectory(&aform, steps),
        tn,
        t32: trajectory(&Linear::<f32, N>::new(&m, &c, &k, h).unwrap(), steps),
        m,
        c,
        k,
        h,
        aform,
    }
}
