//! A fixed-lag smoother with steady gains: the estimate of the state `L` samples late,
//! given the measurements up to now.
//!
//! On any model of the observers ([`StateSpace`], [`Measurement`]; for an unknown force,
//! the [`AugmentedModel`](super::augmented::AugmentedModel), whose state carries the
//! force) with the steady-state Kalman solution ([`SteadyState`]: a-priori `P`, gain
//! `L₀ = P Hᵀ Σ⁻¹`, `Σ = H P Hᵀ + R`), the smoothed estimates obey (Anderson & Moore,
//! *Optimal Filtering*, §7.3):
//!
//! ```text
//! x̂_{n−i|n} = x̂_{n−i|n−1} + K_i ν_n,     ν_n = y_n − H x̂_{n|n−1} − D w_n,  i = 0 … L
//! K_i = P (Āᵀ)^i Hᵀ Σ⁻¹,                  Ā = Φ (I − L₀ H)
//! ```
//!
//! since the cross covariance of the a-priori errors `n − i` and `n` is `P (Āᵀ)^i` in the
//! steady state (`i = 0` is the filter's own correction). With a process–measurement cross
//! covariance `N` ([`SteadyState::from_parts_cross`], held in [`SteadyState::cross`]) the
//! a-priori error is correlated with its own sample's measurement noise, so
//! `Σ = H P Hᵀ + R + H N + Nᵀ Hᵀ`, `K_0 = (P Hᵀ + N) Σ⁻¹` and
//! `K_i = (P Āᵀ − N L₀ᵀ Φᵀ) (Āᵀ)^(i−1) Hᵀ Σ⁻¹`. A step is the fixed-gain
//! observer's plus the `L` updates of a ring of past estimates.

use nalgebra::{SMatrix, SVector};

use crate::linalg::{self, Mat, add_scaled, all_finite, finite_as, identity, mul, round_rows};
use crate::linalg::{rows_f64, transpose};
use crate::observer::{Measurement, StateSpace, SteadyState, is_covariance, lu_of, symmetrize};
use crate::observer::{innovation_parts, is_zero, next_counts};
use crate::{Error, Real, StepState};

/// The gains `K_0` (the filter gain) and `K_1 … K_L` from the steady solution and `r`,
/// and the checks that the model and the gains fit the scalar type whose largest finite
/// value is `max` (the run-time constructor and the `const fn` twins alike).
#[allow(clippy::type_complexity)]
const fn lag_gains<
    const N: usize,
    const S: usize,
    const I: usize,
    const O: usize,
    const L: usize,
