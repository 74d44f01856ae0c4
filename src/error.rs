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
    /// The time step `h` is not finite and strictly positive.
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
    /// A scheme parameter (Newmark β, γ; generalized-α ρ∞; HHT α) is not finite or is
    /// outside its documented range.
    InvalidParameter,
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
            Error::InvalidParameter => "a scheme parameter is not finite or out of range",
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl core::error::Error for Error {}
