//! Actuator delay compensation: polynomial extrapolation over a known delay, and an
//! adaptive compensator that estimates the delay from the measured response.

use crate::kinematics::check_time_step_as;
use crate::{Error, Param, Real};

/// What sits between the model's target displacement and the actuator: one call a sample.
///
/// The timing, for the loop of [`Split`](crate::hybrid::Split) (`x` targets, `c`
/// commands, `d` displacements reached):
///
/// ```text
/// sample n:  x_{n+1} = split.command(&s)            target for t_{n+1}
///            c_{n+1} = comp.command(&mut cs, x_{n+1}, d_n)
///            d_{n+1} = actuator reaches it (its transducer measures it)
///            split.complete(&mut s, force at d_{n+1}, p_{n+1})
/// ```
///
/// `measured` is the displacement reached at the last sample, `d_n`, the response to the
/// target `x_n` of the previous call: compensators that learn compare the two.
pub trait Compensator<T: Real> {
    /// The compensator's memory: plain, fixed-size data.
    type State: Copy;

    /// At rest at displacement `x0` (m): every past target and measurement `x0`.
    fn rest(&self, x0: T) -> Self::State;

    /// The command (m) to send for the target `target` (m) of the next sample, given the
    /// displacement `measured` (m) reached at the current one.
    ///
    /// Errors: [`Error::NonFiniteInput`] (`target` or `measured` NaN or infinite),
    /// [`Error::NonFiniteState`] (the command overflows); the state is unchanged on error.
    fn command(&self, s: &mut Self::State, target: T, measured: T) -> Result<T, Error>;
}

/// The memory of a compensator: the last four targets (newest first), the adaptive
/// compensator's delay estimate and the mean square of the targets' rate.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompensatorState<T> {
    x: [T; 4],
    tau: T,
    power: T,
}

/// At rest at 0 with a zero delay estimate: as `CompensatorState::at_rest_f32`/
/// `at_rest_f64`, for any `T`.
impl<T: Real> Default for CompensatorState<T> {
    fn default() -> Self {
        Self {
            x: [T::zero(); 4],
            tau: T::zero(),
            power: T::zero(),
        }
    }
}

macro_rules! compensator_state_at_rest {
    ($t:ident, $at_rest:ident) => {
        impl CompensatorState<$t> {
            /// At rest at 0 (every past target 0, delay estimate 0, no rate power):
            /// `const fn`, for a `static`; equal to `CompensatorState::default()` and to
            /// [`Polynomial`]'s [`Compensator::rest`]`(0)`. (An [`Adaptive`] compensator's
            /// rest starts its delay estimate at its initial delay instead: the same
            /// state once `rest` has been called, or this one if that delay is 0.) Cost:
            /// none.
            pub const fn $at_rest() -> Self {
                Self {
                    x: [0.0; 4],
                    tau: 0.0,
                    power: 0.0,
                }
            }
        }
    };
}
compensator_state_at_rest!(f32, at_rest_f32);
compensator_state_at_rest!(f64, at_rest_f64);

/// The Lagrange extrapolation weights of order `p ≤ 3` on the nodes `0, −1, …, −p`
/// (samples) at `s` samples ahead: `c_j = Π_{m ≠ j} (s + m) / (m − j)`; zero beyond `p`.
/// The same expressions in `f64` (`const`) and in `T` (the adaptive compensator's
/// per-sample weights).
macro_rules! lagrange {
    ($p:expr, $s:expr, $one:expr, $two:expr, $three:expr, $six:expr, $zero:expr) => {{
        let (s, one, two, three, six, zero) = ($s, $one, $two, $three, $six, $zero);
        match $p {
            1 => [one + s, zero - s, zero, zero],
            2 => [
                (s + one) * (s + two) / two,
                zero - s * (s + two),
                s * (s + one) / two,
                zero,
            ],
            _ => [
                (s + one) * (s + two) * (s + three) / six,
                zero - s * (s + two) * (s + three) / two,
                s * (s + one) * (s + three) / two,
                zero - s * (s + one) * (s + two) / six,
            ],
        }
    }};
}

