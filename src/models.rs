//! Ready-made structural models: builders for `M`, `K`, `C` as row-major `f64` arrays,
//! usable in `const` contexts (so firmware can build operators from them at compile time).
//!
//! The benchmark building of this repository's tables is [`five_storey_building`]. A
//! shear building whose storeys yield (bilinear, Bouc–Wen or friction storeys with linear
//! damping, for the nonlinear stepper) is
//! [`hysteresis::ShearBuilding`](crate::hysteresis::ShearBuilding).

pub use crate::linalg::Rows;

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
