//! Fuzz target `control` (`fuzz_targets/control.rs`): checks the vibration-control family
//! (issue 33): `Lqr` (`from_parts`, `new`, on a model and its delayed form), `Controller`
//! (`new` on an observer of a zero-order-hold model; `try_step`), `MrDamper` (`new`,
//! trials), `Coupled` (a 1- or 2-DOF `LinearStructure` with an MR damper: `new`,
//! `passive_on`, `set_command`, the `Nonlinear` stepper's start and checked steps) and
//! `ClippedOptimal` (`new`, `command`), f64, with weights, gains, commands, measurements
//! and device parameters from the bytes (NaN, ±∞, extremes included).
//!
//! Beyond the properties every target checks (`mod.rs`): an `Lqr` that is `Ok` has a
//! finite gain, cost and closed loop, `radius_bound` in `[0, 1)`, `new` and `from_parts`
//! agree bit for bit, and the closed loop's eigenvalues (nalgebra, independent) lie within
//! the bound (to the eigen-solver's rounding); a failed `Controller::try_step`,
//! `Coupled::set_command` or checked coupled step changes nothing (state, history,
//! command), a successful one gives a finite output within the force limit, holding the
//! last output unless computed; `ClippedOptimal::command` is `V_max` exactly where the
//! desired force exceeds the measured one in the measured force's direction (signs alone),
//! `0` elsewhere, and refuses non-finite input with `NonFiniteInput`.
//!
//! The decoder and the checks every target shares are in `common.rs`.

use aemstep::control::{
    ClippedOptimal, Command, Controller, Coupled, DesignModel, Device, LinearStructure, Link, Lqr,
    MrDamper, MrParameters, Status, Weights,
};
use aemstep::hysteresis::HistoryModel;
use aemstep::nalgebra::{DMatrix, SMatrix, SVector};
use aemstep::observer::{Observer, Outputs, StateSpace};
use aemstep::{Error, NewtonSettings};

use super::common::*;

const CTL: &str = "control";

/// Target `control`.
pub fn control(data: &[u8]) {
    let mut b = Bytes::new(data);
    match b.pick(4) {
        0 => {
            lqr_checks::<2, 1, 3>(&mut b);
            controller_checks(&mut b);
        }
        1 => {
            lqr_checks::<1, 1, 2>(&mut b);
            clipped_checks::<1>(&mut b);
        }
        2 => coupled_checks::<1>(&mut b),
        _ => {
            coupled_checks::<2>(&mut b);
            clipped_checks::<2>(&mut b);
        }
    }
    count(CTL, "inputs");
    count(CTL, b.category());
}

/// Bit-level equality of plain data (`Debug` prints every `f64` exactly, `-0.0` and `NaN`
/// included).
fn same<X: core::fmt::Debug>(a: &X, b: &X) -> bool {
    format!("{a:?}") == format!("{b:?}")
}

/// The largest `|λ|` of `a` (nalgebra's Schur form), `None` if it does not converge.
fn spectral_radius<const S: usize>(a: &[[f64; S]; S]) -> Option<f64> {
    let m = DMatrix::<f64>::from_fn(S, S, |i, j| a[i][j]);
    let schur = aemstep::nalgebra::Schur::try_new(m, f64::EPSILON, 1000 * S)?;
    Some(
        schur
            .complex_eigenvalues()
            .iter()
            .map(|l| l.norm())
            .fold(0.0, f64::max),
    )
}

fn design<const S: usize, const I: usize>(b: &mut Bytes) -> (DesignModel<S, I>, Weights<S, I>) {
    let model = DesignModel {
        phi: rows(&b.matrix::<S, S>()),
        gamma: rows(&b.matrix::<S, I>()),
    };
    let cross = if b.flag() {
        SMatrix::<f64, S, I>::zeros()
    } else {
        b.matrix::<S, I>()
    };
    let weights = Weights {
        q: rows(&covariance::<S>(b)),
        r: rows(&covariance::<I>(b)),
        cross: rows(&cross),
    };
    (model, weights)
}

