//! The split step of real-time hybrid simulation (`hybrid::Split`, issue 22) against an
//! independent implementation of the papers' equations with a nonlinear restoring force
//! (Chen & Ricles 2008; Kolay & Ricles 2014: `u, v` explicit through `α1, α2`, the
//! weighted equation of motion `M [(I − α3) a' + α3 a] + C v̄ + R̄ = p̄` with
//! `R̄ = (1 − α_f) R(u') + α_f R(u)`), written in `tests/support/kr.rs` (`DMatrix`); the
//! zero-delay equivalence with the all-numerical explicit run; the partition with a
//! hysteretic numerical part; the Chen–Ricles stability limit for a specimen stiffer than
//! the operators assume against its closed form; bad input and failed steps; the `const`
//! builds.
#![allow(clippy::needless_range_loop)]

use aemstep::hybrid::{Actuator, Split, SplitState};
use aemstep::hysteresis::{Bilinear, BilinearHistory, Law};
use aemstep::models::{self, Rows, base_excitation};
use aemstep::nalgebra::{SMatrix, SVector};
use aemstep::{Error, KrAlpha, Param, Real, Stepper};
use nalgebra::{DMatrix, DVector};

#[path = "support/kr.rs"]
mod kr;
use kr::{Reference, members};

const EPS: f64 = f64::EPSILON;
const B: (Rows<5>, Rows<5>, Rows<5>) = models::five_storey_building();
const K1: f64 = models::FIVE_STOREY_STIFFNESS;
/// Storey yield force (N) of the yielding storeys: about a quarter of the elastic storey-1
/// demand of the pulse below, so they yield several times.
const FY: f64 = 2.0e6;

fn sm<const N: usize>(r: &Rows<N>) -> SMatrix<f64, N, N> {
    SMatrix::from_fn(|i, j| r[i][j])
}

fn dm<const N: usize>(a: &SMatrix<f64, N, N>) -> DMatrix<f64> {
    DMatrix::from_fn(N, N, |i, j| a[(i, j)])
}

fn split<T: Real, const N: usize>(
    m: &SMatrix<f64, N, N>,
    c: &SMatrix<f64, N, N>,
    k: &SMatrix<f64, N, N>,
    kn: &SMatrix<f64, N, N>,
    h: f64,
    rho: Option<f64>,
) -> Split<T, N> {
    match rho {
        Some(r) => Split::new(m, c, k, kn, h, r).unwrap(),
        None => Split::chen_ricles(m, c, k, kn, h).unwrap(),
    }
}

/// A strong ground pulse (m/s²) at step `n` of `h`.
fn pulse(n: usize, h: f64) -> f64 {
    let t = n as f64 * h;
    6.0 * (-((t - 0.6) / 0.25).powi(2)).exp() * (11.0 * t).sin()
}

/// The restoring force (N, per DOF) of the 5-storey building whose storeys `yielding`
/// are bilinear (`k = K1`, `f_y = FY`, 5 % hardening) and the rest linear `K1`, at the
/// floor displacements `u`, from the committed storey histories; and the trial histories.
fn building_force(
    law: &Bilinear<f64>,
    yielding: &[usize],
    hist: &[BilinearHistory<f64>; 5],
    u: &[f64],
) -> ([f64; 5], [BilinearHistory<f64>; 5]) {
    let mut f = [0.0; 5];
    let mut next = *hist;
    for i in 0..5 {
        let d = u[i] - if i > 0 { u[i - 1] } else { 0.0 };
        let fs = if yielding.contains(&i) {
            let t = law.trial(&hist[i], d, 0.0);
            next[i] = t.history;
            t.force
        } else {
            K1 * d
        };
        f[i] += fs;
        if i > 0 {
            f[i - 1] -= fs;
        }
    }
    (f, next)
}

/// The linear numerical stiffness of the building without the storeys in `given`.
fn k_without(given: &[usize]) -> SMatrix<f64, 5, 5> {
    let mut k = sm(&B.2);
    for &i in given {
        k[(i, i)] -= K1;
        if i > 0 {
            k[(i - 1, i - 1)] -= K1;
            k[(i, i - 1)] += K1;
            k[(i - 1, i)] += K1;
        }
    }
    k
}

