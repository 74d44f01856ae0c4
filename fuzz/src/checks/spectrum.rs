//! Fuzz target `spectrum` (`fuzz_targets/spectrum.rs`): checks Bank::new, Bank::with (both
//! schemes, every sub-step rule), RotD, the host batch, and the yielding bank
//! (`inelastic::Yielding`: construction, streaming, constant strength and constant
//! ductility); f32 and f64. Also what feeds them on the host: the record readers
//! (`records::at2`, `records::column`, on the input read as text) and IDA tracing
//! (`ida::trace`, `ida::fractiles`) with decoded settings and an analytic analysis.
//!
//! The decoder and the checks every target shares are in `common.rs`.

use std::fmt::Debug;

use aemstep::spectrum::inelastic::{Outcome, Search, Yielding};
use aemstep::spectrum::{Bank, NonFinite, Response, RotD, RotDResponse, Scheme, Substeps};
use aemstep::{Error, Param, Real};

use super::common::*;

const SP: &str = "spectrum";

/// Target `spectrum`.
pub fn spectrum(data: &[u8]) {
    let mut b = Bytes::new(data);
    let mut period = [0.0; 3];
    for p in &mut period {
        *p = match b.pick(4) {
            0 => b.value(),
            _ => 10f64.powf(-2.0 + 3.0 * b.unit()),
        };
        b.note(*p);
    }
    if b.flag() {
        period.sort_by(f64::total_cmp);
    }
    let damping = [b.param(0.0, 0.3), b.param(0.0, 0.3), b.param(0.0, 0.3)];
    let dt = match b.pick(3) {
        0 => b.time_step(),
        _ => 10f64.powf(-3.0 + 2.0 * b.unit()),
    };
    b.note(dt);
    let scheme = if b.flag() { Scheme::Exact } else { Scheme::Aem };
    let sub = match b.pick(4) {
        0 => Substeps::AUTO,
        1 => Substeps::Fixed(b.u16() % 1100),
        2 => Substeps::PointsPerPeriod(b.u16() % 64),
        _ => Substeps::Fixed(1),
    };
    let samples: Vec<(f64, f64)> = (0..12)
        .map(|_| match b.pick(8) {
            0 => (b.value(), b.value()),
            _ => (b.ordinary(), b.ordinary()),
        })
        .collect();
    let batch = b.pick(8) == 0;
    let yielding = Inelastic {
        alpha: match b.pick(4) {
            0 => b.value(),
            1 => 0.0,
            _ => b.param(0.0, 0.5),
        },
        ay: [b.value(), b.param(0.01, 20.0), f64::INFINITY],
        reduction: [b.param(1.0, 8.0), b.value(), b.param(1.0, 8.0)],
        target: match b.pick(4) {
            0 => b.value(),
            _ => b.param(1.0, 8.0),
        },
        search: Search {
            points: b.u16() % 40,
            lowest: b.param(0.0, 1.0),
            tol: match b.pick(4) {
                0 => b.value(),
                _ => 10f64.powf(-7.0 * b.unit()),
            },
        },
    };
    set_context(format!(
        "periods = {period:?}, damping = {damping:?}, dt = {dt:e}, scheme = {scheme:?}, substeps = {sub:?}, samples = {samples:?}, batch = {batch}, yielding = {yielding:?}"
    ));
    let r64 = bank_typed::<f64>(&period, &damping, dt, scheme, sub, &samples, batch);
    let r32 = bank_typed::<f32>(&period, &damping, dt, scheme, sub, &samples, batch);
    same_kind(SP, "Bank f64 vs f32", &r64, &r32);
    let y64 = inelastic_typed::<f64>(&period, &damping, dt, sub, &samples, &yielding, r64);
    let y32 = inelastic_typed::<f32>(&period, &damping, dt, sub, &samples, &yielding, r32);
    same_kind(SP, "Yielding f64 vs f32", &y64, &y32);
    records_checks(&String::from_utf8_lossy(data));
    #[cfg(feature = "std")]
    ida_checks(&mut b);
    count(SP, "inputs");
    count(SP, b.category());
}

