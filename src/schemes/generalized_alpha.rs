//! The generalized-α scheme of Chung and Hulbert (1993), with the Hilber–Hughes–Taylor
//! (HHT-α) scheme as the member `α_m = 0`.
//!
//! Newmark kinematics with the equation of motion enforced at weighted points,
//!
//! ```text
//! M a_{n−α_m} + C v_{n−α_f} + K u_{n−α_f} = p_{n−α_f},     x_{n−α} = (1 − α) x_n + α x_{n−1}
//! u_n = u_{n−1} + h v_{n−1} + h² ((1/2 − β) a_{n−1} + β a_n)
//! v_n = v_{n−1} + h ((1 − γ) a_{n−1} + γ a_n)
//! ```
//!
//! From the high-frequency spectral radius `ρ∞ ∈ [0, 1]`:
//! `α_m = (2ρ∞ − 1)/(ρ∞ + 1)`, `α_f = ρ∞/(ρ∞ + 1)`, `γ = 1/2 − α_m + α_f`,
//! `β = (1 − α_m + α_f)²/4`: second order, unconditionally stable, with the least
//! low-frequency dissipation for a given `ρ∞`. `ρ∞ = 1` is the average-acceleration rule.
//!
//! **The load.** The weighted load `p_{n−α_f} = (1 − α_f) p_n + α_f p_{n−1}` needs the
//! previous sample, which the shared [`State`] does not carry (the scheme's acceleration
//! does not satisfy the equation of motion at `t_{n−1}`, so `p_{n−1}` cannot be recovered
//! from it). [`Stepper::step_with_previous_input`] takes both samples and is the
//! textbook scheme, second order for any load. [`Stepper::step`] takes `p_{n−1} = p_n`: it
//! is the textbook scheme for free vibration and piecewise-constant loads, but only first
//! order in `h` for loads that vary in time (an `α_f h` lag).

use nalgebra::{SMatrix, SVector};

use crate::kernel::{StartOps, effective_lu, range_verdict, start_operators};
use crate::kinematics::{Kinematics, NewmarkKinematics, check_time_step_as};
use crate::linalg::lu::{Lu, condition};
use crate::linalg::{Mat, add_scaled, all_finite, finite_as, fits, round_rows, rows_f64, scaled};
use crate::macros::mck_fn;
use crate::{Error, Param, Real, State, Stepper};

/// The parameters `(α_m, α_f, β, γ)` of a generalized-α scheme.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlphaParameters {
    /// Weight of the previous acceleration in the inertia term.
    pub alpha_m: f64,
    /// Weight of the previous state and load in the damping, stiffness and load terms.
    pub alpha_f: f64,
    /// Newmark β.
    pub beta: f64,
    /// Newmark γ.
    pub gamma: f64,
}

impl AlphaParameters {
    /// Chung–Hulbert parameters for the high-frequency spectral radius `rho_inf ∈ [0, 1]`.
    ///
    /// Errors: [`Error::InvalidParameter`] outside `[0, 1]` or not finite. `const fn`
    /// (usable in a `static`); cost O(1).
    pub const fn chung_hulbert(rho_inf: f64) -> Result<Self, Error> {
        // Written as comparisons (`contains` is not `const`); NaN fails both.
        if !(rho_inf >= 0.0 && rho_inf <= 1.0) {
            return Err(Error::InvalidParameter(Param::RhoInf));
        }
        let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let alpha_f = rho_inf / (rho_inf + 1.0);
        let d = 1.0 - alpha_m + alpha_f;
        Ok(Self {
            alpha_m,
            alpha_f,
            beta: 0.25 * d * d,
            gamma: 0.5 - alpha_m + alpha_f,
        })
    }

