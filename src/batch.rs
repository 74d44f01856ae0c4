//! Many independent jobs on the host (feature `std`): [`map`] runs a function over a slice
//! of jobs on a work-stealing pool ([rayon](https://docs.rs/rayon/1)) of a chosen number of threads and returns the
//! results in the order of the jobs. For batches whose jobs are coarse and independent: the
//! spectra of many records ([`spectrum::batch::spectra`](crate::spectrum::batch::spectra)),
//! the time-history analyses of an incremental dynamic analysis (one per record and
//! intensity), inelastic spectra (one per record, period and strength).
//!
//! ```
//! use aemstep::batch;
//!
//! // The squares of 0..100 on 2 threads, in input order.
//! let jobs: Vec<u64> = (0..100).collect();
//! let squares = batch::map(&jobs, 2, |&x| x * x);
//! assert_eq!(squares[7], 49);
//! assert_eq!(squares, jobs.iter().map(|x| x * x).collect::<Vec<_>>());
//! ```
//!
//! Design:
//!
//! - **One pool per call**, of exactly the threads asked for ([`threads`]): the caller's
//!   thread count is honoured whatever else the process runs on rayon's global pool, and
//!   nothing is left running between batches. Building it costs the creation of that many
//!   OS threads (tens of µs each): negligible against jobs of a millisecond or more, the
//!   kind this module is for; for many tiny jobs, batch them into fewer, larger ones.
//! - **Every job its own task**: the pool balances jobs of unequal cost (an analysis that
//!   yields takes more Newton iterations than one that stays elastic) by stealing single
//!   jobs, not halves of the slice.
//! - **No pool for one thread**: `threads == 1`, or at most one job, runs on the caller's
//!   thread, as the serial loop `items.iter().map(f).collect()` would.
//! - **Never panics on its own account**: if the pool cannot be built (the OS refuses a
//!   thread), the jobs run serially on the caller's thread, with the same results.
//! - **Results bit for bit those of the serial loop**: each job runs `f` once, whole, on one
//!   thread, and jobs share nothing through the pool, so a deterministic `f` gives the same
//!   bits on any thread count.
//! - **A panic in `f` propagates** to the caller of [`map`] (after the jobs already running
//!   have finished), with its original payload, as it would from the serial loop; the
//!   results of the other jobs are dropped.

use std::vec::Vec;

use rayon::iter::{IndexedParallelIterator, IntoParallelRefIterator, ParallelIterator};

/// The number of threads [`map`] runs `jobs` jobs on, for a requested count `requested`:
/// `requested` (`0`: all available, [`std::thread::available_parallelism`], `1` if that is
/// unknown), at most `jobs`, at least `1`. Cost: one system query when `requested == 0`.
///
/// ```
/// use aemstep::batch::threads;
/// assert_eq!(threads(2, 100), 2);
/// assert_eq!(threads(8, 3), 3); // never more threads than jobs
/// assert_eq!(threads(2, 0), 1);
/// assert!(threads(0, 100) >= 1);
/// ```
pub fn threads(requested: usize, jobs: usize) -> usize {
    let wanted = if requested == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        requested
    };
    wanted.min(jobs).max(1)
}

/// `f` applied to every job of `items`, on [`threads(threads, items.len())`](threads)
/// threads of a work-stealing pool built for this call (`threads`: any count, `0` for all
/// available); the results in the order of `items`.
///
/// Equal, bit for bit, to `items.iter().map(f).collect()` for an `f` whose result depends
/// only on its argument (no shared mutable state, no thread identity). With one thread, or
/// at most one job, or if the pool cannot be built, it is exactly that loop on the caller's
/// thread.
///
/// Panics: only if `f` panics; the panic is propagated with its payload (`#[should_panic]`
/// and `std::panic::catch_unwind` see it as from the serial loop), once the jobs already
/// running have finished.
///
/// Cost: `f` once per job, spread over the threads by work stealing (each job a task of
/// its own); plus the pool's creation and teardown (one OS thread per pool thread, tens
/// of µs each) and about a microsecond of scheduling per job. Allocates the result
/// (`items.len()` values of `R`) and the pool.
///
/// ```
/// use aemstep::batch;
///
/// // An incremental dynamic analysis has this shape: one run per intensity.
/// let intensities: Vec<f64> = (1..=8).map(|k| k as f64 * 0.25).collect();
/// let peaks = batch::map(&intensities, 0, |&s| s * s); // a run would go here
/// assert_eq!(peaks[3], 1.0);
/// ```
pub fn map<I, R, F>(items: &[I], threads: usize, f: F) -> Vec<R>
where
    I: Sync,
    R: Send,
    F: Fn(&I) -> R + Sync + Send,
{
    let n = self::threads(threads, items.len());
    if n == 1 {
        return items.iter().map(f).collect();
    }
    match rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .thread_name(|i| std::format!("aemstep-batch-{i}"))
        .build()
    {
        Ok(pool) => pool.install(|| items.par_iter().with_max_len(1).map(&f).collect()),
        Err(_) => items.iter().map(f).collect(),
    }
}