fn check_lqr<const S: usize, const I: usize>(what: &str, r: &Result<Lqr<S, I>, Error>) {
    outcome(CTL, r);
    let Ok(l) = r else { return };
    let finite = l.gain.iter().flatten().all(|x| x.is_finite())
        && l.cost.iter().flatten().all(|x| x.is_finite())
        && l.closed_loop.iter().flatten().all(|x| x.is_finite());
    check!(
        finite,
        "{what}: Ok with a non-finite gain, cost or closed loop: {l:?}"
    );
    // The documented contract (`Lqr::radius_bound`: `< 1`, else `NotStabilizing`). A seed-1
    // run found `Lqr::from_parts` Ok with a bound of 1.0000000000000002 for Φ = [[1]],
    // Γ = [[-8.985290527343751e-18]], Q = [[0.10941138105771858]], R = [[1e-6]] (a marginal
    // mode the input barely reaches): fixed, kept in fuzz/regressions/control/ and
    // tests/control_lqr.rs (`bound_that_rounds_up_to_one_is_refused`).
    check!(
        l.radius_bound >= 0.0 && l.radius_bound < 1.0,
        "{what}: radius bound {} outside [0, 1)",
        l.radius_bound
    );
    if let Some(rho) = spectral_radius(&l.closed_loop) {
        let scale = l
            .closed_loop
            .iter()
            .flatten()
            .map(|x| x * x)
            .sum::<f64>()
            .sqrt();
        // The eigen-solver's rounding (sqrt(ε) for a defective pair).
        let tol = 1e-6 * scale.max(1.0);
        check!(
            rho <= l.radius_bound + tol,
            "{what}: spectral radius {rho} above the certified bound {}",
            l.radius_bound
        );
        count(CTL, "lqr radius checked");
    }
}

fn lqr_checks<const S: usize, const I: usize, const Z: usize>(b: &mut Bytes) {
    let (model, weights) = design::<S, I>(b);
    set_context(format!("lqr {S}x{I}: {model:?} {weights:?}"));
    let r = Lqr::from_parts(&model, &weights);
    check_lqr("Lqr::from_parts", &r);
    let phi = SMatrix::<f64, S, S>::from_fn(|i, j| model.phi[i][j]);
    let gamma = SMatrix::<f64, S, I>::from_fn(|i, j| model.gamma[i][j]);
    let r2 = Lqr::new(&phi, &gamma, &weights);
    check!(
        same(&r, &r2),
        "Lqr::new differs from from_parts: {r:?} against {r2:?}"
    );
    // The delayed design, with a decision weight from the data.
    if let Ok(dm) = model.delayed::<Z>() {
        let decision = rows(&covariance::<I>(b));
        match weights.delayed::<Z>(&decision) {
            Ok(w) => check_lqr("Lqr::from_parts (delayed)", &Lqr::from_parts(&dm, &w)),
            Err(e) => check!(false, "Weights::delayed refused Z = S + I: {e:?}"),
        }
    } else {
        check!(false, "DesignModel::delayed refused Z = S + I");
    }
}

