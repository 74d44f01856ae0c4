//! Host benchmarks of the lane-batched stepper (`aemstep::lanes`, issue 35) on the yielding
//! 5-storey building of `scenes/ida/building.rs` (bilinear storeys yielding at 3 MN, h =
//! 0.005 s, Newton up to 50 iterations to 1e-12):
//!
//! - `lanes/step`: the first [`STEPS`] steps (20 s) of El Centro ×2 (×2·(1 + l/100) in lane
//!   `l`), by one `Nonlinear` analysis and by `LaneStepper<f64, 5, L>` at L = 2, 4, 8;
//!   criterion's throughput is analysis-steps a second.
//! - `IDA880`: 44 records × 20 intensities (0.1, 0.2, …, 2.0) = 880 whole analyses (15 975
//!   steps each), peak storey drift, no collapse limit: `ida::stripes` with one analysis a
//!   run on 1 and 2 threads, and `ida::batched` (`Plan::Stripes`) with `LaneStepper<f64, 5, 4>` (and
//!   8) on 1 and 2 threads; the curves are asserted bit-identical. The records: El Centro
//!   NS, reversed in time, negated, and 41 synthetic records of its length (white noise of
//!   a SplitMix64 generator, seeds 1 … 41, Box–Muller, a 3-point moving average, under the
//!   envelope t²·exp(−t/τ), τ = 2 … 8 s cycling), each scaled to El Centro's peak: the
//!   recipe of `scripts/bench_python.py` with another generator.
//!
//! After criterion, each case is timed again ([`REPEATS`] times, fastest kept: on a shared
//! machine the fastest run is the least disturbed) and printed as `LANES …` lines with the
//! load averages before and after; the step cases also by their time on a CPU (the thread's
//! scheduler statistics: what they cost when other processes hold the cores). A last line
//! states what bounds a lane step: the Newton iterations a step of the 880 single analyses
//! take, on average and as the slowest lane of each batch of 4 or 8 (the lane step's count).
//!
//! Run: `cargo bench -p xtask --bench lanes` (about three minutes on an idle machine);
//! `-- --skip-criterion` times only the summary lines.

#[path = "../../scenes/modal/elcentro.rs"]
mod elcentro;
#[path = "../../scenes/ida/building.rs"]
mod ida;

use std::hint::black_box;
use std::time::Instant;

use aemstep::hysteresis::HistoryModel;
use aemstep::ida::{Batching, Collapse, OnFailure, Plan, batched, stripes};
use aemstep::lanes::LaneStepper;
use criterion::{Criterion, Throughput};

/// Steps of the throughput case: 20 s of the record, through its strong motion.
const STEPS: u64 = 4000;
/// Timed repetitions of the summary (fastest kept).
const REPEATS: usize = 3;
/// Repetitions of a step case timed on the CPU (mean kept).
const CPU_REPEATS: usize = 40;

fn loadavg() -> String {
    std::fs::read_to_string("/proc/loadavg").map_or_else(|_| "?".into(), |s| s.trim().into())
}

/// The 44 records (see the module docs), m/s² at 0.02 s.
fn records() -> Vec<Vec<f64>> {
    let el = elcentro::AG_F64;
    let pga = el.iter().fold(0.0f64, |m, a| m.max(a.abs()));
    let mut out = vec![
        el.to_vec(),
        el.iter().rev().copied().collect(),
        el.iter().map(|a| -a).collect(),
    ];
    for seed in 1..=41u64 {
        let mut x = seed;
        let mut uniform = || {
            // SplitMix64, to (0, 1].
            x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = x;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64 + f64::EPSILON
        };
        let w: Vec<f64> = (0..el.len())
            .map(|_| {
                let (u1, u2) = (uniform(), uniform());
                (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
            })
            .collect();
        let tau = 2.0 + (seed % 7) as f64;
        let x: Vec<f64> = (0..el.len())
            .map(|i| {
                let lo = if i > 0 { w[i - 1] } else { 0.0 };
                let hi = w.get(i + 1).copied().unwrap_or(0.0);
                let t = i as f64 * 0.02;
                (lo + w[i] + hi) / 3.0 * (t / tau).powi(2) * (-t / tau).exp()
            })
            .collect();
        let peak = x.iter().fold(0.0f64, |m, a| m.max(a.abs()));
        out.push(x.iter().map(|a| a * pga / peak).collect());
    }
    out
}

/// This thread's time on a CPU so far (s; `/proc/thread-self/schedstat`, NaN elsewhere):
/// on a machine shared with other processes, what a single-threaded case costs without the
/// time it waited for a core.
fn thread_cpu() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(f64::NAN, |ns| ns * 1e-9)
}

