//! One step of the hybrid loop of the firmware example (`examples/firmware/qemu_hybrid.rs`)
//! and its host twin (`tests/firmware_hybrid.rs`), in one place so both run the same
//! arithmetic: the numerical model's displacement command for storey 1, compensation
//! (polynomial extrapolation over the actuator's delay), the emulated actuator, the
//! bilinear specimen's force at the displacement reached, the step completed with that
//! force. Needs `scene` (scenes/hybrid/scene.rs) included beside it.
#![allow(dead_code)] // each includer uses a different subset

use aemstep::hybrid::{
    Actuator, ActuatorState, Compensator, CompensatorState, Polynomial, Split, SplitState,
};
use aemstep::hysteresis::{Bilinear, BilinearHistory, Law};
use aemstep::nalgebra::SVector;
use aemstep::{Error, Real};

use crate::scene::{BLD, N};

/// The emulated actuator's delay line (commands): holds 14 samples of delay, enough for
/// 5 ms at 2048 Hz (10.24 samples).
pub const LINE: usize = 16;
/// The load's influence vector `−M ι` (kg): `p = IOTA · a_g`.
pub const IOTA: [[f64; 1]; N] = aemstep::models::base_excitation(&BLD.0);

/// The rig's fixed parts: actuator, compensator, specimen, and the load's influence
/// vector rounded to `T`.
#[derive(Clone, Copy)]
pub struct Rig<T: Real> {
    pub actuator: Actuator<T, LINE>,
    pub compensator: Polynomial<T>,
    pub specimen: Bilinear<T>,
    pub iota: [T; N],
}

/// What changes from step to step: the model's committed state, the actuator's line, the
/// compensator's memory, the specimen's history and the displacement last reached.
#[derive(Clone, Copy)]
pub struct Loop<T: Real> {
    pub model: SplitState<T, N>,
    pub actuator: ActuatorState<T, LINE>,
    pub compensator: CompensatorState<T>,
    pub history: BilinearHistory<T>,
    pub measured: T,
}

impl<T: Real> Rig<T> {
    /// At rest: every state zero, the load of `ag0` (m/s²).
    pub fn rest(&self, sys: &Split<T, N>, ag0: T) -> Result<Loop<T>, Error> {
        let z = SVector::zeros();
        Ok(Loop {
            model: sys.start(&z, &z, &z, &self.load(ag0))?,
            actuator: self.actuator.rest(T::zero()),
            compensator: self.compensator.rest(T::zero()),
            history: self.specimen.initial_history(),
            measured: T::zero(),
        })
    }

    /// The load `p = −M ι a_g` (N).
    pub fn load(&self, ag: T) -> SVector<T, N> {
        SVector::from_fn(|i, _| self.iota[i] * ag)
    }

    /// One step to the next sample with ground acceleration `ag` (m/s²): returns the
    /// storey-1 drift (m). `force_error` is added to the measured force (zero; NaN in a
    /// broken firmware build). On error the loop is not to be continued (the
    /// compensator's memory may have moved on).
    #[inline(always)]
    pub fn step(
        &self,
        sys: &Split<T, N>,
        s: &mut Loop<T>,
        ag: T,
        force_error: T,
    ) -> Result<T, Error> {
        let target = sys.command(&s.model)[0];
        let command = self
            .compensator
            .command(&mut s.compensator, target, s.measured)?;
        let reached = self.actuator.step(&mut s.actuator, command)?;
        let trial = self.specimen.trial(&s.history, reached, T::zero());
        let mut r = SVector::zeros();
        r[0] = trial.force + force_error;
        sys.complete(&mut s.model, &r, &self.load(ag))?;
        s.history = trial.history;
        s.measured = reached;
        Ok(s.model.state().u()[0])
    }
}
