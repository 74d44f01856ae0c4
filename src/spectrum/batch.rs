//! Many records in parallel on the host (feature `std`): one [`Bank`] shared by the
//! threads of a work-stealing pool ([`crate::batch::map`]), one record per job.

use std::vec::Vec;

use super::bank::{Bank, Response};
use crate::Real;

/// The spectra of many records (each a slice of ground-acceleration samples, m/s² or any
/// unit, at the bank's time step [`Bank::time_step`]), on `threads` threads (`0`: as many as
/// `std::thread::available_parallelism`; never more than records) of a work-stealing pool
/// ([`crate::batch::map`]). Each record is stepped through the whole bank ([`Bank::step`]),
/// then continued `free_vibration` samples in free vibration ([`Bank::free_vibration`];
/// pass [`Bank::free_vibration_samples`] for every peak, `0` for none).
///
/// Returns one [`Response`] per record, in the order of `records`, bit for bit those of
/// stepping each record alone, on any thread count. Cost: that of [`Bank::step`] per
/// sample, divided among the threads, plus the pool's creation (one OS thread per pool
/// thread); allocates the result and the pool. Stepping does not panic, so neither does
/// this (a pool that cannot be built runs the records serially).
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
    crate::batch::map(records, threads, |record| {
        let mut r = zero_response(bank);
        for &a in *record {
            bank.step(&mut r, a);
        }
        bank.free_vibration(&mut r, free_vibration);
        r
    })
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
