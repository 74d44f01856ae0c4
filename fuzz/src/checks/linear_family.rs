//! Fuzz target `linear_family` (`fuzz_targets/linear_family.rs`): checks Linear, AForm,
//! CompensatedLinear, LinearInput, Newmark, GeneralizedAlpha, Exact — every constructor
//! (and `from_rows_f32`/`_f64`), f32 and f64, N = 1, 2, 3.
//!
//! The decoder and the checks every target shares are in `common.rs`.

use std::fmt::Debug;

use aemstep::nalgebra::{SMatrix, SVector};
use aemstep::{
    AlphaParameters, CompensatedLinear, Error, Exact, GeneralizedAlpha, Linear, LinearInput,
    Newmark, Param, Real,
};

use super::common::*;

const LIN: &str = "linear_family";

/// Target `linear_family`.
pub fn linear_family(data: &[u8]) {
    let mut b = Bytes::new(data);
    match b.pick(3) {
        0 => linear_n::<1>(&mut b),
        1 => linear_n::<2>(&mut b),
        _ => linear_n::<3>(&mut b),
    }
    count(LIN, "inputs");
    count(LIN, b.category());
}

struct LinearInputs<const N: usize> {
    sys: System<N>,
    b: SMatrix<f64, N, N>,
    beta: f64,
    gamma: f64,
    rho: f64,
    alpha: f64,
    u0: SVector<f64, N>,
    v0: SVector<f64, N>,
    p: SVector<f64, N>,
    q: SVector<f64, N>,
}

fn linear_n<const N: usize>(b: &mut Bytes) {
    let sys = b.system::<N>();
    let bm = if b.flag() {
        SMatrix::identity()
    } else {
        b.matrix()
    };
    let d = LinearInputs {
        sys,
        b: bm,
        beta: b.param(0.0, 0.5),
        gamma: b.param(0.0, 1.0),
        rho: b.param(0.0, 1.0),
        alpha: b.param(-1.0 / 3.0, 0.0),
        u0: if b.flag() {
            b.small_vector()
        } else {
            b.vector()
        },
        v0: if b.flag() {
            b.small_vector()
        } else {
            b.vector()
        },
        p: b.vector(),
        q: b.vector(),
    };
    set_context(format!(
        "N = {N}, M = {:?}, C = {:?}, K = {:?}, h = {:e}, B = {:?}, β = {:e}, γ = {:e}, ρ∞ = {:e}, α = {:e}, u0 = {:?}, v0 = {:?}, p = {:?}, q = {:?}",
        d.sys.m.as_slice(),
        d.sys.c.as_slice(),
        d.sys.k.as_slice(),
        d.sys.h,
        d.b.as_slice(),
        d.beta,
        d.gamma,
        d.rho,
        d.alpha,
        d.u0.as_slice(),
        d.v0.as_slice(),
        d.p.as_slice(),
        d.q.as_slice()
    ));
    linear_typed::<f64, N>(&d);
    linear_typed::<f32, N>(&d);
    linear_cross::<N>(&d);
}

