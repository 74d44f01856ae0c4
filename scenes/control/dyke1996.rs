//! The MR-damper benchmark of Dyke, Spencer, Sain & Carlson (1996) run by the crate: the
//! 3-storey model (`docs/control-benchmark-data.md`, UNVERIFIED structure) with
//! [`MrDamper`] of [`MrParameters::DYKE_1996`] between the ground and floor 1, as a
//! [`Coupled`] model under the [`aemstep::Nonlinear`] stepper; El Centro NS played at five
//! times its recorded rate (linear between samples, zero after, 1 s of free vibration).
//!
//! The clipped-optimal case: the crate's [`Controller`] sampled at 1 kHz (`TC`) on the
//! three absolute floor accelerations and the measured damper force, designed on the
//! zero-order-hold model with the one-sample computation delay
//! ([`DesignModel::delayed`]), the continuous weights of the reference (ASSUMED, not the
//! paper's: `Q` on the floor displacements) sampled exactly ([`Weights::sampled`]); the
//! voltage of [`ClippedOptimal`] computed at `t_k` is held from `t_{k+1}` to `t_{k+2}`.
//!
//! Shared by `tests/control_benchmark.rs` and `xtask/src/bin/control_benchmark.rs`.
#![allow(dead_code)]

use aemstep::control::{
    ClippedOptimal, Controller, Coupled, LinearStructure, Link, Lqr, MrDamper, MrParameters,
    Weights,
};
use aemstep::hysteresis::HistoryModel;
use aemstep::models::base_excitation;
use aemstep::nalgebra::{SMatrix, SVector};
use aemstep::observer::{Observer, Outputs, StateSpace, SteadyState};
use aemstep::{Error, NewtonSettings, Nonlinear, State};

/// Floor mass (kg), UNVERIFIED (recalled restatement of the benchmark).
pub const MASS: f64 = 98.3;
/// Stiffness (N/m), UNVERIFIED.
pub const K: [[f64; 3]; 3] = [
    [12.0e5, -6.84e5, 0.0],
    [-6.84e5, 13.7e5, -6.84e5],
    [0.0, -6.84e5, 6.84e5],
];
/// Damping (N·s/m), UNVERIFIED.
pub const C: [[f64; 3]; 3] = [
    [175.0, -50.0, 0.0],
    [-50.0, 100.0, -50.0],
    [0.0, -50.0, 50.0],
];
/// The record's time scale: played at five times its recorded rate.
pub const TIME_SCALE: f64 = 0.2;
/// Free vibration after the record (s).
pub const EXTRA: f64 = 1.0;
/// The controller's sample period (s): 1 kHz.
pub const TC: f64 = 1e-3;
/// ASSUMED continuous weights (the reference's, not the paper's): `Q` on each floor
/// displacement (N²/m²), `R` on the force (1/N² scale), ground-acceleration intensity
/// ((m/s²)²·s), accelerometer noise intensity ((m/s²)²·s).
pub const Q_DISP: f64 = 1e10;
/// See [`Q_DISP`].
pub const R_FORCE: f64 = 1.0;
/// See [`Q_DISP`].
pub const GROUND: f64 = 1.0;
/// See [`Q_DISP`].
pub const SENSOR: f64 = 1e-2;
/// The weight on the command as computed, relative to the sampled `R`
/// ([`Weights::delayed`]).
pub const DECISION: f64 = 1e-3;
/// The controller's force limit (N): far above anything the damper delivers, so the
/// clipped-optimal decision never sees it.
pub const LIMIT: f64 = 1e5;

/// The four configurations of the benchmark's table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Case {
    /// The bare structure.
    Uncontrolled,
    /// The damper at 0 V.
    PassiveOff,
    /// The damper at `V_max`.
    PassiveOn,
    /// The damper under clipped-optimal control.
    ClippedOptimal,
}

/// Peak responses (absolute values): floor displacements relative to the ground (m),
/// inter-storey drifts (m), absolute floor accelerations (m/s²), damper force (N).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Peaks {
    pub displacement: [f64; 3],
    pub drift: [f64; 3],
    pub acceleration: [f64; 3],
    pub force: f64,
}

