//! Real-time hybrid simulation: a numerical model stepped in real time, coupled to a
//! physical specimen through an actuator. Each step the model commands a displacement, the
//! specimen's force is measured at it, and the model takes the force in.
//!
//! - [`Split`]: the explicit model-based KR-α / Chen–Ricles step split in two —
//!   [`Split::command`] (the displacement of `t_{n+1}` from the committed state) and
//!   [`Split::complete`] (the step finished with the measured restoring force). A missing
//!   or NaN force is a typed error and changes nothing.
//! - [`StoreySpecimen`]: a storey specimen on two degrees of freedom — the actuator command
//!   `u_i − u_{i−1}` and the force vector `±f` (`docs/hybrid.md`).
//! - [`Compensator`]: between the model's target and the actuator — [`Polynomial`]
//!   extrapolation over a known delay (orders 1–3), [`Adaptive`] extrapolation over a delay
//!   it estimates from the measured displacement.
//! - [`Actuator`]: an emulated actuator (pure delay and first-order lag) for tests and
//!   examples, so a whole hybrid test runs on the host and under QEMU.
//!
//! Equations, the scene (a 5-storey building with its first storey "physical") and the
//! measured errors against actuator delay: `docs/hybrid.md`.

mod actuator;
mod compensation;
mod split;

pub use actuator::{Actuator, ActuatorState};
pub use compensation::{Adaptive, Compensator, CompensatorState, Polynomial};
pub use split::{Split, SplitState, StoreySpecimen};
