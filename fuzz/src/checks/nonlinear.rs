//! Fuzz target `nonlinear` (`fuzz_targets/nonlinear.rs`): checks Nonlinear (Duffing-type
//! cubic springs, analytic tangent or finite differences) and Varying, f32 and f64, N = 1
//! and 2.
//!
//! The decoder and the checks every target shares are in `common.rs`.

use aemstep::nalgebra::{SMatrix, SVector};
use aemstep::{
    Coefficients, Error, Linear, Model, NewtonSettings, Nonlinear, Real, Tangent, Varying,
};

use super::common::*;

const NL: &str = "nonlinear";

/// Target `nonlinear`.
pub fn nonlinear(data: &[u8]) {
    let mut b = Bytes::new(data);
    if b.flag() {
        nonlinear_n::<1>(&mut b);
    } else {
        nonlinear_n::<2>(&mut b);
    }
    count(NL, "inputs");
    count(NL, b.category());
}

/// `M u'' + C u' + K u + k3 ∘ u³ = p`, any signs and sizes.
struct Cubic<T, const N: usize> {
    m: SMatrix<T, N, N>,
    c: SMatrix<T, N, N>,
    k: SMatrix<T, N, N>,
    k3: SVector<T, N>,
    tangent: bool,
}

impl<T: Real, const N: usize> Model<T, N> for Cubic<T, N> {
    fn mass(&self) -> SMatrix<T, N, N> {
        self.m
    }
    fn force(&self, u: &SVector<T, N>, v: &SVector<T, N>) -> SVector<T, N> {
        self.c * v + self.k * u + self.k3.component_mul(&u.map(|x| x * x * x))
    }
    fn tangent(&self, u: &SVector<T, N>, _v: &SVector<T, N>) -> Option<Tangent<T, N>> {
        let three = T::from_f64_rounded(3.0);
        self.tangent.then(|| Tangent {
            stiffness: self.k
                + SMatrix::from_diagonal(&self.k3.component_mul(&u.map(|x| three * x * x))),
            damping: self.c,
        })
    }
}

fn settings<T: Real>(b: &mut Bytes) -> (NewtonSettings<T>, bool) {
    let k = u32::from(b.pick(24));
    let tol = match b.pick(4) {
        0 => b.value(),
        1 => 1e-5,
        _ => 1e-10,
    };
    // The rule on the tolerance as the stepper gets it, in `T` (`-1e-50` is `-0` in f32).
    let tol = T::from_f64_rounded(tol);
    let valid = k > 0 && tol.is_finite() && tol >= T::zero();
    let s = if b.flag() {
        NewtonSettings::up_to(k, tol)
    } else {
        NewtonSettings::exactly(k, tol)
    };
    (s, valid)
}

fn nonlinear_n<const N: usize>(b: &mut Bytes) {
    let s = b.system::<N>();
    let k3 = b.vector::<N>();
    let tangent = b.flag();
    let u0 = if b.flag() {
        b.small_vector::<N>()
    } else {
        b.vector()
    };
    let v0 = if b.flag() {
        b.small_vector::<N>()
    } else {
        b.vector()
    };
    let (p, q) = (b.vector::<N>(), b.vector::<N>());
    set_context(format!(
        "N = {N}, M = {:?}, C = {:?}, K = {:?}, h = {:e}, k3 = {:?}, tangent = {tangent}, u0 = {:?}, v0 = {:?}, p = {:?}, q = {:?}",
        s.m.as_slice(),
        s.c.as_slice(),
        s.k.as_slice(),
        s.h,
        k3.as_slice(),
        u0.as_slice(),
        v0.as_slice(),
        p.as_slice(),
        q.as_slice()
    ));
    let set_byte = b.pos;
    nonlinear_typed::<f64, N>(b, &s, &k3, tangent, &u0, &v0, &p, &q);
    b.pos = set_byte; // the same settings bytes for f32
    nonlinear_typed::<f32, N>(b, &s, &k3, tangent, &u0, &v0, &p, &q);
    varying_typed::<f64, N>(&s, &u0, &v0, &p, &q);
    varying_typed::<f32, N>(&s, &u0, &v0, &p, &q);
    // Varying with constant coefficients judges the step's effective matrix as Linear does.
    let lin = Linear::<f64, N>::new(&s.m, &s.c, &s.k, s.h);
    if lin.as_ref().err() == Some(&Error::SingularEffectiveMatrix)
        && let Ok(st) = Varying::<f64, N>::new(s.h)
    {
        let (m, c, k) = (s.m, s.c, s.k);
        let co = move |_t: f64| Coefficients {
            mass: m,
            damping: c,
            stiffness: k,
        };
        let one = SVector::<f64, N>::from_element(1.0);
        if let Ok(mut x) = st.start_with_acceleration(&one, &one, &SVector::zeros()) {
            let r = st.try_step(&co, &mut x, &SVector::zeros());
            check!(
                r == Err(Error::SingularEffectiveMatrixAtStep { step: 1 }),
                "{NL}: Linear found the effective matrix singular, Varying's step gave {r:?}"
            );
            count(NL, "singular verdict compared with Linear");
        }
    }
}

