//! Ready-made structural models: builders for `M`, `K`, `C` as row-major `f64` arrays,
//! usable in `const` contexts (so firmware can build operators from them at compile time).
//!
//! The benchmark building of this repository's tables is [`five_storey_building`]. A
//! shear building whose storeys yield (bilinear, Bouc–Wen or friction storeys with linear
//! damping, for the nonlinear stepper) is
//! [`hysteresis::ShearBuilding`](crate::hysteresis::ShearBuilding).

pub use crate::linalg::Rows;

use nalgebra::{SMatrix, SVector};

use crate::Real;

/// Unwrap a `Result<_, aemstep::Error>` in a `const` or `static` initializer: the value, or
/// a build error naming the reason ([`Error::as_str`](crate::Error::as_str)). The same in
/// run-time code, where it panics with that text (prefer `?` there).
///
/// A macro, not a `const fn`: a generic `const fn` cannot drop a `Result<T, _>` whose `T`
/// may have drop glue, so it would need one function per type. Expands to
/// `match expr { Ok(v) => v, Err(e) => panic!("{}", e.as_str()) }`. Cost: none at run
/// time in a `static`.
///
/// ```
/// use aemstep::Linear;
/// static SYS: Linear<f32, 1> =
///     aemstep::unwrap_const!(Linear::<f32, 1>::from_rows_f32([[1.0]], [[0.28]], [[4.0]], 0.002));
/// const M: aemstep::models::Rows<2> = aemstep::models::diagonal([1.0e5, 2.0e5]);
/// assert_eq!(M[1][1], 2.0e5);
/// # let _ = &SYS;
/// ```
///
/// A constructor that fails stops the build:
///
/// ```compile_fail
/// use aemstep::Linear;
/// // h = 0 is not a time step: error[E0080] ... "invalid time step"
/// static SYS: Linear<f32, 1> =
///     aemstep::unwrap_const!(Linear::<f32, 1>::from_rows_f32([[1.0]], [[0.0]], [[4.0]], 0.0));
/// ```
#[macro_export]
macro_rules! unwrap_const {
    ($result:expr) => {
        match $result {
            ::core::result::Result::Ok(value) => value,
            ::core::result::Result::Err(e) => ::core::panic!("{}", $crate::Error::as_str(&e)),
        }
    };
}

/// `diag(d)`: the row-major `N×N` matrix with `d` on its diagonal (e.g. lumped masses, kg,
/// or a diagonal covariance). `const`; cost `N²` stores.
pub const fn diagonal<const N: usize>(d: [f64; N]) -> Rows<N> {
    let mut a = [[0.0; N]; N];
    let mut i = 0;
    while i < N {
        a[i][i] = d[i];
        i += 1;
    }
    a
}

/// The floor masses of a lumped mass matrix: its diagonal (kg when `m` is), the argument
/// [`ShearBuilding::new`] takes, e.g. from [`shear_building`] or
/// [`five_storey_building`]'s `M`. Off-diagonal entries are ignored (a lumped `M` has
/// none). `const`; cost `N`.
pub const fn floor_masses<const N: usize>(m: &Rows<N>) -> [f64; N] {
    let mut d = [0.0; N];
    let mut i = 0;
    while i < N {
        d[i] = m[i][i];
        i += 1;
    }
    d
}

/// Storey drifts `δ_i = u_i − u_{i−1}` (`u_{−1} = 0`, the ground) of a floor vector `u`
/// (displacements, m, or velocities, m/s; DOFs ground storey first), in any scalar type,
/// without naming the building's type. The run-time form of [`storey_drifts`]; what
/// [`ShearBuilding::drifts`] computes. Cost: `N − 1` subtractions.
pub fn drifts<T: Real, const N: usize>(u: &SVector<T, N>) -> SVector<T, N> {
    let mut d = *u;
    for i in 1..N {
        d[i] -= u[i - 1];
    }
    d
}