>(
    model: &StateSpace<N, S, I>,
    meas: &Measurement<S, I, O>,
    steady: &SteadyState<S, O>,
    r: &Mat<O, O>,
    max: f64,
) -> Result<(Mat<S, O>, [Mat<S, O>; L]), Error> {
    if !is_covariance(r, true) {
        return Err(Error::InvalidCovariance);
    }
    if !(all_finite(&steady.covariance)
        && all_finite(&steady.gain)
        && all_finite(&meas.h)
        && all_finite(&meas.d)
        && all_finite(&model.phi))
    {
        return Err(Error::NonFiniteInput);
    }
    let p = &steady.covariance;
    let h = &meas.h;
    if !all_finite(&steady.cross) {
        return Err(Error::NonFiniteInput);
    }
    let cross = if is_zero(&steady.cross) {
        None
    } else {
        Some(&steady.cross)
    };
    let sigma = match cross {
        None => symmetrize(&add_scaled(r, 1.0, &mul(h, &mul(p, &transpose(h))))),
        Some(n) => symmetrize(&innovation_parts(p, h, r, Some(n)).1),
    };
    let lu = match lu_of(&sigma) {
        Some(lu) => lu,
        None => return Err(Error::InvalidCovariance),
    };
    // V₀ = Hᵀ Σ⁻¹ = (Σ⁻¹ H)ᵀ; V_i = Āᵀ V_{i−1}; K_i = P V_i. With the cross covariance N
    // (E e⁻_m r_mᵀ = N) the filter's own gain is K₀ = P V₀ + N Σ⁻¹, and the a-priori
    // errors m and m + 1 have the cross covariance P Āᵀ − N Lᵀ Φᵀ, so
    // K_i = P V_i − N Lᵀ Φᵀ V_{i−1}.
    let mut v = transpose(&lu.solve(h));
    let k0 = match cross {
        None => mul(p, &v),
        Some(n) => add_scaled(&mul(p, &v), 1.0, &transpose(&lu.solve(&transpose(n)))),
    };
    let abar = mul(
        &model.phi,
        &add_scaled(&identity(), -1.0, &mul(&steady.gain, h)),
    );
    let abt = transpose(&abar);
    // N Lᵀ Φᵀ (S×S), only with the cross term.
    let nlp = match cross {
        None => [[0.0; S]; S],
        Some(n) => mul(n, &transpose(&mul(&model.phi, &steady.gain))),
    };
    let mut ks = [[[0.0; O]; S]; L];
    let mut i = 0;
    while i < L {
        let prev = v;
        v = mul(&abt, &v);
        ks[i] = match cross {
            None => mul(p, &v),
            Some(_) => add_scaled(&mul(p, &v), -1.0, &mul(&nlp, &prev)),
        };
        i += 1;
    }
    // The model and gains fit `T`.
    if !(all_finite(&model.gamma0) && all_finite(&model.gamma1) && all_finite(&k0)) {
        return Err(Error::NonFiniteInput);
    }
    let mut ok = finite_as(&model.phi, max)
        && finite_as(&model.gamma0, max)
        && finite_as(&model.gamma1, max)
        && finite_as(&meas.h, max)
        && finite_as(&meas.d, max)
        && finite_as(&k0, max);
    let mut i = 0;
    while i < L {
        ok = ok && finite_as(&ks[i], max);
        i += 1;
    }
    if ok {
        Ok((k0, ks))
    } else {
        Err(Error::OperatorOverflow)
    }
}

/// The state of a [`FixedLag`] smoother: the filtered estimate `x̂_{n|n}`, the last
/// input, a ring of the `L` previous estimates (each smoothed by every measurement since)
/// and their inputs, the step count and the missing measurements. Plain data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixedLagState<T, const S: usize, const I: usize, const L: usize> {
    x: SVector<T, S>,
    w: SVector<T, I>,
    past: [[T; S]; L],
    past_w: [[T; I]; L],
    head: usize,
    n: u64,
    missing: u64,
}

impl<T: Real, const S: usize, const I: usize, const L: usize> FixedLagState<T, S, I, L> {
    /// The filtered estimate `x̂_{n|n}`.
    pub fn filtered(&self) -> &SVector<T, S> {
        &self.x
    }
    /// The smoothed estimate `x̂_{n−L|n}` and the input `w_{n−L}` of that step (for a
    /// [`Readout`](crate::observer::Readout)). For `n < L` it is the start, smoothed.
    pub fn lagged(&self) -> (SVector<T, S>, SVector<T, I>) {
        if L == 0 {
            return (self.x, self.w);
        }
        (self.past[self.head].into(), self.past_w[self.head].into())
    }
    /// Steps taken since the start.
    pub fn steps(&self) -> u64 {
        self.n
    }
    /// Steps whose measurement was missing (predicted, nothing smoothed).
    pub fn missing(&self) -> u64 {
        self.missing
    }
}

impl<T: Real, const S: usize, const I: usize, const L: usize> StepState
    for FixedLagState<T, S, I, L>
{
    fn is_finite(&self) -> bool {
        self.x.iter().chain(self.w.iter()).all(|v| v.is_finite())
            && self.past.iter().flatten().all(|v| v.is_finite())
    }
    fn steps(&self) -> u64 {
        self.n
    }
}

