//! The ideal force actuator and the viscous damper.

use nalgebra::ComplexField;

use super::Device;
use crate::hysteresis::{LawTrial, positive};
use crate::{Error, Param, Real};

/// An ideal force actuator: it pushes its first point (`d` increasing) with the command
/// force, clipped to `|F| ≤ F_max`, through an optional first-order lag of time constant
/// `τ` (`Ḟ = (v − F)/τ`, integrated exactly over a step with `v` held:
/// `F_n = v + (F_{n−1} − v) e^{−h/τ}`; `τ = 0`: `F_n = v`).
///
/// **Stroke**: at a committed deformation `|d_{n−1}| ≥ s_max` the actuator delivers no
/// force that would push further out (`F d_{n−1} > 0`); it still pulls back. (An end stop
/// without impact: the step that crosses the stroke is taken, the next ones do not push
/// further.) As a [`Device`], its internal force is `f = −F` (it drives the structure
/// instead of resisting), and [`Device::delivered_force`] is that `−F`.
///
/// Cost per trial: one `exp` (with a lag) and 5 comparisons.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForceActuator<T> {
    f_max: T,
    stroke: T,
    /// `1/τ`, `None` without a lag.
    rate: Option<T>,
}

/// The history of a [`ForceActuator`] at the end of the last accepted step.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActuatorHistory<T> {
    /// The force `F` the actuator pushes with (N).
    pub output: T,
    /// The deformation `d` (m).
    pub deformation: T,
}

impl<T: Real> ForceActuator<T> {
    /// An actuator with force limit `f_max` (N), stroke `stroke` (m), both finite and
    /// `> 0`, and lag time constant `tau` (s, finite, `≥ 0`; `0` for none).
    ///
    /// Errors: [`Error::InvalidParameter`]`(`[`Param::Saturation`]`)` (`f_max` or `stroke`
    /// not finite or `≤ 0`), [`Error::InvalidMaterial`]`(`[`Param::Device`]`)` (`tau`
    /// negative or not finite), [`Error::OperatorOverflow`] (a value does not fit `T`).
    /// Cost: O(1).
    pub fn new(f_max: f64, stroke: f64, tau: f64) -> Result<Self, Error> {
        if !(positive(f_max) && positive(stroke)) {
            return Err(Error::InvalidParameter(Param::Saturation));
        }
        if !(tau.is_finite() && tau >= 0.0) {
            return Err(Error::InvalidMaterial(Param::Device));
        }
        let [f_max, stroke, rate] = crate::hysteresis::rounded::<T, 3>([
            f_max,
            stroke,
            if tau > 0.0 { 1.0 / tau } else { 0.0 },
        ])?;
        Ok(Self {
            f_max,
            stroke,
            rate: (tau > 0.0).then_some(rate),
        })
    }
}

impl<T: Real> Device<T> for ForceActuator<T> {
    type History = ActuatorHistory<T>;

    fn initial_history(&self) -> ActuatorHistory<T> {
        let zero = T::zero();
        ActuatorHistory {
            output: zero,
            deformation: zero,
        }
    }

    /// `[−F_max, F_max]` (N).
    fn command_limits(&self) -> (T, T) {
        (-self.f_max, self.f_max)
    }

    fn trial(&self, old: &Self::History, d: T, _r: T, v: T, h: T) -> LawTrial<T, Self::History> {
        let zero = T::zero();
        let held = if v > self.f_max {
            self.f_max
        } else if v < -self.f_max {
            -self.f_max
        } else {
            v // (NaN stays NaN)
        };
        let clipped = held != v;
        let mut output = match self.rate {
            Some(rate) => held + (old.output - held) * <T as ComplexField>::exp(-(h * rate)),
            None => held,
        };
        let d0 = old.deformation;
        let stopped = d0.abs() >= self.stroke && output * d0 > zero;
        if stopped {
            output = zero;
        }
        LawTrial {
            force: -output,
            stiffness: zero,
            damping: zero,
            history: ActuatorHistory {
                output,
                deformation: d,
            },
            inelastic: clipped || stopped,
        }
    }

    fn delivered_force(&self, history: &ActuatorHistory<T>) -> T {
        -history.output
    }
}

/// A linear viscous damper `f = c ḋ` (a passive baseline; the command is ignored).
///
/// Cost per trial: one multiply.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Viscous<T> {
    c: T,
}

impl<T: Real> Viscous<T> {
    /// A damper of coefficient `c` (N·s/m, finite, `> 0`).
    ///
    /// Errors: [`Error::InvalidMaterial`]`(`[`Param::Device`]`)`,
    /// [`Error::OperatorOverflow`] (`c` does not fit `T`). Cost: O(1).
    pub fn new(c: f64) -> Result<Self, Error> {
        if !positive(c) {
            return Err(Error::InvalidMaterial(Param::Device));
        }
        let [c] = crate::hysteresis::rounded::<T, 1>([c])?;
        Ok(Self { c })
    }
}

impl<T: Real> Device<T> for Viscous<T> {
    /// The force delivered (N).
    type History = T;

    fn initial_history(&self) -> T {
        T::zero()
    }

    /// `[0, 0]`: no command.
    fn command_limits(&self) -> (T, T) {
        (T::zero(), T::zero())
    }

    fn trial(&self, _: &T, _d: T, rate: T, _command: T, _h: T) -> LawTrial<T, T> {
        let force = self.c * rate;
        LawTrial {
            force,
            stiffness: T::zero(),
            damping: self.c,
            history: force,
            inelastic: false,
        }
    }

    fn delivered_force(&self, history: &T) -> T {
        *history
    }
}
