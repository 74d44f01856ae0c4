//! Host benchmarks of the yielding shear building step (issue 34): the const-generic
//! `Nonlinear<f64, N>` stepping `ShearBuilding<f64, Bilinear<f64>, N>` and the run-time-sized
//! `DynNonlinear<f64>` stepping `DynShearBuilding<f64, Bilinear<f64>>`, at N = 5 and 20.
//!
//! The building: floors of 1e5 kg, storeys of 2e8 N/m tapering to half at the top, yielding
//! at 3e5 N times the storeys above (5 % hardening), Rayleigh damping `0.3 M + 0.002 K`
//! (the banded `L D Lᵀ` path), h = 0.005 s, Newton to 1e-10 (at most 20 iterations). Each
//! iteration runs [`STEPS`] steps from rest under `5 sin 9t + 2 sin 23t` m/s² (it yields);
//! criterion's throughput is steps a second. The two paths are asserted bit-identical
//! first.
//!
//! Run: `cargo bench -p xtask --bench building` (about a minute on an idle machine);
//! filter with e.g. `-- building/N=5`.

use std::hint::black_box;

use aemstep::hysteresis::{Bilinear, HistoryModel, ShearBuilding};
use aemstep::nalgebra::{DMatrix, SVector};
use aemstep::{DynNonlinear, DynShearBuilding, NewtonSettings, Nonlinear};
use criterion::{Criterion, Throughput};

/// Steps a timed run.
const STEPS: usize = 2000;
const H: f64 = 0.005;

fn ground(s: usize) -> f64 {
    let t = s as f64 * H;
    5.0 * (9.0 * t).sin() + 2.0 * (23.0 * t).sin()
}

/// Masses (kg), laws and damping (N·s/m) of the `n`-storey building.
fn building(n: usize) -> (Vec<f64>, Vec<Bilinear<f64>>, DMatrix<f64>) {
    let ks: Vec<f64> = (0..n)
        .map(|i| 2e8 * (1.0 - 0.5 * i as f64 / n as f64))
        .collect();
    let laws = (0..n)
        .map(|i| Bilinear::new(ks[i], 3e5 * (n - i) as f64, 0.05).expect("law"))
        .collect();
    let masses = vec![1e5; n];
    let k = |i: usize| if i < n { ks[i] } else { 0.0 };
    let c = DMatrix::from_fn(n, n, |r, s| {
        let kk = match r.abs_diff(s) {
            0 => k(r) + k(r + 1),
            1 => -k(r.max(s)),
            _ => 0.0,
        };
        0.002 * kk + if r == s { 0.3 * masses[r] } else { 0.0 }
    });
    (masses, laws, c)
}

/// The const-generic run: the last floor displacement.
fn run_const<const N: usize>(
    b: &ShearBuilding<f64, Bilinear<f64>, N>,
    stepper: &Nonlinear<f64, N>,
) -> f64 {
    let zero = SVector::<f64, N>::zeros();
    let (mut s, mut history) = stepper
        .start_with_history(b, &zero, &zero, &b.ground_load(0.0), &b.initial_history())
        .expect("start");
    for step in 1..=STEPS {
        stepper
            .try_step_with_history(b, &mut s, &mut history, &b.ground_load(ground(step)))
            .expect("step");
    }
    s.u()[N - 1]
}

/// The run-time-sized run: the last floor displacement.
fn run_dyn(b: &DynShearBuilding<f64, Bilinear<f64>>, stepper: &DynNonlinear<f64>) -> f64 {
    let n = b.size();
    let (zero, mut p) = (vec![0.0; n], vec![0.0; n]);
    let mut s = stepper.start(b, &zero, &zero, &zero).expect("start");
    for step in 1..=STEPS {
        b.ground_load(ground(step), &mut p);
        stepper.try_step(b, &mut s, &p).expect("step");
    }
    s.u()[n - 1]
}

fn bench<const N: usize>(c: &mut Criterion) {
    let (masses, laws, damping) = building(N);
    let rows: [[f64; N]; N] = core::array::from_fn(|i| core::array::from_fn(|j| damping[(i, j)]));
    let fixed = ShearBuilding::new(
        core::array::from_fn(|i| masses[i]),
        core::array::from_fn(|i| laws[i]),
        &rows,
    )
    .expect("building");
    let dynamic = DynShearBuilding::new(&masses, laws, &damping).expect("building");
    let settings = NewtonSettings::default();
    let stepper = Nonlinear::<f64, N>::new(H, settings).expect("stepper");
    let dyn_stepper = DynNonlinear::<f64>::new(H, settings).expect("stepper");
    assert_eq!(
        run_const(&fixed, &stepper).to_bits(),
        run_dyn(&dynamic, &dyn_stepper).to_bits()
    );
    let mut g = c.benchmark_group(format!("building/N={N}"));
    g.throughput(Throughput::Elements(STEPS as u64));
    g.bench_function("const", |b| {
        b.iter(|| black_box(run_const(&fixed, &stepper)))
    });
    g.bench_function("runtime", |b| {
        b.iter(|| black_box(run_dyn(&dynamic, &dyn_stepper)))
    });
    g.finish();
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    bench::<5>(&mut c);
    bench::<20>(&mut c);
    c.final_summary();
}