/// The 5-storey building under the pulse, h = 1/1024 s, the split step against the
/// reference: storey 1 bilinear and "physical" (its force given), the rest linear
/// numerical; and storeys 1 and 2 bilinear, storey 1 physical and storey 2 a numerical
/// hysteretic part (its law evaluated at the command, its history committed only when
/// `complete` succeeds), the rest linear. Both use the same recurrence as the
/// reference; only the rounding differs (operators formed in another order; `G (p̄ − r̄)`
/// against the reference's `p̄ − r̄` solved by LU). The bilinear return map is Lipschitz
/// (constant 1), so rounding is carried along without amplification beyond that of the
/// stable linear recurrence: measured ≤ 5.2e-15 of the largest response (printed), bound
/// 100·N·ε = 1.1e-13.
#[test]
fn split_matches_the_papers_equations_with_yielding_storeys() {
    let (m, c, k) = (sm(&B.0), sm(&B.1), sm(&B.2));
    let iota = base_excitation(&B.0);
    let h = 1.0 / 1024.0;
    let law = Bilinear::<f64>::new(K1, FY, 0.05).unwrap();
    let load = |n: usize| SVector::<f64, 5>::from_fn(|i, _| iota[i][0] * pulse(n, h));
    let dv = |x: &SVector<f64, 5>| DVector::from_fn(5, |i, _| x[i]);
    for (name, rho) in members() {
        let r = Reference::new(dm(&m), dm(&c), dm(&k), h, rho);
        for given in [&[0usize][..], &[0, 1][..]] {
            let sys = split::<f64, 5>(&m, &c, &k, &k_without(given), h, rho);
            let z = SVector::<f64, 5>::zeros();
            let virgin = [law.initial_history(); 5];
            let mut s = sys.start(&z, &z, &z, &load(0)).unwrap();
            let mut x = [
                dv(&z),
                dv(&z),
                dv(&(sm(&B.0).try_inverse().unwrap() * load(0))),
            ];
            let (mut hist, mut hist_ref) = (virgin, virgin);
            let (mut r_prev, mut err, mut size, mut yielded) = (dv(&z), 0.0f64, 0.0f64, 0usize);
            for n in 1..=3072 {
                // The split: command, the given storeys' forces at it, complete.
                let cmd = sys.command(&s);
                let (_, trial) = building_force(&law, given, &hist, cmd.as_slice());
                // Only the given storeys' forces go in `r` (the rest is K_num's).
                let mut rg = [0.0; 5];
                for &i in given {
                    let d = cmd[i] - if i > 0 { cmd[i - 1] } else { 0.0 };
                    let fs = law.trial(&hist[i], d, 0.0).force;
                    rg[i] += fs;
                    if i > 0 {
                        rg[i - 1] -= fs;
                    }
                }
                sys.complete(&mut s, &SVector::from(rg), &load(n)).unwrap();
                hist = trial;
                // The reference: the whole restoring force at its own explicit displacement.
                let (u1, _) = r.explicit(&x);
                let (f_ref, trial_ref) = building_force(&law, given, &hist_ref, u1.as_slice());
                let r1 = DVector::from_row_slice(&f_ref);
                r.complete(&mut x, &r_prev, &r1, &dv(&load(n - 1)), &dv(&load(n)));
                r_prev = r1;
                hist_ref = trial_ref;
                yielded += given
                    .iter()
                    .filter(|&&i| hist[i] != virgin[i])
                    .count()
                    .min(1);
                for i in 0..5 {
                    err = err.max((s.state().u()[i] - x[0][i]).abs());
                    size = size.max(x[0][i].abs());
                }
            }
            eprintln!(
                "{name}, given storeys {given:?}: {err:.2e} of {size:.2e} (rel. {:.2e}), {yielded} steps since the first yield",
                err / size
            );
            assert!(yielded > 1000, "{name}: the storeys must yield");
            assert!(err <= 100.0 * 5.0 * EPS * size, "{name} {given:?}: {err:e}");
        }
    }
}

