//! The explicit model-based schemes of real-time hybrid simulation: the Chen–Ricles (CR)
//! algorithm (Chen & Ricles 2008) and the KR-α family (Kolay & Ricles 2014, EESD
//! 43:1361–1380) with controllable numerical dissipation `ρ∞ ∈ [0, 1]`.
//!
//! Displacement and velocity are **explicit**: both come from the committed state alone,
//! through integration parameter matrices computed once from `M, C, K, h` (a hybrid test
//! can command `u_{n+1}` before the specimen's force is known). The acceleration then
//! follows from the equation of motion at weighted points:
//!
//! ```text
//! u_{n+1} = u_n + h v_n + h² α2 a_n                       (explicit displacement)
//! v_{n+1} = v_n + h α1 a_n                                (explicit velocity)
//! M â_{n+1−α_m} + C v_{n+1−α_f} + K u_{n+1−α_f} = p_{n+1−α_f}
//! â_{n+1−α_m} = (I − α3) a_{n+1} + α3 a_n,    x_{n+1−α} = (1 − α) x_{n+1} + α x_n
//! ```
//!
//! with the integration parameter matrices (`N×N`)
//!
//! ```text
//! α1 = (M + γh C + βh² K)⁻¹ M
//! α2 = (1/2 + γ) α1
//! α3 = (M + γh C + βh² K)⁻¹ (α_m M + α_f γh C + α_f βh² K)
//! ```
//!
//! and the generalized-α parameters of `ρ∞` (Chung–Hulbert, [`AlphaParameters::chung_hulbert`]):
//! `α_m = (2ρ∞ − 1)/(ρ∞ + 1)`, `α_f = ρ∞/(ρ∞ + 1)`, `γ = 1/2 − α_m + α_f`,
//! `β = (1 − α_m + α_f)²/4`. Moving the known terms right, the new acceleration is
//!
//! ```text
//! M (I − α3) a_{n+1} = p̄ − C v̄ − K ū − M α3 a_n,
//! p̄ = (1 − α_f) p_{n+1} + α_f p_n,  v̄ = (1 − α_f) v_{n+1} + α_f v_n,  ū = (1 − α_f) u_{n+1} + α_f u_n
//! ```
//!
//! (signs: every term of the equation of motion keeps its sign on the left; the known
//! `α3 a_n` part of the weighted inertia moves right with a minus). With
//! `G = (M (I − α3))⁻¹` the step is
//!
//! ```text
//! w = α1 a_n;   u_{n+1} = u_n + h v_n + (1/2 + γ) h² w;   v_{n+1} = v_n + h w
//! a_{n+1} = G p̄ − (G C) v̄ − (G K) ū − (G M α3) a_n
//! ```
//!
//! `α1, G, GC, GK, GMα3` are computed once in `f64` (LU of `M + γh C + βh² K` and of
//! `M (I − α3)`, solves) and rounded once to `T`; a step costs `5N²` multiply-adds plus
//! `O(N)`.
//!
//! **The two members.** For linear systems the scheme has the characteristic polynomial of
//! the generalized-α scheme with the same parameters: second order, unconditionally stable,
//! spectral radius `ρ∞` as `ωh → ∞` (checked in `tests/kr_alpha.rs`).
//! - [`KrAlpha::new`]`(…, ρ∞)`: the KR-α family. `ρ∞ = 1` (`α_m = α_f = 1/2`, `γ = 1/2`,
//!   `β = 1/4`) gives `α1 = α2` of CR and `α3 = I/2`: the equation of motion averaged over
//!   the step, the CR sequence from a state that satisfies the equation of motion, with a
//!   spurious root `−1` that keeps (but never grows) a start-up residual of it.
//! - [`KrAlpha::chen_ricles`]: the CR algorithm as published, `α_m = α_f = 0`, `γ = 1/2`,
//!   `β = 1/4`: `α1 = α2 = 4 (4M + 2h C + h² K)⁻¹ M`, `α3 = 0`, the equation of motion
//!   enforced at `t_{n+1}` (`M a_{n+1} = p_{n+1} − C v_{n+1} − K u_{n+1}`); no dissipation.
//!
//! `M` must be regular (`M (I − α3)` is solved for the acceleration): an explicit scheme has
//! no effective stiffness to make up for a massless degree of freedom.
//!
//! **The start.** The explicit update `u_{n+1} = u_n + h v_n + (1/2 + γ) h² α1 a_n`
//! matches the Taylor step `u + h v + (h²/2) a` only if the velocity variable is the
//! physical velocity less `γh a` (to first order; for CR, `u_{n+1} = u_n + h v_{n+1}`
//! exactly: a mid-step velocity). Taking the physical `v0` as the variable (the papers' and
//! OpenSees' start) from a state with a nonzero initial acceleration (an initial
//! displacement, a load at `t = 0`) leaves an `O(h)` displacement error for the whole run.
//! So [`Stepper::start`] starts the variable at `v0 − γh α1 a0` (second order from any
//! state), and [`Stepper::start_with_acceleration`] takes `u0, v0, a0` as given (the
//! papers' start; right for a state saved from this scheme). From rest under a load that
//! starts at zero (a ground motion) the two are the same. Both measured in
//! `tests/kr_alpha.rs`. The state's `v` is the scheme's variable throughout, not `u'(t_n)`.
//!
//! **The load.** As for [`GeneralizedAlpha`](crate::GeneralizedAlpha): the weighted load
//! needs `p_n`, which the shared [`State`] does not carry.
//! [`Stepper::step_with_previous_input`] takes both samples (second order for any load);
//! [`Stepper::step`] takes `p_n = p_{n+1}`, exact for free vibration and constant loads,
//! first order for a varying load when `α_f ≠ 0` (CR has `α_f = 0`: no difference).

