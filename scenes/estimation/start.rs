//! The unknown-load scene's filter starts, shared by the tests (`tests/estimation.rs`) and
//! the page's generator (`xtask/src/bin/estimation_building.rs`): the 5-storey building's
//! state (`S = 10`) known to be near rest, the roof force (`I = 1`) unknown. The joint
//! filter and the augmented Kalman filter start at zero with the state's variance
//! [`P0`] and the force's [`PW0`].
#![allow(dead_code)] // each includer uses a different subset

use aemstep::estimation::augmented::AugmentedModel;
use aemstep::estimation::{InputStateFilter, InputStateFilterState};
use aemstep::nalgebra::{SMatrix, SVector};
use aemstep::observer::{Kalman, KalmanState};

/// Initial variance of every state (m², (m/s)²): the building at rest, known to 0.1 mm.
pub const P0: f64 = 1e-8;
/// Initial variance of the unknown force (N²): 10⁵ N standard deviation, diffuse.
pub const PW0: f64 = 1e10;

/// `SMatrix` to rows.
pub fn rows<const R: usize, const C: usize>(a: &SMatrix<f64, R, C>) -> [[f64; C]; R] {
    core::array::from_fn(|i| core::array::from_fn(|j| a[(i, j)]))
}

/// The time-varying joint filter started at zero: `P₀ = P0·I`, `P_w0 = PW0`.
pub fn start_joint<const O: usize>(
    f: &InputStateFilter<f64, 10, 1, O>,
) -> InputStateFilterState<f64, 10, 1, O> {
    f.start(
        &SVector::zeros(),
        &(SMatrix::identity() * P0),
        &SVector::zeros(),
        &SMatrix::from([[PW0]]),
    )
    .unwrap()
}

/// The augmented model's time-varying Kalman filter (measurement noise `r`) and its start
/// at zero: `P₀ = diag(P0·I₁₀, PW0)`.
pub fn augmented_kalman<const O: usize>(
    aug: &AugmentedModel<10, 1, 11, O>,
    r: &SMatrix<f64, O, O>,
) -> (Kalman<f64, 11, 0, O>, KalmanState<f64, 11, 0>) {
    let kf = Kalman::<f64, 11, 0, O>::new(
        &aug.model,
        &aug.measurement,
        &SMatrix::from_fn(|i, j| aug.process_noise[i][j]),
        r,
    )
    .unwrap();
    let p0 = SMatrix::<f64, 11, 11>::from_fn(|i, j| match (i == j, i < 10) {
        (false, _) => 0.0,
        (true, true) => P0,
        (true, false) => PW0,
    });
    let s = kf.start(&SVector::zeros(), &p0, &SVector::zeros()).unwrap();
    (kf, s)
}