const fn weights_f64(order: usize, s: f64) -> [f64; 4] {
    lagrange!(order, s, 1.0, 2.0, 3.0, 6.0, 0.0)
}

fn weights<T: Real>(order: usize, s: T) -> [T; 4] {
    let c = |x: f64| T::from_f64_rounded(x);
    lagrange!(order, s, c(1.0), c(2.0), c(3.0), c(6.0), c(0.0))
}

/// `x` finite in both arguments' sense.
fn finite_pair<T: Real>(a: T, b: T) -> Result<(), Error> {
    if a.is_finite() && b.is_finite() {
        Ok(())
    } else {
        Err(Error::NonFiniteInput)
    }
}

/// `Σ c_j x_j` of the targets after `target` is pushed, and the pushed history.
fn extrapolate<T: Real>(c: &[T; 4], x: &[T; 4], target: T) -> (T, [T; 4]) {
    let next = [target, x[0], x[1], x[2]];
    let mut y = T::zero();
    for j in 0..4 {
        y += c[j] * next[j];
    }
    (y, next)
}

/// Polynomial extrapolation of the target over a known actuator delay `τ` (Horiuchi et
/// al. 1999): the Lagrange polynomial of order `p ∈ {1, 2, 3}` through the last `p + 1`
/// targets, evaluated `τ` ahead,
///
/// ```text
/// c_{n+1} = Σ_{j=0..p} w_j x_{n+1−j},   w_j = Π_{m≠j} (s + m)/(m − j),   s = τ/h
/// ```
///
/// exact for targets that are polynomials of degree `≤ p`; for a smooth target the error
/// is the Lagrange remainder `x^{(p+1)} h^{p+1} Π_{m=0..p} (s + m) / (p + 1)!`. The
/// weights grow like `s^p / p!` (about 1 300 for `p = 3` at `s = 20`): long delays at high
/// rates amplify the target's high-frequency content (`docs/hybrid.md` measures it).
/// Weights computed once in `f64`, rounded to `T`.
///
/// Cost: 4 multiply-adds a sample. `measured` is not used (checked for finiteness).
///
/// ```
/// use aemstep::hybrid::{Compensator, Polynomial};
/// // order 2, h = 1 ms, delay 3 ms: a ramp-plus-parabola target extrapolated exactly
/// let comp = Polynomial::<f64>::new(2, 1e-3, 3e-3)?;
/// let mut s = comp.rest(0.0);
/// let x = |n: f64| 1.0 + 0.5 * n + 0.25 * n * n;
/// let mut c = 0.0;
/// for n in -3..=10 {
///     c = comp.command(&mut s, x(n as f64), 0.0)?;
/// }
/// assert!((c - x(13.0)).abs() < 1e-10);
/// # Ok::<(), aemstep::Error>(())
/// ```
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Polynomial<T> {
    w: [T; 4],
    order: usize,
}

/// Check `order`, `h`, `delay` and compute the weights in `f64` (`const fn`).
const fn polynomial_weights(order: usize, h: f64, delay: f64, max: f64) -> Result<[f64; 4], Error> {
    if order < 1 || order > 3 {
        return Err(Error::InvalidParameter(Param::CompensationOrder));
    }
    let h = match check_time_step_as(h, max) {
        Ok(h) => h,
        Err(e) => return Err(e),
    };
    if !(delay.is_finite() && delay >= 0.0) {
        return Err(Error::InvalidParameter(Param::Delay));
    }
    let w = weights_f64(order, delay / h);
    if !crate::linalg::all_fit(&w, max) {
        return Err(Error::OperatorOverflow);
    }
    Ok(w)
}

