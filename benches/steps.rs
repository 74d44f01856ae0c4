//! Host benchmarks: time per step against N for every form and scheme, f32 and f64, and
//! the paper's Example 10 timing table (spec §8) re-run at the same N, t_tot and h.
//!
//! Run: `cargo bench --bench steps` (a few minutes), then
//! `python3 scripts/bench_table.py` turns `target/criterion/**/estimates.json` into the
//! README tables. Filter with e.g. `cargo bench --bench steps -- step/f64`.
//!
//! Systems are random, symmetric, fully populated and positive definite (M, K), with
//! C = 0.01 M + 0.001 K, built by a fixed-seed generator, so every run times the same
//! matrices. Steppers live on the heap (`Box`), and the whole run happens on a thread
//! with a 1 GiB stack, because building the N = 100 operators uses `f64` temporaries of
//! 80 KB (Linear) to 1.3 MB (Exact) each on the stack.

use std::hint::black_box;
use std::time::Duration;

use aemstep::{Exact, GeneralizedAlpha, Linear, Newmark, Real, State, Stepper};
use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, BenchmarkId, Criterion};
use nalgebra::{SMatrix, SVector};

/// Fixed-seed xorshift generator in [−1, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// Random symmetric fully populated positive-definite M, K and C = 0.01 M + 0.001 K.
fn system<const N: usize>() -> Box<(SMatrix<f64, N, N>, SMatrix<f64, N, N>, SMatrix<f64, N, N>)> {
    let mut r = Rng(0x9E37_79B9_7F4A_7C15 ^ N as u64);
    let mut spd = |diag: f64| {
        let mut a = SMatrix::<f64, N, N>::zeros();
        for i in 0..N {
            for j in 0..=i {
                let x = r.next();
                a[(i, j)] = x;
                a[(j, i)] = x;
            }
            // Diagonal dominance: positive definite.
            a[(i, i)] = diag + N as f64;
        }
        a
    };
    let m = spd(10.0);
    let k = spd(1000.0) * 10.0;
    let c = m * 0.01 + k * 0.001;
    Box::new((m, c, k))
}

fn bench_stepper<
    T: Real,
    S: Stepper<T, N, Input = SVector<T, N>, State = State<T, N>>,
    const N: usize,
>(
    g: &mut BenchmarkGroup<'_, WallTime>,
    name: &str,
    sys: &S,
) {
    let p = SVector::<T, N>::from_element(T::from_f64_rounded(1.0));
    let z = SVector::<T, N>::zeros();
    let mut s = sys.start(&z, &z, &p).expect("start");
    g.bench_with_input(BenchmarkId::new(name, N), &N, |b, _| {
        b.iter(|| sys.step(black_box(&mut s), black_box(&p)))
    });
}

fn per_step<T: Real, const N: usize>(c: &mut Criterion, ty: &str) {
    let sys = system::<N>();
    let (m, cc, k) = (&sys.0, &sys.1, &sys.2);
    let h = 0.01;
    let mut g = c.benchmark_group(format!("step/{ty}"));
    g.warm_up_time(Duration::from_millis(200))
        .measurement_time(Duration::from_millis(700))
        .sample_size(20);
    let lin = Box::new(Linear::<T, N>::new(m, cc, k, h).expect("linear"));
    bench_stepper(&mut g, "aem", &*lin);
    let af = Box::new(lin.a_form());
    bench_stepper(&mut g, "aem-aform", &*af);
    drop(af);
    let nm = Box::new(Newmark::<T, N>::linear_acceleration(m, cc, k, h).expect("newmark"));
    bench_stepper(&mut g, "newmark", &*nm);
    drop(nm);
    let ga = Box::new(GeneralizedAlpha::<T, N>::new(m, cc, k, h, 0.8).expect("gen-alpha"));
    bench_stepper(&mut g, "gen-alpha", &*ga);
    drop(ga);
    let ex = Box::new(Exact::<T, N>::new(m, cc, k, h).expect("exact"));
    bench_stepper(&mut g, "exact", &*ex);
    g.finish();
}

fn per_step_all(c: &mut Criterion, full: bool) {
    macro_rules! sizes {
        ($($n:literal)*) => {$(
            per_step::<f64, $n>(c, "f64");
            per_step::<f32, $n>(c, "f32");
        )*};
    }
    if full {
        sizes!(1 2 3 4 5 6 7 8 9 10 11 12 25 50 100);
    } else {
        sizes!(1 3 5);
    }
}

/// Paper Example 10 (spec §8): whole runs of t_tot / h steps, h = 0.01, f64.
fn example10_n<const N: usize>(c: &mut Criterion) {
    let sys = system::<N>();
    let (m, cc, k) = (&sys.0, &sys.1, &sys.2);
    let h = 0.01;
    let mut g = c.benchmark_group(format!("example10/N={N}"));
    g.warm_up_time(Duration::from_millis(100))
        .measurement_time(Duration::from_millis(1500))
        .sample_size(10);
    g.bench_function("build aem", |b| {
        b.iter(|| Box::new(Linear::<f64, _>::new(black_box(m), cc, k, h).expect("linear")))
    });
    g.bench_function("build aem-aform", |b| {
        b.iter(|| {
            Box::new(
                Linear::<f64, _>::new(black_box(m), cc, k, h)
                    .expect("linear")
                    .a_form(),
            )
        })
    });
    let lin = Box::new(Linear::<f64, _>::new(m, cc, k, h).expect("linear"));
    let af = Box::new(lin.a_form());
    let p = SVector::<f64, N>::from_element(1.0);
    let z = SVector::<f64, N>::zeros();
    for t_tot in [20u32, 100, 200] {
        let steps = (t_tot as f64 / h).round() as usize;
        g.bench_with_input(BenchmarkId::new("run aem", t_tot), &steps, |b, &n| {
            b.iter(|| {
                let mut s = lin.start(&z, &z, &p).expect("start");
                for _ in 0..n {
                    lin.step(&mut s, black_box(&p));
                }
                s
            })
        });
        g.bench_with_input(BenchmarkId::new("run aem-aform", t_tot), &steps, |b, &n| {
            b.iter(|| {
                let mut s = af.start(&z, &z, &p).expect("start");
                for _ in 0..n {
                    af.step(&mut s, black_box(&p));
                }
                s
            })
        });
    }
    g.finish();
}

fn example10(c: &mut Criterion) {
    example10_n::<25>(c);
    example10_n::<50>(c);
    example10_n::<100>(c);
}

fn main() {
    std::thread::Builder::new()
        .stack_size(1 << 30)
        .spawn(|| {
            // `cargo test --all-targets` runs this binary without `--bench` (criterion's
            // test mode: every benchmark once): check a few small sizes only, since the
            // N = 100 operators take minutes to build in a debug build.
            let full = std::env::args().any(|a| a == "--bench");
            let mut c = Criterion::default().configure_from_args();
            per_step_all(&mut c, full);
            if full {
                example10(&mut c);
            }
            c.final_summary();
        })
        .expect("spawn")
        .join()
        .expect("bench thread");
}
