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
    /// A parameter is not finite or is outside its documented range: a scheme's (Newmark
    /// β, γ; generalized-α ρ∞; HHT α), a change detector's (window length, false-alarm
    /// probability, bank size), a delay compensator's, a spectrum's or an analysis'
    /// setting. The payload names the parameter and, in its message, the rule it broke.
    InvalidParameter(Param),
    /// A response-spectrum period is not finite and at least `1e-150` s (shorter ones have
    /// an `ω²` that overflows), or the periods of a bank are not in non-decreasing order
    /// (`spectrum::Bank`).
    InvalidPeriod,
    /// A damping ratio is NaN or outside `[0, 1)` (`spectrum::Bank`).
    InvalidDamping,
    /// A hysteretic law's parameter is not finite or is outside its documented range
    /// (e.g. a yield force `≤ 0`, a post-yield ratio outside `[0, 1)`). The payload names
    /// the parameter.
    InvalidMaterial(Param),
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
    /// `x = [u; v]`, `S = 3N` for generalized-α's `x = [u; v; a]`, `S = 2R` for `R` modes;
    /// or, for a model sized at run time (`DynLinear`, feature `std`),
    /// a matrix, vector or state not of the model's size.
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
    /// The stiffness matrix `K` has a negative eigenvalue beyond rounding (`K φ = ω² M φ`
    /// with `ω² < 0`): the model is unstable and has no real natural frequency
    /// ([`models::natural_frequencies`](crate::models::natural_frequencies)).
    StiffnessIndefinite,
    /// An estimator's step counter (or its count of missing samples) would pass
    /// `u64::MAX`: a checked step refuses rather than wrap to zero; the estimate was left
    /// unchanged. Start a new estimate (with the old one's state) to go on.
    StepCountOverflow,
    /// A feedback gain does not stabilize its loop: the closed-loop transition matrix
    /// (`Φ − Γ K` of a [`control`](crate::control) design, or an observer's error dynamics
    /// when a design certifies them) has spectral radius `≥ 1`, certified with its rounding
    /// bounded. Nothing was built.
    NotStabilizing,
}

