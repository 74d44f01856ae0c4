//! The yielding shear-building step timed on the host, beside OpenSees
//! (`scripts/bench_nonlinear.py` runs both and writes the "nonlinear peers" section of
//! docs/performance.md; this binary is its Rust half).
//!
//! `cargo run --release -p xtask --bin nonlinear_bench -- [--reps R] [--ida K] [--drifts PATH]`
//!
//! Prints one JSON object a line per case: ns/step (fastest, median of `R` whole runs timed
//! with `std::time::Instant`), Newton iterations and trial evaluations per step, the flops
//! a step needs by [`flops_per_step`], and their share of the measured scalar floor.
//! `--drifts PATH` writes the 5-storey bilinear drift history (one step a line, `%.17e`) for
//! the script's comparison with OpenSees. `--ida K`: the serial IDA row, `K` analyses of
//! the 5-storey bilinear building at scales `2.0·j/K`, `j = 1…K` (0 skips it).

#[path = "../../../scenes/modal/elcentro.rs"]
mod elcentro;
#[path = "../../../scenes/ida/building.rs"]
mod scene;

use std::fmt::Write as _;
use std::hint::black_box;
use std::time::Instant;

use aemstep::hysteresis::{
    Bilinear, BoucWen, Friction, HistoryModel, Law, Parallel, ShearBuilding,
};
use aemstep::models::{self, Rows};
use aemstep::nalgebra::SVector;
use aemstep::{NewtonSettings, Nonlinear};

/// Which storey law, for the flop count.
#[derive(Clone, Copy)]
enum LawKind {
    Bilinear,
    BoucWen,
    BilinearFriction,
}

/// Floating-point operations of one step of `Nonlinear` on a `ShearBuilding` of `n` storeys
/// with Rayleigh (tridiagonal) damping and `k` Newton iterations, as the code path in
/// src/nonlinear/mod.rs (`iterate`, `Linearization`), src/linalg/tridiagonal.rs and
/// src/hysteresis/building.rs (`fused`) reads. Counted: additions, multiplications,
/// divisions, comparisons/abs/max/finiteness tests (1 each); branches and copies not.
///
/// - once a step: predictor `v̂, û` `6n`, `p` finite `n`, `‖p‖∞` `2n`; the new state finite
///   `3n`;
/// - each of the `k + 1` trials: correction `v, u` `4n`; drifts `2n`; `n` law trials
///   ([`law_trial_flops`]); `C v` on three diagonals `5n`, storey forces into floors `2n`;
///   the tridiagonal tangent `4n`; force and mass finite `3n`; `M q` on three diagonals
///   `5n`; `r = M q + F − p` `2n`; relative residual (three ∞-norms) `6n + 3`;
/// - each of the `k` trials after the first: the correction test (three ∞-norms, three
///   divisions) `6n + 5`;
/// - each of the `k` solves: tangent finite `4n`; `J` on three diagonals `8n` and its entry
///   scale `16n`; `L D Lᵀ` with the pivot tests `11n` (`n` divisions); `q −= δ`, `‖δ‖∞` `3n`.
fn flops_per_step(n: usize, law: LawKind, k: f64) -> f64 {
    let n = n as f64;
    let once = 6.0 * n + n + 2.0 * n + 3.0 * n;
    let trial = 4.0 * n
        + 2.0 * n
        + n * law_trial_flops(law)
        + 5.0 * n
        + 2.0 * n
        + 4.0 * n
        + 3.0 * n
        + 5.0 * n
        + 2.0 * n
        + (6.0 * n + 3.0);
    let correction = 6.0 * n + 5.0;
    let solve = 4.0 * n + 8.0 * n + 16.0 * n + 11.0 * n + 3.0 * n;
    once + (k + 1.0) * trial + k * (correction + solve)
}

/// Flops of one storey law trial (src/hysteresis/bilinear.rs, bouc_wen.rs, friction.rs).
/// Bilinear: trial force at half scale 4, back-stress 2, excess 2, flow 6 → 14. Bouc–Wen
/// (`n = 2`, no `powf`): its implicit `z` update, about 4 scalar Newton iterations of ~15
/// flops (the file's own count) plus ~30 for the predictor, force and consistent tangent
/// → 90, an estimate. Friction: `tanh` counted as 20, plus 6; `Parallel` adds 3.
fn law_trial_flops(law: LawKind) -> f64 {
    match law {
        LawKind::Bilinear => 14.0,
        LawKind::BoucWen => 90.0,
        LawKind::BilinearFriction => 14.0 + 26.0 + 3.0,
    }
}

/// The uniform `n`-storey building's Rayleigh damping, 5 % in the first two elastic modes
/// (frequencies from `K/m`'s eigenvalues); the 5-storey one is `models::five_storey_building`.
fn damping<const N: usize>() -> Rows<N> {
    let (m, k) = models::shear_building([scene::MASS; N], [scene::STIFFNESS; N]);
    if N == 5 {
        let c = models::five_storey_building().1;
        let mut out = [[0.0; N]; N];
        for i in 0..N {
            out[i].copy_from_slice(&c[i]);
        }
        return out;
    }
    let km = aemstep::nalgebra::DMatrix::from_fn(N, N, |i, j| k[i][j] / scene::MASS);
    let mut w2: Vec<f64> = km.symmetric_eigenvalues().iter().copied().collect();
    w2.sort_by(f64::total_cmp);
    let (a0, a1) = models::rayleigh_coefficients(w2[0].sqrt(), w2[1].sqrt(), scene::XI);
    models::rayleigh(&m, &k, a0, a1)
}

