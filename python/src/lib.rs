//! `aemstep._aemstep`: the native half of the Python package `aemstep` (PyO3, stable ABI
//! `abi3-py39`, numpy arrays through rust-numpy).
//!
//! Every function copies its arrays in (`float64`; the pure-Python wrapper `aemstep/`
//! converts lists, integers and non-contiguous arrays first), checks shapes and sizes
//! (a typed exception, never a panic), then runs the record with the GIL released
//! (`Python::detach`) and hands fresh numpy arrays back. Units are SI throughout: m, s,
//! kg, N, ground accelerations in m/s².
//!
//! **Sizes.** The library's sizes are const generics. Structures (`n` degrees of freedom,
//! storeys) are dispatched over [`SIZES`] (1 to 10, 12, 15, 20); `linear_response` with
//! the AEM takes any other `n` on the run-time-sized `DynLinear`, `shear_building` on
//! `DynShearBuilding` (bit-identical where both serve); other `n` elsewhere raise
//! `UnsupportedSize`. Spectra take any number of periods: they are stepped in banks of
//! [`CHUNK`] oscillators, the last bank padded with copies of the longest period.
//! `observe`'s fixed-gain observer and Kalman filter take any `n` and any number of sensors
//! (the run-time-sized `DynObserver` and `DynKalman` outside the compiled sizes and
//! [`MAX_SENSORS`]).
//!
//! **Errors.** Every `aemstep::Error` variant is a Python exception of the same name,
//! subclass of `AemstepError` (itself a `ValueError`), with the Rust `Display` as message;
//! a step that fails sets the exception's `step` attribute to its index.
//!
//! Vibration control (`control.rs`): the zero-order-hold design model, the LQR, the MR
//! damper and a building with one MR damper.
//!
//! Incremental dynamic analysis (`ida.rs`) runs the building of [`shear_building`] (its laws
//! built by `laws.rs`) over many records and intensities; `records.rs` reads records.

use aemstep::hysteresis::{EnergyAccount, HistoryModel, Law, ShearBuilding};
use aemstep::nalgebra::{DMatrix, SMatrix, SVector};
use aemstep::observer::{
    DynKalman, DynObserver, DynStateSpace, DynSteadyState, Kalman, Observer, Outputs, StateSpace,
    SteadyState,
};
use aemstep::spectrum::inelastic::{Outcome, Search, Yielding};
use aemstep::spectrum::{Bank, RotD, Scheme, Substeps};
use aemstep::{
    Damping, DynEnergyAccount, DynLinear, DynNonlinear, DynShearBuilding, DynState, Error, Exact,
    GeneralizedAlpha, Linear, Modal, Newmark, NewtonSettings, Nonlinear, Stepper, batch,
};
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::{PyKeyboardInterrupt, PyMemoryError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::Duration;

/// The numbers of degrees of freedom (storeys) the package is compiled for.
pub const SIZES: [usize; 13] = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 12, 15, 20];

/// Oscillators per spectrum bank: periods are stepped in banks of this many.
pub const CHUNK: usize = 16;

/// The most modes a truncated modal run keeps (besides all of them).
pub const MAX_TRUNCATED_MODES: usize = 3;

/// The largest number of sensors the compiled observers are built for (more, and sizes
/// outside [`SIZES`], run on the run-time-sized `DynObserver` / `DynKalman`).
pub const MAX_SENSORS: usize = 3;

/// The largest model `observe` takes (`n` DOFs, `2n` states). Its gain solve costs
/// about `2400 n³` multiply-adds and looks at Ctrl-C between pieces of at most `40 n³`
/// multiply-adds (a doubling iteration's `10 S³` flops, `S = 2n` states, a multiply-add
/// two flops); its model and noise build (`O(n³)`) and a Kalman step
/// (`O(n³)`) are not split. At `n = 200` each of those is a fraction of a second on the
/// development machine (`python/tests/test_interrupt.py`); above, Ctrl-C would wait
/// seconds and the gain minutes: reduce the model (e.g. to its lowest modes) first.
pub const MAX_OBSERVE_DOFS: usize = 200;

/// Rotation angles of RotD50/RotD100 (1° increments over 180°).
pub const ROTD_ANGLES: usize = 180;

pyo3::create_exception!(
    aemstep,
    AemstepError,
    PyValueError,
    "Base of every aemstep error (a ValueError)."
);
pyo3::create_exception!(
    aemstep,
    ShapeError,
    AemstepError,
    "An array has the wrong shape or length for the call."
);
pyo3::create_exception!(
    aemstep,
    UnsupportedSize,
    ShapeError,
    "A number of degrees of freedom or sensors outside those compiled in."
);
pyo3::create_exception!(
    aemstep,
    InvalidArgument,
    AemstepError,
    "An argument outside its rule (e.g. a negative count, a file descriptor for a path); \
     `.argument` names it."
);

/// One Python exception per `aemstep::Error` variant, same name, subclass of
/// `AemstepError`; `variants!` also writes the mapping and the registration.
///
/// Every class is created with module `aemstep` (not `_aemstep`) and re-exported there by
/// `aemstep/__init__.py`, so pickle finds `aemstep.NotConverged` by that name: an error
/// raised in a process pool or on a Dask worker reaches the caller with its class, and its
/// attributes (`step`, `line`, `parameter`, set on the instance) travel in the instance
/// `__dict__` that `BaseException.__reduce__` carries.
macro_rules! variants {
    ($($name:ident),* $(,)?) => {
        $(pyo3::create_exception!(
            aemstep,
            $name,
            AemstepError,
            concat!("aemstep::Error::", stringify!($name), " (see the Rust docs).")
        );)*

        /// The Python exception of a library error, its message the Rust `Display`.
        fn exception(e: Error) -> PyErr {
            let msg = e.to_string();
            match e {
                $(Error::$name { .. } => $name::new_err(msg),)*
                // `Error` is non-exhaustive: a variant added later is still an AemstepError.
                _ => AemstepError::new_err(msg),
            }
        }

        /// Register the exception classes in the module.
        fn register_exceptions(m: &Bound<'_, PyModule>) -> PyResult<()> {
            let py = m.py();
            m.add("AemstepError", py.get_type::<AemstepError>())?;
            m.add("ShapeError", py.get_type::<ShapeError>())?;
            m.add("UnsupportedSize", py.get_type::<UnsupportedSize>())?;
            m.add("InvalidArgument", py.get_type::<InvalidArgument>())?;
            $(m.add(stringify!($name), py.get_type::<$name>())?;)*
            m.add("ERROR_VARIANTS", vec![$(stringify!($name)),*])?;
            Ok(())
        }
    };
}

variants!(
    NonFiniteInput,
    InvalidTimeStep,
    SingularEffectiveMatrix,
    SingularMass,
    NonFiniteState,
    NotConverged,
    SingularJacobian,
    NonFiniteForce,
    InvalidNewtonSettings,
    SingularEffectiveMatrixAtStep,
    MassNotSpd,
    StiffnessNotSymmetric,
    InvalidModeSelection,
    NonClassicalDamping,
    EigenNotConverged,
    OperatorOverflow,
    OperatorUnderflow,
    InvalidParameter,
    InvalidPeriod,
    InvalidDamping,
    InvalidMaterial,
    InvalidCovariance,
    RiccatiNotConverged,
    StateSizeMismatch,
    InputNotIdentifiable,
    MalformedRecord,
    StiffnessIndefinite,
    StepCountOverflow,
    NotStabilizing,
);

/// Why a run stopped: a library error (at a step, if a step failed), a bad argument, an
/// output too large for memory, or the caller's interrupt.
enum Fail {
    Lib(Error, Option<usize>),
    Shape(String),
    Size(String),
    /// `MemoryError`: the outputs would not fit (checked before allocating).
    Memory(String),
    /// The run saw its stop flag (Ctrl-C on the Python thread); the signal's own
    /// `KeyboardInterrupt` is what the caller gets.
    Cancelled,
}

impl From<Error> for Fail {
    fn from(e: Error) -> Self {
        Fail::Lib(e, None)
    }
}

/// A library error at step `n`.
fn at(n: usize) -> impl Fn(Error) -> Fail {
    move |e| Fail::Lib(e, Some(n))
}

impl Fail {
    fn raise(self, py: Python<'_>) -> PyErr {
        match self {
            Fail::Lib(e, step) => {
                let err = exception(e);
                if let Some(n) = step {
                    // Best effort: the message already says what failed.
                    let _ = err.value(py).setattr("step", n);
                }
                if let Error::MalformedRecord { line } = e {
                    let _ = err.value(py).setattr("line", line);
                }
                if let Error::InvalidParameter(p) | Error::InvalidMaterial(p) = e {
                    // The parameter's name (`Param`'s variant), e.g. "RhoInf".
                    let _ = err.value(py).setattr("parameter", format!("{p:?}"));
                }
                err
            }
            Fail::Shape(m) => ShapeError::new_err(m),
            Fail::Size(m) => UnsupportedSize::new_err(m),
            Fail::Memory(m) => PyMemoryError::new_err(m),
            Fail::Cancelled => PyKeyboardInterrupt::new_err("aemstep: the run was interrupted"),
        }
    }
}

type Res<T> = Result<T, Fail>;

fn shape<T>(msg: String) -> Res<T> {
    Err(Fail::Shape(msg))
}