    /// Hilber–Hughes–Taylor parameters for `alpha ∈ [−1/3, 0]` (Hilber's sign):
    /// `α_m = 0`, `α_f = −α`, `γ = 1/2 − α`, `β = (1 − α)²/4`; `ρ∞ = (1 + α)/(1 − α)`.
    ///
    /// Errors: [`Error::InvalidParameter`] outside `[−1/3, 0]` or not finite. `const fn`
    /// (usable in a `static`); cost O(1).
    pub const fn hht(alpha: f64) -> Result<Self, Error> {
        if !(alpha >= -1.0 / 3.0 && alpha <= 0.0) {
            return Err(Error::InvalidParameter(Param::HhtAlpha));
        }
        Ok(Self {
            alpha_m: 0.0,
            alpha_f: -alpha,
            beta: 0.25 * (1.0 - alpha) * (1.0 - alpha),
            gamma: 0.5 - alpha,
        })
    }
}

/// The `f64` operators of a generalized-α step, `a_n = G p̄ − GK u_{n−1} + A_v v_{n−1} +
/// A_a a_{n−1}` with `p̄ = (1 − α_f) p_n + α_f p_{n−1}` and `G = M_eff⁻¹`, the kinematics,
/// the factorization of `M_eff` (for further solves, e.g. `G B`) and the start-up
/// operators: shared by [`GeneralizedAlpha`] (rounded to `T`) and the state-space form
/// ([`StateSpace::generalized_alpha`](crate::observer::StateSpace::generalized_alpha)).
pub(crate) struct AlphaOps<const N: usize> {
    pub g: Mat<N, N>,
    pub gk: Mat<N, N>,
    pub av: Mat<N, N>,
    pub aa: Mat<N, N>,
    pub kin: NewmarkKinematics<f64>,
    pub lu: Lu<N>,
    /// `κ₁` of the row-equilibrated `M_eff` ([`condition`]).
    pub condition: f64,
    /// The factorization of `M` (if regular) and the start-up operators.
    pub start: Option<(Lu<N>, StartOps<f64, N>)>,
}

/// Check `M, C, K, h` and the parameters and build the generalized-α operators by
/// factorizing `M_eff = (1 − α_m) M + (1 − α_f)(γh C + βh² K)` and solving (`const fn`).
/// `max`: the largest finite value of the scalar type the operators will be rounded to.
///
/// Errors, in this order: [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`],
/// [`Error::InvalidParameter`], [`Error::OperatorOverflow`] (`M_eff` not finite),
/// [`Error::SingularEffectiveMatrix`], [`Error::OperatorOverflow`],
/// [`Error::OperatorUnderflow`] (as the Newmark family's builds).
pub(crate) const fn alpha_operators<const N: usize>(
    m: &Mat<N, N>,
    c: &Mat<N, N>,
    k: &Mat<N, N>,
    h: f64,
    p: &AlphaParameters,
    max: f64,
) -> Result<AlphaOps<N>, Error> {
    if !(all_finite(m) && all_finite(c) && all_finite(k)) {
        return Err(Error::NonFiniteInput);
    }
    let AlphaParameters {
        alpha_m,
        alpha_f,
        beta,
        gamma,
    } = *p;
    let finite =
        alpha_m.is_finite() && alpha_f.is_finite() && beta.is_finite() && gamma.is_finite();
    // The time step first (as the stepper always checked it; in the scalar type: `h` and
    // `h²/4` representable), then the parameters.
    let h = match check_time_step_as(h, max) {
        Ok(h) => h,
        Err(e) => return Err(e),
    };
    let kin = match NewmarkKinematics::new(h, beta, gamma) {
        Ok(kin) => kin,
        Err(e) => return Err(e),
    };
    if !(finite && alpha_m < 1.0 && alpha_f < 1.0 && beta >= 0.0 && gamma >= 0.0) {
        return Err(Error::InvalidParameter(Param::AlphaParameters));
    }
    let hf = kin.h;
    let f1 = 1.0 - alpha_f;
    let (wm, wc, wk) = (1.0 - alpha_m, f1 * gamma * hf, f1 * beta * hf * hf);
    let (meff, scales, lu) = match effective_lu(&scaled(wm, m), c, k, wc, wk) {
        Ok(e) => e,
        Err(e) => return Err(e),
    };
    let (g, gc, gk, gm) = (lu.inverse(), lu.solve(c), lu.solve(k), lu.solve(m));
    // a_n = G p̄ − α_m GM a − (1−α_f) GC v̂ − (1−α_f) GK û − α_f (GC v + GK u), with
    // v̂ = v + (1−γ)h a, û = u + h v + (1/2−β)h² a, collected on (u, v, a).
    let av = add_scaled(&scaled(-1.0, &gc), -f1 * hf, &gk);
    let aa = add_scaled(
        &add_scaled(&scaled(-alpha_m, &gm), -f1 * (1.0 - gamma) * hf, &gc),
        -f1 * (0.5 - beta) * hf * hf,
        &gk,
    );
    // The same range check as the Newmark family's (`G`, `GC`, `GK` representable and not
    // flushed to zero), then the combined blocks and the kinematics; overflow anywhere
    // before underflow anywhere.
    let fit = [fits(&g, &meff, max), fits(&gc, c, max), fits(&gk, k, max)];
    let combined = finite_as(&av, max) && finite_as(&aa, max) && kin.fits(max);
    if let Err(e) = range_verdict(fit, combined) {
        return Err(e);
    }
    let start = match start_operators(m, c, k, max) {
        Ok(s) => s,
        Err(e) => return Err(e),
    };
    Ok(AlphaOps {
        g,
        gk,
        av,
        aa,
        kin,
        lu,
        condition: condition(&meff, &g, &scales),
        start,
    })
}

