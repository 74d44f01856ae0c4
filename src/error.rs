//! The crate's one error type.

use core::fmt;

/// What went wrong. Every fallible call in the crate returns this; none panics.
///
/// A step that fails leaves the caller's state exactly as it was.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum Error {
    /// An input matrix, vector or load has a NaN or infinite entry.
    NonFiniteInput,
    /// The time step `h` is not finite and strictly positive, or `h²` under- or overflows;
    /// or `h` or `h²/4` is not representable (finite and nonzero) in the stepper's scalar
    /// type (e.g. `h = 1e58` or `1e-30` in `f32`).
    InvalidTimeStep,
    /// The effective matrix `M + (h/2) C + (h²/4) K` is singular to working precision,
    /// so no step can be taken.
    SingularEffectiveMatrix,
    /// The mass matrix `M` is singular, so the initial acceleration
    /// `q0 = M⁻¹ (p0 − C v0 − K u0)` cannot be formed. Start with a known initial
    /// acceleration instead (`start_with_acceleration`).
    SingularMass,
    /// The step would produce a NaN or infinite state (e.g. a NaN load sample);
    /// the state was left unchanged.
    NonFiniteState,
    /// The nonlinear step's Newton iteration did not bring the relative residual down to
    /// its tolerance within the iteration budget; the state was left unchanged
    /// (`Nonlinear::trial_step` still returns the unconverged candidate).
    NotConverged,
    /// The Newton matrix `J = M + (h/2) ∂F/∂v + (h²/4) ∂F/∂u` of a nonlinear step is
    /// singular to working precision; the state was left unchanged.
    SingularJacobian,
    /// A nonlinear model's force `F(u, v)` or its tangent returned a NaN or infinite
    /// entry; the state was left unchanged.
    NonFiniteForce,
    /// Newton settings with zero iterations, or a tolerance that is negative or not finite.
    InvalidNewtonSettings,
    /// The effective matrix `M(t) + (h/2) C(t) + (h²/4) K(t)` of a time-varying system is
    /// singular to working precision at `t = step·h`; the state was left unchanged.
    SingularEffectiveMatrixAtStep {
        /// The index `n` of the step that could not be taken (the state is still at `n − 1`).
        step: u64,
    },
    /// The mass matrix `M` is not symmetric positive definite (modal stepper: the
    /// generalized eigenproblem needs its Cholesky factor).
    MassNotSpd,
    /// The stiffness matrix `K` is not symmetric (modal stepper).
    StiffnessNotSymmetric,
    /// The kept modes are not a valid selection: none (`R = 0`), more than `N`, an index
    /// `≥ N`, or a repeated index.
    InvalidModeSelection,
    /// The damping matrix couples the modes (it is not classical), so the modes cannot be
    /// stepped independently: use the full `Linear` stepper.
    NonClassicalDamping,
    /// The symmetric eigen-solver did not converge (only with pathological input).
    EigenNotConverged,
    /// An operator computed from the data overflows the scalar type: it is not finite in
    /// `f64`, or exceeds the largest finite value of `T` (e.g. `f32`) and would round to
    /// `∞`.
    OperatorOverflow,
    /// An operator computed from nonzero data underflows the scalar type: it rounds to
    /// zero, or its largest entry is subnormal (below `MIN_POSITIVE` of `T`), where it has
    /// lost its precision (e.g. `M⁻¹K ≈ 1e-324` from data whose scales are 1e300 apart).
    /// Rescale the units.
    OperatorUnderflow,
    /// A scheme parameter (Newmark β, γ; generalized-α ρ∞; HHT α) or a change detector's
    /// (window length, false-alarm probability, bank size) is not finite or is outside its
    /// documented range.
    InvalidParameter,
    /// A response-spectrum period is not finite and at least `1e-150` s (shorter ones have
    /// an `ω²` that overflows), or the periods of a bank are not in non-decreasing order
    /// (`spectrum::Bank`).
    InvalidPeriod,
    /// A damping ratio is NaN or outside `[0, 1)` (`spectrum::Bank`).
    InvalidDamping,
    /// A hysteretic law's parameter is not finite or is outside its documented range
    /// (e.g. a yield force `≤ 0`, a post-yield ratio outside `[0, 1)`).
    InvalidMaterial,
    /// A covariance matrix (observer process or measurement noise, or an initial
    /// estimation covariance) is not finite, not symmetric, or not positive (semi)definite
    /// as required; or a Kalman filter's innovation covariance lost definiteness (state
    /// unchanged).
    InvalidCovariance,
    /// The discrete algebraic Riccati equation of the steady-state Kalman gain did not
    /// converge (the model is not detectable from the outputs, or not stabilizable by the
    /// process noise).
    RiccatiNotConverged,
    /// A state-space size parameter does not match the model: `S = 2N` for the full state
    /// `x = [u; v]`, `S = 3N` for generalized-α's `x = [u; v; a]`, `S = 2R` for `R` modes.
    StateSizeMismatch,
    /// The unknown input cannot be estimated from the chosen sensors
    /// ([`estimation`](crate::estimation)): fewer measurements than unknown inputs, a
    /// feedthrough `D̃ = HΓ₁ + D` without full column rank, or an invariant zero of the
    /// model on or outside the unit circle (acceleration-only sensing: the static
    /// force–displacement pair at `z = 1`, the drift), so the estimator has no stable
    /// steady state.
    InputNotIdentifiable,
    /// A ground-motion record's text ([`records`](crate::records)) is malformed at this
    /// line (1-based): a PEER AT2 header without a readable `NPTS`/`DT` (a count that is not
    /// a whole number, a `DT` that is not finite and `> 0`), a value that is not a number,
    /// more or fewer values than the header's `NPTS`, more than one value on a line of a
    /// one-column record, or a record with no values at all.
    MalformedRecord {
        /// The line (1-based) where the problem was found; for a record that ends early,
        /// the line after its last.
        line: u32,
    },
    /// An estimator's step counter (or its count of missing samples) would pass
    /// `u64::MAX`: a checked step refuses rather than wrap to zero; the estimate was left
    /// unchanged. Start a new estimate (with the old one's state) to go on.
    StepCountOverflow,
}

