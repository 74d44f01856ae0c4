//! Vibration control: loops that act on the structure.
//!
//! Design models (zero-order hold with the one-sample computation delay), optimal state
//! and output feedback (discrete LQR on the observer's Riccati solver, LQG on its
//! observers), the devices that deliver the force (ideal actuator, active mass driver,
//! magnetorheological damper, passive baselines) and the semi-active laws that command
//! them. Fixed size, `no_std`, `f32`/`f64`; every gain can be computed in `const fn` into
//! flash, and a failed step changes nothing.

pub mod devices;
pub mod lqg;
pub mod lqr;
pub mod semiactive;

pub use devices::{
    ActuatorHistory, Coupled, Device, ForceActuator, LinearStructure, Link, MassDamper, MrDamper,
    MrHistory, MrParameters, MrPhenomenological, PhenomenologicalHistory,
    PhenomenologicalParameters, Viscous, mass_damper,
};
pub use lqg::{Command, ControlState, Controller, Status};
pub use lqr::{DesignModel, Lqr, Weights};
pub use semiactive::{ClippedOptimal, Lyapunov, ModulatedFriction};
