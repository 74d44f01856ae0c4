//! Vibration control (`aemstep::control`): the zero-order-hold design model of a building,
//! the discrete LQR (with the one-sample computation delay), the MR damper of Dyke et al.
//! (1996) driven by a prescribed motion, and a building with one MR damper under a
//! ground-acceleration record (passive off, passive on, or the clipped-optimal law on a
//! state-feedback gain).
//!
//! **Sizes.** Buildings take the `by_size!` sizes; a design model takes 1 to
//! [`MAX_DESIGN_STATES`] states and 1 to [`MAX_CONTROL_INPUTS`] inputs (`by_design!`).

use aemstep::control::{
    ClippedOptimal, Coupled, DesignModel, Device, LinearStructure, Link, Lqr, MrDamper,
    MrParameters, Weights,
};
use aemstep::hysteresis::HistoryModel;
use aemstep::nalgebra::{SMatrix, SVector};
use aemstep::observer::{Outputs, StateSpace, SteadyState};
use aemstep::{Error, NewtonSettings};
use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use std::sync::atomic::AtomicBool;

use crate::{
    Fail, Res, SIZES, at, buffer, fits, interruptible, matrix, out1, out2, read1, read2, rows,
    shape, square, stopped, work_units,
};

/// The largest state size of a design model (`lqr`): 12 (a 6-storey building's `[u; v]`;
/// with the computation delay the design has `S + I` states).
pub const MAX_DESIGN_STATES: usize = 12;

/// The most control inputs of a design model (`zero_order_hold`, `lqr`).
pub const MAX_CONTROL_INPUTS: usize = 2;

/// The number of `MrParameters` values, in its field order.
const MR_PARAMETERS: usize = 10;

/// Call `$f::<S, I, S + I>(args…)` for the run-time sizes `($s, $i)`, or fail with
/// `UnsupportedSize`.
macro_rules! by_design {
    ($s:expr, $i:expr, $f:ident ( $($arg:expr),* $(,)? )) => {
        match ($s, $i) {
            (1, 1) => $f::<1, 1, 2>($($arg),*),
            (2, 1) => $f::<2, 1, 3>($($arg),*),
            (3, 1) => $f::<3, 1, 4>($($arg),*),
            (4, 1) => $f::<4, 1, 5>($($arg),*),
            (5, 1) => $f::<5, 1, 6>($($arg),*),
            (6, 1) => $f::<6, 1, 7>($($arg),*),
            (7, 1) => $f::<7, 1, 8>($($arg),*),
            (8, 1) => $f::<8, 1, 9>($($arg),*),
            (9, 1) => $f::<9, 1, 10>($($arg),*),
            (10, 1) => $f::<10, 1, 11>($($arg),*),
            (11, 1) => $f::<11, 1, 12>($($arg),*),
            (12, 1) => $f::<12, 1, 13>($($arg),*),
            (1, 2) => $f::<1, 2, 3>($($arg),*),
            (2, 2) => $f::<2, 2, 4>($($arg),*),
            (3, 2) => $f::<3, 2, 5>($($arg),*),
            (4, 2) => $f::<4, 2, 6>($($arg),*),
            (5, 2) => $f::<5, 2, 7>($($arg),*),
            (6, 2) => $f::<6, 2, 8>($($arg),*),
            (7, 2) => $f::<7, 2, 9>($($arg),*),
            (8, 2) => $f::<8, 2, 10>($($arg),*),
            (9, 2) => $f::<9, 2, 11>($($arg),*),
            (10, 2) => $f::<10, 2, 12>($($arg),*),
            (11, 2) => $f::<11, 2, 13>($($arg),*),
            (12, 2) => $f::<12, 2, 14>($($arg),*),
            (s, i) => Err(Fail::Size(format!(
                "a design model of {s} states and {i} inputs: this build takes 1 to {} states \
                 and 1 to {} inputs",
                MAX_DESIGN_STATES, MAX_CONTROL_INPUTS
            ))),
        }
    };
}