use nalgebra::{SMatrix, SVector};

use crate::kernel::{StartOps, effective_lu, range_verdict, start_operators, terms_scales};
use crate::kinematics::check_time_step_as;
use crate::linalg::lu::Lu;
use crate::linalg::{Mat, Rows, add_scaled, all_finite, all_fit, fits, mul};
use crate::linalg::{round_rows, rows_f64, scaled};
use crate::macros::mck_fn;
use crate::stepper::start_fn;
use crate::{AlphaParameters, Error, Real, State, Stepper};

/// The parameters of the CR algorithm: `α_m = α_f = 0`, `β = 1/4`, `γ = 1/2`.
pub(crate) const CHEN_RICLES: AlphaParameters = AlphaParameters {
    alpha_m: 0.0,
    alpha_f: 0.0,
    beta: 0.25,
    gamma: 0.5,
};

/// The `f64` operators of a KR-α step (see the module docs).
pub(crate) struct KrOps<const N: usize> {
    pub alpha1: Mat<N, N>,
    pub g: Mat<N, N>,
    pub gc: Mat<N, N>,
    pub gk: Mat<N, N>,
    pub gma3: Mat<N, N>,
    /// `h`, `(1/2 + γ) h²`, `γ h`, `1 − α_f`, `α_f`.
    pub h: f64,
    pub c2: f64,
    pub gamma_h: f64,
    pub w1: f64,
    pub w0: f64,
    pub start: StartOps<f64, N>,
}

