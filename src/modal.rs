//! Modal reduction: step only the modes, inputs and outputs a scene needs.
//!
//! For `M u'' + C u' + K u = B w(t)` with `M` symmetric positive definite, `K` symmetric
//! and classical damping, the mass-normalised modes `Φ` (`Φᵀ M Φ = I`,
//! `Φᵀ K Φ = diag(ω²)`, `Φᵀ C Φ = diag(2ξω)`) decouple the system into `N` independent
//! oscillators
//!
//! ```text
//! η_r'' + 2ξ_r ω_r η_r' + ω_r² η_r = Γ_r w(t),     Γ = Φᵀ B,     u ≈ Σ_r φ_r η_r
//! ```
//!
//! [`Modal`] keeps `R` of them and steps each with the scalar AEM recurrence (the same
//! scheme as [`Linear`](crate::Linear), which is invariant under this change of
//! coordinates: with `R = N` both give the same sequence up to rounding). A step costs
//! `R·I` multiply-adds for the inputs and `7R` for the oscillators; `O` outputs
//! `y = Y u` (any `O×N` selection: DOFs, inter-storey drifts, …) cost `O·R` each time
//! they are read; the full state (`3N·R`) only when asked for.
//!
//! The eigenproblem `K φ = ω² M φ` is solved once, in `f64`, by `const fn` code: Cholesky
//! `M = L Lᵀ`, symmetric eigen-decomposition `L⁻¹ K L⁻ᵀ = Q Λ Qᵀ` (cyclic Jacobi),
//! `Φ = L⁻ᵀ Q`. At run time ([`Modal::new`]) or by the compiler into flash
//! (`Modal::from_rows` in a `static`), with bit-identical results.

use nalgebra::{SMatrix, SVector};

use crate::models::Rows;
use crate::ops;
use crate::{Error, Real, State};

/// Relative tolerance below which `M`, `K` count as symmetric: `|a_ij − a_ji| ≤
/// 64 ε max|a|` (rounding of a matrix assembled in `f64`).
const SYMMETRY_TOL: f64 = 64.0 * f64::EPSILON;

/// Largest modal coupling `|(ΦᵀCΦ)_rs| / √((ΦᵀCΦ)_rr (ΦᵀCΦ)_ss)`, `r ≠ s`, for which a
/// damping matrix counts as classical. Dropping couplings this small changes modal
/// responses by about the same relative amount, far below the AEM's `O(h²)` error at
/// practical steps.
pub const CLASSICAL_COUPLING_TOL: f64 = 1e-6;

/// How the structure is damped; every form here is classical (diagonal in the modes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Damping<const N: usize> {
    /// No damping (`C = 0`).
    None,
    /// Rayleigh damping `C = a0 M + a1 K` (`a0` in 1/s, `a1` in s): mode `r` gets
    /// `ξ_r = a0/(2ω_r) + a1 ω_r / 2`.
    Rayleigh {
        /// Mass-proportional coefficient (1/s).
        a0: f64,
        /// Stiffness-proportional coefficient (s).
        a1: f64,
    },
    /// One damping ratio per mode, modes in ascending frequency (`ξ = 0.05` is 5 %).
    Ratios([f64; N]),
    /// A full damping matrix `C` (row-major). It must be classical: its modal couplings
    /// must stay below [`CLASSICAL_COUPLING_TOL`], else [`Error::NonClassicalDamping`].
    Matrix(Rows<N>),
}

/// The state of a [`Modal`] stepper at step `n`: modal displacements `η`, velocities `η'`
/// and accelerations `η''` of the `R` kept modes. Plain data, `3R + 1` words;
/// [`Modal::full_state`] rebuilds the `N`-DOF state from it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModalState<T, const R: usize> {
    eta: [T; R],
    deta: [T; R],
    ddeta: [T; R],
    n: u64,
}

impl<T: Real, const R: usize> ModalState<T, R> {
    /// Modal displacements `η` (mass-normalised modes: `η_r = φ_rᵀ M u`, units of
    /// `u·√mass`).
    pub fn eta(&self) -> &[T; R] {
        &self.eta
    }
    /// Modal velocities `η'`.
    pub fn eta_velocity(&self) -> &[T; R] {
        &self.deta
    }
    /// Modal accelerations `η''`.
    pub fn eta_acceleration(&self) -> &[T; R] {
        &self.ddeta
    }
    /// Steps taken since the start, `n`.
    pub fn steps(&self) -> u64 {
        self.n
    }
    /// Every entry is finite.
    pub fn is_finite(&self) -> bool {
        self.eta
            .iter()
            .chain(self.deta.iter())
            .chain(self.ddeta.iter())
            .all(|x| x.is_finite())
    }
}