/// A `rows×cols` array, checked.
fn sized(a: &PyReadonlyArray2<'_, f64>, r: usize, c: usize, name: &str) -> Res<Vec<f64>> {
    let (v, rr, cc) = read2(a);
    if rr != r || cc != c {
        return shape(format!("{name} must be {r}x{c}, got {rr}x{cc}"));
    }
    Ok(v)
}

/// Row-major `R×C` rows of a row-major slice.
fn table<const R: usize, const C: usize>(v: &[f64]) -> [[f64; C]; R] {
    core::array::from_fn(|i| core::array::from_fn(|j| v[i * C + j]))
}

fn flat<const R: usize, const C: usize>(a: &[[f64; C]; R]) -> Vec<f64> {
    a.iter().flatten().copied().collect()
}

// ---------------------------------------------------------------------------------------
// The design model.

fn zoh_ni<const N: usize, const S: usize, const I: usize>(
    m: &[f64],
    c: &[f64],
    k: &[f64],
    b: &[f64],
    h: f64,
) -> Res<(Vec<f64>, Vec<f64>)> {
    let b = SMatrix::<f64, N, I>::from_fn(|i, j| b[i * I + j]);
    let ss = StateSpace::<N, S, I>::zero_order_hold(
        &matrix::<N>(m),
        &matrix::<N>(c),
        &matrix::<N>(k),
        &b,
        h,
    )?;
    let design = DesignModel::from_state_space(&ss);
    Ok((flat(&design.phi), flat(&design.gamma)))
}

#[allow(clippy::type_complexity)]
fn zoh_n<const N: usize, const S: usize>(
    job: &(Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>, usize, f64),
) -> Res<(Vec<f64>, Vec<f64>)> {
    let (m, c, k, b, inputs, h) = job;
    match inputs {
        1 => zoh_ni::<N, S, 1>(m, c, k, b, *h),
        2 => zoh_ni::<N, S, 2>(m, c, k, b, *h),
        i => Err(Fail::Size(format!(
            "{i} inputs: this build takes 1 to {MAX_CONTROL_INPUTS}"
        ))),
    }
}

/// The exact sampled-data model of `M u'' + C u' + K u = B f` with the force `f` held over
/// each step of `h` (zero-order hold: `aemstep::observer::StateSpace::zero_order_hold`,
/// `aemstep::control::DesignModel::from_state_space`), the state `x = [u; v]`.
///
/// Arguments: `m`, `c`, `k` (kg, N·s/m, N/m; `n×n`, `n` in `SIZES`), `b` (`n×inputs`, 1 to
/// `MAX_CONTROL_INPUTS` columns: the force distribution, dimensionless), `h` (s, finite,
/// `> 0`). Returns `(phi, gamma)`: `Φ` (`2n×2n`) and `Γ` (`2n×inputs`, m/N and m/s/N).
/// Raises `InvalidTimeStep`, `SingularMass`, `NonFiniteInput`, … Cost: one matrix
/// exponential of size `4n`.
#[pyfunction]
#[pyo3(signature = (m, c, k, b, h))]
#[allow(clippy::type_complexity)]
fn zero_order_hold<'py>(
    py: Python<'py>,
    m: PyReadonlyArray2<'py, f64>,
    c: PyReadonlyArray2<'py, f64>,
    k: PyReadonlyArray2<'py, f64>,
    b: PyReadonlyArray2<'py, f64>,
    h: f64,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
    let n = m.as_array().dim().0;
    let inputs = b.as_array().dim().1;
    let prepare = || -> Res<_> {
        Ok((
            square(&m, n, "m")?,
            square(&c, n, "c")?,
            square(&k, n, "k")?,
            sized(&b, n, inputs, "b")?,
            inputs,
            h,
        ))
    };
    let job = prepare().map_err(|f| f.raise(py))?;
    let (phi, gamma) = py
        .detach(|| by_size!(n, zoh_n(&job)))
        .map_err(|f| f.raise(py))?;
    Ok((out2(py, phi, 2 * n), out2(py, gamma, inputs)))
}