/// Zero delay, the specimen a linear spring equal to the numerical storey 1 behind the
/// emulated actuator (no delay, no lag: it reaches the command bit for bit): the hybrid
/// run is the all-numerical [`KrAlpha`] run to rounding. The two differ only in how the
/// storey-1 force enters (`G (p̄ − r̄)` with `r = k u_0` against `G K ū`): a few roundings
/// of `N`-term dot products per step, carried by the stable recurrence. Measured (printed)
/// ≤ 1.3e-15 of the largest response in `f64`, ≤ 7.2e-7 in `f32`; bounds 16·N·ε of each
/// (1.8e-14, 9.5e-6).
#[test]
fn zero_delay_linear_specimen_is_the_all_numerical_run() {
    let (m, c, k) = (sm(&B.0), sm(&B.1), sm(&B.2));
    let iota = base_excitation(&B.0);
    let h = 1.0 / 1024.0;
    let kn = k_without(&[0]);
    fn run<T: Real>(
        sys: &Split<T, 5>,
        all: &KrAlpha<T, 5>,
        load: impl Fn(usize) -> SVector<T, 5>,
    ) -> (f64, f64) {
        let z = SVector::<T, 5>::zeros();
        let k1 = T::from_f64_rounded(K1);
        let mut s = sys.start(&z, &z, &z, &load(0)).unwrap();
        let mut a = all.start(&z, &z, &load(0)).unwrap();
        let act = Actuator::<T, 4>::new(1.0 / 1024.0, 0.0, 0.0).unwrap();
        let mut at = act.rest(T::zero());
        let (mut err, mut size) = (0.0f64, 0.0f64);
        for n in 1..=4096 {
            let cmd = sys.command(&s);
            // Through the emulated actuator with no delay and no lag: the command itself.
            let reached = act.step(&mut at, cmd[0]).unwrap();
            assert_eq!(reached.as_f64().to_bits(), cmd[0].as_f64().to_bits());
            let mut r = z;
            r[0] = k1 * reached;
            sys.complete(&mut s, &r, &load(n)).unwrap();
            all.try_step_with_previous_input(&mut a, &load(n - 1), &load(n))
                .unwrap();
            for i in 0..5 {
                let (x, y) = (s.state().u()[i].as_f64(), a.u()[i].as_f64());
                err = err.max((x - y).abs());
                size = size.max(y.abs());
            }
        }
        (err, size)
    }
    for (name, rho) in members() {
        let load64 = |n: usize| SVector::<f64, 5>::from_fn(|i, _| iota[i][0] * pulse(n, h));
        let load32 = |n: usize| load64(n).cast::<f32>();
        let all64 = match rho {
            Some(r) => KrAlpha::<f64, 5>::new(&m, &c, &k, h, r).unwrap(),
            None => KrAlpha::<f64, 5>::chen_ricles(&m, &c, &k, h).unwrap(),
        };
        let all32 = match rho {
            Some(r) => KrAlpha::<f32, 5>::new(&m, &c, &k, h, r).unwrap(),
            None => KrAlpha::<f32, 5>::chen_ricles(&m, &c, &k, h).unwrap(),
        };
        let (e64, s64) = run(&split::<f64, 5>(&m, &c, &k, &kn, h, rho), &all64, load64);
        let (e32, s32) = run(&split::<f32, 5>(&m, &c, &k, &kn, h, rho), &all32, load32);
        eprintln!(
            "{name}: f64 {:.2e}, f32 {:.2e} (relative)",
            e64 / s64,
            e32 / s32
        );
        assert!(e64 <= 16.0 * 5.0 * EPS * s64, "{name}: f64 {e64:e}");
        assert!(
            e32 <= 16.0 * 5.0 * f64::from(f32::EPSILON) * s32,
            "{name}: f32 {e32:e}"
        );
    }
}

