//! The yielding 3-storey shear building of the hysteresis tests, report and firmware:
//! storey data as `const`s, shared by `examples/qemu_hysteretic.rs` (f32, on target),
//! `tests/firmware_hysteretic.rs` and `tests/hysteresis.rs` (f64, host) and
//! `xtask/src/bin/hysteresis_report.rs`.
#![allow(dead_code)] // each includer uses a different subset

use aemstep::hysteresis::{Bilinear, BoucWen, ShearBuilding};
use aemstep::{Error, Real, models};

/// Storeys.
pub const N: usize = 3;
/// Floor mass (kg), every floor.
pub const MASS: f64 = 1.0e5;
/// Initial storey stiffness (N/m), every storey.
pub const STIFFNESS: f64 = 1.0e8;
/// Storey yield forces (N), ground storey first: about a third of the elastic demand of
/// El Centro, so every storey yields.
pub const YIELD: [f64; N] = [6.0e5, 5.0e5, 3.5e5];
/// Post-yield stiffness ratio.
pub const ALPHA: f64 = 0.05;
/// Rayleigh damping ratio in the first two elastic modes.
pub const XI: f64 = 0.02;
/// Bouc–Wen shape: `β = γ = 1/2`, `n = 2` (saturates at `z = 1`, unloads with `k`).
pub const BETA: f64 = 0.5;
/// See [`BETA`].
pub const GAMMA: f64 = 0.5;
/// See [`BETA`].
pub const EXPONENT: f64 = 2.0;

/// `√(k/m)` (rad/s), written out (no `sqrt` in `core`); checked in tests/hysteresis.rs.
pub const ROOT: f64 = 31.622_776_601_683_793;
/// `sin(π/14)` and `sin(3π/14)`, written out; checked in tests/hysteresis.rs.
pub const SINES: (f64, f64) = (0.222_520_933_956_314_4, 0.623_489_801_858_733_5);

/// Elastic circular frequencies of modes 1 and 2 (rad/s): `2 √(k/m) sin((2r − 1)π/14)`.
pub fn elastic_frequencies() -> (f64, f64) {
    (2.0 * ROOT * SINES.0, 2.0 * ROOT * SINES.1)
}

/// The Rayleigh damping matrix (N·s/m) of the elastic building.
pub fn damping() -> models::Rows<N> {
    let (m, k) = models::shear_building([MASS; N], [STIFFNESS; N]);
    let (w1, w2) = elastic_frequencies();
    let (a0, a1) = models::rayleigh_coefficients(w1, w2, XI);
    models::rayleigh(&m, &k, a0, a1)
}

/// The building with bilinear (kinematic hardening) storeys.
pub fn bilinear<T: Real>() -> Result<ShearBuilding<T, Bilinear<T>, N>, Error> {
    let mut laws = [Bilinear::new(STIFFNESS, YIELD[0], ALPHA)?; N];
    for i in 1..N {
        laws[i] = Bilinear::new(STIFFNESS, YIELD[i], ALPHA)?;
    }
    ShearBuilding::new([MASS; N], laws, &damping())
}

/// The building with Bouc–Wen storeys (same `k`, `f_y`, `α`).
pub fn bouc_wen<T: Real>() -> Result<ShearBuilding<T, BoucWen<T>, N>, Error> {
    let law = |fy| BoucWen::new(STIFFNESS, fy, ALPHA, BETA, GAMMA, EXPONENT);
    let mut laws = [law(YIELD[0])?; N];
    for i in 1..N {
        laws[i] = law(YIELD[i])?;
    }
    ShearBuilding::new([MASS; N], laws, &damping())
}