/// The fixed-lag smoother (module docs) on `S` states, `I` known inputs, `O`
/// measurements, lag `L` samples, stepping in `T`.
///
/// Cost of a step: `S² + 2S·I + 2S·O + O·I + L·S·O` multiply-adds (the observer's plus
/// `L·S·O`). Size: `S² + 2S·I + O·(S + I) + (L + 1)·S·O` values of `T`; the state
/// `(L + 1)·(S + I)`. [`FixedLag::new`] and `from_parts_f32`/`_f64` (`const fn`) are bit-identical.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixedLag<T, const S: usize, const I: usize, const O: usize, const L: usize> {
    phi: [[T; S]; S],
    gamma0: [[T; I]; S],
    gamma1: [[T; I]; S],
    h: [[T; S]; O],
    d: [[T; I]; O],
    k0: [[T; O]; S],
    ks: [[[T; O]; S]; L],
}

impl<T: Real, const S: usize, const I: usize, const O: usize, const L: usize>
    FixedLag<T, S, I, O, L>
{
    /// The smoother of `model` measuring `meas` with the steady Kalman solution `steady`
    /// ([`SteadyState`] of the same model, measurement and `r`) and the measurement
    /// noise `r`, rounded once to `T`.
    ///
    /// Errors: [`Error::InvalidCovariance`] (`r`), [`Error::NonFiniteInput`],
    /// [`Error::OperatorOverflow`]. Cost: `O(L·S²·O)`.
    pub fn new<const N: usize>(
        model: &StateSpace<N, S, I>,
        meas: &Measurement<S, I, O>,
        steady: &SteadyState<S, O>,
        r: &SMatrix<f64, O, O>,
    ) -> Result<Self, Error> {
        let (k0, ks) = lag_gains::<N, S, I, O, L>(model, meas, steady, &rows_f64(r), T::MAX)?;
        Ok(Self {
            phi: round_rows(&model.phi),
            gamma0: round_rows(&model.gamma0),
            gamma1: round_rows(&model.gamma1),
            h: round_rows(&meas.h),
            d: round_rows(&meas.d),
            k0: round_rows(&k0),
            ks: core::array::from_fn(|i| round_rows(&ks[i])),
        })
    }

    /// The start: `x̂_0 = x0`, input `w0`; the ring holds copies of them.
    /// Errors: [`Error::NonFiniteInput`].
    pub fn start(
        &self,
        x0: &SVector<T, S>,
        w0: &SVector<T, I>,
    ) -> Result<FixedLagState<T, S, I, L>, Error> {
        let s = FixedLagState {
            x: *x0,
            w: *w0,
            past: [(*x0).into(); L],
            past_w: [(*w0).into(); L],
            head: 0,
            n: 0,
            missing: 0,
        };
        if s.is_finite() && w0.iter().all(|v| v.is_finite()) {
            Ok(s)
        } else {
            Err(Error::NonFiniteInput)
        }
    }

    /// One step with the input `w` (`w_n`) and the measurement `y` (a non-finite entry:
    /// missing, nothing corrected, counted). Checked: a non-finite input or result leaves
    /// `s` unchanged.
    ///
    /// Errors: [`Error::NonFiniteInput`] (`w`), [`Error::NonFiniteState`],
    /// [`Error::StepCountOverflow`] (the step count, or the count of missing samples, would
    /// pass `u64::MAX`: refused rather than wrapped). No allocation,
    /// no panic; cost in the type docs.
    pub fn try_step(
        &self,
        s: &mut FixedLagState<T, S, I, L>,
        w: &SVector<T, I>,
        y: &SVector<T, O>,
    ) -> Result<(), Error> {
        if !w.iter().all(|v| v.is_finite()) {
            return Err(Error::NonFiniteInput);
        }
        let mut next = *s;
        let xp = SVector::<T, S>::from_fn(|i, _| {
            let mut a = T::zero();
            for j in 0..S {
                a += self.phi[i][j] * s.x[j];
            }
            for j in 0..I {
                a += self.gamma0[i][j] * s.w[j] + self.gamma1[i][j] * w[j];
            }
            a
        });
        let measured = y.iter().all(|v| v.is_finite());
        let nu = SVector::<T, O>::from_fn(|o, _| {
            let mut a = y[o];
            for j in 0..S {
                a -= self.h[o][j] * xp[j];
            }
            for j in 0..I {
                a -= self.d[o][j] * w[j];
            }
            if measured { a } else { T::zero() }
        });
        next.x = xp;
        for i in 0..S {
            for o in 0..O {
                next.x[i] += self.k0[i][o] * nu[o];
            }
        }
        if L > 0 {
            // The ring: lag j (1 … L) of the step before sits at slot (head + L − j) % L,
            // lag L at head. Lag j becomes lag j + 1 (corrected by K_{j+1} ν); lag L drops
            // out, and its slot takes the previous filtered estimate as lag 1 (+ K_1 ν).
            let head = s.head;
            for lag in 1..L {
                let slot = (head + L - lag) % L;
                for i in 0..S {
                    for o in 0..O {
                        next.past[slot][i] += self.ks[lag][i][o] * nu[o];
                    }
                }
            }
            for i in 0..S {
                let mut a = s.x[i];
                for o in 0..O {
                    a += self.ks[0][i][o] * nu[o];
                }
                next.past[head][i] = a;
            }
            next.past_w[head] = s.w.into();
            next.head = (head + 1) % L;
        }
        next.w = *w;
        (next.n, next.missing) =
            next_counts(s.n, s.missing, measured).ok_or(Error::StepCountOverflow)?;
        if !next.is_finite() {
            return Err(Error::NonFiniteState);
        }
        *s = next;
        Ok(())
    }
}