/// The nalgebra matrix of a row-major array: `a[i][j]` becomes entry `(i, j)`, rounded
/// once to `T`. Use it (not `SMatrix::from(a)`, which reads the arrays as **columns** and
/// gives the transpose) to pass [`Rows`] data to the run-time constructors
/// (`Linear::new(&models::matrix_of(&k), …)` builds what `Linear::from_rows(…, k, …)`
/// builds). Cost: `N²` conversions.
///
/// ```
/// use aemstep::models;
/// use aemstep::nalgebra::SMatrix;
/// let k = [[2.0, -1.0], [0.0, 3.0]]; // row-major: k[0][1] = −1 is row 0, column 1
/// let a: SMatrix<f64, 2, 2> = models::matrix_of(&k);
/// assert_eq!(a[(0, 1)], -1.0);
/// assert_eq!(SMatrix::<f64, 2, 2>::from(k)[(1, 0)], -1.0); // nalgebra's reading: transposed
/// assert_eq!(models::rows_of(&a), k);
/// ```
pub fn matrix_of<T: Real, const N: usize>(rows: &Rows<N>) -> SMatrix<T, N, N> {
    crate::linalg::matrix_t(rows)
}

/// The row-major array of a matrix (`a[i][j]` = entry `(i, j)`, as `f64`), the inverse of
/// [`matrix_of`]: for the `const` constructors' [`Rows`] arguments. Cost: `N²`.
pub fn rows_of<T: Real, const N: usize>(a: &SMatrix<T, N, N>) -> Rows<N> {
    core::array::from_fn(|i| core::array::from_fn(|j| a[(i, j)].as_f64()))
}

/// The hysteretic shear building (storeys from any [`hysteresis`](crate::hysteresis) law
/// plus linear damping, for the nonlinear stepper at any `N`), here beside the linear
/// builders; defined in [`hysteresis`](crate::hysteresis).
pub use crate::hysteresis::ShearBuilding;

/// Lumped masses and storey stiffnesses of a shear building with `N` storeys, ground
/// storey first: returns `(M, K)`, `M = diag(m)`, `K` tridiagonal with
/// `K_ii = k_i + k_{i+1}` (`k_{N+1} = 0`), `K_{i,i+1} = K_{i+1,i} = −k_{i+1}`.
///
/// Units: kg and N/m (or any consistent set). DOF `i` is the displacement of floor `i+1`
/// relative to the ground. No checks here: `Linear::new`/`from_rows_f32`/`from_rows_f64` check the result.
pub const fn shear_building<const N: usize>(m: [f64; N], k: [f64; N]) -> (Rows<N>, Rows<N>) {
    let mut mm = [[0.0; N]; N];
    let mut kk = [[0.0; N]; N];
    let mut i = 0;
    while i < N {
        mm[i][i] = m[i];
        kk[i][i] += k[i];
        if i + 1 < N {
            kk[i][i] += k[i + 1];
            kk[i][i + 1] = -k[i + 1];
            kk[i + 1][i] = -k[i + 1];
        }
        i += 1;
    }
    (mm, kk)
}

/// `A + B` entrywise (e.g. a numerical stiffness plus a specimen's,
/// [`StoreySpecimen::stiffness`](crate::hybrid::StoreySpecimen::stiffness)), in the units
/// of `a` and `b`. `const`; cost `N²` additions.
pub const fn add<const N: usize>(a: &Rows<N>, b: &Rows<N>) -> Rows<N> {
    let mut c = [[0.0; N]; N];
    let mut i = 0;
    while i < N {
        let mut j = 0;
        while j < N {
            c[i][j] = a[i][j] + b[i][j];
            j += 1;
        }
        i += 1;
    }
    c
}

/// Rayleigh damping `C = a0 M + a1 K`.
pub const fn rayleigh<const N: usize>(m: &Rows<N>, k: &Rows<N>, a0: f64, a1: f64) -> Rows<N> {
    let mut c = [[0.0; N]; N];
    let mut i = 0;
    while i < N {
        let mut j = 0;
        while j < N {
            c[i][j] = a0 * m[i][j] + a1 * k[i][j];
            j += 1;
        }
        i += 1;
    }
    c
}

