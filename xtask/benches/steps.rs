//! Host benchmarks: time per step against N for every form and scheme, f32 and f64, and
//! the paper's Example 10 timing table (spec §8) re-run at the same N, t_tot and h.
//!
//! Run: `cargo bench -p xtask --bench steps` (a few minutes), then
//! `python3 scripts/bench_table.py` turns `target/criterion/**/estimates.json` into the
//! README tables. Filter with e.g. `cargo bench -p xtask --bench steps -- step/f64`.
//!
//! Beside every stepper, the same run times two references (see `docs/performance.md`):
//! - `nalgebra-dmatrix`: a plain Newmark average-acceleration loop on `nalgebra::DMatrix`
//!   (heap matrices, in place, three `gemv`s a step), the comparator a user would write;
//! - `floor-read`: one pass reading as many bytes as the step's operators (`3N²` values),
//!   the memory floor of a step on this machine at that size.
//!
//! Throughput is multiply-adds (criterion prints it as `Gelem/s` = multiply-adds per ns);
//! `scripts/bench_table.py` also prints the share of the floor.
//!
//! Systems are random, symmetric, fully populated and positive definite (M, K), with
//! C = 0.01 M + 0.001 K, built by a fixed-seed generator, so every run times the same
//! matrices. Steppers live on the heap (`Box`), and the whole run happens on a thread
//! with a 1 GiB stack, because building the N = 100 operators uses `f64` temporaries of
//! 80 KB (Linear) to 1.3 MB (Exact) each on the stack.

use std::hint::black_box;
use std::time::Duration;

use aemstep::{
    CompensatedLinear, DynLinear, Exact, GeneralizedAlpha, Linear, Newmark, Real, Stepper,
};
use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, BenchmarkId, Criterion, Throughput};
use nalgebra::{DMatrix, DVector, SMatrix, SVector};

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

fn bench_stepper<T: Real, S: Stepper<T, N, Input = SVector<T, N>>, const N: usize>(
    g: &mut BenchmarkGroup<'_, WallTime>,
    name: &str,
    sys: &S,
    madds: usize,
) {
    let p = SVector::<T, N>::from_element(T::from_f64_rounded(1.0));
    let z = SVector::<T, N>::zeros();
    let mut s = sys.start(&z, &z, &p).expect("start");
    g.throughput(Throughput::Elements(madds as u64));
    g.bench_with_input(BenchmarkId::new(name, N), &N, |b, _| {
        b.iter(|| sys.step(black_box(&mut s), black_box(&p)))
    });
}

