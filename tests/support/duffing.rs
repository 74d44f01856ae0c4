//! Paper Example 5, the Duffing oscillator `u'' + 0.2 u' + u + u³ = p(t)` (`models::Duffing`),
//! u0 = 0, v0 = 1, `p(t)` chosen so that the exact solution is `u = e^{−0.1t} sin t`, run
//! as the firmware (`examples/qemu_nonlinear.rs`) runs it: exactly 2 Newton iterations a
//! step. Shared by `tests/firmware_duffing.rs` (which derives the firmware's bound from
//! it) and `xtask/src/bin/verification.rs` (which prints it).
#![allow(dead_code)]

use aemstep::models::Duffing;
use aemstep::{NewtonSettings, Nonlinear, Real};
use nalgebra::vector;

/// Newton tolerance of the firmware: `NewtonSettings::default_tolerance()` for f32.
pub const TOL: f64 = 1.5e-5;

/// The exact solution, written here.
pub fn exact(t: f64) -> f64 {
    (-0.1 * t).exp() * t.sin()
}

/// `p(t) = u'' + 0.2 u' + u + u³` for the exact `u`: the linear part reduces to
/// `−0.01 e^{−0.1t} sin t`.
pub fn load(t: f64) -> f64 {
    -0.01 * (-0.1 * t).exp() * t.sin() + (-0.3 * t).exp() * t.sin().powi(3)
}

/// Every `u_n` (n = 1..=steps at step h) and the number of steps whose Newton report was
/// not (converged, 2 iterations).
pub fn trajectory<T: Real>(h: f64, steps: u32) -> (Vec<f64>, u32) {
    let r = T::from_f64_rounded;
    let stepper = Nonlinear::<T, 1>::new(h, NewtonSettings::exactly(2, r(TOL))).expect("settings");
    let mut s = stepper
        .start(
            &Duffing,
            &vector![r(0.0)],
            &vector![r(1.0)],
            &vector![r(load(0.0))],
        )
        .expect("start");
    let (mut us, mut bad) = (Vec::new(), 0);
    for n in 1..=steps {
        let t = n as f64 * h;
        match stepper.try_step(&Duffing, &mut s, &vector![r(load(t))]) {
            Ok(rep) if rep.converged && rep.iterations == 2 => {}
            _ => bad += 1,
        }
        us.push(s.u()[0].as_f64());
    }
    (us, bad)
}

/// max |u_n − u(t_n)| of a [`trajectory`] at step `h`.
pub fn max_error(us: &[f64], h: f64) -> f64 {
    us.iter()
        .enumerate()
        .map(|(i, u)| (u - exact((i + 1) as f64 * h)).abs())
        .fold(0.0, f64::max)
}
