//! Firmware: every other stepper of the crate on a Cortex-M4F (QEMU `mps2-an386`), in `f32`
//! and in `f64` (software floating point on this core), checked against the exact solution.
//!
//! Paper Example 2 (ii), `u'' + 2ξω u' + ω² u = 10 H(t)`, ω = 2, ξ = 0.07, u0 = 1, v0 = 20,
//! h = 0.002 s, 2500 steps (t ≤ 5 s), through: the literal `AForm`, `Newmark` (linear
//! acceleration, central difference), `GeneralizedAlpha` (ρ∞ = 0.8, HHT α = −0.1),
//! `Exact`, `Varying` (constant coefficients given by a closure) and `LinearInput`
//! (`p = B w`, `B = 1`, `w = 10`). This proves each compiles `no_std` for the target and
//! runs there, and checks what it computes:
//!
//! - `f64`: max |u − exact| ≤ 1e-3 for the second-order schemes (their O(h²) error here is
//!   ~1e-5…1e-4) and ≤ 1e-9 for `Exact` (exact for this load; rounding only);
//! - `f32`: max |u − exact| ≤ the same scheme's `f64` error + the f32 rounding allowance
//!   8·ε₃₂·max|u|·√n = 8 · 1.19e-7 · 10 · 50 ≈ 4.8e-4: about 8 rounded operations feed `u`
//!   each step (fewer for the AEM, more through `Exact`'s recovered acceleration), and
//!   independent roundings accumulate like a random walk. Measured: 3e-5…9e-5 (`Exact`,
//!   whose f64 error is 2e-13, shows the rounding alone: 9.4e-5). A wrong operator or a
//!   scheme bug shows as an error of 1e-2 or more.
//!
//! Run: `cargo run -p aemstep-firmware --release --target thumbv7em-none-eabihf --example qemu_schemes`
//! (or `bash scripts/qemu.sh`). Broken variant that must fail: `--cfg aemstep_broken="inject-nan"`
//! (a NaN load sample at step 1000, refused by `try_step`).
#![no_std]
#![no_main]

#[macro_use]
#[path = "fw/mod.rs"]
mod fw;

use aemstep::{
    AForm, Coefficients, Error, Exact, GeneralizedAlpha, Linear, LinearInput, Newmark, Real, State,
    Stepper, Varying,
};
use core::hint::black_box;
use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use nalgebra::{SMatrix, SVector, matrix, vector};

const H: f64 = 0.002;
const STEPS: u32 = 2500;
const W: f64 = 2.0;
const XI: f64 = 0.07;
const P: f64 = 10.0;
/// f32 rounding allowance 8·ε₃₂·max|u|·√n, max|u| ≈ 10 (see the module docs).
fn f32_allowance() -> f64 {
    8.0 * f32::EPSILON as f64 * 10.0 * libm::sqrt(STEPS as f64)
}

/// The closed form of Example 2 (ii) (libm).
fn exact(t: f64) -> f64 {
    let wd = W * libm::sqrt(1.0 - XI * XI);
    let us = P / (W * W);
    let a = 1.0 - us;
    let b = (20.0 + XI * W * a) / wd;
    us + libm::exp(-XI * W * t) * (a * libm::cos(wd * t) + b * libm::sin(wd * t))
}

/// The load sample at step `n` (a step load).
fn load<T: Real>(n: u32) -> SVector<T, 1> {
    if cfg!(aemstep_broken = "inject-nan") && n == 1000 {
        return vector![T::from_f64_rounded(f64::NAN)];
    }
    vector![T::from_f64_rounded(P)]
}

fn mat(x: f64) -> SMatrix<f64, 1, 1> {
    matrix![x]
}

fn c1() -> f64 {
    2.0 * XI * W
}

/// Max |u − exact| of a [`Stepper`], driven with both load samples of each step.
fn run<T: Real>(
    name: &str,
    sys: &dyn Stepper<T, 1, Input = SVector<T, 1>, State = State<T, 1>>,
) -> f64 {
    let one = |x: f64| vector![T::from_f64_rounded(x)];
    let mut s = match sys.start(&one(1.0), &one(20.0), &load(0)) {
        Ok(s) => s,
        Err(e) => fail!("{}: start: {}", name, e.as_str()),
    };
    let mut err: f64 = 0.0;
    for n in 1..=STEPS {
        if let Err(e) = sys.try_step_with_previous_input(&mut s, &load(n - 1), &load(n)) {
            fail!("{}: step {} refused: {}", name, n, e.as_str());
        }
        err = err.max(libm::fabs(s.u()[0].as_f64() - exact(n as f64 * H)));
    }
    err
}

