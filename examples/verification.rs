//! The measured numbers of `docs/verification.md`, computed from scratch against exact
//! solutions and independent implementations (`tests/support/`), printed as the page.
//!
//! Run: `cargo run --release --example verification` (a few seconds). The page is this
//! program's output: `python3 scripts/check_docs.py --write` writes it, and the test command
//! (`bash scripts/test.sh`, through `scripts/check_docs.py`) regenerates it and fails when
//! a committed number differs by more than one unit in its last printed digit.
//!
//! The tests in `tests/` assert bounds on the same quantities; this program only measures
//! and prints. Everything here is deterministic IEEE arithmetic (no timing).
#![allow(clippy::type_complexity, clippy::needless_range_loop)]

#[path = "../tests/support/mod.rs"]
mod support;

use aemstep::models::Duffing;
use aemstep::models::base_excitation;
use aemstep::{
    Coefficients, Linear, LinearInput, NewtonSettings, Nonlinear, Real, State, Stepper,
    TimeVarying, Varying, models,
};
use nalgebra::{DMatrix, DVector, SMatrix, SVector, matrix, vector};
use support::*;

/// `Linear` from `f64` rows for either scalar type (built in `f64`, rounded once).
trait Build: Real {
    fn linear<const N: usize>(
        m: [[f64; N]; N],
        c: [[f64; N]; N],
        k: [[f64; N]; N],
        h: f64,
    ) -> Linear<Self, N>;
}
impl Build for f64 {
    fn linear<const N: usize>(
        m: [[f64; N]; N],
        c: [[f64; N]; N],
        k: [[f64; N]; N],
        h: f64,
    ) -> Linear<f64, N> {
        Linear::<f64, N>::from_rows(m, c, k, h).expect("operators")
    }
}
impl Build for f32 {
    fn linear<const N: usize>(
        m: [[f64; N]; N],
        c: [[f64; N]; N],
        k: [[f64; N]; N],
        h: f64,
    ) -> Linear<f32, N> {
        Linear::<f32, N>::from_rows(m, c, k, h).expect("operators")
    }
}

fn rows<const N: usize, const C: usize>(a: &SMatrix<f64, N, C>) -> [[f64; C]; N] {
    core::array::from_fn(|i| core::array::from_fn(|j| a[(i, j)]))
}

fn sdof<T: Build>(w: f64, xi: f64, h: f64) -> Linear<T, 1> {
    T::linear([[1.0]], [[2.0 * xi * w]], [[w * w]], h)
}

fn vec1<T: Real>(x: f64) -> SVector<T, 1> {
    vector![T::from_f64_rounded(x)]
}

/// `1.234e-5` with `d` digits after the point.
fn e(x: f64, d: usize) -> String {
    format!("{x:.d$e}")
}

// ------------------------------------------------------------------ linear: paper examples

