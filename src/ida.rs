//! Incremental dynamic analysis (IDA) on the host (feature `std`): each record of a suite
//! run at a sequence of intensities, the engineering demand parameter (EDP, e.g. the peak
//! storey drift) of each run against its intensity measure (IM) — the record's **IDA
//! curve** — up to collapse; over the suite, the curves' **fractiles**. Traced by
//! hunt-and-fill ([`hunt_fill`], Vamvatsikos & Cornell 2002, "Incremental dynamic
//! analysis", Earthquake Engng Struct. Dyn. 31(3), the tracing algorithm) or on fixed
//! stripes of intensity ([`stripes`]); records run in parallel on [`batch::map`](crate::batch::map).
//!
//! ```
//! use aemstep::Error;
//! use aemstep::ida::{self, Collapse, HuntFill, OnFailure};
//!
//! // Any analysis: a closure from (record, intensity) to the EDP. Here a toy whose drift
//! // grows linearly to 1 % at intensity 0.5, then softens, and fails (a Newton
//! // non-convergence, say) from intensity 1.2 on.
//! let records = vec![1.0, 0.8, 1.3]; // whatever a record is: here, a strength
//! let analysis = |&strength: &f64, im: f64| -> Result<f64, Error> {
//!     let x = im / strength;
//!     if x >= 1.2 { return Err(Error::NotConverged); }
//!     Ok(if x <= 0.5 { 0.02 * x } else { 0.01 + 0.05 * (x - 0.5) / (1.2 - x) })
//! };
//! let settings = HuntFill {
//!     collapse: Collapse { edp: 0.10, on_failure: OnFailure::Collapse },
//!     ..HuntFill::DEFAULT
//! };
//! let curves = ida::hunt_fill(&records, &settings, 2, analysis, None)?;
//! let [lo, hi] = curves[0].collapse.unwrap(); // the capacity, bracketed
//! assert!(hi - lo <= settings.resolution && curves[0].points.len() <= settings.runs);
//!
//! // Median and 16/84 % intensity at drifts 0.5 %, 1 %, 2 %.
//! let f = ida::fractiles(&curves, &[0.005, 0.01, 0.02], &[0.16, 0.5, 0.84])?;
//! let at_2pc = |k| f.at(k, 2).unwrap(); // quantile k, drift 2 %
//! assert!(at_2pc(0) <= at_2pc(1) && at_2pc(1) <= at_2pc(2));
//! # Ok::<(), Error>(())
//! ```
//!
//! **The intensity** is whatever the closure makes of it. By default read it as the
//! record's scale factor (the closure runs the record times `im`). For the spectral
//! acceleration at the first-mode period, `Sa(T₁)`, compute each record's own
//! [`spectral_acceleration`] once and run the record scaled by `im / sa_record` (the
//! `im` is then in the record's units, e.g. g); the hunt-and-fill settings are then in
//! those units too.
//!
//! **Collapse** ([`Collapse`]): a run collapses if its EDP is at least
//! [`Collapse::edp`] (`+∞`: never by EDP), or, with [`OnFailure::Collapse`], if the
//! analysis fails (returns `Err`, e.g. [`Error::NotConverged`] when Newton cannot follow a
//! structure losing its stiffness, or an EDP that is NaN or `−∞`, a failure with
//! [`Error::NonFiniteState`]): the run is kept as a collapsed
//! [`Point`] with `edp = +∞` and the error. With [`OnFailure::Abort`] a failed analysis
//! ends the record's trace and the call returns the error.
//!
//! **Hunt and fill** ([`hunt_fill`], one record: [`trace`]), at most [`HuntFill::runs`]
//! analyses a record (the paper's example allows 12), in three phases:
//!
//! 1. *hunt up*: intensities `first`, then each the last plus a step that grows by
//!    `step_increment` a run (`first`, `first + step`, `first + 2 step + increment`, …),
//!    until a run collapses or the budget is spent (then the record never collapsed:
//!    [`Curve::collapse`] is `None`);
//! 2. *bracket*: bisection between the highest non-collapsing intensity (`0` if the first
//!    run collapsed) and the lowest collapsing one, until they are at most `resolution`
//!    apart or the budget is spent;
//! 3. *fill*: the rest of the budget at the midpoints of the largest gaps between the
//!    non-collapsing intensities below the lowest collapse (the origin `0` included;
//!    ties: the lowest gap), the largest first — the paper's "fill in the gaps".
//!
//! A run inside the non-collapse range that collapses (a non-monotone, "resurrecting"
//! curve seen from above) lowers the collapse intensity: [`Curve::collapse`] is always
//! `[the highest non-collapsing intensity below the lowest collapsing one, that lowest]`.
//! Midpoints that rounding cannot separate from their ends end a phase early (only for a
//! `resolution` or gaps near the rounding of `f64`), so fewer runs than the budget are
//! possible, never more.
//!
//! **Stripes** ([`stripes`]): every record at every intensity of a list (one job per
//! run, the finest balancing), the curves assembled the same way.
//!
//! **Fractiles** ([`fractiles`]): the *intensity given the EDP*. Each curve (its
//! non-collapsing points below its collapse, from the origin, joined by straight lines) is
//! read at each EDP level where it first reaches it; past its last such point a collapsed
//! curve stays at that point's intensity (its flatline); across the records, the `q`
//! quantile of these intensities (linear between order statistics, numpy's default). This
//! is the choice of Vamvatsikos & Cornell: the intensity at a given EDP is finite for
//! every record, collapsed or not, while the EDP at a given intensity is infinite past a
//! record's collapse. A record that never collapsed and never reached the level is
//! *censored* (its intensity there is only known to exceed its highest run): where the
//! quantile depends on where such records lie, it is `NaN` rather than a guess.
//!
//! **Parallel runs** ([`hunt_fill`], [`stripes`]): on [`batch::map`](crate::batch::map)
//! with `threads` threads (`0`: all available); the results are in input order and, for an
//! analysis whose result depends only on its arguments, bit for bit those of one thread.
//! An optional progress callback `(done, total)` is called after every run, from the
//! worker threads (each call has a distinct `done` in `1..=total`; calls from different
//! threads may arrive out of order): `total` is `records × runs` ([`hunt_fill`]; a record
//! that ends early adds its unused runs at once) or `records × intensities`.
//!
//! **Cost**: at most `runs` analyses a record ([`hunt_fill`]) or `records × intensities`
//! ([`stripes`]), divided among the threads, plus `O(runs²)` bookkeeping a record; the
//! fractiles `O(records × (levels × points + levels × q × log records))`.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::vec::Vec;

