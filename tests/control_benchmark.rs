//! Scene 1 of issue 33: the MR-damper benchmark of Dyke, Spencer, Sain & Carlson (1996) run
//! by the crate (`scenes/control/dyke1996.rs`: [`aemstep::control::Coupled`] structure +
//! [`aemstep::control::MrDamper`] under the `Nonlinear` stepper, the crate's `Controller`
//! at 1 kHz with `ClippedOptimal` switching) against the independent RK4 reference
//! (`tests/support/dyke1996.rs`, which calls nothing of `aemstep`).
//!
//! Fast tests run the first `SHORT` samples of the record (its first 3 s, 0.6 s of model
//! time: the motion builds up later, the peaks there are a tenth of the full record's);
//! the full record is the `#[ignore]`d `full_record_rows` (release stage) and
//! `docs/control.md` (`cargo run --release -p xtask --bin control_benchmark`).

#[path = "support/dyke1996.rs"]
mod dyke1996;
#[path = "../scenes/modal/elcentro.rs"]
mod elcentro;
#[path = "../scenes/control/dyke1996.rs"]
mod scene;

use dyke1996::{Attached, DAMPER, Record, STRUCTURE};
use scene::{Case, Peaks, worst};

/// Samples of the record in the fast tests: 3 s of recorded time, 0.6 s of model time.
const SHORT: usize = 151;

/// The first `n` samples of the record and a zero sample after them (so the ground motion
/// ends continuously: a jump to zero after a strong sample would put an `O(h)` impulse
/// error into any step-based scheme and hide its order).
fn short(n: usize) -> Vec<f64> {
    let mut ag = elcentro::AG_F64[..n].to_vec();
    ag.push(0.0);
    ag
}

fn record(ag: &[f64]) -> Record<'_> {
    Record {
        ag,
        dt: elcentro::DT,
        time_scale: scene::TIME_SCALE,
        amplitude: 1.0,
    }
}

fn reference(case: Case, ag: &[f64], h: f64) -> Peaks {
    let rec = record(ag);
    let p = match case {
        Case::Uncontrolled => dyke1996::simulate(
            &STRUCTURE,
            &DAMPER,
            &rec,
            Attached::No,
            h,
            scene::EXTRA,
            |_, _, _| 0.0,
        ),
        Case::PassiveOff => dyke1996::simulate(
            &STRUCTURE,
            &DAMPER,
            &rec,
            Attached::Yes,
            h,
            scene::EXTRA,
            |_, _, _| 0.0,
        ),
        Case::PassiveOn => dyke1996::simulate(
            &STRUCTURE,
            &DAMPER,
            &rec,
            Attached::Yes,
            h,
            scene::EXTRA,
            |_, _, _| DAMPER.v_max,
        ),
        Case::ClippedOptimal => {
            let g = dyke1996::design(
                &STRUCTURE,
                scene::Q_DISP,
                scene::R_FORCE,
                scene::GROUND,
                scene::SENSOR,
            );
            dyke1996::clipped_optimal(&STRUCTURE, &DAMPER, &rec, h, 2e-4, &g)
        }
    };
    Peaks {
        displacement: p.displacement,
        drift: p.drift,
        acceleration: p.acceleration,
        force: p.force,
    }
}

/// The highest natural frequency of the structure (rad/s), from its `K` and `M` (the
/// reference's structure; checked here, not assumed).
fn omega_max() -> f64 {
    let k = nalgebra::SMatrix::<f64, 3, 3>::from_fn(|i, j| {
        STRUCTURE.k[i][j] / (STRUCTURE.m[i] * STRUCTURE.m[j]).sqrt()
    });
    k.symmetric_eigenvalues().max().sqrt()
}

/// Uncontrolled, passive-off and passive-on: the crate (average-acceleration `Nonlinear`
/// stepper, the damper's `z` by the trapezoid in the displacement, the filter exactly;
/// peaks read at the step ends) at `h = 1, 0.5, 0.25` ms against the reference (RK4,
/// `h = 5e-5` s, whose own error is below 1e-5: `control_benchmark_reference.rs`).
///
/// The tolerance, from the step: the scheme's relative period error `(ωh)²/12` and the
/// grid's peak-sampling error `(ωh)²/8` (the damper's trapezoid is of the same order) for
/// the structure's highest mode `ω₃ = 148.5 rad/s` sum to `0.21 (ω₃h)²`: bound
/// `(ω₃h)²/3` (7.4e-3 at 1 ms) on every peak, measured at most 6.1e-3 (passive-on
/// accelerations). The order: the largest error at `h/4` is below `1/8` of that at `h`
/// (second order gives `1/16`, first order `1/4`); measured `1/9.5` to `1/16.8`. (Halving
/// once gives ratios from 2.3 to 4.6: the peaks are maxima over a grid, not smooth in `h`.)
#[test]
fn passive_rows_agree_with_the_reference_to_second_order() {
    let ag = short(SHORT);
    let w3 = omega_max();
    assert!((w3 - 148.5).abs() < 0.1, "{w3}");
    for case in [Case::Uncontrolled, Case::PassiveOff, Case::PassiveOn] {
        let r = reference(case, &ag, 5e-5);
        let mut errors = [0.0; 3];
        for (e, h) in errors.iter_mut().zip([1e-3, 5e-4, 2.5e-4]) {
            let c = scene::run(case, &ag, elcentro::DT, h).unwrap();
            let w = worst(&c, &r);
            *e = w.iter().copied().fold(0.0, f64::max);
            let bound = (w3 * h).powi(2) / 3.0;
            println!(
                "{case:?}, h = {h:.2e} s: largest relative difference from the reference: \
                 displacement/drift {:.2e}, acceleration {:.2e}, force {:.2e} (bound {bound:.1e})",
                w[0], w[1], w[2]
            );
            assert!(*e < bound, "{case:?} h {h}: {w:?}");
        }
        println!(
            "{case:?}: error ratio h/(h/2) {:.2}, h/(h/4) {:.1}",
            errors[0] / errors[1],
            errors[0] / errors[2]
        );
        assert!(errors[0] / errors[2] > 8.0, "{case:?}: {errors:?}");
    }
}