/// Call `$f::<N, 2N>(args…)` for the run-time size `$n`, or fail with `UnsupportedSize`;
/// with `else $g(args…)`, sizes outside [`SIZES`] go to `$g` (the run-time-sized path)
/// instead. The compiled sizes stay: their steps are unrolled for the size.
macro_rules! by_size {
    ($n:expr, $f:ident ( $($arg:expr),* $(,)? ) else $g:ident ( $($garg:expr),* $(,)? )) => {
        if SIZES.contains(&$n) {
            by_size!($n, $f($($arg),*))
        } else {
            $g($($garg),*)
        }
    };
    ($n:expr, $f:ident ( $($arg:expr),* $(,)? )) => {
        match $n {
            1 => $f::<1, 2>($($arg),*),
            2 => $f::<2, 4>($($arg),*),
            3 => $f::<3, 6>($($arg),*),
            4 => $f::<4, 8>($($arg),*),
            5 => $f::<5, 10>($($arg),*),
            6 => $f::<6, 12>($($arg),*),
            7 => $f::<7, 14>($($arg),*),
            8 => $f::<8, 16>($($arg),*),
            9 => $f::<9, 18>($($arg),*),
            10 => $f::<10, 20>($($arg),*),
            12 => $f::<12, 24>($($arg),*),
            15 => $f::<15, 30>($($arg),*),
            20 => $f::<20, 40>($($arg),*),
            n => Err(Fail::Size(format!(
                "{n} degrees of freedom: this build supports n in {:?}",
                SIZES
            ))),
        }
    };
}

// ---------------------------------------------------------------------------------------
// Long calls: off the Python thread, answering Ctrl-C; outputs sized before allocating.

/// How often the waiting Python thread checks for signals (and reports progress).
pub(crate) const POLL: Duration = Duration::from_millis(100);

/// Steps between two looks at the stop flag within a run: 64 steps are 5 µs to 10 ms of
/// work (a one-DOF linear step; a 20-storey Newton step at the 10 000-iteration budget the
/// Python wrapper allows), so Ctrl-C is answered within a second however slow the steps.
pub(crate) const STOP_EVERY: usize = 64;

/// `Err(Fail::Cancelled)` at every [`STOP_EVERY`]-th step `n` once `stop` is set: the
/// run's cheap look at its stop flag (one relaxed load per 64 steps).
pub(crate) fn stopped(stop: &AtomicBool, n: usize) -> Res<()> {
    if n.is_multiple_of(STOP_EVERY) && stop.load(Ordering::Relaxed) {
        Err(Fail::Cancelled)
    } else {
        Ok(())
    }
}

/// Runs `work` on a scoped worker thread while the Python thread waits with the GIL
/// released, waking every [`POLL`] (or at once when `work` ends) to call `poll` (with the
/// GIL: e.g. a progress callback) and check for signals. An exception from either (Ctrl-C's
/// `KeyboardInterrupt`) sets the stop flag `work` is handed — its loops look at it through
/// [`stopped`] — and is raised once the worker has returned: no thread outlives the call.
/// A panic in `work` is a `RuntimeError`. Cost: one thread spawn (tens of µs) a call.
pub(crate) fn polled<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(&AtomicBool) -> Res<T> + Send,
    mut poll: impl FnMut() -> PyResult<()>,
) -> PyResult<T> {
    let stop = AtomicBool::new(false);
    let finished = (Mutex::new(false), Condvar::new());
    /// Marks the worker finished however it ends (a panic included).
    struct Done<'a>(&'a (Mutex<bool>, Condvar));
    impl Drop for Done<'_> {
        fn drop(&mut self) {
            let (lock, cv) = self.0;
            *lock.lock().unwrap_or_else(|e| e.into_inner()) = true;
            cv.notify_all();
        }
    }
    std::thread::scope(|scope| {
        let worker = scope.spawn(|| {
            let _done = Done(&finished);
            work(&stop)
        });
        let mut raised: Option<PyErr> = None;
        loop {
            let over = py.detach(|| {
                let (lock, cv) = &finished;
                let guard = lock.lock().unwrap_or_else(|e| e.into_inner());
                let (guard, _) = cv
                    .wait_timeout_while(guard, POLL, |f| !*f)
                    .unwrap_or_else(|e| e.into_inner());
                *guard
            });
            if raised.is_none()
                && let Err(e) = poll().and_then(|()| py.check_signals())
            {
                stop.store(true, Ordering::Relaxed);
                raised = Some(e);
            }
            if over {
                break;
            }
        }
        let out = py.detach(|| worker.join());
        if let Some(e) = raised {
            return Err(e);
        }
        match out {
            Ok(r) => r.map_err(|f| f.raise(py)),
            Err(_) => Err(PyRuntimeError::new_err(
                "aemstep: the worker thread panicked",
            )),
        }
    })
}

/// Work units (about a multiply-add each: `steps · n²`, `steps · n³` for an observer)
/// below which a call runs on the Python thread with the GIL released and no worker: a few
/// ms at most, shorter than the wait for Ctrl-C, and no thread spawn and hand-over (about
/// 70 µs a call on the 2-core machine) in loops of short calls.
pub(crate) const INLINE_WORK: usize = 1 << 18;

/// [`polled`] with nothing to report: a long call that answers Ctrl-C. A call of at most
/// [`INLINE_WORK`] units of `work_units` runs inline instead (the GIL released, never
/// stopped: it ends sooner than a poll would come).
pub(crate) fn interruptible<T: Send>(
    py: Python<'_>,
    work_units: usize,
    work: impl FnOnce(&AtomicBool) -> Res<T> + Send,
) -> PyResult<T> {
    if work_units <= INLINE_WORK {
        return py
            .detach(|| work(&AtomicBool::new(false)))
            .map_err(|f| f.raise(py));
    }
    polled(py, work, || Ok(()))
}

/// `steps · n^power` work units for [`interruptible`], saturating.
pub(crate) fn work_units(steps: usize, n: usize, power: u32) -> usize {
    steps.saturating_mul(n.saturating_pow(power))
}

/// The machine's memory and swap (bytes) from `/proc/meminfo`, if readable.
fn memory_limit() -> Option<u128> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let kb = |key: &str| -> Option<u128> {
        let line = info.lines().find(|l| l.starts_with(key))?;
        line[key.len()..].split_whitespace().next()?.parse().ok()
    };
    Some((kb("MemTotal:")? + kb("SwapTotal:").unwrap_or(0)) * 1024)
}

/// Checks, before anything is allocated, that `float64` arrays of `(rows, cols)` each fit:
/// their sizes multiplied and summed without overflow, the total within the address space
/// and the machine's memory and swap. `MemoryError` naming `what` otherwise.
pub(crate) fn fits(what: &str, arrays: &[(usize, usize)]) -> Res<()> {
    let total = arrays
        .iter()
        .try_fold(0u128, |t, &(r, c)| t.checked_add(r as u128 * c as u128 * 8));
    let limit = memory_limit()
        .unwrap_or(isize::MAX as u128)
        .min(isize::MAX as u128);
    match total {
        Some(t) if t <= limit => Ok(()),
        _ => Err(Fail::Memory(format!(
            "{what}: the outputs would take {} bytes, more than this machine's {limit} bytes of memory",
            total.map_or_else(|| "more than 2^128".to_string(), |t| t.to_string())
        ))),
    }
}

/// An empty `Vec` with room for `rows × cols` values, or `MemoryError` (the size checked,
/// the allocation `try_reserve_exact`: never an abort).
pub(crate) fn buffer(rows: usize, cols: usize) -> Res<Vec<f64>> {
    let mut v = Vec::new();
    rows.checked_mul(cols)
        .and_then(|n| v.try_reserve_exact(n).ok())
        .ok_or_else(|| {
            Fail::Memory(format!("{rows}x{cols} float64 values do not fit in memory"))
        })?;
    Ok(v)
}

// ---------------------------------------------------------------------------------------
// Arrays in and out.

/// A 2-D array copied into a row-major `Vec` with its shape.
fn read2(a: &PyReadonlyArray2<'_, f64>) -> (Vec<f64>, usize, usize) {
    let v = a.as_array();
    let (r, c) = v.dim();
    (v.iter().copied().collect(), r, c)
}

/// A 1-D array copied into a `Vec`.
fn read1(a: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    a.as_array().iter().copied().collect()
}

/// An `n×n` matrix, checked square of size `n`.
fn square(a: &PyReadonlyArray2<'_, f64>, n: usize, name: &str) -> Res<Vec<f64>> {
    let (v, r, c) = read2(a);
    if r != n || c != n {
        return shape(format!("{name} must be {n}x{n}, got {r}x{c}"));
    }
    Ok(v)
}

fn matrix<const N: usize>(v: &[f64]) -> SMatrix<f64, N, N> {
    SMatrix::from_fn(|i, j| v[i * N + j])
}

fn rows<const N: usize>(v: &[f64]) -> [[f64; N]; N] {
    core::array::from_fn(|i| core::array::from_fn(|j| v[i * N + j]))
}

fn vector<const N: usize>(v: &[f64]) -> SVector<f64, N> {
    SVector::from_column_slice(v)
}