/// Rayleigh coefficients `(a0, a1)` giving damping ratio `xi` at the two circular
/// frequencies `wi`, `wj` (rad/s): `a1 = 2ξ/(ωi + ωj)`, `a0 = a1 ωi ωj`.
pub const fn rayleigh_coefficients(wi: f64, wj: f64, xi: f64) -> (f64, f64) {
    let a1 = 2.0 * xi / (wi + wj);
    (a1 * wi * wj, a1)
}

/// The undamped natural circular frequencies `ω_r` (rad/s) of `M u'' + K u = 0`, ascending:
/// `ω_r = √λ_r` with `K φ_r = λ_r M φ_r`. `const`, so a `const` or `static` feeds them to
/// [`rayleigh_coefficients`] instead of pasting numbers:
///
/// ```
/// use aemstep::models::{self, Rows};
/// use aemstep::unwrap_const;
/// // A 3-storey shear building: 2·10⁵ kg and 4·10⁸ N/m a storey; 5 % in modes 1 and 2.
/// const MK: (Rows<3>, Rows<3>) = models::shear_building([2.0e5; 3], [4.0e8; 3]);
/// const W: [f64; 3] = unwrap_const!(models::natural_frequencies(&MK.0, &MK.1)); // rad/s
/// const AB: (f64, f64) = models::rayleigh_coefficients(W[0], W[1], 0.05);
/// const C: Rows<3> = models::rayleigh(&MK.0, &MK.1, AB.0, AB.1); // N·s/m
/// // ω₁ = 2 √(k/m) sin(π/14) for the uniform 3-storey building.
/// let exact = 2.0 * (4.0e8f64 / 2.0e5).sqrt() * (core::f64::consts::PI / 14.0).sin();
/// assert!((W[0] - exact).abs() < 1e-13 * exact);
/// assert!(C[0][0] > 0.0);
/// ```
///
/// - `m`, `k`: row-major `N×N` (e.g. kg and N/m; any consistent units give `ω` in rad per
///   time unit). `M` symmetric positive definite, `K` symmetric (both to `64 ε`
///   relative) and positive semidefinite; `λ_r ≥ −64 N ε max|λ|` counts as rounding of a
///   zero (a rigid-body mode, `ω = 0`).
/// - Method: the modal stepper's ([`Modal`](crate::Modal)): exact power-of-two scaling,
///   Cholesky `M = L Lᵀ`, cyclic Jacobi on `L⁻¹ K L⁻ᵀ`. Accuracy: each `λ_r` to a small
///   multiple of `ε max|λ|`, so `ω_r` to about `ε λ_max / λ_r` relative
///   (`tests/frequencies.rs`: ≤ 3e-15 relative on uniform shear buildings up to 12 storeys).
///
/// Errors: [`Error::NonFiniteInput`](crate::Error::NonFiniteInput),
/// [`Error::MassNotSpd`](crate::Error::MassNotSpd),
/// [`Error::StiffnessNotSymmetric`](crate::Error::StiffnessNotSymmetric),
/// [`Error::StiffnessIndefinite`](crate::Error::StiffnessIndefinite) (an eigenvalue
/// below the rounding bound), [`Error::EigenNotConverged`](crate::Error::EigenNotConverged),
/// [`Error::OperatorOverflow`](crate::Error::OperatorOverflow) (`ω²` beyond `f64`).
///
/// Cost: `O(N³)` `f64` flops (Jacobi: `≈ 4N³` a sweep, a few sweeps) and a few `N×N` `f64`
/// temporaries on the stack; at compile time in a `const`.
pub const fn natural_frequencies<const N: usize>(
    m: &Rows<N>,
    k: &Rows<N>,
) -> Result<[f64; N], crate::Error> {
    if !(crate::linalg::all_finite(m) && crate::linalg::all_finite(k)) {
        return Err(crate::Error::NonFiniteInput);
    }
    let lam = match crate::modal::modes_of(m, k) {
        Ok((lam, _)) => lam,
        Err(e) => return Err(e),
    };
    // Ascending already; the largest magnitude is at one end.
    let mut big = 0.0f64;
    let mut r = 0;
    while r < N {
        if lam[r].abs() > big {
            big = lam[r].abs();
        }
        r += 1;
    }
    let floor = -64.0 * (N as f64) * f64::EPSILON * big;
    let mut w = [0.0; N];
    let mut r = 0;
    while r < N {
        if lam[r] < floor {
            return Err(crate::Error::StiffnessIndefinite);
        }
        w[r] = if lam[r] > 0.0 {
            crate::linalg::sqrt(lam[r])
        } else {
            0.0
        };
        r += 1;
    }
    Ok(w)
}

