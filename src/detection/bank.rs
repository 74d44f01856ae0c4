//! Localization by a bank of models ranked by the likelihood of their innovations.

use nalgebra::SVector;

use super::{Whitener, Window};
use crate::observer::{Estimate, Observer};
use crate::{Error, Param, Real, StepState};

/// `ln 2π`.
const LN_2PI: f64 = 1.837_877_066_409_345_5;

/// `M` fixed-gain observers of `S` states, `I` inputs, `O` measurements on the same
/// measurements — hypotheses about the structure (e.g. the intact building, and one model
/// per storey with that storey's stiffness reduced) — each with the [`Whitener`] of its
/// own innovation covariance. Plain data; `M·(S² + 2S·I + 2S·O + O·I + O² + 2)` values.
///
/// Each step runs every observer ([`Observer::step_innovation`]) and pushes its
/// normalized innovation squared into its [`Window`] of `W` samples; the log-likelihood
/// of model `m` over the window is the Gaussian
///
/// ```text
/// ℓ_m = −½ Σ_window ν_mᵀ S_m⁻¹ ν_m − (n/2) ln det S_m − (n·O/2) ln 2π     (n samples held)
/// ```
///
/// and [`ModelBank::ranking`] orders the models by it, most likely first. Everything is in
/// `T` (an `f32` bank computes no `f64`). Cost of a step: `M` observer steps and
/// `M·O(O+1)/2` multiply-adds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelBank<T, const S: usize, const I: usize, const O: usize, const M: usize> {
    observers: [Observer<T, S, I, O>; M],
    whiteners: [Whitener<T, O>; M],
}

/// The state of a [`ModelBank`]: each model's [`Estimate`] and [`Window`]. Plain data;
/// `const` at rest (`BankState::at_rest_f32`/`at_rest_f64`: every estimate zero with zero
/// input, every window empty; equal to `Default` and to [`ModelBank::start`] at rest).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BankState<T, const S: usize, const I: usize, const M: usize, const W: usize> {
    pub(super) estimates: [Estimate<T, S, I>; M],
    windows: [Window<T, W>; M],
}

/// At rest: as `BankState::at_rest_f32`/`at_rest_f64`.
impl<T: Real, const S: usize, const I: usize, const M: usize, const W: usize> Default
    for BankState<T, S, I, M, W>
{
    fn default() -> Self {
        Self {
            estimates: [Estimate {
                x: SVector::zeros(),
                w: SVector::zeros(),
                n: 0,
                missing: 0,
            }; M],
            windows: [Window::at_rest(); M],
        }
    }
}

macro_rules! bank_state_const {
    ($t:ident, $at_rest:ident, $zeros:ident) => {
        impl<const S: usize, const I: usize, const M: usize, const W: usize>
            BankState<$t, S, I, M, W>
        {
            /// At rest: every model's estimate `x̂ = 0` with input `w = 0`, step 0, every
            /// window empty. `const fn` (for a `static`); equal to `Default`. Cost: none
            /// in a `static`.
            pub const fn $at_rest() -> Self {
                Self {
                    estimates: [Estimate {
                        x: crate::state::$zeros(),
                        w: crate::state::$zeros(),
                        n: 0,
                        missing: 0,
                    }; M],
                    windows: [Window::at_rest(); M],
                }
            }
        }
    };
}
bank_state_const!(f32, at_rest_f32, zeros_f32);
bank_state_const!(f64, at_rest_f64, zeros_f64);

impl<T: Real, const S: usize, const I: usize, const M: usize, const W: usize>
    BankState<T, S, I, M, W>
{
    /// Model `m`'s estimate (`m < M`; panics otherwise, as indexing does).
    pub fn estimate(&self, m: usize) -> &Estimate<T, S, I> {
        &self.estimates[m]
    }

    /// Model `m`'s window of normalized innovations squared (`m < M`).
    pub fn window(&self, m: usize) -> &Window<T, W> {
        &self.windows[m]
    }

    /// Empty every model's window (the estimates are kept): e.g. at a detector's alarm,
    /// so that the ranking weighs only the samples after it. Cost: `O(M)`.
    pub fn clear_windows(&mut self) {
        for w in self.windows.iter_mut() {
            let skipped = w.skipped();
            *w = Window::at_rest();
            w.add_skipped(skipped);
        }
    }
}