use crate::{Error, Param};

/// What a failed analysis (an `Err` from the closure, or an EDP that is NaN or `−∞`) means.
/// An EDP of `+∞` is a collapse by the EDP rule (it is at least any [`Collapse::edp`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OnFailure {
    /// The run collapsed (the usual reading of a dynamic instability that the solver
    /// cannot follow): kept as a collapsed [`Point`] with `edp = +∞` and the error.
    Collapse,
    /// The record's trace stops and the call returns the error.
    Abort,
}

/// The collapse rule of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Collapse {
    /// The EDP at or above which a run has collapsed (EDP units, e.g. m of drift; `> 0`,
    /// `+∞` for "only failed analyses collapse").
    pub edp: f64,
    /// What a failed analysis means.
    pub on_failure: OnFailure,
}

/// Hunt-and-fill settings (see the [module](self)). Intensities in the closure's units
/// (the record scale factor by default).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HuntFill {
    /// The first intensity (finite, `> 0`).
    pub first: f64,
    /// The first step of the hunt (finite, `> 0`).
    pub step: f64,
    /// The growth of the step a run (finite, `≥ 0`).
    pub step_increment: f64,
    /// The bracket width at which bisection stops (finite, `> 0`).
    pub resolution: f64,
    /// The budget: analyses a record (`1 ..= 10 000`).
    pub runs: usize,
    /// The collapse rule.
    pub collapse: Collapse,
}

impl HuntFill {
    /// For record scale factors: first `0.1`, step `0.2`, step increment `0.1`
    /// (intensities 0.1, 0.3, 0.6, 1.0, 1.5, 2.1, …), resolution `0.05`, 12 runs, collapse
    /// only by failed analyses ([`Collapse::edp`] `= +∞`, [`OnFailure::Collapse`]): set
    /// [`HuntFill::collapse`] for a collapse EDP.
    pub const DEFAULT: HuntFill = HuntFill {
        first: 0.1,
        step: 0.2,
        step_increment: 0.1,
        resolution: 0.05,
        runs: 12,
        collapse: Collapse {
            edp: f64::INFINITY,
            on_failure: OnFailure::Collapse,
        },
    };

    /// The settings are in range (see the fields), and the highest intensity the hunt can
    /// reach, `first + runs·step + runs²·step_increment`, is finite.
    fn check(&self) -> Result<(), Error> {
        let pos = |x: f64| x.is_finite() && x > 0.0;
        let n = self.runs as f64;
        let top = self.first + n * self.step + n * n * self.step_increment;
        if pos(self.first)
            && pos(self.step)
            && self.step_increment.is_finite()
            && self.step_increment >= 0.0
            && pos(self.resolution)
            && (1..=10_000).contains(&self.runs)
            && top.is_finite()
        {
            self.collapse.check()
        } else {
            Err(Error::InvalidParameter(Param::HuntFill))
        }
    }
}

impl Default for HuntFill {
    fn default() -> Self {
        Self::DEFAULT
    }
}

