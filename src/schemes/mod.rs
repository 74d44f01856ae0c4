//! The constant-coefficient linear schemes, one file each, all behind
//! [`Stepper`](crate::Stepper):
//!
//! - [`Linear`]: the AEM in eliminated form (`3N²` a step), the crate's kernel.
//! - [`AForm`]: the paper's literal `U_n = A U_{n−1} + b p_n` (`12N²`), for reference.
//! - [`LinearInput`]: loads through an influence matrix `p = B w` (`2N² + N·I`).
//! - [`CompensatedLinear`]: the AEM with the state update compensated (long `f32` runs).
//! - [`Newmark`], [`GeneralizedAlpha`], [`Exact`]: the comparators.
//! - [`KrAlpha`]: the explicit model-based schemes of real-time hybrid simulation
//!   (Chen–Ricles, KR-α).

mod aform;
mod compensated;
mod exact;
mod generalized_alpha;
mod input;
pub(crate) mod kr_alpha;
mod linear;
mod newmark;

pub use aform::AForm;
pub use compensated::{CompensatedLinear, CompensatedState};
pub use exact::Exact;
pub(crate) use exact::{Exponential, exponential};
pub(crate) use generalized_alpha::alpha_operators;
pub use generalized_alpha::{AlphaParameters, GeneralizedAlpha};
pub use input::LinearInput;
pub use kr_alpha::KrAlpha;
pub use linear::Linear;
pub use newmark::Newmark;
