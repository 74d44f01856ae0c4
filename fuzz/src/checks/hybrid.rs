//! Fuzz target `hybrid` (`fuzz_targets/hybrid.rs`): checks `KrAlpha` (new, chen_ricles,
//! from_rows_f32/_f64, from_rows_chen_ricles_f32/_f64) and `hybrid::Split` (the same
//! constructors with `K_num`; start, start_with_acceleration, command, complete), f32 and
//! f64, N = 1, 2, 3.
//!
//! Beyond the properties every target checks (`mod.rs`): a `Split` with `K_num = K` has
//! `KrAlpha`'s operators bit for bit, and fails with `KrAlpha`'s early errors; its start is
//! `KrAlpha`'s start with the load `p0 − r0`; `command` is `KrAlpha::next_displacement` and
//! the `u` a successful `complete` commits; a successful `complete` is
//! `scheme().step_with_previous_input(state, p_prev − r_prev, p − r)` bit for bit, and a
//! failed one (`NonFiniteForce`, `NonFiniteInput`, `NonFiniteState`) changes nothing.
//!
//! No energy check: KR-α with `ρ∞ < 1` dissipates (and, as generalized-α, may overshoot in
//! its first steps at large `ωh`); with `ρ∞ = 1` its spurious root `−1` keeps a start-up
//! residual of the equation of motion, and CR's undamped energy is conserved only in the
//! scheme's own (mid-step velocity) variables, not in `½ vᵀMv + ½ uᵀKu` of the state.
//!
//! The decoder and the checks every target shares are in `common.rs`.

use aemstep::hybrid::{Actuator, Adaptive, Compensator, Polynomial, Split, SplitState};
use aemstep::nalgebra::{SMatrix, SVector};
use aemstep::{Error, KrAlpha, Param, Real, Stepper};

use super::common::*;

const HYB: &str = "hybrid";

/// Target `hybrid`.
pub fn hybrid(data: &[u8]) {
    let mut b = Bytes::new(data);
    match b.pick(3) {
        0 => hybrid_n::<1>(&mut b),
        1 => hybrid_n::<2>(&mut b),
        _ => hybrid_n::<3>(&mut b),
    }
    count(HYB, "inputs");
    count(HYB, b.category());
}

struct HybridInputs<const N: usize> {
    sys: System<N>,
    /// The numerical part's stiffness `K_num` (`K` itself, zero, a fraction of `K`, or
    /// anything).
    kn: SMatrix<f64, N, N>,
    rho: f64,
    u0: SVector<f64, N>,
    v0: SVector<f64, N>,
    a0: SVector<f64, N>,
    /// Given restoring forces and loads.
    r: [SVector<f64, N>; 3],
    p: [SVector<f64, N>; 3],
}

fn hybrid_n<const N: usize>(b: &mut Bytes) {
    let sys = b.system::<N>();
    let kn = match b.pick(5) {
        0 | 1 => sys.k,
        2 => SMatrix::zeros(),
        3 => sys.k * b.unit(),
        _ => b.square(),
    };
    b.note_all(kn.as_slice());
    let vec = |b: &mut Bytes| -> SVector<f64, N> {
        if b.flag() {
            b.small_vector()
        } else {
            b.vector()
        }
    };
    let d = HybridInputs {
        sys,
        kn,
        rho: b.param(0.0, 1.0),
        u0: vec(b),
        v0: vec(b),
        a0: vec(b),
        r: [vec(b), vec(b), vec(b)],
        p: [vec(b), vec(b), vec(b)],
    };
    set_context(format!(
        "N = {N}, M = {:?}, C = {:?}, K = {:?}, K_num = {:?}, h = {:e}, ρ∞ = {:e}, u0 = {:?}, v0 = {:?}, a0 = {:?}, r = {:?}, p = {:?}",
        d.sys.m.as_slice(),
        d.sys.c.as_slice(),
        d.sys.k.as_slice(),
        d.kn.as_slice(),
        d.sys.h,
        d.rho,
        d.u0.as_slice(),
        d.v0.as_slice(),
        d.a0.as_slice(),
        d.r.iter()
            .map(|x| x.as_slice().to_vec())
            .collect::<Vec<_>>(),
        d.p.iter()
            .map(|x| x.as_slice().to_vec())
            .collect::<Vec<_>>(),
    ));
    hybrid_typed::<f64, N>(&d);
    hybrid_typed::<f32, N>(&d);
    hybrid_cross::<N>(&d);
    delay_compensation(b);
}