impl Collapse {
    fn check(&self) -> Result<(), Error> {
        if self.edp > 0.0 {
            Ok(())
        } else {
            Err(Error::InvalidParameter(Param::CollapseLimit))
        }
    }
}

/// One run of an IDA curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// The intensity (the closure's units).
    pub intensity: f64,
    /// The EDP the analysis returned (`+∞` for a failed analysis counted as collapse).
    pub edp: f64,
    /// The run collapsed ([`Collapse`]).
    pub collapsed: bool,
    /// The error of a failed analysis counted as collapse.
    pub error: Option<Error>,
}

/// The IDA curve of one record.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// The runs, sorted by intensity (ascending).
    pub points: Vec<Point>,
    /// `[lower, upper]`: the highest non-collapsing intensity below the lowest collapsing
    /// one (`0` if none) and that lowest collapsing intensity; `None` if no run collapsed.
    pub collapse: Option<[f64; 2]>,
}

impl Curve {
    /// A curve of `points` (any order): sorted, its collapse bracket found. Cost:
    /// `O(n log n)`.
    pub fn from_points(mut points: Vec<Point>) -> Curve {
        points.sort_by(|a, b| a.intensity.total_cmp(&b.intensity));
        let collapse = points.iter().find(|p| p.collapsed).map(|c| {
            let lower = points
                .iter()
                .filter(|p| !p.collapsed && p.intensity < c.intensity)
                .map(|p| p.intensity)
                .fold(0.0, f64::max);
            [lower, c.intensity]
        });
        Curve { points, collapse }
    }

    /// The collapse capacity: the highest intensity shown not to collapse below the lowest
    /// collapse (`collapse[0]`); `None` if no run collapsed. Cost: none.
    pub fn capacity(&self) -> Option<f64> {
        self.collapse.map(|c| c[0])
    }

    /// The intensity at which the curve first reaches `edp` (EDP units, finite, `≥ 0`; `0`
    /// for `edp ≤ 0`) on its non-collapsing points below its collapse joined by straight
    /// lines from the origin (see [`fractiles`]), and whether it is censored (the curve
    /// never collapsed and never reached `edp`: then the value is its highest
    /// non-collapsing intensity, a lower bound). Past its last point a collapsed curve
    /// gives that point's intensity (the flatline). Cost: `O(points)`.
    pub fn intensity_at(&self, edp: f64) -> (f64, bool) {
        let cap = self.collapse.map_or(f64::INFINITY, |c| c[1]);
        let (mut im0, mut e0) = (0.0f64, 0.0f64);
        if edp <= 0.0 {
            return (0.0, false);
        }
        for p in self
            .points
            .iter()
            .filter(|p| !p.collapsed && p.intensity < cap)
        {
            if p.edp >= edp {
                // e0 < edp ≤ p.edp: the first crossing, on the segment from (im0, e0).
                return (im0 + (edp - e0) / (p.edp - e0) * (p.intensity - im0), false);
            }
            (im0, e0) = (p.intensity, p.edp);
        }
        (im0, self.collapse.is_none())
    }
}

/// Runs the analysis once and classifies the run.
fn run<R, F>(record: &R, im: f64, rule: &Collapse, analysis: &F) -> Result<Point, Error>
where
    F: Fn(&R, f64) -> Result<f64, Error>,
{
    classify(analysis(record, im), im, rule)
}

/// Classifies the outcome of the analysis at intensity `im` (a [`Point`], or with
/// [`OnFailure::Abort`] the error).
fn classify(outcome: Result<f64, Error>, im: f64, rule: &Collapse) -> Result<Point, Error> {
    let failed = |e: Error| match rule.on_failure {
        OnFailure::Collapse => Ok(Point {
            intensity: im,
            edp: f64::INFINITY,
            collapsed: true,
            error: Some(e),
        }),
        OnFailure::Abort => Err(e),
    };
    match outcome {
        // NaN and −∞ are no EDP (+∞ is a collapse, as the EDP rule reads it)
        Ok(edp) if edp.is_nan() || edp == f64::NEG_INFINITY => failed(Error::NonFiniteState),
        Ok(edp) => Ok(Point {
            intensity: im,
            edp,
            collapsed: edp >= rule.edp,
            error: None,
        }),
        Err(e) => failed(e),
    }
}

/// The outcomes of a batched analysis for `jobs` runs, one each in order; a missing one
/// (the closure returned fewer) is a failed run, [`Error::InvalidParameter`]
/// ([`Param::Intensity`]).
fn outcomes(mut out: Vec<Result<f64, Error>>, jobs: usize) -> Vec<Result<f64, Error>> {
    out.resize(jobs, Err(Error::InvalidParameter(Param::Intensity)));
    out
}