fn out2(py: Python<'_>, v: Vec<f64>, cols: usize) -> Bound<'_, PyArray2<f64>> {
    let r = v.len().checked_div(cols).unwrap_or(0);
    Array2::from_shape_vec((r, cols), v)
        .expect("length is rows × cols by construction")
        .into_pyarray(py)
}

fn out1(py: Python<'_>, v: Vec<f64>) -> Bound<'_, PyArray1<f64>> {
    Array1::from_vec(v).into_pyarray(py)
}

// ---------------------------------------------------------------------------------------
// Linear models over a record.

/// Which linear scheme, with its parameters.
#[derive(Clone, Copy)]
enum LinearScheme {
    Aem,
    /// The `R` lowest modes (`0`: all).
    Modal(usize),
    Newmark(f64, f64),
    GeneralizedAlpha(f64),
    Hht(f64),
    Exact,
}

struct LinearJob {
    m: Vec<f64>,
    c: Vec<f64>,
    k: Vec<f64>,
    h: f64,
    p: Vec<f64>,
    u0: Vec<f64>,
    v0: Vec<f64>,
    scheme: LinearScheme,
}

/// The histories `u, v, a` (row-major, steps × n).
type Histories = (Vec<f64>, Vec<f64>, Vec<f64>);

fn drive<const N: usize, S>(sys: &S, job: &LinearJob, stop: &AtomicBool) -> Res<Histories>
where
    S: Stepper<f64, N, Input = SVector<f64, N>>,
{
    let steps = job.p.len() / N;
    let load = |n: usize| vector::<N>(&job.p[n * N..(n + 1) * N]);
    let (mut u, mut v, mut a) = (buffer(steps, N)?, buffer(steps, N)?, buffer(steps, N)?);
    let mut keep = |s: &S::State| {
        let f = sys.full_state(s);
        u.extend_from_slice(f.u().as_slice());
        v.extend_from_slice(f.v().as_slice());
        a.extend_from_slice(f.a().as_slice());
    };
    let mut s = sys
        .start(&vector(&job.u0), &vector(&job.v0), &load(0))
        .map_err(at(0))?;
    keep(&s);
    for n in 1..steps {
        stopped(stop, n)?;
        sys.try_step_with_previous_input(&mut s, &load(n - 1), &load(n))
            .map_err(at(n))?;
        keep(&s);
    }
    Ok((u, v, a))
}

fn linear_n<const N: usize, const S: usize>(job: &LinearJob, stop: &AtomicBool) -> Res<Histories> {
    let (m, c, k) = (
        matrix::<N>(&job.m),
        matrix::<N>(&job.c),
        matrix::<N>(&job.k),
    );
    let h = job.h;
    match job.scheme {
        LinearScheme::Aem => drive::<N, _>(&Linear::<f64, N>::new(&m, &c, &k, h)?, job, stop),
        LinearScheme::Newmark(beta, gamma) => drive::<N, _>(
            &Newmark::<f64, N>::new(&m, &c, &k, h, beta, gamma)?,
            job,
            stop,
        ),
        LinearScheme::GeneralizedAlpha(rho) => drive::<N, _>(
            &GeneralizedAlpha::<f64, N>::new(&m, &c, &k, h, rho)?,
            job,
            stop,
        ),
        LinearScheme::Hht(alpha) => drive::<N, _>(
            &GeneralizedAlpha::<f64, N>::hht(&m, &c, &k, h, alpha)?,
            job,
            stop,
        ),
        LinearScheme::Exact => drive::<N, _>(&Exact::<f64, N>::new(&m, &c, &k, h)?, job, stop),
        LinearScheme::Modal(r) => match r {
            // Every mode, or the R lowest: R in 1..=MAX_TRUNCATED_MODES (a copy of the
            // modal stepper per (n, R), so the list is short; R > n is the library's error).
            0 => modal_run::<N, N>(job, stop),
            r if r == N => modal_run::<N, N>(job, stop),
            r if r > N => Err(Error::InvalidModeSelection.into()),
            1 => modal_run::<N, 1>(job, stop),
            2 => modal_run::<N, 2>(job, stop),
            3 => modal_run::<N, 3>(job, stop),
            r => Err(Fail::Size(format!(
                "{r} modes of {N}: this build keeps 1 to {MAX_TRUNCATED_MODES} modes or all of them"
            ))),
        },
    }
}

/// [`linear_n`] at a size outside [`SIZES`]: the AEM on [`DynLinear`], the const-generic
/// `Linear` sized at run time (bit-identical to it where both serve); the other schemes
/// are compiled for [`SIZES`] only.
fn linear_any(job: &LinearJob, n: usize, stop: &AtomicBool) -> Res<Histories> {
    if n == 0 || !matches!(job.scheme, LinearScheme::Aem) {
        return Err(Fail::Size(format!(
            "{n} degrees of freedom: scheme \"aem\" takes any n, the other schemes n in {SIZES:?}"
        )));
    }
    let dm = |a: &[f64]| DMatrix::from_row_slice(n, n, a);
    let sys = DynLinear::<f64>::new(&dm(&job.m), &dm(&job.c), &dm(&job.k), job.h)?;
    let steps = job.p.len() / n;
    let load = |s: usize| &job.p[s * n..(s + 1) * n];
    let (mut u, mut v, mut a) = (buffer(steps, n)?, buffer(steps, n)?, buffer(steps, n)?);
    let mut keep = |s: &DynState<f64>| {
        u.extend_from_slice(s.u());
        v.extend_from_slice(s.v());
        a.extend_from_slice(s.a());
    };
    let mut s = sys.start(&job.u0, &job.v0, load(0)).map_err(at(0))?;
    keep(&s);
    for i in 1..steps {
        stopped(stop, i)?;
        sys.try_step(&mut s, load(i)).map_err(at(i))?;
        keep(&s);
    }
    Ok((u, v, a))
}

/// The `R` lowest modes of the job's model, the loads as `N` inputs (`B = I`), the DOFs as
/// outputs; the full state rebuilt from the modes at every step.
fn modal_run<const N: usize, const R: usize>(job: &LinearJob, stop: &AtomicBool) -> Res<Histories> {
    let eye = SMatrix::<f64, N, N>::identity();
    let modal = Modal::<f64, N, R, N, N>::new(
        &matrix::<N>(&job.m),
        &matrix::<N>(&job.k),
        &Damping::Matrix(rows::<N>(&job.c)),
        &eye,
        &eye,
        job.h,
    )?;
    drive::<N, _>(&modal, job, stop)
}

/// Step the linear model `M u'' + C u' + K u = p(t)` over a load history.
///
/// Arguments: `m`, `c`, `k` — mass (kg), damping (N·s/m) and stiffness (N/m) matrices,
/// `n×n`; `h` — time step (s); `p` — loads (N), `steps×n`, row `i` at `t = i·h` (row 0 the
/// load at the start); `u0`, `v0` — initial displacements (m) and velocities (m/s);
/// `scheme` — `"aem"` (the analog equation method, `Linear`), `"modal"` (`Modal`: the
/// `modes` lowest modes, `0` for all, else 1 to 3; `M` SPD, `K` symmetric, `C` classical;
/// `u` is then the modes' part of the response), `"newmark"` (`beta`, `gamma`),
/// `"generalized_alpha"` (`rho_inf` in [0, 1]), `"hht"` (`alpha` in [−1/3, 0]), `"exact"`
/// (matrix exponential, load linear between samples).
///
/// Returns `(u, v, a)`: displacements (m), velocities (m/s), accelerations (m/s²), each
/// `steps×n`, row 0 the initial state. Raises the library's errors (e.g. `InvalidTimeStep`,
/// `SingularEffectiveMatrix`, `NonFiniteInput`, `NonClassicalDamping`), `ShapeError`,
/// `UnsupportedSize`. The GIL is released while stepping.
#[pyfunction]
#[pyo3(signature = (m, c, k, h, p, u0, v0, scheme="aem", beta=0.25, gamma=0.5, rho_inf=1.0, alpha=0.0, modes=0))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn linear_response<'py>(
    py: Python<'py>,
    m: PyReadonlyArray2<'py, f64>,
    c: PyReadonlyArray2<'py, f64>,
    k: PyReadonlyArray2<'py, f64>,
    h: f64,
    p: PyReadonlyArray2<'py, f64>,
    u0: PyReadonlyArray1<'py, f64>,
    v0: PyReadonlyArray1<'py, f64>,
    scheme: &str,
    beta: f64,
    gamma: f64,
    rho_inf: f64,
    alpha: f64,
    modes: usize,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
)> {
    let scheme = match scheme {
        "aem" | "linear" => LinearScheme::Aem,
        "modal" => LinearScheme::Modal(modes),
        "newmark" => LinearScheme::Newmark(beta, gamma),
        "generalized_alpha" => LinearScheme::GeneralizedAlpha(rho_inf),
        "hht" => LinearScheme::Hht(alpha),
        "exact" => LinearScheme::Exact,
        other => {
            return Err(PyValueError::new_err(format!(
                "unknown scheme {other:?}: one of aem, modal, newmark, generalized_alpha, hht, exact"
            )));
        }
    };
    let run = || -> Res<(LinearJob, usize)> {
        let n = m.as_array().dim().0;
        // The copy of `p` and the three histories, checked before anything is allocated.
        let steps = p.as_array().dim().0;
        fits("linear_response", &[(steps, n); 4])?;
        let job = LinearJob {
            m: square(&m, n, "m")?,
            c: square(&c, n, "c")?,
            k: square(&k, n, "k")?,
            h,
            p: {
                let (v, r, cols) = read2(&p);
                if cols != n || r == 0 {
                    return shape(format!(
                        "p must be steps x {n} with at least one row, got {r}x{cols}"
                    ));
                }
                v
            },
            u0: read1(&u0),
            v0: read1(&v0),
            scheme,
        };
        if job.u0.len() != n || job.v0.len() != n {
            return shape(format!("u0 and v0 must have length {n}"));
        }
        Ok((job, n))
    };
    let (job, n) = run().map_err(|f| f.raise(py))?;
    let (u, v, a) = interruptible(
        py,
        work_units(job.p.len() / n.max(1), n, 2),
        |stop| by_size!(n, linear_n(&job, stop) else linear_any(&job, n, stop)),
    )?;
    Ok((out2(py, u, n), out2(py, v, n), out2(py, a, n)))
}

// ---------------------------------------------------------------------------------------
// The yielding shear building.

struct BuildingJob {
    masses: Vec<f64>,
    params: Vec<f64>,
    width: usize,
    c: Vec<f64>,
    h: f64,
    ag: Vec<f64>,
    settings: NewtonSettings<f64>,
    /// Keep the energy account (`N` law trials and `N²` more a step).
    energy: bool,
    /// Keep the per-step histories (`u`, `v`, `a`, drifts, iterations, energy): `4N + 1`
    /// values a step written to memory; without, only the peaks and the last energy row.
    histories: bool,
}

/// The outcome of a building run (histories row-major, empty without `histories`).
struct BuildingOut {
    u: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    /// Storey drifts `u_i − u_{i−1}` (m), `steps×N`.
    drifts: Vec<f64>,
    /// E_in, E_k, E_s, E_v, E_h, balance error (J) per step (empty without the account;
    /// the last step's row only without `histories`).
    energy: Vec<f64>,
    iterations: Vec<f64>,
    initial_energy: f64,
    /// max |drift| per storey over the steps (m), always kept.
    peak_drifts: Vec<f64>,
    /// Newton iterations summed over the steps, always kept.
    total_iterations: u64,
}

/// The outputs of a building run as they are produced: the histories when kept, the peak
/// drifts and iteration count always; one recorder for the compiled and the run-time
/// paths.
struct Recorder {
    o: BuildingOut,
    peaks: Vec<f64>,
    drifts: Vec<f64>,
    histories: bool,
}

impl Recorder {
    /// Capacity only when the histories are kept: the run then writes each value once into
    /// memory handed to numpy as it is (no copy on the way out).
    fn new(job: &BuildingJob, n: usize, initial_energy: f64) -> Res<Self> {
        let kept = if job.histories { job.ag.len() } else { 0 };
        Ok(Self {
            o: BuildingOut {
                u: buffer(kept, n)?,
                v: buffer(kept, n)?,
                a: buffer(kept, n)?,
                drifts: buffer(kept, n)?,
                energy: buffer(if job.energy { kept.max(1) } else { 0 }, 6)?,
                iterations: buffer(kept, 1)?,
                initial_energy,
                peak_drifts: Vec::new(),
                total_iterations: 0,
            },
            peaks: vec![0.0; n],
            drifts: vec![0.0; n],
            histories: job.histories,
        })
    }

    /// One sample: the drifts as numpy's `np.diff(u, axis=1, prepend=0.0)` forms them
    /// (`u_0 − 0` first), so the peaks are bitwise those of the histories.
    fn keep(&mut self, u: &[f64], v: &[f64], a: &[f64], iterations: u32) {
        let mut below = 0.0;
        for (i, &ui) in u.iter().enumerate() {
            self.drifts[i] = ui - below;
            below = ui;
            self.peaks[i] = self.peaks[i].max(self.drifts[i].abs());
        }
        self.o.total_iterations += u64::from(iterations);
        if self.histories {
            self.o.u.extend_from_slice(u);
            self.o.v.extend_from_slice(v);
            self.o.a.extend_from_slice(a);
            self.o.drifts.extend_from_slice(&self.drifts);
            self.o.iterations.push(f64::from(iterations));
        }
    }

    /// The energy row of a step: every step's with the histories (`last` false), else
    /// only the run's last (`last` true, at the end).
    fn energy(&mut self, row: Option<[f64; 6]>, last: bool) {
        if let Some(row) = row
            && self.histories != last
        {
            self.o.energy.extend_from_slice(&row);
        }
    }

    fn finish(mut self) -> BuildingOut {
        self.o.peak_drifts = self.peaks;
        self.o
    }
}

/// The energy row `E_in, E_k, E_s, E_v, E_h, error` of an account (either path's).
macro_rules! energy_row {
    ($e:expr) => {{
        let e = $e;
        [
            e.input,
            e.kinetic,
            e.recoverable,
            e.viscous,
            e.hysteretic,
            e.balance_error(),
        ]
    }};
}

fn building_run<const N: usize, L: Law<f64>>(
    laws: [L; N],
    job: &BuildingJob,
    stop: &AtomicBool,
) -> Res<BuildingOut> {
    let masses: [f64; N] = core::array::from_fn(|i| job.masses[i]);
    let building = ShearBuilding::<f64, L, N>::new(masses, laws, &rows::<N>(&job.c))?;
    let stepper = Nonlinear::<f64, N>::new(job.h, job.settings)?;
    let zero = SVector::<f64, N>::zeros();
    let p0 = building.ground_load(job.ag[0]);
    let (mut s, mut history) = stepper
        .start_with_history(&building, &zero, &zero, &p0, &building.initial_history())
        .map_err(at(0))?;
    let mut account = job
        .energy
        .then(|| EnergyAccount::start(&building, &s, &history, &p0));
    let mut o = Recorder::new(job, N, account.as_ref().map_or(f64::NAN, |e| e.initial))?;
    o.keep(s.u().as_slice(), s.v().as_slice(), s.a().as_slice(), 0);
    o.energy(account.as_ref().map(|e| energy_row!(e)), false);
    for n in 1..job.ag.len() {
        stopped(stop, n)?;
        let p = building.ground_load(job.ag[n]);
        let previous = history;
        let report = stepper
            .try_step_with_history(&building, &mut s, &mut history, &p)
            .map_err(at(n))?;
        if let Some(e) = account.as_mut() {
            e.step(&building, &previous, &s, &history, &p);
        }
        o.energy(account.as_ref().map(|e| energy_row!(e)), false);
        o.keep(
            s.u().as_slice(),
            s.v().as_slice(),
            s.a().as_slice(),
            report.iterations,
        );
    }
    o.energy(account.as_ref().map(|e| energy_row!(e)), true);
    Ok(o.finish())
}

/// [`building_run`] at a run-time size (`DynShearBuilding`, `DynNonlinear`,
/// `DynEnergyAccount`: bit-identical to the compiled path where both serve).
fn building_any<L: Law<f64>>(
    laws: Vec<L>,
    job: &BuildingJob,
    stop: &AtomicBool,
) -> Res<BuildingOut> {
    let n = laws.len();
    let c = DMatrix::from_row_slice(n, n, &job.c);
    let building = DynShearBuilding::<f64, L>::new(&job.masses, laws, &c)?;
    let stepper = DynNonlinear::<f64>::new(job.h, job.settings)?;
    let (zero, mut p) = (vec![0.0; n], vec![0.0; n]);
    building.ground_load(job.ag[0], &mut p);
    let mut s = stepper.start(&building, &zero, &zero, &p).map_err(at(0))?;
    let mut account = job
        .energy
        .then(|| DynEnergyAccount::start(&building, &s, &p));
    let mut o = Recorder::new(
        job,
        n,
        account.as_ref().map_or(f64::NAN, |e| e.totals().initial),
    )?;
    o.keep(s.u(), s.v(), s.a(), 0);
    o.energy(account.as_ref().map(|e| energy_row!(e.totals())), false);
    for step in 1..job.ag.len() {
        stopped(stop, step)?;
        building.ground_load(job.ag[step], &mut p);
        let report = stepper.try_step(&building, &mut s, &p).map_err(at(step))?;
        if let Some(e) = account.as_mut() {
            e.step(&building, &s, &p);
        }
        o.energy(account.as_ref().map(|e| energy_row!(e.totals())), false);
        o.keep(s.u(), s.v(), s.a(), report.iterations);
    }
    o.energy(account.as_ref().map(|e| energy_row!(e.totals())), true);
    Ok(o.finish())
}

/// The storey laws from the parameter rows (`laws.rs`), then the run.
fn building_n<const N: usize, const S: usize>(
    law: &str,
    job: &BuildingJob,
    stop: &AtomicBool,
) -> Res<BuildingOut> {
    struct Run<'a>(&'a BuildingJob, &'a AtomicBool);
    impl<const N: usize> laws::WithLaws<N> for Run<'_> {
        type Out = BuildingOut;
        fn run<L: Law<f64> + Send + Sync>(self, laws: [L; N]) -> Res<BuildingOut> {
            building_run::<N, L>(laws, self.0, self.1)
        }
    }
    laws::with_laws::<N, _>(law, &job.params, job.width, Run(job, stop))
}

