//! The one interface of every constant-coefficient linear scheme.

use nalgebra::SVector;

use crate::{Error, Real, State};

/// What a stepper advances: [`State`] (`u, v, a` of the `N` degrees of freedom) or a
/// reduced state ([`ModalState`](crate::ModalState)). Plain data.
pub trait StepState: Copy {
    /// Every value is finite.
    fn is_finite(&self) -> bool;
    /// Steps taken since the start, `n` (time is `n·h`).
    fn steps(&self) -> u64;
}

/// What drives a step: a load or input vector. Implemented for `SVector<T, I>`.
pub trait StepInput {
    /// Every value is finite.
    fn is_finite(&self) -> bool;
}

impl<T: Real, const I: usize> StepInput for SVector<T, I> {
    #[inline]
    fn is_finite(&self) -> bool {
        self.iter().all(|v| v.is_finite())
    }
}

/// A fixed-step integrator for `M u'' + C u' + K u = p(t)` with `N` degrees of freedom:
/// the interface every linear scheme of the crate implements — [`Linear`](crate::Linear),
/// [`AForm`](crate::AForm), [`LinearInput`](crate::LinearInput),
/// [`Modal`](crate::Modal), [`Newmark`](crate::Newmark),
/// [`GeneralizedAlpha`](crate::GeneralizedAlpha), [`Exact`](crate::Exact),
/// [`KrAlpha`](crate::KrAlpha) — so one
/// generic function drives them all and switching scheme is a one-line change:
///
/// ```
/// use aemstep::{Error, Linear, Modal, StepState, Stepper};
/// use aemstep::{matrix, vector};
/// use aemstep::nalgebra::SVector;
///
/// /// Step any scheme through a load history; the displacement of DOF 0 at the end.
/// fn run<S: Stepper<f64, 2>>(sys: &S, loads: &[S::Input]) -> Result<f64, Error> {
///     let zero = SVector::zeros();
///     let mut s = sys.start(&zero, &zero, &loads[0])?;
///     for pair in loads.windows(2) {
///         sys.try_step_with_previous_input(&mut s, &pair[0], &pair[1])?;
///     }
///     Ok(sys.full_state(&s).u()[0])
/// }
/// let (m, c, k) = (matrix![1.0, 0.0; 0.0, 1.0], matrix![0.0, 0.0; 0.0, 0.0],
///                  matrix![2.0, -1.0; -1.0, 2.0]);
/// let full = Linear::<f64, 2>::new(&m, &c, &k, 0.01)?;
/// let loads = [vector![0.0, 0.0], vector![1.0, 0.0], vector![1.0, 0.0]];
/// let u_full = run(&full, &loads)?;
/// // Both modes kept, input through B = I: the same sequence to rounding.
/// let modal = Modal::<f64, 2, 2, 2, 1>::new(&m, &k, &aemstep::Damping::None,
///     &matrix![1.0, 0.0; 0.0, 1.0], &matrix![1.0, 0.0], 0.01)?;
/// assert!((run(&modal, &loads)? - u_full).abs() < 1e-15);
/// # Ok::<(), aemstep::Error>(())
/// ```
///
/// **Checked and unchecked.** [`Stepper::step`] is the bare recurrence: fixed cost, no
/// check, a NaN input gives a NaN state. [`Stepper::try_step`] checks the input and the
/// result and commits only a finite state: that is what `try_` means everywhere in the
/// crate ([`Nonlinear::try_step`](crate::Nonlinear::try_step),
/// [`Varying::try_step`](crate::Varying::try_step) have no unchecked twin).
pub trait Stepper<T: Real, const N: usize> {
    /// What drives a step: the load `p` (`SVector<T, N>`), or the `I` input signals `w` of
    /// an influence matrix `p = B w` (`SVector<T, I>`).
    type Input: StepInput;
    /// What a step advances: [`State<T, N>`], or a reduced state.
    type State: StepState;

    /// The time step `h` (s).
    fn time_step(&self) -> T;