/// The emulated actuator and the compensators on decoded parameters and a command
/// sequence.
struct DelayInputs {
    h: f64,
    delay: f64,
    lag: f64,
    tau_max: f64,
    order: usize,
    x: [f64; 8],
}

fn delay_compensation(b: &mut Bytes) {
    let h = b.time_step();
    let d = DelayInputs {
        h,
        delay: match b.pick(3) {
            0 => b.param(0.0, 6.0 * h),
            1 => (b.pick(7) as f64) * h,
            _ => b.value(),
        },
        lag: if b.flag() { 0.0 } else { b.param(0.0, 0.01) },
        tau_max: b.param(0.0, 0.05),
        order: usize::from(b.pick(5)),
        x: core::array::from_fn(|_| if b.flag() { b.value() } else { b.unit() - 0.5 }),
    };
    set_context(format!(
        "actuator/compensators: h = {:e}, delay = {:e}, lag = {:e}, τ_max = {:e}, order = {}, x = {:?}",
        d.h, d.delay, d.lag, d.tau_max, d.order, d.x
    ));
    delay_typed::<f64>(&d);
    delay_typed::<f32>(&d);
    // The `const` twins of Polynomial are the run-time builds.
    check!(
        Polynomial::new_f64(d.order, d.h, d.delay) == Polynomial::<f64>::new(d.order, d.h, d.delay),
        "Polynomial::new_f64 differs from Polynomial::new"
    );
    check!(
        Polynomial::new_f32(d.order, d.h, d.delay) == Polynomial::<f32>::new(d.order, d.h, d.delay),
        "Polynomial::new_f32 differs from Polynomial::new"
    );
}

/// Construction rules, then every command: `Err` changes nothing, `Ok` is finite (and the
/// identity for a zero delay without a lag).
fn delay_typed<T: Real>(d: &DelayInputs) {
    let h_ok = valid_h_as::<T>(d.h);
    let delay_ok = d.delay.is_finite() && d.delay >= 0.0;
    let lag_ok = d.lag.is_finite() && d.lag >= 0.0;
    let t = |x: f64| T::from_f64_rounded(x);

    let act = Actuator::<T, 8>::new(d.h, d.delay, d.lag);
    outcome(HYB, &act);
    if !h_ok {
        check!(
            act == Err(Error::InvalidTimeStep),
            "Actuator: bad h gave {act:?}"
        );
    } else if !(delay_ok && lag_ok) {
        check!(
            act == Err(Error::InvalidParameter(if delay_ok {
                Param::Lag
            } else {
                Param::Delay
            })),
            "Actuator: bad delay or lag gave {act:?}"
        );
    }
    if let Ok(a) = &act {
        let identity = d.delay == 0.0 && d.lag == 0.0;
        let mut s = a.rest(T::zero());
        for &x in &d.x {
            let before = format!("{s:?}");
            match a.step(&mut s, t(x)) {
                Ok(y) => {
                    count(HYB, "actuator steps");
                    check!(
                        y.is_finite() && y == s.reached(),
                        "Actuator: {y:?} not finite or not kept"
                    );
                    if identity {
                        check!(y == t(x), "Actuator without delay or lag: {y:?} for {x:e}");
                    }
                }
                Err(e) => {
                    count(HYB, "actuator steps refused");
                    check!(
                        format!("{s:?}") == before,
                        "Actuator: {e:?} changed the state"
                    );
                    check!(
                        matches!(e, Error::NonFiniteInput | Error::NonFiniteState),
                        "Actuator: step error {e:?}"
                    );
                    if !t(x).is_finite() {
                        check!(
                            e == Error::NonFiniteInput,
                            "Actuator: a non-finite command gave {e:?}"
                        );
                    }
                }
            }
        }
    }

    let poly = Polynomial::<T>::new(d.order, d.h, d.delay);
    outcome(HYB, &poly);
    if !(1..=3).contains(&d.order) {
        check!(
            poly == Err(Error::InvalidParameter(Param::CompensationOrder)),
            "Polynomial: order {} gave {poly:?}",
            d.order
        );
    } else if !h_ok {
        check!(
            poly == Err(Error::InvalidTimeStep),
            "Polynomial: bad h gave {poly:?}"
        );
    } else if !delay_ok {
        check!(
            poly == Err(Error::InvalidParameter(Param::Delay)),
            "Polynomial: bad delay gave {poly:?}"
        );
    }
    if let Ok(p) = &poly {
        check!(
            p.weights().iter().all(|w| w.is_finite()),
            "Polynomial: weights {:?}",
            p.weights()
        );
        compensate(p, d, |_| {}, d.delay == 0.0);
    }

    let adaptive = Adaptive::<T>::new(d.order, d.h, d.tau_max * 0.5, d.tau_max);
    outcome(HYB, &adaptive);
    if !(1..=3).contains(&d.order) {
        check!(
            adaptive == Err(Error::InvalidParameter(Param::CompensationOrder)),
            "Adaptive: order {} gave {adaptive:?}",
            d.order
        );
    } else if !h_ok {
        check!(
            adaptive == Err(Error::InvalidTimeStep),
            "Adaptive: bad h gave {adaptive:?}"
        );
    }
    if let Ok(a) = &adaptive {
        let max = t(d.tau_max);
        compensate(
            a,
            d,
            |s| {
                let tau = a.delay(s);
                check!(
                    tau >= T::zero() && tau <= max,
                    "Adaptive: estimate {tau:?} outside [0, {max:?}]"
                );
            },
            false,
        );
    }
}

