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
//! The eigenproblem `K φ = ω² M φ` is solved once, in `f64`, `no_std`: Cholesky
//! `M = L Lᵀ` (`nalgebra`), symmetric eigen-decomposition `L⁻¹ K L⁻ᵀ = Q Λ Qᵀ` (cyclic
//! Jacobi), `Φ = L⁻ᵀ Q`.

use nalgebra::{Cholesky, ComplexField, SMatrix, SVector};

use crate::models::Rows;
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
/// Size: `R·(I + O + 2N + 6) + 3` values of `T`. Build with [`Modal::new`] (the `R`
/// lowest modes) or [`Modal::with_modes`], in `f64`, rounded once to `T`.
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

fn max_abs<const N: usize>(a: &Rows<N>) -> f64 {
    a.iter().flatten().fold(0.0, |s, x| s.max(x.abs()))
}

fn is_symmetric<const N: usize>(a: &Rows<N>) -> bool {
    let tol = SYMMETRY_TOL * max_abs(a);
    (0..N).all(|i| (0..i).all(|j| (a[i][j] - a[j][i]).abs() <= tol))
}

fn finite<const R: usize, const C: usize>(a: &[[f64; C]; R]) -> bool {
    a.iter().flatten().all(|x| x.is_finite())
}

/// Eigen-decomposition of a symmetric `a` by cyclic Jacobi rotations: `(λ, V)` with
/// `a V = V diag(λ)`, `V` orthogonal, unsorted.
///
/// Jacobi is used rather than `nalgebra::SymmetricEigen` because the latter needs
/// `Const<N>: DimSub<U1>` bounds that a const-generic `N` cannot satisfy without leaking
/// type-level-integer bounds into every caller. Jacobi is backward stable and accurate
/// to `O(ε‖a‖)`; it converges quadratically (≲ 10 sweeps for `N ≤ 50`). Cost
/// `≈ 4N³` flops per sweep.
fn jacobi_eigen<const N: usize>(
    mut a: SMatrix<f64, N, N>,
) -> Result<([f64; N], SMatrix<f64, N, N>), Error> {
    let mut v = SMatrix::<f64, N, N>::identity();
    let fro = ComplexField::sqrt(a.iter().map(|x| x * x).sum::<f64>());
    // 64 sweeps: far beyond what quadratic convergence needs; a guard, not a tuning knob.
    for _ in 0..64 {
        let mut off = 0.0;
        for p in 0..N {
            for q in 0..N {
                if p != q {
                    off += a[(p, q)] * a[(p, q)];
                }
            }
        }
        if ComplexField::sqrt(off) <= f64::EPSILON * fro {
            return Ok((core::array::from_fn(|i| a[(i, i)]), v));
        }
        for p in 0..N {
            for q in p + 1..N {
                let apq = a[(p, q)];
                // Below rounding of the diagonal pair: already decoupled.
                if apq.abs()
                    <= 0.25 * f64::EPSILON * ComplexField::sqrt((a[(p, p)] * a[(q, q)]).abs())
                {
                    a[(p, q)] = 0.0;
                    a[(q, p)] = 0.0;
                    continue;
                }
                // Rotation zeroing a_pq: cot 2φ = θ, t = tan φ (the smaller root).
                let theta = (a[(q, q)] - a[(p, p)]) / (2.0 * apq);
                let t = if theta.abs() > 1e150 {
                    0.5 / theta
                } else {
                    let t = 1.0 / (theta.abs() + ComplexField::sqrt(theta * theta + 1.0));
                    if theta < 0.0 { -t } else { t }
                };
                let c = 1.0 / ComplexField::sqrt(t * t + 1.0);
                let s = t * c;
                for k in 0..N {
                    let (akp, akq) = (a[(k, p)], a[(k, q)]);
                    a[(k, p)] = c * akp - s * akq;
                    a[(k, q)] = s * akp + c * akq;
                }
                for k in 0..N {
                    let (apk, aqk) = (a[(p, k)], a[(q, k)]);
                    a[(p, k)] = c * apk - s * aqk;
                    a[(q, k)] = s * apk + c * aqk;
                }
                // Zeroed by construction; store the exact zero, not its rounding.
                a[(p, q)] = 0.0;
                a[(q, p)] = 0.0;
                for k in 0..N {
                    let (vkp, vkq) = (v[(k, p)], v[(k, q)]);
                    v[(k, p)] = c * vkp - s * vkq;
                    v[(k, q)] = s * vkp + c * vkq;
                }
            }
        }
    }
    Err(Error::EigenNotConverged)
}

