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
//! (`Modal::from_rows_f32`/`_f64` in a `static`), with bit-identical results.

use nalgebra::{SMatrix, SVector};

use crate::kinematics::{AemKinematics, Kinematics, check_time_step_as};
use crate::linalg::cholesky::{cholesky, lower_solve, lower_transpose_solve};
use crate::linalg::symmetric_eigen::{JACOBI_MAX_SWEEPS, jacobi_eigen};
use crate::linalg::{
    self, Rows, all_finite, first_error, fits_alone, is_symmetric, max_abs, mul, rows_f64, sqrt,
    transpose,
};
use crate::observer::symmetrize;
use crate::stepper::start_fn;
use crate::{Error, Real, State, Stepper};

/// Relative tolerance below which `M`, `K` count as symmetric: `|a_ij − a_ji| ≤
/// 64 ε max|a|` (rounding of a matrix assembled in `f64`).
const SYMMETRY_TOL: f64 = 64.0 * f64::EPSILON;

/// Largest modal coupling `|(ΦᵀCΦ)_rs| / √((ΦᵀCΦ)_rr (ΦᵀCΦ)_ss)`, `r ≠ s`, for which a
/// damping matrix counts as classical. Dropping couplings this small changes modal
/// responses by about the same relative amount, far below the AEM's `O(h²)` error at
/// practical steps.
pub const CLASSICAL_COUPLING_TOL: f64 = 1e-6;

/// How the structure is damped; every form here is classical (diagonal in the modes).
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
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
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
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

