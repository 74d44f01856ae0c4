//! The helpers users wrote by hand, now in the library (issue 20): `unwrap_const!`,
//! `models::diagonal`, `floor_masses`, `drifts`, `matrix_of`/`rows_of`, and the guard
//! against nalgebra's column-major reading of the row-major arrays the `const` API takes.

use aemstep::hysteresis::{Bilinear, HistoryModel, ShearBuilding};
use aemstep::nalgebra::{SMatrix, SVector, vector};
use aemstep::{Linear, Stepper, models};

/// A `static` built through the macro, as a downstream firmware would.
static SYS: Linear<f64, 2> = aemstep::unwrap_const!(Linear::<f64, 2>::from_rows_f64(
    models::diagonal([2.0, 1.0]),
    [[0.0; 2]; 2],
    [[6.0, -2.0], [-2.0, 4.0]],
    0.01
));

#[test]
fn unwrap_const_builds_statics_and_panics_with_the_reason_at_run_time() {
    let direct = Linear::<f64, 2>::from_rows_f64(
        [[2.0, 0.0], [0.0, 1.0]],
        [[0.0; 2]; 2],
        [[6.0, -2.0], [-2.0, 4.0]],
        0.01,
    )
    .unwrap();
    assert_eq!(SYS, direct);
    // At run time the macro panics with `Error::as_str`.
    let r = std::panic::catch_unwind(|| {
        aemstep::unwrap_const!(Linear::<f64, 1>::from_rows_f64(
            [[1.0]],
            [[0.0]],
            [[1.0]],
            0.0
        ))
    });
    let msg = r
        .expect_err("h = 0 is refused")
        .downcast::<String>()
        .map(|s| *s)
        .unwrap_or_default();
    assert_eq!(msg, aemstep::Error::InvalidTimeStep.as_str());
}

#[test]
fn diagonal_floor_masses_and_drifts() {
    const M: models::Rows<3> = models::diagonal([1.0, 2.0, 3.0]);
    assert_eq!(M, [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]]);
    let (m, _) = models::shear_building([4.0, 5.0, 6.0], [1.0; 3]);
    const FLOORS: [f64; 5] = models::floor_masses(&models::five_storey_building().0);
    assert_eq!(FLOORS, [models::FIVE_STOREY_MASS; 5]);
    assert_eq!(models::floor_masses(&m), [4.0, 5.0, 6.0]);
    // Drifts in f64 and f32 without a turbofish, and the building's own.
    let u = vector![1.0, 3.0, 2.5];
    assert_eq!(models::drifts(&u), vector![1.0, 2.0, -0.5]);
    assert_eq!(
        models::drifts(&vector![1.0f32, 3.0, 2.5]),
        vector![1.0f32, 2.0, -0.5]
    );
    let law = Bilinear::<f64>::new(1e8, 1e5, 0.05).unwrap();
    let b = ShearBuilding::new(models::floor_masses(&m), [law; 3], &[[0.0; 3]; 3]).unwrap();
    assert_eq!(
        ShearBuilding::<f64, Bilinear<f64>, 3>::drifts(&u),
        models::drifts(&u)
    );
    assert_eq!(*b.masses(), vector![4.0, 5.0, 6.0]);
    assert_eq!(b.mass(), SMatrix::from_diagonal(b.masses()));
    // The drift output matrix applied to u is the same vector.
    let y: SMatrix<f64, 3, 3> = models::matrix_of(&models::storey_drifts::<3>());
    assert_eq!(y * u, models::drifts(&u));
}

/// A non-symmetric stiffness (a follower force, or a typo): `from_rows` reads `k[i][j]` as
/// row `i`, `matrix_of` does too, so `Linear::from_rows(k)` is `Linear::new(matrix_of(k))`
/// entry for entry; nalgebra's `SMatrix::from(k)` reads each inner array as a column and
/// builds the transpose, a different system (its free response differs).
#[test]
fn row_major_arrays_convert_by_matrix_of_and_not_by_smatrix_from() {
    let m = [[2.0, 0.0], [0.0, 1.0]];
    let c = [[0.1, 0.0], [0.05, 0.2]];
    let k = [[6.0, -2.0], [-1.0, 4.0]];
    let h = 0.01;
    let rows = Linear::<f64, 2>::from_rows_f64(m, c, k, h).unwrap();
    let conv = Linear::<f64, 2>::new(
        &models::matrix_of(&m),
        &models::matrix_of(&c),
        &models::matrix_of(&k),
        h,
    )
    .unwrap();
    assert_eq!(rows, conv);
    let km: SMatrix<f64, 2, 2> = models::matrix_of(&k);
    assert_eq!(km[(0, 1)], -2.0);
    assert_eq!(km[(1, 0)], -1.0);
    let nalgebra_reading = SMatrix::<f64, 2, 2>::from(k);
    assert_eq!(nalgebra_reading, km.transpose());
    assert_ne!(nalgebra_reading, km);
    let wrong = Linear::<f64, 2>::new(
        &models::matrix_of(&m),
        &models::matrix_of(&c),
        &nalgebra_reading,
        h,
    )
    .unwrap();
    assert_ne!(rows, wrong);
    // The two systems move differently from the same start.
    let run = |sys: &Linear<f64, 2>| {
        let p = SVector::<f64, 2>::zeros();
        let mut s = sys
            .start(&vector![1.0, 0.0], &vector![0.0, 0.0], &p)
            .unwrap();
        for _ in 0..50 {
            sys.try_step(&mut s, &p).unwrap();
        }
        *s.u()
    };
    assert_eq!(run(&rows), run(&conv));
    assert!((run(&rows) - run(&wrong)).norm() > 1e-3);
    // rows_of is matrix_of's inverse.
    assert_eq!(models::rows_of(&km), k);
    assert_eq!(models::rows_of(&models::matrix_of::<f32, 2>(&k)), k);
}