/// Every constructor in `T`: the data rule, finite operators on `Ok`, `from_rows`
/// bit-identical to `new`, the checked-step contract, and the energy check.
fn linear_typed<T: Real, const N: usize>(d: &LinearInputs<N>)
where
    Linear<T, N>: Debug,
{
    let s = &d.sys;
    let (m, c, k, h) = (&s.m, &s.c, &s.k, s.h);
    let want = data_error_as::<T>(&[m.as_slice(), c.as_slice(), k.as_slice()], h);
    let want_b = data_error_as::<T>(
        &[m.as_slice(), c.as_slice(), k.as_slice(), d.b.as_slice()],
        h,
    );
    let (u0, v0) = (to_t::<T, N, 1>(&d.u0), to_t::<T, N, 1>(&d.v0));
    let ld = loads::<T, N>(&d.p, &d.q);

    let lin = Linear::<T, N>::new(m, c, k, h);
    outcome(LIN, &lin);
    expect_data(LIN, "Linear::new", &lin, want);
    if let Ok(sys) = &lin {
        check!(
            finite(&sys.effective_inverse()),
            "{LIN}: Linear: G not finite"
        );
        check!(
            !sys.condition().is_nan() && sys.condition() >= 0.5,
            "{LIN}: Linear: condition {}",
            sys.condition()
        );
        drive::<T, N, N, _>(LIN, "Linear", sys, &u0, &v0, &ld);
        energy_holds::<T, N, N, _>(LIN, "Linear", sys, s, &d.u0, &d.v0);
        let af = match sys.try_a_form() {
            Ok(af) => af,
            Err(e) => {
                // Only an overflow of the literal form's blocks (products in T).
                check!(e == Error::OperatorOverflow, "{LIN}: try_a_form: {e:?}");
                let af = sys.a_form();
                let blocks_finite = (0..3).all(|r| {
                    af.b_block(r).is_some_and(|x| finite(&x))
                        && (0..3).all(|c| af.a_block(r, c).is_some_and(|x| finite(&x)))
                });
                check!(!blocks_finite, "{LIN}: try_a_form failed on finite blocks");
                count(LIN, "rejected");
                return linear_rest::<T, N>(d, &u0, &v0, &ld, want, want_b);
            }
        };
        for r in 0..3 {
            check!(
                af.b_block(r).is_some_and(|x| finite(&x)),
                "{LIN}: AForm: b block {r}"
            );
            for cc in 0..3 {
                check!(
                    af.a_block(r, cc).is_some_and(|x| finite(&x)),
                    "{LIN}: AForm: a block {r},{cc}"
                );
            }
        }
        check!(
            af.a_block(3, 0).is_none() && af.b_block(3).is_none(),
            "{LIN}: AForm: block 3 exists"
        );
        drive::<T, N, N, _>(LIN, "AForm", &af, &u0, &v0, &ld);
        energy_holds::<T, N, N, _>(LIN, "AForm", &af, s, &d.u0, &d.v0);
    }
    linear_rest::<T, N>(d, &u0, &v0, &ld, want, want_b);
}

