//! Many records in parallel on the host (feature `std`): one [`Bank`] shared by a few
//! threads (`std::thread::scope`), each taking the next record from a shared counter.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::vec::Vec;

use super::bank::{Bank, Response};
use crate::Real;

/// The spectra of many records (each a slice of ground-acceleration samples at the bank's
/// time step [`Bank::time_step`]), on `threads` threads (`0`: as many as `std::thread::available_parallelism`).
/// Each record is stepped through the whole bank ([`Bank::step`]), then continued
/// `free_vibration` samples in free vibration ([`Bank::free_vibration`]; pass
/// [`Bank::free_vibration_samples`] for every peak, `0` for none).
///
/// Returns one [`Response`] per record, in the order of `records`. Cost: that of
/// [`Bank::step`] per sample, divided among the threads; one allocation (the result).
/// A thread that panics (it cannot: stepping does not panic) would propagate the panic.
pub fn spectra<T, const P: usize>(
    bank: &Bank<T, P>,
    records: &[&[T]],
    free_vibration: u32,
    threads: usize,
) -> Vec<Response<T, P>>
where
    T: Real + Send + Sync,
    Response<T, P>: Send,
    Bank<T, P>: Sync,
{
    let threads = if threads == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        threads
    }
    .min(records.len())
    .max(1);
    let next = AtomicUsize::new(0);
    let one = |i: usize| {
        let mut r = zero_response(bank);
        for &a in records[i] {
            bank.step(&mut r, a);
        }
        bank.free_vibration(&mut r, free_vibration);
        r
    };
    let mut parts: Vec<Vec<(usize, Response<T, P>)>> = std::thread::scope(|s| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                s.spawn(|| {
                    let mut mine = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        if i >= records.len() {
                            break mine;
                        }
                        mine.push((i, one(i)));
                    }
                })
            })
            .collect();
        workers
            .into_iter()
            .map(|w| w.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    });
    let mut out: Vec<(usize, Response<T, P>)> =
        parts.iter_mut().flat_map(|p| p.drain(..)).collect();
    out.sort_unstable_by_key(|(i, _)| *i);
    out.into_iter().map(|(_, r)| r).collect()
}

/// A response at rest for a generic `T` (the `const` constructors are per type).
fn zero_response<T: Real, const P: usize>(_bank: &Bank<T, P>) -> Response<T, P> {
    let z = T::from_f64_rounded(0.0);
    Response {
        u: [z; P],
        v: [z; P],
        sd: [z; P],
        sv: [z; P],
        sa: [z; P],
        last: z,
        samples: 0,
        skipped: 0,
        walks: 0,
    }
}