macro_rules! lag_const {
    ($t:ident, $from_parts:ident) => {
        impl<const S: usize, const I: usize, const O: usize, const L: usize>
            FixedLag<$t, S, I, O, L>
        {
            /// `const fn` twin of [`FixedLag::new`] with `r` row-major (a `static` keeps
            /// the gains in flash); bit-identical to it.
            ///
            /// Errors: as [`FixedLag::new`].
            pub const fn $from_parts<const N: usize>(
                model: &StateSpace<N, S, I>,
                meas: &Measurement<S, I, O>,
                steady: &SteadyState<S, O>,
                r: &[[f64; O]; O],
            ) -> Result<Self, Error> {
                let max = $t::MAX as f64;
                let (k0, ks) = match lag_gains::<N, S, I, O, L>(model, meas, steady, r, max) {
                    Ok(g) => g,
                    Err(e) => return Err(e),
                };
                let mut kt = [[[0.0 as $t; O]; S]; L];
                let mut i = 0;
                while i < L {
                    kt[i] = linalg::const_round!($t, rows ks[i]);
                    i += 1;
                }
                Ok(Self {
                    phi: linalg::const_round!($t, rows model.phi),
                    gamma0: linalg::const_round!($t, rows model.gamma0),
                    gamma1: linalg::const_round!($t, rows model.gamma1),
                    h: linalg::const_round!($t, rows meas.h),
                    d: linalg::const_round!($t, rows meas.d),
                    k0: linalg::const_round!($t, rows k0),
                    ks: kt,
                })
            }
        }
    };
}
lag_const!(f32, from_parts_f32);
lag_const!(f64, from_parts_f64);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::observer::building_fixture;

    /// Regression: the smoother's step wrapped its counters (`u64::MAX + 1 = 0`); it now
    /// refuses with a typed error, the state unchanged.
    #[test]
    fn smoother_refuses_to_wrap_its_counters() {
        let (ss, meas) = building_fixture();
        let q = SMatrix::<f64, 10, 10>::identity() * 1e-10;
        let r = SMatrix::<f64, 2, 2>::identity() * 0.01;
        let kf = SteadyState::new(&ss, &meas, &q, &r).unwrap();
        let sm = FixedLag::<f64, 10, 1, 2, 3>::new(&ss, &meas, &kf, &r).unwrap();
        let w = SVector::from([0.1]);
        let mut s = sm.start(&SVector::zeros(), &w).unwrap();
        s.n = u64::MAX;
        let before = s;
        let y = SVector::from([0.0, 0.0]);
        assert_eq!(sm.try_step(&mut s, &w, &y), Err(Error::StepCountOverflow));
        assert_eq!(s, before);
        s.n = 0;
        s.missing = u64::MAX;
        let before = s;
        let gap = SVector::from([f64::NAN, 0.0]);
        assert_eq!(sm.try_step(&mut s, &w, &gap), Err(Error::StepCountOverflow));
        assert_eq!(s, before);
    }
}