// ---------------------------------------------------------------------------------------
// The regulator.

struct LqrJob {
    phi: Vec<f64>,
    gamma: Vec<f64>,
    q: Vec<f64>,
    r: Vec<f64>,
    cross: Vec<f64>,
    /// The decision weight of the delayed design (`None`: no delay).
    delay: Option<Vec<f64>>,
}

/// `(K, P, Φ − Γ K, radius bound, iterations)`, row-major.
type LqrOut = (Vec<f64>, Vec<f64>, Vec<f64>, f64, u32);

fn lqr_out<const S: usize, const I: usize>(l: &Lqr<S, I>) -> LqrOut {
    (
        flat(&l.gain),
        flat(&l.cost),
        flat(&l.closed_loop),
        l.radius_bound,
        l.iterations,
    )
}

fn lqr_sized<const S: usize, const I: usize, const Z: usize>(job: &LqrJob) -> Res<LqrOut> {
    let model = DesignModel::<S, I> {
        phi: table(&job.phi),
        gamma: table(&job.gamma),
    };
    let weights = Weights::<S, I> {
        q: table(&job.q),
        r: table(&job.r),
        cross: table(&job.cross),
    };
    match &job.delay {
        None => Ok(lqr_out(&Lqr::from_parts(&model, &weights)?)),
        Some(decision) => {
            let design = model.delayed::<Z>()?;
            let w = weights.delayed::<Z>(&table(decision))?;
            Ok(lqr_out(&Lqr::from_parts(&design, &w)?))
        }
    }
}

/// The discrete linear–quadratic regulator (`aemstep::control::Lqr::from_parts`) of
/// `x_{k+1} = Φ x_k + Γ u_k` for the cost `Σ xᵀQx + 2xᵀSu + uᵀRu`, `u = −K x`.
///
/// Arguments: `phi` (`S×S`, 1 to `MAX_DESIGN_STATES` states), `gamma` (`S×I`, 1 to
/// `MAX_CONTROL_INPUTS` inputs), `q` (`S×S`, symmetric positive semidefinite), `r` (`I×I`,
/// symmetric positive definite), `s` (`S×I` cross weight), `decision` (`I×I`, symmetric
/// positive definite, or `None`): with `decision` the design is on the model with the
/// one-sample computation delay, `z = [x; u_{k−1}]` (`DesignModel::delayed`,
/// `Weights::delayed` with this weight on the command as computed), and `K` is `I×(S+I)`.
///
/// Returns `(K, P, closed_loop, radius_bound, iterations)`: the gain, the Riccati solution,
/// `Φ − ΓK`, the certified bound on its spectral radius (`< 1`), and the doubling
/// iterations. Raises `InvalidParameter` (`.parameter == "Weight"`), `NonFiniteInput`,
/// `RiccatiNotConverged`, `NotStabilizing`, `OperatorOverflow`, `UnsupportedSize`.
/// Cost: `O(S³)` flops per doubling iteration (10–25 of them) and the certificate.
#[pyfunction]
#[pyo3(signature = (phi, gamma, q, r, s, decision=None))]
#[allow(clippy::type_complexity)]
fn lqr<'py>(
    py: Python<'py>,
    phi: PyReadonlyArray2<'py, f64>,
    gamma: PyReadonlyArray2<'py, f64>,
    q: PyReadonlyArray2<'py, f64>,
    r: PyReadonlyArray2<'py, f64>,
    s: PyReadonlyArray2<'py, f64>,
    decision: Option<PyReadonlyArray2<'py, f64>>,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    f64,
    u32,
)> {
    let states = phi.as_array().dim().0;
    let inputs = gamma.as_array().dim().1;
    let prepare = || -> Res<LqrJob> {
        Ok(LqrJob {
            phi: square(&phi, states, "phi")?,
            gamma: sized(&gamma, states, inputs, "gamma")?,
            q: square(&q, states, "q")?,
            r: square(&r, inputs, "r")?,
            cross: sized(&s, states, inputs, "s")?,
            delay: match &decision {
                None => None,
                Some(d) => Some(square(d, inputs, "decision")?),
            },
        })
    };
    let job = prepare().map_err(|f| f.raise(py))?;
    let (k, p, cl, radius, iterations) = py
        .detach(|| by_design!(states, inputs, lqr_sized(&job)))
        .map_err(|f| f.raise(py))?;
    let z = if job.delay.is_some() {
        states + inputs
    } else {
        states
    };
    Ok((
        out2(py, k, z),
        out2(py, p, z),
        out2(py, cl, z),
        radius,
        iterations,
    ))
}