/// One run's outcome: Newton iterations and the peak |drift|.
struct Run {
    iterations: u64,
    steps: u64,
    peak: f64,
}

/// Step the building through the record ×`scale` from rest; `drifts` collects the history.
fn run<L: Law<f64>, const N: usize>(
    b: &ShearBuilding<f64, L, N>,
    scale: f64,
    mut drifts: Option<&mut Vec<[f64; N]>>,
) -> Run {
    let stepper = Nonlinear::<f64, N>::new(
        1.0 / scene::RATE as f64,
        NewtonSettings::up_to(scene::NEWTON_ITERATIONS, scene::NEWTON_TOLERANCE),
    )
    .expect("settings");
    let zero = SVector::<f64, N>::zeros();
    let (mut s, mut h) = stepper
        .start_with_history(b, &zero, &zero, &b.ground_load(0.0), &b.initial_history())
        .expect("start");
    let mut iterations = 0u64;
    let mut peak = 0.0f64;
    for n in 1..=scene::steps(elcentro::SAMPLES) {
        let ag = scene::ground(&elcentro::AG_F64, scale, n);
        let r = stepper
            .try_step_with_history(b, &mut s, &mut h, &b.ground_load(ag))
            .expect("step");
        iterations += u64::from(r.iterations);
        let d = models::drifts(s.u());
        peak = peak.max(d.amax());
        if let Some(out) = drifts.as_deref_mut() {
            let mut row = [0.0; N];
            row.copy_from_slice(d.as_slice());
            out.push(row);
        }
    }
    Run {
        iterations,
        steps: scene::steps(elcentro::SAMPLES),
        peak,
    }
}