fn bank_typed<T: Real + Send + Sync + 'static>(
    period: &[f64; 3],
    damping: &[f64; 3],
    dt: f64,
    scheme: Scheme,
    sub: Substeps,
    samples: &[(f64, f64)],
    batch: bool,
) -> Option<Error>
where
    Bank<T, 3>: Debug,
{
    let (bank, default) = if eps::<T>() > 1e-10 {
        (
            cast_bank::<T>(
                Bank::<f32, 3>::with_f32(*period, *damping, dt, scheme, sub).map(BankAny::F32),
            ),
            cast_bank::<T>(Bank::<f32, 3>::new_f32(*period, *damping, dt).map(BankAny::F32)),
        )
    } else {
        (
            cast_bank::<T>(
                Bank::<f64, 3>::with_f64(*period, *damping, dt, scheme, sub).map(BankAny::F64),
            ),
            cast_bank::<T>(Bank::<f64, 3>::new_f64(*period, *damping, dt).map(BankAny::F64)),
        )
    };
    outcome(SP, &bank);
    outcome(SP, &default);
    // The documented rule, in its order: dt, the sub-step rule, then per oscillator its
    // period (finite, ≥ 1e-150, not below the previous) and its damping ratio ([0, 1)).
    let rule_err = if !(dt.is_finite() && dt > 0.0) {
        Some(Error::InvalidTimeStep)
    } else if matches!(sub, Substeps::Fixed(0) | Substeps::PointsPerPeriod(0))
        || matches!(sub, Substeps::Fixed(n) if n > aemstep::spectrum::MAX_SUBSTEPS)
    {
        Some(Error::InvalidParameter(Param::Substeps))
    } else {
        (0..3).find_map(|p| {
            let t = period[p];
            if !(t.is_finite() && t >= 1e-150) || (p > 0 && t < period[p - 1]) {
                Some(Error::InvalidPeriod)
            } else if !(damping[p] >= 0.0 && damping[p] < 1.0) {
                Some(Error::InvalidDamping)
            } else {
                None
            }
        })
    };
    let got = bank.as_ref().err().copied();
    match rule_err {
        Some(e) => check!(
            got == Some(e),
            "{SP}: Bank::with gave {got:?}, the rule says {e:?}"
        ),
        // Operators that do not fit the scalar type are an overflow.
        None => check!(
            got.is_none() || got == Some(Error::OperatorOverflow),
            "{SP}: Bank::with gave {got:?} for data within the rule"
        ),
    }
    let Ok(bank) = bank else { return got };
    check!(
        bank.periods() == period
            && bank.damping() == damping
            && bank.time_step() == dt
            && bank.scheme() == scheme,
        "{SP}: the bank does not keep its data"
    );
    let _ = bank.free_vibration_samples();
    // The policy for non-finite samples: refused by default (checked below against the
    // skipping bank, whose documented hold-and-count the rest of this check follows).
    check!(
        bank.non_finite() == NonFinite::Refuse,
        "{SP}: a bank does not refuse non-finite samples by default"
    );
    let refusing = bank;
    let bank = bank.with_non_finite(NonFinite::Skip);
    let (rot, mut r, mut rr) = at_rest(&bank);
    let mut held = T::zero();
    let mut record = Vec::new();
    for &(ax, ay) in samples {
        let (x, y) = (T::from_f64_rounded(ax), T::from_f64_rounded(ay));
        record.push(x);
        let before = r;
        // The checked step: the unchecked one's result when finite, else `r` unchanged.
        let mut tried = r;
        let t = bank.try_step(&mut tried, x);
        let mut refused = before;
        let tr = refusing.try_step(&mut refused, x);
        check!(
            refusal_holds(x, (&t, &tried), (&tr, &refused), &before),
            "{SP}: the refusing Bank::try_step gave {tr:?} for the sample {x:?}"
        );
        bank.step(&mut r, x);
        count(SP, "samples");
        match t {
            Ok(()) => check!(
                tried == r && r.is_finite(),
                "{SP}: Bank::try_step Ok differs from step or is not finite"
            ),
            Err(e) => {
                count(SP, "checked steps refused");
                check!(
                    e == Error::NonFiniteState && bits(&tried) == bits(&before) && !r.is_finite(),
                    "{SP}: Bank::try_step gave {e:?} or changed the response"
                );
            }
        }
        if !x.is_finite() {
            count(SP, "samples skipped");
            // A skipped sample: counted, and the same as the last finite sample held.
            let mut held_r = before;
            bank.step(&mut held_r, held);
            check!(
                r.skipped() == before.skipped() + 1
                    && bits(&(
                        r.displacement(),
                        r.velocity(),
                        r.sd(),
                        r.sv(),
                        r.sa(),
                        r.samples(),
                        r.walks()
                    )) == bits(&(
                        held_r.displacement(),
                        held_r.velocity(),
                        held_r.sd(),
                        held_r.sv(),
                        held_r.sa(),
                        held_r.samples(),
                        held_r.walks()
                    )),
                "{SP}: a non-finite sample was not skipped as documented"
            );
        } else {
            held = x;
        }
        // Peaks never fall.
        for p in 0..3 {
            check!(
                r.sd()[p] >= before.sd()[p]
                    && r.sv()[p] >= before.sv()[p]
                    && r.sa()[p] >= before.sa()[p],
                "{SP}: a peak fell"
            );
        }
        let (rr_before, mut rr_tried) = (rr, rr);
        let t = rot.try_step(&bank, &mut rr_tried, x, y);
        rot.step(&bank, &mut rr, x, y);
        check!(
            match t {
                Ok(()) => rr_tried == rr && rr.is_finite(),
                Err(e) => {
                    e == Error::NonFiniteState
                        && bits(&rr_tried) == bits(&rr_before)
                        && !rr.is_finite()
                }
            },
            "{SP}: RotD::try_step differs from step, or changed the response"
        );
    }
    // Ordinary samples: each at most 10 (m/s²) in size, or skipped (not finite).
    let ordinary = samples
        .iter()
        .all(|&(x, _)| !x.is_finite() || x.abs() <= 10.0);
    let fv = bank.free_vibration_samples().min(40);
    let mut rf = r;
    bank.free_vibration(&mut rf, fv);
    if ordinary {
        // Ok ⇒ finite operators: ordinary samples give a finite response.
        let all = r
            .displacement()
            .iter()
            .chain(r.velocity())
            .chain(r.sd())
            .chain(r.sv())
            .chain(r.sa())
            .chain(rf.sd())
            .chain(rf.sv())
            .chain(rf.sa());
        let fin = all.copied().all(|x| x.is_finite());
        check!(
            fin,
            "{SP}: Bank Ok, ordinary samples gave a non-finite response: {r:?} (bank {bank:?})"
        );
        check!(
            bank.psa(r.sd())
                .iter()
                .chain(&bank.psv(r.sd()))
                .all(|x| x.is_finite()),
            "{SP}: PSA/PSV not finite"
        );
        count(SP, "response checked finite");
    }
    let _ = (rr.rotd50(), rr.rotd100());
    #[cfg(feature = "std")]
    if batch {
        let out = aemstep::spectrum::batch::spectra(&bank, &[&record[..]], 0, 1);
        check!(
            out.len() == 1
                && match &out[0] {
                    Ok(o) => bits(o) == bits(&r) && r.is_finite(),
                    Err(e) => *e == Error::NonFiniteState && !r.is_finite(),
                },
            "{SP}: batch differs from stepping"
        );
        count(SP, "batch compared");
        let refused = aemstep::spectrum::batch::spectra(&refusing, &[&record[..]], 0, 1);
        let fin = record.iter().all(|x| x.is_finite());
        check!(
            match (&refused[0], &out[0]) {
                (Err(Error::NonFiniteInput), _) => !fin,
                (a, b) => fin && a.as_ref().map(bits) == b.as_ref().map(bits),
            },
            "{SP}: the refusing batch differs from the policy"
        );
    }
    let _ = batch;
    None
}

