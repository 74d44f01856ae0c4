//! Fuzz target `hysteresis` (`fuzz_targets/hysteresis.rs`): checks the laws' constructors
//! (Bilinear, Bouc–Wen, friction) and their trials, Parallel, ShearBuilding::new, and a
//! hysteretic building stepped by Nonlinear with history; f32 and f64.
//!
//! The decoder and the checks every target shares are in `common.rs`.

use std::fmt::Debug;

use aemstep::hysteresis::{
    Bilinear, BoucWen, BoucWenHistory, Friction, HistoryModel, Law, Parallel, ShearBuilding,
};
use aemstep::lanes::{Failure, LaneLaw, LaneStepper};
use aemstep::nalgebra::{SMatrix, SVector};
use aemstep::{Error, NewtonSettings, Nonlinear, Real};

use super::common::*;

const HY: &str = "hysteresis";

/// Target `hysteresis`.
pub fn hysteresis(data: &[u8]) {
    let mut b = Bytes::new(data);
    let k = b.param(1e3, 1e9);
    let fy = b.param(1e2, 1e7);
    let alpha = b.param(0.0, 0.99);
    let beta = b.param(0.1, 1.0);
    let gamma = b.param(-0.5, 0.5);
    let n = match b.pick(4) {
        0 => 1.0,
        1 => 2.0,
        _ => b.param(1.0, 6.0),
    };
    let fs = b.param(1e2, 1e6);
    let vr = b.param(1e-4, 1e-1);
    let path: Vec<f64> = (0..8)
        .map(|_| {
            if b.pick(4) == 0 {
                b.value()
            } else {
                b.ordinary()
            }
        })
        .collect();
    let rates: Vec<f64> = (0..8).map(|_| b.value()).collect();
    let masses = [b.param(1e3, 1e6), b.param(1e3, 1e6)];
    let mut cd = b.matrix::<2, 2>();
    // Half the buildings with a symmetric (so tridiagonal) damping matrix: the stepper's
    // O(N) Newton path (`HistoryModel::trial_tridiagonal`); the other half the dense one.
    if b.pick(2) == 0 {
        cd[(1, 0)] = cd[(0, 1)];
    }
    let h = b.time_step();
    let ag = [b.value(), b.ordinary(), f64::NAN, b.ordinary()];
    let law = LawData {
        k,
        fy,
        alpha,
        beta,
        gamma,
        n,
        fs,
        vr,
        path,
        rates,
        masses,
        cd,
        h,
        ag,
    };
    let which = b.pick(3);
    set_context(format!(
        "k = {k:e}, fy = {fy:e}, α = {alpha:e}, β = {beta:e}, γ = {gamma:e}, n = {n:e}, fs = {fs:e}, vr = {vr:e}, path = {:?}, rates = {:?}, masses = {:?}, C = {:?}, h = {:e}, ag = {:?}, which = {which}",
        law.path,
        law.rates,
        law.masses,
        law.cd.as_slice(),
        law.h,
        law.ag
    ));
    laws_typed::<f64>(&law, which);
    laws_typed::<f32>(&law, which);
    count(HY, "inputs");
    count(HY, b.category());
}

struct LawData {
    k: f64,
    fy: f64,
    alpha: f64,
    beta: f64,
    gamma: f64,
    n: f64,
    fs: f64,
    vr: f64,
    path: Vec<f64>,
    rates: Vec<f64>,
    masses: [f64; 2],
    cd: SMatrix<f64, 2, 2>,
    h: f64,
    ag: [f64; 4],
}

fn pos(x: f64) -> bool {
    x.is_finite() && x > 0.0
}