/// Storey mass of the benchmark building (kg).
pub const FIVE_STOREY_MASS: f64 = 1.0e5;
/// Storey stiffness of the benchmark building (N/m).
pub const FIVE_STOREY_STIFFNESS: f64 = 1.0e8;
/// Damping ratio of the benchmark building in its first two modes (Rayleigh).
pub const FIVE_STOREY_DAMPING: f64 = 0.05;

/// The benchmark 5-storey shear building used in this repository's tables: uniform
/// storeys, `m = 1·10⁵ kg`, `k = 1·10⁸ N/m`, Rayleigh damping with 5 % in modes 1 and 2.
/// Returns `(M, C, K)`; base excitation is `p = −M ι a_g(t)`, `ι = (1, …, 1)`.
///
/// Its circular frequencies have the closed form
/// `ω_r = 2 √(k/m) sin((2r − 1) π / 22)`, `r = 1…5` (ω₁ ≈ 9.00 rad/s, T₁ ≈ 0.70 s).
/// Cost: `O(N²)` flops; `const`.
pub const fn five_storey_building() -> (Rows<5>, Rows<5>, Rows<5>) {
    let (m, k) = shear_building([FIVE_STOREY_MASS; 5], [FIVE_STOREY_STIFFNESS; 5]);
    // ω_r = 2 √(k/m) sin((2r−1)π/22) for r = 1, 2, with √(k/m) = √1000 and the sines
    // written out (no `const` sin): sin(π/22), sin(3π/22).
    let root = 31.622776601683793; // √(1e8 / 1e5)
    let w1 = 2.0 * root * 0.142314838273285_1;
    let w2 = 2.0 * root * 0.415415013001886_4;
    let (a0, a1) = rayleigh_coefficients(w1, w2, FIVE_STOREY_DAMPING);
    let c = rayleigh(&m, &k, a0, a1);
    (m, c, k)
}

/// The output matrix of the `N` inter-storey drifts of a shear building with DOFs ground
/// storey first: row `i` is `u_i − u_{i−1}` (`u_{−1} = 0`, the ground). `const`.
pub const fn storey_drifts<const N: usize>() -> Rows<N> {
    let mut y = [[0.0; N]; N];
    let mut i = 0;
    while i < N {
        y[i][i] = 1.0;
        if i > 0 {
            y[i][i - 1] = -1.0;
        }
        i += 1;
    }
    y
}

