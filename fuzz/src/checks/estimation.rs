//! Fuzz target `estimation` (`fuzz_targets/estimation.rs`): checks InputModel (from_parts,
//! zero_dynamics), InputStateGains (solve, new), InputStateObserver (new,
//! from_parts_f32/_f64), InputStateFilter, DualGains (solve, new), DualKalmanFilter, DualFilter (new,
//! from_parts_f32/_f64), AugmentedModel (from_parts, steady_state) and FixedLag (new,
//! from_parts_f32/_f64; on the model and on the augmented model); S = 2, 4, I = 1,
//! O = 1 … 3; f32, f64.
//!
//! The decoder and the checks every target shares are in `common.rs`.

use std::fmt::Debug;

use aemstep::estimation::augmented::AugmentedModel;
use aemstep::estimation::dual::{DualFilter, DualGains, DualKalmanFilter};
use aemstep::estimation::smoother::{FixedLag, FixedLagState};
use aemstep::estimation::{
    InputModel, InputStateFilter, InputStateGains, InputStateObserver, JointEstimate,
    STEADY_MAX_ITERATIONS,
};
use aemstep::nalgebra::{SMatrix, SVector};
use aemstep::observer::{Measurement, Outputs, StateSpace, SteadyState};
use aemstep::{Error, Real, StepState};

use super::common::*;

const ES: &str = "estimation";

/// Target `estimation`.
pub fn estimation(data: &[u8]) {
    let mut b = Bytes::new(data);
    match b.pick(5) {
        0 => sized::<1, 2, 3, 1>(&mut b),
        1 => sized::<1, 2, 3, 2>(&mut b),
        2 => sized::<2, 4, 5, 1>(&mut b),
        3 => sized::<2, 4, 5, 2>(&mut b),
        _ => sized::<2, 4, 5, 3>(&mut b),
    }
    count(ES, b.category());
}

/// The `Debug` text of `x` has no NaN or infinity (every float of a built operator).
pub(super) fn debug_finite<X: Debug>(x: &X) -> bool {
    let s = format!("{x:?}");
    !(s.contains("NaN") || s.contains("inf"))
}

/// `a` has a diagonal entry that no tolerance of a covariance test accepts: NaN, or below
/// `−(16 N ε max|a| + MIN_POSITIVE)` twice over (or `≤ 0` where `definite`).
fn clearly_not_cov<const N: usize>(a: &SMatrix<f64, N, N>, definite: bool) -> bool {
    if !all_finite(a.as_slice()) {
        return true;
    }
    let tol = 2.0 * (16.0 * N as f64 * f64::EPSILON * a.amax() + f64::MIN_POSITIVE);
    (0..N).any(|i| {
        let d = a[(i, i)];
        if definite { d <= 0.0 } else { d < -tol }
    })
}

/// The f32 twin of a constructor that does not check `h`: the same error, except that
/// `f32` may overflow where `f64` fits or overflows.
fn twins_no_h(name: &str, e64: Option<Error>, e32: Option<Error>) {
    let ok = e32 == e64
        || (e32 == Some(Error::OperatorOverflow)
            && (e64.is_none() || e64 == Some(Error::OperatorOverflow)));
    check!(ok, "{ES}: {name}: f64 gave {e64:?}, f32 gave {e32:?}");
}

fn err<X>(r: &Result<X, Error>) -> Option<Error> {
    r.as_ref().err().copied()
}