/// The constructors of `linear_family` after `Linear` and `AForm`.
fn linear_rest<T: Real, const N: usize>(
    d: &LinearInputs<N>,
    u0: &SVector<T, N>,
    v0: &SVector<T, N>,
    ld5: &[SVector<T, N>; 5],
    want: Option<Error>,
    want_b: Option<Error>,
) {
    let s = &d.sys;
    let (m, c, k, h) = (&s.m, &s.c, &s.k, s.h);
    let (u0, v0, ld) = (*u0, *v0, *ld5);

    let comp = CompensatedLinear::<T, N>::new(m, c, k, h);
    outcome(LIN, &comp);
    expect_data(LIN, "CompensatedLinear::new", &comp, want);
    if let Ok(sys) = &comp {
        check!(
            finite(&sys.effective_inverse()),
            "{LIN}: CompensatedLinear: G not finite"
        );
        check!(
            !sys.condition().is_nan(),
            "{LIN}: CompensatedLinear: condition NaN"
        );
        drive::<T, N, N, _>(LIN, "CompensatedLinear", sys, &u0, &v0, &ld);
        energy_holds::<T, N, N, _>(LIN, "CompensatedLinear", sys, s, &d.u0, &d.v0);
    }

    let inp = LinearInput::<T, N, N>::new(m, c, k, &d.b, h);
    outcome(LIN, &inp);
    expect_data(LIN, "LinearInput::new", &inp, want_b);
    if let Ok(sys) = &inp {
        check!(
            finite(&sys.input_operator()),
            "{LIN}: LinearInput: G B not finite"
        );
        check!(
            !sys.condition().is_nan(),
            "{LIN}: LinearInput: condition NaN"
        );
        drive::<T, N, N, _>(LIN, "LinearInput", sys, &u0, &v0, &ld);
    }

    let valid_beta_gamma =
        d.beta.is_finite() && d.gamma.is_finite() && d.beta >= 0.0 && d.gamma >= 0.0;
    let nm = Newmark::<T, N>::new(m, c, k, h, d.beta, d.gamma);
    outcome(LIN, &nm);
    if valid_beta_gamma {
        expect_data(LIN, "Newmark::new", &nm, want);
    } else if want != Some(Error::NonFiniteInput) {
        check!(
            nm.as_ref().err() == Some(&Error::InvalidParameter(Param::NewmarkBetaGamma)),
            "{LIN}: Newmark β = {}, γ = {}: {:?}",
            d.beta,
            d.gamma,
            nm.as_ref().err()
        );
    }
    for (name, r) in [
        ("Newmark", nm),
        (
            "Newmark::average_acceleration",
            Newmark::<T, N>::average_acceleration(m, c, k, h),
        ),
        (
            "Newmark::linear_acceleration",
            Newmark::<T, N>::linear_acceleration(m, c, k, h),
        ),
        (
            "Newmark::central_difference",
            Newmark::<T, N>::central_difference(m, c, k, h),
        ),
    ] {
        if name != "Newmark" {
            outcome(LIN, &r);
            expect_data(LIN, name, &r, want);
        }
        if let Ok(sys) = &r {
            check!(!sys.condition().is_nan(), "{LIN}: {name}: condition NaN");
            drive::<T, N, N, _>(LIN, name, sys, &u0, &v0, &ld);
            if name == "Newmark::average_acceleration" {
                energy_holds::<T, N, N, _>(LIN, name, sys, s, &d.u0, &d.v0);
            }
        }
    }

    let rho_ok = (0.0..=1.0).contains(&d.rho);
    let alpha_ok = (-1.0 / 3.0..=0.0).contains(&d.alpha);
    let ga = GeneralizedAlpha::<T, N>::new(m, c, k, h, d.rho);
    let hht = GeneralizedAlpha::<T, N>::hht(m, c, k, h, d.alpha);
    for (name, r, ok, which) in [
        ("GeneralizedAlpha::new", ga, rho_ok, Param::RhoInf),
        ("GeneralizedAlpha::hht", hht, alpha_ok, Param::HhtAlpha),
    ] {
        outcome(LIN, &r);
        if ok {
            expect_data(LIN, name, &r, want);
        } else {
            check!(
                r.as_ref().err() == Some(&Error::InvalidParameter(which)),
                "{LIN}: {name} with a parameter out of range: {:?}",
                r.as_ref().err()
            );
        }
        if let Ok(sys) = &r {
            check!(!sys.condition().is_nan(), "{LIN}: {name}: condition NaN");
            drive::<T, N, N, _>(LIN, name, sys, &u0, &v0, &ld);
            // No energy check: generalized-α is stable (spectral radius ≤ 1) but not
            // energy-conserving, and overshoots in its first steps at large ωh (the fuzzer
            // found ×290 after one step at ωh = 95, ρ∞ = 0: the method's known overshoot).
        }
    }
    check!(
        AlphaParameters::chung_hulbert(d.rho).is_ok() == rho_ok
            && AlphaParameters::hht(d.alpha).is_ok() == alpha_ok,
        "{LIN}: AlphaParameters range"
    );

    let ex = Exact::<T, N>::new(m, c, k, h);
    outcome(LIN, &ex);
    expect_data(LIN, "Exact::new", &ex, want);
    if let Ok(sys) = &ex {
        drive::<T, N, N, _>(LIN, "Exact", sys, &u0, &v0, &ld);
    }
}

