//! The state every stepper advances, and the interface they share.

use nalgebra::SVector;

use crate::{Error, Real};

/// The state at step `n`: displacement `u`, velocity `v`, acceleration `a` (the paper's
/// fictitious load `q`) and the step count. Time is `n·h`, computed from the count
/// ([`State::time`]), never accumulated.
///
/// A state comes from a stepper's `start` and is advanced by its `step`; it is plain data
/// (`Copy`, `3N + 1` words).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State<T, const N: usize> {
    pub(crate) u: SVector<T, N>,
    pub(crate) v: SVector<T, N>,
    pub(crate) a: SVector<T, N>,
    pub(crate) n: u64,
}

impl<T: Real, const N: usize> State<T, N> {
    /// A state from its parts (no check; used by steppers and by callers restoring a
    /// saved state).
    pub fn from_parts(u: SVector<T, N>, v: SVector<T, N>, a: SVector<T, N>, steps: u64) -> Self {
        Self { u, v, a, n: steps }
    }
    /// Displacement `u_n` (model units, e.g. m).
    pub fn u(&self) -> &SVector<T, N> {
        &self.u
    }
    /// Velocity `v_n = u'(t_n)`.
    pub fn v(&self) -> &SVector<T, N> {
        &self.v
    }
    /// Acceleration `a_n = u''(t_n)`, the paper's fictitious load `q_n`.
    pub fn a(&self) -> &SVector<T, N> {
        &self.a
    }
    /// Steps taken since the start, `n`.
    pub fn steps(&self) -> u64 {
        self.n
    }
    /// Time `t_n = n·h` (computed in `f64` from the count, then rounded once).
    pub fn time(&self, h: T) -> T {
        T::from_f64_rounded(self.n as f64 * h.as_f64())
    }
    /// The state at step 0 from given `u0, v0, a0`.
    /// Errors: [`Error::NonFiniteInput`] if any entry is not finite.
    pub(crate) fn initial_given(
        u0: &SVector<T, N>,
        v0: &SVector<T, N>,
        a0: &SVector<T, N>,
    ) -> Result<Self, Error> {
        Self::initial_computed(u0, v0, *a0).map_err(|_| Error::NonFiniteInput)
    }

    /// The state at step 0 with a computed initial acceleration `a0` (inputs already
    /// checked finite). Errors: [`Error::NonFiniteState`] if `a0` overflowed.
    pub(crate) fn initial_computed(
        u0: &SVector<T, N>,
        v0: &SVector<T, N>,
        a0: SVector<T, N>,
    ) -> Result<Self, Error> {
        let s = Self::from_parts(*u0, *v0, a0, 0);
        if s.is_finite() {
            Ok(s)
        } else {
            Err(Error::NonFiniteState)
        }
    }

    /// Every entry of `u`, `v`, `a` is finite.
    pub fn is_finite(&self) -> bool {
        self.u
            .iter()
            .chain(self.v.iter())
            .chain(self.a.iter())
            .all(|x| x.is_finite())
    }
}

#[cfg(feature = "defmt")]
impl<T: Real + defmt::Format, const N: usize> defmt::Format for State<T, N> {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(
            f,
            "State {{ n: {}, u: {}, v: {}, a: {} }}",
            self.n,
            self.u.as_slice(),
            self.v.as_slice(),
            self.a.as_slice()
        )
    }
}

/// A fixed-step integrator for `M u'' + C u' + K u = p(t)` with `N` degrees of freedom.
///
/// Every scheme of the crate implements it, so switching scheme is a one-line change.
pub trait Stepper<T: Real, const N: usize> {
    /// The time step `h` (s).
    fn time_step(&self) -> T;

    /// The state at `t = 0` with the initial acceleration from the equation of motion,
    /// `a0 = M⁻¹ (p0 − C v0 − K u0)` (paper eq. 40).
    ///
    /// Errors: [`Error::NonFiniteInput`]; [`Error::SingularMass`] if `M` is singular.
    fn start(
        &self,
        u0: &SVector<T, N>,
        v0: &SVector<T, N>,
        p0: &SVector<T, N>,
    ) -> Result<State<T, N>, Error>;

    /// The state at `t = 0` with a known initial acceleration `a0` (for singular `M`).
    ///
    /// Errors: [`Error::NonFiniteInput`].
    fn start_with_acceleration(
        &self,
        u0: &SVector<T, N>,
        v0: &SVector<T, N>,
        a0: &SVector<T, N>,
    ) -> Result<State<T, N>, Error> {
        State::initial_given(u0, v0, a0)
    }

    /// Advance `state` from `t_{n−1}` to `t_n` under the load `p_n = p(t_n)`.
    ///
    /// Fixed cost, no allocation, no panic, no data-dependent branch. A NaN load gives a
    /// NaN state: use [`Stepper::try_step`] where that must not happen.
    fn step(&self, state: &mut State<T, N>, p: &SVector<T, N>);

    /// Advance with the load samples at both ends of the step, `p_prev = p(t_{n−1})` and
    /// `p = p(t_n)` — what a loop over a sampled signal has anyway. Generic code that
    /// calls this drives every scheme at its full order:
    ///
    /// - schemes whose step depends on `p_n` only — the AEM ([`Linear`](crate::Linear),
    ///   [`AForm`](crate::AForm)), [`Newmark`](crate::Newmark), and
    ///   [`Exact`](crate::Exact), which recovers `p_{n−1}` from its state — ignore
    ///   `p_prev` (this default);
    /// - [`GeneralizedAlpha`](crate::GeneralizedAlpha) takes the load as
    ///   `(1 − α_f) p + α_f p_prev`, the textbook form; through [`Stepper::step`] it must
    ///   assume `p_prev = p`, which is first order for a time-varying load.
    ///
    /// Cost, panics, allocation: as [`Stepper::step`].
    #[inline]
    fn step_with_previous_load(
        &self,
        state: &mut State<T, N>,
        p_prev: &SVector<T, N>,
        p: &SVector<T, N>,
    ) {
        let _ = p_prev;
        self.step(state, p);
    }

    /// [`Stepper::step`], committed only if the new state is finite.
    ///
    /// Errors: [`Error::NonFiniteState`] (e.g. a NaN load sample), leaving `state`
    /// bit-identical to what it was. Cost: one step plus a copy and a scan of `3N` values.
    fn try_step(&self, state: &mut State<T, N>, p: &SVector<T, N>) -> Result<(), Error> {
        commit_if_finite(state, |next| self.step(next, p))
    }

    /// [`Stepper::step_with_previous_load`], committed only if the new state is finite.
    ///
    /// Errors: as [`Stepper::try_step`]; `state` is unchanged on error.
    fn try_step_with_previous_load(
        &self,
        state: &mut State<T, N>,
        p_prev: &SVector<T, N>,
        p: &SVector<T, N>,
    ) -> Result<(), Error> {
        commit_if_finite(state, |next| self.step_with_previous_load(next, p_prev, p))
    }
}

/// Run `step` on a copy of `state` and commit it only if the result is finite.
#[inline]
fn commit_if_finite<T: Real, const N: usize>(
    state: &mut State<T, N>,
    step: impl FnOnce(&mut State<T, N>),
) -> Result<(), Error> {
    let mut next = *state;
    step(&mut next);
    if next.is_finite() {
        *state = next;
        Ok(())
    } else {
        Err(Error::NonFiniteState)
    }
}