// ---------------------------------------------------------------------------------------
// Output feedback: the observer gain and the regulator gain of one model.

/// Which physical outputs the sensors read.
#[derive(Clone, Copy)]
enum Sensed {
    Displacements,
    Velocities,
    Accelerations,
}

struct LqgJob {
    m: Vec<f64>,
    c: Vec<f64>,
    k: Vec<f64>,
    b: Vec<f64>,
    h: f64,
    sensors: Vec<usize>,
    sensed: Sensed,
    q: Vec<f64>,
    r: f64,
    w: Vec<f64>,
    v: Vec<f64>,
}

/// `(L, K, P_filter, P_regulator, radius bound)`, row-major.
type LqgOut = (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>, f64);

fn lqg_no<const N: usize, const S: usize, const O: usize>(job: &LqgJob) -> Res<LqgOut> {
    let b = SMatrix::<f64, N, 1>::from_column_slice(&job.b);
    let ss = StateSpace::<N, S, 1>::zero_order_hold(
        &matrix::<N>(&job.m),
        &matrix::<N>(&job.c),
        &matrix::<N>(&job.k),
        &b,
        job.h,
    )?;
    let y = Outputs::<N, 1, O>::select(core::array::from_fn(|o| job.sensors[o]));
    let outputs = match job.sensed {
        Sensed::Displacements => Outputs::displacements(y),
        Sensed::Velocities => Outputs::velocities(y),
        Sensed::Accelerations => Outputs::accelerations(y),
    };
    let meas = ss.outputs(&outputs)?;
    let filter = SteadyState::<S, O>::from_parts(&ss, &meas, &table(&job.w), &table(&job.v))?;
    let design = DesignModel::from_state_space(&ss);
    let weights = Weights::<S, 1>::new(&table(&job.q), &[[job.r]]);
    let reg = Lqr::from_parts(&design, &weights)?;
    Ok((
        flat(&filter.gain),
        flat(&reg.gain),
        flat(&filter.covariance),
        flat(&reg.cost),
        reg.radius_bound,
    ))
}

fn lqg_n<const N: usize, const S: usize>(job: &LqgJob) -> Res<LqgOut> {
    match job.sensors.len() {
        1 => lqg_no::<N, S, 1>(job),
        2 if N >= 2 => lqg_no::<N, S, 2>(job),
        3 if N >= 3 => lqg_no::<N, S, 3>(job),
        o => Err(Fail::Size(format!(
            "{o} sensors on {N} floors: this build takes 1 to {} sensors",
            crate::MAX_SENSORS.min(N)
        ))),
    }
}