impl<T: Real> Polynomial<T> {
    /// Extrapolation of order `order` (1, 2 or 3) over `delay` seconds (`≥ 0`; 0 sends the
    /// target as it is) at a sample interval `h` (s). Bit-identical to
    /// [`Polynomial::new_f32`] / [`Polynomial::new_f64`].
    ///
    /// Errors: [`Error::InvalidParameter`] (`order` outside 1..=3, `delay` negative or not
    /// finite), [`Error::InvalidTimeStep`] (`h`), [`Error::OperatorOverflow`] (a weight
    /// does not fit `T`). Cost: O(1).
    pub fn new(order: usize, h: f64, delay: f64) -> Result<Self, Error> {
        let w = polynomial_weights(order, h, delay, T::MAX)?;
        Ok(Self {
            w: w.map(T::from_f64_rounded),
            order,
        })
    }

    /// The weights `w_0 … w_3` on the newest to the oldest target (zero beyond the order).
    /// Cost: none.
    pub fn weights(&self) -> [T; 4] {
        self.w
    }

    /// The order `p`. Cost: none.
    pub fn order(&self) -> usize {
        self.order
    }
}

macro_rules! polynomial_const {
    ($t:ident, $name:ident) => {
        impl Polynomial<$t> {
            /// `const fn` twin of [`Polynomial::new`] (weights computed by the compiler).
            /// Errors: as [`Polynomial::new`].
            pub const fn $name(order: usize, h: f64, delay: f64) -> Result<Self, Error> {
                match polynomial_weights(order, h, delay, $t::MAX as f64) {
                    Ok(w) => Ok(Self {
                        w: [w[0] as $t, w[1] as $t, w[2] as $t, w[3] as $t],
                        order,
                    }),
                    Err(e) => Err(e),
                }
            }
        }
    };
}
polynomial_const!(f32, new_f32);
polynomial_const!(f64, new_f64);

impl<T: Real> Compensator<T> for Polynomial<T> {
    type State = CompensatorState<T>;

    fn rest(&self, x0: T) -> CompensatorState<T> {
        CompensatorState {
            x: [x0; 4],
            tau: T::zero(),
            power: T::zero(),
        }
    }

    fn command(&self, s: &mut CompensatorState<T>, target: T, measured: T) -> Result<T, Error> {
        finite_pair(target, measured)?;
        let (y, x) = extrapolate(&self.w, &s.x, target);
        if !y.is_finite() {
            return Err(Error::NonFiniteState);
        }
        s.x = x;
        Ok(y)
    }
}

/// Polynomial extrapolation over a delay it estimates from the measured response: the
/// tracking error `e_n = d_n − x_n` of a compensated actuator is, to first order,
/// `(τ̂ − τ) ẋ_n` (the actuator reaches `x(t − τ + τ̂)`), so the estimate follows a
/// normalized gradient step,
///
/// ```text
/// ẋ_n = (x_n − x_{n−1}) / h,   P_n = (1 − μ) P_{n−1} + μ ẋ_n²
/// τ̂ ← clamp(τ̂ − clamp(μ e_n ẋ_n / P_n, ±μ τ_max), 0, τ_max),   μ = h / T_c
/// ```
///
/// (the least-mean-squares form of the tracking-indicator adaptation of Chen & Ricles'
/// adaptive inverse compensation, 2010), then extrapolates the target `τ̂` ahead with
/// the order-`p` Lagrange weights of [`Polynomial`], recomputed each sample. The error
/// converges geometrically with time constant about `T_c` while the target moves; at
/// rest (`ẋ = 0`) nothing changes. What it estimates is the *effective* delay of the
/// actuator (a discrete first-order lag `T_a`, as [`Actuator`](crate::hybrid::Actuator)'s,
/// adds its mean delay `h/(e^{h/T_a} − 1) ≈ T_a − h/2`). `T_c = 0.5 s`.
///
/// Cost: about 20 flops and one division a sample. Size: 6 values of `T`.
///
/// ```
/// use aemstep::hybrid::{Actuator, Adaptive, Compensator};
/// let h = 1.0 / 1024.0;
/// let act = Actuator::<f64, 32>::new(h, 0.008, 0.0)?; // 8 ms, unknown to the compensator
/// let comp = Adaptive::<f64>::new(2, h, 0.0, 0.02)?;
/// let (mut a, mut c) = (act.rest(0.0), comp.rest(0.0));
/// let mut measured = 0.0;
/// for n in 0..10 * 1024 {
///     let t = n as f64 * h;
///     let target = 0.01 * (2.0 * t).sin() + 0.005 * (5.3 * t).sin(); // m
///     measured = act.step(&mut a, comp.command(&mut c, target, measured)?)?;
/// }
/// assert!((comp.delay(&c) - 0.008).abs() < 2e-4);
/// # Ok::<(), aemstep::Error>(())
/// ```
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adaptive<T> {
    order: usize,
    /// `1/h` (1/s), `μ`, `1 − μ`, `μ τ_max` (s), `τ_max` (s), `τ̂_0` (s).
    inv_h: T,
    mu: T,
    keep: T,
    max_step: T,
    max: T,
    initial: T,
}