/// The checked step of a bank that refuses non-finite samples against the skipping bank's
/// (each `(result, response after it)`, both from `before`): the same result and bits for a
/// finite sample `x`; for a non-finite one `NonFiniteInput` with the response unchanged.
fn refusal_holds<T: Real, S: Debug>(
    x: T,
    skipping: (&Result<(), Error>, &S),
    refusing: (&Result<(), Error>, &S),
    before: &S,
) -> bool {
    if x.is_finite() {
        refusing.0 == skipping.0 && bits(refusing.1) == bits(skipping.1)
    } else {
        *refusing.0 == Err(Error::NonFiniteInput) && bits(refusing.1) == bits(before)
    }
}

/// A bank of either scalar, for the generic checks (short-lived: its size is no matter).
#[allow(clippy::large_enum_variant)]
enum BankAny {
    F32(Bank<f32, 3>),
    F64(Bank<f64, 3>),
}

fn cast_bank<T: Real + 'static>(b: Result<BankAny, Error>) -> Result<Bank<T, 3>, Error> {
    b.map(|b| {
        let any: Box<dyn std::any::Any> = match b {
            BankAny::F32(x) => Box::new(x),
            BankAny::F64(x) => Box::new(x),
        };
        *any.downcast::<Bank<T, 3>>()
            .expect("bank of the scalar asked for")
    })
}