fn sized<const N: usize, const S: usize, const Z: usize, const O: usize>(b: &mut Bytes) {
    let s = b.system::<N>();
    let bm: SMatrix<f64, N, 1> = b.matrix();
    let mut out = Outputs::<N, 1, O>::zero();
    match b.pick(4) {
        0 => out.u = rows(&b.matrix::<O, N>()),
        1 => {
            out.u = rows(&b.matrix::<O, N>());
            out.a = rows(&b.matrix::<O, N>());
        }
        2 => {
            out.a = rows(&b.matrix::<O, N>());
            out.w = rows(&b.matrix::<O, 1>());
        }
        _ => {
            // The identifiable layout: a displacement, then accelerations.
            out.u[0][0] = 1.0;
            for o in 1..O {
                out.a[o][(o + N - 1) % N] = 1.0;
            }
            if O == 1 {
                out.a[0][N - 1] = 1.0;
            }
        }
    }
    // One operator entry replaced by a decoded value (0: none).
    let poke = b.pick(8);
    let poked = b.value();
    let q = covariance::<S>(b);
    let r = covariance::<O>(b);
    let qw = covariance::<1>(b);
    let gain_poke = b.pick(6);
    let gain_value = b.value();
    let x0 = b.vector::<S>();
    let w0 = b.vector::<1>();
    let p0 = covariance::<S>(b);
    let ys = [
        b.vector::<O>(),
        SVector::from_element(f64::NAN),
        b.vector::<O>(),
        b.vector::<O>(),
    ];
    let ws = [b.vector::<1>(), b.vector::<1>()];
    count(ES, "inputs");
    set_context(format!(
        "N = {N}, O = {O}, M = {:?}, C = {:?}, K = {:?}, h = {:e}, B = {:?}, outputs = {out:?}, poke = {poke} {poked:e}, Q = {:?}, R = {:?}, Qw = {:?}, gain poke = {gain_poke} {gain_value:e}, x0 = {:?}, w0 = {:?}, P0 = {:?}, y = {ys:?}, w = {ws:?}",
        s.m.as_slice(),
        s.c.as_slice(),
        s.k.as_slice(),
        s.h,
        bm.as_slice(),
        q.as_slice(),
        r.as_slice(),
        qw.as_slice(),
        x0.as_slice(),
        w0.as_slice(),
        p0.as_slice()
    ));
    // The model: the AEM state space of the data, else of a unit oscillator (so that the
    // estimators are reached), with one entry poked.
    let ss = StateSpace::<N, S, 1>::aem(&s.m, &s.c, &s.k, &bm, s.h);
    outcome(ES, &ss);
    let mut ss = match ss {
        Ok(ss) => ss,
        Err(_) => StateSpace::<N, S, 1>::aem(
            &SMatrix::identity(),
            &SMatrix::zeros(),
            &SMatrix::identity(),
            &SMatrix::from_element(1.0),
            0.05,
        )
        .expect("the unit oscillator"),
    };
    let meas = ss.outputs(&out);
    outcome(ES, &meas);
    let mut meas = match meas {
        Ok(m) => m,
        Err(e) => {
            let data = out.u.iter().chain(&out.v).chain(&out.a).flatten();
            check!(
                e != Error::NonFiniteInput
                    || !data.chain(out.w.iter().flatten()).all(|x| x.is_finite()),
                "{ES}: outputs of finite weights gave {e:?}"
            );
            Measurement {
                h: rows(&SMatrix::<f64, O, S>::from_fn(|i, j| {
                    if i == 0 && j == 0 { 1.0 } else { 0.0 }
                })),
                d: [[1.0]; O],
            }
        }
    };
    match poke {
        1 => ss.phi[S - 1][0] = poked,
        2 => ss.gamma0[0][0] = poked,
        3 => ss.gamma1[S - 1][0] = poked,
        4 => meas.h[O - 1][S - 1] = poked,
        5 => meas.d[0][0] = poked,
        _ => {}
    }
    let model_data_finite = [
        ss.phi.as_flattened(),
        ss.gamma0.as_flattened(),
        ss.gamma1.as_flattened(),
        meas.h.as_flattened(),
        meas.d.as_flattened(),
    ]
    .iter()
    .all(|x| all_finite(x));
    let model = InputModel::from_parts(&ss, &meas);
    outcome(ES, &model);
    check!(
        (err(&model) == Some(Error::NonFiniteInput)) != model_data_finite,
        "{ES}: InputModel::from_parts gave {:?} (data finite: {model_data_finite})",
        err(&model)
    );
    if model_data_finite {
        // More inputs than measurements: not identifiable.
        let two = StateSpace::<N, S, 2> {
            phi: ss.phi,
            gamma0: core::array::from_fn(|i| [ss.gamma0[i][0]; 2]),
            gamma1: core::array::from_fn(|i| [ss.gamma1[i][0]; 2]),
            dof_u: ss.dof_u,
            dof_v: ss.dof_v,
            dof_a: ss.dof_a,
            dof_a_input: core::array::from_fn(|i| [ss.dof_a_input[i][0]; 2]),
            time_step: ss.time_step,
        };
        let m1 = Measurement::<S, 2, 1> {
            h: [meas.h[0]],
            d: [[meas.d[0][0]; 2]],
        };
        check!(
            err(&InputModel::from_parts(&two, &m1)) == Some(Error::InputNotIdentifiable),
            "{ES}: O < I accepted"
        );
    }
    let Ok(model) = model else {
        return;
    };
    check!(
        debug_finite(&model),
        "{ES}: InputModel Ok, not finite: {model:?}"
    );

    // The identifiability of D̃ and R: the same verdict from every constructor that tests it.
    let zd = model.zero_dynamics(&r);
    outcome(ES, &zd);
    if let Ok(z) = &zd {
        check!(
            all_finite(z.as_slice()),
            "{ES}: zero_dynamics Ok, not finite: {z:?}"
        );
    }
    let filter64 = InputStateFilter::<f64, S, 1, O>::new(&model, &q, &r);
    let filter32 = InputStateFilter::<f32, S, 1, O>::new(&model, &q, &r);
    outcome(ES, &filter64);
    outcome(ES, &filter32);
    twins_no_h("InputStateFilter::new", err(&filter64), err(&filter32));
    let q_bad = clearly_not_cov(&q, false);
    let r_bad = clearly_not_cov(&r, true);
    if q_bad {
        check!(
            err(&filter64) == Some(Error::InvalidCovariance),
            "{ES}: InputStateFilter with a bad Q gave {:?}",
            err(&filter64)
        );
    }
    // The filter tests Q, then R and D̃ as zero_dynamics does (which then forms Ā).
    match err(&zd) {
        Some(e @ (Error::InvalidCovariance | Error::InputNotIdentifiable)) => check!(
            err(&filter64) == Some(e) || err(&filter64) == Some(Error::InvalidCovariance),
            "{ES}: zero_dynamics gave {e:?}, InputStateFilter {:?}",
            err(&filter64)
        ),
        None => check!(
            err(&filter64).is_none() || err(&filter64) == Some(Error::InvalidCovariance),
            "{ES}: zero_dynamics Ok, InputStateFilter {:?}",
            err(&filter64)
        ),
        _ => {}
    }
    if r_bad {
        check!(
            err(&zd) == Some(Error::InvalidCovariance),
            "{ES}: zero_dynamics with a bad R gave {:?}",
            err(&zd)
        );
    }

    // The steady gains.
    let gains = InputStateGains::new(&model, &q, &r);
    let solved = InputStateGains::solve(&model, &rows(&q), &rows(&r));
    outcome(ES, &gains);
    check!(
        bits(&gains) == bits(&solved),
        "{ES}: InputStateGains::new differs from solve"
    );
    if q_bad || r_bad {
        check!(
            err(&gains) == Some(Error::InvalidCovariance),
            "{ES}: InputStateGains with a bad Q or R gave {:?}",
            err(&gains)
        );
    }
    if matches!(
        err(&filter64),
        Some(Error::InvalidCovariance | Error::InputNotIdentifiable)
    ) {
        check!(
            err(&gains) == err(&filter64),
            "{ES}: InputStateGains gave {:?}, InputStateFilter {:?}",
            err(&gains),
            err(&filter64)
        );
    }
    if let Ok(g) = &gains {
        let p = g.covariance_matrix();
        let pw = g.input_covariance_matrix();
        check!(
            all_finite(p.as_slice())
                && all_finite(g.state_gain_matrix().as_slice())
                && all_finite(g.input_gain_matrix().as_slice())
                && all_finite(pw.as_slice())
                && p == p.transpose()
                && g.iterations <= STEADY_MAX_ITERATIONS,
            "{ES}: InputStateGains Ok, not finite or not symmetric: {g:?}"
        );
        let mut g = *g;
        match gain_poke {
            1 => g.state_gain[S - 1][O - 1] = gain_value,
            2 => g.input_gain[0][O - 1] = gain_value,
            _ => {}
        }
        let gains_finite =
            all_finite(g.state_gain.as_flattened()) && all_finite(g.input_gain.as_flattened());
        let o64 = InputStateObserver::<f64, S, 1, O>::new(&model, &g);
        let o32 = InputStateObserver::<f32, S, 1, O>::new(&model, &g);
        outcome(ES, &o64);
        outcome(ES, &o32);
        check!(
            bits(&o64) == bits(&InputStateObserver::from_parts_f64(&model, &g))
                && bits(&o32) == bits(&InputStateObserver::from_parts_f32(&model, &g)),
            "{ES}: InputStateObserver::from_parts differs from new"
        );
        twins(
            ES,
            model.time_step,
            "InputStateObserver",
            err(&o64),
            err(&o32),
        );
        check!(
            gains_finite || err(&o64) == Some(Error::NonFiniteInput),
            "{ES}: InputStateObserver with a non-finite gain gave {:?}",
            err(&o64)
        );
        if let Ok(o) = &o64 {
            joint_observer(o, &x0, &w0, &ys);
        }
        if let Ok(o) = &o32 {
            joint_observer(o, &x0, &w0, &ys);
        }
    }
    if let Ok(f) = &filter64 {
        time_varying(f, &x0, &p0, &w0, &ys);
    }
    if let Ok(f) = &filter32 {
        time_varying(f, &x0, &p0, &w0, &ys);
    }

    // The dual filter.
    let dual = DualGains::new(&model, &q, &qw, &r);
    outcome(ES, &dual);
    check!(
        bits(&dual) == bits(&DualGains::solve(&model, &rows(&q), &rows(&qw), &rows(&r))),
        "{ES}: DualGains::new differs from solve"
    );
    check!(
        !q_bad || dual.is_err(),
        "{ES}: DualGains with a bad Q accepted"
    );
    if r_bad || clearly_not_cov(&qw, false) {
        check!(
            err(&dual) == Some(Error::InvalidCovariance),
            "{ES}: DualGains with a bad covariance gave {:?}",
            err(&dual)
        );
    }
    if let Ok(dg) = &dual {
        check!(debug_finite(dg), "{ES}: DualGains Ok, not finite: {dg:?}");
        let mut dg = *dg;
        match gain_poke {
            3 => dg.input.gain[0][O - 1] = gain_value,
            4 => dg.state.gain[S - 1][0] = gain_value,
            _ => {}
        }
        let d64 = DualFilter::<f64, S, 1, O>::new(&model, &dg);
        let d32 = DualFilter::<f32, S, 1, O>::new(&model, &dg);
        outcome(ES, &d64);
        outcome(ES, &d32);
        check!(
            bits(&d64) == bits(&DualFilter::from_parts_f64(&model, &dg))
                && bits(&d32) == bits(&DualFilter::from_parts_f32(&model, &dg)),
            "{ES}: DualFilter::from_parts differs from new"
        );
        twins(ES, model.time_step, "DualFilter", err(&d64), err(&d32));
        if !(all_finite(dg.input.gain.as_flattened()) && all_finite(dg.state.gain.as_flattened())) {
            check!(
                err(&d64) == Some(Error::NonFiniteInput),
                "{ES}: DualFilter with a non-finite gain gave {:?}",
                err(&d64)
            );
        }
        if let Ok(d) = &d64 {
            dual_filter(d, &x0, &w0, &ys);
        }
        if let Ok(d) = &d32 {
            dual_filter(d, &x0, &w0, &ys);
        }
    }

    // The time-varying dual filter: the same covariances' verdict as DualGains where it is
    // about them, and the checked-step contract.
    let tv64 = DualKalmanFilter::<f64, S, 1, O>::new(&model, &q, &qw, &r);
    let tv32 = DualKalmanFilter::<f32, S, 1, O>::new(&model, &q, &qw, &r);
    outcome(ES, &tv64);
    outcome(ES, &tv32);
    // (It tests its covariances first, before the time step in `T`.)
    if err(&tv64) == Some(Error::InvalidCovariance) {
        check!(
            err(&tv32) == Some(Error::InvalidCovariance),
            "{ES}: DualKalmanFilter: f64 gave InvalidCovariance, f32 {:?}",
            err(&tv32)
        );
    } else {
        twins(
            ES,
            model.time_step,
            "DualKalmanFilter",
            err(&tv64),
            err(&tv32),
        );
    }
    if q_bad || r_bad || clearly_not_cov(&qw, false) {
        check!(
            err(&tv64) == Some(Error::InvalidCovariance),
            "{ES}: DualKalmanFilter with a bad covariance gave {:?}",
            err(&tv64)
        );
    }
    if let Ok(f) = &tv64 {
        dual_time_varying(f, &x0, &w0, &ys);
    }
    if let Ok(f) = &tv32 {
        dual_time_varying(f, &x0, &w0, &ys);
    }

    // The augmented model, its steady state and the fixed-lag smoother on it.
    check!(
        err(&AugmentedModel::<S, 1, S, O>::from_parts(
            &model,
            &rows(&q),
            &rows(&qw)
        )) == Some(Error::StateSizeMismatch),
        "{ES}: AugmentedModel with Z ≠ S + I accepted"
    );
    let aug = AugmentedModel::<S, 1, Z, O>::from_parts(&model, &rows(&q), &rows(&qw));
    outcome(ES, &aug);
    if q_bad || clearly_not_cov(&qw, false) {
        check!(
            err(&aug) == Some(Error::InvalidCovariance),
            "{ES}: AugmentedModel with a bad covariance gave {:?}",
            err(&aug)
        );
    }
    if let Ok(aug) = &aug {
        check!(debug_finite(aug), "{ES}: AugmentedModel Ok, not finite");
        let st = aug.steady_state(&rows(&r));
        outcome(ES, &st);
        if r_bad {
            check!(
                err(&st) == Some(Error::InvalidCovariance),
                "{ES}: augmented steady_state with a bad R gave {:?}",
                err(&st)
            );
        }
        if let Ok(st) = &st {
            check!(
                debug_finite(st),
                "{ES}: augmented steady state Ok, not finite: {st:?}"
            );
            let zs = [SVector::<f64, 0>::zeros(); 2];
            fixed_lag::<0, Z, 0, O>(
                &aug.model,
                &aug.measurement,
                st,
                &r,
                &x0_z::<S, Z>(&x0),
                &zs,
                &ys,
            );
        }
    }
    // The smoother on the model itself (a known input).
    let st = SteadyState::new(&ss, &meas, &q, &r);
    outcome(ES, &st);
    if let Ok(st) = &st {
        fixed_lag::<N, S, 1, O>(&ss, &meas, st, &r, &x0, &ws, &ys);
    }
}