/// Commands of `comp` for the targets of `d` (the measured value: the previous target, or
/// a decoded value): `Err` leaves the state as it was, `Ok` is finite; `identity`: the
/// command is the target.
fn compensate<T: Real, C: Compensator<T>>(
    comp: &C,
    d: &DelayInputs,
    also: impl Fn(&C::State),
    identity: bool,
) where
    C::State: core::fmt::Debug,
{
    let t = |x: f64| T::from_f64_rounded(x);
    let mut s = comp.rest(T::zero());
    let mut measured = T::zero();
    for &x in &d.x {
        let before = format!("{s:?}");
        match comp.command(&mut s, t(x), measured) {
            Ok(c) => {
                count(HYB, "compensator commands");
                check!(c.is_finite(), "compensator: command {c:?}");
                if identity {
                    check!(c == t(x), "compensator with zero delay: {c:?} for {x:e}");
                }
                measured = t(x);
            }
            Err(e) => {
                count(HYB, "compensator commands refused");
                check!(
                    format!("{s:?}") == before,
                    "compensator: {e:?} changed the state"
                );
                check!(
                    matches!(e, Error::NonFiniteInput | Error::NonFiniteState),
                    "compensator: error {e:?}"
                );
                if !t(x).is_finite() {
                    check!(
                        e == Error::NonFiniteInput,
                        "compensator: a non-finite target gave {e:?}"
                    );
                }
            }
        }
        also(&s);
    }
}