/// A 1-DOF Chen–Ricles run with the operators built for `k0` and a specimen of stiffness
/// `λ k0` (undamped): `α = 4/(4 + Ω0²)`, `a_n = −λω0² u_n`, so in `(u, h v)` the step is
/// `[[1 − αλΩ0², 1], [−αλΩ0², 1]]`, determinant 1, trace `2 − αλΩ0²`: stable iff
/// `αλΩ0² ≤ 4`, i.e. `λ ≤ 1 + 4/Ω0²` (`(ωh)² ≤ 4 + (ω0 h)²`). Checked on both sides of
/// the limit: 1 % below, the response stays within its initial energy bound over 20 000
/// steps; 1 % above, it grows past 10⁶.
#[test]
fn chen_ricles_stiffening_limit_is_the_closed_form() {
    let m = SMatrix::<f64, 1, 1>::new(1.0);
    let zero = SMatrix::<f64, 1, 1>::zeros();
    for omega_h in [0.5, 1.0, 2.0] {
        let h = 0.01;
        let w0 = omega_h / h;
        let k0 = SMatrix::<f64, 1, 1>::new(w0 * w0);
        let sys = Split::<f64, 1>::chen_ricles(&m, &zero, &k0, &zero, h).unwrap();
        let limit = 1.0 + 4.0 / (omega_h * omega_h);
        for (lambda, stable) in [(0.99 * limit, true), (1.01 * limit, false)] {
            let ks = lambda * w0 * w0;
            let u0 = SVector::<f64, 1>::new(1.0);
            let mut s = sys
                .start_with_acceleration(
                    &u0,
                    &SVector::zeros(),
                    &SVector::<f64, 1>::new(-ks),
                    &SVector::<f64, 1>::new(ks),
                    &SVector::zeros(),
                )
                .unwrap();
            let mut peak = 0.0f64;
            for _ in 0..20_000 {
                let d = sys.command(&s);
                if sys.complete(&mut s, &(d * ks), &SVector::zeros()).is_err() {
                    peak = f64::INFINITY;
                    break;
                }
                peak = peak.max(s.state().u()[0].abs());
            }
            // The invariant of the stable (unit-determinant) map bounds |u| by a constant
            // of order 1/sin(θ/2) of the initial value, θ the step's rotation angle
            // (small near the limit): bounded by 100 here, against > 10⁶ when unstable.
            eprintln!("Ωh = {omega_h}, λ = {lambda:.4} (limit {limit:.4}): peak {peak:.3e}");
            if stable {
                assert!(peak < 100.0, "Ωh = {omega_h}, λ = {lambda}: {peak:e}");
            } else {
                assert!(peak > 1e6, "Ωh = {omega_h}, λ = {lambda}: {peak:e}");
            }
        }
    }
}

/// The command is explicit: it depends on the committed state alone and is the
/// displacement the step commits.
#[test]
fn command_is_the_committed_displacement() {
    let (m, c, k) = (sm(&B.0), sm(&B.1), sm(&B.2));
    let sys = Split::<f64, 5>::new(&m, &c, &k, &k_without(&[0]), 0.005, 0.6).unwrap();
    let p = SVector::<f64, 5>::from_fn(|i, _| 1e5 * (i as f64 - 1.5));
    let z = SVector::zeros();
    let mut s = sys.start(&z, &z, &z, &p).unwrap();
    for n in 0..50 {
        let cmd = sys.command(&s);
        assert_eq!(cmd, sys.command(&s));
        let mut r = z;
        r[0] = K1 * cmd[0] * (1.0 + 0.1 * (n as f64).sin());
        sys.complete(&mut s, &r, &p).unwrap();
        assert_eq!(s.state().u(), &cmd);
        assert_eq!(s.restoring_force(), &r);
        assert_eq!(s.load(), &p);
    }
    assert_eq!(s.state().steps(), 50);
}

fn bits(s: &SplitState<f64, 5>) -> Vec<u64> {
    let x = s.state();
    x.u()
        .iter()
        .chain(x.v().iter())
        .chain(x.a().iter())
        .chain(s.restoring_force().iter())
        .chain(s.load().iter())
        .map(|v| v.to_bits())
        .chain([x.steps()])
        .collect()
}

/// A missing (NaN) or infinite force is `NonFiniteForce`, a bad load `NonFiniteInput`, an
/// overflowing step `NonFiniteState`; each leaves the state (and the committed force and
/// load) bit-identical, and the run goes on.
#[test]
fn failed_steps_change_nothing() {
    let (m, c, k) = (sm(&B.0), sm(&B.1), sm(&B.2));
    let sys = Split::<f64, 5>::new(&m, &c, &k, &k_without(&[0]), 0.01, 0.5).unwrap();
    let p = SVector::<f64, 5>::repeat(1e5);
    let z = SVector::zeros();
    let mut bad = p;
    bad[2] = f64::NAN;
    assert_eq!(sys.start(&z, &z, &z, &bad), Err(Error::NonFiniteInput));
    assert_eq!(sys.start(&bad, &z, &z, &p), Err(Error::NonFiniteInput));
    assert_eq!(sys.start(&z, &z, &bad, &p), Err(Error::NonFiniteForce));
    assert_eq!(
        sys.start_with_acceleration(&z, &z, &z, &bad, &p),
        Err(Error::NonFiniteForce)
    );
    assert_eq!(
        sys.start_with_acceleration(&z, &z, &bad, &z, &p),
        Err(Error::NonFiniteInput)
    );
    let mut s = sys.start(&z, &z, &z, &p).unwrap();
    for _ in 0..10 {
        let cmd = sys.command(&s);
        sys.complete(&mut s, &(cmd * 1e6), &p).unwrap();
    }
    let before = bits(&s);
    for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut bad = p;
        bad[0] = x;
        assert_eq!(sys.complete(&mut s, &bad, &p), Err(Error::NonFiniteForce));
        assert_eq!(sys.complete(&mut s, &p, &bad), Err(Error::NonFiniteInput));
        assert_eq!(bits(&s), before);
    }
    // Finite force and load whose difference overflows, and a finite force whose step
    // overflows: refused, nothing changed.
    let huge = SVector::<f64, 5>::repeat(f64::MAX);
    assert_eq!(
        sys.complete(&mut s, &huge, &-huge),
        Err(Error::NonFiniteState)
    );
    assert_eq!(bits(&s), before);
    // A finite state whose step overflows (`G K_num u` with `|G K_num| ≈ 1e3`, `u = 1e307`).
    let mut big = sys
        .start_with_acceleration(&SVector::repeat(1e307), &z, &z, &z, &z)
        .unwrap();
    let big_before = bits(&big);
    assert_eq!(sys.complete(&mut big, &z, &z), Err(Error::NonFiniteState));
    assert_eq!(bits(&big), big_before);
    let cmd = sys.command(&s);
    sys.complete(&mut s, &(cmd * 1e6), &p).unwrap();
    assert_eq!(s.state().steps(), 11);
}

