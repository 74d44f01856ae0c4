//! Host benchmark of the observers' step, compiled (const-generic) against run-time-sized
//! (issue 34): the fixed-gain `Observer<f64, 10, 1, 2>` against `DynObserver<f64>` and the
//! full `Kalman<f64, 10, 1, 2>` against `DynKalman<f64>`, at N = 5 (S = 10 states, 2
//! accelerometers, one ground input), over 999 steps of a noisy record, repeated; the mean
//! time a step is printed (host timings).
//!
//! Run: `cargo bench -p xtask --bench observer` (a few seconds).

use aemstep::nalgebra::{DMatrix, SMatrix, SVector};
use aemstep::observer::{
    DynKalman, DynObserver, DynStateSpace, Kalman, Observer, Outputs, StateSpace, SteadyState,
};

const H: f64 = 0.02;

#[path = "../../scenes/observer/any_size.rs"]
mod any_size;
use any_size::{building, ground, record};

/// The step times, printed.
fn main() {
    use std::hint::black_box;
    use std::time::Instant;
    const N: usize = 5;
    let (m, c, k) = building(N);
    let b = ground(&m);
    let sm = |a: &DMatrix<f64>| SMatrix::<f64, N, N>::from_fn(|i, j| a[(i, j)]);
    let bs = SMatrix::<f64, N, 1>::from_fn(|i, _| b[(i, 0)]);
    let ss = StateSpace::<N, 10, 1>::aem(&sm(&m), &sm(&c), &sm(&k), &bs, H).unwrap();
    let meas = ss
        .outputs(&Outputs::absolute_accelerations(
            Outputs::<N, 1, 2>::select([1, 4]),
            0,
        ))
        .unwrap();
    let q = SMatrix::<f64, 10, 10>::identity() * 1e-8;
    let r = SMatrix::<f64, 2, 2>::identity() * 0.01;
    let kf = SteadyState::new(&ss, &meas, &q, &r).unwrap();
    let obs = Observer::<f64, 10, 1, 2>::new(&ss, &meas, &kf.gain_matrix()).unwrap();
    let dss = DynStateSpace::aem(&m, &c, &k, &b, H).unwrap();
    let dmeas = dss.absolute_accelerations(&[1, 4], 0).unwrap();
    let dobs =
        DynObserver::<f64>::new(&dss, &dmeas, &DMatrix::from_fn(10, 2, |i, j| kf.gain[i][j]))
            .unwrap();
    let (ag, y) = record(1000, 2);
    let reps = 2000;
    let t = Instant::now();
    for _ in 0..reps {
        let mut e = obs.start_at_rest(&SVector::from([0.0])).unwrap();
        for i in 1..ag.len() {
            let _ = obs.try_step(
                &mut e,
                &SVector::from([ag[i]]),
                &SVector::from_column_slice(&y[i]),
            );
        }
        black_box(&e);
    }
    let tc = t.elapsed().as_secs_f64() / (reps * (ag.len() - 1)) as f64;
    let t = Instant::now();
    for _ in 0..reps {
        let mut e = dobs.start_at_rest(&[0.0]).unwrap();
        for i in 1..ag.len() {
            let _ = dobs.try_step(&mut e, &[ag[i]], &y[i]);
        }
        black_box(&e);
    }
    let td = t.elapsed().as_secs_f64() / (reps * (ag.len() - 1)) as f64;
    println!(
        "step N = 5 (S = 10, O = 2): compiled {:.1} ns, run-time {:.1} ns ({:.2}×)",
        tc * 1e9,
        td * 1e9,
        td / tc
    );
    // The full Kalman filter: Kalman vs DynKalman.
    let kk = Kalman::<f64, 10, 1, 2>::new(&ss, &meas, &q, &r).unwrap();
    let dq = DMatrix::<f64>::identity(10, 10) * 1e-8;
    let dk = DynKalman::<f64>::new(&dss, &dmeas, &dq, &(DMatrix::identity(2, 2) * 0.01)).unwrap();
    let reps = 200;
    let t = Instant::now();
    for _ in 0..reps {
        let mut s = kk
            .start(&SVector::zeros(), &SMatrix::zeros(), &SVector::from([0.0]))
            .unwrap();
        for i in 1..ag.len() {
            let w = SVector::from([ag[i]]);
            let _ = kk.try_step(&mut s, &w, &SVector::from_column_slice(&y[i]));
        }
        black_box(&s);
    }
    let tc = t.elapsed().as_secs_f64() / (reps * (ag.len() - 1)) as f64;
    let t = Instant::now();
    for _ in 0..reps {
        let mut s = dk
            .start(&[0.0; 10], &DMatrix::zeros(10, 10), &[0.0])
            .unwrap();
        for i in 1..ag.len() {
            let _ = dk.try_step(&mut s, &[ag[i]], &y[i]);
        }
        black_box(&s);
    }
    let td = t.elapsed().as_secs_f64() / (reps * (ag.len() - 1)) as f64;
    println!(
        "Kalman step N = 5 (S = 10, O = 2): compiled {:.1} ns, run-time {:.1} ns ({:.2}×)",
        tc * 1e9,
        td * 1e9,
        td / tc
    );
}