impl<T: Real, const S: usize, const I: usize, const O: usize, const M: usize>
    ModelBank<T, S, I, O, M>
{
    /// The bank of `observers`, each with the whitener of its innovations. `const fn`
    /// (a `static` of `const`-built observers and whiteners).
    /// Errors: [`Error::InvalidParameter`] (`M = 0`). Cost: a copy.
    pub const fn from_parts(
        observers: [Observer<T, S, I, O>; M],
        whiteners: [Whitener<T, O>; M],
    ) -> Result<Self, Error> {
        if M == 0 {
            return Err(Error::InvalidParameter(Param::BankSize));
        }
        Ok(Self {
            observers,
            whiteners,
        })
    }

    /// Every model at `x0` with input `w0`, empty windows. Errors:
    /// [`Error::NonFiniteInput`].
    pub fn start<const W: usize>(
        &self,
        x0: &SVector<T, S>,
        w0: &SVector<T, I>,
    ) -> Result<BankState<T, S, I, M, W>, Error> {
        let e = self.observers[0].start(x0, w0)?;
        Ok(BankState {
            estimates: [e; M],
            windows: [Window::at_rest(); M],
        })
    }

    /// One step of every model with input `w` (`w_n`) and measurement `y` (a non-finite
    /// entry: a missing sample, every model predicts only). Each window skips (and
    /// counts) a NaN normalized innovation squared — a NaN sample, or `∞ − ∞` — and takes
    /// an infinite one as its capped term ([`Window::push`]): an infinite sample (its term
    /// is then usually infinite) weighs against every model for a window's length.
    ///
    /// Errors, `state` unchanged: [`Error::NonFiniteInput`] (`w`),
    /// [`Error::NonFiniteState`] (a model's estimate would not be finite). No allocation,
    /// no panic; cost in the type docs.
    pub fn try_step<const W: usize>(
        &self,
        state: &mut BankState<T, S, I, M, W>,
        w: &SVector<T, I>,
        y: &SVector<T, O>,
    ) -> Result<(), Error> {
        if !w.iter().all(|v| v.is_finite()) {
            return Err(Error::NonFiniteInput);
        }
        let mut next = state.estimates;
        let mut q = [T::zero(); M];
        for m in 0..M {
            let nu = self.observers[m].step_innovation(&mut next[m], w, y);
            if !next[m].is_finite() {
                return Err(Error::NonFiniteState);
            }
            q[m] = self.whiteners[m].nis(&nu);
        }
        state.estimates = next;
        for m in 0..M {
            state.windows[m].push(q[m]);
        }
        Ok(())
    }

    /// The log-likelihood `ℓ_m` of each model over its window (natural log, densities in
    /// output units; see the type docs), in `T`. Cost: `O(M)`.
    pub fn log_likelihoods<const W: usize>(&self, state: &BankState<T, S, I, M, W>) -> [T; M] {
        // `O ln 2π` in `f64`, rounded once (a constant after inlining).
        let norm = T::from_f64_rounded(O as f64 * LN_2PI);
        let half = T::from_f64_rounded(0.5);
        core::array::from_fn(|m| {
            let win = &state.windows[m];
            // `as` (never `None` for a float).
            let n = T::from_usize(win.len()).unwrap_or_else(T::zero);
            -(half * (win.sum() + n * (self.whiteners[m].log_det() + norm)))
        })
    }

    /// The models' indices ordered by [`ModelBank::log_likelihoods`], most likely first
    /// (ties: the lower index first). Cost: `O(M²)` comparisons.
    pub fn ranking<const W: usize>(&self, state: &BankState<T, S, I, M, W>) -> [usize; M] {
        let ll = self.log_likelihoods(state);
        let mut idx: [usize; M] = core::array::from_fn(|m| m);
        // Insertion sort: stable, no allocation, M is small.
        for i in 1..M {
            let mut j = i;
            while j > 0 && ll[idx[j]] > ll[idx[j - 1]] {
                idx.swap(j, j - 1);
                j -= 1;
            }
        }
        idx
    }

    /// Model `m`'s observer (`m < M`).
    pub fn observer(&self, m: usize) -> &Observer<T, S, I, O> {
        &self.observers[m]
    }
}
