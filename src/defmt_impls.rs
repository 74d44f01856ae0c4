//! `defmt::Format` for the public types that hold nalgebra vectors or matrices (which have
//! no `Format`) or private data, written by hand (feature `defmt`). Types whose fields are
//! all `Format` derive it beside their definition instead.
//!
//! States, estimates, reports and models print their numbers (vectors as slices, matrices
//! column by column, nalgebra's storage order). Steppers, observers and operators hold
//! `N×N` operators, too many numbers for a log line: they print their sizes and time step
//! (the numbers are in their accessors). `tests/defmt_coverage.rs` checks that every public
//! type of `src/` has an impl (here or derived) or a reason on its skip list.

use defmt::{Format, Formatter, write};

use crate::estimation::smoother::{FixedLag, FixedLagState};
use crate::estimation::{
    InputStateFilter, InputStateFilterState, InputStateObserver, JointEstimate, dual::DualFilter,
    dual::DualKalmanFilter, dual::DualKalmanFilterState,
};
use crate::hybrid::{Split, SplitState};
use crate::hysteresis::{EnergyAccount, Law, ShearBuilding, Trial};
use crate::observer::{
    Estimate, Kalman, KalmanState, Measurement, Observer, Outputs, Readout, StateSpace, SteadyState,
};
use crate::records::{At2, Values};
use crate::spectrum::Bank;
use crate::{
    AForm, Coefficients, CompensatedLinear, CompensatedState, Exact, GeneralizedAlpha, KrAlpha,
    Linear, LinearInput, Modal, Newmark, Nonlinear, Real, Stepper, SymTridiagonal, Tangent,
    TridiagonalTangent, Varying,
};

impl<T: Real + Format, const N: usize> Format for CompensatedState<T, N> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "CompensatedState {{ state: {}, u_low: {}, v_low: {} }}",
            self.state(),
            self.u_low().as_slice(),
            self.v_low().as_slice()
        )
    }
}

impl<T: Real + Format, const S: usize, const I: usize> Format for Estimate<T, S, I> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "Estimate {{ n: {}, missing: {}, x: {}, last_input: {} }}",
            self.steps(),
            self.missing(),
            self.x().as_slice(),
            self.last_input().as_slice()
        )
    }
}

impl<T: Real + Format, const S: usize, const I: usize> Format for KalmanState<T, S, I> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "KalmanState {{ estimate: {}, covariance (columns): {} }}",
            self.estimate(),
            self.covariance().as_slice()
        )
    }
}

impl<T: Real + Format, const N: usize> Format for Tangent<T, N> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "Tangent {{ stiffness (columns): {}, damping (columns): {} }}",
            self.stiffness.as_slice(),
            self.damping.as_slice()
        )
    }
}

impl<T: Real + Format, const N: usize> Format for SymTridiagonal<T, N> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "SymTridiagonal {{ diagonal: {}, off: {} }}",
            self.diagonal.as_slice(),
            self.off.as_slice()
        )
    }
}

impl<T: Real + Format, const N: usize> Format for TridiagonalTangent<T, N> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "TridiagonalTangent {{ mass: {}, stiffness: {}, damping: {} }}",
            self.mass, self.stiffness, self.damping
        )
    }
}

impl<T: Real + Format, const N: usize> Format for Coefficients<T, N> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "Coefficients {{ mass (columns): {}, damping (columns): {}, stiffness (columns): {} }}",
            self.mass.as_slice(),
            self.damping.as_slice(),
            self.stiffness.as_slice()
        )
    }
}

impl<T: Real + Format, const N: usize, H: Format> Format for Trial<T, N, H> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "Trial {{ force: {}, history: {}, branch: {=u64:#x} }}",
            self.force.as_slice(),
            self.history,
            self.branch
        )
    }
}

impl<T: Real + Format, const N: usize> Format for EnergyAccount<T, N> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "EnergyAccount {{ initial: {} J, input: {} J, kinetic: {} J, recoverable: {} J, viscous: {} J, hysteretic: {} J, balance_error: {} J }}",
            self.initial,
            self.input,
            self.kinetic,
            self.recoverable,
            self.viscous,
            self.hysteretic,
            self.balance_error()
        )
    }
}

impl<T: Real + Format, L: Law<T> + Format, const N: usize> Format for ShearBuilding<T, L, N> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "ShearBuilding {{ masses: {}, damping (columns): {}, laws: {} }}",
            self.masses().as_slice(),
            self.damping().as_slice(),
            self.laws()
        )
    }
}