/// The lowest collapsing intensity of `points` (`+∞` if none).
fn lowest_collapse(points: &[Point]) -> f64 {
    points
        .iter()
        .filter(|p| p.collapsed)
        .map(|p| p.intensity)
        .fold(f64::INFINITY, f64::min)
}

/// Where a hunt-and-fill trace is (see the [module](self)).
#[derive(Clone, Copy, Debug)]
enum Phase {
    /// Hunting up: the next run is at `im`.
    Hunt,
    /// Bisecting between `lo` and `hi`.
    Bracket,
    /// Filling the largest gaps.
    Fill,
    /// The budget is spent or no new intensity can be separated.
    Done,
}

/// One record's hunt-and-fill trace as a state machine: [`Tracer::next`] chooses the next
/// intensity from the runs so far, [`Tracer::record`] takes its result. The serial trace
/// ([`trace`]) and the traces in lanes ([`batched`], one record a lane) both
/// drive it, so both choose the same intensities from the same results.
struct Tracer<'a> {
    s: &'a HuntFill,
    pts: Vec<Point>,
    phase: Phase,
    /// The hunt's next intensity and step.
    im: f64,
    step: f64,
    /// The bracket: the highest non-collapsing and the lowest collapsing intensity.
    lo: f64,
    hi: f64,
    /// The intensity asked by the last [`Tracer::next`].
    asked: f64,
    /// The fill's sorted intensities (reused).
    xs: Vec<f64>,
}

impl<'a> Tracer<'a> {
    fn new(s: &'a HuntFill) -> Self {
        Tracer {
            s,
            pts: Vec::with_capacity(s.runs),
            phase: Phase::Hunt,
            im: s.first,
            step: s.step,
            lo: 0.0,
            hi: 0.0,
            asked: 0.0,
            xs: Vec::with_capacity(s.runs + 1),
        }
    }

    /// The next intensity to run, `None` once the trace is complete.
    fn next(&mut self) -> Option<f64> {
        let s = self.s;
        if let Phase::Hunt = self.phase {
            self.asked = self.im;
            return Some(self.im);
        }
        if let Phase::Bracket = self.phase {
            let (lo, hi) = (self.lo, self.hi);
            let mid = lo + 0.5 * (hi - lo);
            if self.pts.len() < s.runs && hi - lo > s.resolution && mid > lo && mid < hi {
                self.asked = mid;
                return Some(mid);
            }
            self.phase = Phase::Fill;
        }
        if let Phase::Fill = self.phase {
            if self.pts.len() < s.runs {
                let cap = lowest_collapse(&self.pts);
                let xs = &mut self.xs;
                xs.clear();
                xs.push(0.0);
                xs.extend(
                    self.pts
                        .iter()
                        .filter(|p| !p.collapsed && p.intensity < cap)
                        .map(|p| p.intensity),
                );
                xs.sort_by(f64::total_cmp);
                let mut best = (0.0f64, 0.0f64);
                for w in xs.windows(2) {
                    if w[1] - w[0] > best.1 - best.0 {
                        best = (w[0], w[1]);
                    }
                }
                let mid = best.0 + 0.5 * (best.1 - best.0);
                if mid > best.0 && mid < best.1 {
                    self.asked = mid;
                    return Some(mid);
                }
            }
            self.phase = Phase::Done;
        }
        None
    }

    /// The run at the intensity [`Tracer::next`] asked for.
    fn record(&mut self, p: Point) {
        self.pts.push(p);
        match self.phase {
            Phase::Hunt => {
                if p.collapsed {
                    (self.phase, self.hi) = (Phase::Bracket, self.asked);
                } else if self.pts.len() == self.s.runs {
                    self.phase = Phase::Done;
                } else {
                    self.lo = self.asked;
                    self.im += self.step;
                    self.step += self.s.step_increment;
                }
            }
            Phase::Bracket if p.collapsed => self.hi = self.asked,
            Phase::Bracket => self.lo = self.asked,
            Phase::Fill | Phase::Done => {}
        }
    }

    /// The curve of the runs.
    fn finish(self) -> Curve {
        Curve::from_points(self.pts)
    }
}

/// The hunt-and-fill trace of one record, serially (see the [module](self));
/// `tick` is called after every run.
fn trace_with<R, F>(record: &R, s: &HuntFill, analysis: &F, tick: &dyn Fn()) -> Result<Curve, Error>
where
    F: Fn(&R, f64) -> Result<f64, Error>,
{
    let mut tracer = Tracer::new(s);
    while let Some(im) = tracer.next() {
        tracer.record(run(record, im, &s.collapse, analysis)?);
        tick();
    }
    Ok(tracer.finish())
}

