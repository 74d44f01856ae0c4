//! Incremental dynamic analysis of the yielding shear building (`aemstep::ida`): every
//! record of a suite scaled by an intensity (the record scale factor), the peak absolute
//! storey drift of each run, the runs on fixed stripes or traced by hunt-and-fill, and the
//! fractile curves.
//!
//! **Progress without the GIL.** The library calls its progress callback on the worker
//! threads, where Python must not be called. The batch runs instead on a scoped background
//! thread (which drives the library's pool) while the Python thread waits with the GIL
//! released, waking every [`POLL`](crate::POLL) to read an atomic counter, call the user's
//! `progress(done, total)` and check for signals (Ctrl-C). A raised exception (from the
//! callback or a `KeyboardInterrupt`) sets a cancel flag that makes every later run of the
//! batch return at once (the loads of the runs going turn NaN, which ends them at their
//! next step); the exception is raised when the batch has wound down.
//!
//! **Many runs at once.** The runs go [`LANES`] at a time through `aemstep::ida::batched`,
//! one a SIMD lane of `aemstep::lanes::LaneStepper` (stripes: a stripe's records side by
//! side; hunt-and-fill: [`LANES`] records' traces side by side), every law of the package. Each
//! lane is bit for bit the single run of `shear_building`, so the curves are those of the
//! serial one-run-at-a-time IDA, bit for bit, on any thread count; a run that fails does
//! not stop the others of its batch, and the collapse and abort rules are the library's.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use aemstep::hysteresis::ShearBuilding;
use aemstep::ida::{self, Collapse, Curve, HuntFill, OnFailure, Point};
use aemstep::lanes::{LaneLaw, LaneState, LaneStepper};
use aemstep::{Error, NewtonSettings, Param};
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::laws::{self, WithLaws};
use crate::{Fail, Res, SIZES, out1, out2, read1, read2, rows, shape, square};

/// Analyses stepped together by [`LaneStepper`], one a lane: `f64 × 8`, one AVX-512
/// register where the CPU has it (two AVX ones, four SSE2 ones otherwise). The width
/// `xtask/benches/lanes.rs` measures fastest on the 880-analysis IDA since the lane step
/// takes AVX-512 for lane arrays that fill a 512-bit register (`docs/performance.md`,
/// lanes): 8 lanes are as fast as 4 on AVX alone, faster with AVX-512; 110 batches of the
/// IDA to share between threads.
const LANES: usize = 8;

/// The intensities to run: fixed stripes, or a hunt-and-fill trace.
enum Plan {
    Stripes(Vec<f64>),
    HuntFill(HuntFill),
}

/// One IDA batch: the building (as `shear_building` takes it), the records and the plan.
struct IdaJob {
    records: Vec<Vec<f64>>,
    h: f64,
    masses: Vec<f64>,
    law: String,
    params: Vec<f64>,
    width: usize,
    c: Vec<f64>,
    settings: NewtonSettings<f64>,
    collapse: Collapse,
    plan: Plan,
    threads: usize,
}

impl IdaJob {
    /// The progress total: runs of the stripes, or the hunt-and-fill budget.
    fn total(&self) -> usize {
        let per = match &self.plan {
            Plan::Stripes(ims) => ims.len(),
            Plan::HuntFill(s) => s.runs,
        };
        self.records.len().saturating_mul(per)
    }
}

/// A run of the IDA: `(record, scale factor)`.
type Run<'a> = (&'a Vec<f64>, f64);