/// Fastest and median of `reps` timings (s) of `f`.
fn time<R>(reps: usize, mut f: impl FnMut() -> R) -> (f64, f64) {
    let mut t: Vec<f64> = (0..reps)
        .map(|_| {
            let t0 = Instant::now();
            black_box(f());
            t0.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    (t[0], t[t.len() / 2])
}

/// The host's `f64` multiply-add rate without AVX (flop/s): 24 independent chains of
/// `a = a·m + k` (2 flops each, no dependence between chains), as
/// xtask/benches/steps.rs `floor_compute` does without AVX; fastest of 20 timings. The
/// compiler packs the chains two to an SSE2 register: the SSE2 rate, twice one lane's.
fn peak_flops() -> f64 {
    const LANES: usize = 24;
    const ROUNDS: usize = 1 << 16;
    let (m, k) = (black_box(0.999f64), black_box(1e-3f64));
    let (best, _) = time(20, || {
        let mut acc = [1.0f64; LANES];
        for _ in 0..ROUNDS {
            for a in acc.iter_mut() {
                *a = *a * m + k;
            }
        }
        acc
    });
    2.0 * (LANES * ROUNDS) as f64 / best
}

/// The dependency chain of one Newton solve of the 5-storey building alone (ns): the
/// `L D Lᵀ` factor-and-solve of a symmetric tridiagonal `J` (the recurrence of
/// `linalg::tridiagonal::solve_positive`: a row's pivot `d_i = a_i − e_i² / d_{i−1}`, its
/// reciprocal by one division, the forward and back substitutions), each solve's
/// right-hand side the previous solution and each `J`'s diagonal shifted by it, as
/// successive Newton iterations are chained; fastest of 20 timings of 2¹⁶ solves. A step
/// that corrects its predictor runs at least one such solve between two trial
/// evaluations that depend on it, so no single analysis steps faster than this.
fn solve_chain_ns() -> f64 {
    const N: usize = 5;
    const ROUNDS: usize = 1 << 16;
    // J of the elastic building at h = 0.005, M + (h²/4) K, divided by the floor mass: its
    // eigenvalues lie in [1, 1.025], so the chained solutions shrink slowly and stay normal
    // numbers (no subnormal slow path) over the 2¹⁶ solves.
    let (m, k) = (
        black_box(1.0),
        black_box(scene::STIFFNESS * 0.25 * scene::H * scene::H / scene::MASS),
    );
    let (best, _) = time(20, || {
        let mut x = [1.0f64; N];
        for _ in 0..ROUNDS {
            let shift = x[N - 1] * 1e-30; // ties J to the last solution, changes nothing
            let d: [f64; N] =
                core::array::from_fn(|i| m + k * if i + 1 < N { 2.0 } else { 1.0 } + shift);
            let e = -k;
            let mut inv = [0.0f64; N];
            let mut prev = 0.0f64;
            for i in 0..N {
                let l = e * prev;
                let di = if i == 0 { d[0] } else { d[i] - l * e };
                if i > 0 {
                    x[i] -= l * x[i - 1];
                }
                prev = 1.0 / di;
                inv[i] = prev;
            }
            for i in (0..N).rev() {
                let upper = if i + 1 < N { e * x[i + 1] } else { 0.0 };
                x[i] = (x[i] - upper) * inv[i];
            }
        }
        x
    });
    best / ROUNDS as f64 * 1e9
}

fn building<L: Law<f64> + Copy, const N: usize>(law: L) -> ShearBuilding<f64, L, N> {
    ShearBuilding::new([scene::MASS; N], [law; N], &damping::<N>()).expect("building")
}

fn case<L: Law<f64> + Copy, const N: usize>(
    name: &str,
    law: L,
    kind: LawKind,
    reps: usize,
    peak: f64,
) -> String {
    let b = building::<L, N>(law);
    let r = run(&b, scene::SCALE, None);
    let (fast, median) = time(reps, || run(&b, scene::SCALE, None).peak);
    let steps = r.steps as f64;
    let its = r.iterations as f64 / steps;
    let flops = flops_per_step(N, kind, its);
    let mut s = String::new();
    write!(
        s,
        "{{\"case\": \"{name}\", \"n\": {N}, \"ns_fast\": {:.1}, \"ns_median\": {:.1}, \
         \"iterations\": {its:.4}, \"trials\": {:.4}, \"ns_per_iteration\": {:.1}, \
         \"flops_iteration\": {:.0}, \"flops_step\": {flops:.0}, \"floor_share\": {:.4}, \
         \"peak_drift\": {:.6e}}}",
        fast / steps * 1e9,
        median / steps * 1e9,
        its + 1.0,
        fast / r.iterations.max(1) as f64 * 1e9,
        flops_per_step(N, kind, 1.0) - flops_per_step(N, kind, 0.0),
        flops / (fast / steps * peak),
        r.peak,
    )
    .expect("write");
    s
}

fn bilinear() -> Bilinear<f64> {
    Bilinear::new(scene::STIFFNESS, scene::FY, scene::ALPHA).expect("bilinear")
}

/// The serial IDA row: `k` analyses at scales `2.0·j/k`, one after another; returns the
/// peak drift of each (so nothing is optimized away).
fn ida(k: usize) -> Vec<f64> {
    let b = building::<_, 5>(bilinear());
    (1..=k)
        .map(|j| run(&b, 2.0 * j as f64 / k as f64, None).peak)
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let reps: usize = arg("--reps").map_or(3, |s| s.parse().expect("--reps"));
    let ida_k: usize = arg("--ida").map_or(100, |s| s.parse().expect("--ida"));
    let peak = peak_flops();
    println!(
        "{{\"peak_flops\": {peak:.4e}, \"solve_chain_ns\": {:.2}}}",
        solve_chain_ns()
    );
    if let Some(path) = arg("--drifts") {
        let mut d = Vec::new();
        run(&building::<_, 5>(bilinear()), scene::SCALE, Some(&mut d));
        let mut text = String::new();
        for row in &d {
            let cols: Vec<String> = row.iter().map(|x| format!("{x:.17e}")).collect();
            writeln!(text, "{}", cols.join(" ")).expect("write");
        }
        std::fs::write(&path, text).expect("drifts file");
    }
    println!(
        "{}",
        case::<_, 5>("bilinear", bilinear(), LawKind::Bilinear, reps, peak)
    );
    let bw = BoucWen::new(scene::STIFFNESS, scene::FY, scene::ALPHA, 0.5, 0.5, 2.0).expect("bw");
    println!(
        "{}",
        case::<_, 5>("bouc-wen", bw, LawKind::BoucWen, reps, peak)
    );
    // Friction dampers slipping at 5 % of the building's weight (the heaviest, ground
    // storey's share; one value for every storey), regularized at 10 mm/s: (h/2) f_s / v_r
    // = 0.0025·2.45e5/1e-2 ≈ 6e4 kg, 0.6 floor masses. At 1 mm/s (six floor masses) Newton
    // bounces on the tanh and a step is refused (see src/hysteresis/friction.rs).
    let fs = 0.05 * 5.0 * scene::MASS * elcentro::G;
    let fr = Parallel(bilinear(), Friction::new(fs, 1e-2).expect("friction"));
    println!(
        "{}",
        case::<_, 5>(
            "bilinear+friction",
            fr,
            LawKind::BilinearFriction,
            reps,
            peak
        )
    );
    println!(
        "{}",
        case::<_, 3>("bilinear", bilinear(), LawKind::Bilinear, reps, peak)
    );
    println!(
        "{}",
        case::<_, 10>("bilinear", bilinear(), LawKind::Bilinear, reps, peak)
    );
    println!(
        "{}",
        case::<_, 20>("bilinear", bilinear(), LawKind::Bilinear, reps, peak)
    );
    if ida_k > 0 {
        let (fast, median) = time(reps, || ida(ida_k));
        println!(
            "{{\"case\": \"ida\", \"analyses\": {ida_k}, \"s_fast\": {fast:.4}, \"s_median\": {median:.4}}}"
        );
    }
}