fn laws_typed<T: Real>(d: &LawData, which: u8) {
    let unit = |x: f64| x.is_finite() && (0.0..1.0).contains(&x);
    let bl = Bilinear::<T>::new(d.k, d.fy, d.alpha);
    outcome(HY, &bl);
    law_rule("Bilinear::new", &bl, pos(d.k) && pos(d.fy) && unit(d.alpha));
    let bw = BoucWen::<T>::new(d.k, d.fy, d.alpha, d.beta, d.gamma, d.n);
    outcome(HY, &bw);
    let bw_ok = pos(d.k)
        && pos(d.fy)
        && unit(d.alpha)
        && pos(d.beta)
        && d.gamma.is_finite()
        && d.gamma.abs() <= d.beta
        && d.n.is_finite()
        && d.n >= 1.0;
    law_rule("BoucWen::new", &bw, bw_ok);
    let fr = Friction::<T>::new(d.fs, d.vr);
    outcome(HY, &fr);
    law_rule("Friction::new", &fr, pos(d.fs) && pos(d.vr));
    let uy = d.fy / d.k;
    if let Ok(l) = &bl {
        check!(
            [
                l.stiffness(),
                l.yield_force(),
                l.post_yield_stiffness(),
                l.hardening()
            ]
            .iter()
            .all(|x| x.is_finite()),
            "{HY}: Bilinear Ok with a non-finite coefficient: {l:?}"
        );
        drive_law(l, "Bilinear", uy, d, false, |_, _| true);
    }
    // Bouc–Wen's finiteness is judged where its tangent is representable: with k near the
    // largest finite value, α k + (1 − α) k g (…) overflows (the fuzzer's k = 1.8e308).
    // Otherwise along every path (any step, any β, γ, n), as the other laws.
    // And where the law's own slope is: `dz/dd = g/u_y` with `g` up to `1 + (β − γ)|z|ⁿ`
    // on unloading, so the tangent is up to `k (1 + (β + |γ|) |z|ⁿ)`. `z` stays within
    // `2^{1/n} z_max` when `β + γ > 0`; with `γ = −β` it does not saturate, `|z|` grows by
    // up to `2|Δ|/u_y` a step, and the unloading tangent `k |z|ⁿ` of a deformation of
    // `10 u_y` with `n = 1000` is beyond `f64` (the fuzzer's first such "NaN" was that).
    // The slope `g` itself must fit too, as the law documents ("the unloading slope can
    // leave `T`"): with `k = 1e-62` the tangent `k g ≈ 1e270` fits where `g ≈ 1e334`
    // (`|z| = 2.16`, `n = 1000`) does not (found by fuzzing).
    let bw_judged = |hist: &BoucWenHistory<T>, step: f64| {
        let bg = d.beta + d.gamma;
        let zb = if bg > 0.0 {
            hist.z
                .as_f64()
                .abs()
                .max(2f64.powf(1.0 / d.n) * bg.powf(-1.0 / d.n))
        } else {
            hist.z.as_f64().abs() + 2.0 * step.abs()
        };
        let log_wn = (d.beta + d.gamma.abs()).ln() + d.n * zb.ln();
        d.k.ln().max(0.0) + log_wn.max(0.0) + 16f64.ln() < T::MAX.ln()
    };
    if let Ok(l) = &bw {
        drive_law(l, "BoucWen", uy, d, d.k * 4.0 >= T::MAX, bw_judged);
    }
    if let Ok(l) = &fr {
        check!(
            l.slip_force().is_finite(),
            "{HY}: Friction Ok with slip force {:?}",
            l.slip_force()
        );
        drive_law(l, "Friction", 1.0, d, false, |_, _| true);
    }
    match (which, bl, bw, fr) {
        (0, Ok(l), _, _) => building(l, "Bilinear", d),
        (1, _, Ok(l), _) => building(l, "BoucWen", d),
        (2, Ok(l), _, Ok(f)) => building(Parallel(l, f), "Bilinear ∥ Friction", d),
        _ => {}
    }
}

/// A law's constructor against its documented parameter ranges: out of range is
/// `InvalidMaterial`; in range is `Ok`, or `OperatorOverflow` where a coefficient does not
/// fit the scalar type.
fn law_rule<X>(name: &str, r: &Result<X, Error>, in_range: bool) {
    let e = r.as_ref().err().copied();
    let ok = if in_range {
        e.is_none() || e == Some(Error::OperatorOverflow)
    } else {
        matches!(e, Some(Error::InvalidMaterial(_)))
    };
    check!(
        ok,
        "{HY}: {name}: parameters in range: {in_range}, gave {e:?}"
    );
}

