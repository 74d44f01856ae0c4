//! Host benchmarks of the response-spectrum bank (`aemstep::spectrum`): one 100-period,
//! 5 %-damped spectrum of the El Centro record (3 995 samples at 0.02 s) by each scheme and
//! sub-step rule, `f64` and `f32`, on log-spaced (0.01–10 s) and linearly spaced periods
//! (those `sdof.spectrum` takes on its threaded C path), and the batch throughput (records
//! a second) on 1 thread and on every core.
//!
//! After criterion, each spectrum is also timed as 200 single calls, and the fastest is
//! printed as `FASTEST <id> <seconds>`: the estimator `scripts/bench_spectrum.py` applies
//! to `sdof.spectrum` too (on a shared machine the fastest call is the least disturbed).
//!
//! Run: `cargo bench -p xtask --bench spectrum` (about a minute);
//! `python3 scripts/bench_spectrum.py` runs it beside `sdof.spectrum` and writes
//! `docs/spectrum.md`.

#[path = "../../scenes/modal/elcentro.rs"]
mod elcentro;

use std::hint::black_box;
use std::time::Duration;

use aemstep::spectrum::{Bank, Scheme, Substeps, batch};
use criterion::Criterion;

const P: usize = 100;
const DT: f64 = 0.02;

fn log_periods() -> [f64; P] {
    core::array::from_fn(|i| 0.01 * 1000f64.powf(i as f64 / (P - 1) as f64))
}

fn lin_periods() -> [f64; P] {
    core::array::from_fn(|i| 0.01 + (10.0 - 0.01) * i as f64 / (P - 1) as f64)
}

fn main() {
    let mut c = Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .sample_size(20)
        .configure_from_args();
    let (rec, rec32) = (elcentro::AG_F64, elcentro::AG_F32);
    let mut fastest: Vec<(String, f64)> = Vec::new();
    let mut single = |id: String, f: &mut dyn FnMut()| {
        let mut best = f64::INFINITY;
        for _ in 0..200 {
            let t = std::time::Instant::now();
            f();
            best = best.min(t.elapsed().as_secs_f64());
        }
        fastest.push((id, best));
    };
    let mut g = c.benchmark_group("spectrum");
    for (pname, per) in [("log", log_periods()), ("lin", lin_periods())] {
        for (sname, scheme, sub) in [
            ("exact-auto", Scheme::Exact, Substeps::AUTO),
            ("exact-1", Scheme::Exact, Substeps::Fixed(1)),
            ("aem-1", Scheme::Aem, Substeps::Fixed(1)),
        ] {
            let b = Bank::<f64, P>::with(per, [0.05; P], DT, scheme, sub).expect("bank");
            let run64 = || {
                let mut r = b.at_rest();
                for &a in black_box(&rec) {
                    b.step(&mut r, a);
                }
                black_box(r.sd()[0])
            };
            g.bench_function(format!("f64/{pname}/{sname}"), |bch| bch.iter(run64));
            single(format!("spectrum/f64/{pname}/{sname}"), &mut || {
                run64();
            });
            let b = Bank::<f32, P>::with(per, [0.05; P], DT, scheme, sub).expect("bank");
            let run32 = || {
                let mut r = b.at_rest();
                for &a in black_box(&rec32) {
                    b.step(&mut r, a);
                }
                black_box(r.sd()[0])
            };
            g.bench_function(format!("f32/{pname}/{sname}"), |bch| bch.iter(run32));
            single(format!("spectrum/f32/{pname}/{sname}"), &mut || {
                run32();
            });
        }
    }
    g.finish();

    // Batch: 32 records (El Centro scaled), default bank, f64, with free vibration.
    const RECORDS: usize = 32;
    let recs: Vec<Vec<f64>> = (0..RECORDS)
        .map(|i| {
            rec.iter()
                .map(|a| a * (0.5 + i as f64 / RECORDS as f64))
                .collect()
        })
        .collect();
    let slices: Vec<&[f64]> = recs.iter().map(|r| r.as_slice()).collect();
    let b = Bank::<f64, P>::new(log_periods(), [0.05; P], DT).expect("bank");
    let mut g = c.benchmark_group("batch32");
    g.sample_size(10);
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    for threads in [1, cores] {
        g.bench_function(format!("threads{threads}"), |bch| {
            bch.iter(|| black_box(batch::spectra(&b, black_box(&slices), 0, threads)))
        });
    }
    g.finish();
    c.final_summary();
    for (id, t) in fastest {
        println!("FASTEST {id} {t:e}");
    }
}