/// Every constructor in `T`: the data and parameter rules, finite operators on `Ok`, the
/// checked-step contract of `KrAlpha`, `Split` against `KrAlpha`, and the split steps.
fn hybrid_typed<T: Real, const N: usize>(d: &HybridInputs<N>) {
    let s = &d.sys;
    let (m, c, k, kn, h) = (&s.m, &s.c, &s.k, &d.kn, s.h);
    let rho_ok = (0.0..=1.0).contains(&d.rho);
    let want = data_error_as::<T>(&[m.as_slice(), c.as_slice(), k.as_slice()], h);
    let want_split = data_error_as::<T>(
        &[m.as_slice(), c.as_slice(), k.as_slice(), kn.as_slice()],
        h,
    );
    let (u0, v0) = (to_t::<T, N, 1>(&d.u0), to_t::<T, N, 1>(&d.v0));
    let ld = loads::<T, N>(&d.p[0], &d.p[1]);

    let kr = KrAlpha::<T, N>::new(m, c, k, h, d.rho);
    let cr = KrAlpha::<T, N>::chen_ricles(m, c, k, h);
    let sp = Split::<T, N>::new(m, c, k, kn, h, d.rho);
    let scr = Split::<T, N>::chen_ricles(m, c, k, kn, h);
    for (name, r, with_rho, w) in [
        ("KrAlpha::new", &kr, true, want),
        ("KrAlpha::chen_ricles", &cr, false, want),
    ] {
        outcome(HYB, r);
        expect_rule(name, r, with_rho && !rho_ok, w);
        if let Ok(sys) = r {
            operators_finite(name, sys);
            drive::<T, N, N, _>(HYB, name, sys, &u0, &v0, &ld);
            command_is_the_step(name, sys, &u0, &v0, &ld);
        }
    }
    for (name, r, with_rho, kr_r) in [
        ("Split::new", &sp, true, &kr),
        ("Split::chen_ricles", &scr, false, &cr),
    ] {
        outcome(HYB, r);
        expect_rule(name, r, with_rho && !rho_ok, want_split);
        // Against KrAlpha of the same M, C, K, h: the same checks up to M's factorization
        // (K_num enters only at the start-up and step operators).
        let (e_sp, e_kr) = (r.as_ref().err().copied(), kr_r.as_ref().err().copied());
        if all_finite(kn.as_slice()) {
            let early = matches!(
                e_kr,
                Some(
                    Error::InvalidParameter(_)
                        | Error::NonFiniteInput
                        | Error::InvalidTimeStep
                        | Error::SingularMass
                )
            );
            check!(
                // (an early error of either is the other's too)
                e_sp == e_kr || (!early && e_sp != Some(Error::SingularMass)),
                "{HYB}: {name} gave {e_sp:?}, KrAlpha {e_kr:?}"
            );
        }
        // (Bit for bit: `K_num = −0` where `K = 0` gives `G K_num = −0`.)
        if bits(kn) == bits(k) {
            check!(
                bits(&r.as_ref().map(|x| *x.scheme())) == bits(kr_r),
                "{HYB}: {name} with K_num = K differs from KrAlpha: {e_sp:?} against {e_kr:?}"
            );
            count(HYB, "split with K_num = K compared with KrAlpha");
        }
        if let Ok(sys) = r {
            operators_finite(name, sys.scheme());
            check!(
                sys.parameters() == sys.scheme().parameters(),
                "{HYB}: {name}: parameters"
            );
            split_run::<T, N>(name, sys, d);
        }
    }
}

/// A constructor's result: `InvalidParameter` for `ρ∞` outside `[0, 1]` (checked first),
/// else the data rule.
fn expect_rule<X>(name: &str, r: &Result<X, Error>, bad_rho: bool, want: Option<Error>) {
    if bad_rho {
        let got = r.as_ref().err().copied();
        check!(
            got == Some(Error::InvalidParameter(Param::RhoInf)),
            "{HYB}: {name} with ρ∞ out of [0, 1] gave {got:?}"
        );
    } else {
        expect_data(HYB, name, r, want);
    }
}

fn operators_finite<T: Real, const N: usize>(name: &str, sys: &KrAlpha<T, N>) {
    let h = Stepper::time_step(sys);
    check!(
        finite(&sys.alpha1()) && h.is_finite() && h > T::zero(),
        "{HYB}: {name}: α1 or h not finite (h = {h:?})"
    );
    let p = sys.parameters();
    check!(
        [p.alpha_m, p.alpha_f, p.beta, p.gamma]
            .iter()
            .all(|x| x.is_finite()),
        "{HYB}: {name}: parameters {p:?}"
    );
}