/// The hunt-and-fill IDA curve of one record, on the caller's thread (see the
/// [module](self)).
///
/// Errors: [`Error::InvalidParameter`] for settings out of range ([`HuntFill`]); with
/// [`OnFailure::Abort`], the first error of the analysis. Cost: at most
/// [`HuntFill::runs`] analyses.
pub fn trace<R, F>(record: &R, settings: &HuntFill, analysis: F) -> Result<Curve, Error>
where
    F: Fn(&R, f64) -> Result<f64, Error>,
{
    settings.check()?;
    trace_with(record, settings, &analysis, &|| {})
}

/// The progress counter shared by the workers.
struct Progress<'a> {
    done: AtomicUsize,
    total: usize,
    report: Option<&'a (dyn Fn(usize, usize) + Sync)>,
}

impl<'a> Progress<'a> {
    /// No run done yet, of `total`; `report(done, total)` is called by [`Progress::add`].
    fn new(total: usize, report: Option<&'a (dyn Fn(usize, usize) + Sync)>) -> Self {
        Progress {
            done: AtomicUsize::new(0),
            total,
            report,
        }
    }
    fn add(&self, k: usize) {
        if let (Some(f), true) = (self.report, k > 0) {
            f(self.done.fetch_add(k, Ordering::Relaxed) + k, self.total);
        }
    }
}

/// The hunt-and-fill IDA curves of a suite of records (see the [module](self)), one
/// record a job on [`batch::map`](crate::batch::map) with `threads` threads (`0`: all
/// available). `analysis(record, intensity)` returns the run's EDP (e.g. the peak storey
/// drift, m); `progress(done, total)`, if given, is called after every run.
///
/// Returns one [`Curve`] per record, in the order of `records`, bit for bit those of
/// [`trace`] on each record alone, on any thread count (for an `analysis` whose result
/// depends only on its arguments).
///
/// Errors: [`Error::InvalidParameter`] for settings out of range ([`HuntFill`]), before any
/// run; with [`OnFailure::Abort`], the error of the first record (in input order) whose
/// analysis failed (the other records still run). Cost: at most
/// `records × `[`HuntFill::runs`] analyses, divided among the threads; the pool's creation.
pub fn hunt_fill<R, F>(
    records: &[R],
    settings: &HuntFill,
    threads: usize,
    analysis: F,
    progress: Option<&(dyn Fn(usize, usize) + Sync)>,
) -> Result<Vec<Curve>, Error>
where
    R: Sync,
    F: Fn(&R, f64) -> Result<f64, Error> + Sync + Send,
{
    settings.check()?;
    let p = Progress::new(records.len().saturating_mul(settings.runs), progress);
    let out = crate::batch::map(records, threads, |r| {
        let used = AtomicUsize::new(0);
        let curve = trace_with(r, settings, &analysis, &|| {
            used.fetch_add(1, Ordering::Relaxed);
            p.add(1);
        });
        p.add(settings.runs - used.load(Ordering::Relaxed));
        curve
    });
    out.into_iter().collect()
}

/// The IDA curves of a suite of records on fixed stripes: every record at every
/// intensity of `intensities` (finite, `> 0`, any order), one run a job on
/// [`batch::map`](crate::batch::map) with `threads` threads (`0`: all available); each
/// run classified by `collapse`, each record's runs assembled into a [`Curve`]
/// ([`Curve::from_points`]). `progress(done, total)`, if given, is called after every run
/// (`total = records × intensities`).
///
/// Returns one curve per record, in the order of `records`, bit for bit those of one
/// thread (for an `analysis` whose result depends only on its arguments).
///
/// Errors: [`Error::InvalidParameter`] for an intensity not finite and `> 0` or a
/// [`Collapse::edp`] not `> 0`, before any run; with [`OnFailure::Abort`], the first error
/// in the order (record, intensity) of the input (every run still runs). Cost:
/// `records × intensities` analyses, divided among the threads; the pool's creation.
pub fn stripes<R, F>(
    records: &[R],
    intensities: &[f64],
    collapse: &Collapse,
    threads: usize,
    analysis: F,
    progress: Option<&(dyn Fn(usize, usize) + Sync)>,
) -> Result<Vec<Curve>, Error>
where
    R: Sync,
    F: Fn(&R, f64) -> Result<f64, Error> + Sync + Send,
{
    let plan = Plan::Stripes {
        intensities,
        collapse: *collapse,
    };
    let how = Batching {
        width: 1,
        threads,
        progress,
    };
    batched(records, &plan, &how, |jobs: &[(&R, f64)]| {
        jobs.iter().map(|&(r, im)| analysis(r, im)).collect()
    })
}

/// What [`batched`] runs: fixed stripes ([`stripes`]) or hunt-and-fill traces
/// ([`hunt_fill`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Plan<'a> {
    /// Every record at every intensity (finite, `> 0`), each run classified by `collapse`.
    Stripes {
        /// The intensities (the closure's units).
        intensities: &'a [f64],
        /// The collapse rule.
        collapse: Collapse,
    },
    /// One hunt-and-fill trace a record.
    HuntFill(HuntFill),
}

