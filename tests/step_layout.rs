//! The step functions' storage layout and operation order (interleaved, negated operator
//! rows processed two at a time, with a remainder row for odd N) against an independent
//! Newmark average-acceleration integrator written here with nalgebra's LU, for every
//! size the firmware cost table uses (N = 1, 2, 3, 5, 6, 12: even and odd, so both the
//! two-row blocks and the remainder row are exercised).
//!
//! In exact arithmetic the three recurrences are the same (the AEM step *is* Newmark-AA,
//! spec §3), so the differences are rounding only. Measured max differences over 2000
//! f64 steps, relative to the largest |u|, |v|, |a| of the run
//! (`cargo test --release --test step_layout -- --nocapture`): 1.1e-14 (N = 1), 2.5e-14,
//! 2.9e-14, 6.6e-14, 1.1e-13, 2.4e-13 (N = 12), growing about ∝ N as rounding of N-term
//! sums does. The bound 1e-11 leaves 40× for other summation orders and platforms; any
//! real defect (a dropped row, a wrong block) shows as O(1).

use aemstep::models::{Rows, rayleigh, shear_building};
use aemstep::{AForm, Linear, State, Stepper};
use nalgebra::{DMatrix, DVector, SVector};

const H: f64 = 0.01;
const STEPS: usize = 2000;

fn building<const N: usize>() -> (Rows<N>, Rows<N>, Rows<N>) {
    let (m, k) = shear_building([1.0e5; N], [1.0e8; N]);
    let c = rayleigh(&m, &k, 0.5, 1.0e-3);
    (m, c, k)
}

fn mat<const N: usize>(r: &Rows<N>) -> DMatrix<f64> {
    DMatrix::from_fn(N, N, |i, j| r[i][j])
}

/// Newmark β = 1/4, γ = 1/2 in its textbook effective-stiffness form (solve for u_n).
fn newmark(
    m: &DMatrix<f64>,
    c: &DMatrix<f64>,
    k: &DMatrix<f64>,
    u0: DVector<f64>,
    v0: DVector<f64>,
    load: impl Fn(usize) -> DVector<f64>,
) -> Vec<[DVector<f64>; 3]> {
    let a0 = m
        .clone()
        .lu()
        .solve(&(load(0) - c * &v0 - k * &u0))
        .expect("M regular");
    let keff = k + c * (2.0 / H) + m * (4.0 / (H * H));
    let lu = keff.lu();
    let (mut u, mut v, mut a) = (u0, v0, a0);
    let mut out = Vec::with_capacity(STEPS);
    for n in 1..=STEPS {
        let rhs =
            load(n) + m * (&u * (4.0 / (H * H)) + &v * (4.0 / H) + &a) + c * (&u * (2.0 / H) + &v);
        let un = lu.solve(&rhs).expect("K_eff regular");
        let vn = (&un - &u) * (2.0 / H) - &v;
        let an = (&un - &u) * (4.0 / (H * H)) - &v * (4.0 / H) - &a;
        (u, v, a) = (un, vn, an);
        out.push([u.clone(), v.clone(), a.clone()]);
    }
    out
}

fn check<const N: usize>() -> f64 {
    let (mr, cr, kr) = building::<N>();
    let (m, c, k) = (mat(&mr), mat(&cr), mat(&kr));
    let u0 = SVector::<f64, N>::from_fn(|i, _| 0.01 * (i as f64 + 1.0));
    let v0 = SVector::<f64, N>::from_fn(|i, _| 0.1 * (-1.0f64).powi(i as i32));
    // A load that varies in time and in space.
    let load = |n: usize| {
        SVector::<f64, N>::from_fn(|i, _| 1.0e5 * ((n as f64 * H * 7.0) + i as f64).sin())
    };
    let dyn_load = |n: usize| DVector::from_column_slice(load(n).as_slice());
    let dv = |x: &SVector<f64, N>| DVector::from_column_slice(x.as_slice());
    let reference = newmark(&m, &c, &k, dv(&u0), dv(&v0), dyn_load);
    let lin = Linear::<f64, N>::from_rows_f64(mr, cr, kr, H).expect("operators");
    let afm: AForm<f64, N> = lin.a_form();
    // Differences relative to the largest |u|, |v|, |a| of the run (a vector's own size
    // passes through zero as it oscillates).
    let scale: [f64; 3] =
        core::array::from_fn(|q| reference.iter().map(|r| r[q].amax()).fold(0.0, f64::max));
    let mut worst: f64 = 0.0;
    for sys in [
        &lin as &dyn Stepper<f64, N, Input = SVector<f64, N>, State = State<f64, N>>,
        &afm as &dyn Stepper<f64, N, Input = SVector<f64, N>, State = State<f64, N>>,
    ] {
        let mut s = sys.start(&u0, &v0, &load(0)).expect("start");
        for (n, [u, v, a]) in reference.iter().enumerate() {
            sys.step(&mut s, &load(n + 1));
            for (q, (x, y)) in [(s.u(), u), (s.v(), v), (s.a(), a)].into_iter().enumerate() {
                worst = worst.max((dv(x) - y).amax() / scale[q]);
            }
        }
    }
    worst
}

#[test]
fn linear_and_aform_match_an_independent_newmark_for_every_table_size() {
    for (n, worst) in [
        (1, check::<1>()),
        (2, check::<2>()),
        (3, check::<3>()),
        (5, check::<5>()),
        (6, check::<6>()),
        (12, check::<12>()),
    ] {
        println!("N = {n:2}: max relative difference {worst:.2e}");
        assert!(worst <= 1e-11, "N = {n}: {worst:e}");
    }
}

#[test]
fn aform_blocks_out_of_range_are_none() {
    let (m, c, k) = building::<2>();
    let a = Linear::<f64, 2>::from_rows_f64(m, c, k, H)
        .expect("operators")
        .a_form();
    assert!(a.a_block(2, 2).is_some() && a.b_block(2).is_some());
    assert!(a.a_block(0, 3).is_none() && a.a_block(3, 0).is_none() && a.b_block(3).is_none());
}