// Steppers: name, size and time step.

impl<T: Real + Format, const N: usize> Format for Linear<T, N> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "Linear {{ N: {=usize}, h: {} }}",
            N,
            Stepper::time_step(self)
        )
    }
}

impl<T: Real + Format, const N: usize> Format for AForm<T, N> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "AForm {{ N: {=usize}, h: {} }}",
            N,
            Stepper::time_step(self)
        )
    }
}

impl<T: Real + Format, const N: usize> Format for Newmark<T, N> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "Newmark {{ N: {=usize}, h: {} }}",
            N,
            Stepper::time_step(self)
        )
    }
}

impl<T: Real + Format, const N: usize> Format for Exact<T, N> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "Exact {{ N: {=usize}, h: {} }}",
            N,
            Stepper::time_step(self)
        )
    }
}

impl<T: Real + Format, const N: usize> Format for GeneralizedAlpha<T, N> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "GeneralizedAlpha {{ N: {=usize}, h: {} }}",
            N,
            Stepper::time_step(self)
        )
    }
}

impl<T: Real + Format, const N: usize> Format for KrAlpha<T, N> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "KrAlpha {{ N: {=usize}, h: {}, alpha_m: {}, alpha_f: {} }}",
            N,
            Stepper::time_step(self),
            self.parameters().alpha_m,
            self.parameters().alpha_f
        )
    }
}

impl<T: Real + Format, const N: usize> Format for Split<T, N> {
    fn format(&self, f: Formatter) {
        write!(f, "Split {{ scheme: {} }}", self.scheme())
    }
}

impl<T: Real + Format, const N: usize> Format for SplitState<T, N> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "SplitState {{ state: {}, restoring_force: {}, load: {} }}",
            self.state(),
            self.restoring_force().as_slice(),
            self.load().as_slice()
        )
    }
}

impl<T: Real + Format, const N: usize> Format for CompensatedLinear<T, N> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "CompensatedLinear {{ N: {=usize}, h: {} }}",
            N,
            Stepper::time_step(self)
        )
    }
}

impl<T: Real + Format, const N: usize, const I: usize> Format for LinearInput<T, N, I> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "LinearInput {{ N: {=usize}, I: {=usize}, h: {} }}",
            N,
            I,
            Stepper::time_step(self)
        )
    }
}

impl<T: Real + Format, const N: usize, const R: usize, const I: usize, const O: usize> Format
    for Modal<T, N, R, I, O>
{
    fn format(&self, f: Formatter) {
        write!(
            f,
            "Modal {{ N: {=usize}, R: {=usize}, I: {=usize}, O: {=usize}, h: {} }}",
            N,
            R,
            I,
            O,
            Stepper::time_step(self)
        )
    }
}

impl<T: Real + Format, const N: usize> Format for Nonlinear<T, N> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "Nonlinear {{ N: {=usize}, h: {} }}",
            N,
            Nonlinear::time_step(self)
        )
    }
}

impl<T: Real + Format, const N: usize> Format for Varying<T, N> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "Varying {{ N: {=usize}, h: {} }}",
            N,
            Varying::time_step(self)
        )
    }
}

impl<T: Real + Format, const S: usize, const I: usize, const O: usize> Format
    for Observer<T, S, I, O>
{
    fn format(&self, f: Formatter) {
        write!(
            f,
            "Observer {{ S: {=usize}, I: {=usize}, O: {=usize}, h: {} }}",
            S,
            I,
            O,
            self.time_step()
        )
    }
}

// Operators whose sizes are all they print.

impl<T: Real, const S: usize, const I: usize, const O: usize> Format for Kalman<T, S, I, O> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "Kalman {{ S: {=usize}, I: {=usize}, O: {=usize} }}",
            S, I, O
        )
    }
}

impl<T: Real, const S: usize, const I: usize, const P: usize> Format for Readout<T, S, I, P> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "Readout {{ S: {=usize}, I: {=usize}, P: {=usize} }}",
            S, I, P
        )
    }
}

impl<T: Real, const P: usize> Format for Bank<T, P> {
    fn format(&self, f: Formatter) {
        write!(f, "Bank {{ P: {=usize} }}", P)
    }
}

impl<const N: usize, const S: usize, const I: usize> Format for StateSpace<N, S, I> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "StateSpace {{ N: {=usize}, S: {=usize}, I: {=usize} }}",
            N, S, I
        )
    }
}

impl<const N: usize, const I: usize, const O: usize> Format for Outputs<N, I, O> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "Outputs {{ N: {=usize}, I: {=usize}, O: {=usize} }}",
            N, I, O
        )
    }
}