/// `[x0; 0]` of the augmented state.
fn x0_z<const S: usize, const Z: usize>(x0: &SVector<f64, S>) -> SVector<f64, Z> {
    SVector::from_fn(|i, _| if i < S { x0[i] } else { 0.0 })
}

/// The checked-step contract of a fixed-gain joint estimator (`InputStateObserver`,
/// `DualFilter`): `Ok` ⇒ the unchecked step, finite, one more step; `Err` ⇒
/// `NonFiniteState`, the estimate bit-identical; a NaN measurement counted, the input
/// estimate held.
fn joint_steps<T: Real, const S: usize, const I: usize, const O: usize>(
    name: &str,
    e: &mut JointEstimate<T, S, I>,
    ys: &[SVector<f64, O>],
    step: impl Fn(&mut JointEstimate<T, S, I>, &SVector<T, O>),
    try_step: impl Fn(&mut JointEstimate<T, S, I>, &SVector<T, O>) -> Result<(), Error>,
) {
    for y in ys {
        let y = to_t::<T, O, 1>(y);
        let before = bits(e);
        let input = bits(e.input());
        let (n, missing) = (e.steps(), e.missing());
        let mut unchecked = *e;
        step(&mut unchecked, &y);
        let measured = finite(&y);
        check!(
            unchecked.missing() == missing + u64::from(!measured)
                && unchecked.steps() == n + 1
                && (measured || bits(unchecked.input()) == input),
            "{ES}: {name}: a missing sample not counted or its input not held: {unchecked:?}"
        );
        count(ES, "checked steps");
        match try_step(e, &y) {
            Ok(()) => check!(
                e.is_finite() && bits(e) == bits(&unchecked),
                "{ES}: {name}: Ok step differs from the unchecked one or is not finite: {e:?}"
            ),
            Err(err) => {
                count(ES, "failed checked steps");
                check!(
                    bits(e) == before,
                    "{ES}: {name}: failed step ({err:?}) changed the estimate"
                );
                check!(
                    err == Error::NonFiniteState && !unchecked.is_finite(),
                    "{ES}: {name}: step gave {err:?} (unchecked finite: {})",
                    unchecked.is_finite()
                );
            }
        }
    }
}