/// Check `M, C, K, h` and build the KR-α operators of the parameters `p` (`const fn`).
/// `max`: the largest finite value of the scalar type the operators will be rounded to.
/// `k_rest`: the stiffness whose force the step computes itself (`G K_rest`, and the
/// start's `M⁻¹ K_rest`): `k` for [`KrAlpha`]; the numerical part's linear stiffness for
/// the split step of [`crate::hybrid::Split`], where `k` only builds `α1, α3` and the rest
/// of the restoring force is given (measured) each step.
///
/// Errors, in this order: [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`],
/// [`Error::OperatorOverflow`] (`M + γh C + βh² K` not finite),
/// [`Error::SingularEffectiveMatrix`] (`M + γh C + βh² K` singular),
/// [`Error::SingularMass`] (`M` singular), [`Error::SingularEffectiveMatrix`]
/// (`M (I − α3)` singular with `M` regular), [`Error::OperatorOverflow`],
/// [`Error::OperatorUnderflow`].
pub(crate) const fn kr_operators<const N: usize>(
    m: &Mat<N, N>,
    c: &Mat<N, N>,
    k: &Mat<N, N>,
    k_rest: &Mat<N, N>,
    h: f64,
    p: &AlphaParameters,
    max: f64,
) -> Result<KrOps<N>, Error> {
    if !(all_finite(m) && all_finite(c) && all_finite(k) && all_finite(k_rest)) {
        return Err(Error::NonFiniteInput);
    }
    let h = match check_time_step_as(h, max) {
        Ok(h) => h,
        Err(e) => return Err(e),
    };
    let AlphaParameters {
        alpha_m,
        alpha_f,
        beta,
        gamma,
    } = *p;
    let (wc, wk) = (gamma * h, beta * h * h);
    // α1 = M_eff⁻¹ M, α3 = M_eff⁻¹ (α_m M + α_f γh C + α_f βh² K).
    let lu = match effective_lu(m, c, k, wc, wk) {
        Ok((_, _, lu)) => lu,
        Err(e) => return Err(e),
    };
    let num3 = add_scaled(
        &add_scaled(&scaled(alpha_m, m), alpha_f * wc, c),
        alpha_f * wk,
        k,
    );
    let alpha1 = lu.solve(m);
    let alpha3 = lu.solve(&num3);
    // M regular (the start-up operators are its solves): checked before M (I − α3). The
    // start-up operators' range is judged with the other operators', after that
    // singularity: an f32 build said `OperatorUnderflow` where f64 said
    // `SingularEffectiveMatrix` (found by fuzzing).
    let (start, start_fit) = match start_operators(m, c, k_rest, max) {
        Ok(Some((_, s))) => (Some(s), Ok(())),
        Ok(None) => return Err(Error::SingularMass),
        Err(e) => (None, Err(e)),
    };
    // D = M (I − α3) = M − M α3, judged against the size of its two terms.
    let ma3 = mul(m, &alpha3);
    let d = add_scaled(m, -1.0, &ma3);
    let zero = [[0.0; N]; N];
    let lu_d = match Lu::new(&d, &terms_scales(m, &ma3, &zero, 1.0, 0.0)) {
        Some(lu) => lu,
        None => return Err(Error::SingularEffectiveMatrix),
    };
    let (g, gc, gk, gma3) = (
        lu_d.inverse(),
        lu_d.solve(c),
        lu_d.solve(k_rest),
        lu_d.solve(&ma3),
    );
    let c2 = (0.5 + gamma) * h * h;
    let fit = [
        fits(&alpha1, m, max),
        fits(&g, &d, max),
        fits(&gc, c, max),
        fits(&gk, k_rest, max),
        fits(&gma3, &ma3, max),
        start_fit,
    ];
    // Overflow (of an operator or of a coefficient) anywhere before underflow anywhere.
    if let Err(e) = range_verdict(fit, all_fit(&[c2, wc, alpha_f, 1.0 - alpha_f], max)) {
        return Err(e);
    }
    let start = match start {
        Some(s) => s,
        // (unreachable: `start_fit` is its error)
        None => return Err(Error::OperatorOverflow),
    };
    Ok(KrOps {
        alpha1,
        g,
        gc,
        gk,
        gma3,
        h,
        c2,
        gamma_h: wc,
        w1: 1.0 - alpha_f,
        w0: alpha_f,
        start,
    })
}