/// Clipped-optimal: the crate's discrete LQG at 1 kHz (the design's continuous weights
/// sampled exactly, the one-sample computation delay, the voltage held from the next
/// sample) against the reference's continuous LQG at 5 kHz without delay, the same ASSUMED
/// weights and noise intensities. Not the same controller, so not the same peaks: the
/// gains differ by `O(h)` between the discrete and continuous designs, and the switching
/// instants of the on/off law move by up to a controller period (1 ms against 0.2 ms,
/// plus the 1 ms delay); the switching changes the force by jumps, so accelerations move
/// most. The difference does not shrink with the plant's step (it is the controller's),
/// which is checked: at `h = 1` and `0.25` ms the crate's displacement, drift and force
/// peaks agree to 1e-2 relative (measured 2.6e-3, 1.1e-3), its accelerations to 6e-2
/// (measured 4.4e-2: a force jump read one plant step apart); regression pins. The differences from the reference
/// are printed and pinned (displacement/drift below 10 %, accelerations below 25 %,
/// force below 12 %: measured 5.4 %, 18 %, 7.8 %; regression pins); both controllers
/// lower storey 1's drift (where the damper acts) below the uncontrolled run's. (Over this
/// opening part both RAISE storey 3's drift, 0.37 and 0.35 mm against 0.29 mm: printed,
/// not hidden; over the whole record every drift is lowered, `full_record_rows`.)
#[test]
fn clipped_optimal_row_against_the_reference_design() {
    let ag = short(SHORT);
    let r = reference(Case::ClippedOptimal, &ag, 5e-5);
    let c = scene::run(Case::ClippedOptimal, &ag, elcentro::DT, 1e-3).unwrap();
    let fine = scene::run(Case::ClippedOptimal, &ag, elcentro::DT, 2.5e-4).unwrap();
    let bare = scene::run(Case::Uncontrolled, &ag, elcentro::DT, 1e-3).unwrap();
    let w = worst(&c, &r);
    let self_w = worst(&c, &fine);
    println!(
        "clipped-optimal, crate (1 kHz, discrete, delayed) against the reference (5 kHz, \
         continuous): displacement/drift {:.2e}, acceleration {:.2e}, force {:.2e}",
        w[0], w[1], w[2]
    );
    println!(
        "clipped-optimal, crate at h = 1 ms against 0.25 ms: displacement/drift {:.2e}, \
         acceleration {:.2e}, force {:.2e}",
        self_w[0], self_w[1], self_w[2]
    );
    assert!(
        w[0] < 0.10 && w[1] < 0.25 && w[2] < 0.12,
        "{w:?} (regression pins)"
    );
    assert!(
        self_w[0] < 1e-2 && self_w[1] < 6e-2 && self_w[2] < 1e-2,
        "{self_w:?} (regression pins)"
    );
    for i in 0..3 {
        println!(
            "drift {i}: crate {:.5} reference {:.5} uncontrolled {:.5} (m)",
            c.drift[i], r.drift[i], bare.drift[i]
        );
    }
    assert!(c.drift[0] < bare.drift[0] && r.drift[0] < bare.drift[0]);
}

/// The whole record (the table of `docs/control.md`): the passive rows at `h = 1` and
/// `0.5` ms against the reference (RK4, `h = 5e-5` s): second order — halving the step
/// divides the largest difference of each row by more than 3 (measured 3.7 to 4.6; 4 for
/// second order, 2 for first); and the clipped-optimal runs, the crate's and the
/// reference's, lower every drift below the uncontrolled run's.
#[test]
#[ignore = "release stage: the 17 s record, 7 crate runs and 4 RK4 reference runs (~1 s in release)"]
fn full_record_rows() {
    let ag = elcentro::AG_F64.to_vec();
    let bare = scene::run(Case::Uncontrolled, &ag, elcentro::DT, 1e-3).unwrap();
    for case in [Case::Uncontrolled, Case::PassiveOff, Case::PassiveOn] {
        let r = reference(case, &ag, 5e-5);
        let e: Vec<f64> = [1e-3, 5e-4]
            .iter()
            .map(|&h| {
                let c = scene::run(case, &ag, elcentro::DT, h).unwrap();
                worst(&c, &r).iter().copied().fold(0.0, f64::max)
            })
            .collect();
        println!(
            "{case:?}, whole record: largest relative difference {:.2e} at 1 ms, {:.2e} at 0.5 ms, ratio {:.2}",
            e[0],
            e[1],
            e[0] / e[1]
        );
        assert!(e[0] / e[1] > 3.0, "{case:?}: {e:?}");
    }
    let c = scene::run(Case::ClippedOptimal, &ag, elcentro::DT, 1e-3).unwrap();
    let r = reference(Case::ClippedOptimal, &ag, 5e-5);
    for i in 0..3 {
        println!(
            "drift {i}: crate {:.5} reference {:.5} uncontrolled {:.5} (m)",
            c.drift[i], r.drift[i], bare.drift[i]
        );
        assert!(c.drift[i] < bare.drift[i] && r.drift[i] < bare.drift[i]);
    }
}