/// Which parameter an [`Error::InvalidParameter`] or [`Error::InvalidMaterial`] names; its
/// [`as_str`](Param::as_str) states the rule it broke (the limits live in the message).
/// `Copy`, usable in `const` contexts.
///
/// Four bytes (`repr(u32)`), so that in [`Error`] it sits where
/// [`Error::MalformedRecord`]'s `line: u32` does (offset 4): every payload of `Error` is then
/// an aligned word and the compiler moves an `Error` as whole words. As one byte at offset 1
/// it made the Cortex-M4F code of `Result<_, Error>` shift bytes in the Newton loop
/// (`Nonlinear::try_step_with_history`: 3336 instead of 3293 instructions a step of the
/// yielding 3-storey building, `docs/cortex-m4-cost.md`). `Error` stays 16 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum Param {
    /// Newmark's `β` and `γ` (finite, `≥ 0`).
    NewmarkBetaGamma,
    /// The high-frequency spectral radius `ρ∞` of generalized-α or KR-α (in `[0, 1]`).
    RhoInf,
    /// HHT's `α` (in `[−1/3, 0]`).
    HhtAlpha,
    /// Generalized-α's `α_m`, `α_f` (finite, `< 1`), `β`, `γ` (finite, `≥ 0`).
    AlphaParameters,
    /// An actuator or compensation delay (s; finite, `≥ 0`; an adaptive compensator's initial delay at most its maximum).
    Delay,
    /// An actuator's first-order lag time constant (s; finite, `≥ 0`).
    Lag,
    /// A delay longer than the actuator's delay line holds (`delay/h ≤ L − 2` samples).
    DelayLine,
    /// A delay compensator's polynomial order (`1..=3`).
    CompensationOrder,
    /// A spectrum's sub-step rule (`Fixed(n)`, `1 ≤ n ≤` the documented maximum; `PointsPerPeriod(k)`, `k ≥ 1`).
    Substeps,
    /// An output buffer too short for the values (a record reader's `out`).
    OutputBuffer,
    /// A strength-reduction factor `R` (finite, `> 0`).
    StrengthReduction,
    /// A record's elastic strength demand at a period (finite, `> 0`: the record must move the oscillator).
    ElasticStrength,
    /// A target ductility `μ` (finite, `> 1`).
    TargetDuctility,
    /// A ductility search's settings (iterations `≥ 1`, a tolerance finite and at least 4 machine epsilons).
    Search,
    /// Hunt-and-fill settings (first intensity, growth, resolution finite and `> 0`, runs in `1..=10 000`, a finite top).
    HuntFill,
    /// A collapse EDP limit (`> 0`).
    CollapseLimit,
    /// An intensity measure level (finite, `> 0`).
    Intensity,
    /// Fractile inputs: at least one curve, EDP levels finite and `≥ 0`, quantiles in `[0, 1]`.
    Fractiles,
    /// A batch run cancelled by its caller (e.g. Ctrl-C) before it finished.
    Cancelled,
    /// A detector's number of outputs or degrees of freedom (`≥ 1`).
    Outputs,
    /// A detector's window length `W` (`≥ 1`).
    Window,
    /// A false-alarm probability `α` (in `(0, 1)`).
    FalseAlarm,
    /// A χ² threshold too large for the window's fixed-point sum.
    Threshold,
    /// A CUSUM's likelihood-ratio scale `λ` (finite, `> 1`).
    CusumDrift,
    /// A model bank's number of models `M` (`≥ 1`).
    BankSize,
    /// A storey index outside the model (`0 ≤ i < N`, `0` the storey on the ground).
    Storey,
    /// A law's initial stiffness `k` (finite, `> 0`).
    Stiffness,
    /// A law's yield force `f_y`, or a yield strength (finite, `> 0`, its yield displacement normal).
    YieldForce,
    /// A law's post-yield stiffness ratio `α` (finite, in `[0, 1)`).
    PostYieldRatio,
    /// Bouc–Wen's shape parameters: `β` finite `> 0`, `|γ| ≤ β`, exponent `n` finite `≥ 1`.
    BoucWenShape,
    /// A friction law's slip force `f_s` (finite, `> 0`).
    FrictionForce,
    /// A friction law's regularizing velocity `v_r` (finite, `> 0`).
    ReferenceVelocity,
    /// A control design's weights: `Q` (or `Q_y`) finite, symmetric, positive
    /// semidefinite; `R` finite, symmetric, positive definite; the cross weight such that
    /// the joint weight `[Q S; Sᵀ R]` is positive semidefinite.
    Weight,
    /// A saturation limit (force, stroke, voltage, rate) finite and `> 0`.
    Saturation,
    /// A control device's parameters (damper, actuator, mass damper) finite and in their
    /// documented ranges.
    Device,
}