/// Drive a law along deformations `u_y·path` (rates `rates`), committing each trial: no
/// panic; the force and tangent finite wherever they are representable (unless
/// `unjudged`): the deformation and rate finite, the elastic force `k u_y x` within `T`,
/// and the path's dimensionless length `Σ|x|` within `T` (Bouc–Wen's `z` moves by at most
/// about that: with `β + γ = 0` it does not saturate), and `judged(committed, Δ/u_y)`
/// (the law's own slope representable).
fn drive_law<T: Real, L: Law<T> + Debug>(
    l: &L,
    name: &str,
    uy: f64,
    d: &LawData,
    unjudged: bool,
    judged: impl Fn(&L::History, f64) -> bool,
) {
    let mut hist = l.initial_history();
    let mut length = 0.0f64;
    let mut last = 0.0f64;
    for (i, &x) in d.path.iter().enumerate() {
        let def = T::from_f64_rounded(uy * x);
        let rate = T::from_f64_rounded(d.rates[i]);
        let tr = l.trial(&hist, def, rate);
        count(HY, "law trials");
        // A force beyond the scalar type is not representable (`k d` of a deformation of
        // 1e307): only deformations whose elastic force fits are judged.
        let representable = (uy * x).abs() * (d.k.max(d.fs)) * 4.0 < T::MAX;
        length += x.abs();
        if !unjudged
            && judged(&hist, (def.as_f64() - last) / uy)
            && def.is_finite()
            && rate.is_finite()
            && representable
            && length * 4.0 < T::MAX
        {
            check!(
                tr.force.is_finite() && tr.stiffness.is_finite() && tr.damping.is_finite(),
                "{HY}: {name}: trial at d = {def:?}, rate {rate:?}: {tr:?} ({l:?})"
            );
        }
        if tr.force.is_finite() {
            hist = tr.history;
            last = def.as_f64();
        }
        let _ = l.recoverable_energy(&hist, def);
    }
}

fn building<T: Real, L: LaneLaw<T> + Copy + Debug>(l: L, name: &str, d: &LawData)
where
    L::History: Debug,
{
    let b = ShearBuilding::<T, L, 2>::new(d.masses, [l, l], &rows(&d.cd));
    outcome(HY, &b);
    let want = if !(all_finite(&d.masses) && all_finite(d.cd.as_slice())) {
        Some(Error::NonFiniteInput)
    } else if d.masses.iter().any(|&m| m <= 0.0) {
        Some(Error::MassNotSpd)
    } else {
        None
    };
    let e = b.as_ref().err().copied();
    // (A mass below the smallest normal number of `T` is `OperatorUnderflow`: in `f32` a
    // mass of 6e-322 kg rounded to 0 and the start failed with `SingularMass`.)
    let tiny = d
        .masses
        .iter()
        .any(|&m| m > 0.0 && m < T::MAX.recip() * 4.0);
    check!(
        e == want
            || (want.is_none() && e == Some(Error::OperatorOverflow))
            || (want.is_none() && tiny && e == Some(Error::OperatorUnderflow)),
        "{HY}: ShearBuilding::new gave {e:?}, want {want:?}"
    );
    let Ok(b) = b else { return };
    check!(
        finite(&b.mass()) && finite(b.damping()),
        "{HY}: ShearBuilding Ok with non-finite mass or damping: {:?} {:?}",
        b.mass(),
        b.damping()
    );
    let Ok(st) = Nonlinear::<T, 2>::new(d.h, NewtonSettings::default()) else {
        return;
    };
    lanes_match::<T, L, 4>(&b, &st, name, d);
    lanes_match::<T, L, 8>(&b, &st, name, d);
    let zero = SVector::<T, 2>::zeros();
    let Ok((mut x, mut hist)) =
        st.start_with_history(&b, &zero, &zero, &zero, &b.initial_history())
    else {
        panic!(
            "property broken: {HY}: {name} building could not start at rest\n  data: {}",
            context()
        );
    };
    for &a in &d.ag {
        let p = b.ground_load(T::from_f64_rounded(a));
        let (bx, bh) = (bits(&x), bits(&hist));
        let trial = st.trial_step_with_history(&b, &x, &hist, &p);
        let r = st.try_step_with_history(&b, &mut x, &mut hist, &p);
        count(HY, "checked steps");
        match r {
            Ok(_) => {
                check!(
                    x.is_finite() && finite(&p),
                    "{HY}: {name} building: Ok step gave {x:?}"
                );
                let (cx, ch, _) = trial.expect("trial failed where the step succeeded");
                check!(
                    bits(&cx) == bits(&x) && bits(&ch) == bits(&hist),
                    "{HY}: {name}: trial and step differ"
                );
            }
            Err(e) => {
                count(HY, "failed checked steps");
                check!(
                    bits(&x) == bx && bits(&hist) == bh,
                    "{HY}: {name} building: failed step ({e:?}) changed the state or history"
                );
                if !finite(&p) {
                    check!(
                        e == Error::NonFiniteInput,
                        "{HY}: {name}: a non-finite load gave {e:?}"
                    );
                }
            }
        }
    }
}