fn nonlinear_typed<T: Real, const N: usize>(
    b: &mut Bytes,
    s: &System<N>,
    k3: &SVector<f64, N>,
    tangent: bool,
    u0: &SVector<f64, N>,
    v0: &SVector<f64, N>,
    p: &SVector<f64, N>,
    q: &SVector<f64, N>,
) {
    let (set, set_ok) = settings::<T>(b);
    let st = Nonlinear::<T, N>::new(s.h, set);
    outcome(NL, &st);
    let want = if !valid_h_as::<T>(s.h) {
        Some(Error::InvalidTimeStep)
    } else if !set_ok {
        Some(Error::InvalidNewtonSettings)
    } else {
        None
    };
    check!(
        st.as_ref().err().copied() == want,
        "{NL}: Nonlinear::new gave {:?}, want {want:?}",
        st.as_ref().err()
    );
    let Ok(st) = st else { return };
    check!(st.time_step().is_finite(), "{NL}: h not finite");
    let model = Cubic {
        m: to_t(&s.m),
        c: to_t(&s.c),
        k: to_t(&s.k),
        k3: to_t(k3),
        tangent,
    };
    let (u, v, p0) = (to_t::<T, N, 1>(u0), to_t::<T, N, 1>(v0), to_t::<T, N, 1>(p));
    let inputs_finite = finite(&u) && finite(&v) && finite(&p0) && finite(&model.m);
    let one = SVector::<T, N>::from_element(T::one());
    let mut x = match st.start(&model, &u, &v, &p0) {
        Ok(x) => {
            check!(inputs_finite && x.is_finite(), "{NL}: start gave {x:?}");
            x
        }
        Err(e) => {
            if !inputs_finite {
                check!(
                    e == Error::NonFiniteInput,
                    "{NL}: start with a non-finite input gave {e:?}"
                );
            } else {
                check!(
                    matches!(
                        e,
                        Error::NonFiniteForce | Error::SingularMass | Error::NonFiniteState
                    ),
                    "{NL}: start gave {e:?}"
                );
            }
            match st.start_with_acceleration(&one, &one, &SVector::zeros()) {
                Ok(x) => x,
                Err(e) => panic!(
                    "property broken: {NL}: start_with_acceleration: {e:?}\n  data: {}",
                    context()
                ),
            }
        }
    };
    for w in loads::<T, N>(p, q) {
        let before = bits(&x);
        let trial = st.trial_step(&model, &x, &w);
        check!(bits(&x) == before, "{NL}: trial_step changed the state");
        let r = st.try_step(&model, &mut x, &w);
        count(NL, "checked steps");
        match r {
            Ok(rep) => {
                check!(
                    finite(&w) && x.is_finite() && rep.converged,
                    "{NL}: Ok step: {x:?}, {rep:?}"
                );
                let (cand, trep) = trial.expect("trial_step failed where try_step succeeded");
                check!(
                    bits(&cand) == bits(&x) && bits(&trep) == bits(&rep),
                    "{NL}: trial_step and try_step differ"
                );
            }
            Err(e) => {
                count(NL, "failed checked steps");
                check!(
                    bits(&x) == before,
                    "{NL}: failed step ({e:?}) changed the state"
                );
                if !finite(&w) || !finite(&model.m) {
                    check!(
                        e == Error::NonFiniteInput,
                        "{NL}: a non-finite load gave {e:?}"
                    );
                } else {
                    check!(
                        matches!(
                            e,
                            Error::NonFiniteForce
                                | Error::SingularJacobian
                                | Error::NotConverged
                                | Error::NonFiniteState
                        ),
                        "{NL}: step gave {e:?}"
                    );
                }
                match (e, trial) {
                    (Error::NotConverged, Ok((_, rep))) => {
                        check!(!rep.converged, "{NL}: NotConverged, the trial converged")
                    }
                    (e, Err(te)) => check!(e == te, "{NL}: try_step {e:?}, trial_step {te:?}"),
                    (e, Ok(_)) => panic!(
                        "property broken: {NL}: try_step {e:?}, trial_step Ok\n  data: {}",
                        context()
                    ),
                }
            }
        }
    }
}

