//! The state every full-order stepper advances.

use nalgebra::SVector;

use crate::observer::Estimate;
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
    /// The largest step count [`State::restore`] accepts, `2⁶³ − 1`. The steppers count
    /// steps in a `u64` and do not check it (a check would cost every step); from a count
    /// at most this, `2⁶³` more steps (about 300 years at one step a nanosecond) are needed
    /// before it could wrap, so no run ever sees its time `n·h` wrap to 0. A state from a
    /// stepper's `start` begins at 0.
    pub const MAX_RESTORED_STEPS: u64 = u64::MAX / 2;

    /// A state restored from saved parts: displacement `u`, velocity `v`, acceleration `a`
    /// (model units, as [`State::u`], [`State::v`], [`State::a`]) and the step count
    /// `steps` (time `steps·h`, `0 ..= State::MAX_RESTORED_STEPS`). Give it to the stepper
    /// the parts came from.
    ///
    /// Errors: [`Error::NonFiniteInput`] if any entry of `u`, `v`, `a` is not finite;
    /// [`Error::StepCountOverflow`] if `steps > State::MAX_RESTORED_STEPS` (a count the
    /// steps could wrap: `u64::MAX` wrapped to `0` on the next step, its time to `0`).
    /// Cost: a scan of the `3N` entries.
    ///
    /// ```
    /// use aemstep::{Error, State};
    /// use aemstep::vector;
    /// let s = State::restore(vector![0.1], vector![0.0], vector![-2.5], 40)?;
    /// assert_eq!((s.u()[0], s.steps()), (0.1, 40));
    /// assert_eq!(
    ///     State::restore(vector![f64::NAN], vector![0.0], vector![0.0], 0),
    ///     Err(Error::NonFiniteInput)
    /// );
    /// assert!(State::restore(vector![0.0], vector![0.0], vector![0.0], u64::MAX).is_err());
    /// # Ok::<(), aemstep::Error>(())
    /// ```
    pub fn restore(
        u: SVector<T, N>,
        v: SVector<T, N>,
        a: SVector<T, N>,
        steps: u64,
    ) -> Result<Self, Error> {
        if steps > Self::MAX_RESTORED_STEPS {
            return Err(Error::StepCountOverflow);
        }
        let s = Self::unchecked(u, v, a, steps);
        if s.is_finite() {
            Ok(s)
        } else {
            Err(Error::NonFiniteInput)
        }
    }

    /// A state from its parts, unchecked (the steppers' own results).
    pub(crate) fn unchecked(
        u: SVector<T, N>,
        v: SVector<T, N>,
        a: SVector<T, N>,
        steps: u64,
    ) -> Self {
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
        let s = Self::unchecked(*u0, *v0, a0, 0);
        if s.is_finite() {
            Ok(s)
        } else {
            Err(Error::NonFiniteState)
        }
    }

    /// Every entry of `u`, `v`, `a` is finite.
    ///
    /// One indexed pass (no iterator adapters, whose inlining into the firmware's step
    /// varied with the codegen-unit split: `docs/cortex-m4-cost.md`). Cost: at most `3N`
    /// comparisons.
    pub fn is_finite(&self) -> bool {
        let mut i = 0;
        while i < N {
            if !(self.u[i].is_finite() && self.v[i].is_finite() && self.a[i].is_finite()) {
                return false;
            }
            i += 1;
        }
        true
    }
}

/// The zero vector of `f32`, in `const` (`SVector::zeros` is not a `const fn`).
pub(crate) const fn zeros_f32<const N: usize>() -> SVector<f32, N> {
    SVector::from_array_storage(nalgebra::ArrayStorage([[0.0; N]; 1]))
}

/// The zero vector of `f64`, in `const`.
pub(crate) const fn zeros_f64<const N: usize>() -> SVector<f64, N> {
    SVector::from_array_storage(nalgebra::ArrayStorage([[0.0; N]; 1]))
}

/// At rest: as `State::at_rest_f32`/`at_rest_f64`, for any `T`.
impl<T: Real, const N: usize> Default for State<T, N> {
    fn default() -> Self {
        Self::unchecked(SVector::zeros(), SVector::zeros(), SVector::zeros(), 0)
    }
}

macro_rules! state_at_rest {
    ($t:ident, $at_rest:ident, $zeros:ident) => {
        impl<const N: usize> State<$t, N> {
            /// At rest at step 0: `u = v = a = 0`. `const fn`, so a state can live in a
            /// `static` (e.g. `static S: Mutex<RefCell<State<f32, 4>>>`) with no run-time
            /// start; equal to `State::default()` and to a stepper's start at rest
            /// with no load. Cost: none in a `static`, `3N` stores otherwise.
            ///
            /// ```
            /// use aemstep::State;
            #[doc = concat!("static S: State<", stringify!($t), ", 4> = State::", stringify!($at_rest), "();")]
            /// assert_eq!(S, State::default());
            /// assert_eq!(S.steps(), 0);
            /// ```
            pub const fn $at_rest() -> Self {
                Self {
                    u: $zeros(),
                    v: $zeros(),
                    a: $zeros(),
                    n: 0,
                }
            }
        }
    };
}
state_at_rest!(f32, at_rest_f32, zeros_f32);
state_at_rest!(f64, at_rest_f64, zeros_f64);

// The observer's estimate at rest (its fields are the crate's; kept beside `State`'s).

/// At rest: as `Estimate::at_rest_f32`/`at_rest_f64`, for any `T`.
impl<T: Real, const S: usize, const I: usize> Default for Estimate<T, S, I> {
    fn default() -> Self {
        Estimate {
            x: SVector::zeros(),
            w: SVector::zeros(),
            n: 0,
            missing: 0,
        }
    }
}

macro_rules! estimate_at_rest {
    ($t:ident, $at_rest:ident, $zeros:ident) => {
        impl<const S: usize, const I: usize> Estimate<$t, S, I> {
            /// At rest with no input (`x̂_0 = 0`, `w_0 = 0`, step 0): `const fn`, for a
            /// `static`; equal to `Estimate::default()` and to
            /// [`Observer::start_at_rest`](crate::observer::Observer::start_at_rest) with
            /// `w0 = 0`. Cost: none in a `static`.
            pub const fn $at_rest() -> Self {
                Estimate {
                    x: $zeros(),
                    w: $zeros(),
                    n: 0,
                    missing: 0,
                }
            }
        }
    };
}
estimate_at_rest!(f32, at_rest_f32, zeros_f32);
estimate_at_rest!(f64, at_rest_f64, zeros_f64);

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

/// The [`StepState`](crate::StepState) impl of a state type `$ty<T, $n…>` (`T: Real`, the sizes
/// `const $n: usize`), both methods `#[inline]`: `is_finite` is the expression
/// `$finite` of `$this` (written `self` at the call), `steps` the field path `$steps`
/// (e.g. `n`). The one impl of the crate's states and estimates. Cost: none.
macro_rules! step_state {
    ($ty:ident<$($n:ident),+>, |$this:ident| $finite:expr, $($steps:ident).+) => {
        impl<T: $crate::Real, $(const $n: usize),+> $crate::StepState for $ty<T, $($n),+> {
            #[inline]
            fn is_finite(&$this) -> bool {
                $finite
            }
            #[inline]
            fn steps(&self) -> u64 {
                self.$($steps).+
            }
        }
    };
}
pub(crate) use step_state;

step_state!(State<N>, |self| State::is_finite(self), n);
