//! The README table of "Modelling only what the scene requires": the benchmark 5-storey
//! building under El Centro 1940 NS, modal models with R = 1…5 modes against the full
//! model, and what each costs a step on this host.
//!
//! ```text
//! cargo run --release -p xtask --bin modal_building
//! ```
//!
//! Errors are against the full model `Linear<f64, 5>` at the same step h = 0.02 s (the
//! record's): that is what dropping modes costs. The full model's own time-step error is
//! shown beside it, against `Linear<f64, 5>` at h/16 (ground motion linearly interpolated
//! between samples), so truncation and time-step error can be told apart.
//! Timing: a loop over the record, best of 7 runs of 100 passes, `black_box` on the input
//! and the output; ns per step, including reading the one output (roof drift).

#[path = "../../../scenes/modal/elcentro.rs"]
mod elcentro;

use std::hint::black_box;
use std::time::Instant;

use aemstep::modal::lowest_modes;
use aemstep::models::{base_excitation, storey_drifts};
use aemstep::{Damping, Linear, LinearInput, Modal, Real, Stepper, models};
use nalgebra::{SMatrix, SVector};

const H: f64 = 0.02;

/// Roof and inter-storey drift histories (`[u5, d1..d5]` per sample) of a run.
type History = Vec<[f64; 6]>;

fn record(u: &SVector<f64, 5>) -> [f64; 6] {
    let mut r = [u[4], u[0], 0.0, 0.0, 0.0, 0.0];
    for i in 1..5 {
        r[i + 1] = u[i] - u[i - 1];
    }
    r
}

type M5 = SMatrix<f64, 5, 5>;

/// The benchmark building: `M, C, K` and the influence vector `B = −M ι`.
fn building() -> (M5, M5, M5, SVector<f64, 5>) {
    let (m, c, k) = models::five_storey_building();
    let sm = |a: [[f64; 5]; 5]| M5::from_fn(|i, j| a[i][j]);
    let b = SVector::from_fn(|i, _| base_excitation(&m)[i][0]);
    (sm(m), sm(c), sm(k), b)
}

fn full_history(ag: &[f64], sub: usize) -> History {
    let (m, c, k, b) = building();
    let sys = Linear::<f64, _>::new(&m, &c, &k, H / sub as f64).unwrap();
    let z = SVector::zeros();
    let mut s = sys.start(&z, &z, &(b * ag[0])).unwrap();
    let mut out = vec![record(s.u())];
    for n in 1..ag.len() {
        for j in 1..=sub {
            let f = j as f64 / sub as f64;
            let a = ag[n - 1] * (1.0 - f) + ag[n] * f;
            sys.step(&mut s, &(b * a));
        }
        out.push(record(s.u()));
    }
    out
}

fn modal_history<const R: usize>(ag: &[f64]) -> History {
    let (m, c, k) = models::five_storey_building();
    let y = storey_drifts::<5>();
    let sys = Modal::<f64, 5, R, 1, 5>::from_rows_with_modes_f64(
        m,
        k,
        Damping::Matrix(c),
        base_excitation(&m),
        y,
        lowest_modes(),
        H,
    )
    .unwrap();
    let mut s = sys.start_at_rest(&SVector::from([ag[0]])).unwrap();
    let mut out = vec![];
    let rec = |s: &aemstep::ModalState<f64, R>| {
        let d = sys.output(s);
        [d.iter().sum(), d[0], d[1], d[2], d[3], d[4]]
    };
    out.push(rec(&s));
    for &a in &ag[1..] {
        sys.step(&mut s, &SVector::from([a]));
        out.push(rec(&s));
    }
    out
}

/// (peak roof, error of the peak, max history error, peak drift, error of the peak drift,
/// max drift history error), all absolute (m).
fn compare(x: &History, reference: &History) -> [f64; 6] {
    let peak = |h: &History, i: usize| h.iter().fold(0.0f64, |m, r| m.max(r[i].abs()));
    let hist = |i: usize| {
        x.iter()
            .zip(reference)
            .fold(0.0f64, |m, (a, b)| m.max((a[i] - b[i]).abs()))
    };
    let (mut pd, mut epd, mut ehd) = (0.0f64, 0.0f64, 0.0f64);
    for i in 1..6 {
        pd = pd.max(peak(x, i));
        epd = epd.max((peak(x, i) - peak(reference, i)).abs());
        ehd = ehd.max(hist(i));
    }
    [
        peak(x, 0),
        (peak(x, 0) - peak(reference, 0)).abs(),
        hist(0),
        pd,
        epd,
        ehd,
    ]
}

/// Best-of-7 ns per call of `f` over 100 passes of the record.
fn time_per_step(ag: &[f64], mut f: impl FnMut(f64) -> f64) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..7 {
        let t = Instant::now();
        let mut acc = 0.0;
        for _ in 0..100 {
            for &a in ag {
                acc += f(black_box(a));
            }
        }
        black_box(acc);
        best = best.min(t.elapsed().as_nanos() as f64 / (100 * ag.len()) as f64);
    }
    best
}