fn varying_typed<T: Real, const N: usize>(
    s: &System<N>,
    u0: &SVector<f64, N>,
    v0: &SVector<f64, N>,
    p: &SVector<f64, N>,
    q: &SVector<f64, N>,
) {
    let st = Varying::<T, N>::new(s.h);
    outcome(NL, &st);
    check!(
        st.as_ref().err().copied() == (!valid_h_as::<T>(s.h)).then_some(Error::InvalidTimeStep),
        "{NL}: Varying::new({:e}) gave {:?}",
        s.h,
        st.as_ref().err()
    );
    let Ok(st) = st else { return };
    let (m, c, k) = (
        to_t::<T, N, N>(&s.m),
        to_t::<T, N, N>(&s.c),
        to_t::<T, N, N>(&s.k),
    );
    let two = T::from_f64_rounded(2.0);
    // C(t) grows with t: the coefficients move between steps.
    let co = move |t: T| Coefficients {
        mass: m,
        damping: c * (T::one() + t.min(T::one())),
        stiffness: k * two,
    };
    // Finite coefficients at the time of step n (as the stepper evaluates them).
    let h_t = st.time_step().as_f64();
    let coefficients_finite = |n: u64| {
        let k = co(T::from_f64_rounded(n as f64 * h_t));
        finite(&k.mass) && finite(&k.damping) && finite(&k.stiffness)
    };
    let (u, v, p0) = (to_t::<T, N, 1>(u0), to_t::<T, N, 1>(v0), to_t::<T, N, 1>(p));
    let one = SVector::<T, N>::from_element(T::one());
    let mut x = match st.start(&co, &u, &v, &p0) {
        Ok(x) => {
            check!(x.is_finite(), "{NL}: Varying start non-finite");
            x
        }
        Err(e) => {
            if !(finite(&u) && finite(&v) && finite(&p0) && coefficients_finite(0)) {
                check!(
                    e == Error::NonFiniteInput,
                    "{NL}: Varying start with a non-finite input gave {e:?}"
                );
            }
            match st.start_with_acceleration(&one, &one, &SVector::zeros()) {
                Ok(x) => x,
                Err(e) => panic!(
                    "property broken: {NL}: Varying start_with_acceleration: {e:?}\n  data: {}",
                    context()
                ),
            }
        }
    };
    for w in loads::<T, N>(p, q) {
        let before = bits(&x);
        let n = x.steps() + 1;
        let r = st.try_step(&co, &mut x, &w);
        count(NL, "checked steps");
        match r {
            Ok(()) => check!(
                finite(&w) && x.is_finite(),
                "{NL}: Varying Ok step gave {x:?}"
            ),
            Err(e) => {
                count(NL, "failed checked steps");
                check!(
                    bits(&x) == before,
                    "{NL}: Varying failed step ({e:?}) changed the state"
                );
                if !(finite(&w) && coefficients_finite(n)) {
                    check!(
                        e == Error::NonFiniteInput,
                        "{NL}: Varying: a non-finite load gave {e:?}"
                    );
                } else {
                    check!(
                        e == Error::NonFiniteState
                            || e == Error::SingularEffectiveMatrixAtStep { step: n },
                        "{NL}: Varying step {n} gave {e:?}"
                    );
                }
            }
        }
    }
}