    /// The state at `t = 0` with the initial acceleration from the equation of motion,
    /// `a0 = M⁻¹ (p0 − C v0 − K u0)` (paper eq. 40), `p0` the load (or `B w0`).
    ///
    /// Errors: [`Error::NonFiniteInput`]; [`Error::SingularMass`] if `M` is singular (start
    /// with [`Stepper::start_with_acceleration`] instead); [`Error::NonFiniteState`] if `a0`
    /// overflows.
    fn start(
        &self,
        u0: &SVector<T, N>,
        v0: &SVector<T, N>,
        w0: &Self::Input,
    ) -> Result<Self::State, Error>;

    /// The state at `t = 0` with a known initial acceleration `a0` (for singular `M`, or a
    /// state handed over from another scheme). A reduced stepper projects `u0, v0, a0` on
    /// its basis.
    ///
    /// Errors: [`Error::NonFiniteInput`]; [`Error::NonFiniteState`] where a reduced
    /// stepper's projection overflows.
    fn start_with_acceleration(
        &self,
        u0: &SVector<T, N>,
        v0: &SVector<T, N>,
        a0: &SVector<T, N>,
    ) -> Result<Self::State, Error>;

    /// Advance `state` from `t_{n−1}` to `t_n` under the input `w_n = w(t_n)`.
    ///
    /// Fixed cost, no allocation, no panic, no data-dependent branch. A NaN input gives a
    /// NaN state: use [`Stepper::try_step`] where that must not happen.
    fn step(&self, state: &mut Self::State, w: &Self::Input);

    /// Advance with the input samples at both ends of the step, `w_prev = w(t_{n−1})` and
    /// `w = w(t_n)` — what a loop over a sampled signal has anyway. Generic code that calls
    /// this drives every scheme at its full order:
    ///
    /// - the AEM ([`Linear`](crate::Linear), [`AForm`](crate::AForm),
    ///   [`LinearInput`](crate::LinearInput), [`Modal`](crate::Modal)) and
    ///   [`Newmark`](crate::Newmark) depend on `w_n` only and ignore `w_prev` (this
    ///   default);
    /// - [`GeneralizedAlpha`](crate::GeneralizedAlpha) and [`KrAlpha`](crate::KrAlpha) take
    ///   the load as `(1 − α_f) p + α_f p_prev`; [`Exact`](crate::Exact) takes the load linear between
    ///   `p_prev` and `p`. Through [`Stepper::step`] both must assume a previous load (see
    ///   their docs).
    ///
    /// Cost, panics, allocation: as [`Stepper::step`].
    #[inline]
    fn step_with_previous_input(
        &self,
        state: &mut Self::State,
        w_prev: &Self::Input,
        w: &Self::Input,
    ) {
        let _ = w_prev;
        self.step(state, w);
    }

    /// [`Stepper::step`], checked: the input must be finite and the new state finite, else
    /// `state` is left bit-identical.
    ///
    /// Errors: [`Error::NonFiniteInput`] (a NaN or infinite input), [`Error::NonFiniteState`]
    /// (the step overflowed). Cost: one step plus a copy, a scan of the input and of the
    /// state.
    fn try_step(&self, state: &mut Self::State, w: &Self::Input) -> Result<(), Error> {
        if !w.is_finite() {
            return Err(Error::NonFiniteInput);
        }
        commit_if_finite(state, |next| self.step(next, w))
    }

    /// [`Stepper::step_with_previous_input`], checked.
    ///
    /// Errors: as [`Stepper::try_step`] (both samples are checked); `state` is unchanged on
    /// error.
    fn try_step_with_previous_input(
        &self,
        state: &mut Self::State,
        w_prev: &Self::Input,
        w: &Self::Input,
    ) -> Result<(), Error> {
        if !(w_prev.is_finite() && w.is_finite()) {
            return Err(Error::NonFiniteInput);
        }
        commit_if_finite(state, |next| self.step_with_previous_input(next, w_prev, w))
    }

    /// The state in the `N` physical degrees of freedom: a copy for the full-order schemes,
    /// `u = Φ η` (and `v`, `a`) for a reduced one. Cost: `0` or `3N·R`.
    fn full_state(&self, state: &Self::State) -> State<T, N>;
}