/// A generalized-α stepper for constant `M, C, K` (see the module docs for the
/// recurrence and for how the load is taken).
///
/// Same state and start-up as [`Linear`](crate::Linear); `4N² + O(N)` multiply-adds a
/// step. Size: `7N² + 7` values of `T`.
///
/// ```
/// use aemstep::{GeneralizedAlpha, Stepper};
/// use aemstep::{matrix, vector};
/// let sys = GeneralizedAlpha::<f64, 1>::new(&matrix![1.0], &matrix![0.0], &matrix![25.0], 0.01, 0.8)?;
/// let mut s = sys.start(&vector![1.0], &vector![0.0], &vector![0.0])?;
/// for _ in 0..100 {
///     sys.step(&mut s, &vector![0.0]);
/// }
/// assert!((s.u()[0] - 5.0f64.cos()).abs() < 2e-3);
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeneralizedAlpha<T, const N: usize> {
    params: AlphaParameters,
    /// `1 − α_f`, `α_f`.
    w1: T,
    w0: T,
    kin: NewmarkKinematics<T>,
    /// `a_n = G p̄ − GK u_{n−1} + Av v_{n−1} + Aa a_{n−1}`.
    g: [[T; N]; N],
    gk: [[T; N]; N],
    av: [[T; N]; N],
    aa: [[T; N]; N],
    start: Option<StartOps<T, N>>,
    condition: f64,
}

impl<T: Real, const N: usize> GeneralizedAlpha<T, N> {
    mck_fn! {
        /// The Chung–Hulbert scheme with high-frequency spectral radius `rho_inf ∈ [0, 1]`
        /// (1: no dissipation, the average-acceleration rule; 0: asymptotic annihilation).
        ///
        /// Errors: as [`GeneralizedAlpha::with_parameters`].
        pub fn new(m, c, k, h: f64, rho_inf: f64) {
            Self::with_parameters(m, c, k, h, AlphaParameters::chung_hulbert(rho_inf)?)
        }
    }

    mck_fn! {
        /// HHT-α with `alpha ∈ [−1/3, 0]` (Hilber's sign; `−0.05 … −0.1` is common).
        ///
        /// Errors: as [`GeneralizedAlpha::with_parameters`].
        pub fn hht(m, c, k, h: f64, alpha: f64) {
            Self::with_parameters(m, c, k, h, AlphaParameters::hht(alpha)?)
        }
    }

