//! An emulated actuator: a pure delay and a first-order lag, for tests and examples of the
//! hybrid loop on the host and on the device.

use crate::kinematics::check_time_step_as;
use crate::{Error, Param, Real};

/// An emulated servo-hydraulic actuator for one degree of freedom: the displacement it
/// reaches at sample `n` is its command delayed by `τ` and passed through a first-order
/// lag of time constant `T_a`:
///
/// ```text
/// c̃_n = c(t_n − τ)                            (delay line, linear interpolation)
/// d_n = d_{n−1} + (1 − e^{−h/T_a}) (c̃_n − d_{n−1})   (exact for c̃ held over the step)
/// ```
///
/// `τ = (j + f) h` with `j` whole samples and `f ∈ [0, 1)`: `c̃_n = (1 − f) c_{n−j} + f
/// c_{n−j−1}`. `τ = 0` and `T_a = 0` give `d_n = c_n` exactly. The line holds the last `L`
/// commands, so `τ ≤ (L − 2) h`. The lag's low-frequency (mean) delay is
/// `h/(e^{h/T_a} − 1) ≈ T_a − h/2` (the update takes the sample's command at once). For tests and examples (a hybrid loop on the host or
/// under QEMU with no hardware), not a model of any particular actuator.
///
/// Cost: 3 multiply-adds a sample. Size: `L + 1` values of `T` in the state.
///
/// ```
/// use aemstep::hybrid::Actuator;
/// // h = 0.25 s, delay 0.625 s, no lag: the command of 2.5 samples ago
/// let act = Actuator::<f64, 8>::new(0.25, 0.625, 0.0)?;
/// let mut s = act.rest(0.0);
/// let reached: Vec<f64> = (0..6)
///     .map(|n| act.step(&mut s, n as f64))
///     .collect::<Result<_, _>>()?;
/// assert_eq!(reached, [0.0, 0.0, 0.0, 0.5, 1.5, 2.5]);
/// # Ok::<(), aemstep::Error>(())
/// ```
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Actuator<T, const L: usize> {
    /// Whole samples of delay `j`.
    whole: usize,
    /// The interpolation weights `1 − f`, `f`, and the lag's coefficient
    /// `1 − e^{−h/T_a}` (`None` without a lag).
    near: T,
    frac: T,
    lag: Option<T>,
    delay: T,
}

/// The state of an [`Actuator`]: the last `L` commands and the displacement reached.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActuatorState<T, const L: usize> {
    line: [T; L],
    head: usize,
    reached: T,
}

/// At rest at 0: as `ActuatorState::at_rest_f32`/`at_rest_f64`, for any `T`.
impl<T: Real, const L: usize> Default for ActuatorState<T, L> {
    fn default() -> Self {
        Self {
            line: [T::zero(); L],
            head: 0,
            reached: T::zero(),
        }
    }
}

macro_rules! actuator_state_at_rest {
    ($t:ident, $at_rest:ident) => {
        impl<const L: usize> ActuatorState<$t, L> {
            /// At rest at displacement 0 (every past command 0): `const fn`, for a
            /// `static`; equal to `ActuatorState::default()` and to
            /// [`Actuator::rest`]`(0)`. Cost: none in a `static`, `L` stores otherwise.
            pub const fn $at_rest() -> Self {
                Self {
                    line: [0.0; L],
                    head: 0,
                    reached: 0.0,
                }
            }
        }
    };
}
actuator_state_at_rest!(f32, at_rest_f32);
actuator_state_at_rest!(f64, at_rest_f64);

impl<T: Real, const L: usize> ActuatorState<T, L> {
    /// The displacement reached at the last sample (m). Cost: none.
    pub fn reached(&self) -> T {
        self.reached
    }
}

impl<T: Real, const L: usize> Actuator<T, L> {
    /// An actuator sampled every `h` seconds with a pure delay `delay` (s, `0 ≤ τ ≤
    /// (L − 2) h`) and a first-order lag of time constant `lag` (s, `≥ 0`; 0 for none).
    ///
    /// Errors: [`Error::InvalidTimeStep`] (`h` not finite and positive in `T`),
    /// [`Error::InvalidParameter`] (`delay` or `lag` negative or not finite, or the delay
    /// longer than the line holds). Cost: one `exp`.
    pub fn new(h: f64, delay: f64, lag: f64) -> Result<Self, Error> {
        let h = check_time_step_as(h, T::MAX)?;
        if !(delay.is_finite() && delay >= 0.0) {
            return Err(Error::InvalidParameter(Param::Delay));
        }
        if !(lag.is_finite() && lag >= 0.0) {
            return Err(Error::InvalidParameter(Param::Lag));
        }
        let samples = delay / h;
        // `samples` is finite (delay finite, h > 0): no NaN to let through.
        if samples > L as f64 - 2.0 {
            return Err(Error::InvalidParameter(Param::DelayLine));
        }
        // `samples` ≤ L − 2: the cast is exact and in range.
        let whole = samples as usize;
        let frac = samples - whole as f64;
        let lag = if lag == 0.0 {
            None
        } else {
            Some(T::from_f64_rounded(
                1.0 - nalgebra::ComplexField::exp(-h / lag),
            ))
        };
        Ok(Self {
            whole,
            near: T::from_f64_rounded(1.0 - frac),
            frac: T::from_f64_rounded(frac),
            lag,
            delay: T::from_f64_rounded(delay),
        })
    }

    /// The delay `τ` (s), rounded to `T`. Cost: none.
    pub fn delay(&self) -> T {
        self.delay
    }

    /// At rest at displacement `d0` (m): every past command `d0`. Cost: `L` stores.
    pub fn rest(&self, d0: T) -> ActuatorState<T, L> {
        ActuatorState {
            line: [d0; L],
            head: 0,
            reached: d0,
        }
    }

    /// Send `command` (m) for this sample; returns the displacement reached (m).
    ///
    /// Errors: [`Error::NonFiniteInput`] (`command` NaN or infinite),
    /// [`Error::NonFiniteState`] (the displacement overflows); the state is unchanged on
    /// error. Cost: 3 multiply-adds; no allocation, no panic.
    pub fn step(&self, s: &mut ActuatorState<T, L>, command: T) -> Result<T, Error> {
        if !command.is_finite() {
            return Err(Error::NonFiniteInput);
        }
        // L ≥ 2 (checked by `new`): `% L` and the indices below are in range.
        let head = (s.head + 1) % L;
        let at = |back: usize| {
            if back == 0 {
                command
            } else {
                s.line[(head + L - back) % L]
            }
        };
        let (a, b) = (at(self.whole), at(self.whole + 1));
        // `(1 − f) a + f b`: exactly `a` for a whole number of samples, and no difference
        // of two commands to overflow.
        let delayed = self.near * a + self.frac * b;
        let reached = match self.lag {
            Some(g) => s.reached + g * (delayed - s.reached),
            None => delayed,
        };
        if !reached.is_finite() {
            return Err(Error::NonFiniteState);
        }
        s.line[head] = command;
        s.head = head;
        s.reached = reached;
        Ok(reached)
    }
}