/// [`building_n`] for `n` storeys outside the compiled sizes (or any `n` with
/// `compiled=False`): the run-time-sized path.
fn building_vec(law: &str, job: &BuildingJob, n: usize, stop: &AtomicBool) -> Res<BuildingOut> {
    struct Run<'a>(&'a BuildingJob, &'a AtomicBool);
    impl laws::WithLawVec for Run<'_> {
        type Out = BuildingOut;
        fn run<L: Law<f64> + Send + Sync>(self, laws: Vec<L>) -> Res<BuildingOut> {
            building_any::<L>(laws, self.0, self.1)
        }
    }
    laws::with_law_vec(law, &job.params, job.width, n, Run(job, stop))
}

/// Step a hysteretic shear building (`ShearBuilding` with the `Nonlinear` AEM stepper and
/// Newton) over a ground-acceleration record, with its energy account.
///
/// Arguments: `masses` — floor masses (kg), ground storey first, length `n`; `law` —
/// `"bilinear"` (`params` columns: k N/m, fy N, alpha), `"bouc_wen"` (k N/m, fy N, alpha,
/// beta, gamma, n) or `"bilinear_friction"` (a bilinear frame and a Coulomb friction
/// damper in parallel: k N/m, fy N, alpha, fs N, vr m/s); `params` — one row per storey;
/// `c` — damping matrix (N·s/m), `n×n`; `h` — time step (s); `ag` — ground acceleration
/// (m/s²) at `t = i·h`; `max_iterations`, `tolerance` — Newton budget and relative
/// tolerance; `energy` — keep the energy account (about `N` law trials and `N²`
/// multiply-adds more a step; `False` for the bare stepping speed); `histories` — keep
/// the per-step histories (`4n + 1` values a step, `8·(4n + 1)` bytes, plus 48 with the
/// account; `False`: the peaks only, no memory a step, the speed of the Rust loop).
///
/// Returns a dict. Always: `peak_drifts` — max |storey drift| per storey (m), length `n`;
/// `peak_drift` — their max (m); `total_iterations` — Newton iterations over the run.
/// With `histories`: `u`, `v`, `a` — floor displacements (m), velocities (m/s),
/// accelerations (m/s²) relative to the ground, `steps×n`; `drifts` — storey drifts
/// `u_i − u_{i−1}` (m), `steps×n`; `iterations` — Newton iterations per step. With
/// `energy`: `energy` — `steps×6` (`1×6`, the last step, without `histories`): input,
/// kinetic, recoverable strain, viscous, hysteretic energies and the balance error (J);
/// `initial_energy` (J). Raises the library's errors (`NotConverged` with `.step`,
/// `InvalidMaterial`, `InvalidNewtonSettings`, …).
///
/// Any `n ≥ 1`: sizes in [`SIZES`] run the compiled `Nonlinear<f64, N>`, others the
/// run-time-sized `DynNonlinear` on a `DynShearBuilding` (bit-identical where both serve;
/// `compiled=False` takes the run-time path at every size, to compare).
#[pyfunction]
#[pyo3(signature = (masses, law, params, c, h, ag, max_iterations=20, tolerance=1e-10, energy=true, histories=true, compiled=true))]
#[allow(clippy::too_many_arguments)]
fn shear_building<'py>(
    py: Python<'py>,
    masses: PyReadonlyArray1<'py, f64>,
    law: &str,
    params: PyReadonlyArray2<'py, f64>,
    c: PyReadonlyArray2<'py, f64>,
    h: f64,
    ag: PyReadonlyArray1<'py, f64>,
    max_iterations: u32,
    tolerance: f64,
    energy: bool,
    histories: bool,
    compiled: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let width = laws::known_law(law)?;
    let prepare = || -> Res<(BuildingJob, usize)> {
        let masses = read1(&masses);
        let n = masses.len();
        if n == 0 {
            return shape("masses must have at least one storey".into());
        }
        let (p, r, cols) = read2(&params);
        if r != n || cols != width {
            return shape(format!(
                "params must be {n}x{width} for law {law:?} and {n} storeys, got {r}x{cols}"
            ));
        }
        // The histories (u, v, a, drifts, iterations, energy) checked before allocating.
        let steps = ag.as_array().dim();
        let kept = if histories { steps } else { 0 };
        let rows = if energy { kept.max(1) } else { 0 };
        // The run-time path also holds `C` twice and `n²` of Newton work space.
        fits(
            "shear_building",
            &[
                (kept, n),
                (kept, n),
                (kept, n),
                (kept, n),
                (kept, 1),
                (rows, 6),
                (n, n),
                (n, n),
                (n, n),
            ],
        )?;
        let ag = read1(&ag);
        if ag.is_empty() {
            return shape("ag must have at least one sample".into());
        }
        Ok((
            BuildingJob {
                masses,
                params: p,
                width,
                c: square(&c, n, "c")?,
                h,
                ag,
                settings: NewtonSettings::up_to(max_iterations, tolerance),
                energy,
                histories,
            },
            n,
        ))
    };
    let (job, n) = prepare().map_err(|f| f.raise(py))?;
    let o = interruptible(py, work_units(job.ag.len(), n, 2), |stop| {
        if compiled {
            by_size!(n, building_n(law, &job, stop) else building_vec(law, &job, n, stop))
        } else {
            building_vec(law, &job, n, stop)
        }
    })?;
    let d = PyDict::new(py);
    let peak = o.peak_drifts.iter().fold(0.0f64, |m, &x| m.max(x));
    d.set_item("peak_drifts", out1(py, o.peak_drifts))?;
    d.set_item("peak_drift", peak)?;
    d.set_item("total_iterations", o.total_iterations)?;
    if histories {
        d.set_item("u", out2(py, o.u, n))?;
        d.set_item("v", out2(py, o.v, n))?;
        d.set_item("a", out2(py, o.a, n))?;
        d.set_item("drifts", out2(py, o.drifts, n))?;
        d.set_item("iterations", out1(py, o.iterations))?;
    }
    if energy {
        d.set_item("energy", out2(py, o.energy, 6))?;
        d.set_item("initial_energy", o.initial_energy)?;
    }
    Ok(d)
}

