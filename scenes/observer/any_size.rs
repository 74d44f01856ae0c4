//! The run-time-size observer scene (issue 34), shared by `tests/runtime_size_observer.rs`
//! and `xtask/benches/observer.rs`: an `n`-storey shear building, its ground input and a
//! record with one missing sample.

use aemstep::nalgebra::DMatrix;

/// A shear building of `n` storeys: floor masses 1e5 kg, storey stiffness 2e8 N/m,
/// damping `C = 0.2 M + 1e-3 K` (about 2–5 % in the lower modes).
pub fn building(n: usize) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let m = DMatrix::<f64>::identity(n, n) * 1.0e5;
    let k = DMatrix::from_fn(n, n, |i, j| {
        let ks = 2.0e8;
        match (i.abs_diff(j), i + 1 == n) {
            (0, true) => ks,
            (0, false) => 2.0 * ks,
            (1, _) => -ks,
            _ => 0.0,
        }
    });
    let c = &m * 0.2 + &k * 1.0e-3;
    (m, c, k)
}

/// The ground-acceleration input `B = −M ι`.
pub fn ground(m: &DMatrix<f64>) -> DMatrix<f64> {
    let n = m.nrows();
    DMatrix::from_fn(n, 1, |i, _| -(0..n).map(|j| m[(i, j)]).sum::<f64>())
}

/// A record of `steps` samples: ground acceleration (m/s²) and `o` measured absolute
/// accelerations, with sample 7 of sensor 0 missing (NaN).
pub fn record(steps: usize, o: usize) -> (Vec<f64>, Vec<Vec<f64>>) {
    let ag = (0..steps)
        .map(|n| {
            let t = n as f64 * 0.02;
            (7.0 * t).sin() * (-0.2 * t).exp() + 0.3 * (19.0 * t).cos()
        })
        .collect();
    let y = (0..steps)
        .map(|n| {
            (0..o)
                .map(|s| {
                    if n == 7 && s == 0 {
                        f64::NAN
                    } else {
                        0.5 * ((3.0 + s as f64) * n as f64 * 0.02).sin()
                    }
                })
                .collect()
        })
        .collect();
    (ag, y)
}