/// A start from `x0, w0`: a non-finite one is `NonFiniteInput`, an `Ok` one finite.
fn joint_start<T: Real, const S: usize, const I: usize>(
    name: &str,
    r: Result<JointEstimate<T, S, I>, Error>,
    x0: &SVector<T, S>,
    w0: &SVector<T, I>,
) -> Option<JointEstimate<T, S, I>> {
    match r {
        Ok(e) => {
            check!(
                finite(x0) && finite(w0) && e.is_finite() && e.steps() == 0,
                "{ES}: {name}: start Ok from non-finite data or not finite: {e:?}"
            );
            Some(e)
        }
        Err(err) => {
            check!(
                err == Error::NonFiniteInput,
                "{ES}: {name}: start gave {err:?}"
            );
            None
        }
    }
}

fn joint_observer<T: Real, const S: usize, const O: usize>(
    o: &InputStateObserver<T, S, 1, O>,
    x0: &SVector<f64, S>,
    w0: &SVector<f64, 1>,
    ys: &[SVector<f64, O>],
) {
    check!(
        debug_finite(o) && o.time_step().is_finite() && o.time_step() > T::zero(),
        "{ES}: InputStateObserver Ok, not finite: {o:?}"
    );
    let (x, w) = (to_t::<T, S, 1>(x0), to_t::<T, 1, 1>(w0));
    let mut e = joint_start("InputStateObserver", o.start(&x, &w), &x, &w)
        .unwrap_or_else(|| o.start_at_rest());
    joint_steps(
        "InputStateObserver",
        &mut e,
        ys,
        |e, y| o.step(e, y),
        |e, y| o.try_step(e, y),
    );
}