/// The adaptation's time constant `T_c` (s).
const TIME_CONSTANT: f64 = 0.5;

impl<T: Real> Adaptive<T> {
    /// Extrapolation of order `order` (1, 2 or 3) over a delay estimated between 0 and
    /// `max_delay` seconds, starting from `initial_delay`, at a sample interval `h` (s).
    ///
    /// Errors: [`Error::InvalidParameter`] (`order` outside 1..=3; the delays negative,
    /// not finite, or `initial_delay > max_delay`), [`Error::InvalidTimeStep`] (`h`, or
    /// `h ≥ T_c = 0.5 s`). Cost: O(1).
    pub fn new(order: usize, h: f64, initial_delay: f64, max_delay: f64) -> Result<Self, Error> {
        if !(1..=3).contains(&order) {
            return Err(Error::InvalidParameter(Param::CompensationOrder));
        }
        let h = check_time_step_as(h, T::MAX)?;
        if h >= TIME_CONSTANT {
            return Err(Error::InvalidTimeStep);
        }
        if !(initial_delay.is_finite()
            && max_delay.is_finite()
            && initial_delay >= 0.0
            && initial_delay <= max_delay)
        {
            return Err(Error::InvalidParameter(Param::Delay));
        }
        let mu = h / TIME_CONSTANT;
        if !crate::linalg::all_fit(&[1.0 / h, max_delay / h], T::MAX) {
            return Err(Error::OperatorOverflow);
        }
        let r = T::from_f64_rounded;
        Ok(Self {
            order,
            inv_h: r(1.0 / h),
            mu: r(mu),
            keep: r(1.0 - mu),
            max_step: r(mu * max_delay),
            max: r(max_delay),
            initial: r(initial_delay),
        })
    }

    /// The current delay estimate `τ̂` (s). Cost: none.
    pub fn delay(&self, s: &CompensatorState<T>) -> T {
        s.tau
    }
}

impl<T: Real> Compensator<T> for Adaptive<T> {
    type State = CompensatorState<T>;

    fn rest(&self, x0: T) -> CompensatorState<T> {
        CompensatorState {
            x: [x0; 4],
            tau: self.initial,
            power: T::zero(),
        }
    }

    fn command(&self, s: &mut CompensatorState<T>, target: T, measured: T) -> Result<T, Error> {
        finite_pair(target, measured)?;
        // The error of the previous target, and its rate.
        let rate = (s.x[0] - s.x[1]) * self.inv_h;
        let e = measured - s.x[0];
        let power = self.keep * s.power + self.mu * rate * rate;
        let mut tau = s.tau;
        if power > T::zero() {
            let step = self.mu * e * rate / power;
            let step = step.clamp(-self.max_step, self.max_step);
            // NaN-safe: a NaN step (overflowing products) leaves the estimate as it was.
            if step.is_finite() {
                tau = (tau - step).clamp(T::zero(), self.max);
            }
        }
        let w = weights(self.order, tau * self.inv_h);
        let (y, x) = extrapolate(&w, &s.x, target);
        if !(y.is_finite() && power.is_finite()) {
            return Err(Error::NonFiniteState);
        }
        *s = CompensatorState { x, tau, power };
        Ok(y)
    }
}