/// The two gains of an output-feedback (LQG) controller of a building driven by one
/// control force: the steady-state Kalman gain of its zero-order-hold model
/// (`aemstep::observer::SteadyState`) and the LQR gain (`aemstep::control::Lqr`), as
/// `aemstep::control::Controller` combines them.
///
/// Arguments: `m`, `c`, `k` (kg, N·s/m, N/m; `n×n`, `n` in `SIZES`), `b` (`n`: the control
/// force's distribution), `h` (s); `sensors` (0-based DOFs, 1 to `MAX_SENSORS`, distinct),
/// `sensed` — `"displacements"`, `"velocities"` or `"accelerations"` (relative); `q`
/// (`2n×2n`) and `r` (scalar, `> 0`) — the regulator's weights on `x = [u; v]` and the
/// force; `w` (`2n×2n`) and `v` (`sensors×sensors`) — the process and measurement noise
/// covariances of the discrete model.
///
/// Returns `(L, K, P_filter, P_regulator, radius_bound)`: the observer gain
/// `L = P Hᵀ (H P Hᵀ + V)⁻¹` (`2n×sensors`), the regulator gain (`1×2n`, `u = −K x̂`), the
/// two Riccati solutions and the regulator's certified spectral-radius bound. Raises
/// `InvalidCovariance`, `InvalidParameter` (`"Weight"`), `RiccatiNotConverged`,
/// `NotStabilizing`, … Cost: two Riccati solutions of size `2n`.
#[pyfunction]
#[pyo3(signature = (m, c, k, b, h, sensors, sensed, q, r, w, v))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn lqg<'py>(
    py: Python<'py>,
    m: PyReadonlyArray2<'py, f64>,
    c: PyReadonlyArray2<'py, f64>,
    k: PyReadonlyArray2<'py, f64>,
    b: PyReadonlyArray1<'py, f64>,
    h: f64,
    sensors: Vec<usize>,
    sensed: &str,
    q: PyReadonlyArray2<'py, f64>,
    r: f64,
    w: PyReadonlyArray2<'py, f64>,
    v: PyReadonlyArray2<'py, f64>,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    f64,
)> {
    let n = m.as_array().dim().0;
    let o = sensors.len();
    let prepare = || -> Res<LqgJob> {
        let b = read1(&b);
        if b.len() != n {
            return shape(format!("b must have {n} values, got {}", b.len()));
        }
        if sensors.is_empty() || sensors.iter().any(|&s| s >= n) {
            return shape(format!(
                "sensors must be 1 or more DOF indices in 0..{n}, got {sensors:?}"
            ));
        }
        let mut sorted = sensors.clone();
        sorted.sort_unstable();
        sorted.dedup();
        if sorted.len() != o {
            return shape(format!("sensors must be distinct, got {sensors:?}"));
        }
        let sensed = match sensed {
            "displacements" => Sensed::Displacements,
            "velocities" => Sensed::Velocities,
            "accelerations" => Sensed::Accelerations,
            s => {
                return shape(format!(
                    "sensed must be \"displacements\", \"velocities\" or \"accelerations\", got {s:?}"
                ));
            }
        };
        Ok(LqgJob {
            m: square(&m, n, "m")?,
            c: square(&c, n, "c")?,
            k: square(&k, n, "k")?,
            b,
            h,
            sensors: sensors.clone(),
            sensed,
            q: square(&q, 2 * n, "q")?,
            r,
            w: square(&w, 2 * n, "w")?,
            v: square(&v, o, "v")?,
        })
    };
    let job = prepare().map_err(|f| f.raise(py))?;
    let (l, kk, pf, pr, radius) = py
        .detach(|| by_size!(n, lqg_n(&job)))
        .map_err(|f| f.raise(py))?;
    Ok((
        out2(py, l, o),
        out2(py, kk, 2 * n),
        out2(py, pf, 2 * n),
        out2(py, pr, 2 * n),
        radius,
    ))
}

// ---------------------------------------------------------------------------------------
// The MR damper.