/// `Varying` with constant coefficients (a closure of t).
fn run_varying<T: Real>() -> f64 {
    let name = "Varying";
    let coeffs = |_t: T| Coefficients {
        mass: mat(1.0).map(T::from_f64_rounded),
        damping: mat(c1()).map(T::from_f64_rounded),
        stiffness: mat(W * W).map(T::from_f64_rounded),
    };
    let sys = match Varying::<T, 1>::new(H) {
        Ok(s) => s,
        Err(e) => fail!("{}: new: {}", name, e.as_str()),
    };
    let one = |x: f64| vector![T::from_f64_rounded(x)];
    let mut s = match sys.start(&coeffs, &one(1.0), &one(20.0), &load(0)) {
        Ok(s) => s,
        Err(e) => fail!("{}: start: {}", name, e.as_str()),
    };
    let mut err: f64 = 0.0;
    for n in 1..=STEPS {
        if let Err(e) = sys.try_step(&coeffs, &mut s, &load(n)) {
            fail!("{}: step {} refused: {}", name, n, e.as_str());
        }
        err = err.max(libm::fabs(s.u()[0].as_f64() - exact(n as f64 * H)));
    }
    err
}

/// `LinearInput` with `B = 1`, `w = P`.
fn run_input<T: Real>() -> f64 {
    let name = "LinearInput";
    let sys = match LinearInput::<T, 1, 1>::new(&mat(1.0), &mat(c1()), &mat(W * W), &mat(1.0), H) {
        Ok(s) => s,
        Err(e) => fail!("{}: new: {}", name, e.as_str()),
    };
    let one = |x: f64| vector![T::from_f64_rounded(x)];
    let mut s = match sys.start(&one(1.0), &one(20.0), &load(0)) {
        Ok(s) => s,
        Err(e) => fail!("{}: start: {}", name, e.as_str()),
    };
    let mut err: f64 = 0.0;
    for n in 1..=STEPS {
        if let Err(e) = sys.try_step(&mut s, &load(n)) {
            fail!("{}: step {} refused: {}", name, n, e.as_str());
        }
        err = err.max(libm::fabs(s.u()[0].as_f64() - exact(n as f64 * H)));
    }
    err
}

