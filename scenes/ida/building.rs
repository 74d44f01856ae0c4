//! The incremental dynamic analysis (IDA) scene: the benchmark 5-storey building
//! (`models::five_storey_building`: M, C, K) with every storey bilinear
//! (`FIVE_STOREY_STIFFNESS`, yield force [`FY`], hardening [`ALPHA`]) under El Centro 1940
//! NS scaled by [`scales`] (0.02, 0.04, …, 2.0), the record linearly interpolated to
//! h = 1/[`RATE`] s, stepped by `Nonlinear::<f64, 5>` with Newton up to 50 iterations to
//! 1e-12. One run returns the peak absolute storey drift.
//!
//! Shared by `xtask/benches/batch.rs` (the scaling benchmark), `tests/batch.rs` and
//! `xtask/src/bin/nonlinear_bench.rs` (the step beside OpenSees, record ×[`SCALE`]); the
//! record is passed in (`elcentro::AG_F64`, `scenes/modal/elcentro.rs`).
#![allow(dead_code)] // each includer uses a different subset

use aemstep::hysteresis::{Bilinear, HistoryModel, ShearBuilding};
use aemstep::nalgebra::SVector;
use aemstep::{Error, NewtonSettings, Nonlinear, models};

/// Storeys.
pub const N: usize = 5;
/// Floor mass (kg), every floor.
pub const MASS: f64 = models::FIVE_STOREY_MASS;
/// Storey stiffness (N/m), every storey.
pub const STIFFNESS: f64 = models::FIVE_STOREY_STIFFNESS;
/// Rayleigh damping ratio in modes 1 and 2.
pub const XI: f64 = models::FIVE_STOREY_DAMPING;
/// The record scale of the single-run benchmark (`nonlinear_bench`, the OpenSees twin).
pub const SCALE: f64 = 2.0;
/// Every storey's yield force (N): yield drift `FY / FIVE_STOREY_STIFFNESS` = 3 cm.
pub const FY: f64 = 3.0e6;
/// Post-yield stiffness ratio.
pub const ALPHA: f64 = 0.05;
/// Steps per second (Hz): h = 0.005 s, four steps per record sample.
pub const RATE: u64 = 200;
/// The time step (s).
pub const H: f64 = 1.0 / RATE as f64;
/// Newton: at most this many iterations a step …
pub const NEWTON_ITERATIONS: u32 = 50;
/// … to this tolerance.
pub const NEWTON_TOLERANCE: f64 = 1e-12;
/// Intensities of the analysis.
pub const INTENSITIES: usize = 100;

/// The building type.
pub type Building = ShearBuilding<f64, Bilinear<f64>, N>;

/// The record scale factors `k/50`, `k = 1 … 100`: 0.02, 0.04, …, 2.0.
pub fn scales() -> Vec<f64> {
    (1..=INTENSITIES).map(|k| k as f64 / 50.0).collect()
}

/// The yielding building: `five_storey_building`'s masses and damping `C`, every storey
/// `Bilinear::new(FIVE_STOREY_STIFFNESS, FY, ALPHA)`.
pub fn building() -> Result<Building, Error> {
    let (m, c, _k) = models::five_storey_building();
    let law = Bilinear::<f64>::new(models::FIVE_STOREY_STIFFNESS, FY, ALPHA)?;
    ShearBuilding::new(models::floor_masses(&m), [law; N], &c)
}

/// The stepper: h = [`H`], Newton up to [`NEWTON_ITERATIONS`] to [`NEWTON_TOLERANCE`].
pub fn stepper() -> Result<Nonlinear<f64, N>, Error> {
    Nonlinear::new(
        H,
        NewtonSettings::up_to(NEWTON_ITERATIONS, NEWTON_TOLERANCE),
    )
}

/// The ground acceleration (m/s²) at step `n` (t = n h): the record `ag` (m/s², at 0.02 s)
/// times `scale`, linear between its samples (the record's position `50 n / RATE` formed
/// exactly in integers, as `scenes/hybrid/scene.rs` `ground`); zero from its last sample on.
pub fn ground(ag: &[f64], scale: f64, n: u64) -> f64 {
    let pos = n * 50;
    let (i, rem) = ((pos / RATE) as usize, pos % RATE);
    if i + 1 >= ag.len() {
        return 0.0;
    }
    let frac = rem as f64 / RATE as f64;
    scale * (ag[i] + frac * (ag[i + 1] - ag[i]))
}

/// Steps of a whole run: every step before the record's last sample, `(samples − 1)·RATE/50
/// − 1` (15 975 for El Centro's 3 995 samples: t = 0.005 … 79.875 s).
pub const fn steps(samples: usize) -> u64 {
    (samples as u64 - 1) * RATE / 50 - 1
}

/// One analysis: the building at rest under the record ×`scale` for `steps` steps; the
/// peak absolute storey drift over the storeys and steps (m). Errors: a step that fails
/// (`Error::NotConverged`, …).
pub fn peak_drift(
    building: &Building,
    stepper: &Nonlinear<f64, N>,
    ag: &[f64],
    scale: f64,
    steps: u64,
) -> Result<f64, Error> {
    let zero = SVector::<f64, N>::zeros();
    let (mut s, mut history) = stepper.start_with_history(
        building,
        &zero,
        &zero,
        &building.ground_load(ground(ag, scale, 0)),
        &building.initial_history(),
    )?;
    let mut peak = 0.0f64;
    for n in 1..=steps {
        let p = building.ground_load(ground(ag, scale, n));
        stepper.try_step_with_history(building, &mut s, &mut history, &p)?;
        peak = Building::drifts(s.u())
            .iter()
            .fold(peak, |m, d| m.max(d.abs()));
    }
    Ok(peak)
}

/// [`peak_drift`] of up to `L` runs at once, one a lane of `lanes` (`aemstep::lanes`), bit
/// for bit: `jobs` are `(record, scale, steps)`, run in groups of `L`; each result is what
/// [`peak_drift`] returns for the job.
pub fn peak_drifts<const L: usize>(
    building: &Building,
    lanes: &aemstep::lanes::LaneStepper<f64, N, L>,
    jobs: &[(&[f64], f64, u64)],
) -> Vec<Result<f64, Error>> {
    let mut out = Vec::with_capacity(jobs.len());
    for group in jobs.chunks(L) {
        let steps: [u64; L] = core::array::from_fn(|l| group.get(l).map_or(0, |j| j.2));
        let mut peak = [0.0f64; L];
        let outcome = lanes.run(
            building,
            steps,
            |l, n| group.get(l).map_or(0.0, |j| ground(j.0, j.1, n)),
            |state, stepped| {
                let u = state.u();
                for l in 0..L {
                    if stepped[l] {
                        for i in 0..N {
                            let d = if i == 0 {
                                u[0][l]
                            } else {
                                u[i][l] - u[i - 1][l]
                            };
                            peak[l] = peak[l].max(d.abs());
                        }
                    }
                }
            },
        );
        for l in 0..group.len() {
            out.push(outcome[l].map(|()| peak[l]).map_err(|f| f.error));
        }
    }
    out
}