/// Largest relative difference of the displacement and drift peaks, of the acceleration
/// peaks, and of the force peak.
pub fn worst(a: &Peaks, b: &Peaks) -> [f64; 3] {
    let rel = |x: f64, y: f64| if y > 0.0 { (x - y).abs() / y } else { x.abs() };
    let mut w = [0.0_f64; 3];
    for i in 0..3 {
        w[0] = w[0].max(rel(a.displacement[i], b.displacement[i]));
        w[0] = w[0].max(rel(a.drift[i], b.drift[i]));
        w[1] = w[1].max(rel(a.acceleration[i], b.acceleration[i]));
    }
    w[2] = rel(a.force, b.force);
    w
}

/// The ground acceleration (m/s²) at model time `t`: the record `ag` (m/s², recorded every
/// `dt` s) at `TIME_SCALE`, linear between samples, zero after.
pub fn ground(ag: &[f64], dt: f64, t: f64) -> f64 {
    let s = t / (dt * TIME_SCALE);
    let i = s.floor() as usize;
    if i + 1 < ag.len() {
        let w = s - i as f64;
        (1.0 - w) * ag[i] + w * ag[i + 1]
    } else if i + 1 == ag.len() && s == i as f64 {
        ag[i]
    } else {
        0.0
    }
}

fn mat(r: &[[f64; 3]; 3]) -> SMatrix<f64, 3, 3> {
    SMatrix::from_fn(|i, j| r[i][j])
}

fn structure() -> Result<LinearStructure<f64, 3>, Error> {
    let m = [[MASS, 0.0, 0.0], [0.0, MASS, 0.0], [0.0, 0.0, MASS]];
    LinearStructure::new(&m, &C, &K)
}

/// The controller: the LQR of the delayed zero-order-hold model with the sampled ASSUMED
/// weights, the observer's steady-state Kalman gain (the ground acceleration as process
/// noise of variance `GROUND/TC` per sample, the accelerometers' noise `SENSOR/TC`).
pub fn controller() -> Result<Controller<f64, 6, 1, 3>, Error> {
    let m = SMatrix::<f64, 3, 3>::identity() * MASS;
    // The damper's internal force f acts on floor 1 as −f.
    let bf = SMatrix::<f64, 3, 1>::new(-1.0, 0.0, 0.0);
    let mrows = [[MASS, 0.0, 0.0], [0.0, MASS, 0.0], [0.0, 0.0, MASS]];
    let bg = SMatrix::<f64, 3, 1>::from_fn(|i, _| base_excitation(&mrows)[i][0]);
    let ss = StateSpace::<3, 6, 1>::zero_order_hold(&m, &mat(&C), &mat(&K), &bf, TC)?;
    let ssg = StateSpace::<3, 6, 1>::zero_order_hold(&m, &mat(&C), &mat(&K), &bg, TC)?;
    // ẋ = F x + G f, x = [u; v].
    let mut f = [[0.0; 6]; 6];
    let mut g = [[0.0; 1]; 6];
    for i in 0..3 {
        f[i][3 + i] = 1.0;
        for j in 0..3 {
            f[3 + i][j] = -K[i][j] / MASS;
            f[3 + i][3 + j] = -C[i][j] / MASS;
        }
    }
    g[3][0] = -1.0 / MASS;
    let mut q = [[0.0; 6]; 6];
    for (i, row) in q.iter_mut().enumerate().take(3) {
        row[i] = Q_DISP;
    }
    let continuous = Weights::new(&q, &[[R_FORCE]]);
    let (model, w) = Weights::sampled::<7>(&continuous, &f, &g, TC)?;
    let decision = [[DECISION * w.r[0][0]]];
    let lqr = Lqr::from_parts(&model.delayed::<7>()?, &w.delayed::<7>(&decision)?)?;
    let sensors = ss.outputs(&Outputs::accelerations(Outputs::<3, 1, 3>::select([
        0, 1, 2,
    ])))?;
    let qn = SMatrix::<f64, 6, 6>::from_fn(|i, j| ssg.input_noise(&[[GROUND / TC]])[i][j])
        + SMatrix::identity() * 1e-14;
    let rn = SMatrix::<f64, 3, 3>::identity() * (SENSOR / TC);
    let kf = SteadyState::new(&ss, &sensors, &qn, &rn)?;
    let obs = Observer::new(&ss, &sensors, &kf.gain_matrix())?;
    Controller::new(obs, &lqr.gain_matrix(), &[LIMIT])
}