fn modal_ns<T: Real, const R: usize>(ag: &[f64]) -> f64 {
    let (m, _, k, b) = building();
    let c = Damping::Matrix(models::five_storey_building().1);
    let roof = SMatrix::<f64, 1, 5>::new(0.0, 0.0, 0.0, 0.0, 1.0);
    let sys = Modal::<T, 5, R>::new(&m, &k, &c, &b, &roof, H).unwrap();
    let mut s = sys.start_at_rest(&SVector::from([T::zero()])).unwrap();
    time_per_step(ag, |a| {
        sys.step(&mut s, &SVector::from([T::from_f64_rounded(a)]));
        sys.output(&s)[0].as_f64()
    })
}

fn linear_ns<T: Real>(ag: &[f64]) -> f64 {
    let (m, c, k, b) = building();
    let b = b.map(T::from_f64_rounded);
    let sys = Linear::<T, 5>::new(&m, &c, &k, H).unwrap();
    let z = SVector::zeros();
    let mut s = sys.start(&z, &z, &z).unwrap();
    time_per_step(ag, |a| {
        sys.step(&mut s, &(b * T::from_f64_rounded(a)));
        s.u()[4].as_f64()
    })
}

fn input_ns<T: Real>(ag: &[f64]) -> f64 {
    let (m, c, k, b) = building();
    let sys = LinearInput::<T, 5, 1>::new(&m, &c, &k, &b, H).unwrap();
    let z = SVector::zeros();
    let mut s = sys.start(&z, &z, &SVector::from([T::zero()])).unwrap();
    time_per_step(ag, |a| {
        sys.step(&mut s, &SVector::from([T::from_f64_rounded(a)]));
        s.u()[4].as_f64()
    })
}

fn main() {
    let ag = elcentro::AG_F64;
    let full = full_history(&ag, 1);
    let fine = full_history(&ag, 16);
    let histories = [
        modal_history::<1>(&ag),
        modal_history::<2>(&ag),
        modal_history::<3>(&ag),
        modal_history::<4>(&ag),
        modal_history::<5>(&ag),
    ];
    let ns: [(f64, f64); 5] = [
        (modal_ns::<f64, 1>(&ag), modal_ns::<f32, 1>(&ag)),
        (modal_ns::<f64, 2>(&ag), modal_ns::<f32, 2>(&ag)),
        (modal_ns::<f64, 3>(&ag), modal_ns::<f32, 3>(&ag)),
        (modal_ns::<f64, 4>(&ag), modal_ns::<f32, 4>(&ag)),
        (modal_ns::<f64, 5>(&ag), modal_ns::<f32, 5>(&ag)),
    ];
    let f = compare(&full, &fine);
    // The four error cells of a row (`compare`'s errors), each in mm and in % of the full
    // model's peak: roof errors of the peak roof drift, drift errors of the peak drift.
    let errors = |e: &[f64; 6]| {
        [(e[1], f[0]), (e[2], f[0]), (e[4], f[3]), (e[5], f[3])]
            .map(|(x, of)| format!("{:.3} mm ({:.2} %)", 1e3 * x, 100.0 * x / of))
            .join(" | ")
    };
    println!(
        "5-storey building, El Centro 1940 NS ({} samples, h = {H} s); full model: peak roof drift {:.2} mm, peak inter-storey drift {:.2} mm",
        ag.len(),
        1e3 * f[0],
        1e3 * f[3]
    );
    println!();
    println!(
        "| model | roof: error of peak | roof: max history error | storey drift: error of peak | storey drift: max history error | multiply-adds/step | host ns/step f64 | host ns/step f32 |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for (r, h) in histories.iter().enumerate() {
        let e = compare(h, &full);
        let rr = r + 1;
        println!(
            "| `Modal`, R = {rr} | {} | {} | {:.1} | {:.1} |",
            errors(&e),
            // R·I + 7R for the modes, O·R for one output
            rr + 7 * rr + rr,
            ns[r].0,
            ns[r].1
        );
    }
    println!(
        "| `LinearInput<5, 1>` (full, B = −Mι) | 0 | 0 | 0 | 0 | {} | {:.1} | {:.1} |",
        2 * 25 + 5 + 5 * 5,
        input_ns::<f64>(&ag),
        input_ns::<f32>(&ag)
    );
    println!(
        "| `Linear<5>` (full, p = B a_g) | 0 | 0 | 0 | 0 | {} | {:.1} | {:.1} |",
        3 * 25 + 5 * 5 + 5,
        linear_ns::<f64>(&ag),
        linear_ns::<f32>(&ag)
    );
    println!(
        "| `Linear<5>` at h = 0.02 against h/16 (time-step error) | {} | | | |",
        errors(&f)
    );
    // Truncation bound for the firmware check (R = 2, roof, f64 on the host).
    let e2 = compare(&histories[1], &full);
    println!();
    println!(
        "R = 2 roof drift: max |modal − full| = {:.6e} m over the record (firmware check bound)",
        e2[2]
    );
}