/// `(ω², Φ)` of `K φ = ω² M φ`, ascending, `Φᵀ M Φ = I`.
fn modes_of<const N: usize>(
    m: &Rows<N>,
    k: &Rows<N>,
) -> Result<([f64; N], SMatrix<f64, N, N>), Error> {
    if !is_symmetric(m) {
        return Err(Error::MassNotSpd);
    }
    if !is_symmetric(k) {
        return Err(Error::StiffnessNotSymmetric);
    }
    let mm = SMatrix::<f64, N, N>::from_fn(|i, j| 0.5 * (m[i][j] + m[j][i]));
    let kk = SMatrix::<f64, N, N>::from_fn(|i, j| 0.5 * (k[i][j] + k[j][i]));
    let l = Cholesky::new(mm).ok_or(Error::MassNotSpd)?.unpack();
    // Pivots at rounding level mean M is singular to working precision.
    let tiny = N as f64 * f64::EPSILON * max_abs(m);
    if (0..N).any(|i| l[(i, i)] * l[(i, i)] <= tiny) {
        return Err(Error::MassNotSpd);
    }
    // A = L⁻¹ K L⁻ᵀ = L⁻¹ (L⁻¹ K)ᵀ for symmetric K.
    let x = l
        .solve_lower_triangular(&kk)
        .ok_or(Error::MassNotSpd)?
        .transpose();
    let a = l.solve_lower_triangular(&x).ok_or(Error::MassNotSpd)?;
    let (lam, q) = jacobi_eigen((a + a.transpose()) * 0.5)?;
    // Ascending order (insertion sort of the indices, no allocation).
    let mut idx: [usize; N] = lowest_modes();
    for i in 1..N {
        let mut j = i;
        while j > 0 && lam[idx[j - 1]] > lam[idx[j]] {
            idx.swap(j - 1, j);
            j -= 1;
        }
    }
    let q = SMatrix::<f64, N, N>::from_fn(|i, j| q[(i, idx[j])]);
    let phi = l.tr_solve_lower_triangular(&q).ok_or(Error::MassNotSpd)?;
    Ok((core::array::from_fn(|r| lam[idx[r]]), phi))
}