    mck_fn! {
        /// Any `(α_m, α_f, β, γ)`; computed in `f64`, rounded once to `T`.
        ///
        /// Errors: [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`],
        /// [`Error::InvalidParameter`] (a parameter not finite, `α_m ≥ 1`, `α_f ≥ 1`, `β < 0`
        /// or `γ < 0`), [`Error::SingularEffectiveMatrix`] (`(1 − α_m) M + (1 − α_f)(γh C +
        /// βh² K)` singular to working precision against its terms),
        /// [`Error::OperatorOverflow`], [`Error::OperatorUnderflow`].
        ///
        /// Cost: about `9N³` flops in `f64`, six `N×N` `f64` temporaries on the stack.
        pub fn with_parameters(m, c, k, h: f64, p: AlphaParameters) {
            let (m, c, k) = (rows_f64(m), rows_f64(c), rows_f64(k));
            let op = alpha_operators(&m, &c, &k, h, &p, T::MAX)?;
            Ok(Self {
                params: p,
                w1: T::from_f64_rounded(1.0 - p.alpha_f),
                w0: T::from_f64_rounded(p.alpha_f),
                kin: op.kin.round(),
                g: round_rows(&op.g),
                gk: round_rows(&op.gk),
                av: round_rows(&op.av),
                aa: round_rows(&op.aa),
                start: op.start.map(|(_, s)| s.round()),
                condition: op.condition,
            })
        }
    }

    /// How close the effective matrix is to singular: `κ₁` of the row-equilibrated
    /// effective matrix (each row divided by the size of the terms it was assembled from),
    /// computed once in `f64`; see [`Linear::condition`](crate::Linear::condition). Cost:
    /// O(1).
    pub fn condition(&self) -> f64 {
        self.condition
    }

    /// The scheme's parameters.
    pub fn parameters(&self) -> AlphaParameters {
        self.params
    }

    #[inline(always)]
    fn step_inner(&self, s: &mut State<T, N>, p_prev: &SVector<T, N>, p: &SVector<T, N>) {
        let mut pbar = [T::zero(); N];
        for j in 0..N {
            pbar[j] = self.w1 * p[j] + self.w0 * p_prev[j];
        }
        let mut anew = [T::zero(); N];
        for i in 0..N {
            let (g, gk, av, aa) = (&self.g[i], &self.gk[i], &self.av[i], &self.aa[i]);
            let mut q = T::zero();
            for j in 0..N {
                q += g[j] * pbar[j] - gk[j] * s.u[j] + av[j] * s.v[j] + aa[j] * s.a[j];
            }
            anew[i] = q;
        }
        for j in 0..N {
            let (vh, uh) = self.kin.predict(s.u[j], s.v[j], s.a[j]);
            (s.v[j], s.u[j]) = self.kin.correct(vh, uh, anew[j]);
            s.a[j] = anew[j];
        }
        s.n = s.n.wrapping_add(1);
    }
}

impl<T: Real, const N: usize> Stepper<T, N> for GeneralizedAlpha<T, N> {
    type Input = SVector<T, N>;
    type State = State<T, N>;

    crate::stepper::full_order_state!(start);

    #[inline]
    fn time_step(&self) -> T {
        self.kin.h
    }

    crate::stepper::steps_through_inner!(
        /// [`Stepper::step_with_previous_input`] with `p_prev = p`: exact for free vibration and
        /// constant loads, but FIRST order for a time-varying load (the weighted load
        /// `(1 − α_f) p_n + α_f p_{n−1}` needs the previous sample, which the shared [`State`]
        /// does not carry). Drive it with `step_with_previous_input` for second order.
        /// Cost: `4N²` multiply-adds + `10N`.
        ;
        /// The textbook step: the load taken as `(1 − α_f) p + α_f p_prev`, with
        /// `p_prev = p(t_{n−1})`, `p = p(t_n)`. Second order for any smooth load.
        ///
        /// Cost: `4N²` multiply-adds + `10N`. No allocation, no panic.
    );
}