fn dual_filter<T: Real, const S: usize, const O: usize>(
    d: &DualFilter<T, S, 1, O>,
    x0: &SVector<f64, S>,
    w0: &SVector<f64, 1>,
    ys: &[SVector<f64, O>],
) {
    check!(
        debug_finite(d) && d.time_step().is_finite() && d.time_step() > T::zero(),
        "{ES}: DualFilter Ok, not finite: {d:?}"
    );
    let (x, w) = (to_t::<T, S, 1>(x0), to_t::<T, 1, 1>(w0));
    let Some(mut e) = joint_start("DualFilter", d.start(&x, &w), &x, &w)
        .or_else(|| d.start(&SVector::zeros(), &SVector::zeros()).ok())
    else {
        panic!(
            "property broken: {ES}: DualFilter could not start at rest\n  data: {}",
            context()
        );
    };
    joint_steps(
        "DualFilter",
        &mut e,
        ys,
        |e, y| d.step(e, y),
        |e, y| d.try_step(e, y),
    );
}

fn time_varying<T: Real, const S: usize, const O: usize>(
    f: &InputStateFilter<T, S, 1, O>,
    x0: &SVector<f64, S>,
    p0: &SMatrix<f64, S, S>,
    w0: &SVector<f64, 1>,
    ys: &[SVector<f64, O>],
) {
    check!(debug_finite(f), "{ES}: InputStateFilter Ok, not finite");
    let (x, w, p) = (
        to_t::<T, S, 1>(x0),
        to_t::<T, 1, 1>(w0),
        to_t::<T, S, S>(p0),
    );
    let pw = SMatrix::<T, 1, 1>::identity();
    let st = f.start(&x, &p, &w, &pw);
    if !(finite(&x) && finite(&w)) {
        check!(
            err(&st) == Some(Error::NonFiniteInput),
            "{ES}: InputStateFilter start from non-finite data gave {:?}",
            err(&st)
        );
    } else if !finite(&p) {
        // (`ξ̂₀ = x0 − Γ₁ w0` not finite is `NonFiniteInput` first.)
        check!(
            matches!(
                err(&st),
                Some(Error::InvalidCovariance | Error::NonFiniteInput)
            ),
            "{ES}: InputStateFilter start with a non-finite P0 gave {:?}",
            err(&st)
        );
    }
    let Ok(mut s) = st.or_else(|_| {
        f.start(
            &SVector::zeros(),
            &SMatrix::identity(),
            &SVector::zeros(),
            &pw,
        )
    }) else {
        panic!(
            "property broken: {ES}: InputStateFilter could not start at rest with P = I\n  data: {}",
            context()
        );
    };
    for y in ys {
        let y = to_t::<T, O, 1>(y);
        let before = bits(&s);
        let held = bits(&(
            s.estimate().input(),
            s.input_covariance(),
            s.cross_covariance(),
        ));
        let (n, missing) = (s.estimate().steps(), s.estimate().missing());
        count(ES, "checked steps");
        match f.try_step(&mut s, &y) {
            Ok(()) => {
                let e = s.estimate();
                check!(
                    e.is_finite()
                        && finite(s.covariance())
                        && finite(s.input_covariance())
                        && finite(s.cross_covariance())
                        && e.steps() == n + 1,
                    "{ES}: InputStateFilter Ok step not finite: {s:?}"
                );
                if finite(&y) {
                    check!(
                        e.missing() == missing,
                        "{ES}: InputStateFilter: a sample counted missing"
                    );
                } else {
                    check!(
                        e.missing() == missing + 1
                            && bits(&(e.input(), s.input_covariance(), s.cross_covariance()))
                                == held,
                        "{ES}: InputStateFilter: a missing sample not counted or its input not held"
                    );
                }
            }
            Err(err) => {
                count(ES, "failed checked steps");
                check!(
                    bits(&s) == before,
                    "{ES}: InputStateFilter failed step ({err:?}) changed the state"
                );
                check!(
                    err == Error::NonFiniteState || (err == Error::InvalidCovariance && finite(&y)),
                    "{ES}: InputStateFilter step gave {err:?}"
                );
            }
        }
    }
}