/// The mean on-CPU time ([`thread_cpu`]) of [`CPU_REPEATS`] runs of `f` on this thread (s;
/// many runs: the kernel brings the figure up to date at its ticks, a few milliseconds).
fn mean_cpu(mut f: impl FnMut()) -> f64 {
    let t = thread_cpu();
    for _ in 0..CPU_REPEATS {
        f();
    }
    (thread_cpu() - t) / CPU_REPEATS as f64
}

/// The fastest of [`REPEATS`] runs of `f` (s).
fn fastest(mut f: impl FnMut()) -> f64 {
    (0..REPEATS)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let skip_criterion = std::env::args().any(|a| a == "--skip-criterion");
    // `cargo test` runs this target without `--bench`, unoptimized: a smoke run.
    let smoke = !std::env::args().any(|a| a == "--bench");
    println!("LOADAVG before {}", loadavg());
    let building = ida::building().expect("building");
    let single = ida::stepper().expect("stepper");
    let settings = single.settings();
    let l2 = LaneStepper::<f64, 5, 2>::new(ida::H, settings).expect("lanes");
    let l4 = LaneStepper::<f64, 5, 4>::new(ida::H, settings).expect("lanes");
    let l8 = LaneStepper::<f64, 5, 8>::new(ida::H, settings).expect("lanes");
    let rec: &[f64] = &elcentro::AG_F64;
    let steps = if smoke { 200 } else { STEPS };
    let jobs: Vec<(&[f64], f64, u64)> = (0..8)
        .map(|l| (rec, ida::SCALE * (1.0 + l as f64 / 100.0), steps))
        .collect();
    let one = || {
        black_box(ida::peak_drift(&building, &single, rec, ida::SCALE, steps).expect("ok"));
    };
    // The lanes are the single analyses, bit for bit.
    let want: Vec<u64> = jobs
        .iter()
        .map(|j| {
            let d = ida::peak_drift(&building, &single, j.0, j.1, j.2).expect("ok");
            d.to_bits()
        })
        .collect();
    let got: Vec<u64> = ida::peak_drifts(&building, &l4, &jobs)
        .into_iter()
        .map(|d| d.expect("ok").to_bits())
        .collect();
    assert_eq!(got, want);

    if !skip_criterion && !smoke {
        let mut c = Criterion::default().configure_from_args();
        let mut g = c.benchmark_group("lanes/step");
        g.throughput(Throughput::Elements(steps));
        g.bench_function("single", |b| b.iter(one));
        g.throughput(Throughput::Elements(2 * steps));
        g.bench_function("L2", |b| {
            b.iter(|| black_box(ida::peak_drifts(&building, &l2, &jobs[..2])))
        });
        g.throughput(Throughput::Elements(4 * steps));
        g.bench_function("L4", |b| {
            b.iter(|| black_box(ida::peak_drifts(&building, &l4, &jobs[..4])))
        });
        g.throughput(Throughput::Elements(8 * steps));
        g.bench_function("L8", |b| {
            b.iter(|| black_box(ida::peak_drifts(&building, &l8, &jobs)))
        });
        g.finish();
        c.final_summary();
    }

    // Per analysis-step, fastest of the repetitions.
    let per = |t: f64, lanes: u64| t / (lanes * steps) as f64 * 1e9;
    let t1 = fastest(one);
    let t2 = fastest(|| {
        black_box(ida::peak_drifts(&building, &l2, &jobs[..2]));
    });
    let t4 = fastest(|| {
        black_box(ida::peak_drifts(&building, &l4, &jobs[..4]));
    });
    let t8 = fastest(|| {
        black_box(ida::peak_drifts(&building, &l8, &jobs));
    });
    println!(
        "LANES step ns/analysis-step: single {:.1} L2 {:.1} L4 {:.1} L8 {:.1}",
        per(t1, 1),
        per(t2, 2),
        per(t4, 4),
        per(t8, 8)
    );

    let c1 = mean_cpu(one);
    let c2 = mean_cpu(|| {
        black_box(ida::peak_drifts(&building, &l2, &jobs[..2]));
    });
    let c4 = mean_cpu(|| {
        black_box(ida::peak_drifts(&building, &l4, &jobs[..4]));
    });
    let c8 = mean_cpu(|| {
        black_box(ida::peak_drifts(&building, &l8, &jobs));
    });
    println!(
        "LANES step on-CPU (mean) ns/analysis-step: single {:.1} L2 {:.1} L4 {:.1} L8 {:.1}",
        per(c1, 1),
        per(c2, 2),
        per(c4, 4),
        per(c8, 8)
    );

    // The 880-analysis IDA.
    let mut recs = records();
    let mut scales: Vec<f64> = (1..=20).map(|k| k as f64 / 10.0).collect();
    if smoke {
        recs.truncate(3);
        scales.truncate(2);
        for r in &mut recs {
            r.truncate(60);
        }
    }
    let collapse = Collapse {
        edp: f64::INFINITY,
        on_failure: OnFailure::Collapse,
    };
    let plan = Plan::Stripes {
        intensities: &scales,
        collapse,
    };
    let run_one =
        |r: &Vec<f64>, im: f64| ida::peak_drift(&building, &single, r, im, ida::steps(r.len()));
    let serial = |threads| stripes(&recs, &scales, &collapse, threads, run_one, None).expect("ida");
    let batched4 = |jobs: &[(&Vec<f64>, f64)]| {
        let jobs: Vec<(&[f64], f64, u64)> = jobs
            .iter()
            .map(|&(r, im)| (r.as_slice(), im, ida::steps(r.len())))
            .collect();
        ida::peak_drifts(&building, &l4, &jobs)
    };
    let batched8 = |jobs: &[(&Vec<f64>, f64)]| {
        let jobs: Vec<(&[f64], f64, u64)> = jobs
            .iter()
            .map(|&(r, im)| (r.as_slice(), im, ida::steps(r.len())))
            .collect();
        ida::peak_drifts(&building, &l8, &jobs)
    };
    let lanes4 = |threads| {
        batched(
            &recs,
            &plan,
            &Batching {
                width: 4,
                threads,
                progress: None,
            },
            batched4,
        )
        .expect("ida")
    };
    let lanes8 = |threads| {
        batched(
            &recs,
            &plan,
            &Batching {
                width: 8,
                threads,
                progress: None,
            },
            batched8,
        )
        .expect("ida")
    };
    let want = format!("{:?}", serial(1));
    assert_eq!(format!("{:?}", lanes4(2)), want);
    assert_eq!(format!("{:?}", lanes8(1)), want);
    let n = recs.len() * scales.len();
    let s1 = fastest(|| drop(black_box(serial(1))));
    let s2 = fastest(|| drop(black_box(serial(2))));
    let a1 = fastest(|| drop(black_box(lanes4(1))));
    let a2 = fastest(|| drop(black_box(lanes4(2))));
    let b1 = fastest(|| drop(black_box(lanes8(1))));
    let b2 = fastest(|| drop(black_box(lanes8(2))));
    println!(
        "LANES IDA{n} s: single t1 {s1:.3} t2 {s2:.3}; lanes4 t1 {a1:.3} t2 {a2:.3}; lanes8 t1 {b1:.3} t2 {b2:.3}"
    );
    // What bounds a lane step: the Newton iterations of the slowest lane. Each run's
    // iteration count at every step (single analyses), then per step the largest of each
    // batch of `L` runs as `ida::batched` groups them (a stripe's records side by side).
    let iterations: Vec<Vec<u32>> = scales
        .iter()
        .flat_map(|&im| recs.iter().map(move |r| (r, im)))
        .map(|(r, im)| newton_iterations(&building, &single, r, im))
        .collect();
    let total: u64 = iterations.iter().flatten().map(|&k| u64::from(k)).sum();
    let steps_all: usize = iterations.iter().map(Vec::len).sum();
    let lane_max = |l: usize| {
        let mut sum = 0u64;
        let mut lane_steps = 0usize;
        for batch in iterations.chunks(l) {
            let longest = batch.iter().map(Vec::len).max().unwrap_or(0);
            for n in 0..longest {
                sum += u64::from(
                    batch
                        .iter()
                        .filter_map(|k| k.get(n))
                        .max()
                        .copied()
                        .unwrap_or(0),
                );
            }
            lane_steps += longest * l;
        }
        sum as f64 / lane_steps as f64 * l as f64
    };
    println!(
        "LANES iterations a step: mean {:.3}; slowest of the batch L4 {:.3} L8 {:.3}",
        total as f64 / steps_all as f64,
        lane_max(4),
        lane_max(8)
    );
    println!("LOADAVG after {}", loadavg());
}

/// The Newton iterations of every step of one whole run (as `ida::peak_drift` steps it).
fn newton_iterations(
    building: &ida::Building,
    single: &aemstep::Nonlinear<f64, { ida::N }>,
    r: &[f64],
    im: f64,
) -> Vec<u32> {
    let zero = aemstep::nalgebra::SVector::<f64, { ida::N }>::zeros();
    let virgin = building.initial_history();
    let p0 = building.ground_load(ida::ground(r, im, 0));
    let Ok((mut s, mut h)) = single.start_with_history(building, &zero, &zero, &p0, &virgin) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for n in 1..=ida::steps(r.len()) {
        let p = building.ground_load(ida::ground(r, im, n));
        match single.try_step_with_history(building, &mut s, &mut h, &p) {
            Ok(report) => out.push(report.iterations),
            Err(_) => break,
        }
    }
    out
}