/// The peak absolute storey drift (m) of every run of `jobs`, [`LANES`] runs at a time in
/// the lanes of `lanes`: each run is that of `shear_building` (from rest, the load of
/// `ag[n] × scale` at step `n`, every sample; same start, same steps, bit for bit, see
/// `aemstep::lanes`), its drifts `u_i − u_{i−1}` (`u_{−1} = 0`) over the storeys and steps;
/// a run that fails gives its error, the other lanes going on. Once `cancel` is set the
/// loads turn NaN (looked at every [`STOP_EVERY`](crate::STOP_EVERY) steps), which ends
/// every lane at its next step, and the runs give `InvalidParameter(Cancelled)` (the batch
/// is being abandoned; the values are discarded).
fn peak_drifts<const N: usize, L: LaneLaw<f64>>(
    building: &ShearBuilding<f64, L, N>,
    lanes: &LaneStepper<f64, N, LANES>,
    jobs: &[Run<'_>],
    cancel: &AtomicBool,
) -> Vec<Result<f64, Error>> {
    let cancelled = Error::InvalidParameter(Param::Cancelled);
    let mut out = Vec::with_capacity(jobs.len());
    for group in jobs.chunks(LANES) {
        let steps: [u64; LANES] = core::array::from_fn(|l| {
            group
                .get(l)
                .map_or(0, |j| j.0.len().saturating_sub(1) as u64)
        });
        let mut peak = [0.0f64; LANES];
        let ground = |l: usize, n: u64| {
            let n = usize::try_from(n).unwrap_or(usize::MAX);
            if crate::stopped(cancel, n).is_err() {
                return f64::NAN;
            }
            group
                .get(l)
                .and_then(|&(ag, scale)| ag.get(n).map(|a| a * scale))
                .unwrap_or(0.0)
        };
        // Storey by storey over all lanes at once (packed), a lane that did not step
        // keeping its peak: the same maxima in the same order as lane by lane.
        let observe = |state: &LaneState<f64, N, LANES>, stepped: &[bool; LANES]| {
            let mut below = [0.0f64; LANES];
            for ui in state.u() {
                for l in 0..LANES {
                    let p = peak[l].max((ui[l] - below[l]).abs());
                    peak[l] = if stepped[l] { p } else { peak[l] };
                    below[l] = ui[l];
                }
            }
        };
        let outcome = lanes.run(building, steps, ground, observe);
        for (o, &p) in outcome.iter().zip(&peak).take(group.len()) {
            out.push(match o {
                Ok(()) => Ok(p),
                Err(_) if cancel.load(Ordering::Relaxed) => Err(cancelled),
                Err(f) => Err(f.error),
            });
        }
    }
    out
}

/// The batch on the `N` laws.
struct Batch<'a> {
    job: &'a IdaJob,
    progress: &'a (dyn Fn(usize, usize) + Sync),
    cancel: &'a AtomicBool,
}

impl<const N: usize> WithLaws<N> for Batch<'_> {
    type Out = Vec<Curve>;
    fn run<L: LaneLaw<f64> + Send + Sync>(self, laws: [L; N]) -> Res<Vec<Curve>> {
        let job = self.job;
        let masses: [f64; N] = core::array::from_fn(|i| job.masses[i]);
        let building = ShearBuilding::<f64, L, N>::new(masses, laws, &rows::<N>(&job.c))?;
        let lanes = LaneStepper::<f64, N, LANES>::new(job.h, job.settings)?;
        let cancel = self.cancel;
        let analysis = |jobs: &[Run<'_>]| peak_drifts(&building, &lanes, jobs, cancel);
        run_plan(job, &analysis, self.progress)
    }
}