fn at_rest<T: Real + 'static>(
    bank: &Bank<T, 3>,
) -> (RotD<T, 4>, Response<T, 3>, RotDResponse<T, 3, 4>) {
    // `at_rest` and `RotD::new_f32`/`new_f64` are `const fn` of each scalar type: pick `T`'s.
    let bk: &dyn std::any::Any = bank;
    let x: Box<dyn std::any::Any> = if let Some(b) = bk.downcast_ref::<Bank<f32, 3>>() {
        let rot = RotD::<f32, 4>::new_f32();
        let rr = rot.at_rest(b);
        Box::new((rot, b.at_rest(), rr))
    } else {
        let b = bk
            .downcast_ref::<Bank<f64, 3>>()
            .expect("a bank of f32 or f64");
        let rot = RotD::<f64, 4>::new_f64();
        let rr = rot.at_rest(b);
        Box::new((rot, b.at_rest(), rr))
    };
    *x.downcast().expect("the scalar asked for")
}

/// The yielding bank's own data (beside the elastic bank's periods, damping, step, rule).
#[derive(Debug)]
struct Inelastic {
    alpha: f64,
    ay: [f64; 3],
    reduction: [f64; 3],
    target: f64,
    search: Search,
}

/// `inelastic::Yielding` on the same periods, damping, step and sub-step rule as the
/// elastic bank: the same variant for the same bad data (the elastic bank's error
/// `bank_err`, then `InvalidMaterial` for α outside `[0, 1)`); strengths, reduction
/// factors, targets and search settings out of range are typed errors; streaming never
/// panics, skips and counts non-finite samples, and its peaks never fall; a
/// constant-ductility result keeps its strength inside its bracket.
fn inelastic_typed<T: Real>(
    period: &[f64; 3],
    damping: &[f64; 3],
    dt: f64,
    sub: Substeps,
    samples: &[(f64, f64)],
    y: &Inelastic,
    bank_err: Option<Error>,
) -> Option<Error> {
    let bank = Yielding::<T, 3>::with(*period, *damping, y.alpha, dt, sub);
    outcome(SP, &bank);
    let got = bank.as_ref().err().copied();
    let alpha_ok = y.alpha.is_finite() && (0.0..1.0).contains(&y.alpha);
    match bank_err {
        // The elastic bank's data errors come first, in its order.
        Some(e) if e != Error::OperatorOverflow => check!(
            got == Some(e),
            "{SP}: Yielding::with gave {got:?} where Bank::with gave {e:?}"
        ),
        _ if !alpha_ok => check!(
            got == Some(Error::InvalidMaterial(Param::PostYieldRatio)) || got == bank_err,
            "{SP}: Yielding::with with α = {} gave {got:?}",
            y.alpha
        ),
        _ => check!(
            got.is_none() || got == Some(Error::OperatorOverflow),
            "{SP}: Yielding::with gave {got:?} for data within the rule"
        ),
    }
    let Ok(bank) = bank else { return got };
    let refusing = bank;
    let bank = bank.with_non_finite(NonFinite::Skip);
    let ay = y.ay.map(T::from_f64_rounded);
    let rest = bank.at_rest(&ay);
    outcome(SP, &rest);
    let bad_strength = ay.iter().any(|&a| !(a > T::zero()));
    if bad_strength {
        check!(
            rest == Err(Error::InvalidMaterial(Param::YieldForce)),
            "{SP}: Yielding::at_rest with strengths {ay:?} gave {:?}",
            rest.as_ref().err()
        );
    }
    let record: Vec<T> = samples
        .iter()
        .map(|&(x, _)| T::from_f64_rounded(x))
        .collect();
    if let Ok(mut r) = rest {
        for &x in &record {
            let before = r;
            let mut tried = r;
            let t = bank.try_step(&mut tried, x);
            let mut refused = before;
            let tr = refusing.try_step(&mut refused, x);
            check!(
                refusal_holds(x, (&t, &tried), (&tr, &refused), &before),
                "{SP}: the refusing Yielding::try_step gave {tr:?} for the sample {x:?}"
            );
            bank.step(&mut r, x);
            count(SP, "yielding samples");
            check!(
                match t {
                    Ok(()) => tried == r && r.is_finite(),
                    Err(e) =>
                        e == Error::NonFiniteState
                            && bits(&tried) == bits(&before)
                            && !r.is_finite(),
                },
                "{SP}: Yielding::try_step differs from step, or changed the response"
            );
            check!(
                r.samples() == before.samples() + 1
                    && r.skipped() == before.skipped() + u64::from(!x.is_finite()),
                "{SP}: Yielding::step did not count a sample"
            );
            for p in 0..3 {
                check!(!(r.sd()[p] < before.sd()[p]), "{SP}: a yielding peak fell");
            }
        }
        bank.free_vibration(&mut r, bank.free_vibration_samples().min(40));
    }
    // The whole-record functions step the record and one longest period of free vibration
    // per pass (a constant-ductility search makes up to `points + 128` passes): only where
    // that is cheap, so every input stays fast (a long period at a tiny step is a
    // legitimate, slow input).
    let work = (record.len() as u64 + u64::from(bank.free_vibration_samples()))
        * u64::from(bank.substeps_per_sample());
    if work > 4_000 {
        count(SP, "yielding whole-record checks skipped (slow input)");
        return None;
    }
    let reduction = y.reduction.map(T::from_f64_rounded);
    let cs = bank.constant_strength(&record, &reduction);
    outcome(SP, &cs);
    // The record-level errors: bad data, an underflowing strength, an overflowing response.
    let typed_pass = |e: &Error| {
        matches!(
            e,
            Error::InvalidParameter(_)
                | Error::InvalidMaterial(_)
                | Error::OperatorUnderflow
                | Error::OperatorOverflow
                | Error::NonFiniteState
        )
    };
    match &cs {
        Err(e) => check!(typed_pass(e), "{SP}: constant_strength gave {e:?}"),
        // Every field finite, or an error.
        Ok(c) => check!(
            c.response.is_finite()
                && c.elastic
                    .iter()
                    .chain(&c.yield_acceleration)
                    .chain(&c.ductility)
                    .chain(&c.plastic_work)
                    .all(|x| x.is_finite()),
            "{SP}: constant_strength Ok with a non-finite field: {c:?}"
        ),
    }
    if reduction.iter().any(|&x| !(x > T::zero() && x.is_finite())) {
        check!(
            cs.as_ref().err() == Some(&Error::InvalidParameter(Param::StrengthReduction)),
            "{SP}: constant_strength with R = {reduction:?} gave {:?}",
            cs.as_ref().err()
        );
    }
    let cd = bank.constant_ductility(&record, T::from_f64_rounded(y.target), &y.search);
    outcome(SP, &cd);
    match cd {
        Err(e) => check!(typed_pass(&e), "{SP}: constant_ductility gave {e:?}"),
        Ok(c) => {
            count(SP, "constant-ductility searches");
            for p in 0..3 {
                if c.outcome[p] == Outcome::Converged {
                    let (lo, hi) = (c.bracket[p][0], c.bracket[p][1]);
                    let a = c.yield_acceleration[p];
                    check!(
                        lo <= a && a <= hi,
                        "{SP}: constant_ductility strength {a:?} outside its bracket [{lo:?}, {hi:?}]"
                    );
                }
            }
        }
    }
    None
}