/// `MrParameters` from its 10 values in field order.
fn mr_parameters(p: &[f64]) -> Res<MrParameters> {
    if p.len() != MR_PARAMETERS {
        return shape(format!(
            "params must have {MR_PARAMETERS} values (c0a, c0b, alpha_a, alpha_b, gamma, beta, a, n, eta, v_max), got {}",
            p.len()
        ));
    }
    Ok(MrParameters {
        c0a: p[0],
        c0b: p[1],
        alpha_a: p[2],
        alpha_b: p[3],
        gamma: p[4],
        beta: p[5],
        a: p[6],
        n: p[7],
        eta: p[8],
        v_max: p[9],
    })
}

/// The force of an MR damper (`aemstep::control::MrDamper`, Dyke et al. 1996) driven by a
/// prescribed motion and command voltage.
///
/// Arguments: `x`, `xdot` — the damper's displacement (m) and velocity (m/s) at the
/// samples, `voltage` — the command (V) at the samples, each held over the step that
/// follows and clipped into `[0, V_max]`; `h` — the step (s); `params` — the 10 values
/// `(c0a, c0b, alpha_a, alpha_b, gamma, beta, a, n, eta, v_max)` (SI: N·s/m, N·s/(m·V),
/// N/m, N/(m·V), m⁻ⁿ, m⁻ⁿ, -, -, 1/s, V). The damper starts at rest at `x[0]`
/// (`z = 0`, filtered voltage 0; row 0 reports that state, force 0); step `k` goes from
/// sample `k−1` to `k` with `voltage[k−1]` held.
///
/// Returns `(force, z, filtered_voltage)`: N, m, V, one value per sample. Raises
/// `InvalidMaterial` (`.parameter == "Device"`), `InvalidParameter` (`"Saturation"`),
/// `InvalidTimeStep`, `NonFiniteInput` (a non-finite sample, `.step` set),
/// `NonFiniteState`. Cost: one Bouc–Wen trial and one `exp` per step.
#[pyfunction]
#[pyo3(signature = (x, xdot, voltage, h, params))]
#[allow(clippy::type_complexity)]
fn mr_damper_response<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    xdot: PyReadonlyArray1<'py, f64>,
    voltage: PyReadonlyArray1<'py, f64>,
    h: f64,
    params: Vec<f64>,
) -> PyResult<(
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
)> {
    let (x, xdot, voltage) = (read1(&x), read1(&xdot), read1(&voltage));
    let run = |stop: &AtomicBool| -> Res<(Vec<f64>, Vec<f64>, Vec<f64>)> {
        if x.is_empty() || xdot.len() != x.len() || voltage.len() != x.len() {
            return shape(format!(
                "x, xdot and voltage must have one value per sample (at least one), got {}, {} and {}",
                x.len(),
                xdot.len(),
                voltage.len()
            ));
        }
        let damper = MrDamper::<f64>::new(&mr_parameters(&params)?)?;
        if !(h.is_finite() && h > 0.0) {
            return Err(Error::InvalidTimeStep.into());
        }
        let (lo, hi) = damper.command_limits();
        let mut hist = damper.initial_history();
        hist.z.deformation = x[0];
        if !x[0].is_finite() {
            return Err(Fail::Lib(Error::NonFiniteInput, Some(0)));
        }
        let steps = x.len();
        let (mut f, mut z, mut u) = (buffer(steps, 1)?, buffer(steps, 1)?, buffer(steps, 1)?);
        let mut keep = |hist: &aemstep::control::MrHistory<f64>| {
            f.push(damper.delivered_force(hist));
            z.push(hist.z.z);
            u.push(hist.voltage);
        };
        keep(&hist);
        for n in 1..steps {
            stopped(stop, n)?;
            let v = voltage[n - 1];
            if !(x[n].is_finite() && xdot[n].is_finite() && v.is_finite()) {
                return Err(Fail::Lib(Error::NonFiniteInput, Some(n)));
            }
            let trial = damper.trial(&hist, x[n], xdot[n], v.clamp(lo, hi), h);
            if !trial.force.is_finite() {
                return Err(at(n)(Error::NonFiniteState));
            }
            hist = trial.history;
            keep(&hist);
        }
        Ok((f, z, u))
    };
    let (f, z, u) = interruptible(py, work_units(x.len(), 16, 1), run)?;
    Ok((out1(py, f), out1(py, z), out1(py, u)))
}