// ---------------------------------------------------------------------------------------
// Spectra: periods in banks of CHUNK.

/// Samples stepped between two looks at the cancel flag (a few ms of the slowest bank).
const CANCEL_CHUNK: usize = 4096;

/// The non-finite-sample policy named by `nan`: `"raise"` (the default) or `"skip"`.
fn non_finite_of(nan: &str) -> PyResult<aemstep::spectrum::NonFinite> {
    match nan {
        "raise" => Ok(aemstep::spectrum::NonFinite::Refuse),
        "skip" => Ok(aemstep::spectrum::NonFinite::Skip),
        other => Err(PyValueError::new_err(format!(
            "unknown nan policy {other:?}: \"raise\" or \"skip\""
        ))),
    }
}

/// Under `"raise"`, the first record (of `records`, in order) with a non-finite sample:
/// `NonFiniteInput` with `.step` (the sample's index) and `.record` (the record's).
fn refuse_non_finite(
    py: Python<'_>,
    policy: aemstep::spectrum::NonFinite,
    records: &[&[f64]],
) -> PyResult<()> {
    if policy == aemstep::spectrum::NonFinite::Skip {
        return Ok(());
    }
    for (i, rec) in records.iter().enumerate() {
        if let Some(k) = aemstep::spectrum::first_non_finite(rec) {
            let err = Fail::Lib(Error::NonFiniteInput, Some(k)).raise(py);
            let _ = err.value(py).setattr("record", i);
            return Err(err);
        }
    }
    Ok(())
}

/// A library error of a record-level call on `record`: `NonFiniteInput` gets the index of
/// the sample refused (`.step`), the library's [`first_non_finite`](aemstep::spectrum::first_non_finite).
fn on_record(record: &[f64]) -> impl Fn(Error) -> Fail + '_ {
    move |e| match e {
        Error::NonFiniteInput => Fail::Lib(e, aemstep::spectrum::first_non_finite(record)),
        e => Fail::Lib(e, None),
    }
}

/// The free-vibration tail after a record (`free_vibration`): one longest period of the
/// last bank (the longest periods), the same for every bank so that a period's result does
/// not depend on the bank it falls in; refused with `InvalidTimeStep` above
/// [`MAX_FREE_VIBRATION_SAMPLES`](aemstep::spectrum::MAX_FREE_VIBRATION_SAMPLES), as the
/// library's record-level calls do (a 3 s period at `h = 1e-300` asked for 2³² − 1 samples:
/// hours of stepping).
fn free_vibration_tail(free_vibration: bool, last: Option<&Bank<f64, CHUNK>>) -> Res<u32> {
    let n = match (free_vibration, last) {
        (true, Some(b)) => b.free_vibration_samples(),
        _ => 0,
    };
    if n > aemstep::spectrum::MAX_FREE_VIBRATION_SAMPLES {
        return Err(Error::InvalidTimeStep.into());
    }
    Ok(n)
}

/// Periods and damping checked (same length, periods non-decreasing) and cut into banks of
/// `CHUNK`, the last padded with copies of the last period.
fn chunks(periods: &[f64], damping: &[f64]) -> Res<Vec<([f64; CHUNK], [f64; CHUNK])>> {
    if periods.is_empty() || periods.len() != damping.len() {
        return shape(format!(
            "periods ({}) and damping ({}) must have the same nonzero length",
            periods.len(),
            damping.len()
        ));
    }
    // Across banks too (each bank checks its own): the order is the library's rule.
    if periods
        .windows(2)
        .any(|w| w[0].partial_cmp(&w[1]).is_none_or(|o| o.is_gt()))
    {
        return Err(Error::InvalidPeriod.into());
    }
    let last = periods.len() - 1;
    Ok(periods
        .chunks(CHUNK)
        .enumerate()
        .map(|(b, _)| {
            let at = |j: usize| (b * CHUNK + j).min(last);
            (
                core::array::from_fn(|j| periods[at(j)]),
                core::array::from_fn(|j| damping[at(j)]),
            )
        })
        .collect())
}

fn scheme_of(s: &str) -> PyResult<Scheme> {
    match s {
        "exact" => Ok(Scheme::Exact),
        "aem" => Ok(Scheme::Aem),
        other => Err(PyValueError::new_err(format!(
            "unknown spectrum scheme {other:?}: exact or aem"
        ))),
    }
}

/// `[sd, sv, sa, psv, psa]` of one record, one value per period.
type Spectrum = [Vec<f64>; 5];