/// The building's analyses from rest under `ag` scaled per lane (1, −1, ½, 2, … cycling;
/// records of 4, 3, 2, 1 … steps), by `LaneStepper::run` with `W` lanes (`f64 × 8`: the
/// AVX-512 path where the CPU has it) and one at a time by `st`: every state after every
/// step and every outcome bit for bit (the all-elastic factors formed once, laws,
/// failures).
fn lanes_match<T: Real, L: LaneLaw<T> + Copy + Debug, const W: usize>(
    b: &ShearBuilding<T, L, 2>,
    st: &Nonlinear<T, 2>,
    name: &str,
    d: &LawData,
) where
    L::History: Debug,
{
    let Ok(lanes) = LaneStepper::<T, 2, W>::new(d.h, st.settings()) else {
        panic!(
            "property broken: {HY}: LaneStepper::new refused what Nonlinear::new took\n  data: {}",
            context()
        );
    };
    let scale = |l: usize| [1.0, -1.0, 0.5, 2.0][l % 4] * (1 + l / 4) as f64;
    let ground = |l: usize, n: u64| {
        let a = if n == 0 {
            0.0
        } else {
            d.ag[(n as usize - 1) % 4]
        };
        T::from_f64_rounded(a * scale(l))
    };
    let steps: [u64; W] = core::array::from_fn(|l| 4 - (l as u64 % 4));
    let mut seen: Vec<Vec<String>> = vec![Vec::new(); W];
    let out = lanes.run(b, steps, ground, |s, stepped| {
        for (l, lane) in seen.iter_mut().enumerate() {
            if stepped[l] {
                lane.push(bits(&s.lane(l)));
            }
        }
    });
    let zero = SVector::<T, 2>::zeros();
    for l in 0..W {
        let mut want = Vec::new();
        let outcome = (|| {
            let (mut x, mut h) = st
                .start_with_history(
                    b,
                    &zero,
                    &zero,
                    &b.ground_load(ground(l, 0)),
                    &b.initial_history(),
                )
                .map_err(|error| Failure { step: 0, error })?;
            for n in 1..=steps[l] {
                st.try_step_with_history(b, &mut x, &mut h, &b.ground_load(ground(l, n)))
                    .map_err(|error| Failure { step: n, error })?;
                want.push(bits(&Some(x)));
            }
            Ok(())
        })();
        count(HY, "lane analyses");
        check!(
            out[l] == outcome && seen[l] == want,
            "{HY}: {name}: lane {l} of {W} differs from its single analysis: {:?} against {outcome:?}",
            out[l]
        );
    }
}