// ---------------------------------------------------------------------------------------
// A building with one MR damper.

/// What decides the damper's voltage.
enum Law {
    Off,
    On,
    /// The clipped-optimal law on the desired force `f_c = −K x` (`K`: `1×2n`, of the true
    /// state `x = [u; v]` at each sample).
    Clipped(Vec<f64>),
}

struct MrBuildingJob {
    m: Vec<f64>,
    c: Vec<f64>,
    k: Vec<f64>,
    ag: Vec<f64>,
    h: f64,
    storey: usize,
    params: MrParameters,
    law: Law,
}

/// `u`, `v` (row-major, steps × n), the damper force and the command held from each
/// sample.
type MrBuildingOut = (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>);

fn mr_building_n<const N: usize, const S: usize>(
    job: &MrBuildingJob,
    stop: &AtomicBool,
) -> Res<MrBuildingOut> {
    let structure =
        LinearStructure::<f64, N>::new(&rows::<N>(&job.m), &rows::<N>(&job.c), &rows::<N>(&job.k))?;
    let damper = MrDamper::<f64>::new(&job.params)?;
    let link = match job.storey {
        0 => Link::Ground(0),
        j => Link::Between(j, j - 1),
    };
    // Started at 0 V whatever the law (the damper's filtered voltage 0 at t = 0, as the
    // documented equations start): `"on"` holds V_max from the first step on, and the
    // filter charges from there. (`Coupled::passive_on` would instead start with the
    // filter settled at V_max.)
    let mut model = Coupled::passive_off(structure, damper, link, job.h)?;
    let clipped = ClippedOptimal::<f64, 1>::new(job.params.v_max)?;
    let stepper = model.nonlinear(NewtonSettings::default())?;
    let mass = matrix::<N>(&job.m);
    // The ground-acceleration load −M 1 a_g.
    let load = |ag: f64| -> SVector<f64, N> { -(mass * SVector::<f64, N>::repeat(1.0)) * ag };
    let zero = SVector::<f64, N>::zeros();
    let steps = job.ag.len();
    let (mut s, mut hist) = stepper
        .start_with_history(
            &model,
            &zero,
            &zero,
            &load(job.ag[0]),
            &model.initial_history(),
        )
        .map_err(at(0))?;
    if let Law::On = job.law {
        let on = model.device().command_limits().1;
        model.set_command(on).map_err(at(0))?;
    }
    let (mut u, mut v, mut f, mut cmd) = (
        buffer(steps, N)?,
        buffer(steps, N)?,
        buffer(steps, 1)?,
        buffer(steps, 1)?,
    );
    for n in 0..steps {
        if n > 0 {
            stopped(stop, n)?;
            stepper
                .try_step_with_history(&model, &mut s, &mut hist, &load(job.ag[n]))
                .map_err(at(n))?;
        }
        let delivered = model.delivered_force(&hist);
        if let Law::Clipped(gain) = &job.law {
            let desired: f64 = -(0..N)
                .map(|i| gain[i] * s.u()[i] + gain[N + i] * s.v()[i])
                .sum::<f64>();
            let c = clipped
                .command(&SVector::from([desired]), &SVector::from([delivered]))
                .map_err(at(n))?;
            model.set_command(c[0]).map_err(at(n))?;
        }
        u.extend_from_slice(s.u().as_slice());
        v.extend_from_slice(s.v().as_slice());
        f.push(delivered);
        cmd.push(model.command());
    }
    Ok((u, v, f, cmd))
}