/// The record readers on any text: typed errors only; a header read `Ok` has `npts > 0`
/// and a finite `dt > 0`; a whole read gives exactly `npts` finite values (AT2), equal to
/// the iterator's, and the `f32` read holds each of them rounded once (or fails where one
/// overflows `f32`); the iterator ends after its first error.
fn records_checks(text: &str) {
    use aemstep::records;
    let typed = |e: &Error| {
        matches!(
            e,
            Error::MalformedRecord { .. } | Error::InvalidParameter(_)
        )
    };
    let values = |it: records::Values<'_>| {
        let mut out = Vec::new();
        let mut it = it;
        while let Some(v) = it.next() {
            match v {
                Ok(x) => {
                    check!(x.is_finite(), "records: a non-finite value {x} yielded");
                    out.push(x);
                }
                Err(e) => {
                    check!(typed(&e), "records: untyped error {e:?}");
                    check!(it.next().is_none(), "records: values after an error");
                    return Err(e);
                }
            }
        }
        Ok(out)
    };
    match records::at2(text) {
        Ok(h) => {
            check!(
                h.npts > 0 && h.dt.is_finite() && h.dt > 0.0,
                "records: header {h:?}"
            );
            let it = values(h.values());
            // Bounded buffers: a header may claim any count.
            if h.npts <= 1 << 16 {
                let mut buf = vec![0.0f64; h.npts];
                let read = h.read_into(&mut buf);
                match (&read, &it) {
                    (Ok(n), Ok(v)) => {
                        check!(*n == h.npts && v.len() == h.npts, "records: AT2 count {n}");
                        check!(
                            buf.iter().zip(v).all(|(a, b)| a.to_bits() == b.to_bits()),
                            "records: read_into differs from the iterator"
                        );
                        let mut b32 = vec![0.0f32; h.npts];
                        match h.read_into(&mut b32) {
                            Ok(m) => check!(
                                m == h.npts && b32.iter().zip(v).all(|(a, b)| *a == *b as f32),
                                "records: f32 read is not the values rounded once"
                            ),
                            Err(e) => check!(
                                matches!(e, Error::MalformedRecord { .. })
                                    && v.iter().any(|x| !(*x as f32).is_finite()),
                                "records: f32 read failed ({e:?}) with every value in range"
                            ),
                        }
                    }
                    (Err(a), Err(b)) => {
                        check!(a == b, "records: {a:?} from read_into, {b:?} iterated")
                    }
                    _ => check!(false, "records: read_into {read:?} but iterated {it:?}"),
                }
            }
            count(SP, "records: AT2 headers read");
        }
        Err(e) => check!(typed(&e), "records: untyped header error {e:?}"),
    }
    let col = values(records::column(text));
    if let Ok(v) = &col {
        let mut buf = vec![0.0f64; v.len()];
        let n = records::column_into(text, &mut buf);
        check!(
            n == Ok(v.len()),
            "records: column_into {n:?} for {} values",
            v.len()
        );
        if !v.is_empty() {
            check!(
                records::column_into(text, &mut buf[..v.len() - 1])
                    == Err(Error::InvalidParameter(Param::OutputBuffer)),
                "records: a short buffer is not InvalidParameter"
            );
        }
        count(SP, "records: columns read");
    }
}