/// The `R` lowest modes, `[0, 1, …, R−1]` (the default selection of [`Modal::new`]).
pub const fn lowest_modes<const R: usize>() -> [usize; R] {
    let mut r = [0; R];
    let mut i = 0;
    while i < R {
        r[i] = i;
        i += 1;
    }
    r
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

/// A modal (reduced) AEM stepper: `R` of the `N` modes of `M u'' + C u' + K u = B w(t)`,
/// `I` input signals `w`, `O` outputs `y = Y u`.
///
/// Per step: `R·I + 7R` multiply-adds ([`Modal::step`]); per output read: `O·R`
/// ([`Modal::output`]). With `R = N` it reproduces [`Linear`](crate::Linear) to rounding;
/// with `R < N` the error is the truncation of the dropped modes (see the README table).
///
/// Size: `R·(2I + O + 2N + 4) + 3` values of `T` and `R` indices. Build with
/// [`Modal::new`] (the `R` lowest modes) or [`Modal::with_modes`] at run time, or with
/// `Modal::from_rows` / `Modal::from_rows_with_modes` (`const fn`: in a `static`, computed
/// by the compiler into flash); in `f64`, rounded once to `T`.
///
/// ```
/// use aemstep::{models, Damping, Modal};
/// use aemstep::modal::{base_excitation, storey_drifts};
/// use nalgebra::vector;
///
/// // The benchmark 5-storey building: 2 modes, base excitation, roof drift out.
/// let (m, _c, k) = models::five_storey_building();
/// let (w1, w2) = (9.0, 26.3); // rad/s, see `five_storey_building`
/// let (a0, a1) = models::rayleigh_coefficients(w1, w2, 0.05);
/// let roof = [[0.0, 0.0, 0.0, 0.0, 1.0]];
/// let sys = Modal::<f32, 5, 2>::new(
///     &m, &k, &Damping::Rayleigh { a0, a1 }, &base_excitation(&m), &roof, 0.02,
/// )?;
/// let mut s = sys.start_at_rest(&vector![0.0])?;
/// sys.step(&mut s, &vector![0.1 * 9.80665]);
/// assert!(sys.output(&s)[0] < 0.0);
/// let _drifts: [[f64; 5]; 5] = storey_drifts();
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Modal<T, const N: usize, const R: usize, const I: usize = 1, const O: usize = 1> {
    h: T,
    half_h: T,
    quarter_h2: T,
    /// `g_r Γ_r`: input projection times the modal effective inverse, `R×I`.
    g_gamma: [[T; I]; R],
    /// `g_r · 2ξ_r ω_r`.
    g_c: [T; R],
    /// `g_r · ω_r²`.
    g_k: [T; R],
    /// `Γ = Φ_Rᵀ B`, `R×I` (start-up).
    gamma: [[T; I]; R],
    /// `2ξ_r ω_r` (1/s).
    c: [T; R],
    /// `ω_r²` (rad²/s²).
    k: [T; R],
    /// `Y Φ_R`, `O×R`.
    out: [[T; R]; O],
    /// `Φ_R`, `N×R` (reconstruction).
    phi: [[T; R]; N],
    /// `Φ_Rᵀ M`, `R×N` (projection of initial conditions).
    proj: [[T; N]; R],
    modes: [usize; R],
}

// ---------------------------------------------------------------------------------------
// Construction, all in `const fn` `f64`: the same code serves `Modal::new` at run time and
// `Modal::from_rows` evaluated by the compiler, so both give bit-identical operators.

/// Largest `|a_ij|` (finite input: checked before every use).
const fn max_abs<const R: usize, const C: usize>(a: &[[f64; C]; R]) -> f64 {
    let mut s = 0.0f64;
    let mut i = 0;
    while i < R {
        let mut j = 0;
        while j < C {
            if a[i][j].abs() > s {
                s = a[i][j].abs();
            }
            j += 1;
        }
        i += 1;
    }
    s
}

const fn is_symmetric<const N: usize>(a: &Rows<N>) -> bool {
    let tol = SYMMETRY_TOL * max_abs(a);
    let mut i = 0;
    while i < N {
        let mut j = 0;
        while j < i {
            if (a[i][j] - a[j][i]).abs() > tol {
                return false;
            }
            j += 1;
        }
        i += 1;
    }
    true
}

/// `√x` for finite `x ≥ 0`, in `const`: Newton's iteration from a bit-level first guess
/// (relative error ≤ 6 %), iterated until it stops changing (≤ 1 ulp from the correctly
/// rounded root; at most 64 iterations, 6 for normal numbers). `NaN` for `x < 0`.
const fn sqrt(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    if x < 0.0 {
        return f64::NAN;
    }
    let mut y = f64::from_bits((x.to_bits() >> 1) + 0x1FF8_0000_0000_0000);
    let mut i = 0;
    while i < 64 {
        let z = 0.5 * (y + x / y);
        if z == y {
            break;
        }
        y = z;
        i += 1;
    }
    y
}

/// The sweep budget of [`jacobi_eigen`]: far beyond what quadratic convergence needs; a
/// guard, not a tuning knob.
const JACOBI_MAX_SWEEPS: u32 = 64;

/// Eigen-decomposition of a symmetric `a` by cyclic Jacobi rotations: `(λ, V)` with
/// `a V = V diag(λ)`, `V` orthogonal (row-major), unsorted.
///
/// Jacobi rather than `nalgebra::SymmetricEigen`: the latter needs `Const<N>: DimSub<U1>`
/// bounds that a const-generic `N` cannot meet without leaking type-level integers into
/// every caller, and it is not `const`. Jacobi is backward stable, accurate to `O(ε‖a‖)`
/// and converges quadratically (≲ 10 sweeps for `N ≤ 50`); `≈ 4N³` flops a sweep.
/// [`Error::EigenNotConverged`] after `max_sweeps` sweeps (callers pass
/// [`JACOBI_MAX_SWEEPS`]).
const fn jacobi_eigen<const N: usize>(
    mut a: Rows<N>,
    max_sweeps: u32,
) -> Result<([f64; N], Rows<N>), Error> {
    let mut v = [[0.0; N]; N];
    let mut fro2 = 0.0;
    let mut i = 0;
    while i < N {
        v[i][i] = 1.0;
        let mut j = 0;
        while j < N {
            fro2 += a[i][j] * a[i][j];
            j += 1;
        }
        i += 1;
    }
    let fro = sqrt(fro2);
    let mut sweep = 0;
    while sweep < max_sweeps {
        let mut off = 0.0;
        let mut p = 0;
        while p < N {
            let mut q = 0;
            while q < N {
                if p != q {
                    off += a[p][q] * a[p][q];
                }
                q += 1;
            }
            p += 1;
        }
        if sqrt(off) <= f64::EPSILON * fro {
            let mut lam = [0.0; N];
            let mut i = 0;
            while i < N {
                lam[i] = a[i][i];
                i += 1;
            }
            return Ok((lam, v));
        }
        let mut p = 0;
        while p < N {
            let mut q = p + 1;
            while q < N {
                let apq = a[p][q];
                // Below rounding of the diagonal pair: already decoupled.
                if apq.abs() <= 0.25 * f64::EPSILON * sqrt((a[p][p] * a[q][q]).abs()) {
                    a[p][q] = 0.0;
                    a[q][p] = 0.0;
                    q += 1;
                    continue;
                }
                // Rotation zeroing a_pq: cot 2φ = θ, t = tan φ (the smaller root).
                let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
                let t = if theta.abs() > 1e150 {
                    0.5 / theta
                } else {
                    let t = 1.0 / (theta.abs() + sqrt(theta * theta + 1.0));
                    if theta < 0.0 { -t } else { t }
                };
                let c = 1.0 / sqrt(t * t + 1.0);
                let s = t * c;
                let mut k = 0;
                while k < N {
                    let (akp, akq) = (a[k][p], a[k][q]);
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                    k += 1;
                }
                k = 0;
                while k < N {
                    let (apk, aqk) = (a[p][k], a[q][k]);
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                    k += 1;
                }
                k = 0;
                while k < N {
                    let (vkp, vkq) = (v[k][p], v[k][q]);
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                    k += 1;
                }
                // Zeroed by construction; store the exact zero, not its rounding.
                a[p][q] = 0.0;
                a[q][p] = 0.0;
                q += 1;
            }
            p += 1;
        }
        sweep += 1;
    }
    Err(Error::EigenNotConverged)
}

/// Cholesky factor `L` (lower, row-major) of a symmetric `m`; `None` unless every pivot
/// exceeds `N ε max|m|` (positive definite and not singular to working precision).
const fn cholesky<const N: usize>(m: &Rows<N>) -> Option<Rows<N>> {
    let tiny = N as f64 * f64::EPSILON * max_abs(m);
    let mut l = [[0.0; N]; N];
    let mut j = 0;
    while j < N {
        let mut s = m[j][j];
        let mut k = 0;
        while k < j {
            s -= l[j][k] * l[j][k];
            k += 1;
        }
        if s.is_nan() || s <= tiny {
            return None;
        }
        let d = sqrt(s);
        l[j][j] = d;
        let mut i = j + 1;
        while i < N {
            let mut s = m[i][j];
            let mut k = 0;
            while k < j {
                s -= l[i][k] * l[j][k];
                k += 1;
            }
            l[i][j] = s / d;
            i += 1;
        }
        j += 1;
    }
    Some(l)
}

/// `L⁻¹ B` for lower-triangular `L` with a nonzero diagonal (forward substitution).
const fn lower_solve<const N: usize>(l: &Rows<N>, b: &Rows<N>) -> Rows<N> {
    let mut x = [[0.0; N]; N];
    let mut c = 0;
    while c < N {
        let mut i = 0;
        while i < N {
            let mut s = b[i][c];
            let mut k = 0;
            while k < i {
                s -= l[i][k] * x[k][c];
                k += 1;
            }
            x[i][c] = s / l[i][i];
            i += 1;
        }
        c += 1;
    }
    x
}

/// `L⁻ᵀ B` for lower-triangular `L` with a nonzero diagonal (back substitution).
const fn lower_transpose_solve<const N: usize>(l: &Rows<N>, b: &Rows<N>) -> Rows<N> {
    let mut x = [[0.0; N]; N];
    let mut c = 0;
    while c < N {
        let mut i = N;
        while i > 0 {
            i -= 1;
            let mut s = b[i][c];
            let mut k = i + 1;
            while k < N {
                s -= l[k][i] * x[k][c];
                k += 1;
            }
            x[i][c] = s / l[i][i];
        }
        c += 1;
    }
    x
}

const fn transpose<const N: usize>(a: &Rows<N>) -> Rows<N> {
    let mut t = [[0.0; N]; N];
    let mut i = 0;
    while i < N {
        let mut j = 0;
        while j < N {
            t[j][i] = a[i][j];
            j += 1;
        }
        i += 1;
    }
    t
}

/// `(ω², Φ)` of `K φ = ω² M φ`, ascending, `Φᵀ M Φ = I` (`Φ` row-major, column `r` is
/// mode `r`): Cholesky `M = L Lᵀ`, Jacobi on `L⁻¹ K L⁻ᵀ = Q Λ Qᵀ`, `Φ = L⁻ᵀ Q`.
const fn modes_of<const N: usize>(m: &Rows<N>, k: &Rows<N>) -> Result<([f64; N], Rows<N>), Error> {
    if !is_symmetric(m) {
        return Err(Error::MassNotSpd);
    }
    if !is_symmetric(k) {
        return Err(Error::StiffnessNotSymmetric);
    }
    let l = match cholesky(m) {
        Some(l) => l,
        None => return Err(Error::MassNotSpd),
    };
    // A = L⁻¹ K L⁻ᵀ = L⁻¹ (L⁻¹ K)ᵀ for symmetric K; symmetrized against rounding.
    let x = lower_solve(&l, k);
    let mut a = lower_solve(&l, &transpose(&x));
    let mut i = 0;
    while i < N {
        let mut j = 0;
        while j < i {
            let s = 0.5 * (a[i][j] + a[j][i]);
            a[i][j] = s;
            a[j][i] = s;
            j += 1;
        }
        i += 1;
    }
    let (lam, q) = match jacobi_eigen(a, JACOBI_MAX_SWEEPS) {
        Ok(e) => e,
        Err(e) => return Err(e),
    };
    // Ascending order (insertion sort of the indices).
    let mut idx: [usize; N] = lowest_modes();
    let mut i = 1;
    while i < N {
        let mut j = i;
        while j > 0 && lam[idx[j - 1]] > lam[idx[j]] {
            let t = idx[j - 1];
            idx[j - 1] = idx[j];
            idx[j] = t;
            j -= 1;
        }
        i += 1;
    }
    let mut qs = [[0.0; N]; N];
    let mut ls = [0.0; N];
    let mut j = 0;
    while j < N {
        ls[j] = lam[idx[j]];
        let mut i = 0;
        while i < N {
            qs[i][j] = q[i][idx[j]];
            i += 1;
        }
        j += 1;
    }
    Ok((ls, lower_transpose_solve(&l, &qs)))
}

/// `2ξ_r ω_r` of every mode for the given damping.
const fn modal_damping<const N: usize>(
    damping: &Damping<N>,
    lam: &[f64; N],
    phi: &Rows<N>,
) -> Result<[f64; N], Error> {
    let mut out = [0.0; N];
    match *damping {
        Damping::None => {}
        Damping::Rayleigh { a0, a1 } => {
            if !(a0.is_finite() && a1.is_finite()) {
                return Err(Error::NonFiniteInput);
            }
            let mut r = 0;
            while r < N {
                out[r] = a0 + a1 * lam[r];
                r += 1;
            }
        }
        Damping::Ratios(xi) => {
            // ω = √|λ|: for a (physically unstable) negative ω² the ratio scales √|ω²|.
            let mut r = 0;
            while r < N {
                if !xi[r].is_finite() {
                    return Err(Error::NonFiniteInput);
                }
                out[r] = 2.0 * xi[r] * sqrt(lam[r].abs());
                r += 1;
            }
        }
        Damping::Matrix(c) => {
            if !ops::all_finite(&c) {
                return Err(Error::NonFiniteInput);
            }
            // D = Φᵀ C Φ
            let mut cp = [[0.0; N]; N];
            let mut i = 0;
            while i < N {
                let mut s = 0;
                while s < N {
                    let mut acc = 0.0;
                    let mut l = 0;
                    while l < N {
                        acc += c[i][l] * phi[l][s];
                        l += 1;
                    }
                    cp[i][s] = acc;
                    s += 1;
                }
                i += 1;
            }
            let mut d = [[0.0; N]; N];
            let mut r = 0;
            while r < N {
                let mut s = 0;
                while s < N {
                    let mut acc = 0.0;
                    let mut l = 0;
                    while l < N {
                        acc += phi[l][r] * cp[l][s];
                        l += 1;
                    }
                    d[r][s] = acc;
                    s += 1;
                }
                r += 1;
            }
            let mut scale = 0.0f64;
            let mut r = 0;
            while r < N {
                if d[r][r].abs() > scale {
                    scale = d[r][r].abs();
                }
                r += 1;
            }
            let floor = SYMMETRY_TOL * scale;
            let mut r = 0;
            while r < N {
                let mut s = 0;
                while s < N {
                    let allowed = CLASSICAL_COUPLING_TOL * sqrt((d[r][r] * d[s][s]).abs()) + floor;
                    if r != s && d[r][s].abs() > allowed {
                        return Err(Error::NonClassicalDamping);
                    }
                    s += 1;
                }
                out[r] = d[r][r];
                r += 1;
            }
        }
    }
    Ok(out)
}

/// Every operator of a [`Modal`], in `f64`.
struct ModalOps<const N: usize, const R: usize, const I: usize, const O: usize> {
    half_h: f64,
    quarter_h2: f64,
    g_gamma: [[f64; I]; R],
    g_c: [f64; R],
    g_k: [f64; R],
    gamma: [[f64; I]; R],
    c: [f64; R],
    k: [f64; R],
    out: [[f64; R]; O],
    phi: [[f64; R]; N],
    proj: [[f64; N]; R],
}

/// Check the data and build every operator (shared by `with_modes` and the `const`
/// constructors).
const fn modal_operators<const N: usize, const R: usize, const I: usize, const O: usize>(
    m: &Rows<N>,
    k: &Rows<N>,
    damping: &Damping<N>,
    b: &[[f64; I]; N],
    y: &[[f64; N]; O],
    modes: &[usize; R],
    h: f64,
) -> Result<ModalOps<N, R, I, O>, Error> {
    if R == 0 || R > N {
        return Err(Error::InvalidModeSelection);
    }
    let mut i = 0;
    while i < R {
        if modes[i] >= N {
            return Err(Error::InvalidModeSelection);
        }
        let mut j = 0;
        while j < i {
            if modes[i] == modes[j] {
                return Err(Error::InvalidModeSelection);
            }
            j += 1;
        }
        i += 1;
    }
    if !(ops::all_finite(m)
        && ops::all_finite(k)
        && ops::all_finite_rect(b)
        && ops::all_finite_rect(y))
    {
        return Err(Error::NonFiniteInput);
    }
    if !(h.is_finite() && h > 0.0) {
        return Err(Error::InvalidTimeStep);
    }
    let (lam, phi) = match modes_of(m, k) {
        Ok(x) => x,
        Err(e) => return Err(e),
    };
    let c_all = match modal_damping(damping, &lam, &phi) {
        Ok(x) => x,
        Err(e) => return Err(e),
    };
    let (half_h, quarter_h2) = (0.5 * h, 0.25 * h * h);
    let mut op = ModalOps {
        half_h,
        quarter_h2,
        g_gamma: [[0.0; I]; R],
        g_c: [0.0; R],
        g_k: [0.0; R],
        gamma: [[0.0; I]; R],
        c: [0.0; R],
        k: [0.0; R],
        out: [[0.0; R]; O],
        phi: [[0.0; R]; N],
        proj: [[0.0; N]; R],
    };
    let mut r = 0;
    while r < R {
        let mode = modes[r];
        let (c, lam) = (c_all[mode], lam[mode]);
        let meff = 1.0 + half_h * c + quarter_h2 * lam;
        if !(meff.is_finite() && meff > f64::EPSILON) {
            return Err(Error::SingularEffectiveMatrix);
        }
        let g = 1.0 / meff;
        op.g_c[r] = g * c;
        op.g_k[r] = g * lam;
        op.c[r] = c;
        op.k[r] = lam;
        let mut j = 0;
        while j < I {
            let mut gam = 0.0;
            let mut i = 0;
            while i < N {
                gam += phi[i][mode] * b[i][j];
                i += 1;
            }
            op.gamma[r][j] = gam;
            op.g_gamma[r][j] = g * gam;
            j += 1;
        }
        let mut o = 0;
        while o < O {
            let mut yo = 0.0;
            let mut i = 0;
            while i < N {
                yo += y[o][i] * phi[i][mode];
                i += 1;
            }
            op.out[o][r] = yo;
            o += 1;
        }
        let mut i = 0;
        while i < N {
            op.phi[i][r] = phi[i][mode];
            let mut pm = 0.0;
            let mut l = 0;
            while l < N {
                pm += phi[l][mode] * m[l][i];
                l += 1;
            }
            op.proj[r][i] = pm;
            i += 1;
        }
        r += 1;
    }
    Ok(op)
}

fn round1<T: Real, const A: usize>(a: &[f64; A]) -> [T; A] {
    a.map(T::from_f64_rounded)
}

fn round2<T: Real, const A: usize, const B: usize>(a: &[[f64; B]; A]) -> [[T; B]; A] {
    a.map(|r| r.map(T::from_f64_rounded))
}

impl<T: Real, const N: usize, const R: usize, const I: usize, const O: usize> Modal<T, N, R, I, O> {
    /// A modal stepper keeping the `R` lowest modes of `M u'' + C u' + K u = B w(t)`.
    ///
    /// - `m`, `k`: `N×N` row-major (units e.g. kg, N/m); `M` symmetric positive
    ///   definite, `K` symmetric (to `64 ε` relative).
    /// - `damping`: classical damping ([`Damping`]).
    /// - `b`: influence matrix, `N×I` (e.g. [`base_excitation`]).
    /// - `y`: output matrix, `O×N` (e.g. a row selecting the roof, or [`storey_drifts`]).
    /// - `h`: time step (s).
    ///
    /// Computed in `f64` by the same `const` code as `Modal::from_rows` (bit-identical
    /// results), rounded once to `T`.
    ///
    /// Errors: [`Error::InvalidModeSelection`] (`R = 0` or `R > N`),
    /// [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`], [`Error::MassNotSpd`],
    /// [`Error::StiffnessNotSymmetric`], [`Error::NonClassicalDamping`],
    /// [`Error::EigenNotConverged`], [`Error::SingularEffectiveMatrix`] (a mode with
    /// `1 + (h/2)·2ξω + (h²/4)·ω² ≤ 0`, possible only for negative `ω²` or `ξ`).
    ///
    /// Cost: `O(N³)` `f64` flops (Jacobi: `≈ 4N³` a sweep, a few sweeps) and a few `N×N`
    /// `f64` temporaries on the stack; once.
    pub fn new(
        m: &Rows<N>,
        k: &Rows<N>,
        damping: &Damping<N>,
        b: &[[f64; I]; N],
        y: &[[f64; N]; O],
        h: f64,
    ) -> Result<Self, Error> {
        Self::with_modes(m, k, damping, b, y, lowest_modes(), h)
    }

    /// As [`Modal::new`], keeping the modes `modes` (indices into the modes sorted by
    /// ascending frequency, `0` the fundamental; distinct, each `< N`).
    ///
    /// Errors: as [`Modal::new`]; [`Error::InvalidModeSelection`] also for an index
    /// `≥ N` or a repeated one.
    pub fn with_modes(
        m: &Rows<N>,
        k: &Rows<N>,
        damping: &Damping<N>,
        b: &[[f64; I]; N],
        y: &[[f64; N]; O],
        modes: [usize; R],
        h: f64,
    ) -> Result<Self, Error> {
        let op = modal_operators(m, k, damping, b, y, &modes, h)?;
        Ok(Self {
            h: T::from_f64_rounded(h),
            half_h: T::from_f64_rounded(op.half_h),
            quarter_h2: T::from_f64_rounded(op.quarter_h2),
            g_gamma: round2(&op.g_gamma),
            g_c: round1(&op.g_c),
            g_k: round1(&op.g_k),
            gamma: round2(&op.gamma),
            c: round1(&op.c),
            k: round1(&op.k),
            out: round2(&op.out),
            phi: round2(&op.phi),
            proj: round2(&op.proj),
            modes,
        })
    }
}

/// Const-fn construction, for modal operators computed at compile time into flash.
macro_rules! const_ctor {
    ($t:ident) => {
        impl<const N: usize, const R: usize, const I: usize, const O: usize> Modal<$t, N, R, I, O> {
            /// `const fn` twin of [`Modal::new`] (the `R` lowest modes), bit-identical to
            /// it. In a `static`, the compiler solves the eigenproblem and no eigen-solver
            /// code is linked into the firmware.
            ///
            /// Errors: as [`Modal::new`].
            pub const fn from_rows(
                m: Rows<N>,
                k: Rows<N>,
                damping: Damping<N>,
                b: [[f64; I]; N],
                y: [[f64; N]; O],
                h: f64,
            ) -> Result<Self, Error> {
                Self::from_rows_with_modes(m, k, damping, b, y, lowest_modes(), h)
            }

            /// `const fn` twin of [`Modal::with_modes`], bit-identical to it.
            ///
            /// Errors: as [`Modal::with_modes`].
            pub const fn from_rows_with_modes(
                m: Rows<N>,
                k: Rows<N>,
                damping: Damping<N>,
                b: [[f64; I]; N],
                y: [[f64; N]; O],
                modes: [usize; R],
                h: f64,
            ) -> Result<Self, Error> {
                let op = match modal_operators(&m, &k, &damping, &b, &y, &modes, h) {
                    Ok(op) => op,
                    Err(e) => return Err(e),
                };
                Ok(Self {
                    h: h as $t,
                    half_h: op.half_h as $t,
                    quarter_h2: op.quarter_h2 as $t,
                    g_gamma: ops::const_round!($t, rows op.g_gamma),
                    g_c: ops::const_round!($t, vec op.g_c),
                    g_k: ops::const_round!($t, vec op.g_k),
                    gamma: ops::const_round!($t, rows op.gamma),
                    c: ops::const_round!($t, vec op.c),
                    k: ops::const_round!($t, vec op.k),
                    out: ops::const_round!($t, rows op.out),
                    phi: ops::const_round!($t, rows op.phi),
                    proj: ops::const_round!($t, rows op.proj),
                    modes,
                })
            }
        }
    };
}
const_ctor!(f32);
const_ctor!(f64);

impl<T: Real, const N: usize, const R: usize, const I: usize, const O: usize> Modal<T, N, R, I, O> {
    /// The time step `h` (s).
    pub fn time_step(&self) -> T {
        self.h
    }

    /// The kept modes (indices in ascending frequency, `0` the fundamental).
    pub fn modes(&self) -> &[usize; R] {
        &self.modes
    }

    /// Circular frequencies `ω_r` (rad/s) of the kept modes (`√|ω²|`).
    pub fn frequencies(&self) -> [T; R] {
        self.k.map(|k| k.abs().sqrt())
    }

    /// Damping ratios `ξ_r = (2ξω)_r / (2ω_r)` of the kept modes (`NaN` for `ω = 0`).
    pub fn damping_ratios(&self) -> [T; R] {
        let two = T::one() + T::one();
        core::array::from_fn(|r| self.c[r] / (two * self.k[r].abs().sqrt()))
    }

    /// The kept mass-normalised mode shapes `Φ_R` (`N×R`, `Φᵀ M Φ = I`).
    pub fn mode_shapes(&self) -> SMatrix<T, N, R> {
        SMatrix::from_fn(|i, r| self.phi[i][r])
    }

    /// The modal input matrix `Γ = Φ_Rᵀ B` (`R×I`).
    pub fn participation(&self) -> SMatrix<T, R, I> {
        SMatrix::from_fn(|r, j| self.gamma[r][j])
    }

    /// The state at `t = 0` from `u0`, `v0` (projected on the kept modes:
    /// `η0 = Φ_Rᵀ M u0`, exact when `u0` lies in their span) and `w0`, with
    /// `η0'' = Γ w0 − 2ξω η0' − ω² η0`.
    ///
    /// Errors: [`Error::NonFiniteInput`], [`Error::NonFiniteState`]. Cost: `2R·N + R·I`.
    pub fn start(
        &self,
        u0: &SVector<T, N>,
        v0: &SVector<T, N>,
        w0: &SVector<T, I>,
    ) -> Result<ModalState<T, R>, Error> {
        let ok = u0
            .iter()
            .chain(v0.iter())
            .chain(w0.iter())
            .all(|x| x.is_finite());
        if !ok {
            return Err(Error::NonFiniteInput);
        }
        let mut s = ModalState {
            eta: [T::zero(); R],
            deta: [T::zero(); R],
            ddeta: [T::zero(); R],
            n: 0,
        };
        for r in 0..R {
            let (mut e, mut de, mut f) = (T::zero(), T::zero(), T::zero());
            for i in 0..N {
                e += self.proj[r][i] * u0[i];
                de += self.proj[r][i] * v0[i];
            }
            for j in 0..I {
                f += self.gamma[r][j] * w0[j];
            }
            s.eta[r] = e;
            s.deta[r] = de;
            s.ddeta[r] = f - self.c[r] * de - self.k[r] * e;
        }
        if s.is_finite() {
            Ok(s)
        } else {
            Err(Error::NonFiniteState)
        }
    }

    /// The state at `t = 0` at rest (`u0 = v0 = 0`) under the input `w0`.
    ///
    /// Errors: [`Error::NonFiniteInput`]. Cost: `R·I`.
    pub fn start_at_rest(&self, w0: &SVector<T, I>) -> Result<ModalState<T, R>, Error> {
        self.start(&SVector::zeros(), &SVector::zeros(), w0)
    }

    /// Advance `state` from `t_{n−1}` to `t_n` under the input `w_n = w(t_n)`: each kept
    /// mode takes one scalar AEM step.
    ///
    /// Cost: `R·I + 7R` multiply-adds; fixed, no allocation, no panic. A NaN input gives a
    /// NaN state: use [`Modal::try_step`] where that must not happen.
    #[inline]
    pub fn step(&self, s: &mut ModalState<T, R>, w: &SVector<T, I>) {
        let (half_h, h, quarter_h2) = (self.half_h, self.h, self.quarter_h2);
        for r in 0..R {
            let vh = s.deta[r] + half_h * s.ddeta[r];
            let uh = s.eta[r] + h * s.deta[r] + quarter_h2 * s.ddeta[r];
            let mut q = T::zero();
            for j in 0..I {
                q += self.g_gamma[r][j] * w[j];
            }
            q -= self.g_c[r] * vh + self.g_k[r] * uh;
            s.ddeta[r] = q;
            s.deta[r] = vh + half_h * q;
            s.eta[r] = uh + quarter_h2 * q;
        }
        s.n = s.n.wrapping_add(1);
    }

    /// [`Modal::step`], committed only if the new state is finite.
    ///
    /// Errors: [`Error::NonFiniteState`], leaving `state` bit-identical.
    pub fn try_step(&self, state: &mut ModalState<T, R>, w: &SVector<T, I>) -> Result<(), Error> {
        let mut next = *state;
        self.step(&mut next, w);
        if next.is_finite() {
            *state = next;
            Ok(())
        } else {
            Err(Error::NonFiniteState)
        }
    }

    /// The outputs `y = Y u ≈ (Y Φ_R) η` (displacement units). Cost: `O·R`.
    #[inline]
    pub fn output(&self, s: &ModalState<T, R>) -> SVector<T, O> {
        self.apply_out(&s.eta)
    }

    /// The output rates `Y u'`. Cost: `O·R`.
    pub fn output_velocity(&self, s: &ModalState<T, R>) -> SVector<T, O> {
        self.apply_out(&s.deta)
    }

    /// The output accelerations `Y u''` (relative to the base for base excitation).
    /// Cost: `O·R`.
    pub fn output_acceleration(&self, s: &ModalState<T, R>) -> SVector<T, O> {
        self.apply_out(&s.ddeta)
    }

    #[inline]
    fn apply_out(&self, x: &[T; R]) -> SVector<T, O> {
        SVector::from_fn(|o, _| {
            let mut y = T::zero();
            for r in 0..R {
                y += self.out[o][r] * x[r];
            }
            y
        })
    }

    /// The full `N`-DOF state `u = Φ_R η`, `v = Φ_R η'`, `a = Φ_R η''` (on demand, not
    /// every step). Cost: `3N·R`.
    pub fn full_state(&self, s: &ModalState<T, R>) -> State<T, N> {
        let map = |x: &[T; R]| {
            SVector::<T, N>::from_fn(|i, _| {
                let mut y = T::zero();
                for r in 0..R {
                    y += self.phi[i][r] * x[r];
                }
                y
            })
        };
        State::from_parts(map(&s.eta), map(&s.deta), map(&s.ddeta), s.n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sweep guard: a matrix that needs rotations fails with `EigenNotConverged` when
    /// the budget is too small, and converges within the real budget.
    #[test]
    fn jacobi_reports_non_convergence_past_its_sweep_budget() {
        let a = [[2.0, 1.0, 0.5], [1.0, 3.0, 0.25], [0.5, 0.25, 4.0]];
        assert_eq!(
            jacobi_eigen(a, 0).map(|_| ()),
            Err(Error::EigenNotConverged)
        );
        assert_eq!(
            jacobi_eigen(a, 1).map(|_| ()),
            Err(Error::EigenNotConverged)
        );
        let (lam, _) = jacobi_eigen(a, JACOBI_MAX_SWEEPS).unwrap();
        // Trace and determinant are invariants: Σλ = 9, Πλ = det a = 19.375.
        assert!((lam.iter().sum::<f64>() - 9.0).abs() < 1e-14);
        assert!((lam.iter().product::<f64>() - 19.375).abs() < 1e-12);
    }

    /// The `const` square root is within 1 ulp of the correctly rounded one (libm's
    /// `sqrt` is correctly rounded) over 40 decades and at the edges.
    #[test]
    fn const_sqrt_within_one_ulp() {
        let mut x = 1e-300f64;
        let mut worst = 0u64;
        while x < 1e300 {
            for f in [1.0, 1.37, 2.0, 3.99, 7.3] {
                let v = x * f;
                let (a, b) = (sqrt(v).to_bits(), nalgebra::ComplexField::sqrt(v).to_bits());
                worst = worst.max(a.abs_diff(b));
            }
            x *= 1.0e10;
        }
        assert!(worst <= 1, "{worst} ulp");
        assert_eq!(sqrt(0.0), 0.0);
        assert_eq!(sqrt(4.0), 2.0);
        assert!(sqrt(-1.0).is_nan());
        assert_eq!(sqrt(f64::INFINITY), f64::INFINITY);
        // Subnormal input still converges.
        let t = 4.9e-324f64;
        assert!((sqrt(t) - 2.2227587494850775e-162).abs() <= 1e-177);
    }
}