/// Steps `model` over the record (`samples` of it) and `EXTRA` s after with the
/// [`Nonlinear`] stepper of step `h`, from rest; `each(model, state, history, ag, n)` runs
/// before step `n + 1` (at `t_n`) and returns the damper force there (N). Peaks at `t = 0`
/// and at every step's end.
fn simulate<M: HistoryModel<f64, 3>>(
    model: &mut M,
    ag: &[f64],
    dt: f64,
    h: f64,
    mut each: impl FnMut(&mut M, &State<f64, 3>, &M::History, f64, usize) -> Result<f64, Error>,
) -> Result<Peaks, Error> {
    let stepper = Nonlinear::new(h, NewtonSettings::default())?;
    let load = |a: f64| SVector::<f64, 3>::from_element(-MASS * a);
    let zero = SVector::zeros();
    let duration = (ag.len() - 1) as f64 * dt * TIME_SCALE + EXTRA;
    let steps = (duration / h).round() as usize;
    let h0 = model.initial_history();
    let (mut s, mut hist) =
        stepper.start_with_history(&*model, &zero, &zero, &load(ground(ag, dt, 0.0)), &h0)?;
    let mut p = Peaks::default();
    for n in 0..=steps {
        let t = n as f64 * h;
        let a_g = ground(ag, dt, t);
        let force = each(model, &s, &hist, a_g, n)?;
        for i in 0..3 {
            p.displacement[i] = p.displacement[i].max(s.u()[i].abs());
            let below = if i == 0 { 0.0 } else { s.u()[i - 1] };
            p.drift[i] = p.drift[i].max((s.u()[i] - below).abs());
            p.acceleration[i] = p.acceleration[i].max((s.a()[i] + a_g).abs());
        }
        p.force = p.force.max(force.abs());
        if n == steps {
            break;
        }
        let next = load(ground(ag, dt, t + h));
        stepper.try_step_with_history(&*model, &mut s, &mut hist, &next)?;
    }
    Ok(p)
}

/// One configuration of the benchmark over `ag` (m/s², recorded every `dt` s), the plant
/// stepped at `h` (s; for [`Case::ClippedOptimal`] `TC` must be a multiple of it).
pub fn run(case: Case, ag: &[f64], dt: f64, h: f64) -> Result<Peaks, Error> {
    let damper = MrDamper::<f64>::new(&MrParameters::DYKE_1996)?;
    match case {
        Case::Uncontrolled => {
            let mut bare = structure()?;
            simulate(&mut bare, ag, dt, h, |_, _, _, _, _| Ok(0.0))
        }
        Case::PassiveOff | Case::PassiveOn => {
            let mut model = if case == Case::PassiveOn {
                Coupled::passive_on(structure()?, damper, Link::Ground(0), h)?
            } else {
                Coupled::passive_off(structure()?, damper, Link::Ground(0), h)?
            };
            simulate(&mut model, ag, dt, h, |m, _, hist, _, _| {
                Ok(m.delivered_force(hist))
            })
        }
        Case::ClippedOptimal => {
            let every = (TC / h).round() as usize;
            if every == 0 || ((every as f64) * h - TC).abs() > 1e-12 * TC {
                return Err(Error::InvalidTimeStep);
            }
            let ctl = controller()?;
            let law = ClippedOptimal::<f64, 1>::new(MrParameters::DYKE_1996.v_max)?;
            let mut cs = ctl.start_at_rest();
            let mut pending = 0.0; // the voltage computed at the last sample (V)
            let mut model = Coupled::passive_off(structure()?, damper, Link::Ground(0), h)?;
            simulate(&mut model, ag, dt, h, |m, s, hist, a_g, n| {
                let f = m.delivered_force(hist);
                if n % every == 0 {
                    m.set_command(pending)?; // computed at t_{k−1}, held from t_k
                    let y = SVector::<f64, 3>::from_fn(|i, _| s.a()[i] + a_g);
                    let fv = SVector::<f64, 1>::new(f);
                    let cmd = ctl.try_step(&mut cs, &y, &fv, false)?;
                    pending = law.command(&SVector::<f64, 1>::new(cmd.force[0]), &fv)?[0];
                }
                Ok(f)
            })
        }
    }
}