/// Every scheme in type `T`: (name, max error), in a fixed order.
fn all<T: Real>() -> [(&'static str, f64); 8] {
    let (m, c, k, h) = (mat(1.0), mat(c1()), mat(W * W), H);
    let ok = |r: Result<f64, aemstep::Error>, name: &str| match r {
        Ok(e) => e,
        Err(e) => fail!("{}: new: {}", name, e.as_str()),
    };
    let aform: Result<AForm<T, 1>, _> = Linear::<T, 1>::new(&m, &c, &k, h).map(|l| l.a_form());
    [
        ("AForm", ok(aform.map(|s| run("AForm", &s)), "AForm")),
        (
            "Newmark lin. acc.",
            ok(
                Newmark::<T, 1>::linear_acceleration(&m, &c, &k, h).map(|s| run("Newmark LA", &s)),
                "Newmark LA",
            ),
        ),
        (
            "central difference",
            ok(
                Newmark::<T, 1>::central_difference(&m, &c, &k, h).map(|s| run("CD", &s)),
                "CD",
            ),
        ),
        (
            "gen-alpha 0.8",
            ok(
                GeneralizedAlpha::<T, 1>::new(&m, &c, &k, h, 0.8).map(|s| run("gen-alpha", &s)),
                "gen-alpha",
            ),
        ),
        (
            "HHT -0.1",
            ok(
                GeneralizedAlpha::<T, 1>::hht(&m, &c, &k, h, -0.1).map(|s| run("HHT", &s)),
                "HHT",
            ),
        ),
        (
            "Exact",
            ok(
                Exact::<T, 1>::new(&m, &c, &k, h).map(|s| run("Exact", &s)),
                "Exact",
            ),
        ),
        ("Varying", run_varying::<T>()),
        ("LinearInput", run_input::<T>()),
    ]
}

/// `f32` constant coefficients for the out-of-line `Varying` step.
fn coefficients_f32(_t: f32) -> Coefficients<f32, 1> {
    Coefficients {
        mass: mat(1.0).cast(),
        damping: mat(c1()).cast(),
        stiffness: mat(W * W).cast(),
    }
}

// Out-of-line `f32` steps, one per stepper: `scripts/qemu.sh` walks the ELF's call graph
// from every `*_step` symbol and fails if any reaches a panic.
type S1 = State<f32, 1>;
type V1 = SVector<f32, 1>;
#[unsafe(no_mangle)]
#[inline(never)]
fn qemu_schemes_aform_step(sys: &AForm<f32, 1>, s: &mut S1, p: &V1) {
    sys.step(s, p)
}
#[unsafe(no_mangle)]
#[inline(never)]
fn qemu_schemes_newmark_step(sys: &Newmark<f32, 1>, s: &mut S1, p: &V1) {
    sys.step(s, p)
}
#[unsafe(no_mangle)]
#[inline(never)]
fn qemu_schemes_alpha_step(sys: &GeneralizedAlpha<f32, 1>, s: &mut S1, q: &V1, p: &V1) {
    sys.step_with_previous_input(s, q, p)
}
#[unsafe(no_mangle)]
#[inline(never)]
fn qemu_schemes_exact_step(sys: &Exact<f32, 1>, s: &mut S1, p: &V1) {
    sys.step(s, p)
}
#[unsafe(no_mangle)]
#[inline(never)]
fn qemu_schemes_varying_step(sys: &Varying<f32, 1>, s: &mut S1, p: &V1) -> Result<(), Error> {
    sys.try_step(&coefficients_f32, s, p)
}
#[unsafe(no_mangle)]
#[inline(never)]
fn qemu_schemes_input_step(sys: &LinearInput<f32, 1, 1>, s: &mut S1, w: &V1) {
    sys.step(s, w)
}

/// One call of each out-of-line step (keeps them linked; results unused).
fn probe_steps() -> Result<(), Error> {
    let (m, c, k, h) = (mat(1.0), mat(c1()), mat(W * W), H);
    let p = vector![P as f32];
    let lin = Linear::<f32, 1>::new(&m, &c, &k, h)?;
    let mut s = lin.start(&vector![1.0], &vector![20.0], &p)?;
    qemu_schemes_aform_step(black_box(&lin.a_form()), &mut s, &p);
    qemu_schemes_newmark_step(
        black_box(&Newmark::<f32, 1>::linear_acceleration(&m, &c, &k, h)?),
        &mut s,
        &p,
    );
    qemu_schemes_alpha_step(
        black_box(&GeneralizedAlpha::<f32, 1>::new(&m, &c, &k, h, 0.8)?),
        &mut s,
        &p,
        &p,
    );
    qemu_schemes_exact_step(black_box(&Exact::<f32, 1>::new(&m, &c, &k, h)?), &mut s, &p);
    qemu_schemes_varying_step(black_box(&Varying::<f32, 1>::new(h)?), &mut s, &p)?;
    qemu_schemes_input_step(
        black_box(&LinearInput::<f32, 1, 1>::new(&m, &c, &k, &mat(1.0), h)?),
        &mut s,
        &p,
    );
    black_box(s);
    Ok(())
}

#[entry]
fn main() -> ! {
    if let Err(e) = probe_steps() {
        fail!("probe: {}", e.as_str());
    }
    let e64 = all::<f64>();
    let e32 = all::<f32>();
    for ((name, a), (_, b)) in e64.iter().zip(e32.iter()) {
        let bound64 = if *name == "Exact" { 1e-9 } else { 1e-3 };
        hprintln!(
            "qemu_schemes: {:<20} max |u - exact|: f64 {:e}, f32 {:e}",
            name,
            a,
            b
        );
        if a.is_nan() || *a > bound64 {
            fail!("{}: f64 error {:e} > {:e}", name, a, bound64);
        }
        if b.is_nan() || *b > a + f32_allowance() {
            fail!(
                "{}: f32 error {:e} > f64 error + {:e}",
                name,
                b,
                f32_allowance()
            );
        }
    }
    fw::report_stack("qemu_schemes");
    hprintln!("qemu_schemes: all 8 steppers ran in f32 and f64 on the target within their bounds");
    fw::exit_success()
}