/// `next_displacement` is the `u` the step commits (checked or not), from a start and
/// along the loads.
fn command_is_the_step<T: Real, const N: usize>(
    name: &str,
    sys: &KrAlpha<T, N>,
    u0: &SVector<T, N>,
    v0: &SVector<T, N>,
    ld: &[SVector<T, N>],
) {
    let zero = SVector::<T, N>::zeros();
    let Ok(mut s) = sys
        .start(u0, v0, &zero)
        .or_else(|_| sys.start_with_acceleration(&zero, &zero, &zero))
    else {
        panic!(
            "property broken: {HYB}: {name}: start from rest failed\n  data: {}",
            context()
        );
    };
    let mut prev = zero;
    for w in ld.iter().filter(|w| finite(*w)) {
        let cmd = sys.next_displacement(&s);
        let mut unchecked = s;
        sys.step_with_previous_input(&mut unchecked, &prev, w);
        check!(
            bits(&cmd) == bits(unchecked.u()),
            "{HYB}: {name}: next_displacement {cmd:?}, the step's u {:?}",
            unchecked.u()
        );
        if sys.try_step_with_previous_input(&mut s, &prev, w).is_ok() {
            check!(
                bits(&cmd) == bits(s.u()),
                "{HYB}: {name}: next_displacement is not the committed u"
            );
        } else {
            break;
        }
        prev = *w;
    }
}

/// What a given restoring force of a split step is.
#[derive(Clone, Copy)]
enum Force {
    /// A decoded force.
    Given(usize),
    /// A linear specimen, `(K − K_num)` times the command (in `f64`, rounded).
    Specimen,
    /// A missing sample (NaN) in the first entry.
    Nan,
    /// An infinite entry.
    Inf,
}

/// What a load of a split step is.
#[derive(Clone, Copy)]
enum Load {
    Given(usize),
    Nan,
    Zero,
}

/// The split steps: the force and load of each, failures among them.
const SCHEDULE: [(Force, Load); 9] = [
    (Force::Specimen, Load::Given(0)),
    (Force::Nan, Load::Given(0)),
    (Force::Given(0), Load::Given(1)),
    (Force::Specimen, Load::Nan),
    (Force::Inf, Load::Given(1)),
    (Force::Given(1), Load::Given(2)),
    (Force::Specimen, Load::Zero),
    (Force::Given(2), Load::Given(2)),
    (Force::Specimen, Load::Given(1)),
];

