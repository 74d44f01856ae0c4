//! The Newmark family (β, γ): average acceleration, linear acceleration, central
//! difference and every other member, behind the same [`Stepper`] interface as
//! [`Linear`](crate::Linear).
//!
//! ```text
//! û = u_{n−1} + h v_{n−1} + (1/2 − β) h² a_{n−1}      v̂ = v_{n−1} + (1 − γ) h a_{n−1}
//! a_n = G p_n − (G C) v̂ − (G K) û                    G = (M + γh C + βh² K)⁻¹
//! u_n = û + β h² a_n                                  v_n = v̂ + γ h a_n
//! ```
//!
//! Second order iff γ = 1/2. Unconditionally stable iff 2β ≥ γ ≥ 1/2; otherwise stable for
//! `ωh ≤ 1/√(γ/2 − β)` (undamped), e.g. `ωh ≤ 2` for central difference, `ωh ≤ 2√3` for
//! linear acceleration. β = 1/4, γ = 1/2 is the AEM step itself.

use nalgebra::{SMatrix, SVector};

use crate::linear::{StartOps, initial_state, interleave, newmark_step};
pub(crate) use crate::linear::{round_rows, rows_f64};
use crate::ops::{self, Mat};
use crate::{Error, Real, State, Stepper};

/// `y += A x` for a row-major `A`.
#[inline(always)]
pub(crate) fn mac<T: Real, const N: usize>(y: &mut [T; N], a: &[[T; N]; N], x: &[T; N]) {
    for i in 0..N {
        let mut s = T::zero();
        for j in 0..N {
            s += a[i][j] * x[j];
        }
        y[i] += s;
    }
}

/// Check inputs; `(M, C, K)` in `f64` and the start-up operators (`None` if `M` is
/// singular).
pub(crate) type Checked<const N: usize> = (Mat<N>, Mat<N>, Mat<N>, Option<StartOps<f64, N>>);

pub(crate) fn check_inputs<T: Real, const N: usize>(
    m: &SMatrix<T, N, N>,
    c: &SMatrix<T, N, N>,
    k: &SMatrix<T, N, N>,
    h: T,
) -> Result<Checked<N>, Error> {
    let (m, c, k) = (rows_f64(m), rows_f64(c), rows_f64(k));
    if !(ops::all_finite(&m) && ops::all_finite(&c) && ops::all_finite(&k)) {
        return Err(Error::NonFiniteInput);
    }
    let hf = h.as_f64();
    if !(hf.is_finite() && hf > 0.0) {
        return Err(Error::InvalidTimeStep);
    }
    let start = ops::inverse(&m).map(|mi| StartOps {
        minv: mi,
        minv_c: ops::mul(&mi, &c),
        minv_k: ops::mul(&mi, &k),
    });
    Ok((m, c, k, start))
}

pub(crate) fn round_start<T: Real, const N: usize>(s: &StartOps<f64, N>) -> StartOps<T, N> {
    StartOps {
        minv: round_rows(&s.minv),
        minv_c: round_rows(&s.minv_c),
        minv_k: round_rows(&s.minv_k),
    }
}

/// A Newmark-family stepper (β, γ) for constant `M, C, K`.
///
/// Same state, same start-up and the same `3N² + O(N)` multiply-adds a step as
/// [`Linear`](crate::Linear); switch with one line:
///
/// ```
/// use aemstep::{Linear, Newmark, Stepper};
/// use nalgebra::{matrix, vector};
/// let (m, c, k, h) = (matrix![1.0], matrix![0.0], matrix![25.0], 0.01);
/// // let sys = Linear::new(&m, &c, &k, h)?;
/// let sys = Newmark::linear_acceleration(&m, &c, &k, h)?;
/// let mut s = sys.start(&vector![1.0], &vector![0.0], &vector![0.0])?;
/// for _ in 0..100 {
///     sys.step(&mut s, &vector![0.0]);
/// }
/// assert!((s.u()[0] - 5.0f64.cos()).abs() < 1e-3);
/// # let _ = Linear::new(&m, &c, &k, h)?;
/// # Ok::<(), aemstep::Error>(())
/// ```
///
/// Size: `6N² + 5` values of `T`.
#[derive(Clone, Copy, Debug, PartialEq)]
// `repr(C)` with `ops` first, as `Linear` (short load offsets on Thumb-2).
#[repr(C)]
pub struct Newmark<T, const N: usize> {
    /// `[G[i], −GC[i], −GK[i]]` for every row `i`, as in `Linear`.
    ops: [[[T; N]; 3]; N],
    /// `[h, (1 − γ) h, (β + 1/2 − γ) h², γ h, β h²]`: the kinematics of `newmark_step`.
    coef: [T; 5],
    start: Option<StartOps<T, N>>,
}