/// A KR-α (or Chen–Ricles) stepper for constant `M, C, K`: explicit displacement and
/// velocity, the acceleration from the weighted equation of motion
/// (Kolay & Ricles 2014; Chen & Ricles 2008):
///
/// ```text
/// u_{n+1} = u_n + h v_n + h² α2 a_n,        v_{n+1} = v_n + h α1 a_n
/// M [(I − α3) a_{n+1} + α3 a_n] + C v_{n+1−α_f} + K u_{n+1−α_f} = p_{n+1−α_f}
/// α1 = (M + γh C + βh² K)⁻¹ M,   α2 = (1/2 + γ) α1
/// α3 = (M + γh C + βh² K)⁻¹ (α_m M + α_f γh C + α_f βh² K)
/// ```
///
/// with `x_{n+1−α} = (1 − α) x_{n+1} + α x_n` and the Chung–Hulbert `(α_m, α_f, β, γ)` of
/// `ρ∞` ([`AlphaParameters::chung_hulbert`]); CR is `α_m = α_f = 0`, `β = 1/4`, `γ = 1/2`
/// (`α1 = α2 = 4 (4M + 2h C + h² K)⁻¹ M`, `α3 = 0`). For linear systems: second order,
/// unconditionally stable, the characteristic polynomial of
/// [`GeneralizedAlpha`](crate::GeneralizedAlpha) with the same parameters (spectral
/// radius `ρ∞` as `ωh → ∞`). `M` must be regular.
///
/// **The start.** The state's `v` is the scheme's velocity variable, which lags the
/// physical velocity by `γh a` (to first order). [`Stepper::start`] sets it to
/// `v0 − γh α1 a0`, and the displacement is second order from any initial state;
/// [`Stepper::start_with_acceleration`] takes `v0` as given (the papers' and OpenSees'
/// start: first order in the displacement when `a0 ≠ 0`, the same as `start` from rest).
///
/// Same state and start-up as [`Linear`](crate::Linear); `5N² + O(N)` multiply-adds a
/// step. Size: `8N² + 5` values of `T` (`5N²` for stepping, `3N²` for start-up) and the
/// parameters.
///
/// ```
/// use aemstep::{KrAlpha, Stepper};
/// use aemstep::{matrix, vector};
/// // u'' + 25 u = 0, h = 0.01 s, ρ∞ = 0.8, from u0 = 1
/// let sys = KrAlpha::<f64, 1>::new(&matrix![1.0], &matrix![0.0], &matrix![25.0], 0.01, 0.8)?;
/// let mut s = sys.start(&vector![1.0], &vector![0.0], &vector![0.0])?;
/// let command = sys.next_displacement(&s); // explicit: known before the step's load
/// sys.step(&mut s, &vector![0.0]);
/// assert_eq!(s.u(), &command);
/// for _ in 1..100 {
///     sys.step(&mut s, &vector![0.0]);
/// }
/// assert!((s.u()[0] - 5.0f64.cos()).abs() < 2e-3); // t = 1 s, O(h²) error
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KrAlpha<T, const N: usize> {
    params: AlphaParameters,
    /// `h` (s), `(1/2 + γ) h²` (s²), `γ h` (s), `1 − α_f`, `α_f`.
    h: T,
    c2: T,
    gamma_h: T,
    w1: T,
    w0: T,
    /// `α1`, and `G = (M (I − α3))⁻¹`, `G C`, `G K`, `G M α3`.
    alpha1: [[T; N]; N],
    g: [[T; N]; N],
    gc: [[T; N]; N],
    gk: [[T; N]; N],
    gma3: [[T; N]; N],
    start: Option<StartOps<T, N>>,
}