/// Elastic response spectra of one or more records.
///
/// Arguments: `periods` — oscillator periods (s), non-decreasing, any count (stepped in
/// banks of 16); `damping` — damping ratios, one per period; `h` — sample interval of the
/// records (s); `records` — a list of 1-D arrays of ground acceleration (m/s²); `scheme` —
/// `"exact"` (piecewise exact, default) or `"aem"`; `free_vibration` — continue each
/// record in free vibration for one longest period (catches late peaks); `threads` —
/// threads of the work-stealing pool (0: all cores); `nan` — `"raise"` (a non-finite
/// sample raises `NonFiniteInput` with `.step`, its index, and `.record`) or `"skip"`
/// (held at the last finite sample, counted). Results are bit for bit the same on any
/// thread count. Ctrl-C stops the call within a fraction of a second.
///
/// Returns `(sd, sv, sa, psv, psa, skipped)`, each `records×periods`, and the skipped
/// samples per record: peak relative displacement (m), peak relative velocity (m/s), peak
/// absolute acceleration (m/s²), pseudo-velocity `ω·sd` (m/s), pseudo-acceleration `ω²·sd`
/// (m/s²).
#[pyfunction]
#[pyo3(signature = (periods, damping, h, records, scheme="exact", free_vibration=true, threads=1, nan="raise"))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn spectra<'py>(
    py: Python<'py>,
    periods: PyReadonlyArray1<'py, f64>,
    damping: PyReadonlyArray1<'py, f64>,
    h: f64,
    records: Vec<PyReadonlyArray1<'py, f64>>,
    scheme: &str,
    free_vibration: bool,
    threads: usize,
    nan: &str,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Vec<u64>,
)> {
    let scheme = scheme_of(scheme)?;
    let policy = non_finite_of(nan)?;
    let periods = read1(&periods);
    let damping = read1(&damping);
    let records: Vec<Vec<f64>> = records.iter().map(read1).collect();
    let slices: Vec<&[f64]> = records.iter().map(|r| r.as_slice()).collect();
    refuse_non_finite(py, policy, &slices)?;
    let np = periods.len();
    let run = |cancel: &std::sync::atomic::AtomicBool| -> Res<(Vec<Spectrum>, Vec<u64>)> {
        let banks = chunks(&periods, &damping)?
            .into_iter()
            .map(|(t, z)| {
                Bank::<f64, CHUNK>::with(t, z, h, scheme, Substeps::AUTO)
                    .map(|b| b.with_non_finite(policy))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let fv = free_vibration_tail(free_vibration, banks.last())?;
        let jobs: Vec<(usize, usize)> = (0..records.len())
            .flat_map(|r| (0..banks.len()).map(move |b| (r, b)))
            .collect();
        let stop = || cancel.load(std::sync::atomic::Ordering::Relaxed);
        let parts = batch::map(&jobs, threads, |&(r, b)| {
            let bank = &banks[b];
            let mut resp = bank.at_rest();
            // Unchecked steps (non-finite samples were refused above, or are skipped and
            // counted), the cancel flag looked at between chunks.
            for chunk in records[r].chunks(CANCEL_CHUNK) {
                if stop() {
                    break;
                }
                for &a in chunk {
                    bank.step(&mut resp, a);
                }
            }
            let mut left = fv;
            while left > 0 && !stop() {
                let n = left.min(CANCEL_CHUNK as u32);
                bank.free_vibration(&mut resp, n);
                left -= n;
            }
            let sd = *resp.sd();
            let part = (sd, *resp.sv(), *resp.sa(), bank.psv(&sd), bank.psa(&sd));
            // A finite sample that overflowed the response stays non-finite to the end
            // (`Bank::response`); a pseudo-spectral value that overflows is refused too.
            if !resp.is_finite() {
                Err(Error::NonFiniteState)
            } else if part.3.iter().chain(&part.4).all(|x| x.is_finite()) {
                Ok((part, resp.skipped()))
            } else {
                Err(Error::OperatorOverflow)
            }
        });
        let mut out: Vec<Spectrum> = (0..records.len()).map(|_| Default::default()).collect();
        let mut skipped = vec![0u64; records.len()];
        for (&(r, _), part) in jobs.iter().zip(parts) {
            let (part, s) = part?;
            skipped[r] = s;
            let o = &mut out[r];
            o[0].extend_from_slice(&part.0);
            o[1].extend_from_slice(&part.1);
            o[2].extend_from_slice(&part.2);
            o[3].extend_from_slice(&part.3);
            o[4].extend_from_slice(&part.4);
        }
        for o in &mut out {
            o.iter_mut().for_each(|v| v.truncate(np));
        }
        Ok((out, skipped))
    };
    let (out, skipped) = polled(py, run, || Ok(()))?;
    let take = |q: usize| {
        let v: Vec<f64> = out.iter().flat_map(|o| o[q].iter().copied()).collect();
        out2(py, v, np)
    };
    Ok((take(0), take(1), take(2), take(3), take(4), skipped))
}

/// RotD50 and RotD100 of two horizontal components.
///
/// Arguments: `periods` (s, non-decreasing), `damping` (one ratio per period), `h` (s),
/// `ax`, `ay` — the two components (m/s², same length and sample interval), `scheme`,
/// `free_vibration`, `threads`, `nan` as `spectra` (under `"raise"`, `.record` is 0 for
/// `ax`, 1 for `ay`). Rotation angles: 180 (1°).
///
/// Returns `(rotd50, rotd100, psa50, psa100, skipped)`: spectral displacements (m), the
/// median and the largest over the angles, their pseudo-accelerations `ω²·sd` (m/s²), and
/// the samples skipped in each component `(ax, ay)`.
#[pyfunction]
#[pyo3(signature = (periods, damping, h, ax, ay, scheme="exact", free_vibration=true, threads=1, nan="raise"))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn rotd<'py>(
    py: Python<'py>,
    periods: PyReadonlyArray1<'py, f64>,
    damping: PyReadonlyArray1<'py, f64>,
    h: f64,
    ax: PyReadonlyArray1<'py, f64>,
    ay: PyReadonlyArray1<'py, f64>,
    scheme: &str,
    free_vibration: bool,
    threads: usize,
    nan: &str,
) -> PyResult<(
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    (u64, u64),
)> {
    let scheme = scheme_of(scheme)?;
    let policy = non_finite_of(nan)?;
    let (periods, damping, ax, ay) = (read1(&periods), read1(&damping), read1(&ax), read1(&ay));
    refuse_non_finite(py, policy, &[&ax, &ay])?;
    let np = periods.len();
    let run = |cancel: &std::sync::atomic::AtomicBool| -> Res<([Vec<f64>; 4], (u64, u64))> {
        if ax.len() != ay.len() {
            return shape(format!(
                "ax ({}) and ay ({}) must have the same length",
                ax.len(),
                ay.len()
            ));
        }
        let banks = chunks(&periods, &damping)?
            .into_iter()
            .map(|(t, z)| {
                Bank::<f64, CHUNK>::with(t, z, h, scheme, Substeps::AUTO)
                    .map(|b| b.with_non_finite(policy))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let fv = free_vibration_tail(free_vibration, banks.last())?;
        let stop = || cancel.load(std::sync::atomic::Ordering::Relaxed);
        let angles = RotD::<f64, ROTD_ANGLES>::new();
        let parts = batch::map(&banks, threads, |bank| {
            let mut r = angles.at_rest(bank);
            for (cx, cy) in ax.chunks(CANCEL_CHUNK).zip(ay.chunks(CANCEL_CHUNK)) {
                if stop() {
                    break;
                }
                for (&x, &y) in cx.iter().zip(cy) {
                    angles.step(bank, &mut r, x, y);
                }
            }
            let mut left = fv;
            while left > 0 && !stop() {
                let n = left.min(CANCEL_CHUNK as u32);
                angles.free_vibration(bank, &mut r, n);
                left -= n;
            }
            let (d50, d100) = (r.rotd50(), r.rotd100());
            let part = (d50, d100, bank.psa(&d50), bank.psa(&d100));
            if !r.is_finite() {
                Err(Error::NonFiniteState)
            } else if part.2.iter().chain(&part.3).all(|x| x.is_finite()) {
                Ok((part, (r.x().skipped(), r.y().skipped())))
            } else {
                Err(Error::OperatorOverflow)
            }
        });
        let mut out: [Vec<f64>; 4] = Default::default();
        let mut skipped = (0, 0);
        for p in parts {
            let (p, s) = p?;
            skipped = s;
            out[0].extend_from_slice(&p.0);
            out[1].extend_from_slice(&p.1);
            out[2].extend_from_slice(&p.2);
            out[3].extend_from_slice(&p.3);
        }
        out.iter_mut().for_each(|v| v.truncate(np));
        Ok((out, skipped))
    };
    let ([a, b, c, d], skipped) = polled(py, run, || Ok(()))?;
    Ok((out1(py, a), out1(py, b), out1(py, c), out1(py, d), skipped))
}

// ---------------------------------------------------------------------------------------
// Inelastic spectra.

fn yielding_banks(
    periods: &[f64],
    damping: &[f64],
    alpha: f64,
    h: f64,
    points_per_period: u16,
    policy: aemstep::spectrum::NonFinite,
) -> Res<Vec<Yielding<f64, CHUNK>>> {
    Ok(chunks(periods, damping)?
        .into_iter()
        .map(|(t, z)| {
            Yielding::<f64, CHUNK>::with(
                t,
                z,
                alpha,
                h,
                Substeps::PointsPerPeriod(points_per_period),
            )
            .map(|y| y.with_non_finite(policy))
        })
        .collect::<Result<Vec<_>, _>>()?)
}

/// The constant-strength inelastic spectrum: ductility demand for given
/// strength-reduction factors.
///
/// Arguments: `periods` (s, initial, non-decreasing), `damping` (ratios on the initial
/// stiffness, one per period), `alpha` — post-yield stiffness ratio in [0, 1) (0:
/// elastic–perfectly plastic), `h` — sample interval (s), `ag` — ground acceleration
/// (m/s²), `reduction` — `R` per period (> 0), `points_per_period` — sub-steps rule (at
/// least this many points per initial period; 40 by default), `threads`, `nan` —
/// `"raise"` (`NonFiniteInput` with `.step`) or `"skip"`, as `spectra`. Ctrl-C stops the
/// call after the record passes running (two a bank).
///
/// Returns `(elastic, yield_acceleration, ductility, plastic_work, skipped)`: per period,
/// elastic strength per unit mass `ω² u_o` (m/s²), yield strength per unit mass
/// `elastic/R` (m/s²), ductility `max|u|/u_y`, plastic work per unit mass (m²/s²); and the
/// samples skipped.
#[pyfunction]
#[pyo3(signature = (periods, damping, alpha, h, ag, reduction, points_per_period=40, threads=1, nan="raise"))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn constant_strength<'py>(
    py: Python<'py>,
    periods: PyReadonlyArray1<'py, f64>,
    damping: PyReadonlyArray1<'py, f64>,
    alpha: f64,
    h: f64,
    ag: PyReadonlyArray1<'py, f64>,
    reduction: PyReadonlyArray1<'py, f64>,
    points_per_period: u16,
    threads: usize,
    nan: &str,
) -> PyResult<(
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    u64,
)> {
    let policy = non_finite_of(nan)?;
    let (periods, damping, ag, reduction) = (
        read1(&periods),
        read1(&damping),
        read1(&ag),
        read1(&reduction),
    );
    let np = periods.len();
    let run = |cancel: &std::sync::atomic::AtomicBool| -> Res<([Vec<f64>; 4], u64)> {
        if reduction.len() != np {
            return shape(format!(
                "reduction must have one factor per period ({np}), got {}",
                reduction.len()
            ));
        }
        let banks = yielding_banks(&periods, &damping, alpha, h, points_per_period, policy)?;
        let jobs: Vec<usize> = (0..banks.len()).collect();
        let last = np - 1;
        let parts = batch::map(&jobs, threads, |&b| {
            if cancel.load(std::sync::atomic::Ordering::Relaxed) {
                // Interrupted: the caller raises KeyboardInterrupt, this is dropped.
                return Err(Fail::Lib(Error::NonFiniteInput, None));
            }
            let r: [f64; CHUNK] = core::array::from_fn(|j| reduction[(b * CHUNK + j).min(last)]);
            banks[b].constant_strength(&ag, &r).map_err(on_record(&ag))
        });
        let mut out: [Vec<f64>; 4] = Default::default();
        let mut skipped = 0;
        for p in parts {
            let p = p?;
            skipped = p.response.skipped();
            out[0].extend_from_slice(&p.elastic);
            out[1].extend_from_slice(&p.yield_acceleration);
            out[2].extend_from_slice(&p.ductility);
            out[3].extend_from_slice(&p.plastic_work);
        }
        out.iter_mut().for_each(|v| v.truncate(np));
        Ok((out, skipped))
    };
    let ([a, b, c, d], skipped) = polled(py, run, || Ok(()))?;
    Ok((out1(py, a), out1(py, b), out1(py, c), out1(py, d), skipped))
}

/// `yield_acceleration, elastic, bracket, bracket ductility, outcome, passes, skipped`
/// (row-major).
type DuctilityOut = (
    Vec<f64>,
    Vec<f64>,
    Vec<f64>,
    Vec<f64>,
    Vec<&'static str>,
    u32,
    u64,
);

/// The constant-ductility inelastic spectrum: the largest strength giving a target
/// ductility (Chopra's convention when several do), by a grid bracket then a safeguarded
/// false-position refinement.
///
/// Arguments: as `constant_strength`, with `target` — the ductility `μ_t > 1` — instead of
/// `reduction`; `points`, `lowest`, `tol` — the search grid (points from the elastic
/// strength down to `lowest` times it) and the relative tolerance on the strength; `nan`
/// as `spectra`. Ctrl-C stops the search after the record pass running.
///
/// Returns a dict: `yield_acceleration` (m/s²), `elastic` (m/s²), `bracket` (`periods×2`,
/// m/s²), `bracket_ductility` (`periods×2`), `outcome` (list of `"converged"`,
/// `"no_crossing"`, `"not_converged"`), `passes` (record passes of the slowest bank),
/// `skipped` (samples skipped).
#[pyfunction]
#[pyo3(signature = (periods, damping, alpha, h, ag, target, points=60, lowest=0.01, tol=1e-6, points_per_period=40, threads=1, nan="raise"))]
#[allow(clippy::too_many_arguments)]
fn constant_ductility<'py>(
    py: Python<'py>,
    periods: PyReadonlyArray1<'py, f64>,
    damping: PyReadonlyArray1<'py, f64>,
    alpha: f64,
    h: f64,
    ag: PyReadonlyArray1<'py, f64>,
    target: f64,
    points: u16,
    lowest: f64,
    tol: f64,
    points_per_period: u16,
    threads: usize,
    nan: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let policy = non_finite_of(nan)?;
    let (periods, damping, ag) = (read1(&periods), read1(&damping), read1(&ag));
    let np = periods.len();
    let search = Search {
        points,
        lowest,
        tol,
    };
    let run = |cancel: &std::sync::atomic::AtomicBool| -> Res<DuctilityOut> {
        let banks = yielding_banks(&periods, &damping, alpha, h, points_per_period, policy)?;
        let parts = batch::map(&banks, threads, |bank| {
            let mut go_on = || !cancel.load(std::sync::atomic::Ordering::Relaxed);
            bank.constant_ductility_while(&ag, target, &search, &mut go_on)
                .map_err(on_record(&ag))
        });
        let (mut ay, mut el, mut br, mut mu, mut oc, mut passes, mut skipped) =
            (vec![], vec![], vec![], vec![], vec![], 0, 0);
        for p in parts {
            let p = p?;
            ay.extend_from_slice(&p.yield_acceleration);
            el.extend_from_slice(&p.elastic);
            br.extend(p.bracket.iter().flatten());
            mu.extend(p.ductility.iter().flatten());
            oc.extend(p.outcome.iter().map(|o| match o {
                Outcome::Converged => "converged",
                Outcome::NoCrossing => "no_crossing",
                Outcome::NotConverged => "not_converged",
            }));
            passes = passes.max(p.passes);
            skipped = p.skipped;
        }
        ay.truncate(np);
        el.truncate(np);
        br.truncate(2 * np);
        mu.truncate(2 * np);
        oc.truncate(np);
        Ok((ay, el, br, mu, oc, passes, skipped))
    };
    let (ay, el, br, mu, oc, passes, skipped) = polled(py, run, || Ok(()))?;
    let d = PyDict::new(py);
    d.set_item("yield_acceleration", out1(py, ay))?;
    d.set_item("elastic", out1(py, el))?;
    d.set_item("bracket", out2(py, br, 2))?;
    d.set_item("bracket_ductility", out2(py, mu, 2))?;
    d.set_item("outcome", oc)?;
    d.set_item("passes", passes)?;
    d.set_item("skipped", skipped)?;
    Ok(d)
}

// ---------------------------------------------------------------------------------------
// Observers on recorded data.

struct ObserveJob {
    m: Vec<f64>,
    c: Vec<f64>,
    k: Vec<f64>,
    h: f64,
    ag: Vec<f64>,
    y: Vec<f64>,
    sensors: Vec<usize>,
    sigma_f: f64,
    sigma_y: f64,
    kalman: bool,
}

/// Estimates `x̂ = [u; v]` per step (row-major, steps × 2n) and the steady-state gain
/// (2n × sensors; empty for the Kalman filter).
type ObserveOut = (Vec<f64>, Vec<f64>);

fn observe_no<const N: usize, const S: usize, const O: usize>(
    job: &ObserveJob,
    stop: &AtomicBool,
) -> Res<ObserveOut> {
    let (m, c, k) = (
        matrix::<N>(&job.m),
        matrix::<N>(&job.c),
        matrix::<N>(&job.k),
    );
    let b = SMatrix::<f64, N, 1>::from_fn(|i, _| -(0..N).map(|j| m[(i, j)]).sum::<f64>());
    let model = StateSpace::<N, S, 1>::aem(&m, &c, &k, &b, job.h)?;
    let sensors: [usize; O] = core::array::from_fn(|o| job.sensors[o]);
    let meas = model.outputs(&Outputs::absolute_accelerations(
        Outputs::<N, 1, O>::select(sensors),
        0,
    ))?;
    // Process noise: white forces of standard deviation sigma_f on every floor.
    let forces = StateSpace::<N, S, N>::aem(&m, &c, &k, &SMatrix::identity(), job.h)?;
    let mut qf = [[0.0; N]; N];
    (0..N).for_each(|i| qf[i][i] = job.sigma_f * job.sigma_f);
    let q = SMatrix::<f64, S, S>::from_fn(|i, j| forces.input_noise(&qf)[i][j]);
    let r = SMatrix::<f64, O, O>::identity() * (job.sigma_y * job.sigma_y);
    let steps = job.ag.len();
    let w = |n: usize| SVector::<f64, 1>::from([job.ag[n]]);
    let y = |n: usize| SVector::<f64, O>::from_column_slice(&job.y[n * O..(n + 1) * O]);
    let mut x = buffer(steps, S)?;
    if job.kalman {
        let filter = Kalman::<f64, S, 1, O>::new(&model, &meas, &q, &r)?;
        let mut s = filter
            .start(&SVector::zeros(), &SMatrix::zeros(), &w(0))
            .map_err(at(0))?;
        x.extend_from_slice(s.estimate().x().as_slice());
        for n in 1..steps {
            stopped(stop, n)?;
            filter.try_step(&mut s, &w(n), &y(n)).map_err(at(n))?;
            x.extend_from_slice(s.estimate().x().as_slice());
        }
        Ok((x, vec![]))
    } else {
        let gain = SteadyState::new(&model, &meas, &q, &r)?;
        let obs = Observer::<f64, S, 1, O>::new(&model, &meas, &gain.gain_matrix())?;
        let mut e = obs.start_at_rest(&w(0)).map_err(at(0))?;
        x.extend_from_slice(e.x().as_slice());
        for n in 1..steps {
            stopped(stop, n)?;
            obs.try_step(&mut e, &w(n), &y(n)).map_err(at(n))?;
            x.extend_from_slice(e.x().as_slice());
        }
        Ok((x, gain.gain.iter().flatten().copied().collect()))
    }
}

fn observe_n<const N: usize, const S: usize>(
    job: &ObserveJob,
    stop: &AtomicBool,
) -> Res<ObserveOut> {
    match job.sensors.len() {
        1 => observe_no::<N, S, 1>(job, stop),
        2 if N >= 2 => observe_no::<N, S, 2>(job, stop),
        3 if N >= 3 => observe_no::<N, S, 3>(job, stop),
        _ => observe_any(job, N, stop),
    }
}

/// The observers at a run-time size (`DynStateSpace`, `DynSteadyState`, `DynObserver`,
/// `DynKalman`: the compiled path's arithmetic, so at a compiled size the same numbers),
/// for sizes and sensor counts the compiled path does not take.
fn observe_any(job: &ObserveJob, n: usize, stop: &AtomicBool) -> Res<ObserveOut> {
    let o = job.sensors.len();
    let dm = |a: &[f64]| DMatrix::from_row_slice(n, n, a);
    let (m, c, k) = (dm(&job.m), dm(&job.c), dm(&job.k));
    let b = DMatrix::from_fn(n, 1, |i, _| -(0..n).map(|j| m[(i, j)]).sum::<f64>());
    let model = DynStateSpace::aem(&m, &c, &k, &b, job.h)?;
    let meas = model.absolute_accelerations(&job.sensors, 0)?;
    // Process noise: white forces of standard deviation sigma_f on every floor.
    let forces = DynStateSpace::aem(&m, &c, &k, &DMatrix::identity(n, n), job.h)?;
    let qf = DMatrix::identity(n, n) * (job.sigma_f * job.sigma_f);
    let q = forces.input_noise(&qf)?;
    let r = DMatrix::identity(o, o) * (job.sigma_y * job.sigma_y);
    let steps = job.ag.len();
    if job.kalman {
        let filter = DynKalman::<f64>::new(&model, &meas, &q, &r)?;
        let mut x = buffer(steps, 2 * n)?;
        let mut s = filter
            .start(
                &vec![0.0; 2 * n],
                &DMatrix::zeros(2 * n, 2 * n),
                &[job.ag[0]],
            )
            .map_err(at(0))?;
        x.extend_from_slice(s.estimate().x());
        for i in 1..steps {
            // A step is O(S³) here: the flag is looked at every step.
            if stop.load(Ordering::Relaxed) {
                return Err(Fail::Cancelled);
            }
            filter
                .try_step(&mut s, &[job.ag[i]], &job.y[i * o..(i + 1) * o])
                .map_err(at(i))?;
            x.extend_from_slice(s.estimate().x());
        }
        return Ok((x, vec![]));
    }
    // The gain solve looks at the stop flag before each piece (`10 S³` flops at most).
    let gain =
        DynSteadyState::new_with_stop(&model, &meas, &q, &r, &mut || stop.load(Ordering::Relaxed))?;
    let obs = DynObserver::<f64>::new(&model, &meas, &gain.gain_matrix())?;
    let mut x = buffer(steps, 2 * n)?;
    let mut e = obs.start_at_rest(&[job.ag[0]]).map_err(at(0))?;
    x.extend_from_slice(e.x());
    for i in 1..steps {
        stopped(stop, i)?;
        obs.try_step(&mut e, &[job.ag[i]], &job.y[i * o..(i + 1) * o])
            .map_err(at(i))?;
        x.extend_from_slice(e.x());
    }
    Ok((x, gain.gain().to_vec()))
}

/// Estimate the state of a linear building from measured absolute floor accelerations:
/// the AEM model's fixed-gain observer with the steady-state Kalman gain, or the full
/// Kalman filter (covariance propagated; started at rest with zero covariance).
///
/// Arguments: `m`, `c`, `k` (kg, N·s/m, N/m; `n×n`), `h` — sample interval (s), `ag` —
/// the measured ground acceleration (m/s², the model's input), `measured` — absolute
/// accelerations (m/s²) of the floors `sensors` (0-based DOF indices), `steps×sensors`
/// (NaN: a missing sample, the correction skipped); `sigma_f` — process noise, the
/// standard deviation of white forces on every floor (N); `sigma_y` — accelerometer noise
/// (m/s²); `kalman` — the full filter instead of the steady-state gain.
///
/// Returns `(u, v, gain)`: estimated displacements (m) and velocities (m/s), `steps×n`,
/// relative to the ground, and the steady-state gain (`2n×sensors`; empty for the
/// Kalman filter). Raises `InvalidCovariance`, `RiccatiNotConverged`, …
///
/// Sizes: both take any `n` and any number of sensors (outside the compiled sizes and 1–3
/// sensors on the run-time-sized `DynObserver` / `DynKalman`, the same arithmetic: equal
/// results where both serve).
#[pyfunction]
#[pyo3(signature = (m, c, k, h, ag, measured, sensors, sigma_f, sigma_y, kalman=false))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn observe<'py>(
    py: Python<'py>,
    m: PyReadonlyArray2<'py, f64>,
    c: PyReadonlyArray2<'py, f64>,
    k: PyReadonlyArray2<'py, f64>,
    h: f64,
    ag: PyReadonlyArray1<'py, f64>,
    measured: PyReadonlyArray2<'py, f64>,
    sensors: Vec<usize>,
    sigma_f: f64,
    sigma_y: f64,
    kalman: bool,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
)> {
    let prepare = || -> Res<(ObserveJob, usize)> {
        let n = m.as_array().dim().0;
        if n > MAX_OBSERVE_DOFS {
            return shape(format!(
                "observe takes models of at most MAX_OBSERVE_DOFS = {MAX_OBSERVE_DOFS} DOFs, got n = {n}: reduce the model (e.g. to its lowest modes) first"
            ));
        }
        // The estimate (2n a step) and its split into u and v, checked before allocating.
        let steps = ag.as_array().dim();
        fits("observe", &[(steps, 2 * n), (steps, n), (steps, n)])?;
        let ag = read1(&ag);
        let (y, r, cols) = read2(&measured);
        if ag.is_empty() || r != ag.len() || cols != sensors.len() {
            return shape(format!(
                "measured must be {} x {} (one row per ground-acceleration sample, one column per sensor), got {r}x{cols}",
                ag.len(),
                sensors.len()
            ));
        }
        if sensors.is_empty() || sensors.iter().any(|&s| s >= n) {
            return shape(format!(
                "sensors must be 1 or more floor indices in 0..{n}, got {sensors:?}"
            ));
        }
        let mut sorted = sensors.clone();
        sorted.sort_unstable();
        sorted.dedup();
        if sorted.len() != sensors.len() {
            return shape(format!("sensors must be distinct, got {sensors:?}"));
        }
        Ok((
            ObserveJob {
                m: square(&m, n, "m")?,
                c: square(&c, n, "c")?,
                k: square(&k, n, "k")?,
                h,
                ag,
                y,
                sensors: sensors.clone(),
                sigma_f,
                sigma_y,
                kalman,
            },
            n,
        ))
    };
    let (job, n) = prepare().map_err(|f| f.raise(py))?;
    let (x, gain) = interruptible(
        py,
        // A step is up to `n³` units (the Kalman filter's), the gain solve about `2400 n³`.
        work_units(job.ag.len().saturating_add(2400), n, 3),
        |stop| by_size!(n, observe_n(&job, stop) else observe_any(&job, n, stop)),
    )?;
    let steps = job.ag.len();
    let (mut u, mut v) = (
        buffer(steps, n).map_err(|f| f.raise(py))?,
        buffer(steps, n).map_err(|f| f.raise(py))?,
    );
    for row in x.chunks(2 * n) {
        u.extend_from_slice(&row[..n]);
        v.extend_from_slice(&row[n..]);
    }
    Ok((
        out2(py, u, n),
        out2(py, v, n),
        out2(py, gain, job.sensors.len()),
    ))
}