/// A 1-DOF zero-order-hold model from the data, its observer (velocity or displacement
/// measured, any gain), a controller (gain with or without the delay column, any limit),
/// and a run of steps with any measurements, forces and overrun flags.
fn controller_checks(b: &mut Bytes) {
    let (m, c, k) = (b.param(0.1, 1e3), b.param(0.0, 1e2), b.param(0.0, 1e5));
    let h = b.time_step();
    let force = b.value();
    let ss = StateSpace::<1, 2, 1>::zero_order_hold(
        &SMatrix::from([[m]]),
        &SMatrix::from([[c]]),
        &SMatrix::from([[k]]),
        &SMatrix::from([[1.0]]),
        h,
    );
    let ss = match ss {
        Ok(s) => s,
        Err(_) => {
            count(CTL, "controller: model rejected");
            return;
        }
    };
    let outputs = if b.flag() {
        Outputs::velocities([[1.0]])
    } else {
        Outputs::displacements([[1.0]])
    };
    let Ok(meas) = ss.outputs(&outputs) else {
        return;
    };
    let gain_l = SMatrix::<f64, 2, 1>::from_fn(|_, _| b.value());
    let Ok(observer) = Observer::<f64, 2, 1, 1>::new(&ss, &meas, &gain_l) else {
        count(CTL, "controller: observer rejected");
        return;
    };
    let limit = [b.param(1.0, 1e4)];
    let ctl = if b.flag() {
        Controller::new(
            observer,
            &SMatrix::<f64, 1, 2>::from_fn(|_, _| b.value()),
            &limit,
        )
    } else {
        Controller::new(
            observer,
            &SMatrix::<f64, 1, 3>::from_fn(|_, _| b.value()),
            &limit,
        )
    };
    set_context(format!(
        "controller: m {m} c {c} k {k} h {h} limit {limit:?} force {force}"
    ));
    outcome(CTL, &ctl);
    let Ok(ctl) = ctl else { return };
    let mut st = ctl.start_at_rest();
    for _ in 0..6 {
        let y = SVector::<f64, 1>::from([if b.flag() { b.ordinary() } else { b.value() }]);
        let f = SVector::<f64, 1>::from([if b.flag() { b.ordinary() } else { b.value() }]);
        let overrun = b.pick(4) == 0;
        let before = st;
        let r: Result<Command<f64, 1>, Error> = ctl.try_step(&mut st, &y, &f, overrun);
        match r {
            Err(e) => {
                check!(
                    same(&st, &before),
                    "Controller::try_step failed ({e:?}) and changed the state"
                );
                if !f[0].is_finite() {
                    check!(e == Error::NonFiniteInput, "non-finite force gave {e:?}");
                }
                count(CTL, "controller: step refused");
            }
            Ok(cmd) => {
                check!(f[0].is_finite(), "a non-finite measured force was accepted");
                let u = cmd.force[0];
                check!(
                    u.is_finite() && u.abs() <= limit[0],
                    "output {u} not finite or beyond the limit {}",
                    limit[0]
                );
                let expected = if !y[0].is_finite() {
                    Status::MissingSample
                } else if overrun {
                    Status::Overrun
                } else {
                    Status::Computed
                };
                check!(
                    cmd.status == expected,
                    "status {:?}, expected {expected:?}",
                    cmd.status
                );
                if cmd.status != Status::Computed {
                    check!(
                        cmd.force == *before.output(),
                        "a held output {u} is not the last safe output {:?}",
                        before.output()
                    );
                }
                check!(
                    *st.output() == cmd.force,
                    "the state's output is not the one returned"
                );
                count(CTL, "controller: step");
            }
        }
    }
}

/// MR damper parameters: mostly valid (around Dyke et al. 1996 as quoted), sometimes
/// anything.
fn mr_parameters(b: &mut Bytes) -> MrParameters {
    let g = b.param(1.0, 1e5);
    MrParameters {
        c0a: b.param(1.0, 1e4),
        c0b: b.param(0.0, 1e4),
        alpha_a: b.param(1e3, 1e6),
        alpha_b: b.param(0.0, 1e6),
        gamma: g,
        beta: if b.flag() { g * b.unit() } else { b.value() },
        a: b.param(0.1, 1e3),
        n: b.param(1.0, 3.0),
        eta: b.param(1.0, 200.0),
        v_max: b.param(0.5, 10.0),
    }
}

