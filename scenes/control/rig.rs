//! One step of the semi-active control loop of the firmware example
//! (`examples/firmware/qemu_control.rs`) and its host twin (`tests/firmware_control.rs`), in
//! one place so both run the same arithmetic. At sample `k`: the three absolute floor
//! accelerations of the emulated structure and the damper force it delivers are sampled,
//! the controller (`Controller::try_step`) gives the desired force, the clipped-optimal law
//! (`ClippedOptimal`) the voltage, which is held over the step while the emulated structure
//! and damper (`Coupled` + the `Nonlinear` stepper) advance to `t_{k+1}`. Needs `scene`
//! (scenes/control/scene.rs) included beside it.
#![allow(dead_code)] // each includer uses a different subset

use aemstep::control::{
    ClippedOptimal, Command, ControlState, Controller, Coupled, LinearStructure, Link, MrDamper,
    MrHistory,
};
use aemstep::hysteresis::HistoryModel;
use aemstep::nalgebra::SVector;
use aemstep::{Error, NewtonSettings, Nonlinear, Real, State};

use crate::scene::{C, DAMPER, H, I, K, M, N, O, S};

/// The emulated plant: the structure with the MR damper from the ground to floor 1.
pub type Plant<T> = Coupled<T, LinearStructure<T, N>, MrDamper<T>, N>;
/// The controller of the scene.
pub type Ctl<T> = Controller<T, S, I, O>;

/// Newton iterations allowed a plant step (it converges in 1–3).
pub const ITERATIONS: u32 = 20;

/// The rig's fixed parts: the plant's stepper and the switching law.
#[derive(Clone, Copy)]
pub struct Rig<T: Real> {
    pub stepper: Nonlinear<T, N>,
    pub law: ClippedOptimal<T, I>,
}

/// What changes from step to step: the plant (its held voltage), its state and history,
/// the controller's state, and the ground acceleration at the state's time.
#[derive(Clone, Copy)]
pub struct Loop<T: Real> {
    pub plant: Plant<T>,
    pub state: State<T, N>,
    pub history: ((), MrHistory<T>),
    pub control: ControlState<T, S, I>,
    pub ag: T,
}

/// What a step reports: the controller's command (desired force held, its status), the
/// voltage held over the step, and the floor-1 displacement reached (m).
#[derive(Clone, Copy)]
pub struct Out<T: Real> {
    pub command: Command<T, I>,
    pub voltage: T,
    pub x1: T,
}

impl<T: Real> Rig<T> {
    /// The rig and the loop at rest (the damper at 0 V), the ground at `ag0` (m/s²).
    pub fn new(ctl: &Ctl<T>, ag0: T) -> Result<(Self, Loop<T>), Error> {
        let structure = LinearStructure::<T, N>::new(&M, &C, &K)?;
        let plant = Coupled::passive_off(structure, MrDamper::new(&DAMPER)?, Link::Ground(0), H)?;
        let stepper = plant.nonlinear(NewtonSettings::up_to(
            ITERATIONS,
            NewtonSettings::<T>::default_tolerance(),
        ))?;
        let z = SVector::zeros();
        let (state, history) =
            stepper.start_with_history(&plant, &z, &z, &load(ag0), &plant.initial_history())?;
        let rig = Rig {
            stepper,
            law: ClippedOptimal::new(DAMPER.v_max)?,
        };
        let s = Loop {
            plant,
            state,
            history,
            control: ctl.start_at_rest(),
            ag: ag0,
        };
        Ok((rig, s))
    }

    /// One sample: sense, control, switch ([`Rig::control`]), and step the plant to the
    /// next sample with ground acceleration `ag` (m/s², [`Rig::advance`]). On error nothing
    /// in `s` changes.
    #[inline(always)]
    pub fn step(
        &self,
        ctl: &Ctl<T>,
        s: &mut Loop<T>,
        ag: T,
        missing: bool,
        force_error: T,
    ) -> Result<Out<T>, Error> {
        let mut next = *s;
        let (command, voltage) = self.control(ctl, &mut next, missing, force_error)?;
        let x1 = self.advance(&mut next, ag)?;
        *s = next;
        Ok(Out {
            command,
            voltage,
            x1,
        })
    }

    /// The controller's side of a sample (what a controller board runs): sample the
    /// absolute floor accelerations and the damper's measured force, the controller's
    /// desired force, the clipped-optimal voltage, held on the plant. `missing`: the
    /// floor-1 accelerometer's sample is lost (NaN). `force_error` is added to the measured
    /// force (zero; NaN in a broken firmware build). Returns the command and the voltage.
    /// On error nothing in `s` changes.
    #[inline(always)]
    pub fn control(
        &self,
        ctl: &Ctl<T>,
        s: &mut Loop<T>,
        missing: bool,
        force_error: T,
    ) -> Result<(Command<T, I>, T), Error> {
        let mut y: SVector<T, O> = s.state.a().map(|a| a + s.ag);
        if missing {
            y[0] = T::from_f64_rounded(f64::NAN);
        }
        let f = SVector::from([s.plant.delivered_force(&s.history) + force_error]);
        let mut control = s.control;
        let command = ctl.try_step(&mut control, &y, &f, false)?;
        let voltage = self.law.command(&SVector::from(command.force), &f)?[0];
        let mut plant = s.plant;
        plant.set_command(voltage)?;
        s.control = control;
        s.plant = plant;
        Ok((command, voltage))
    }

    /// The emulated plant's side: structure and damper, the voltage held, one step to the
    /// next sample with ground acceleration `ag` (m/s²). Returns the floor-1 displacement
    /// (m). On error nothing in `s` changes.
    #[inline(always)]
    pub fn advance(&self, s: &mut Loop<T>, ag: T) -> Result<T, Error> {
        self.stepper
            .try_step_with_history(&s.plant, &mut s.state, &mut s.history, &load(ag))?;
        s.ag = ag;
        Ok(s.state.u()[0])
    }
}

/// The load `p = −M ι ẍ_g` (N).
pub fn load<T: Real>(ag: T) -> SVector<T, N> {
    let m = T::from_f64_rounded(crate::scene::MASS);
    SVector::from_element(-(m * ag))
}