impl Param {
    /// The parameter and the rule it broke, static (usable in a `const` `panic!`).
    pub const fn as_str(&self) -> &'static str {
        match self {
            Param::NewmarkBetaGamma => "Newmark beta and gamma must be finite and >= 0",
            Param::RhoInf => "rho_inf must be in [0, 1]",
            Param::HhtAlpha => "HHT alpha must be in [-1/3, 0]",
            Param::AlphaParameters => {
                "generalized-alpha needs finite alpha_m < 1, alpha_f < 1, beta >= 0, gamma >= 0"
            }
            Param::Delay => {
                "a delay must be finite, >= 0 (and the initial delay <= the maximum delay)"
            }
            Param::Lag => "the actuator lag must be finite and >= 0",
            Param::DelayLine => {
                "the delay is longer than the delay line: need delay/h <= L - 2 samples"
            }
            Param::CompensationOrder => "the compensation order must be 1, 2 or 3",
            Param::Substeps => {
                "substeps: Fixed(n) needs 1 <= n <= the maximum, PointsPerPeriod(k) needs k >= 1"
            }
            Param::OutputBuffer => "the output buffer is shorter than the values to write",
            Param::StrengthReduction => "a strength reduction factor must be finite and > 0",
            Param::ElasticStrength => {
                "the record's elastic strength at a period is zero or not finite"
            }
            Param::TargetDuctility => "the target ductility must be finite and > 1",
            Param::Search => "ductility search: iterations >= 1 and tolerance >= 4 eps, finite",
            Param::HuntFill => {
                "hunt-and-fill settings: positive finite intensities and steps, 1..=10000 runs"
            }
            Param::CollapseLimit => "the collapse EDP limit must be > 0",
            Param::Intensity => "an intensity must be finite and > 0",
            Param::Fractiles => {
                "fractiles need >= 1 curve, EDP levels finite >= 0, quantiles in [0, 1]"
            }
            Param::Cancelled => "the run was cancelled",
            Param::Outputs => "the number of outputs (degrees of freedom) must be >= 1",
            Param::Window => "the window length W must be >= 1",
            Param::FalseAlarm => "the false-alarm probability alpha must be in (0, 1)",
            Param::Threshold => {
                "the chi-square threshold overflows the window's fixed-point sum: use a larger alpha or a shorter window"
            }
            Param::CusumDrift => "the CUSUM lambda must be finite and > 1",
            Param::BankSize => "a model bank needs M >= 1 models",
            Param::Storey => "the storey index must be below the number of storeys N",
            Param::Stiffness => "the stiffness k must be finite and > 0",
            Param::YieldForce => "the yield force must be finite and > 0",
            Param::PostYieldRatio => "the post-yield ratio alpha must be in [0, 1)",
            Param::BoucWenShape => "Bouc-Wen needs beta > 0, |gamma| <= beta, n >= 1, all finite",
            Param::FrictionForce => "the friction slip force must be finite and > 0",
            Param::ReferenceVelocity => "the friction reference velocity must be finite and > 0",
            Param::Weight => {
                "control weights: Q symmetric >= 0, R symmetric > 0, [Q S; S' R] >= 0, all finite"
            }
            Param::Saturation => "a saturation limit must be finite and > 0",
            Param::Device => "a control device's parameter is not finite or out of its range",
        }
    }
}

impl fmt::Display for Param {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl Error {
    /// A short, static description (usable in `const` contexts, e.g. `panic!` while
    /// building a `static` operator at compile time). For [`Error::InvalidParameter`] and
    /// [`Error::InvalidMaterial`] it is the parameter's rule ([`Param::as_str`]).
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
            Error::InvalidParameter(p) | Error::InvalidMaterial(p) => p.as_str(),
            Error::OperatorOverflow => "an operator overflows the scalar type",
            Error::OperatorUnderflow => "an operator underflows the scalar type: rescale the units",
            Error::InvalidPeriod => {
                "a period is not finite and > 0, or the periods are not in non-decreasing order"
            }
            Error::InvalidDamping => "a damping ratio is NaN or outside [0, 1)",
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
            Error::StiffnessIndefinite => {
                "the stiffness matrix K is not positive semidefinite: no real natural frequency"
            }
            Error::StepCountOverflow => {
                "an estimator's step or missing-sample count would pass u64::MAX; state unchanged"
            }
            Error::NotStabilizing => {
                "the feedback gain does not stabilize: closed-loop spectral radius >= 1"
            }
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::InvalidParameter(_) => f.write_str("invalid parameter: ")?,
            Error::InvalidMaterial(_) => f.write_str("invalid material: ")?,
            _ => {}
        }
        f.write_str(self.as_str())?;
        match self {
            Error::SingularEffectiveMatrixAtStep { step } => write!(f, " (step {step})"),
            Error::MalformedRecord { line } => write!(f, " (line {line})"),
            _ => Ok(()),
        }
    }
}

impl core::error::Error for Error {}

#[cfg(test)]
mod tests {
    use super::{Error, Param};
    use core::mem::{align_of, size_of};

    /// Regression pin of the layout `Param`'s `repr(u32)` chooses (see its docs): `Param`
    /// one word, `Error` still 16 bytes, so every payload of `Error` is an aligned word and
    /// the M4F Newton loop costs what it cost before the payload (`docs/cortex-m4-cost.md`).
    #[test]
    fn param_is_a_word_and_error_stays_16_bytes() {
        assert_eq!((size_of::<Param>(), align_of::<Param>()), (4, 4));
        assert_eq!(size_of::<Error>(), 16);
        assert_eq!(size_of::<Result<(), Error>>(), 16);
    }
}