/// Run `step` on a copy of `state` and commit it only if the result is finite: the one
/// commit rule of every checked step in the crate.
///
/// Errors: [`Error::NonFiniteState`], `state` unchanged.
#[inline]
pub(crate) fn commit_if_finite<S: StepState>(
    state: &mut S,
    step: impl FnOnce(&mut S),
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

/// A start of a stepper from `u0`, `v0` (`&SVector<T, N>`, the `T`, `N` of the surrounding
/// `impl`; `&SVector<f64, N>` after a leading `f64;`) and further arguments, returning `Result<$state, Error>`: the one signature of
/// [`Stepper::start`], [`Stepper::start_with_acceleration`] and the starts of the same
/// form. The call names `self` and the two vectors (so that its body can use them) and
/// gives the further arguments with their types, e.g.
/// `start_fn! { fn start(&self, u0, v0, p0: &SVector<T, N>) -> State<T, N> { … } }`;
/// attributes and docs go through unchanged. Cost: none.
macro_rules! start_fn {
    (
        @with $scalar:ty;
        $(#[$attr:meta])*
        $vis:vis fn $name:ident(&$this:ident, $u0:ident, $v0:ident, $($arg:ident: $ty:ty),+ $(,)?)
            -> $state:ty
        $body:block
    ) => {
        $(#[$attr])*
        $vis fn $name(
            &$this,
            $u0: &nalgebra::SVector<$scalar, N>,
            $v0: &nalgebra::SVector<$scalar, N>,
            $($arg: $ty),+
        ) -> Result<$state, $crate::Error> $body
    };
    // The start of a model in `f64` (no `T` in scope): `start_fn! { f64; fn … }`.
    (f64; $($rest:tt)*) => {
        $crate::stepper::start_fn!(@with f64; $($rest)*);
    };
    ($($rest:tt)*) => {
        $crate::stepper::start_fn!(@with T; $($rest)*);
    };
}
pub(crate) use start_fn;

/// The [`Stepper`] methods every full-order scheme (state [`State<T, N>`]) shares, for a
/// scheme whose start-up operators are in the field (path) `$start` (an
/// `Option<StartOps<T, N>>`): `start` (`a0` from the equation of motion),
/// `start_with_acceleration` (the given `u0, v0, a0`, checked finite) and `full_state` (a
/// copy). Expands inside an `impl Stepper<T, N> for …` block.
macro_rules! full_order_state {
    ($($start:ident).+) => {
        $crate::stepper::start_fn! {
            fn start(&self, u0, v0, p0: &nalgebra::SVector<T, N>) -> $crate::State<T, N> {
                $crate::kernel::initial_state(self.$($start).+.as_ref(), u0, v0, p0)
            }
        }

        $crate::stepper::full_order_state!();
    };
    () => {
        $crate::stepper::start_fn! {
            fn start_with_acceleration(&self, u0, v0, a0: &nalgebra::SVector<T, N>)
                -> $crate::State<T, N>
            {
                $crate::State::initial_given(u0, v0, a0)
            }
        }

        #[inline]
        fn full_state(&self, s: &$crate::State<T, N>) -> $crate::State<T, N> {
            *s
        }
    };
}
pub(crate) use full_order_state;

/// [`Stepper::step`] and [`Stepper::step_with_previous_input`] of a scheme whose step is
/// `self.step_inner(s, p_prev, p)` (state [`State<T, N>`]): `step` takes `p_prev = p`. The
/// two groups of attributes (docs) are those of `step` and of `step_with_previous_input`,
/// separated by `;`. Expands inside an `impl Stepper<T, N> for …` block. Cost: none (both
/// `#[inline]`, as written by hand).
macro_rules! steps_through_inner {
    ($(#[$step:meta])* ; $(#[$prev:meta])*) => {
        $(#[$step])*
        #[inline]
        fn step(&self, s: &mut $crate::State<T, N>, p: &nalgebra::SVector<T, N>) {
            self.step_inner(s, p, p);
        }

        $(#[$prev])*
        #[inline]
        fn step_with_previous_input(
            &self,
            s: &mut $crate::State<T, N>,
            p_prev: &nalgebra::SVector<T, N>,
            p: &nalgebra::SVector<T, N>,
        ) {
            self.step_inner(s, p_prev, p);
        }
    };
}
pub(crate) use steps_through_inner;