/// A split run: the starts against `KrAlpha`'s (and their failures typed, nothing
/// returned), then the scheduled steps, each `complete` against the scheme's step with the
/// net load, `command` against `next_displacement` and the committed `u`.
fn split_run<T: Real, const N: usize>(name: &str, sys: &Split<T, N>, d: &HybridInputs<N>) {
    let kr = sys.scheme();
    let (u0, v0, a0) = (
        to_t::<T, N, 1>(&d.u0),
        to_t::<T, N, 1>(&d.v0),
        to_t::<T, N, 1>(&d.a0),
    );
    let (r0, p0) = (to_t::<T, N, 1>(&d.r[0]), to_t::<T, N, 1>(&d.p[0]));
    let zero = SVector::<T, N>::zeros();
    let one = SVector::<T, N>::from_element(T::one());
    let mut nan = one;
    nan[0] = T::from_f64_rounded(f64::NAN);

    // start: non-finite u0, v0, p0 ⇒ NonFiniteInput; r0 ⇒ NonFiniteForce; p0 − r0
    // overflowing ⇒ NonFiniteState; else KrAlpha's start with the load p0 − r0.
    let st = sys.start(&u0, &v0, &r0, &p0);
    let want = if !(finite(&u0) && finite(&v0) && finite(&p0)) {
        Err(Error::NonFiniteInput)
    } else if !finite(&r0) {
        Err(Error::NonFiniteForce)
    } else if !finite(&(p0 - r0)) {
        Err(Error::NonFiniteState)
    } else {
        kr.start(&u0, &v0, &(p0 - r0))
    };
    let got = st.as_ref().map(|s| *s.state()).map_err(|e| *e);
    check!(
        bits(&got) == bits(&want),
        "{HYB}: {name}: start gave {got:?}, KrAlpha's start with p0 − r0 {want:?}"
    );
    if let Ok(s) = &st {
        check!(
            s.state().is_finite()
                && bits(s.restoring_force()) == bits(&r0)
                && bits(s.load()) == bits(&p0),
            "{HYB}: {name}: start committed a non-finite state or other r0, p0"
        );
    }
    // start_with_acceleration: NonFiniteInput for u0, v0, a0, p0; NonFiniteForce for r0;
    // else KrAlpha's (which takes any finite values).
    let sa = sys.start_with_acceleration(&u0, &v0, &a0, &r0, &p0);
    let want_a = if !(finite(&u0) && finite(&v0) && finite(&a0) && finite(&p0)) {
        Err(Error::NonFiniteInput)
    } else if !finite(&r0) {
        Err(Error::NonFiniteForce)
    } else {
        kr.start_with_acceleration(&u0, &v0, &a0)
    };
    let got = sa.as_ref().map(|s| *s.state()).map_err(|e| *e);
    check!(
        bits(&got) == bits(&want_a),
        "{HYB}: {name}: start_with_acceleration gave {got:?}, expected {want_a:?}"
    );
    check!(
        sys.start_with_acceleration(&one, &one, &zero, &nan, &zero)
            .err()
            == Some(Error::NonFiniteForce)
            && sys
                .start_with_acceleration(&one, &one, &zero, &zero, &nan)
                .err()
                == Some(Error::NonFiniteInput)
            && sys.start(&one, &one, &nan, &zero).err() == Some(Error::NonFiniteForce)
            && sys.start(&one, &one, &zero, &nan).err() == Some(Error::NonFiniteInput),
        "{HYB}: {name}: a start accepted a NaN, or gave another error"
    );
    let mut s = match st.or(sa) {
        Ok(s) => s,
        Err(_) => match sys
            .start_with_acceleration(&one, &one, &zero, &zero, &zero)
            .or_else(|_| sys.start_with_acceleration(&zero, &zero, &zero, &zero, &zero))
        {
            Ok(s) => s,
            Err(e) => panic!(
                "property broken: {HYB}: {name}: start_with_acceleration from rest: {e:?}\n  data: {}",
                context()
            ),
        },
    };

    let kspec = d.sys.k - d.kn;
    for (force, load) in SCHEDULE {
        let cmd = sys.command(&s);
        check!(
            bits(&cmd) == bits(&kr.next_displacement(s.state()))
                && bits(&cmd) == bits(&sys.command(&s)),
            "{HYB}: {name}: command is not KrAlpha::next_displacement (or not repeatable)"
        );
        let r: SVector<T, N> = match force {
            Force::Given(i) => to_t(&d.r[i]),
            Force::Specimen => to_t(&(kspec * to_f64(&cmd))),
            Force::Nan => nan,
            Force::Inf => {
                let mut x = one;
                x[N - 1] = T::from_f64_rounded(f64::INFINITY);
                x
            }
        };
        let p: SVector<T, N> = match load {
            Load::Given(i) => to_t(&d.p[i]),
            Load::Nan => nan,
            Load::Zero => zero,
        };
        complete_checked(name, sys, &mut s, &cmd, &r, &p);
    }
}

/// One `complete` against the scheme's step with the net loads on a copy.
fn complete_checked<T: Real, const N: usize>(
    name: &str,
    sys: &Split<T, N>,
    s: &mut SplitState<T, N>,
    cmd: &SVector<T, N>,
    r: &SVector<T, N>,
    p: &SVector<T, N>,
) {
    let before = bits(s);
    let (net_prev, net) = (s.load() - s.restoring_force(), p - r);
    let mut expected = *s.state();
    sys.scheme()
        .step_with_previous_input(&mut expected, &net_prev, &net);
    let res = sys.complete(s, r, p);
    count(HYB, "checked steps");
    match res {
        Ok(()) => {
            check!(
                finite(r) && finite(p),
                "{HYB}: {name}: complete accepted a non-finite force or load"
            );
            check!(
                s.state().is_finite(),
                "{HYB}: {name}: complete committed a non-finite state"
            );
            check!(
                bits(s.state()) == bits(&expected),
                "{HYB}: {name}: complete differs from the scheme's step with p − r"
            );
            check!(
                bits(s.state().u()) == bits(cmd),
                "{HYB}: {name}: the committed u is not the command"
            );
            check!(
                bits(s.restoring_force()) == bits(r) && bits(s.load()) == bits(p),
                "{HYB}: {name}: complete committed another r or p"
            );
        }
        Err(e) => {
            count(HYB, "failed checked steps");
            check!(
                bits(s) == before,
                "{HYB}: {name}: failed complete ({e:?}) changed the state"
            );
            let want = if !finite(r) {
                Error::NonFiniteForce
            } else if !finite(p) {
                Error::NonFiniteInput
            } else {
                check!(
                    !(finite(&net) && expected.is_finite()),
                    "{HYB}: {name}: complete failed ({e:?}) where the scheme's step is finite"
                );
                Error::NonFiniteState
            };
            check!(
                e == want,
                "{HYB}: {name}: complete gave {e:?}, expected {want:?}"
            );
        }
    }
}