/// How [`batched`] runs its analyses.
#[derive(Clone, Copy)]
pub struct Batching<'a> {
    /// Analyses a batch (e.g. the lanes `L` of a [`LaneStepper`](crate::lanes::LaneStepper);
    /// `0` is taken as `1`).
    pub width: usize,
    /// Threads of the [`batch::map`](crate::batch::map) pool (`0`: all available).
    pub threads: usize,
    /// `progress(done, total)`, if given, called after every batch from the worker threads
    /// (see the [module](self)).
    pub progress: Option<&'a (dyn Fn(usize, usize) + Sync)>,
}

/// [`stripes`] or [`hunt_fill`] with a batched analysis: `analysis(jobs)` runs up to
/// `how.width` analyses `(record, intensity)` at once (e.g. one a SIMD lane,
/// [`lanes`](crate::lanes)) and returns their EDPs (or errors) in the order of `jobs`,
/// each what the one-run closure returns for it. Jobs of [`batch::map`](crate::batch::map)
/// with `how.threads` threads ([`Batching`]):
///
/// - [`Plan::Stripes`]: the runs intensity by intensity, all records of a stripe in
///   consecutive lanes, `width` runs a job; `progress(done, total)` after every batch.
/// - [`Plan::HuntFill`]: `width` records a job, traced side by side, one a lane: at each
///   round every unfinished trace of the group chooses its next intensity from its own
///   runs so far, and the round's runs go to `analysis` at once; `progress` as
///   [`hunt_fill`].
///
/// Returns the curves of [`stripes`] or [`hunt_fill`], bit for bit, for a batched analysis
/// whose every result is that of the one-run analysis (each trace sees the same results,
/// so it asks the same intensities). Errors: as [`stripes`] or [`hunt_fill`]; a result
/// missing from a batch (the closure returned fewer than asked) is a failed run
/// ([`Error::InvalidParameter`]). Cost: as [`stripes`] or [`hunt_fill`], in batches of
/// `width` runs (hunt-and-fill: at most `runs` batches a group).
pub fn batched<R, F>(
    records: &[R],
    plan: &Plan<'_>,
    how: &Batching<'_>,
    analysis: F,
) -> Result<Vec<Curve>, Error>
where
    R: Sync,
    F: Fn(&[(&R, f64)]) -> Vec<Result<f64, Error>> + Sync + Send,
{
    let (width, threads, progress) = (how.width.max(1), how.threads, how.progress);
    let (intensities, collapse) = match plan {
        Plan::Stripes {
            intensities,
            collapse,
        } => (*intensities, collapse),
        Plan::HuntFill(settings) => {
            settings.check()?;
            let p = Progress::new(records.len().saturating_mul(settings.runs), progress);
            let groups: Vec<&[R]> = records.chunks(width).collect();
            let out = crate::batch::map(&groups, threads, |group| {
                trace_group(group, settings, &analysis, &p)
            });
            return out.into_iter().flatten().collect();
        }
    };
    collapse.check()?;
    if intensities.iter().any(|&x| !(x.is_finite() && x > 0.0)) {
        return Err(Error::InvalidParameter(Param::Intensity));
    }
    // Intensity-major: a stripe's records side by side.
    let jobs: Vec<(usize, f64)> = intensities
        .iter()
        .flat_map(|&im| (0..records.len()).map(move |r| (r, im)))
        .collect();
    let batches: Vec<&[(usize, f64)]> = jobs.chunks(width).collect();
    let p = Progress::new(jobs.len(), progress);
    let runs = crate::batch::map(&batches, threads, |batch| {
        let asked: Vec<(&R, f64)> = batch.iter().map(|&(r, im)| (&records[r], im)).collect();
        let out = outcomes(analysis(&asked), batch.len());
        let points: Vec<Result<Point, Error>> = batch
            .iter()
            .zip(out)
            .map(|(&(_, im), o)| classify(o, im, collapse))
            .collect();
        p.add(batch.len());
        points
    });
    let mut by_record: Vec<Vec<Result<Point, Error>>> = (0..records.len())
        .map(|_| Vec::with_capacity(intensities.len()))
        .collect();
    for (k, point) in runs.into_iter().flatten().enumerate() {
        by_record[k % records.len()].push(point);
    }
    by_record
        .into_iter()
        .map(|pts| {
            Ok(Curve::from_points(
                pts.into_iter().collect::<Result<Vec<_>, _>>()?,
            ))
        })
        .collect()
}