impl<T: Real, const N: usize> KrAlpha<T, N> {
    mck_fn! {
        /// The KR-α scheme with high-frequency spectral radius `rho_inf ∈ [0, 1]` (1: no
        /// dissipation, the CR sequence; 0: asymptotic annihilation) for
        /// `M u'' + C u' + K u = p(t)` with step `h` (s). `M, C, K` in `f64`, any units
        /// consistent with `h` in seconds (e.g. kg, N·s/m, N/m). Computed in `f64`, rounded
        /// once to `T`; bit-identical to [`KrAlpha::from_rows_f32`] / `from_rows_f64`.
        ///
        /// Errors: [`Error::InvalidParameter`] (`rho_inf` outside `[0, 1]` or NaN), then
        /// [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`] (`h ≤ 0`, not finite, or
        /// `h²` out of range of `T`), [`Error::SingularEffectiveMatrix`]
        /// (`M + γh C + βh² K` or `M (I − α3)` singular to working precision against its
        /// terms), [`Error::SingularMass`] (`M` singular), [`Error::OperatorOverflow`],
        /// [`Error::OperatorUnderflow`] (an operator does not fit `T`).
        ///
        /// Cost: about `10N³` flops in `f64`, a dozen `N×N` `f64` temporaries on the stack.
        pub fn new(m, c, k, h: f64, rho_inf: f64) {
            Self::with_rest(m, c, k, k, h, AlphaParameters::chung_hulbert(rho_inf)?)
        }
    }

    mck_fn! {
        /// The Chen–Ricles algorithm (`α_m = α_f = 0`, `γ = 1/2`, `β = 1/4`: the equation of
        /// motion at `t_{n+1}`, no numerical dissipation). Arguments as [`KrAlpha::new`].
        ///
        /// Errors and cost: as [`KrAlpha::new`] (no parameter to check).
        pub fn chen_ricles(m, c, k, h: f64) {
            Self::with_rest(m, c, k, k, h, CHEN_RICLES)
        }
    }

    mck_fn! {
        /// The operators of `p` with `k_rest` for the computed restoring force
        /// ([`kr_operators`]; `k` for [`KrAlpha`], the numerical part for
        /// [`Split`](crate::hybrid::Split)), rounded once to `T`: the run-time twin of
        /// `from_params`.
        pub(crate) fn with_rest(m, c, k, k_rest: &SMatrix<f64, N, N>, h: f64, p: AlphaParameters) {
            let (m, c, k, kr) = (rows_f64(m), rows_f64(c), rows_f64(k), rows_f64(k_rest));
            Ok(Self::from_ops(
                &kr_operators(&m, &c, &k, &kr, h, &p, T::MAX)?,
                p,
            ))
        }
    }

    /// Round the `f64` operators once to `T` (run time).
    fn from_ops(op: &KrOps<N>, p: AlphaParameters) -> Self {
        Self {
            params: p,
            h: T::from_f64_rounded(op.h),
            c2: T::from_f64_rounded(op.c2),
            gamma_h: T::from_f64_rounded(op.gamma_h),
            w1: T::from_f64_rounded(op.w1),
            w0: T::from_f64_rounded(op.w0),
            alpha1: round_rows(&op.alpha1),
            g: round_rows(&op.g),
            gc: round_rows(&op.gc),
            gk: round_rows(&op.gk),
            gma3: round_rows(&op.gma3),
            start: Some(op.start.round()),
        }
    }

    /// The scheme's parameters `(α_m, α_f, β, γ)` (CR: `(0, 0, 1/4, 1/2)`). Cost: O(1).
    pub fn parameters(&self) -> AlphaParameters {
        self.params
    }

    /// The integration parameter matrix `α1 = (M + γh C + βh² K)⁻¹ M` (dimensionless),
    /// rounded to `T`; `α2 = (1/2 + γ) α1`. Cost: `N²` copies.
    pub fn alpha1(&self) -> SMatrix<T, N, N> {
        SMatrix::from_fn(|i, j| self.alpha1[i][j])
    }

    /// The explicit displacement of the next step, `u_{n+1} = u_n + h v_n + h² α2 a_n`
    /// (the command a hybrid test sends before the step), from the committed `state`; the
    /// same value [`Stepper::step`] computes. Cost: `N²` multiply-adds + `3N`.
    pub fn next_displacement(&self, state: &State<T, N>) -> SVector<T, N> {
        let w = self.alpha1_times(&state.a);
        SVector::from_fn(|i, _| state.u[i] + self.h * state.v[i] + self.c2 * w[i])
    }

