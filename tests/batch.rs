//! The host batch (`aemstep::batch`, feature `std`): results equal, bit for bit and in
//! order, to a serial loop on every thread count (all available, 1, 2, more threads than
//! jobs, no jobs); the thread count asked for is the concurrency reached; a panic in a job
//! propagates; the ported `spectrum::batch::spectra` and the IDA scene's yielding runs
//! (`scenes/ida/building.rs`) equal their serial runs.
#![cfg(feature = "std")]

#[path = "../scenes/modal/elcentro.rs"]
mod elcentro;
#[path = "../scenes/ida/building.rs"]
mod ida;

use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use aemstep::batch;
use aemstep::spectrum::{self, Bank};

/// A job whose bits depend on every operation: a damped oscillator stepped `n` times by
/// explicit Euler from `x` (rounding differs with any change of order).
fn job(&x: &f64) -> f64 {
    let (mut u, mut v) = (x, 0.0f64);
    for _ in 0..2000 {
        let a = -4.0 * u - 0.1 * v + (u * 1.7).sin();
        v += 0.001 * a;
        u += 0.001 * v;
    }
    u * 1e3 + v
}

#[test]
fn equals_serial_loop_bit_for_bit_on_every_thread_count() {
    let items: Vec<f64> = (0..37).map(|i| 0.1 + i as f64 * 0.37).collect();
    let serial: Vec<u64> = items.iter().map(job).map(f64::to_bits).collect();
    for threads in [0, 1, 2, 3, 8, 37, 100] {
        let got: Vec<u64> = batch::map(&items, threads, job)
            .into_iter()
            .map(f64::to_bits)
            .collect();
        assert_eq!(got, serial, "threads = {threads}");
    }
}

#[test]
fn order_kept_and_zero_or_one_job() {
    let items: Vec<usize> = (0..1000).collect();
    for threads in [0, 1, 2, 5] {
        assert_eq!(batch::map(&items, threads, |&i| i), items);
        assert!(batch::map(&items[..0], threads, |&i| i).is_empty());
        assert_eq!(batch::map(&items[..1], threads, |&i| i + 1), vec![1]);
    }
    // non-Copy results, moved out in order
    let names = batch::map(&items[..50], 2, |i| format!("job {i}"));
    assert_eq!(names[49], "job 49");
}

#[test]
fn thread_count_resolution() {
    let avail = std::thread::available_parallelism().map_or(1, |n| n.get());
    assert_eq!(batch::threads(0, 1000), avail.min(1000));
    assert_eq!(batch::threads(1, 1000), 1);
    assert_eq!(batch::threads(2, 1000), 2);
    assert_eq!(batch::threads(64, 3), 3);
    assert_eq!(batch::threads(0, 0), 1);
    assert_eq!(batch::threads(7, 0), 1);
}

/// The concurrency reached equals the thread count asked for (capped by the jobs): each
/// job waits (up to 10 s) until that many jobs run at once, and none sees more.
#[test]
fn runs_on_the_threads_asked_for() {
    for (threads, jobs) in [(1usize, 4usize), (2, 8), (3, 9), (4, 2)] {
        let want = threads.min(jobs);
        let (running, peak) = (AtomicUsize::new(0), AtomicUsize::new(0));
        let items: Vec<usize> = (0..jobs).collect();
        let ids = batch::map(&items, threads, |_| {
            let now = running.fetch_add(1, Ordering::SeqCst) + 1;
            peak.fetch_max(now, Ordering::SeqCst);
            let start = Instant::now();
            while peak.load(Ordering::SeqCst) < want && start.elapsed() < Duration::from_secs(10) {
                std::thread::yield_now();
            }
            running.fetch_sub(1, Ordering::SeqCst);
            std::thread::current().id()
        });
        assert_eq!(peak.load(Ordering::SeqCst), want, "threads = {threads}");
        let mut distinct = ids.clone();
        distinct.sort_by_key(|id| format!("{id:?}"));
        distinct.dedup();
        assert!(distinct.len() <= want, "threads = {threads}: {distinct:?}");
    }
}

#[test]
#[should_panic(expected = "job 13 failed")]
fn a_panic_in_a_job_propagates() {
    let items: Vec<u32> = (0..40).collect();
    batch::map(&items, 2, |&i| {
        if i == 13 {
            panic!("job {i} failed");
        }
        i
    });
}

#[test]
fn a_panic_propagates_on_one_thread_too_and_the_payload_is_kept() {
    let items: Vec<u32> = (0..10).collect();
    for threads in [1, 2, 0] {
        let r = std::panic::catch_unwind(|| {
            batch::map(&items, threads, |&i| {
                if i == 7 {
                    std::panic::panic_any(i * 100);
                }
                i
            })
        });
        let payload = r.expect_err("the job panicked");
        assert_eq!(
            payload.downcast_ref::<u32>(),
            Some(&700),
            "threads = {threads}"
        );
    }
}

/// `spectrum::batch::spectra` on the pool: equal to stepping each record alone, on any
/// thread count, also with no records and more threads than records.
#[test]
fn spectra_equal_one_record_at_a_time() {
    let rec = elcentro::AG_F64;
    let recs: Vec<Vec<f64>> = (0..5)
        .map(|i| rec.iter().map(|a| a * (0.5 + 0.3 * i as f64)).collect())
        .collect();
    let slices: Vec<&[f64]> = recs.iter().map(|r| r.as_slice()).collect();
    let periods: [f64; 20] = core::array::from_fn(|i| 0.05 * 1.25f64.powi(i as i32));
    let b = Bank::<f64, 20>::new(periods, [0.05; 20], 0.02).unwrap();
    let alone: Vec<_> = recs
        .iter()
        .map(|r| {
            let mut resp = b.at_rest();
            r.iter().for_each(|&a| b.step(&mut resp, a));
            b.free_vibration(&mut resp, 30);
            Ok(resp)
        })
        .collect();
    for threads in [0, 1, 2, 9] {
        let out = spectrum::batch::spectra(&b, &slices, 30, threads);
        assert_eq!(out, alone, "threads = {threads}");
        assert!(spectrum::batch::spectra(&b, &[], 30, threads).is_empty());
    }
}

/// The IDA scene's yielding runs (first 20 s of the record, three intensities, the
/// strongest well past yield) on the pool equal the serial runs bit for bit.
#[test]
fn ida_runs_equal_serial_runs() {
    let (bld, stepper) = (ida::building().unwrap(), ida::stepper().unwrap());
    let ag = &elcentro::AG_F64[..];
    assert_eq!(ida::steps(ag.len()), 15_975);
    let scales = [0.4, 1.0, 2.0];
    let steps = 4000;
    let serial: Vec<f64> = scales
        .iter()
        .map(|&s| ida::peak_drift(&bld, &stepper, ag, s, steps).unwrap())
        .collect();
    assert!(
        serial[2] > ida::FY / aemstep::models::FIVE_STOREY_STIFFNESS,
        "{serial:?}"
    );
    for threads in [2, 0] {
        let got = batch::map(&scales, threads, |&s| {
            ida::peak_drift(&bld, &stepper, ag, s, steps).unwrap()
        });
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&got), bits(&serial), "threads = {threads}");
    }
}