/// The same AEM stepper sized at run time (`DynLinear`, heap operators, the same product):
/// whether the compiled sizes of the Python package still pay for themselves.
fn bench_dyn<T: Real, const N: usize>(
    g: &mut BenchmarkGroup<'_, WallTime>,
    m: &SMatrix<f64, N, N>,
    c: &SMatrix<f64, N, N>,
    k: &SMatrix<f64, N, N>,
    h: f64,
) {
    let dm = |a: &SMatrix<f64, N, N>| DMatrix::from_fn(N, N, |i, j| a[(i, j)]);
    let sys = DynLinear::<T>::new(&dm(m), &dm(c), &dm(k), h).expect("dyn linear");
    let (p, z) = (vec![T::from_f64_rounded(1.0); N], vec![T::zero(); N]);
    let mut s = sys.start(&z, &z, &p).expect("start");
    g.throughput(Throughput::Elements((3 * N * N + 7 * N) as u64));
    g.bench_with_input(BenchmarkId::new("aem-dyn", N), &N, |b, _| {
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
    bench_stepper(&mut g, "aem", &*lin, 3 * N * N + 7 * N);
    bench_dyn::<T, N>(&mut g, m, cc, k, h);
    let af = Box::new(lin.a_form());
    bench_stepper(&mut g, "aem-aform", &*af, 12 * N * N);
    drop(af);
    let nm = Box::new(Newmark::<T, N>::linear_acceleration(m, cc, k, h).expect("newmark"));
    bench_stepper(&mut g, "newmark", &*nm, 3 * N * N + 7 * N);
    drop(nm);
    let ga = Box::new(GeneralizedAlpha::<T, N>::new(m, cc, k, h, 0.8).expect("gen-alpha"));
    bench_stepper(&mut g, "gen-alpha", &*ga, 4 * N * N + 10 * N);
    drop(ga);
    let ex = Box::new(Exact::<T, N>::new(m, cc, k, h).expect("exact"));
    bench_stepper(&mut g, "exact", &*ex, 11 * N * N);
    bench_references::<T, N>(&mut g, &sys, 0.01);
    g.finish();
}

/// The plain nalgebra Newmark average-acceleration loop a user would write: `DMatrix`
/// operators `G = (M + (h/2) C + (h²/4) K)⁻¹`, `GC`, `GK` (computed in `f64`, rounded
/// once to `T`, as the crate does) and three `gemv`s a step, everything in place.
struct DMatrixNewmark<T: Real> {
    g: DMatrix<T>,
    gc: DMatrix<T>,
    gk: DMatrix<T>,
    h: T,
    half_h: T,
    quarter_h2: T,
    u: DVector<T>,
    v: DVector<T>,
    a: DVector<T>,
    vh: DVector<T>,
    uh: DVector<T>,
}

impl<T: Real> DMatrixNewmark<T> {
    fn new(m: &DMatrix<f64>, c: &DMatrix<f64>, k: &DMatrix<f64>, h: f64) -> Self {
        let g = (m + c * (h / 2.0) + k * (h * h / 4.0))
            .try_inverse()
            .expect("M_eff regular");
        let (gc, gk) = (&g * c, &g * k);
        let r = |a: &DMatrix<f64>| a.map(T::from_f64_rounded);
        let n = m.nrows();
        Self {
            g: r(&g),
            gc: r(&gc),
            gk: r(&gk),
            h: T::from_f64_rounded(h),
            half_h: T::from_f64_rounded(h / 2.0),
            quarter_h2: T::from_f64_rounded(h * h / 4.0),
            u: DVector::zeros(n),
            v: DVector::zeros(n),
            a: DVector::zeros(n),
            vh: DVector::zeros(n),
            uh: DVector::zeros(n),
        }
    }

    /// `v̂ = v + (h/2) a`, `û = u + h v + (h²/4) a`, `a = G p − GC v̂ − GK û`,
    /// `v = v̂ + (h/2) a`, `u = û + (h²/4) a`: `3N²` multiply-adds + `7N`.
    fn step(&mut self, p: &DVector<T>) {
        let one = T::one();
        self.vh.copy_from(&self.v);
        self.vh.axpy(self.half_h, &self.a, one);
        self.uh.copy_from(&self.u);
        self.uh.axpy(self.h, &self.v, one);
        self.uh.axpy(self.quarter_h2, &self.a, one);
        self.a.gemv(one, &self.g, p, T::zero());
        self.a.gemv(-one, &self.gc, &self.vh, one);
        self.a.gemv(-one, &self.gk, &self.uh, one);
        self.v.copy_from(&self.vh);
        self.v.axpy(self.half_h, &self.a, one);
        self.u.copy_from(&self.uh);
        self.u.axpy(self.quarter_h2, &self.a, one);
    }
}

/// The two references of a size, in the same group as the steppers: the nalgebra
/// `DMatrix` loop, and one read of the step's operator bytes (`3N²` values of `T`).
fn bench_references<T: Real, const N: usize>(
    g: &mut BenchmarkGroup<'_, WallTime>,
    sys: &(SMatrix<f64, N, N>, SMatrix<f64, N, N>, SMatrix<f64, N, N>),
    h: f64,
) {
    let d = |a: &SMatrix<f64, N, N>| DMatrix::from_fn(N, N, |i, j| a[(i, j)]);
    let mut nm = DMatrixNewmark::<T>::new(&d(&sys.0), &d(&sys.1), &d(&sys.2), h);
    let p = DVector::<T>::from_element(N, T::from_f64_rounded(1.0));
    g.throughput(Throughput::Elements((3 * N * N + 7 * N) as u64));
    g.bench_with_input(BenchmarkId::new("nalgebra-dmatrix", N), &N, |b, _| {
        b.iter(|| nm.step(black_box(&p)))
    });
    // The floor: stream the operator bytes once (integer sum: the compiler may reorder
    // and vectorize it freely, so it runs at the cache's bandwidth).
    let bytes = 3 * N * N * core::mem::size_of::<T>();
    let words = vec![1u64; bytes.div_ceil(8)];
    g.throughput(Throughput::Bytes(bytes as u64));
    let avx2 = has_avx2();
    g.bench_with_input(BenchmarkId::new("floor-read", N), &N, |b, _| {
        b.iter(|| {
            if avx2 {
                // SAFETY: `has_avx2()`: the CPU and OS run AVX2 instructions.
                unsafe { read_all_avx(black_box(&words)) }
            } else {
                read_all(black_box(&words))
            }
        })
    });
}

/// Whether the CPU (and OS) run the x86 feature `$f` (a string literal); never in the
/// SSE2-only control build (`--cfg aemstep_control="sse2-only"`), which keeps its floors on
/// SSE2 too.
macro_rules! runs {
    ($f:tt) => {{
        #[cfg(all(target_arch = "x86_64", not(aemstep_control = "sse2-only")))]
        let yes = std::is_x86_feature_detected!($f);
        #[cfg(not(all(target_arch = "x86_64", not(aemstep_control = "sse2-only"))))]
        let yes = false;
        yes
    }};
}

/// Whether the CPU (and OS) run AVX: then the step's column-blocked product runs on AVX
/// registers (`src/linalg/avx.rs`), and so do the floors it is compared with.
fn has_avx() -> bool {
    runs!("avx")
}

/// Whether the CPU (and OS) run AVX2 (256-bit integer adds, for the read floor's sum).
fn has_avx2() -> bool {
    runs!("avx2")
}

/// One pass over `words` (a wrapping integer sum, which the compiler vectorizes freely).
#[inline(always)]
fn read_all(words: &[u64]) -> u64 {
    words.iter().fold(0u64, |s, &w| s.wrapping_add(w))
}

/// [`read_all`] compiled for AVX (two 32-byte loads a cycle where SSE2 has 16-byte ones).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn read_all_avx(words: &[u64]) -> u64 {
    read_all(words)
}

/// No AVX off x86-64.
#[cfg(not(target_arch = "x86_64"))]
unsafe fn read_all_avx(words: &[u64]) -> u64 {
    read_all(words)
}

/// The compute floor: 12 independent chains of packed multiply-then-add (no fusing, as
/// the steppers), `LANES·256` multiply-adds a call; the rate the cores' multiply and add
/// pipes sustain. On a CPU with AVX it runs on 256-bit registers (`LANES` twice as many:
/// 12 packed chains either way), as the column-blocked step does (`src/linalg/avx.rs`).
fn floor_compute<T: Real, const LANES: usize>(c: &mut Criterion, ty: &str, avx: bool) {
    const ROUNDS: usize = 256;
    let mut g = c.benchmark_group("floor");
    g.warm_up_time(Duration::from_millis(200))
        .measurement_time(Duration::from_millis(700))
        .sample_size(20)
        .throughput(Throughput::Elements((LANES * ROUNDS) as u64));
    let (m, k) = (T::from_f64_rounded(0.999), T::from_f64_rounded(1e-3));
    g.bench_function(format!("compute-{ty}"), |b| {
        b.iter(|| {
            if avx {
                // SAFETY: `avx` is true only where `is_x86_feature_detected!("avx")` is
                // (see `main`): the CPU and OS run AVX instructions.
                unsafe { chains_avx::<T, LANES, ROUNDS>(m, k) }
            } else {
                chains::<T, LANES, ROUNDS>(m, k)
            }
        })
    });
    g.finish();
}

/// `LANES` chains of `ROUNDS` multiply-then-adds.
#[inline(always)]
fn chains<T: Real, const LANES: usize, const ROUNDS: usize>(m: T, k: T) -> [T; LANES] {
    let mut acc = [T::one(); LANES];
    for _ in 0..ROUNDS {
        for a in acc.iter_mut() {
            *a = *a * m + k;
        }
    }
    black_box(acc)
}

/// [`chains`] compiled for AVX.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn chains_avx<T: Real, const LANES: usize, const ROUNDS: usize>(m: T, k: T) -> [T; LANES] {
    chains::<T, LANES, ROUNDS>(m, k)
}