/// A linear building with one MR damper (`aemstep::control::MrDamper` in a
/// `aemstep::control::Coupled` model, stepped by the `Nonlinear` stepper) under a ground
/// acceleration record.
///
/// Arguments: `m`, `c`, `k` (kg, N·s/m, N/m; `n×n`, `n` in `SIZES`), `ag` (m/s², one value
/// per step of `h` s), `storey` — the damper's storey (0: between the ground and floor 0;
/// `j`: between floors `j` and `j−1`), `params` — the damper's 10 values (see
/// `mr_damper_response`), `law` — `"off"` (0 V), `"on"` (`V_max`), or `"clipped"`: the
/// clipped-optimal law (`ClippedOptimal`) on the desired force `f_c = −K x` of the state
/// `x = [u; v]` at each sample, `gain` `K` (`1×2n`; internal-force sign: `f_c > 0` resists
/// a positive storey drift), the measured force the damper's delivered force; its
/// command is held from the next step on.
///
/// Returns `(u, v, force, command)`: displacements (m) and velocities (m/s) relative to
/// the ground (`steps×n`), the damper force (N) and the voltage held from each sample.
/// Raises `NotConverged`, `InvalidMaterial`, `InvalidParameter`, `NonFiniteInput`, …
/// with `.step`. Cost per step: a few Newton iterations of an `n×n` solve.
#[pyfunction]
#[pyo3(signature = (m, c, k, ag, h, storey, params, law, gain=None))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn mr_building<'py>(
    py: Python<'py>,
    m: PyReadonlyArray2<'py, f64>,
    c: PyReadonlyArray2<'py, f64>,
    k: PyReadonlyArray2<'py, f64>,
    ag: PyReadonlyArray1<'py, f64>,
    h: f64,
    storey: usize,
    params: Vec<f64>,
    law: &str,
    gain: Option<PyReadonlyArray2<'py, f64>>,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
)> {
    let n = m.as_array().dim().0;
    let prepare = || -> Res<MrBuildingJob> {
        // The histories (u, v: steps×n; force, command), checked before allocating.
        let steps = ag.as_array().dim();
        fits(
            "mr_building",
            &[(steps, n), (steps, n), (steps, 1), (steps, 1)],
        )?;
        let ag = read1(&ag);
        if ag.is_empty() {
            return shape("ag must have at least one sample".into());
        }
        if storey >= n {
            return shape(format!("storey must be in 0..{n}, got {storey}"));
        }
        let law = match (law, &gain) {
            ("off", None) => Law::Off,
            ("on", None) => Law::On,
            ("clipped", Some(g)) => Law::Clipped(sized(g, 1, 2 * n, "gain")?),
            _ => {
                return shape(format!(
                    "law must be \"off\" or \"on\" without a gain, or \"clipped\" with a 1x{} gain, got {law:?}",
                    2 * n
                ));
            }
        };
        Ok(MrBuildingJob {
            m: square(&m, n, "m")?,
            c: square(&c, n, "c")?,
            k: square(&k, n, "k")?,
            ag,
            h,
            storey,
            params: mr_parameters(&params)?,
            law,
        })
    };
    let job = prepare().map_err(|f| f.raise(py))?;
    let (u, v, f, cmd) = interruptible(py, work_units(job.ag.len(), n, 2), |stop| {
        by_size!(n, mr_building_n(&job, stop))
    })?;
    Ok((out2(py, u, n), out2(py, v, n), out1(py, f), out1(py, cmd)))
}

/// Register the functions and limits.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("MAX_DESIGN_STATES", MAX_DESIGN_STATES)?;
    m.add("MAX_CONTROL_INPUTS", MAX_CONTROL_INPUTS)?;
    m.add_function(wrap_pyfunction!(zero_order_hold, m)?)?;
    m.add_function(wrap_pyfunction!(lqr, m)?)?;
    m.add_function(wrap_pyfunction!(lqg, m)?)?;
    m.add_function(wrap_pyfunction!(mr_damper_response, m)?)?;
    m.add_function(wrap_pyfunction!(mr_building, m)?)?;
    Ok(())
}