/// Hunt-and-fill on an analytic IDA curve (EDP = intensity below a capacity, collapse
/// above it, by an EDP limit or a failed analysis): settings out of range are
/// `InvalidParameter` before any run; otherwise at most `runs` analyses, points sorted by
/// intensity with finite positive intensities, the collapse bracket `[lo, hi]` with
/// `lo < capacity ≤ hi` (each end a run that stayed up or collapsed); fractiles of the
/// curve are typed errors or values. (`ida` is host-only: feature `std`.)
#[cfg(feature = "std")]
fn ida_checks(b: &mut Bytes) {
    use aemstep::ida::{self, Collapse, HuntFill, OnFailure};
    use std::cell::Cell;
    // The run budget: out of range (0, 10 001), long (up to 400: the fill's bookkeeping
    // grows as runs² log runs, so 10 000 is left to the tests), or a usual one.
    let runs = match b.pick(8) {
        0 => [0, 10_001][b.pick(2) as usize],
        1 => 1 + b.u16() as usize % 400,
        _ => 1 + b.u16() as usize % 40,
    };
    let settings = HuntFill {
        first: match b.pick(4) {
            0 => b.value(),
            _ => b.param(1e-3, 2.0),
        },
        step: match b.pick(4) {
            0 => b.value(),
            _ => b.param(1e-3, 2.0),
        },
        step_increment: match b.pick(4) {
            0 => b.value(),
            _ => b.param(0.0, 1.0),
        },
        resolution: match b.pick(4) {
            0 => b.value(),
            _ => b.param(1e-6, 0.5),
        },
        runs,
        collapse: Collapse {
            edp: match b.pick(3) {
                0 => b.value(),
                1 => f64::INFINITY,
                _ => b.param(0.1, 10.0),
            },
            on_failure: if b.flag() {
                OnFailure::Collapse
            } else {
                OnFailure::Abort
            },
        },
    };
    // `param` may leave its range (the decoder's extremes): the capacity is kept in it.
    let capacity = match b.param(0.01, 10.0) {
        c if c > 0.01 && c < 10.0 => c,
        _ => 1.0,
    };
    let by_error = b.flag();
    set_context(format!(
        "ida: settings = {settings:?}, capacity = {capacity}, by_error = {by_error}"
    ));
    let calls = Cell::new(0usize);
    let analysis = |_: &(), x: f64| {
        calls.set(calls.get() + 1);
        check!(
            x.is_finite() && x > 0.0,
            "ida: analysis asked at intensity {x}"
        );
        if x < capacity {
            Ok(x)
        } else if by_error {
            Err(Error::NotConverged)
        } else {
            Ok(f64::INFINITY)
        }
    };
    let curve = ida::trace(&(), &settings, analysis);
    let valid = settings.first.is_finite()
        && settings.first > 0.0
        && settings.step.is_finite()
        && settings.step > 0.0
        && settings.step_increment.is_finite()
        && settings.step_increment >= 0.0
        && settings.resolution.is_finite()
        && settings.resolution > 0.0
        && (1..=10_000).contains(&settings.runs)
        && settings.collapse.edp > 0.0;
    match curve {
        Err(Error::InvalidParameter(_)) => {
            check!(
                calls.get() == 0,
                "ida: {} runs before InvalidParameter",
                calls.get()
            );
            count(SP, "ida: settings refused");
        }
        Err(e) => check!(
            valid
                && by_error
                && settings.collapse.on_failure == OnFailure::Abort
                && e == Error::NotConverged,
            "ida: unexpected error {e:?}"
        ),
        Ok(c) => {
            check!(valid, "ida: settings out of range accepted");
            check!(
                c.points.len() <= settings.runs && calls.get() == c.points.len(),
                "ida: {} points, {} runs",
                c.points.len(),
                calls.get()
            );
            check!(
                c.points
                    .windows(2)
                    .all(|w| w[0].intensity <= w[1].intensity),
                "ida: points not sorted"
            );
            // Collapse from the capacity on (a failed or infinite run), or where the EDP
            // (= the intensity) reaches the collapse EDP: from `min(capacity, edp)` on.
            let onset = capacity.min(settings.collapse.edp);
            if let Some([lo, hi]) = c.collapse {
                check!(
                    lo < onset && onset <= hi,
                    "ida: bracket [{lo}, {hi}] misses the collapse onset {onset}"
                );
            }
            let edp = [b.value(), b.param(0.0, 5.0)];
            let q = [b.value(), b.param(0.0, 1.0)];
            match ida::fractiles(core::slice::from_ref(&c), &edp, &q) {
                Ok(f) => check!(
                    f.quantiles() == q
                        && f.edp() == edp
                        && f.as_slice().len() == 4
                        // bits: a fractile of censored curves is NaN
                        && f.at(1, 1).map(f64::to_bits) == f.curve(1).map(|c| c[1].to_bits())
                        && f.at(2, 0).is_none()
                        && f.at(0, 2).is_none(),
                    "ida: fractile axes"
                ),
                Err(e) => check!(
                    e == Error::InvalidParameter(Param::Fractiles),
                    "ida: fractiles {e:?}"
                ),
            }
            count(SP, "ida: curves traced");
        }
    }
}
