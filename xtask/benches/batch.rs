//! Host benchmarks of `aemstep::batch` (the work-stealing pool, feature `std`): the scaling
//! of two batches from 1 to 2 threads.
//!
//! - `spectra200`: 200 El Centro spectra (the record ×(0.5 + i/200)), `spectrum::batch::spectra`
//!   on the spectrum benchmark's default bank (`Bank<f64, 100>`, 100 log-spaced periods
//!   0.01–10 s, 5 %), no free vibration.
//! - `ida100`: 100 nonlinear time-history analyses of the yielding 5-storey building
//!   (`scenes/ida/building.rs`: bilinear storeys yielding at 3 MN, El Centro ×0.02 … ×2.0
//!   at h = 0.005 s, 15 975 steps, Newton up to 50 iterations to 1e-12), each returning its
//!   peak storey drift, through `batch::map`.
//!
//! After criterion, each batch is timed again on 1 and on 2 threads, alternately, and the
//! fastest of the repetitions is kept (on a shared machine the fastest run is the least
//! disturbed); printed as `SCALING <batch> t1 <s> t2 <s> ratio <t1/t2>`, with the load
//! averages before and after.
//!
//! Run: `cargo bench -p xtask --bench batch` (about three minutes) on an otherwise idle
//! machine; `-- --skip-criterion` times only the scaling. `-- --ida-serial` times only the
//! 100 analyses on 1 thread (fastest of the repetitions): two such processes at once
//! show what the machine's second core gives without any pool.

#[path = "../../scenes/modal/elcentro.rs"]
mod elcentro;
#[path = "../../scenes/ida/building.rs"]
mod ida;

use std::hint::black_box;
use std::time::{Duration, Instant};

use aemstep::batch;
use aemstep::spectrum::{self, Bank};
use criterion::Criterion;

const P: usize = 100;
const DT: f64 = 0.02;
const RECORDS: usize = 200;
const REPEATS: usize = 15;

fn log_periods() -> [f64; P] {
    core::array::from_fn(|i| 0.01 * 1000f64.powf(i as f64 / (P - 1) as f64))
}

fn loadavg() -> String {
    std::fs::read_to_string("/proc/loadavg").map_or_else(|_| "?".into(), |s| s.trim().into())
}

fn main() {
    let skip_criterion = std::env::args().any(|a| a == "--skip-criterion");
    // `cargo test` runs this target without `--bench`, unoptimized: a smoke run of a few
    // short jobs (the batch equals the serial loop), no timing.
    let smoke = !std::env::args().any(|a| a == "--bench");
    let records = if smoke { 4 } else { RECORDS };
    println!("LOADAVG before {}", loadavg());
    let rec = elcentro::AG_F64;

    // (a) 200 spectra
    let recs: Vec<Vec<f64>> = (0..records)
        .map(|i| {
            rec.iter()
                .map(|a| a * (0.5 + i as f64 / records as f64))
                .collect()
        })
        .collect();
    let slices: Vec<&[f64]> = recs.iter().map(|r| r.as_slice()).collect();
    let bank = Bank::<f64, P>::new(log_periods(), [0.05; P], DT).expect("bank");
    let spectra = |threads: usize| {
        black_box(spectrum::batch::spectra(
            &bank,
            black_box(&slices),
            0,
            threads,
        ));
    };

    // (b) 100 yielding analyses
    let building = ida::building().expect("building");
    let stepper = ida::stepper().expect("stepper");
    let mut scales = ida::scales();
    let mut steps = ida::steps(rec.len());
    if smoke {
        scales.truncate(2);
        steps = 400;
    }
    let analyses = |threads: usize| -> Vec<f64> {
        batch::map(black_box(&scales), threads, |&s| {
            ida::peak_drift(&building, &stepper, &rec, s, steps).expect("converged")
        })
    };
    // The batch is the serial loop, bit for bit; and it yields.
    let peaks = analyses(1);
    assert_eq!(
        analyses(2).iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
        peaks.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
    );
    let yield_drift = ida::FY / aemstep::models::FIVE_STOREY_STIFFNESS;
    println!(
        "IDA: peak drift {:.4} m at ×{}, {:.4} m at ×{} (yield drift {yield_drift} m); {} of {} runs yield",
        peaks[0],
        scales[0],
        peaks[scales.len() - 1],
        scales[scales.len() - 1],
        peaks.iter().filter(|&&d| d > yield_drift).count(),
        scales.len()
    );

    if smoke {
        spectra(1);
        spectra(2);
        println!("smoke run (cargo test); `cargo bench -p xtask --bench batch` measures");
        return;
    }

    if std::env::args().any(|a| a == "--ida-serial") {
        let mut best = f64::INFINITY;
        for _ in 0..REPEATS {
            let t = Instant::now();
            black_box(analyses(1));
            best = best.min(t.elapsed().as_secs_f64());
        }
        println!("IDA-SERIAL t1 {best:.4} s (fastest of {REPEATS})");
        return;
    }

    if !skip_criterion {
        let mut c = Criterion::default()
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(5))
            .sample_size(10)
            .configure_from_args();
        let mut g = c.benchmark_group("spectra200");
        for threads in [1, 2] {
            g.bench_function(format!("threads{threads}"), |b| b.iter(|| spectra(threads)));
        }
        g.finish();
        let mut g = c.benchmark_group("ida100");
        for threads in [1, 2] {
            g.bench_function(format!("threads{threads}"), |b| {
                b.iter(|| black_box(analyses(threads)))
            });
        }
        g.finish();
        c.final_summary();
    }

    // Scaling: fastest of REPEATS, 1 and 2 threads alternately.
    let time = |f: &dyn Fn()| {
        let t = Instant::now();
        f();
        t.elapsed().as_secs_f64()
    };
    let report = |name: &str, f: &dyn Fn(usize)| {
        let (mut t1, mut t2) = (f64::INFINITY, f64::INFINITY);
        for _ in 0..REPEATS {
            t1 = t1.min(time(&|| f(1)));
            t2 = t2.min(time(&|| f(2)));
        }
        println!(
            "SCALING {name} t1 {t1:.4} s t2 {t2:.4} s ratio {:.3} (fastest of {REPEATS})",
            t1 / t2
        );
    };
    report("spectra200", &spectra);
    report("ida100", &|threads| {
        black_box(analyses(threads));
    });
    println!("LOADAVG after {}", loadavg());
}
