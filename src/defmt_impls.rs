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

/// `impl Format for Type` for each entry `impl[generics] Format for Type => |s| "format",
/// args;`: `fn format` writes the format string (a `defmt` literal, interned as written)
/// with the arguments, in which `s` is `self` (`|_|` where no argument reads it). One
/// shape for every hand-written impl here and in `detection`.
macro_rules! format_impls {
    ($(impl[$($g:tt)*] Format for $ty:ty => |$s:tt| $fmt:tt $(, $arg:expr)*;)*) => {$(
        impl<$($g)*> Format for $ty {
            fn format(&self, f: Formatter) {
                let $s = self;
                write!(f, $fmt $(, $arg)*)
            }
        }
    )*};
}
pub(crate) use format_impls;

format_impls! {
    impl[T: Real + Format, const N: usize] Format for CompensatedState<T, N> => |s|
        "CompensatedState {{ state: {}, u_low: {}, v_low: {} }}",
        s.state(), s.u_low().as_slice(), s.v_low().as_slice();
    impl[T: Real + Format, const S: usize, const I: usize] Format for Estimate<T, S, I> => |s|
        "Estimate {{ n: {}, missing: {}, x: {}, last_input: {} }}",
        s.steps(), s.missing(), s.x().as_slice(), s.last_input().as_slice();
    impl[T: Real + Format, const S: usize, const I: usize] Format for KalmanState<T, S, I> => |s|
        "KalmanState {{ estimate: {}, covariance (columns): {} }}",
        s.estimate(), s.covariance().as_slice();
    impl[T: Real + Format, const N: usize] Format for Tangent<T, N> => |s|
        "Tangent {{ stiffness (columns): {}, damping (columns): {} }}",
        s.stiffness.as_slice(), s.damping.as_slice();
    impl[T: Real + Format, const N: usize] Format for SymTridiagonal<T, N> => |s|
        "SymTridiagonal {{ diagonal: {}, off: {} }}",
        s.diagonal.as_slice(), s.off.as_slice();
    impl[T: Real + Format, const N: usize] Format for TridiagonalTangent<T, N> => |s|
        "TridiagonalTangent {{ mass: {}, stiffness: {}, damping: {} }}",
        s.mass, s.stiffness, s.damping;
    impl[T: Real + Format, const N: usize] Format for Coefficients<T, N> => |s|
        "Coefficients {{ mass (columns): {}, damping (columns): {}, stiffness (columns): {} }}",
        s.mass.as_slice(), s.damping.as_slice(), s.stiffness.as_slice();
    impl[T: Real + Format, const N: usize, H: Format] Format for Trial<T, N, H> => |s|
        "Trial {{ force: {}, history: {}, branch: {=u64:#x} }}",
        s.force.as_slice(), s.history, s.branch;
    impl[T: Real + Format, const N: usize] Format for EnergyAccount<T, N> => |s|
        "EnergyAccount {{ initial: {} J, input: {} J, kinetic: {} J, recoverable: {} J, viscous: {} J, hysteretic: {} J, balance_error: {} J }}",
        s.initial, s.input, s.kinetic, s.recoverable, s.viscous, s.hysteretic, s.balance_error();
    impl[T: Real + Format, L: Law<T> + Format, const N: usize]
        Format for ShearBuilding<T, L, N> => |s|
        "ShearBuilding {{ masses: {}, damping (columns): {}, laws: {} }}",
        s.masses().as_slice(), s.damping().as_slice(), s.laws();

    // Steppers: name, size and time step.
    impl[T: Real + Format, const N: usize] Format for Linear<T, N> => |s|
        "Linear {{ N: {=usize}, h: {} }}",
        N, Stepper::time_step(s);
    impl[T: Real + Format, const N: usize] Format for AForm<T, N> => |s|
        "AForm {{ N: {=usize}, h: {} }}",
        N, Stepper::time_step(s);
    impl[T: Real + Format, const N: usize] Format for Newmark<T, N> => |s|
        "Newmark {{ N: {=usize}, h: {} }}",
        N, Stepper::time_step(s);
    impl[T: Real + Format, const N: usize] Format for Exact<T, N> => |s|
        "Exact {{ N: {=usize}, h: {} }}",
        N, Stepper::time_step(s);
    impl[T: Real + Format, const N: usize] Format for GeneralizedAlpha<T, N> => |s|
        "GeneralizedAlpha {{ N: {=usize}, h: {} }}",
        N, Stepper::time_step(s);
    impl[T: Real + Format, const N: usize] Format for KrAlpha<T, N> => |s|
        "KrAlpha {{ N: {=usize}, h: {}, alpha_m: {}, alpha_f: {} }}",
        N, Stepper::time_step(s), s.parameters().alpha_m, s.parameters().alpha_f;
    impl[T: Real + Format, const N: usize] Format for Split<T, N> => |s|
        "Split {{ scheme: {} }}",
        s.scheme();
    impl[T: Real + Format, const N: usize] Format for SplitState<T, N> => |s|
        "SplitState {{ state: {}, restoring_force: {}, load: {} }}",
        s.state(), s.restoring_force().as_slice(), s.load().as_slice();
    impl[T: Real + Format, const N: usize] Format for CompensatedLinear<T, N> => |s|
        "CompensatedLinear {{ N: {=usize}, h: {} }}",
        N, Stepper::time_step(s);
    impl[T: Real + Format, const N: usize, const I: usize] Format for LinearInput<T, N, I> => |s|
        "LinearInput {{ N: {=usize}, I: {=usize}, h: {} }}",
        N, I, Stepper::time_step(s);
    impl[T: Real + Format, const N: usize, const R: usize, const I: usize, const O: usize]
        Format for Modal<T, N, R, I, O> => |s|
        "Modal {{ N: {=usize}, R: {=usize}, I: {=usize}, O: {=usize}, h: {} }}",
        N, R, I, O, Stepper::time_step(s);
    impl[T: Real + Format, const N: usize] Format for Nonlinear<T, N> => |s|
        "Nonlinear {{ N: {=usize}, h: {} }}",
        N, Nonlinear::time_step(s);
    impl[T: Real + Format, const N: usize] Format for Varying<T, N> => |s|
        "Varying {{ N: {=usize}, h: {} }}",
        N, Varying::time_step(s);
    impl[T: Real + Format, const S: usize, const I: usize, const O: usize]
        Format for Observer<T, S, I, O> => |s|
        "Observer {{ S: {=usize}, I: {=usize}, O: {=usize}, h: {} }}",
        S, I, O, s.time_step();

    // Operators whose sizes are all they print.
    impl[T: Real, const S: usize, const I: usize, const O: usize]
        Format for Kalman<T, S, I, O> => |_|
        "Kalman {{ S: {=usize}, I: {=usize}, O: {=usize} }}",
        S, I, O;
    impl[T: Real, const S: usize, const I: usize, const P: usize]
        Format for Readout<T, S, I, P> => |_|
        "Readout {{ S: {=usize}, I: {=usize}, P: {=usize} }}",
        S, I, P;
    impl[T: Real, const P: usize] Format for Bank<T, P> => |_|
        "Bank {{ P: {=usize} }}",
        P;
    impl[const N: usize, const S: usize, const I: usize] Format for StateSpace<N, S, I> => |_|
        "StateSpace {{ N: {=usize}, S: {=usize}, I: {=usize} }}",
        N, S, I;
    impl[const N: usize, const I: usize, const O: usize] Format for Outputs<N, I, O> => |_|
        "Outputs {{ N: {=usize}, I: {=usize}, O: {=usize} }}",
        N, I, O;
    impl[const S: usize, const I: usize, const O: usize] Format for Measurement<S, I, O> => |_|
        "Measurement {{ S: {=usize}, I: {=usize}, O: {=usize} }}",
        S, I, O;
    impl[const S: usize, const O: usize] Format for SteadyState<S, O> => |_|
        "SteadyState {{ S: {=usize}, O: {=usize} }}",
        S, O;

    // Joint input–state estimation: estimates print their numbers, filters their sizes.
    impl[T: Real + Format, const S: usize, const I: usize] Format for JointEstimate<T, S, I> => |s|
        "JointEstimate {{ n: {}, missing: {}, xi: {}, input: {} }}",
        s.steps(), s.missing(), s.xi().as_slice(), s.input().as_slice();
    impl[T: Real + Format, const S: usize, const I: usize, const O: usize]
        Format for InputStateFilterState<T, S, I, O> => |s|
        "InputStateFilterState {{ estimate: {}, covariance (columns): {}, cross_covariance (columns): {}, input_covariance (columns): {} }}",
        s.estimate(),
        s.covariance().as_slice(),
        s.cross_covariance().as_slice(),
        s.input_covariance().as_slice();
    impl[T: Real + Format, const S: usize, const I: usize, const L: usize]
        Format for FixedLagState<T, S, I, L> => |s|
        "FixedLagState {{ n: {}, missing: {}, filtered: {}, lagged: {}, lagged_input: {} }}",
        s.steps(),
        s.missing(),
        s.filtered().as_slice(),
        s.lagged().0.as_slice(),
        s.lagged().1.as_slice();
    impl[T: Real + Format, const S: usize, const I: usize, const O: usize]
        Format for InputStateObserver<T, S, I, O> => |s|
        "InputStateObserver {{ S: {=usize}, I: {=usize}, O: {=usize}, h: {} }}",
        S, I, O, s.time_step();
    impl[T: Real + Format, const S: usize, const I: usize, const O: usize]
        Format for DualFilter<T, S, I, O> => |s|
        "DualFilter {{ S: {=usize}, I: {=usize}, O: {=usize}, h: {} }}",
        S, I, O, s.time_step();
    impl[T: Real + Format, const S: usize, const I: usize, const O: usize]
        Format for DualKalmanFilterState<T, S, I, O> => |s|
        "DualKalmanFilterState {{ estimate: {}, covariance (columns): {}, input_covariance (columns): {} }}",
        s.estimate(), s.covariance().as_slice(), s.input_covariance().as_slice();
    impl[T: Real + Format, const S: usize, const I: usize, const O: usize]
        Format for DualKalmanFilter<T, S, I, O> => |s|
        "DualKalmanFilter {{ S: {=usize}, I: {=usize}, O: {=usize}, h: {} }}",
        S, I, O, s.time_step();
    impl[T: Real, const S: usize, const I: usize, const O: usize]
        Format for InputStateFilter<T, S, I, O> => |_|
        "InputStateFilter {{ S: {=usize}, I: {=usize}, O: {=usize} }}",
        S, I, O;
    impl[T: Real, const S: usize, const I: usize, const O: usize, const L: usize]
        Format for FixedLag<T, S, I, O, L> => |_|
        "FixedLag {{ S: {=usize}, I: {=usize}, O: {=usize}, L: {=usize} }}",
        S, I, O, L;
    impl[] Format for At2<'_> => |s|
        "At2 {{ title: {=str}, npts: {=usize}, dt: {=f64} }}",
        s.title, s.npts, s.dt;
    impl[] Format for Values<'_> => |s|
        "Values {{ line: {=u32} }}",
        s.line();
}
