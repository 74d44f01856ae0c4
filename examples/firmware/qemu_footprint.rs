//! Firmware: flash footprint — a scene pays only for the capabilities it uses.
//!
//! Default build: only `Linear<f32, 5>` (operators a compiler-built `static`), stepping the
//! benchmark building under a synthetic ground motion. With `--cfg aemstep_control="footprint-modal"`
//! it also steps `Modal<f32, 5, 2>` whose modes the compiler solved (`static`,
//! `Modal::from_rows_f32`). With `--cfg aemstep_control="footprint-all"` it also steps the nonlinear
//! stepper (`Nonlinear<f32, 5>`, the building with hardening storey springs, Newton) and a
//! `Modal<f32, 5, 2>` built at start-up (`Modal::new`: the eigen-solver runs on target).
//! `scripts/qemu.sh` builds and runs all three, compares their flash (`llvm-size`) and
//! checks that the lean build links no symbol of the unused capabilities and the
//! `static`-modal build no eigen-solver (the full build, which has both, is the control).
//!
//! Run: `cargo run -p aemstep-firmware --release --target thumbv7em-none-eabihf --example qemu_footprint`
#![no_std]
#![no_main]

#[macro_use]
#[path = "fw/mod.rs"]
mod fw;

use aemstep::models::{self, Rows};
use aemstep::{Linear, Stepper};
use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use nalgebra::SVector;

const H: f64 = 0.02;
const STEPS: u32 = 1000;
const BUILDING: (Rows<5>, Rows<5>, Rows<5>) = models::five_storey_building();

static FULL: Linear<f32, 5> =
    match Linear::<f32, 5>::from_rows_f32(BUILDING.0, BUILDING.1, BUILDING.2, H) {
        Ok(s) => s,
        Err(e) => panic!("{}", e.as_str()),
    };

/// A deterministic synthetic ground acceleration (m/s²), |a_g| ≤ 1.
fn ground(n: u32) -> f32 {
    ((n.wrapping_mul(37) % 101) as f32) / 50.0 - 1.0
}

/// `p = −M ι a_g` (storey mass 1e5 kg).
fn load(n: u32) -> SVector<f32, 5> {
    SVector::from_element(-1.0e5 * ground(n))
}

#[cfg(aemstep_control = "footprint-modal")]
mod flash_modal {
    //! A modal model whose operators the compiler computed.
    use super::*;
    use aemstep::models::base_excitation;
    use aemstep::{Damping, Modal};

    static MODAL: Modal<f32, 5, 2> = match Modal::from_rows_f32(
        BUILDING.0,
        BUILDING.2,
        Damping::Matrix(BUILDING.1),
        base_excitation(&BUILDING.0),
        [[0.0, 0.0, 0.0, 0.0, 1.0]],
        H,
    ) {
        Ok(s) => s,
        Err(e) => panic!("{}", e.as_str()),
    };

    /// Steps it; returns the roof displacement.
    pub fn run() -> f32 {
        let mut ms = match MODAL.start_at_rest(&SVector::from([ground(0)])) {
            Ok(s) => s,
            Err(e) => fail!("modal start: {}", e.as_str()),
        };
        for n in 1..=STEPS {
            MODAL.step(&mut ms, &SVector::from([ground(n)]));
        }
        MODAL.output(&ms)[0]
    }
}

#[cfg(aemstep_control = "footprint-all")]
mod extra {
    //! The capabilities only the full build uses.
    use super::*;
    use aemstep::models::base_excitation;
    use aemstep::{Damping, Modal, Model, NewtonSettings, Nonlinear, State};
    use nalgebra::SMatrix;

    /// The building with hardening storey springs: storey force `k d (1 + d²/d0²)`.
    struct Hardening;
    impl Model<f32, 5> for Hardening {
        fn mass(&self) -> SMatrix<f32, 5, 5> {
            SMatrix::from_fn(|i, j| BUILDING.0[i][j] as f32)
        }
        fn force(&self, u: &SVector<f32, 5>, v: &SVector<f32, 5>) -> SVector<f32, 5> {
            let c = SMatrix::<f32, 5, 5>::from_fn(|i, j| BUILDING.1[i][j] as f32);
            let mut f = c * v;
            let k = models::FIVE_STOREY_STIFFNESS as f32;
            for i in 0..5 {
                let d = u[i] - if i > 0 { u[i - 1] } else { 0.0 };
                let s = k * d * (1.0 + d * d / 1.0e-4);
                f[i] += s;
                if i > 0 {
                    f[i - 1] -= s;
                }
            }
            f
        }
    }

    /// Steps the nonlinear and the modal model; returns their roof displacements.
    pub fn run() -> (f32, f32) {
        let nl = match Nonlinear::<f32, 5>::new(H, NewtonSettings::default()) {
            Ok(s) => s,
            Err(e) => fail!("nonlinear: {}", e.as_str()),
        };
        let z = SVector::zeros();
        let mut s: State<f32, 5> = match nl.start(&Hardening, &z, &z, &load(0)) {
            Ok(s) => s,
            Err(e) => fail!("nonlinear start: {}", e.as_str()),
        };
        for n in 1..=STEPS {
            if let Err(e) = nl.try_step(&Hardening, &mut s, &load(n)) {
                fail!("nonlinear step {}: {}", n, e.as_str());
            }
        }
        let (m, c, k) = BUILDING;
        let roof = [[0.0, 0.0, 0.0, 0.0, 1.0]];
        let sm = |a: [[f64; 5]; 5]| SMatrix::<f64, 5, 5>::from_fn(|i, j| a[i][j]);
        let b = SMatrix::<f64, 5, 1>::from_fn(|i, _| base_excitation(&m)[i][0]);
        let y = SMatrix::<f64, 1, 5>::from_fn(|_, j| roof[0][j]);
        let modal = match Modal::<f32, 5, 2>::new(&sm(m), &sm(k), &Damping::Matrix(c), &b, &y, H) {
            Ok(s) => s,
            Err(e) => fail!("modal: {}", e.as_str()),
        };
        let mut ms = match modal.start_at_rest(&SVector::from([ground(0)])) {
            Ok(s) => s,
            Err(e) => fail!("modal start: {}", e.as_str()),
        };
        for n in 1..=STEPS {
            modal.step(&mut ms, &SVector::from([ground(n)]));
        }
        (s.u()[4], modal.output(&ms)[0])
    }
}

#[entry]
fn main() -> ! {
    let z = SVector::zeros();
    let mut s = match FULL.start(&z, &z, &load(0)) {
        Ok(s) => s,
        Err(e) => fail!("start: {}", e.as_str()),
    };
    for n in 1..=STEPS {
        FULL.step(&mut s, &load(n));
    }
    if !s.is_finite() {
        fail!("linear state not finite");
    }
    hprintln!("qemu_footprint: Linear<f32, 5> roof {:e} m", s.u()[4]);
    #[cfg(aemstep_control = "footprint-modal")]
    {
        let modal = flash_modal::run();
        if !modal.is_finite() {
            fail!("modal result not finite");
        }
        hprintln!("qemu_footprint: Modal(R = 2, static) roof {:e} m", modal);
    }
    #[cfg(aemstep_control = "footprint-all")]
    {
        let (nl, modal) = extra::run();
        if !(nl.is_finite() && modal.is_finite()) {
            fail!("nonlinear or modal result not finite");
        }
        hprintln!(
            "qemu_footprint: Nonlinear roof {:e} m, Modal(R = 2) roof {:e} m",
            nl,
            modal
        );
    }
    fw::report_stack("qemu_footprint");
    fw::exit_success()
}