/// The influence matrix `B = −M ι` (`ι = (1, …, 1)`) of base excitation: with it,
/// `p = B a_g(t)` for a ground acceleration `a_g` and `u` relative to the ground. `const`.
pub const fn base_excitation<const N: usize>(m: &Rows<N>) -> [[f64; 1]; N] {
    let mut b = [[0.0; 1]; N];
    let mut i = 0;
    while i < N {
        let mut j = 0;
        while j < N {
            b[i][0] -= m[i][j];
            j += 1;
        }
        i += 1;
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SMatrix;

    #[test]
    fn five_storey_constants_match_closed_form_and_eigenvalues() {
        let root = (FIVE_STOREY_STIFFNESS / FIVE_STOREY_MASS).sqrt();
        assert_eq!(root, 31.622776601683793);
        let pi = core::f64::consts::PI;
        assert!((0.142314838273285_1 - (pi / 22.0).sin()).abs() < 1e-16);
        assert!((0.415415013001886_4 - (3.0 * pi / 22.0).sin()).abs() < 1e-16);
        let (m, c, k) = five_storey_building();
        // Eigenvalues of M⁻¹K (M = m I) against the closed form.
        let kk = SMatrix::<f64, 5, 5>::from_fn(|i, j| k[i][j] / m[i][i]);
        let mut ev: [f64; 5] = kk.symmetric_eigenvalues().as_slice().try_into().unwrap();
        ev.sort_by(|a, b| a.partial_cmp(b).unwrap());
        for (r, &l) in ev.iter().enumerate() {
            let w = 2.0 * root * ((2 * r + 1) as f64 * pi / 22.0).sin();
            assert!(
                (l.sqrt() - w).abs() < 1e-10 * w,
                "mode {r}: {} vs {w}",
                l.sqrt()
            );
        }
        // Rayleigh damping gives exactly 5 % in modes 1 and 2: ξ = a0/(2ω) + a1 ω/2.
        for (r, l) in ev.iter().enumerate().take(2) {
            let w = l.sqrt();
            // C = a0 M + a1 K, recovered from two entries: C_01 = −a1 k, C_44 = a0 m + a1 k.
            let a1 = -c[0][1] / FIVE_STOREY_STIFFNESS;
            let a0 = (c[4][4] - a1 * k[4][4]) / m[4][4];
            let xi = a0 / (2.0 * w) + a1 * w / 2.0;
            assert!((xi - 0.05).abs() < 1e-12, "mode {r}: ξ = {xi}");
        }
    }

    #[test]
    fn shear_building_structure() {
        let (m, k) = shear_building([1.0, 2.0, 3.0], [10.0, 20.0, 30.0]);
        assert_eq!(m, [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]]);
        assert_eq!(
            k,
            [[30.0, -20.0, 0.0], [-20.0, 50.0, -30.0], [0.0, -30.0, 30.0]]
        );
    }
}

/// The Duffing oscillator of the paper's Example 5, `u'' + 0.2 u' + u + u³ = p(t)`: `M = 1`,
/// `F(u, v) = 0.2 v + u + u³`, with its analytic tangent (`K_t = 1 + 3u²`, `C_t = 0.2`).
/// With `u0 = 0`, `v0 = 1` and `p(t) = −0.01 e^{−0.1t} sin t + e^{−0.3t} sin³ t` the exact
/// solution is `u = e^{−0.1t} sin t`. Units: any consistent set (the paper's are
/// dimensionless). Cost: `force` 4 multiplies and 2 adds, `tangent` 3 and 1.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Duffing;

impl<T: crate::Real> crate::Model<T, 1> for Duffing {
    fn mass(&self) -> nalgebra::SMatrix<T, 1, 1> {
        nalgebra::matrix![T::one()]
    }
    fn force(
        &self,
        u: &nalgebra::SVector<T, 1>,
        v: &nalgebra::SVector<T, 1>,
    ) -> nalgebra::SVector<T, 1> {
        let (u, v) = (u[0], v[0]);
        nalgebra::vector![T::from_f64_rounded(0.2) * v + u + u * u * u]
    }
    fn tangent(
        &self,
        u: &nalgebra::SVector<T, 1>,
        _v: &nalgebra::SVector<T, 1>,
    ) -> Option<crate::Tangent<T, 1>> {
        let u = u[0];
        Some(crate::Tangent {
            stiffness: nalgebra::matrix![T::one() + T::from_f64_rounded(3.0) * u * u],
            damping: nalgebra::matrix![T::from_f64_rounded(0.2)],
        })
    }
}