/// Bad construction: the same variants as [`KrAlpha`] for the same input.
#[test]
fn bad_input_is_a_typed_error() {
    let one = SMatrix::<f64, 1, 1>::new(1.0);
    let zero = SMatrix::<f64, 1, 1>::zeros();
    let nan = SMatrix::<f64, 1, 1>::new(f64::NAN);
    assert_eq!(
        Split::<f64, 1>::new(&one, &zero, &one, &nan, 0.01, 0.5),
        Err(Error::NonFiniteInput)
    );
    assert_eq!(
        Split::<f64, 1>::new(&one, &zero, &one, &one, 0.01, 1.5),
        Err(Error::InvalidParameter(Param::RhoInf))
    );
    assert_eq!(
        Split::<f64, 1>::chen_ricles(&one, &zero, &one, &one, -0.01),
        Err(Error::InvalidTimeStep)
    );
    assert_eq!(
        Split::<f64, 1>::chen_ricles(&zero, &zero, &one, &one, 0.01),
        Err(Error::SingularMass)
    );
    // `G K_num` does not fit f32 (K_num = 1e39 with M = 1): the operator's own overflow.
    let big = SMatrix::<f64, 1, 1>::new(1e39);
    assert_eq!(
        Split::<f32, 1>::new(&one, &zero, &one, &big, 0.01, 0.5),
        Err(Error::OperatorOverflow)
    );
    assert!(Split::<f64, 1>::new(&one, &zero, &one, &big, 0.01, 0.5).is_ok());
    for (a, b) in [(&one, &nan), (&nan, &one)] {
        assert_eq!(
            Split::<f64, 1>::new(&one, &zero, a, b, 0.01, 0.5).map(|_| ()),
            KrAlpha::<f64, 1>::new(&one, &zero, &nan, 0.01, 0.5).map(|_| ())
        );
    }
}

static S32: Split<f32, 5> = match Split::from_rows_f32(B.0, B.1, B.2, B.2, 1.0 / 1024.0, 0.5) {
    Ok(s) => s,
    Err(e) => panic!("{}", e.as_str()),
};
static CR64: Split<f64, 5> =
    match Split::from_rows_chen_ricles_f64(B.0, B.1, B.2, B.2, 1.0 / 1024.0) {
        Ok(s) => s,
        Err(e) => panic!("{}", e.as_str()),
    };
const H32: f32 = S32.time_step();

/// The `const fn` builds are the run-time builds bit for bit; with `K_num = K` the split's
/// operators are [`KrAlpha`]'s.
#[test]
fn const_builds_are_the_run_time_builds() {
    let (m, c, k) = (sm(&B.0), sm(&B.1), sm(&B.2));
    let h = 1.0 / 1024.0;
    assert_eq!(S32, Split::<f32, 5>::new(&m, &c, &k, &k, h, 0.5).unwrap());
    assert_eq!(
        CR64,
        Split::<f64, 5>::chen_ricles(&m, &c, &k, &k, h).unwrap()
    );
    assert_eq!(H32, 1.0 / 1024.0);
    assert_eq!(
        S32.scheme(),
        &KrAlpha::<f32, 5>::new(&m, &c, &k, h, 0.5).unwrap()
    );
    assert_eq!(CR64.parameters().alpha_f, 0.0);
}