// Sections in their own files (after the macros above, which they use).
mod control;
mod ida;
mod laws;
mod records;

/// The native module: functions, exception classes and the compiled limits.
#[pymodule]
fn _aemstep(m: &Bound<'_, PyModule>) -> PyResult<()> {
    register_exceptions(m)?;
    m.add("SIZES", SIZES.to_vec())?;
    m.add("CHUNK", CHUNK)?;
    m.add("MAX_SENSORS", MAX_SENSORS)?;
    m.add("MAX_OBSERVE_DOFS", MAX_OBSERVE_DOFS)?;
    m.add("MAX_TRUNCATED_MODES", MAX_TRUNCATED_MODES)?;
    m.add("ROTD_ANGLES", ROTD_ANGLES)?;
    m.add_function(wrap_pyfunction!(linear_response, m)?)?;
    m.add_function(wrap_pyfunction!(shear_building, m)?)?;
    m.add_function(wrap_pyfunction!(spectra, m)?)?;
    m.add_function(wrap_pyfunction!(rotd, m)?)?;
    m.add_function(wrap_pyfunction!(constant_strength, m)?)?;
    m.add_function(wrap_pyfunction!(constant_ductility, m)?)?;
    m.add_function(wrap_pyfunction!(observe, m)?)?;
    records::register(m)?;
    ida::register(m)?;
    control::register(m)?;
    Ok(())
}