impl Error {
    /// A short, static description (usable in `const` contexts, e.g. `panic!` while
    /// building a `static` operator at compile time).
    pub const fn as_str(&self) -> &'static str {
        match self {
            Error::NonFiniteInput => "an input has a NaN or infinite entry",
            Error::InvalidTimeStep => "the time step h must be finite and > 0",
            Error::SingularEffectiveMatrix => {
                "the effective matrix M + (h/2)C + (h^2/4)K is singular"
            }
            Error::SingularMass => {
                "the mass matrix M is singular: start with a known initial acceleration"
            }
            Error::NonFiniteState => {
                "the step would make the state NaN or infinite; state unchanged"
            }
            Error::NotConverged => "Newton did not converge within its budget; state unchanged",
            Error::SingularJacobian => {
                "the Newton matrix M + (h/2)dF/dv + (h^2/4)dF/du is singular; state unchanged"
            }
            Error::NonFiniteForce => {
                "the model's force or tangent is NaN or infinite; state unchanged"
            }
            Error::InvalidNewtonSettings => {
                "Newton settings need >= 1 iteration and a finite tolerance >= 0"
            }
            Error::SingularEffectiveMatrixAtStep { .. } => {
                "the time-varying effective matrix is singular at this step; state unchanged"
            }
            Error::MassNotSpd => "the mass matrix M is not symmetric positive definite",
            Error::StiffnessNotSymmetric => "the stiffness matrix K is not symmetric",
            Error::InvalidModeSelection => {
                "invalid mode selection: need 1 <= R <= N distinct modes, each < N"
            }
            Error::NonClassicalDamping => {
                "the damping is not classical (it couples the modes): use the full stepper"
            }
            Error::EigenNotConverged => "the symmetric eigen-solver did not converge",
            Error::InvalidParameter => "a scheme parameter is not finite or out of range",
            Error::OperatorOverflow => "an operator overflows the scalar type",
            Error::OperatorUnderflow => "an operator underflows the scalar type: rescale the units",
            Error::InvalidPeriod => {
                "a period is not finite and > 0, or the periods are not in non-decreasing order"
            }
            Error::InvalidDamping => "a damping ratio is NaN or outside [0, 1)",
            Error::InvalidMaterial => "a hysteretic law parameter is not finite or out of range",
            Error::InvalidCovariance => {
                "a covariance is not finite, symmetric and positive (semi)definite"
            }
            Error::RiccatiNotConverged => {
                "the Riccati equation of the steady-state gain did not converge"
            }
            Error::StateSizeMismatch => "state size must be S = 2N (or 3N gen-alpha, 2R modal)",
            Error::InputNotIdentifiable => {
                "the unknown input is not identifiable from these sensors (count, rank or zeros)"
            }
            Error::MalformedRecord { .. } => {
                "malformed record: header, value count or a value that is not a number"
            }
            Error::StepCountOverflow => {
                "an estimator's step or missing-sample count would pass u64::MAX; state unchanged"
            }
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())?;
        match self {
            Error::SingularEffectiveMatrixAtStep { step } => write!(f, " (step {step})"),
            Error::MalformedRecord { line } => write!(f, " (line {line})"),
            _ => Ok(()),
        }
    }
}

impl core::error::Error for Error {}