    #[inline(always)]
    fn alpha1_times(&self, a: &SVector<T, N>) -> [T; N] {
        let mut w = [T::zero(); N];
        for i in 0..N {
            let row = &self.alpha1[i];
            let mut q = T::zero();
            for j in 0..N {
                q += row[j] * a[j];
            }
            w[i] = q;
        }
        w
    }

    #[inline(always)]
    fn step_inner(&self, s: &mut State<T, N>, p_prev: &SVector<T, N>, p: &SVector<T, N>) {
        let w = self.alpha1_times(&s.a);
        // The explicit part, then the weighted (n+1−α_f) values.
        let (mut ubar, mut vbar, mut pbar) = ([T::zero(); N], [T::zero(); N], [T::zero(); N]);
        let mut u1 = [T::zero(); N];
        let mut v1 = [T::zero(); N];
        for j in 0..N {
            u1[j] = s.u[j] + self.h * s.v[j] + self.c2 * w[j];
            v1[j] = s.v[j] + self.h * w[j];
            ubar[j] = self.w1 * u1[j] + self.w0 * s.u[j];
            vbar[j] = self.w1 * v1[j] + self.w0 * s.v[j];
            pbar[j] = self.w1 * p[j] + self.w0 * p_prev[j];
        }
        let mut anew = [T::zero(); N];
        for i in 0..N {
            let (g, gc, gk, gm) = (&self.g[i], &self.gc[i], &self.gk[i], &self.gma3[i]);
            let mut q = T::zero();
            for j in 0..N {
                q += g[j] * pbar[j] - gc[j] * vbar[j] - gk[j] * ubar[j] - gm[j] * s.a[j];
            }
            anew[i] = q;
        }
        for j in 0..N {
            s.u[j] = u1[j];
            s.v[j] = v1[j];
            s.a[j] = anew[j];
        }
        s.n = s.n.wrapping_add(1);
    }
}

