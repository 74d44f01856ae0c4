//! Many records in parallel on the host (feature `std`): one [`Bank`] shared by the
//! threads of a work-stealing pool ([`crate::batch::map`]), one record per job.

use std::vec::Vec;

use super::bank::{Bank, Response};
use crate::{Error, Real};

/// The spectra of many records (each a slice of ground-acceleration samples, m/s² or any
/// unit, at the bank's time step [`Bank::time_step`]), on `threads` threads (`0`: as many as
/// `std::thread::available_parallelism`; never more than records) of a work-stealing pool
/// ([`crate::batch::map`]). Each record is stepped through the whole bank ([`Bank::step`]),
/// then continued `free_vibration` samples in free vibration ([`Bank::free_vibration`];
/// pass [`Bank::free_vibration_samples`] for every peak, `0` for none).
///
/// Returns one result per record, in the order of `records`: its [`Response`], bit for
/// bit that of stepping the record alone on any thread count, or
/// [`Error::NonFiniteState`] if a finite sample made a state or a peak overflow (the
/// response is checked once at the end, as in [`Bank::response`]), or
/// [`Error::NonFiniteInput`] for a record with a non-finite sample when the bank refuses
/// them ([`NonFinite::Refuse`](super::NonFinite), the default; with
/// [`NonFinite::Skip`](super::NonFinite) they are skipped and counted,
/// [`Response::skipped`]). Cost: that of [`Bank::step`] per
/// sample, divided among the threads, plus the pool's creation (one OS thread per pool
/// thread); allocates the result and the pool. Stepping does not panic, so neither does
/// this (a pool that cannot be built runs the records serially).
pub fn spectra<T, const P: usize>(
    bank: &Bank<T, P>,
    records: &[&[T]],
    free_vibration: u32,
    threads: usize,
) -> Vec<Result<Response<T, P>, Error>>
where
    T: Real + Send + Sync,
    Response<T, P>: Send,
    Bank<T, P>: Sync,
{
    // Checked once at the end (see `Bank::response`: an overflow stays non-finite).
    crate::batch::map(records, threads, |record| {
        bank.record_pass(record, free_vibration)
    })
}