/// `DualKalmanFilter`: starts (typed errors for non-finite data and covariances), then the
/// checked steps: `Ok` ⇒ finite, one more step, a missing sample counted with the input
/// held; `Err` ⇒ the state bit-identical.
fn dual_time_varying<T: Real, const S: usize, const O: usize>(
    f: &DualKalmanFilter<T, S, 1, O>,
    x0: &SVector<f64, S>,
    w0: &SVector<f64, 1>,
    ys: &[SVector<f64, O>],
) {
    check!(debug_finite(f), "{ES}: DualKalmanFilter Ok, not finite");
    let (x, w) = (to_t::<T, S, 1>(x0), to_t::<T, 1, 1>(w0));
    let (p, pw) = (
        SMatrix::<T, S, S>::identity(),
        SMatrix::<T, 1, 1>::identity(),
    );
    let st = f.start(&x, &p, &w, &pw);
    if !(finite(&x) && finite(&w)) {
        check!(
            err(&st) == Some(Error::NonFiniteInput),
            "{ES}: DualKalmanFilter start from non-finite data gave {:?}",
            err(&st)
        );
    }
    let mut bad_p = p;
    bad_p[(0, 0)] = T::from_f64_rounded(f64::NAN);
    check!(
        matches!(
            err(&f.start(&SVector::zeros(), &bad_p, &SVector::zeros(), &pw)),
            Some(Error::InvalidCovariance)
        ),
        "{ES}: DualKalmanFilter start with a NaN P0 accepted"
    );
    let Ok(mut s) = st.or_else(|_| f.start(&SVector::zeros(), &p, &SVector::zeros(), &pw)) else {
        panic!(
            "property broken: {ES}: DualKalmanFilter could not start at rest with P = I\n  data: {}",
            context()
        );
    };
    for y in ys {
        let y = to_t::<T, O, 1>(y);
        let before = bits(&s);
        let held = bits(s.estimate().input());
        let (n, missing) = (s.estimate().steps(), s.estimate().missing());
        count(ES, "checked steps");
        match f.try_step(&mut s, &y) {
            Ok(()) => {
                let e = s.estimate();
                check!(
                    e.is_finite()
                        && finite(s.covariance())
                        && finite(s.input_covariance())
                        && e.steps() == n + 1,
                    "{ES}: DualKalmanFilter Ok step not finite: {s:?}"
                );
                if finite(&y) {
                    check!(
                        e.missing() == missing,
                        "{ES}: DualKalmanFilter: a sample counted missing"
                    );
                } else {
                    check!(
                        e.missing() == missing + 1 && bits(e.input()) == held,
                        "{ES}: DualKalmanFilter: a missing sample not counted or its input not held"
                    );
                }
            }
            Err(err) => {
                count(ES, "failed checked steps");
                check!(
                    bits(&s) == before,
                    "{ES}: DualKalmanFilter failed step ({err:?}) changed the state"
                );
                check!(
                    err == Error::NonFiniteState || (err == Error::InvalidCovariance && finite(&y)),
                    "{ES}: DualKalmanFilter step gave {err:?}"
                );
            }
        }
    }
}