/// `2ξ_r ω_r` of every mode for the given damping.
fn modal_damping<const N: usize>(
    damping: &Damping<N>,
    lam: &[f64; N],
    phi: &SMatrix<f64, N, N>,
) -> Result<[f64; N], Error> {
    match damping {
        Damping::None => Ok([0.0; N]),
        Damping::Rayleigh { a0, a1 } => {
            if !(a0.is_finite() && a1.is_finite()) {
                return Err(Error::NonFiniteInput);
            }
            Ok(core::array::from_fn(|r| a0 + a1 * lam[r]))
        }
        Damping::Ratios(xi) => {
            if !xi.iter().all(|x| x.is_finite()) {
                return Err(Error::NonFiniteInput);
            }
            // ω = √|λ|: for a (physically unstable) negative ω² the ratio scales √|ω²|.
            Ok(core::array::from_fn(|r| {
                2.0 * xi[r] * ComplexField::sqrt(lam[r].abs())
            }))
        }
        Damping::Matrix(c) => {
            if !finite(c) {
                return Err(Error::NonFiniteInput);
            }
            let cc = SMatrix::<f64, N, N>::from_fn(|i, j| c[i][j]);
            let d = phi.transpose() * cc * phi;
            let scale = (0..N).fold(0.0f64, |s, r| s.max(d[(r, r)].abs()));
            let floor = SYMMETRY_TOL * scale;
            for r in 0..N {
                for s in 0..N {
                    let allowed = CLASSICAL_COUPLING_TOL
                        * ComplexField::sqrt((d[(r, r)] * d[(s, s)]).abs())
                        + floor;
                    if r != s && d[(r, s)].abs() > allowed {
                        return Err(Error::NonClassicalDamping);
                    }
                }
            }
            Ok(core::array::from_fn(|r| d[(r, r)]))
        }
    }
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
    /// Errors: [`Error::InvalidModeSelection`] (`R = 0` or `R > N`),
    /// [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`], [`Error::MassNotSpd`],
    /// [`Error::StiffnessNotSymmetric`], [`Error::NonClassicalDamping`],
    /// [`Error::EigenNotConverged`], [`Error::SingularEffectiveMatrix`] (a mode with
    /// `1 + (h/2)·2ξω + (h²/4)·ω² ≤ 0`, possible only for negative `ω²` or `ξ`).
    ///
    /// Cost: `O(N³)` `f64` flops and a few `N×N` `f64` temporaries on the stack; once.
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
        let distinct = (0..R).all(|i| (0..i).all(|j| modes[i] != modes[j]));
        if R == 0 || R > N || !distinct || modes.iter().any(|&r| r >= N) {
            return Err(Error::InvalidModeSelection);
        }
        if !(finite(m) && finite(k) && finite(b) && finite(y)) {
            return Err(Error::NonFiniteInput);
        }
        if !(h.is_finite() && h > 0.0) {
            return Err(Error::InvalidTimeStep);
        }
        let (lam, phi) = modes_of(m, k)?;
        let c_all = modal_damping(damping, &lam, &phi)?;
        let (half_h, quarter_h2) = (0.5 * h, 0.25 * h * h);

        let mut me = Self {
            h: T::from_f64_rounded(h),
            half_h: T::from_f64_rounded(half_h),
            quarter_h2: T::from_f64_rounded(quarter_h2),
            g_gamma: [[T::zero(); I]; R],
            g_c: [T::zero(); R],
            g_k: [T::zero(); R],
            gamma: [[T::zero(); I]; R],
            c: [T::zero(); R],
            k: [T::zero(); R],
            out: [[T::zero(); R]; O],
            phi: [[T::zero(); R]; N],
            proj: [[T::zero(); N]; R],
            modes,
        };
        for (r, &mode) in modes.iter().enumerate() {
            let (c, lam) = (c_all[mode], lam[mode]);
            let meff = 1.0 + half_h * c + quarter_h2 * lam;
            if !(meff.is_finite() && meff > f64::EPSILON) {
                return Err(Error::SingularEffectiveMatrix);
            }
            let g = 1.0 / meff;
            me.g_c[r] = T::from_f64_rounded(g * c);
            me.g_k[r] = T::from_f64_rounded(g * lam);
            me.c[r] = T::from_f64_rounded(c);
            me.k[r] = T::from_f64_rounded(lam);
            for j in 0..I {
                let gam: f64 = (0..N).map(|i| phi[(i, mode)] * b[i][j]).sum();
                me.gamma[r][j] = T::from_f64_rounded(gam);
                me.g_gamma[r][j] = T::from_f64_rounded(g * gam);
            }
            for o in 0..O {
                let yo: f64 = (0..N).map(|i| y[o][i] * phi[(i, mode)]).sum();
                me.out[o][r] = T::from_f64_rounded(yo);
            }
            for i in 0..N {
                me.phi[i][r] = T::from_f64_rounded(phi[(i, mode)]);
                let pm: f64 = (0..N).map(|l| phi[(l, mode)] * m[l][i]).sum();
                me.proj[r][i] = T::from_f64_rounded(pm);
            }
        }
        Ok(me)
    }
}

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
