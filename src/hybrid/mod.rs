//! Real-time hybrid simulation: a numerical model stepped in real time, coupled to a
//! physical specimen through an actuator. Each step the model commands a displacement, the
//! specimen's force is measured at it, and the model takes the force in.
//!
//! - [`Split`]: the explicit model-based KR-α / Chen–Ricles step split in two —
//!   [`Split::command`] (the displacement of `t_{n+1}` from the committed state) and
//!   [`Split::complete`] (the step finished with the measured restoring force). A missing
//!   or NaN force is a typed error and changes nothing.
//!
//! Equations, the scene (a 5-storey building with its first storey "physical") and the
//! measured errors against actuator delay: `docs/hybrid.md`.

mod split;

pub use split::{Split, SplitState};