impl<T: Real, const N: usize> Newmark<T, N> {
    /// Precompute the step operators of the Newmark scheme with parameters `beta` (β ≥ 0)
    /// and `gamma` (γ ≥ 0) for `M u'' + C u' + K u = p(t)` with step `h` (s). Computed in
    /// `f64`, rounded once to `T`.
    ///
    /// Errors: [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`],
    /// [`Error::InvalidParameter`] (β or γ negative or not finite),
    /// [`Error::SingularEffectiveMatrix`] (`M + γh C + βh² K` singular; e.g. central
    /// difference with singular `M`).
    ///
    /// Cost: about `5N³` flops in `f64`, four `N×N` `f64` temporaries on the stack.
    pub fn new(
        m: &SMatrix<T, N, N>,
        c: &SMatrix<T, N, N>,
        k: &SMatrix<T, N, N>,
        h: T,
        beta: f64,
        gamma: f64,
    ) -> Result<Self, Error> {
        let (m, c, k, start) = check_inputs(m, c, k, h)?;
        if !(beta.is_finite() && gamma.is_finite() && beta >= 0.0 && gamma >= 0.0) {
            return Err(Error::InvalidParameter);
        }
        let hf = h.as_f64();
        let meff = ops::add_scaled(&ops::add_scaled(&m, gamma * hf, &c), beta * hf * hf, &k);
        let g = ops::inverse(&meff).ok_or(Error::SingularEffectiveMatrix)?;
        let coef = [
            hf,
            (1.0 - gamma) * hf,
            (beta + 0.5 - gamma) * hf * hf,
            gamma * hf,
            beta * hf * hf,
        ];
        Ok(Self {
            ops: interleave(
                &round_rows(&g),
                &round_rows(&ops::mul(&g, &c)),
                &round_rows(&ops::mul(&g, &k)),
            ),
            coef: coef.map(T::from_f64_rounded),
            start: start.as_ref().map(round_start),
        })
    }

    /// Average acceleration (trapezoidal), β = 1/4, γ = 1/2: the same recurrence as the
    /// AEM [`Linear`](crate::Linear) (bit-identical operators). Errors: as [`Newmark::new`].
    pub fn average_acceleration(
        m: &SMatrix<T, N, N>,
        c: &SMatrix<T, N, N>,
        k: &SMatrix<T, N, N>,
        h: T,
    ) -> Result<Self, Error> {
        Self::new(m, c, k, h, 0.25, 0.5)
    }

    /// Linear acceleration, β = 1/6, γ = 1/2: second order, stable for `ωh ≤ 2√3`.
    /// Errors: as [`Newmark::new`].
    pub fn linear_acceleration(
        m: &SMatrix<T, N, N>,
        c: &SMatrix<T, N, N>,
        k: &SMatrix<T, N, N>,
        h: T,
    ) -> Result<Self, Error> {
        Self::new(m, c, k, h, 1.0 / 6.0, 0.5)
    }

    /// Central difference, β = 0, γ = 1/2: second order, stable for `ωh ≤ 2`
    /// (undamped). Needs `M + (h/2) C` invertible. Errors: as [`Newmark::new`].
    pub fn central_difference(
        m: &SMatrix<T, N, N>,
        c: &SMatrix<T, N, N>,
        k: &SMatrix<T, N, N>,
        h: T,
    ) -> Result<Self, Error> {
        Self::new(m, c, k, h, 0.0, 0.5)
    }
}

impl<T: Real, const N: usize> Stepper<T, N> for Newmark<T, N> {
    #[inline]
    fn time_step(&self) -> T {
        self.coef[0]
    }

    fn start(
        &self,
        u0: &SVector<T, N>,
        v0: &SVector<T, N>,
        p0: &SVector<T, N>,
    ) -> Result<State<T, N>, Error> {
        initial_state(self.start.as_ref(), u0, v0, p0)
    }

    /// Cost: `3N²` multiply-adds + `7N` (the kernel [`Linear`](crate::Linear) steps with).
    #[inline]
    fn step(&self, s: &mut State<T, N>, p: &SVector<T, N>) {
        newmark_step(&self.ops, self.coef, s, p);
    }
}