/// `FixedLag` (lag 2) in `f64` and `f32`: `new` against `from_parts`, the twins' errors,
/// and the checked steps.
fn fixed_lag<const N: usize, const S: usize, const I: usize, const O: usize>(
    ss: &StateSpace<N, S, I>,
    meas: &Measurement<S, I, O>,
    st: &SteadyState<S, O>,
    r: &SMatrix<f64, O, O>,
    x0: &SVector<f64, S>,
    ws: &[SVector<f64, I>],
    ys: &[SVector<f64, O>],
) {
    let l64 = FixedLag::<f64, S, I, O, 2>::new(ss, meas, st, r);
    let l32 = FixedLag::<f32, S, I, O, 2>::new(ss, meas, st, r);
    outcome(ES, &l64);
    outcome(ES, &l32);
    check!(
        bits(&l64)
            == bits(&FixedLag::<f64, S, I, O, 2>::from_parts_f64(
                ss,
                meas,
                st,
                &rows(r)
            ))
            && bits(&l32)
                == bits(&FixedLag::<f32, S, I, O, 2>::from_parts_f32(
                    ss,
                    meas,
                    st,
                    &rows(r)
                )),
        "{ES}: FixedLag::from_parts differs from new"
    );
    twins_no_h("FixedLag::new", err(&l64), err(&l32));
    if let Ok(l) = &l64 {
        lag_steps(l, x0, ws, ys);
    }
    if let Ok(l) = &l32 {
        lag_steps(l, x0, ws, ys);
    }
}