/// The constructors against each other: the const twins bit-identical to the run-time
/// builds (f32 and f64), `f32` failing as `f64` except for range.
fn hybrid_cross<const N: usize>(d: &HybridInputs<N>) {
    let s = &d.sys;
    let (m, c, k, kn, h, rho) = (&s.m, &s.c, &s.k, &d.kn, s.h, d.rho);
    let (mr, cr, kr, knr) = (rows(m), rows(c), rows(k), rows(kn));
    check!(
        bits(&KrAlpha::<f64, N>::new(m, c, k, h, rho))
            == bits(&KrAlpha::<f64, N>::from_rows_f64(mr, cr, kr, h, rho))
            && bits(&KrAlpha::<f32, N>::new(m, c, k, h, rho))
                == bits(&KrAlpha::<f32, N>::from_rows_f32(mr, cr, kr, h, rho)),
        "{HYB}: KrAlpha::from_rows differs from KrAlpha::new"
    );
    check!(
        bits(&KrAlpha::<f64, N>::chen_ricles(m, c, k, h))
            == bits(&KrAlpha::<f64, N>::from_rows_chen_ricles_f64(mr, cr, kr, h))
            && bits(&KrAlpha::<f32, N>::chen_ricles(m, c, k, h))
                == bits(&KrAlpha::<f32, N>::from_rows_chen_ricles_f32(mr, cr, kr, h)),
        "{HYB}: KrAlpha::from_rows_chen_ricles differs from chen_ricles"
    );
    check!(
        bits(&Split::<f64, N>::new(m, c, k, kn, h, rho))
            == bits(&Split::<f64, N>::from_rows_f64(mr, cr, kr, knr, h, rho))
            && bits(&Split::<f32, N>::new(m, c, k, kn, h, rho))
                == bits(&Split::<f32, N>::from_rows_f32(mr, cr, kr, knr, h, rho)),
        "{HYB}: Split::from_rows differs from Split::new"
    );
    check!(
        bits(&Split::<f64, N>::chen_ricles(m, c, k, kn, h))
            == bits(&Split::<f64, N>::from_rows_chen_ricles_f64(
                mr, cr, kr, knr, h
            ))
            && bits(&Split::<f32, N>::chen_ricles(m, c, k, kn, h))
                == bits(&Split::<f32, N>::from_rows_chen_ricles_f32(
                    mr, cr, kr, knr, h
                )),
        "{HYB}: Split::from_rows_chen_ricles differs from chen_ricles"
    );
    count(HYB, "from_rows compared");
    expect_twins(
        HYB,
        h,
        "KrAlpha::new",
        &KrAlpha::<f64, N>::new(m, c, k, h, rho),
        &KrAlpha::<f32, N>::new(m, c, k, h, rho),
    );
    expect_twins(
        HYB,
        h,
        "KrAlpha::chen_ricles",
        &KrAlpha::<f64, N>::chen_ricles(m, c, k, h),
        &KrAlpha::<f32, N>::chen_ricles(m, c, k, h),
    );
    expect_twins(
        HYB,
        h,
        "Split::new",
        &Split::<f64, N>::new(m, c, k, kn, h, rho),
        &Split::<f32, N>::new(m, c, k, kn, h, rho),
    );
    expect_twins(
        HYB,
        h,
        "Split::chen_ricles",
        &Split::<f64, N>::chen_ricles(m, c, k, kn, h),
        &Split::<f32, N>::chen_ricles(m, c, k, kn, h),
    );
}