/// The hunt-and-fill traces of a group of records side by side (see [`batched`]).
fn trace_group<R, F>(
    group: &[R],
    settings: &HuntFill,
    analysis: &F,
    p: &Progress<'_>,
) -> Vec<Result<Curve, Error>>
where
    F: Fn(&[(&R, f64)]) -> Vec<Result<f64, Error>>,
{
    let mut tracers: Vec<Tracer<'_>> = group.iter().map(|_| Tracer::new(settings)).collect();
    let mut failed: Vec<Option<Error>> = std::vec![None; group.len()];
    loop {
        let mut lanes: Vec<usize> = Vec::with_capacity(group.len());
        let mut asked: Vec<(&R, f64)> = Vec::with_capacity(group.len());
        for (k, t) in tracers.iter_mut().enumerate() {
            if let (None, Some(im)) = (failed[k], t.next()) {
                lanes.push(k);
                asked.push((&group[k], im));
            }
        }
        if asked.is_empty() {
            break;
        }
        let out = outcomes(analysis(&asked), asked.len());
        for ((&k, &(_, im)), o) in lanes.iter().zip(&asked).zip(out) {
            match classify(o, im, &settings.collapse) {
                Ok(point) => {
                    tracers[k].record(point);
                    p.add(1);
                }
                Err(e) => failed[k] = Some(e),
            }
        }
    }
    tracers
        .into_iter()
        .zip(failed)
        .map(|(t, f)| {
            p.add(settings.runs - t.pts.len());
            match f {
                Some(e) => Err(e),
                None => Ok(t.finish()),
            }
        })
        .collect()
}

/// The `q` quantile of `x` (sorted ascending), linear between order statistics (numpy's
/// default, Hyndman–Fan type 7): `h = (n − 1) q`, `x[⌊h⌋] + (h − ⌊h⌋)(x[⌊h⌋+1] − x[⌊h⌋])`.
fn quantile(x: &[f64], q: f64) -> f64 {
    let h = (x.len() - 1) as f64 * q;
    let lo = (h.floor() as usize).min(x.len() - 1);
    let frac = h - lo as f64;
    if frac == 0.0 || lo + 1 >= x.len() {
        x[lo]
    } else {
        x[lo] + frac * (x[lo + 1] - x[lo])
    }
}

/// The fractile IDA curves of a suite ([`fractiles`]): the intensity (the closure's
/// units) on two named axes, the quantiles `q` (axis 0, as given) and the EDP levels
/// (axis 1, as given). `NaN` where the quantile depends on records censored at that level.
///
/// ```
/// use aemstep::ida::{Curve, Point, fractiles};
/// let p = |intensity, edp| Point { intensity, edp, collapsed: false, error: None };
/// let curves = [
///     Curve::from_points(vec![p(1.0, 0.01), p(2.0, 0.02)]),
///     Curve::from_points(vec![p(1.0, 0.02), p(2.0, 0.04)]),
/// ];
/// let f = fractiles(&curves, &[0.01, 0.02], &[0.0, 0.5, 1.0])?;
/// assert_eq!((f.quantiles(), f.edp()), (&[0.0, 0.5, 1.0][..], &[0.01, 0.02][..]));
/// assert_eq!(f.at(1, 1), Some(1.5)); // median intensity at 2 % drift: between 1 and 2
/// assert_eq!(f.curve(2), Some(&[1.0, 2.0][..])); // the 100 % fractile curve
/// assert_eq!(f.at(3, 0), None); // no 4th quantile
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Fractiles {
    quantiles: Vec<f64>,
    edp: Vec<f64>,
    /// Quantile-major: `intensity[k · edp.len() + j]`.
    intensity: Vec<f64>,
}

impl Fractiles {
    /// The quantiles, axis 0 (in `[0, 1]`, as given). Cost: none.
    pub fn quantiles(&self) -> &[f64] {
        &self.quantiles
    }
    /// The EDP levels, axis 1 (EDP units, as given). Cost: none.
    pub fn edp(&self) -> &[f64] {
        &self.edp
    }
    /// The `quantiles()[q_index]` quantile of the intensity at which the curves first reach
    /// `edp()[edp_index]`; `None` for an index out of range. Cost: O(1).
    pub fn at(&self, q_index: usize, edp_index: usize) -> Option<f64> {
        if edp_index < self.edp.len() {
            self.curve(q_index)?.get(edp_index).copied()
        } else {
            None
        }
    }
    /// The fractile curve of quantile `quantiles()[q_index]`: its intensity at every EDP
    /// level, in the order of [`Fractiles::edp`]; `None` for an index out of range.
    /// Cost: O(1).
    pub fn curve(&self, q_index: usize) -> Option<&[f64]> {
        let n = self.edp.len();
        let start = q_index.checked_mul(n)?;
        self.intensity.get(start..start.checked_add(n)?)
    }
    /// Every intensity, quantile-major (`[k · levels + j]` for quantile `k`, level `j`):
    /// a `quantiles × levels` row-major matrix. Cost: none.
    pub fn as_slice(&self) -> &[f64] {
        &self.intensity
    }
}