impl<const S: usize, const I: usize, const O: usize> Format for Measurement<S, I, O> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "Measurement {{ S: {=usize}, I: {=usize}, O: {=usize} }}",
            S, I, O
        )
    }
}

impl<const S: usize, const O: usize> Format for SteadyState<S, O> {
    fn format(&self, f: Formatter) {
        write!(f, "SteadyState {{ S: {=usize}, O: {=usize} }}", S, O)
    }
}

// Joint input–state estimation: estimates print their numbers, filters their sizes.

impl<T: Real + Format, const S: usize, const I: usize> Format for JointEstimate<T, S, I> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "JointEstimate {{ n: {}, missing: {}, xi: {}, input: {} }}",
            self.steps(),
            self.missing(),
            self.xi().as_slice(),
            self.input().as_slice()
        )
    }
}

impl<T: Real + Format, const S: usize, const I: usize, const O: usize> Format
    for InputStateFilterState<T, S, I, O>
{
    fn format(&self, f: Formatter) {
        write!(
            f,
            "InputStateFilterState {{ estimate: {}, covariance (columns): {}, cross_covariance (columns): {}, input_covariance (columns): {} }}",
            self.estimate(),
            self.covariance().as_slice(),
            self.cross_covariance().as_slice(),
            self.input_covariance().as_slice()
        )
    }
}

impl<T: Real + Format, const S: usize, const I: usize, const L: usize> Format
    for FixedLagState<T, S, I, L>
{
    fn format(&self, f: Formatter) {
        let (x, w) = self.lagged();
        write!(
            f,
            "FixedLagState {{ n: {}, missing: {}, filtered: {}, lagged: {}, lagged_input: {} }}",
            self.steps(),
            self.missing(),
            self.filtered().as_slice(),
            x.as_slice(),
            w.as_slice()
        )
    }
}

impl<T: Real + Format, const S: usize, const I: usize, const O: usize> Format
    for InputStateObserver<T, S, I, O>
{
    fn format(&self, f: Formatter) {
        write!(
            f,
            "InputStateObserver {{ S: {=usize}, I: {=usize}, O: {=usize}, h: {} }}",
            S,
            I,
            O,
            self.time_step()
        )
    }
}

impl<T: Real + Format, const S: usize, const I: usize, const O: usize> Format
    for DualFilter<T, S, I, O>
{
    fn format(&self, f: Formatter) {
        write!(
            f,
            "DualFilter {{ S: {=usize}, I: {=usize}, O: {=usize}, h: {} }}",
            S,
            I,
            O,
            self.time_step()
        )
    }
}

impl<T: Real + Format, const S: usize, const I: usize, const O: usize> Format
    for DualKalmanFilterState<T, S, I, O>
{
    fn format(&self, f: Formatter) {
        write!(
            f,
            "DualKalmanFilterState {{ estimate: {}, covariance (columns): {}, input_covariance (columns): {} }}",
            self.estimate(),
            self.covariance().as_slice(),
            self.input_covariance().as_slice()
        )
    }
}

impl<T: Real + Format, const S: usize, const I: usize, const O: usize> Format
    for DualKalmanFilter<T, S, I, O>
{
    fn format(&self, f: Formatter) {
        write!(
            f,
            "DualKalmanFilter {{ S: {=usize}, I: {=usize}, O: {=usize}, h: {} }}",
            S,
            I,
            O,
            self.time_step()
        )
    }
}

impl<T: Real, const S: usize, const I: usize, const O: usize> Format
    for InputStateFilter<T, S, I, O>
{
    fn format(&self, f: Formatter) {
        write!(
            f,
            "InputStateFilter {{ S: {=usize}, I: {=usize}, O: {=usize} }}",
            S, I, O
        )
    }
}

impl<T: Real, const S: usize, const I: usize, const O: usize, const L: usize> Format
    for FixedLag<T, S, I, O, L>
{
    fn format(&self, f: Formatter) {
        write!(
            f,
            "FixedLag {{ S: {=usize}, I: {=usize}, O: {=usize}, L: {=usize} }}",
            S, I, O, L
        )
    }
}

impl Format for At2<'_> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "At2 {{ title: {=str}, npts: {=usize}, dt: {=f64} }}",
            self.title, self.npts, self.dt
        )
    }
}

impl Format for Values<'_> {
    fn format(&self, f: Formatter) {
        write!(f, "Values {{ line: {=u32} }}", self.line())
    }
}