/// A modal (reduced) AEM stepper: `R` of the `N` modes of `M u'' + C u' + K u = B w(t)`,
/// `I` input signals `w`, `O` outputs `y = Y u`.
///
/// Per step: `R·I + 7R` multiply-adds ([`Modal::step`]); per output read: `O·R`
/// ([`Modal::output`]). With `R = N` it reproduces [`Linear`](crate::Linear) to rounding;
/// with `R < N` the error is the truncation of the dropped modes (see the README table).
///
/// Size: `R·(2I + O + 2N + 4) + 3` values of `T` and `R` indices. Build with
/// [`Modal::new`] (the `R` lowest modes) or [`Modal::with_modes`] at run time, or with
/// `Modal::from_rows_f32` / `Modal::from_rows_with_modes_f32` (and `_f64`; `const fn`: in a `static`, computed
/// by the compiler into flash); in `f64`, rounded once to `T`.
///
/// ```
/// use aemstep::{models, Damping, Modal, Stepper};
/// use aemstep::models::{base_excitation, storey_drifts};
/// use aemstep::vector;
///
/// // The benchmark 5-storey building: 2 modes, base excitation, roof drift out.
/// let (m, _c, k) = models::five_storey_building();
/// let (w1, w2) = (9.0, 26.3); // rad/s, see `five_storey_building`
/// let (a0, a1) = models::rayleigh_coefficients(w1, w2, 0.05);
/// let roof = [[0.0, 0.0, 0.0, 0.0, 1.0]];
/// let sys = Modal::<f32, 5, 2>::from_rows_f32(
///     m, k, Damping::Rayleigh { a0, a1 }, base_excitation(&m), roof, 0.02,
/// )?;
/// let mut s = sys.start_at_rest(&vector![0.0])?;
/// sys.step(&mut s, &vector![0.1 * 9.80665]);
/// assert!(sys.output(&s)[0] < 0.0);
/// let _drifts: [[f64; 5]; 5] = storey_drifts();
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Modal<T, const N: usize, const R: usize, const I: usize = 1, const O: usize = 1> {
    kin: AemKinematics<T>,
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
// `Modal::from_rows_f32`/`_f64` evaluated by the compiler, so both give bit-identical operators.

/// `(ω², Φ)` of `K φ = ω² M φ`, ascending, `Φᵀ M Φ = I` (`Φ` row-major, column `r` is
/// mode `r`): Cholesky `M = L Lᵀ`, Jacobi on `L⁻¹ K L⁻ᵀ = Q Λ Qᵀ`, `Φ = L⁻ᵀ Q`.
///
/// `M` and `K` are first scaled by powers of two (exact) to entries of order one, so the
/// sums of squares inside Cholesky and Jacobi neither overflow nor underflow for any
/// finite data (`s = 1e±300` gives the modes of `s = 1`); the scales are undone on `ω²`
/// and `Φ` at the end. [`Error::OperatorOverflow`] if `ω²` or `Φ` then overflows `f64`.
pub(crate) const fn modes_of<const N: usize>(
    m: &Rows<N>,
    k: &Rows<N>,
) -> Result<([f64; N], Rows<N>), Error> {
    if !is_symmetric(m, SYMMETRY_TOL) {
        return Err(Error::MassNotSpd);
    }
    if !is_symmetric(k, SYMMETRY_TOL) {
        return Err(Error::StiffnessNotSymmetric);
    }
    // M' = M 2^−em (em even, so √(2^em) is exact), K' = K 2^−ek.
    let em = 2 * (exponent(max_abs(m)) / 2);
    let ek = exponent(max_abs(k));
    let m = &scaled_pow2(m, -em);
    let k = &scaled_pow2(k, -ek);
    let l = match cholesky(m) {
        Some(l) => l,
        None => return Err(Error::MassNotSpd),
    };
    // A = L⁻¹ K L⁻ᵀ = L⁻¹ (L⁻¹ K)ᵀ for symmetric K; symmetrized against rounding.
    let x = lower_solve(&l, k);
    let a = symmetrize(&lower_solve(&l, &transpose(&x)));
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
    // K φ = ω² M φ with ω² = ω'² 2^(ek − em); Φᵀ M Φ = I with Φ = Φ' 2^(−em/2).
    let mut r = 0;
    while r < N {
        ls[r] = times_pow2(ls[r], ek - em);
        if !ls[r].is_finite() {
            return Err(Error::OperatorOverflow);
        }
        r += 1;
    }
    let phi = scaled_pow2(&lower_transpose_solve(&l, &qs), -em / 2);
    if !all_finite(&phi) {
        return Err(Error::OperatorOverflow);
    }
    Ok((ls, phi))
}

/// The binary exponent `e` of a positive finite `x` (`2^e ≤ x < 2^(e+1)`; subnormals and
/// zero give −1022).
const fn exponent(x: f64) -> i32 {
    let e = ((x.to_bits() >> 52) & 0x7ff) as i32;
    if e == 0 { -1022 } else { e - 1023 }
}

/// `x · 2^e`, exact unless it overflows or underflows (applied in steps within the normal
/// range of the factor).
const fn times_pow2(mut x: f64, mut e: i32) -> f64 {
    while e != 0 {
        let step = if e > 1000 {
            1000
        } else if e < -1000 {
            -1000
        } else {
            e
        };
        x *= f64::from_bits(((step + 1023) as u64) << 52);
        e -= step;
    }
    x
}

/// `a · 2^e` entrywise.
const fn scaled_pow2<const N: usize>(a: &Rows<N>, e: i32) -> Rows<N> {
    let mut r = *a;
    let mut i = 0;
    while i < N {
        let mut j = 0;
        while j < N {
            r[i][j] = times_pow2(r[i][j], e);
            j += 1;
        }
        i += 1;
    }
    r
}

/// Every number of a damping description is finite.
const fn damping_finite<const N: usize>(damping: &Damping<N>) -> bool {
    match damping {
        Damping::None => true,
        Damping::Rayleigh { a0, a1 } => a0.is_finite() && a1.is_finite(),
        Damping::Ratios(xi) => all_finite(&[*xi]),
        Damping::Matrix(c) => all_finite(c),
    }
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
            if !all_finite(&c) {
                return Err(Error::NonFiniteInput);
            }
            // D = Φᵀ C Φ
            let d = mul(&transpose(phi), &mul(&c, phi));
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

/// Every operator of a [`Modal`], in `f64` (the observer's modal state-space form reads
/// `c`, `k`, `gamma`, `phi`, `proj`).
pub(crate) struct ModalOps<const N: usize, const R: usize, const I: usize, const O: usize> {
    kin: AemKinematics<f64>,
    g_gamma: [[f64; I]; R],
    g_c: [f64; R],
    g_k: [f64; R],
    pub(crate) gamma: [[f64; I]; R],
    pub(crate) c: [f64; R],
    pub(crate) k: [f64; R],
    out: [[f64; R]; O],
    pub(crate) phi: [[f64; R]; N],
    pub(crate) proj: [[f64; N]; R],
}

/// Check the data and build every operator (shared by `with_modes` and the `const`
/// constructors).
// The model's matrices, the mode selection, the step and the target type's range: one
// `const fn` serves both constructors, so its arguments are the constructors' arguments.
#[allow(clippy::too_many_arguments)]
pub(crate) const fn modal_operators<
    const N: usize,
    const R: usize,
    const I: usize,
    const O: usize,
>(
    m: &Rows<N>,
    k: &Rows<N>,
    damping: &Damping<N>,
    b: &[[f64; I]; N],
    y: &[[f64; N]; O],
    modes: &[usize; R],
    h: f64,
    max: f64,
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
    // Every datum, the damping's included, is checked before any is used: a NaN is
    // `NonFiniteInput` whatever else is wrong (the damping used to be checked after the
    // eigenproblem, so a NaN there could come back as `MassNotSpd`; found by fuzzing).
    if !(all_finite(m)
        && all_finite(k)
        && all_finite(b)
        && all_finite(y)
        && damping_finite(damping))
    {
        return Err(Error::NonFiniteInput);
    }
    let kin = match check_time_step_as(h, max) {
        Ok(h) => match AemKinematics::new(h) {
            Ok(kin) => kin,
            Err(e) => return Err(e),
        },
        Err(e) => return Err(e),
    };
    let (lam, phi) = match modes_of(m, k) {
        Ok(x) => x,
        Err(e) => return Err(e),
    };
    let c_all = match modal_damping(damping, &lam, &phi) {
        Ok(x) => x,
        Err(e) => return Err(e),
    };
    let mut op = ModalOps {
        kin,
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
        let meff = 1.0 + kin.half_h * c + kin.quarter_h2 * lam;
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
    // Every operator must fit the scalar type it will be rounded to (`max`: its largest
    // finite value), else it would round to ∞ — or, its largest entry subnormal there, lose
    // its precision (the range check of every build, `linalg::fits`).
    let fit = [
        fits_alone(&op.g_gamma, max),
        fits_alone(&[op.g_c, op.g_k, op.c, op.k], max),
        fits_alone(&op.gamma, max),
        fits_alone(&op.out, max),
        fits_alone(&op.phi, max),
        fits_alone(&op.proj, max),
    ];
    match first_error(fit) {
        Some(e) => Err(e),
        None => Ok(op),
    }
}

impl<T: Real, const N: usize, const R: usize, const I: usize, const O: usize> Modal<T, N, R, I, O> {
    /// A modal stepper keeping the `R` lowest modes of `M u'' + C u' + K u = B w(t)`.
    ///
    /// - `m`, `k`: `N×N` row-major (units e.g. kg, N/m); `M` symmetric positive
    ///   definite, `K` symmetric (to `64 ε` relative).
    /// - `damping`: classical damping ([`Damping`]).
    /// - `b`: influence matrix, `N×I` (e.g. [`base_excitation`](crate::models::base_excitation)).
    /// - `y`: output matrix, `O×N` (e.g. a row selecting the roof, or
    ///   [`storey_drifts`](crate::models::storey_drifts)).
    /// - `h`: time step (s).
    ///
    /// Computed in `f64` by the same `const` code as `Modal::from_rows_f64` (bit-identical
    /// results), rounded once to `T`.
    ///
    /// Errors: [`Error::InvalidModeSelection`] (`R = 0` or `R > N`),
    /// [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`], [`Error::MassNotSpd`],
    /// [`Error::StiffnessNotSymmetric`], [`Error::NonClassicalDamping`],
    /// [`Error::EigenNotConverged`], [`Error::SingularEffectiveMatrix`] (a mode with
    /// `1 + (h/2)·2ξω + (h²/4)·ω² ≤ 0`, possible only for negative `ω²` or `ξ`),
    /// [`Error::OperatorOverflow`], [`Error::OperatorUnderflow`] (an operator beyond the
    /// range of `T`, or its largest entry subnormal there).
    ///
    /// Cost: `O(N³)` `f64` flops (Jacobi: `≈ 4N³` a sweep, a few sweeps) and a few `N×N`
    /// `f64` temporaries on the stack; once.
    pub fn new(
        m: &SMatrix<f64, N, N>,
        k: &SMatrix<f64, N, N>,
        damping: &Damping<N>,
        b: &SMatrix<f64, N, I>,
        y: &SMatrix<f64, O, N>,
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
        m: &SMatrix<f64, N, N>,
        k: &SMatrix<f64, N, N>,
        damping: &Damping<N>,
        b: &SMatrix<f64, N, I>,
        y: &SMatrix<f64, O, N>,
        modes: [usize; R],
        h: f64,
    ) -> Result<Self, Error> {
        let op = modal_operators(
            &rows_f64(m),
            &rows_f64(k),
            damping,
            &rows_f64(b),
            &rows_f64(y),
            &modes,
            h,
            T::MAX,
        )?;
        Ok(Self {
            kin: op.kin.round(),
            g_gamma: linalg::round_rows(&op.g_gamma),
            g_c: linalg::round_vec(&op.g_c),
            g_k: linalg::round_vec(&op.g_k),
            gamma: linalg::round_rows(&op.gamma),
            c: linalg::round_vec(&op.c),
            k: linalg::round_vec(&op.k),
            out: linalg::round_rows(&op.out),
            phi: linalg::round_rows(&op.phi),
            proj: linalg::round_rows(&op.proj),
            modes,
        })
    }
}

/// Const-fn construction, for modal operators computed at compile time into flash.
macro_rules! const_ctor {
    ($t:ident, $from_rows:ident, $from_rows_with_modes:ident) => {
        impl<const N: usize, const R: usize, const I: usize, const O: usize> Modal<$t, N, R, I, O> {
            /// `const fn` twin of [`Modal::new`] (the `R` lowest modes), bit-identical to
            /// it. In a `static`, the compiler solves the eigenproblem and no eigen-solver
            /// code is linked into the firmware.
            ///
            /// **Matrices are row-major** (`m[i][j]`: row `i`, column `j`; [`Rows`](crate::models::Rows)); to pass
            /// nalgebra data use [`models::rows_of`](crate::models::rows_of), and to convert these
            /// arrays to nalgebra use [`models::matrix_of`](crate::models::matrix_of), not `SMatrix::from`,
            /// which reads columns.
            ///
            /// **Size limit at compile time.** The Jacobi sweeps cost about `4N³` flops
            /// each; measured with rustc 1.95, `Modal<f32, N, 2>` compiles in a `static` up
            /// to `N = 49` and stops at 50 with the `long_running_const_eval` lint (deny by
            /// default; the largest size is pinned by `tests/constructors.rs`). Allow the
            /// lint at the firmware's crate root for larger models, or build at run time
            /// with [`Modal::new`].
            ///
            /// Errors: as [`Modal::new`].
            pub const fn $from_rows(
                m: Rows<N>,
                k: Rows<N>,
                damping: Damping<N>,
                b: [[f64; I]; N],
                y: [[f64; N]; O],
                h: f64,
            ) -> Result<Self, Error> {
                Self::$from_rows_with_modes(m, k, damping, b, y, lowest_modes(), h)
            }

            /// `const fn` twin of [`Modal::with_modes`], bit-identical to it.
            ///
            /// **Matrices are row-major** (`m[i][j]`: row `i`, column `j`; [`Rows`](crate::models::Rows)); to pass
            /// nalgebra data use [`models::rows_of`](crate::models::rows_of), and to convert these
            /// arrays to nalgebra use [`models::matrix_of`](crate::models::matrix_of), not `SMatrix::from`,
            /// which reads columns.
            ///
            /// Errors: as [`Modal::with_modes`].
            pub const fn $from_rows_with_modes(
                m: Rows<N>,
                k: Rows<N>,
                damping: Damping<N>,
                b: [[f64; I]; N],
                y: [[f64; N]; O],
                modes: [usize; R],
                h: f64,
            ) -> Result<Self, Error> {
                let op = match modal_operators(&m, &k, &damping, &b, &y, &modes, h, $t::MAX as f64) {
                    Ok(op) => op,
                    Err(e) => return Err(e),
                };
                Ok(Self {
                    kin: linalg::const_round!($t, kin op.kin),
                    g_gamma: linalg::const_round!($t, rows op.g_gamma),
                    g_c: linalg::const_round!($t, vec op.g_c),
                    g_k: linalg::const_round!($t, vec op.g_k),
                    gamma: linalg::const_round!($t, rows op.gamma),
                    c: linalg::const_round!($t, vec op.c),
                    k: linalg::const_round!($t, vec op.k),
                    out: linalg::const_round!($t, rows op.out),
                    phi: linalg::const_round!($t, rows op.phi),
                    proj: linalg::const_round!($t, rows op.proj),
                    modes,
                })
            }

            /// The time step `h` (s), usable in `const` contexts: the same value as
            /// [`Stepper::time_step`](crate::Stepper::time_step), which generic code still
            /// calls. Cost: none.
            pub const fn time_step(&self) -> $t {
                self.kin.h
            }
        }
    };
}
const_ctor!(f32, from_rows_f32, from_rows_with_modes_f32);
const_ctor!(f64, from_rows_f64, from_rows_with_modes_f64);

impl<T: Real, const N: usize, const R: usize, const I: usize, const O: usize> Modal<T, N, R, I, O> {
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

    /// The state at `t = 0` at rest (`u0 = v0 = 0`) under the input `w0`.
    ///
    /// Errors: [`Error::NonFiniteInput`]. Cost: `R·I`.
    pub fn start_at_rest(&self, w0: &SVector<T, I>) -> Result<ModalState<T, R>, Error> {
        self.start(&SVector::zeros(), &SVector::zeros(), w0)
    }

    /// `Φ_Rᵀ M x` (the modal coordinates of `x`, exact when `x` lies in the span of the
    /// kept modes). Cost: `R·N`.
    fn project(&self, x: &SVector<T, N>) -> [T; R] {
        core::array::from_fn(|r| {
            let mut e = T::zero();
            for i in 0..N {
                e += self.proj[r][i] * x[i];
            }
            e
        })
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
}

crate::state::step_state!(ModalState<R>, |self| ModalState::is_finite(self), n);

impl<T: Real, const N: usize, const R: usize, const I: usize, const O: usize> Stepper<T, N>
    for Modal<T, N, R, I, O>
{
    type Input = SVector<T, I>;
    type State = ModalState<T, R>;

    #[inline]
    fn time_step(&self) -> T {
        self.kin.h
    }

    start_fn! {
        /// The state at `t = 0` from `u0`, `v0` (projected on the kept modes:
        /// `η0 = Φ_Rᵀ M u0`, exact when `u0` lies in their span) and `w0`, with
        /// `η0'' = Γ w0 − 2ξω η0' − ω² η0`.
        ///
        /// Errors: [`Error::NonFiniteInput`], [`Error::NonFiniteState`]. Cost: `2R·N + R·I`.
        fn start(&self, u0, v0, w0: &SVector<T, I>) -> ModalState<T, R> {
            if !crate::scalar::initial_inputs_finite(u0, v0, w0) {
                return Err(Error::NonFiniteInput);
            }
            let (eta, deta) = (self.project(u0), self.project(v0));
            let ddeta = core::array::from_fn(|r| {
                let mut f = T::zero();
                for j in 0..I {
                    f += self.gamma[r][j] * w0[j];
                }
                f - self.c[r] * deta[r] - self.k[r] * eta[r]
            });
            let s = ModalState {
                eta,
                deta,
                ddeta,
                n: 0,
            };
            if s.is_finite() {
                Ok(s)
            } else {
                Err(Error::NonFiniteState)
            }
        }
    }

    start_fn! {
        /// The state at `t = 0` from `u0, v0, a0`, each projected on the kept modes
        /// (`η = Φ_Rᵀ M x`). Errors: [`Error::NonFiniteInput`]; [`Error::NonFiniteState`] if a
        /// projection overflows (large `M` in `f32`). Cost: `3R·N`.
        fn start_with_acceleration(&self, u0, v0, a0: &SVector<T, N>) -> ModalState<T, R> {
            if !crate::scalar::initial_inputs_finite(u0, v0, a0) {
                return Err(Error::NonFiniteInput);
            }
            let s = ModalState {
                eta: self.project(u0),
                deta: self.project(v0),
                ddeta: self.project(a0),
                n: 0,
            };
            if s.is_finite() {
                Ok(s)
            } else {
                Err(Error::NonFiniteState)
            }
        }
    }

    /// Each kept mode takes one scalar AEM step under the input `w_n`.
    ///
    /// Cost: `R·I + 7R` multiply-adds; fixed, no allocation, no panic.
    #[inline]
    fn step(&self, s: &mut ModalState<T, R>, w: &SVector<T, I>) {
        for r in 0..R {
            let (vh, uh) = self.kin.predict(s.eta[r], s.deta[r], s.ddeta[r]);
            let mut q = T::zero();
            for j in 0..I {
                q += self.g_gamma[r][j] * w[j];
            }
            q -= self.g_c[r] * vh + self.g_k[r] * uh;
            s.ddeta[r] = q;
            (s.deta[r], s.eta[r]) = self.kin.correct(vh, uh, q);
        }
        s.n = s.n.wrapping_add(1);
    }

    /// The full `N`-DOF state `u = Φ_R η`, `v = Φ_R η'`, `a = Φ_R η''` (on demand, not
    /// every step). Cost: `3N·R`.
    fn full_state(&self, s: &ModalState<T, R>) -> State<T, N> {
        let map = |x: &[T; R]| {
            SVector::<T, N>::from_fn(|i, _| {
                let mut y = T::zero();
                for r in 0..R {
                    y += self.phi[i][r] * x[r];
                }
                y
            })
        };
        State::unchecked(map(&s.eta), map(&s.deta), map(&s.ddeta), s.n)
    }
}