/// The fractile IDA curves of `curves`: for each quantile `q[k]` (in `[0, 1]`) and EDP
/// level `edp[j]` (finite, `≥ 0`), the `q[k]` quantile across the curves of the
/// intensity at which each first reaches `edp[j]` ([`Curve::intensity_at`]; see the
/// [module](self) for the rule and why the intensity given the EDP). Returns them on named
/// axes ([`Fractiles::at`]`(k, j)`); `NaN` where the quantile depends on records censored
/// at that level.
///
/// Errors: [`Error::InvalidParameter`] if `curves` is empty, a level is not finite and
/// `≥ 0`, or a `q` is outside `[0, 1]`. Cost: `O(curves × levels × points)` plus a sort
/// of `curves` values a level.
pub fn fractiles(curves: &[Curve], edp: &[f64], q: &[f64]) -> Result<Fractiles, Error> {
    if curves.is_empty()
        || edp.iter().any(|&e| !(e.is_finite() && e >= 0.0))
        || q.iter().any(|&x| !(0.0..=1.0).contains(&x))
    {
        return Err(Error::InvalidParameter(Param::Fractiles));
    }
    let mut out = Fractiles {
        quantiles: q.to_vec(),
        edp: edp.to_vec(),
        intensity: std::vec![0.0; q.len() * edp.len()],
    };
    let (mut low, mut high) = (Vec::new(), Vec::new());
    for (j, &e) in edp.iter().enumerate() {
        low.clear();
        high.clear();
        for c in curves {
            let (im, censored) = c.intensity_at(e);
            low.push(im);
            high.push(if censored { f64::INFINITY } else { im });
        }
        low.sort_by(f64::total_cmp);
        high.sort_by(f64::total_cmp);
        for (k, &qk) in q.iter().enumerate() {
            let (a, b) = (quantile(&low, qk), quantile(&high, qk));
            out.intensity[k * edp.len() + j] = if a == b { a } else { f64::NAN };
        }
    }
    Ok(out)
}

/// The pseudo-spectral acceleration `Sa = ω² max|u|` (the record's units, e.g. g or m/s²)
/// of the damped oscillator of period `period` (s) and damping ratio `damping` under
/// `record` (sampled every `h` s), with one period of free vibration after it
/// ([`spectrum::Bank`](crate::spectrum::Bank), exact scheme). For the intensity measure
/// `Sa(T₁)`: run the record scaled by `im / sa` for a target `im`.
///
/// Errors: as [`spectrum::Bank::new`](crate::spectrum::Bank::new)
/// ([`Error::InvalidPeriod`], [`Error::InvalidDamping`], [`Error::InvalidTimeStep`]);
/// [`Error::NonFiniteInput`] if a sample is not finite (the bank's default
/// [`NonFinite::Refuse`](crate::spectrum::NonFinite) policy, as every record-level spectrum
/// call: [`spectrum::first_non_finite`](crate::spectrum::first_non_finite) gives the
/// sample's index); [`Error::NonFiniteState`] if finite
/// samples make the response overflow, [`Error::OperatorOverflow`] if `ω² max|u|` does
/// ([`spectrum::Bank::response`](crate::spectrum::Bank::response));
/// [`Error::InvalidTimeStep`] if one period is more than
/// [`MAX_FREE_VIBRATION_SAMPLES`](crate::spectrum::MAX_FREE_VIBRATION_SAMPLES) samples.
/// Cost: one pass of a one-oscillator bank over the record.
///
/// ```
/// // A record of 1 s of a 2 Hz sine (m/s²), Sa at 0.5 s, 5 % damping: the resonance.
/// let rec: Vec<f64> = (0..100).map(|n| (std::f64::consts::TAU * 2.0 * n as f64 * 0.01).sin()).collect();
/// let sa = aemstep::ida::spectral_acceleration(&rec, 0.01, 0.5, 0.05)?;
/// assert!(sa > 2.0); // amplified
/// let scale = 1.5 / sa; // the record scaled to Sa(0.5 s) = 1.5 m/s²
/// # let _ = scale;
/// # Ok::<(), aemstep::Error>(())
/// ```
pub fn spectral_acceleration(
    record: &[f64],
    h: f64,
    period: f64,
    damping: f64,
) -> Result<f64, Error> {
    let bank = crate::spectrum::Bank::<f64, 1>::new([period], [damping], h)?;
    let r = bank.response(record)?;
    let sa = bank.psa(r.sd())[0];
    if sa.is_finite() {
        Ok(sa)
    } else {
        Err(Error::OperatorOverflow)
    }
}