fn coupled_checks<const N: usize>(b: &mut Bytes) {
    let p = mr_parameters(b);
    let damper = MrDamper::<f64>::new(&p);
    outcome(CTL, &damper);
    if let Ok(d) = &damper {
        // Trials from rest with any data: no panic, and the same trial twice is the same.
        let (x, v, cmd, h) = (b.value(), b.value(), b.value(), b.time_step());
        let h0 = d.initial_history();
        let t1 = d.trial(&h0, x, v, cmd, h);
        let t2 = d.trial(&h0, x, v, cmd, h);
        check!(same(&t1, &t2), "MrDamper::trial is not a pure function");
    }
    let Ok(damper) = damper else { return };
    let sys = b.system::<N>();
    let structure = LinearStructure::<f64, N>::new(&rows(&sys.m), &rows(&sys.c), &rows(&sys.k));
    let Ok(structure) = structure else {
        count(CTL, "coupled: structure rejected");
        return;
    };
    let link = match b.pick(4) {
        0 | 1 => Link::Ground(usize::from(b.pick(3))),
        _ => Link::Between(usize::from(b.pick(3)), usize::from(b.pick(3))),
    };
    let h = if b.flag() { sys.h } else { b.time_step() };
    set_context(format!(
        "coupled N={N}: {p:?} {link:?} h {h} sys {:?}",
        (sys.m, sys.c, sys.k)
    ));
    let model = if b.flag() {
        Coupled::passive_on(structure, damper, link, h)
    } else {
        Coupled::new(structure, damper, link, h)
    };
    outcome(CTL, &model);
    let Ok(mut model) = model else { return };
    let Ok(stepper) = model.nonlinear(NewtonSettings::default()) else {
        return;
    };
    let zero = SVector::<f64, N>::zeros();
    let p0 = b.small_vector::<N>();
    let Ok((mut s, mut hist)) =
        stepper.start_with_history(&model, &zero, &zero, &p0, &model.initial_history())
    else {
        count(CTL, "coupled: start refused");
        return;
    };
    for _ in 0..5 {
        // A command, any value: clipped into [0, V_max], or refused with nothing changed.
        if b.flag() {
            let before = model.command();
            let cmd = b.value();
            match model.set_command(cmd) {
                Ok(held) => {
                    let (lo, hi) = model.device().command_limits();
                    check!(
                        held >= lo && held <= hi && held == model.command(),
                        "set_command held {held}"
                    );
                }
                Err(e) => {
                    check!(e == Error::NonFiniteInput, "set_command({cmd}) gave {e:?}");
                    check!(
                        same(&model.command(), &before),
                        "a refused command changed the command"
                    );
                }
            }
        }
        let load = if b.flag() {
            b.small_vector::<N>() * 1e3
        } else {
            b.vector::<N>()
        };
        let (s0, h0) = (s, hist);
        match stepper.try_step_with_history(&model, &mut s, &mut hist, &load) {
            Ok(_) => {
                let finite = s.u().iter().chain(s.v().iter()).all(|x| x.is_finite());
                check!(finite, "a coupled step gave a non-finite state: {s:?}");
                check!(
                    model.delivered_force(&hist).is_finite(),
                    "a coupled step delivered a non-finite force"
                );
                count(CTL, "coupled: step");
            }
            Err(e) => {
                check!(
                    same(&s, &s0) && same(&hist, &h0),
                    "a failed coupled step ({e:?}) changed the state or history"
                );
                count(CTL, "coupled: step refused");
            }
        }
    }
}

fn clipped_checks<const D: usize>(b: &mut Bytes) {
    let v_max = b.param(0.5, 10.0);
    let law = ClippedOptimal::<f64, D>::new(v_max);
    outcome(CTL, &law);
    let Ok(law) = law else {
        check!(
            !(v_max.is_finite() && v_max > 0.0),
            "ClippedOptimal refused the saturation {v_max}"
        );
        return;
    };
    for _ in 0..4 {
        let desired = SVector::<f64, D>::from_fn(|_, _| b.value());
        let measured = SVector::<f64, D>::from_fn(|_, _| b.value());
        let finite = desired.iter().chain(measured.iter()).all(|x| x.is_finite());
        match law.command(&desired, &measured) {
            Err(e) => check!(
                !finite && e == Error::NonFiniteInput,
                "ClippedOptimal refused {desired:?} {measured:?} with {e:?}"
            ),
            Ok(v) => {
                check!(finite, "ClippedOptimal accepted non-finite forces");
                for i in 0..D {
                    // On where f_c − f and f have the same sign, both nonzero: compared
                    // without subtracting (the sign of f_c − f is that of f_c > f).
                    let (fc, f) = (desired[i], measured[i]);
                    let on = (f > 0.0 && fc > f) || (f < 0.0 && fc < f);
                    let want = if on { v_max } else { 0.0 };
                    check!(
                        v[i] == want,
                        "ClippedOptimal: f_c {fc}, f {f}: {}, expected {want}",
                        v[i]
                    );
                }
                count(CTL, "clipped: command");
            }
        }
    }
}