/// No AVX off x86-64.
#[cfg(not(target_arch = "x86_64"))]
unsafe fn chains_avx<T: Real, const LANES: usize, const ROUNDS: usize>(m: T, k: T) -> [T; LANES] {
    chains::<T, LANES, ROUNDS>(m, k)
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

/// `CompensatedLinear` beside `Linear` (same operators; the compensated update adds the
/// predictor's rounding errors through `GC`, `GK`: `5N² + 34N` against `3N² + 7N`).
fn compensated<T: Real, const N: usize>(c: &mut Criterion, ty: &str) {
    let sys = system::<N>();
    let (m, cc, k) = (&sys.0, &sys.1, &sys.2);
    let mut g = c.benchmark_group(format!("compensated/{ty}"));
    g.warm_up_time(Duration::from_millis(200))
        .measurement_time(Duration::from_millis(700))
        .sample_size(20);
    let lin = Box::new(Linear::<T, N>::new(m, cc, k, 0.01).expect("linear"));
    bench_stepper(&mut g, "aem", &*lin, 3 * N * N + 7 * N);
    let cl = Box::new(CompensatedLinear::<T, N>::new(m, cc, k, 0.01).expect("compensated"));
    bench_stepper(&mut g, "aem-compensated", &*cl, 5 * N * N + 34 * N);
    g.finish();
}

fn compensated_all(c: &mut Criterion, full: bool) {
    compensated::<f32, 1>(c, "f32");
    compensated::<f32, 5>(c, "f32");
    if full {
        compensated::<f32, 12>(c, "f32");
        compensated::<f32, 50>(c, "f32");
        compensated::<f32, 100>(c, "f32");
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
            // 12 packed registers of chains either way (more would spill: 16 registers).
            if has_avx() {
                floor_compute::<f64, 48>(&mut c, "f64", true);
                floor_compute::<f32, 96>(&mut c, "f32", true);
            } else {
                floor_compute::<f64, 24>(&mut c, "f64", false);
                floor_compute::<f32, 48>(&mut c, "f32", false);
            }
            per_step_all(&mut c, full);
            compensated_all(&mut c, full);
            if full {
                example10(&mut c);
            }
            c.final_summary();
        })
        .expect("spawn")
        .join()
        .expect("bench thread");
}
