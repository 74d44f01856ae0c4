//! Regression pin: the const-generic `Kalman` step's outputs — every estimate,
//! a-posteriori covariance, innovation and innovation covariance over 60 steps with missing
//! samples, in `f64` and `f32`, with and without a cross covariance, at several sizes —
//! hashed bit for bit. The hashes were printed by the nalgebra-`SMatrix` step BEFORE the
//! step moved onto the flat-slice core (`observer::flat`, shared with `DynKalman`): the
//! move must not change one bit. These are regression pins of the old code's output, not
//! accuracy bounds (accuracy: tests/runtime_size_observer.rs, tests/cross_covariance.rs).
#![cfg(feature = "std")]

use aemstep::Real;
use aemstep::nalgebra::{SMatrix, SVector};
use aemstep::observer::{Kalman, Outputs, StateSpace};

/// FNV-1a over the `f64` bit patterns (an `f32` widened exactly).
struct Fnv(u64);
impl Fnv {
    fn eat<T: Real>(&mut self, vals: impl IntoIterator<Item = T>) {
        for v in vals {
            for b in v.as_f64().to_bits().to_le_bytes() {
                self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
            }
        }
    }
}

/// A shear building of `N` storeys (masses 1e5 kg, storeys 2e8 N/m, `C = 0.2 M + 1e-3 K`)
/// under ground acceleration, `O` absolute accelerations measured at `dofs`; `q` from unit
/// forces of 1e4 N on every floor, `r = 0.01 I` (+ the feedthrough with `cross`).
fn run<T: Real, const N: usize, const S: usize, const O: usize>(
    dofs: [usize; O],
    cross: bool,
) -> u64 {
    let m = SMatrix::<f64, N, N>::identity() * 1.0e5;
    let k = SMatrix::<f64, N, N>::from_fn(|i, j| match (i.abs_diff(j), i + 1 == N) {
        (0, true) => 2.0e8,
        (0, false) => 4.0e8,
        (1, _) => -2.0e8,
        _ => 0.0,
    });
    let c = m * 0.2 + k * 1.0e-3;
    let b = SMatrix::<f64, N, 1>::from_element(-1.0e5);
    let ss = StateSpace::<N, S, 1>::aem(&m, &c, &k, &b, 0.02).unwrap();
    let meas = ss
        .outputs(&Outputs::absolute_accelerations(
            Outputs::<N, 1, O>::select(dofs),
            0,
        ))
        .unwrap();
    let forces = StateSpace::<N, S, N>::aem(&m, &c, &k, &SMatrix::identity(), 0.02).unwrap();
    let qw: [[f64; N]; N] =
        core::array::from_fn(|i| core::array::from_fn(|j| if i == j { 1.0e8 } else { 0.0 }));
    let q = SMatrix::<f64, S, S>::from_fn(|i, j| forces.input_noise(&qw)[i][j]);
    let mut r = SMatrix::<f64, O, O>::identity() * 0.01;
    let kf = if cross {
        let fm = forces
            .outputs(&Outputs::<N, N, O>::accelerations(core::array::from_fn(
                |s| core::array::from_fn(|j| if j == dofs[s] { 1.0 } else { 0.0 }),
            )))
            .unwrap();
        let n: [[f64; O]; S] = forces.input_cross_noise(&fm, &qw);
        let ft: [[f64; O]; O] = forces.feedthrough_noise(&fm, &qw);
        r += SMatrix::<f64, O, O>::from_fn(|i, j| ft[i][j]);
        let n = SMatrix::<f64, S, O>::from_fn(|i, j| n[i][j]);
        Kalman::<T, S, 1, O>::with_cross(&ss, &meas, &q, &r, &n).unwrap()
    } else {
        Kalman::<T, S, 1, O>::new(&ss, &meas, &q, &r).unwrap()
    };
    let t = T::from_f64_rounded;
    let p0 = SMatrix::<T, S, S>::from_fn(|i, j| if i == j { t(1e-4) } else { t(0.0) });
    let mut st = kf.start(&SVector::zeros(), &p0, &SVector::zeros()).unwrap();
    let mut h = Fnv(0xcbf2_9ce4_8422_2325);
    for n in 0..60 {
        let tn = n as f64 * 0.02;
        let w = SVector::<T, 1>::new(t((7.0 * tn).sin() + 0.3 * (19.0 * tn).cos()));
        let y = SVector::<T, O>::from_fn(|s, _| {
            if (n == 7 && s == 0) || n == 30 {
                t(f64::NAN)
            } else {
                t(0.5 * ((3.0 + s as f64) * tn).sin())
            }
        });
        let (nu, si) = kf.try_step_innovation(&mut st, &w, &y).unwrap();
        h.eat(st.estimate().x().iter().copied());
        h.eat(st.covariance().iter().copied());
        h.eat(nu.iter().copied().filter(|v| v.is_finite()));
        h.eat(si.iter().copied());
    }
    h.0
}

fn all() -> Vec<u64> {
    vec![
        run::<f64, 1, 2, 1>([0], false),
        run::<f32, 1, 2, 1>([0], false),
        run::<f64, 2, 4, 2>([0, 1], false),
        run::<f32, 2, 4, 2>([1, 0], false),
        run::<f64, 3, 6, 3>([0, 1, 2], false),
        run::<f32, 3, 6, 3>([0, 1, 2], false),
        run::<f64, 5, 10, 2>([1, 4], false),
        run::<f64, 5, 10, 2>([1, 4], true),
        run::<f32, 5, 10, 2>([1, 4], true),
        run::<f64, 4, 8, 4>([0, 1, 2, 3], true),
        run::<f64, 10, 20, 9>([0, 1, 2, 3, 4, 5, 6, 7, 9], false),
        run::<f32, 10, 20, 9>([0, 1, 2, 3, 4, 5, 6, 7, 9], false),
        run::<f64, 12, 24, 12>(core::array::from_fn(|i| i), true),
    ]
}

#[test]
fn const_kalman_step_is_bit_identical_to_the_old_nalgebra_step() {
    let got = all();
    let pinned: [u64; 13] = PINNED;
    assert_eq!(got, pinned.to_vec());
}

/// Printed by the old step (commit f14189d, nalgebra `SMatrix` arithmetic).
const PINNED: [u64; 13] = [
    0xb265dc929d256a36,
    0x30e58b247e6c7cfa,
    0xe255fed76049af3c,
    0xe92c8b4c85132fe6,
    0x8bafb2de8d731fa5,
    0x13e83a5cafb8b9b1,
    0x6933b4438909383a,
    0x0256fa8f65d5f5c6,
    0x276f8270b85f6a84,
    0xde24b9b7ce9a8a1b,
    0x3f97593b2a2afdc7,
    0x879c1107413c0011,
    0x7ac31b6f8de07915,
];