/// A batch of runs of the analysis: up to [`LANES`] `(record, scale factor)` → their peak
/// drifts, in order.
type Analysis<'a> = &'a (dyn Fn(&[Run<'_>]) -> Vec<Result<f64, Error>> + Sync);

/// The plan on the library's pool, [`LANES`] runs a batch (`aemstep::ida::batched`: the
/// curves of `stripes` or `hunt_fill`, bit for bit). Not generic: one copy of the batch
/// machinery for every size and law (only `peak_drifts` is per size and law), which keeps
/// the module's build time and size down; the dynamic call is one per batch of thousands
/// of steps.
fn run_plan(
    job: &IdaJob,
    analysis: Analysis<'_>,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Res<Vec<Curve>> {
    let plan = match &job.plan {
        Plan::Stripes(ims) => ida::Plan::Stripes {
            intensities: ims,
            collapse: job.collapse,
        },
        Plan::HuntFill(s) => ida::Plan::HuntFill(*s),
    };
    let how = ida::Batching {
        width: LANES,
        threads: job.threads,
        progress: Some(progress),
    };
    Ok(ida::batched(&job.records, &plan, &how, analysis)?)
}

fn batch_n<const N: usize, const S: usize>(
    job: &IdaJob,
    progress: &(dyn Fn(usize, usize) + Sync),
    cancel: &AtomicBool,
) -> Res<Vec<Curve>> {
    laws::with_laws::<N, _>(
        &job.law,
        &job.params,
        job.width,
        Batch {
            job,
            progress,
            cancel,
        },
    )
}

/// Runs the batch on a background thread (the crate's [`polled`](crate::polled)), the GIL
/// released except at each poll, where `progress(done, total)` is called (when `done`
/// moved) and signals are checked.
fn run_polled(
    py: Python<'_>,
    job: &IdaJob,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<Vec<Curve>> {
    let n = job.masses.len();
    let total = job.total();
    let done = AtomicUsize::new(0);
    let tick = |d: usize, _total: usize| {
        done.fetch_max(d, Ordering::Relaxed);
    };
    let mut reported = 0usize;
    crate::polled(
        py,
        |cancel| by_size!(n, batch_n(job, &tick, cancel)),
        || {
            let d = done.load(Ordering::Relaxed);
            let call = match progress {
                Some(f) if d != reported => f.call1((d, total)).map(|_| ()),
                _ => Ok(()),
            };
            reported = d;
            call
        },
    )
}

fn on_failure_of(s: &str) -> PyResult<OnFailure> {
    match s {
        "collapse" => Ok(OnFailure::Collapse),
        "abort" => Ok(OnFailure::Abort),
        other => Err(PyValueError::new_err(format!(
            "unknown on_failure {other:?}: \"collapse\" or \"abort\""
        ))),
    }
}

/// The building and records checked and copied; `plan` and `collapse` as given.
#[allow(clippy::too_many_arguments)]
fn prepare(
    records: &[PyReadonlyArray1<'_, f64>],
    h: f64,
    masses: &PyReadonlyArray1<'_, f64>,
    law: &str,
    width: usize,
    params: &PyReadonlyArray2<'_, f64>,
    c: &PyReadonlyArray2<'_, f64>,
    max_iterations: u32,
    tolerance: f64,
    collapse: Collapse,
    plan: Plan,
    threads: usize,
) -> Res<IdaJob> {
    let masses = read1(masses);
    let n = masses.len();
    if !SIZES.contains(&n) {
        return Err(Fail::Size(format!(
            "{n} storeys: this build supports n in {SIZES:?}"
        )));
    }
    let (p, r, cols) = read2(params);
    if r != n || cols != width {
        return shape(format!(
            "params must be {n}x{width} for law {law:?} and {n} storeys, got {r}x{cols}"
        ));
    }
    let records: Vec<Vec<f64>> = records.iter().map(read1).collect();
    if let Some(i) = records.iter().position(|r| r.is_empty()) {
        return shape(format!("record {i} has no samples"));
    }
    Ok(IdaJob {
        records,
        h,
        masses,
        law: law.to_owned(),
        params: p,
        width,
        c: square(c, n, "c")?,
        settings: NewtonSettings::up_to(max_iterations, tolerance),
        collapse,
        plan,
        threads,
    })
}

/// The collapse rule of the Python arguments: `collapse_drift` (m, `None`: never by drift)
/// and `on_failure` (`"collapse"` or `"abort"`).
fn collapse_of(collapse_drift: Option<f64>, on_failure: &str) -> PyResult<Collapse> {
    Ok(Collapse {
        edp: collapse_drift.unwrap_or(f64::INFINITY),
        on_failure: on_failure_of(on_failure)?,
    })
}

/// What `ida_stripes` and `ida_hunt_fill` share after reading their plan: the law name
/// checked, the job gathered (`prepare`), run with the GIL released and polled for
/// progress (`run_polled`), the curves as dicts (`curves_out`).
#[allow(clippy::too_many_arguments)]
fn run<'py>(
    py: Python<'py>,
    records: &[PyReadonlyArray1<'py, f64>],
    h: f64,
    masses: &PyReadonlyArray1<'py, f64>,
    law: &str,
    params: &PyReadonlyArray2<'py, f64>,
    c: &PyReadonlyArray2<'py, f64>,
    max_iterations: u32,
    tolerance: f64,
    collapse: Collapse,
    plan: Plan,
    threads: usize,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyList>> {
    let width = laws::known_law(law)?;
    let job = prepare(
        records,
        h,
        masses,
        law,
        width,
        params,
        c,
        max_iterations,
        tolerance,
        collapse,
        plan,
        threads,
    )
    .map_err(|f| f.raise(py))?;
    let curves = run_polled(py, &job, progress)?;
    curves_out(py, curves)
}

/// The curves as dicts: `intensity`, `drift`, `collapsed`, `collapse`, `error`.
fn curves_out<'py>(py: Python<'py>, curves: Vec<Curve>) -> PyResult<Bound<'py, PyList>> {
    let list = PyList::empty(py);
    for c in curves {
        let d = PyDict::new(py);
        let pts = &c.points;
        d.set_item(
            "intensity",
            out1(py, pts.iter().map(|p| p.intensity).collect()),
        )?;
        d.set_item("drift", out1(py, pts.iter().map(|p| p.edp).collect()))?;
        let collapsed: Vec<bool> = pts.iter().map(|p| p.collapsed).collect();
        d.set_item("collapsed", collapsed.into_pyarray(py))?;
        d.set_item("collapse", c.collapse.map(|[lo, hi]| (lo, hi)))?;
        // The variant's name (its Debug form up to a field list, e.g. `NotConverged`).
        let errors: Vec<Option<String>> = pts
            .iter()
            .map(|p| {
                p.error.map(|e| {
                    format!("{e:?}")
                        .split([' ', '{', '('])
                        .next()
                        .unwrap_or("")
                        .to_owned()
                })
            })
            .collect();
        d.set_item("error", errors)?;
        list.append(d)?;
    }
    Ok(list)
}

/// The IDA curves of a suite of records on fixed stripes of intensity: every record scaled
/// by every intensity, each run the yielding shear building of `shear_building`.
///
/// Arguments: `records` — ground accelerations (m/s²), 1-D, sampled every `h` s;
/// `intensities` — the record scale factors (finite, `> 0`, any order); `masses`, `law`,
/// `params`, `c`, `max_iterations`, `tolerance` — the building and its Newton settings, as
/// `shear_building`; `collapse_drift` — the peak storey drift (m, `> 0`; `None` or `inf`:
/// never) at or above which a run has collapsed; `on_failure` — `"collapse"` (a run whose analysis
/// fails, e.g. `NotConverged`, is a collapse with drift `inf`) or `"abort"` (the first
/// failure in (record, intensity) order is raised); `threads` (0: all cores); `progress` —
/// `None` or a callable `progress(done, total)` called from this thread about every 0.1 s
/// while the runs go (`total = records × intensities`).
///
/// Returns one dict per record: `intensity` (sorted), `drift` (peak absolute storey drift,
/// m), `collapsed` (bool), `error` (the error name of a failed run counted as collapse, or
/// `None`), `collapse` (`(lo, hi)`: the highest non-collapsing intensity below the lowest
/// collapsing one, that lowest; `None` if none collapsed). Bit for bit the same on any
/// thread count. The GIL is released while the runs go.
#[pyfunction]
#[pyo3(signature = (records, h, intensities, masses, law, params, c, max_iterations=20, tolerance=1e-10, collapse_drift=None, on_failure="collapse", threads=0, progress=None))]
#[allow(clippy::too_many_arguments)]
fn ida_stripes<'py>(
    py: Python<'py>,
    records: Vec<PyReadonlyArray1<'py, f64>>,
    h: f64,
    intensities: PyReadonlyArray1<'py, f64>,
    masses: PyReadonlyArray1<'py, f64>,
    law: &str,
    params: PyReadonlyArray2<'py, f64>,
    c: PyReadonlyArray2<'py, f64>,
    max_iterations: u32,
    tolerance: f64,
    collapse_drift: Option<f64>,
    on_failure: &str,
    threads: usize,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyList>> {
    let collapse = collapse_of(collapse_drift, on_failure)?;
    let plan = Plan::Stripes(read1(&intensities));
    run(
        py,
        &records,
        h,
        &masses,
        law,
        &params,
        &c,
        max_iterations,
        tolerance,
        collapse,
        plan,
        threads,
        progress.as_ref(),
    )
}

/// The hunt-and-fill IDA curves of a suite of records (Vamvatsikos & Cornell 2002): per
/// record, intensities (record scale factors) `first`, `first + step`, … with the step
/// growing by `step_increment` a run until a run collapses, then bisection of the collapse
/// bracket down to `resolution`, then the largest gaps below it filled, `runs` analyses at
/// most a record.
///
/// Arguments: as `ida_stripes`, with `first`, `step` (`> 0`), `step_increment` (`≥ 0`),
/// `resolution` (`> 0`; all scale factors) and `runs` (1 to 10 000) instead of
/// `intensities`; `progress(done, total)` with `total = records × runs` (a record that ends
/// early counts its unused runs at once).
///
/// Returns the dicts of `ida_stripes`, at most `runs` points each. Raises
/// `InvalidParameter` for settings out of range (before any run), the library's errors
/// with `on_failure="abort"`.
#[pyfunction]
#[pyo3(signature = (records, h, masses, law, params, c, max_iterations=20, tolerance=1e-10, first=0.1, step=0.2, step_increment=0.1, resolution=0.05, runs=12, collapse_drift=None, on_failure="collapse", threads=0, progress=None))]
#[allow(clippy::too_many_arguments)]
fn ida_hunt_fill<'py>(
    py: Python<'py>,
    records: Vec<PyReadonlyArray1<'py, f64>>,
    h: f64,
    masses: PyReadonlyArray1<'py, f64>,
    law: &str,
    params: PyReadonlyArray2<'py, f64>,
    c: PyReadonlyArray2<'py, f64>,
    max_iterations: u32,
    tolerance: f64,
    first: f64,
    step: f64,
    step_increment: f64,
    resolution: f64,
    runs: i64,
    collapse_drift: Option<f64>,
    on_failure: &str,
    threads: usize,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyList>> {
    let collapse = collapse_of(collapse_drift, on_failure)?;
    // A budget outside 1..=10 000 (negative too) is the library's InvalidParameter.
    let runs = usize::try_from(runs).unwrap_or(0);
    let plan = Plan::HuntFill(HuntFill {
        first,
        step,
        step_increment,
        resolution,
        runs,
        collapse,
    });
    run(
        py,
        &records,
        h,
        &masses,
        law,
        &params,
        &c,
        max_iterations,
        tolerance,
        collapse,
        plan,
        threads,
        progress.as_ref(),
    )
}

/// The fractile IDA curves: for each quantile `q[k]` and drift level `drifts[j]`, the
/// `q[k]` quantile over the records of the intensity at which each curve first reaches
/// `drifts[j]` (`aemstep::ida::fractiles`: the non-collapsing points below the collapse
/// joined by straight lines from the origin; a collapsed curve flat past its last point;
/// numpy's default linear quantile; `NaN` where records censored at that level decide it).
///
/// Arguments: `intensity`, `drift`, `collapsed` — one array per curve (as the dicts of
/// `ida_stripes`), `drifts` — the levels (m, finite, `≥ 0`), `q` — in `[0, 1]`.
/// Returns `len(q) × len(drifts)` intensities. Raises `InvalidParameter` for no curves,
/// bad levels or quantiles, `ShapeError` for a curve whose arrays differ in length.
#[pyfunction]
fn ida_fractiles<'py>(
    py: Python<'py>,
    intensity: Vec<PyReadonlyArray1<'py, f64>>,
    drift: Vec<PyReadonlyArray1<'py, f64>>,
    collapsed: Vec<PyReadonlyArray1<'py, bool>>,
    drifts: PyReadonlyArray1<'py, f64>,
    q: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let build = || -> Res<Vec<Curve>> {
        if intensity.len() != drift.len() || intensity.len() != collapsed.len() {
            return shape("intensity, drift and collapsed must hold one array per curve".into());
        }
        let mut curves = Vec::with_capacity(intensity.len());
        for (k, ((im, e), c)) in intensity.iter().zip(&drift).zip(&collapsed).enumerate() {
            let (im, e) = (read1(im), read1(e));
            let c: Vec<bool> = c.as_array().iter().copied().collect();
            if im.len() != e.len() || im.len() != c.len() {
                return shape(format!(
                    "curve {k}: intensity ({}), drift ({}) and collapsed ({}) differ in length",
                    im.len(),
                    e.len(),
                    c.len()
                ));
            }
            let points = im
                .iter()
                .zip(&e)
                .zip(&c)
                .map(|((&intensity, &edp), &collapsed)| Point {
                    intensity,
                    edp,
                    collapsed,
                    error: None,
                })
                .collect();
            curves.push(Curve::from_points(points));
        }
        Ok(curves)
    };
    let curves = build().map_err(|f| f.raise(py))?;
    let (levels, q) = (read1(&drifts), read1(&q));
    let out = ida::fractiles(&curves, &levels, &q).map_err(|e| Fail::from(e).raise(py))?;
    // quantile-major, `len(q) × len(drifts)`: the array the Python API has always returned
    Ok(out2(py, out.as_slice().to_vec(), levels.len()))
}

/// `spectral_acceleration(record, h, period, damping)`: the pseudo-spectral acceleration
/// `Sa = ω² max|u|` (the record's units) of the damped oscillator of `period` (s) and
/// `damping` (ratio) under `record` (sampled every `h` s), with one period of free
/// vibration after it: `aemstep::ida::spectral_acceleration`, the intensity measure
/// `Sa(T₁)` of the IDA calls. The GIL is released during the pass (one oscillator over the
/// record). Raises `NonFiniteInput` for a sample that is not finite, `InvalidPeriod`,
/// `InvalidDamping`, `InvalidTimeStep`, `NonFiniteState`, `OperatorOverflow`.
#[pyfunction]
fn spectral_acceleration(
    py: Python<'_>,
    record: PyReadonlyArray1<'_, f64>,
    h: f64,
    period: f64,
    damping: f64,
) -> PyResult<f64> {
    let rec = read1(&record);
    py.detach(|| ida::spectral_acceleration(&rec, h, period, damping))
        .map_err(|e| Fail::from(e).raise(py))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(spectral_acceleration, m)?)?;
    m.add_function(wrap_pyfunction!(ida_stripes, m)?)?;
    m.add_function(wrap_pyfunction!(ida_hunt_fill, m)?)?;
    m.add_function(wrap_pyfunction!(ida_fractiles, m)?)?;
    Ok(())
}