/// The constructors against each other: `from_rows` bit-identical to `new` (f32 and f64);
/// `f32` fails as `f64` except for overflow; the constructors with the AEM's effective
/// matrix `M + (h/2) C + (h²/4) K` agree.
fn linear_cross<const N: usize>(d: &LinearInputs<N>) {
    let s = &d.sys;
    let (m, c, k, h) = (&s.m, &s.c, &s.k, s.h);
    let (mr, cr, kr, br) = (rows(m), rows(c), rows(k), rows(&d.b));
    check!(
        bits(&Linear::<f64, N>::new(m, c, k, h))
            == bits(&Linear::<f64, N>::from_rows_f64(mr, cr, kr, h))
            && bits(&Linear::<f32, N>::new(m, c, k, h))
                == bits(&Linear::<f32, N>::from_rows_f32(mr, cr, kr, h)),
        "{LIN}: Linear::from_rows differs from Linear::new"
    );
    check!(
        bits(&CompensatedLinear::<f64, N>::new(m, c, k, h))
            == bits(&CompensatedLinear::<f64, N>::from_rows_f64(mr, cr, kr, h))
            && bits(&CompensatedLinear::<f32, N>::new(m, c, k, h))
                == bits(&CompensatedLinear::<f32, N>::from_rows_f32(mr, cr, kr, h)),
        "{LIN}: CompensatedLinear::from_rows differs from new"
    );
    check!(
        bits(&LinearInput::<f64, N, N>::new(m, c, k, &d.b, h))
            == bits(&LinearInput::<f64, N, N>::from_rows_f64(mr, cr, kr, br, h))
            && bits(&LinearInput::<f32, N, N>::new(m, c, k, &d.b, h))
                == bits(&LinearInput::<f32, N, N>::from_rows_f32(mr, cr, kr, br, h)),
        "{LIN}: LinearInput::from_rows differs from new"
    );
    count(LIN, "from_rows compared");
    let l64 = Linear::<f64, N>::new(m, c, k, h);
    let l32 = Linear::<f32, N>::new(m, c, k, h);
    expect_twins(LIN, h, "Linear", &l64, &l32);
    expect_twins(
        LIN,
        h,
        "CompensatedLinear",
        &CompensatedLinear::<f64, N>::new(m, c, k, h),
        &CompensatedLinear::<f32, N>::new(m, c, k, h),
    );
    expect_twins(
        LIN,
        h,
        "LinearInput",
        &LinearInput::<f64, N, N>::new(m, c, k, &d.b, h),
        &LinearInput::<f32, N, N>::new(m, c, k, &d.b, h),
    );
    expect_twins(
        LIN,
        h,
        "Newmark",
        &Newmark::<f64, N>::new(m, c, k, h, d.beta, d.gamma),
        &Newmark::<f32, N>::new(m, c, k, h, d.beta, d.gamma),
    );
    expect_twins(
        LIN,
        h,
        "GeneralizedAlpha",
        &GeneralizedAlpha::<f64, N>::new(m, c, k, h, d.rho),
        &GeneralizedAlpha::<f32, N>::new(m, c, k, h, d.rho),
    );
    expect_twins(
        LIN,
        h,
        "Exact",
        &Exact::<f64, N>::new(m, c, k, h),
        &Exact::<f32, N>::new(m, c, k, h),
    );
    // One effective matrix, one verdict.
    same_outcome(
        LIN,
        "Linear vs CompensatedLinear",
        &l64,
        &CompensatedLinear::<f64, N>::new(m, c, k, h),
    );
    same_outcome(
        LIN,
        "Linear vs Newmark average acceleration",
        &l64,
        &Newmark::<f64, N>::average_acceleration(m, c, k, h),
    );
    same_outcome(
        LIN,
        "Linear vs LinearInput with B = I",
        &l64,
        &LinearInput::<f64, N, N>::new(m, c, k, &SMatrix::identity(), h),
    );
    // Generalized-α with ρ∞ = 1 has half the AEM's effective matrix (a power of two: the
    // same pivots, scaled exactly, where no term is subnormal — halving a subnormal
    // rounds): singular for one, singular for the other.
    let ga1 = GeneralizedAlpha::<f64, N>::new(m, c, k, h, 1.0);
    let sing = |r: Option<Error>| r == Some(Error::SingularEffectiveMatrix);
    // (Within 1e-100 … 1e100: the LU's own products must not underflow either.)
    let normal = |x: f64| x == 0.0 || !x.is_finite() || (1e-100..=1e100).contains(&x.abs());
    let terms = m
        .iter()
        .copied()
        .chain(c.iter().map(|&x| x * (0.5 * h)))
        .chain(k.iter().map(|&x| x * (0.25 * h * h)));
    // (And where neither overflowed first: Linear's effective matrix can overflow where
    // its half does not.)
    let overflow = |r: Option<Error>| r == Some(Error::OperatorOverflow);
    let exact_halving = terms.clone().all(normal)
        && terms.map(|x| x * 0.5).all(normal)
        && !overflow(l64.as_ref().err().copied())
        && !overflow(ga1.as_ref().err().copied());
    check!(
        !exact_halving || sing(l64.as_ref().err().copied()) == sing(ga1.as_ref().err().copied()),
        "{LIN}: Linear {:?} vs GeneralizedAlpha(ρ∞ = 1) {:?}",
        l64.as_ref().err(),
        ga1.as_ref().err()
    );
}