fn lag_steps<T: Real, const S: usize, const I: usize, const O: usize>(
    l: &FixedLag<T, S, I, O, 2>,
    x0: &SVector<f64, S>,
    ws: &[SVector<f64, I>],
    ys: &[SVector<f64, O>],
) {
    check!(debug_finite(l), "{ES}: FixedLag Ok, not finite: {l:?}");
    let x = to_t::<T, S, 1>(x0);
    let s: Result<FixedLagState<T, S, I, 2>, Error> = l.start(&x, &SVector::zeros());
    check!(
        finite(&x) == s.is_ok() && (s.is_ok() || err(&s) == Some(Error::NonFiniteInput)),
        "{ES}: FixedLag start gave {:?}",
        err(&s)
    );
    let mut s = s.unwrap_or_else(|_| {
        l.start(&SVector::zeros(), &SVector::zeros())
            .expect("a start at rest")
    });
    for (k, y) in ys.iter().enumerate() {
        let w = to_t::<T, I, 1>(&ws[k % ws.len()]);
        let y = to_t::<T, O, 1>(y);
        let before = bits(&s);
        let (n, missing) = (s.steps(), s.missing());
        count(ES, "checked steps");
        match l.try_step(&mut s, &w, &y) {
            Ok(()) => check!(
                finite(&w)
                    && s.is_finite()
                    && s.steps() == n + 1
                    && s.missing() == missing + u64::from(!finite(&y)),
                "{ES}: FixedLag Ok step: {s:?}"
            ),
            Err(err) => {
                count(ES, "failed checked steps");
                check!(
                    bits(&s) == before,
                    "{ES}: FixedLag failed step ({err:?}) changed the state"
                );
                let want = if finite(&w) {
                    Error::NonFiniteState
                } else {
                    Error::NonFiniteInput
                };
                check!(
                    err == want,
                    "{ES}: FixedLag step gave {err:?}, want {want:?}"
                );
            }
        }
    }
}