/// Const-fn construction, for operators computed at compile time into flash.
macro_rules! const_ctor {
    ($t:ident, $from_rows:ident, $from_rows_cr:ident) => {
        impl<const N: usize> KrAlpha<$t, N> {
            /// `const fn` twin of [`KrAlpha::new`]: `M, C, K` as row-major `f64` arrays
            /// (`m[i][j]` is row `i`, column `j`; [`Rows`](crate::models::Rows)), `h` in
            /// seconds, `rho_inf ∈ [0, 1]`. Bit-identical to [`KrAlpha::new`] given the same
            /// values; the scalar in the name lets a typed `static` infer `N`:
            ///
            /// ```
            /// use aemstep::KrAlpha;
            /// static SYS: KrAlpha<f32, 1> =
            ///     match KrAlpha::from_rows_f32([[1.0]], [[0.28]], [[4.0]], 1.0 / 1024.0, 0.5) {
            ///         Ok(s) => s,
            ///         Err(e) => panic!("{}", e.as_str()),
            ///     };
            /// assert_eq!(SYS.time_step(), 1.0 / 1024.0);
            /// ```
            ///
            /// The compiler evaluates about `10N³` flops (a `static` of large `N` may need
            /// `#![allow(long_running_const_eval)]`, as for
            /// [`Linear::from_rows_f32`](crate::Linear::from_rows_f32)).
            ///
            /// Errors: as [`KrAlpha::new`].
            pub const fn $from_rows(
                m: Rows<N>,
                c: Rows<N>,
                k: Rows<N>,
                h: f64,
                rho_inf: f64,
            ) -> Result<Self, Error> {
                match AlphaParameters::chung_hulbert(rho_inf) {
                    Ok(p) => Self::from_params(&m, &c, &k, &k, h, p),
                    Err(e) => Err(e),
                }
            }

            /// `const fn` twin of [`KrAlpha::chen_ricles`] (arguments as
            /// [`KrAlpha::from_rows_f32`] without `rho_inf`). Errors: as
            /// [`KrAlpha::new`].
            pub const fn $from_rows_cr(
                m: Rows<N>,
                c: Rows<N>,
                k: Rows<N>,
                h: f64,
            ) -> Result<Self, Error> {
                Self::from_params(&m, &c, &k, &k, h, CHEN_RICLES)
            }

            /// The operators of `p` with `k_rest` for the computed restoring force
            /// ([`kr_operators`]), rounded to the scalar (`const fn`).
            pub(crate) const fn from_params(
                m: &Rows<N>,
                c: &Rows<N>,
                k: &Rows<N>,
                k_rest: &Rows<N>,
                h: f64,
                p: AlphaParameters,
            ) -> Result<Self, Error> {
                let op = match kr_operators(m, c, k, k_rest, h, &p, $t::MAX as f64) {
                    Ok(op) => op,
                    Err(e) => return Err(e),
                };
                let s = &op.start;
                Ok(Self {
                    params: p,
                    h: op.h as $t,
                    c2: op.c2 as $t,
                    gamma_h: op.gamma_h as $t,
                    w1: op.w1 as $t,
                    w0: op.w0 as $t,
                    alpha1: crate::linalg::const_round!($t, rows op.alpha1),
                    g: crate::linalg::const_round!($t, rows op.g),
                    gc: crate::linalg::const_round!($t, rows op.gc),
                    gk: crate::linalg::const_round!($t, rows op.gk),
                    gma3: crate::linalg::const_round!($t, rows op.gma3),
                    start: Some(StartOps::<$t, N>::rounded(s)),
                })
            }

            /// The time step `h` (s), usable in `const` contexts: the same value as
            /// [`Stepper::time_step`], which generic code still calls. Cost: none.
            pub const fn time_step(&self) -> $t {
                self.h
            }
        }
    };
}
const_ctor!(f32, from_rows_f32, from_rows_chen_ricles_f32);
const_ctor!(f64, from_rows_f64, from_rows_chen_ricles_f64);

impl<T: Real, const N: usize> Stepper<T, N> for KrAlpha<T, N> {
    type Input = SVector<T, N>;
    type State = State<T, N>;

    start_fn! {
        /// The state at `t = 0` for a second-order run from any initial condition: `u0`,
        /// `a0 = M⁻¹ (p0 − C v0 − K u0)`, and the scheme's velocity variable
        /// `v0 − γh α1 a0` in place of `v0` (see the type's docs, "The start").
        ///
        /// Errors: [`Error::NonFiniteInput`]; [`Error::NonFiniteState`] if `a0` or the
        /// velocity variable overflows. Cost: `4N²` multiply-adds.
        fn start(&self, u0, v0, p0: &SVector<T, N>) -> State<T, N> {
            let s = crate::kernel::initial_state(self.start.as_ref(), u0, v0, p0)?;
            let w = self.alpha1_times(s.a());
            let v = SVector::from_fn(|i, _| v0[i] - self.gamma_h * w[i]);
            State::initial_computed(u0, &v, *s.a())
        }
    }

    crate::stepper::full_order_state!();

    #[inline]
    fn time_step(&self) -> T {
        self.h
    }

    crate::stepper::steps_through_inner!(
        /// [`Stepper::step_with_previous_input`] with `p_prev = p`: exact for free vibration
        /// and constant loads, first order for a time-varying load when `α_f ≠ 0` (KR-α); the
        /// same as the two-sample step for CR (`α_f = 0`). Cost: `5N²` multiply-adds + `12N`.
        ;
        /// The textbook step: the load taken as `(1 − α_f) p + α_f p_prev`, with
        /// `p_prev = p(t_n)`, `p = p(t_{n+1})`. Second order for any smooth load.
        ///
        /// Cost: `5N²` multiply-adds + `12N`. No allocation, no panic.
    );
}