/// Example 1 (u'' + 25u = 0): numerical period from upward zero crossings over 60 s.
fn example1_period(h: f64) -> f64 {
    let sys = sdof::<f64>(5.0, 0.0, h);
    let mut s = sys.start(&vec1(1.0), &vec1(0.0), &vec1(0.0)).unwrap();
    let mut crossings = Vec::new();
    for _ in 0..(60.0 / h).round() as u64 {
        let (t0, u0) = (s.time(h), s.u()[0]);
        sys.step(&mut s, &vec1(0.0));
        let u1 = s.u()[0];
        if u0 < 0.0 && u1 >= 0.0 {
            crossings.push(t0 + h * (-u0) / (u1 - u0));
        }
    }
    (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64
}

/// Example 1: √(u² + (v/ω)²) − 1 after 10⁵ steps at h = 0.01.
fn example1_amplitude() -> f64 {
    let sys = sdof::<f64>(5.0, 0.0, 0.01);
    let mut s = sys.start(&vec1(1.0), &vec1(0.0), &vec1(0.0)).unwrap();
    for _ in 0..100_000 {
        sys.step(&mut s, &vec1(0.0));
    }
    (s.u()[0].powi(2) + (s.v()[0] / 5.0).powi(2)).sqrt() - 1.0
}

/// Example 2 (ω = 2, ξ = 0.07, u0 = 1, v0 = 20, step load p) at h = 1/(500k) over [0, 25]:
/// the trajectory u_n, n = 1..=12 500 k.
fn example2_run<T: Build>(p: f64, k: u32) -> Vec<f64> {
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

fn example2_error(us: &[f64], p: f64, k: u32) -> f64 {
    let h = 1.0 / (500.0 * k as f64);
    us.iter()
        .enumerate()
        .map(|(i, u)| (u - sdof_exact(2.0, 0.07, 1.0, 20.0, p, (i + 1) as f64 * h).0).abs())
        .fold(0.0, f64::max)
}

/// Example 4 (3-DOF, Caughey damping): (max error over [0, 5], max |u|) at step h.
fn example4_error<T: Build>(h: f64) -> (f64, f64) {
    let (m, k, xi, u0, v0, p) = example4();
    let exact = ModalExact::new(&m, &k, xi, &u0, &v0, &p);
    let sys = T::linear(rows(&m), rows(&exact.c), rows(&k), h);
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

// ------------------------------------------------------------------ linear: cross-checks

fn trajectory<
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
        State::from_parts(c(s.u()), c(s.v()), c(s.a()), s.steps())
    };
    let mut out = vec![f(&s)];
    for n in 1..=steps {
        sys.step(&mut s, &load(n as f64 * h));
        out.push(f(&s));
    }
    out
}

/// max |x − y| / max |y| over u, v, a separately; the worst of the three.
fn rel_diff<const N: usize>(x: &[State<f64, N>], y: &[State<f64, N>]) -> f64 {
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

/// Random system N (seed N, as in `tests/linear.rs`), 10⁴ steps at h = 0.01:
/// (fast vs A-form, fast vs independent Newmark-AA, f32 vs f64).
fn cross_check<const N: usize>() -> (f64, f64, f64) {
    let mut rng = Rng::new(N as u64);
    let (m, c, k) = random_system::<N>(&mut rng);
    let (h, steps) = (0.01, 10_000);
    let fast = f64::linear(rows(&m), rows(&c), rows(&k), h);
    let tf = trajectory(&fast, steps);
    let ta = trajectory(&fast.a_form(), steps);
    let dm = |a: &SMatrix<f64, N, N>| DMatrix::from_fn(N, N, |i, j| a[(i, j)]);
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
    let tn: Vec<State<f64, N>> = nm
        .iter()
        .enumerate()
        .map(|(n, (u, v, a))| State::from_parts(sv(u), sv(v), sv(a), n as u64))
        .collect();
    let t32 = trajectory(&f32::linear(rows(&m), rows(&c), rows(&k), h), steps);
    (rel_diff(&tf, &ta), rel_diff(&tf, &tn), rel_diff(&t32, &tf))
}

// ------------------------------------------------------------------ few inputs

/// `LinearInput` against `Linear` fed `p = B w`, the benchmark building under El Centro in
/// f32 and f64: max ‖u_input − u_linear‖∞ / max ‖u_linear‖∞.
fn input_vs_linear<T: Build>() -> f64
where
    LinearInput<T, 5, 1>: FromRows,
{
    let (m, c, k) = models::five_storey_building();
    let b = base_excitation(&m);
    let h = 0.02;
    let lin = T::linear(m, c, k, h);
    let inp = <LinearInput<T, 5, 1> as FromRows>::from_rows(m, c, k, b, h);
    let bv = SVector::<T, 5>::from_fn(|i, _| T::from_f64_rounded(b[i][0]));
    let ag = elcentro::<T>();
    let z = SVector::<T, 5>::zeros();
    let mut sl = lin.start(&z, &z, &(bv * ag[0])).unwrap();
    let mut si = inp.start(&z, &z, &SVector::from([ag[0]])).unwrap();
    let (mut diff, mut peak) = (0.0f64, 0.0f64);
    for &a in &ag[1..] {
        lin.step(&mut sl, &(bv * a));
        inp.step(&mut si, &SVector::from([a]));
        diff = diff.max((si.u() - sl.u()).map(|x| x.as_f64()).amax());
        peak = peak.max(sl.u().map(|x| x.as_f64()).amax());
    }
    diff / peak
}

trait FromRows {
    fn from_rows(
        m: [[f64; 5]; 5],
        c: [[f64; 5]; 5],
        k: [[f64; 5]; 5],
        b: [[f64; 1]; 5],
        h: f64,
    ) -> Self;
}
impl FromRows for LinearInput<f64, 5, 1> {
    fn from_rows(
        m: [[f64; 5]; 5],
        c: [[f64; 5]; 5],
        k: [[f64; 5]; 5],
        b: [[f64; 1]; 5],
        h: f64,
    ) -> Self {
        LinearInput::<f64, 5, 1>::from_rows(m, c, k, b, h).expect("operators")
    }
}
impl FromRows for LinearInput<f32, 5, 1> {
    fn from_rows(
        m: [[f64; 5]; 5],
        c: [[f64; 5]; 5],
        k: [[f64; 5]; 5],
        b: [[f64; 1]; 5],
        h: f64,
    ) -> Self {
        LinearInput::<f32, 5, 1>::from_rows(m, c, k, b, h).expect("operators")
    }
}

/// El Centro 1940 NS in m/s² (the data file is in g).
fn elcentro<T: Real>() -> Vec<T> {
    let text = include_str!("../data/elcentro-ns-1940.txt");
    text.lines()
        .filter(|l| !l.trim_start().starts_with('#'))
        .flat_map(|l| l.split_whitespace())
        .filter_map(|x| x.parse::<f64>().ok())
        .map(|g| T::from_f64_rounded(g * 9.81))
        .collect()
}

// ------------------------------------------------------------------ extremes

/// 10⁷ undamped steps, ω = 2π, h = 0.01, u0 = 1: max |E/E0 − 1| and max |u − cos(nφ)|
/// (every 1000th step) with φ the phase per step of the operators as rounded to T.
fn ten_million<T: Build>() -> (f64, f64) {
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
    for i in 1..=10_000_000u64 {
        sys.step(&mut s, &z);
        let (u, v) = (s.u()[0].as_f64(), s.v()[0].as_f64());
        emax = emax.max((u * u + v * v / (w * w) - 1.0).abs());
        if i % 1000 == 0 {
            umax = umax.max((u - (i as f64 * phi).cos()).abs());
        }
    }
    (emax, umax)
}

/// h = 1e-9 s, 10⁶ steps of u'' + (2π)² u = 0 from u0 = 1: |u − cos(ωt)| at the end.
fn tiny_step<T: Build>() -> f64 {
    let w = 2.0 * core::f64::consts::PI;
    let (h, n) = (1e-9, 1_000_000u64);
    let sys = sdof::<T>(w, 0.0, h);
    let z = vec1::<T>(0.0);
    let mut s = sys.start(&vec1(1.0), &z, &z).unwrap();
    for _ in 0..n {
        sys.step(&mut s, &z);
    }
    (s.u()[0].as_f64() - (w * n as f64 * h).cos()).abs()
}

// ------------------------------------------------------------------ nonlinear, time-varying

fn duffing_load(t: f64) -> f64 {
    -0.01 * (-0.1 * t).exp() * t.sin() + (-0.3 * t).exp() * t.sin().powi(3)
}

/// Duffing over 0 < t ≤ 20 s, exactly 2 Newton iterations a step (as the firmware):
/// (max error, steps whose report was not "converged in 2").
fn duffing<T: Real>(h: f64) -> (f64, u32) {
    let r = T::from_f64_rounded;
    let st = Nonlinear::<T, 1>::new(h, NewtonSettings::exactly(2, r(1.5e-5))).unwrap();
    let mut s = st
        .start(&Duffing, &vec1(0.0), &vec1(1.0), &vec1(duffing_load(0.0)))
        .unwrap();
    let (mut err, mut bad) = (0.0f64, 0);
    for n in 1..=(20.0 / h).round() as u64 {
        let t = n as f64 * h;
        match st.try_step(&Duffing, &mut s, &vec1(duffing_load(t))) {
            Ok(rep) if rep.converged && rep.iterations == 2 => {}
            _ => bad += 1,
        }
        err = err.max((s.u()[0].as_f64() - (-0.1 * t).exp() * t.sin()).abs());
    }
    (err, bad)
}

/// Paper Example 3, `(1 + t²) u'' + t u' + e^{1/(1+t)} u = p(t)`, exact `u = e^{−0.1t} cos t`.
struct Example3;

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

fn example3_exact(t: f64) -> (f64, f64, f64) {
    let e = (-0.1 * t).exp();
    let (s, c) = t.sin_cos();
    (e * c, e * (-0.1 * c - s), e * (-0.99 * c + 0.2 * s))
}

fn example3_error<T: Real>(h: f64) -> f64 {
    let load = |t: f64| {
        let (u, v, a) = example3_exact(t);
        vec1::<T>((1.0 + t * t) * a + t * v + (1.0 / (1.0 + t)).exp() * u)
    };
    let st = Varying::<T, 1>::new(h).unwrap();
    let mut s = st
        .start(&Example3, &vec1(1.0), &vec1(-0.1), &load(0.0))
        .unwrap();
    let mut err = 0.0f64;
    for n in 1..=(20.0 / h).round() as u64 {
        let t = n as f64 * h;
        st.try_step(&Example3, &mut s, &load(t)).unwrap();
        err = err.max((s.u()[0].as_f64() - example3_exact(t).0).abs());
    }
    err
}

// ------------------------------------------------------------------ the page

fn main() {
    println!("# Verification: measured numbers\n");
    println!(
        "Produced by `cargo run --release --example verification` (a few seconds; deterministic, no timing).\n\
         Generated page: `python3 scripts/check_docs.py --write` writes it, and the test command\n\
         (`bash scripts/test.sh`) regenerates it and fails when a number differs by more than one\n\
         unit in its last printed digit. The tests in `tests/` assert bounds on the same\n\
         quantities, derived from the method's O(h²) error or from rounding; this page says what\n\
         the numbers are today. References: exact solutions and independent implementations in\n\
         `tests/support/` (closed forms, modal superposition, an independent Newmark loop)."
    );

    // Linear: paper examples.
    println!("\n## The linear kernel on the paper's examples\n");
    println!("| check | f64 | f32 |");
    println!("|---|---|---|");
    for h in [0.01, 0.001] {
        let s: f64 = 5.0 * h;
        let t_theory = 2.0 * core::f64::consts::PI * h / (2.0 * (s / 2.0).atan());
        let t_num = example1_period(h);
        let pe = t_num / (2.0 * core::f64::consts::PI / 5.0) - 1.0;
        println!(
            "| Example 1 (u'' + 25u = 0), h = {h}: period against theory 2πh / (2 atan(ωh/2)), relative; period elongation (paper: {}) | {}; PE {} | |",
            if h == 0.01 { "0.02 %" } else { "0.00021 %" },
            e((t_num - t_theory).abs() / t_theory, 1),
            e(pe, 3)
        );
    }
    println!(
        "| Example 1: amplitude √(u² + (v/ω)²) − 1 after 10⁵ steps (h = 0.01) | {} | |",
        e(example1_amplitude(), 1)
    );
    let mut ex2_32 = Vec::new();
    for (case, p) in [("(i)", 0.0), ("(ii)", 10.0)] {
        let errs: Vec<f64> = [1u32, 2, 4, 8]
            .iter()
            .map(|&k| example2_error(&example2_run::<f64>(p, k), p, k))
            .collect();
        let orders: Vec<String> = (1..4)
            .map(|i| format!("{:.3}", order(errs[i - 1], 2.0, errs[i], 1.0)))
            .collect();
        let u32s = example2_run::<f32>(p, 1);
        let u64s = example2_run::<f64>(p, 1);
        let e32 = example2_error(&u32s, p, 1);
        let d = u32s
            .iter()
            .zip(&u64s)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        ex2_32.push((case, e32, d));
        println!(
            "| Example 2 {case}: max error over [0, 25] at h = 1/500; observed order for h = 1/500 … 1/4000 | {}; order {} | {}; max \\|u₃₂ − u₆₄\\| {} |",
            e(errs[0], 3),
            orders.join(", "),
            e(e32, 3),
            e(d, 3)
        );
    }
    let (e4_1, umax) = example4_error::<f64>(0.01);
    let (e4_2, _) = example4_error::<f64>(0.005);
    let (e4_3, _) = example4_error::<f64>(0.0025);
    let (e4_32, _) = example4_error::<f32>(0.01);
    println!(
        "| Example 4 (3-DOF, Caughey damping) against exact modal superposition, max error on [0, 5] at h = 0.01, 0.005, 0.0025 (max \\|u\\| = {umax:.1}) | {}, {}, {}; order {:.3}, {:.3} | {} at h = 0.01 |",
        e(e4_1, 2),
        e(e4_2, 2),
        e(e4_3, 2),
        order(e4_1, 0.01, e4_2, 0.005),
        order(e4_2, 0.005, e4_3, 0.0025),
        e(e4_32, 2)
    );
    let (m, k, xi, u0, v0, p) = example4();
    let ex = ModalExact::new(&m, &k, xi, &u0, &v0, &p);
    println!(
        "| Example 4: Caughey C against the paper's printed C (4 decimals), max abs difference | {} | |",
        e((ex.c - example4_printed_c()).abs().max(), 1)
    );

    println!(
        "\nAbout Example 2: the paper's Fig. 7 reads an error of about 2e-5 at h = 1/500. The AEM step is\n\
         exactly the trapezoidal rule, whose error on this run is the figure above; the crate\n\
         reproduces the rule, not the figure."
    );

    // Linear: cross-checks.
    println!("\n## Independent implementations (random systems, 10⁴ steps, h = 0.01)\n");
    println!(
        "Relative difference max |x − y| / max |y| over u, v and a (the worst of the three).\n"
    );
    println!("| N | fast form vs A-form | fast form vs independent Newmark-AA | f32 vs f64 |");
    println!("|---|---|---|---|");
    macro_rules! cc {
        ($n:literal) => {{
            let (a, b, c) = cross_check::<$n>();
            println!("| {} | {} | {} | {} |", $n, e(a, 1), e(b, 1), e(c, 1));
        }};
    }
    cc!(1);
    cc!(2);
    cc!(3);
    cc!(6);
    cc!(12);

    // Few inputs.
    println!("\n## `LinearInput` against `Linear` fed `p = B w`\n");
    println!(
        "The benchmark 5-storey building under El Centro 1940 NS (h = 0.02 s, 3994 steps), max ‖u_input − u_linear‖∞ / max ‖u_linear‖∞:\n"
    );
    println!("| f64 | f32 |");
    println!("|---|---|");
    println!(
        "| {} | {} |",
        e(input_vs_linear::<f64>(), 1),
        e(input_vs_linear::<f32>(), 1)
    );

    // Firmware host twins.
    println!("\n## Firmware host twins\n");
    println!(
        "The firmware examples check every sample against bounds measured here on the host (their runs are bit-identical to the target's; `scripts/qemu.sh` compares the bits).\n"
    );
    println!("| run | f64 | f32 |");
    println!("|---|---|---|");
    let u64s = example2_run::<f64>(10.0, 1);
    let (_, e32_2, d2) = ex2_32[1];
    println!(
        "| `qemu_timer`: Example 2 (ii), h = 1/500, 12 500 steps, max \\|u − u_exact\\| | {} | {} (rounding part {}) |",
        e(example2_error(&u64s, 10.0, 1), 3),
        e(e32_2, 3),
        e(d2, 3)
    );
    let (d64, bad64) = duffing::<f64>(0.01);
    let (d64_2, _) = duffing::<f64>(0.005);
    let (d32, bad32) = duffing::<f32>(0.01);
    println!(
        "| `qemu_nonlinear`: Duffing (Example 5), h = 0.01, 2000 steps, exactly 2 Newton iterations, max \\|u − u_exact\\| | {}; order {:.3} (h/2) | {} |",
        e(d64, 3),
        order(d64, 0.01, d64_2, 0.005),
        e(d32, 3)
    );
    assert_eq!(
        bad64 + bad32,
        0,
        "every Duffing step converges in exactly 2 iterations"
    );

    // Nonlinear and time-varying.
    println!("\n## Nonlinear and time-varying steppers\n");
    println!("| example | f64: max error at h, h/2; order | f32: max error at h |");
    println!("|---|---|---|");
    let (e3_1, e3_2) = (example3_error::<f64>(0.01), example3_error::<f64>(0.005));
    println!(
        "| Example 3, `(1+t²)u'' + t u' + e^{{1/(1+t)}} u = p`, `Varying`, h = 0.01, T = 20 | {}, {}; {:.3} | {} |",
        e(e3_1, 2),
        e(e3_2, 2),
        order(e3_1, 0.01, e3_2, 0.005),
        e(example3_error::<f32>(0.01), 2)
    );
    let (d64_4, _) = duffing::<f64>(0.0025);
    println!(
        "| Example 5, Duffing `u'' + 0.2u' + u + u³ = p`, `Nonlinear` (2 Newton iterations), h = 0.01, T = 20 | {}, {}; {:.3} | {} |",
        e(d64, 2),
        e(d64_2, 2),
        order(d64_2, 0.005, d64_4, 0.0025),
        e(d32, 2)
    );

    // Extremes.
    println!("\n## Extremes\n");
    println!("| run | f64 | f32 |");
    println!("|---|---|---|");
    let (e64, p64) = ten_million::<f64>();
    let (e32, p32) = ten_million::<f32>();
    println!(
        "| 10⁷ undamped steps (ω = 2π, h = 0.01): energy drift max \\|E/E0 − 1\\| | {} | {} |",
        e(e64, 1),
        e(e32, 1)
    );
    println!(
        "| 10⁷ undamped steps: phase, max \\|u − cos(nφ)\\| against the scheme's own phase φ per step | {} | {} |",
        e(p64, 1),
        e(p32, 1)
    );
    println!(
        "| h = 1e-9 s, 10⁶ steps (ω = 2π): \\|u − cos(ωt)\\| at the end (f32: u stagnates, h·v is below half an ulp of u) | {} | {} |",
        e(tiny_step::<f64>(), 1),
        e(tiny_step::<f32>(), 1)
    );
}
