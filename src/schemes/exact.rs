//! The exact discretization of `M u'' + C u' + K u = p(t)` for a load that is piecewise
//! linear between the samples: no period error, no amplitude error, only rounding.
//!
//! With `z = (u, v)`, `z' = F z + B p`, `F = [[0, I], [−M⁻¹K, −M⁻¹C]]`, `B = [0; M⁻¹]` and
//! `p` linear on each step, `z_n = Φ z_{n−1} + Γ₁ p_{n−1} + Γ₂ (p_n − p_{n−1})/h`, where
//! `Φ, Γ₁, Γ₂` are blocks of the exponential of the `4N×4N` augmented matrix
//! (Van Loan)
//!
//! ```text
//!       [ 0      I      0    0 ]
//! exp(h [ −M⁻¹K  −M⁻¹C  M⁻¹  0 ] ) ,   state (u, v, p, ṗ)
//!       [ 0      0      0    I ]
//!       [ 0      0      0    0 ]
//! ```
//!
//! computed once in `f64` by scaling and squaring a degree-18 Taylor polynomial, after a
//! diagonal balancing that makes the blocks of comparable size (so stiff systems,
//! `‖M⁻¹K‖h² ≫ 1`, square an almost orthogonal matrix), and rounded once to `T`.
//!
//! A step takes the load at both ends, `p_{n−1}` and `p_n`
//! ([`Stepper::step_with_previous_input`]):
//!
//! ```text
//! u_n = Φ_uu u + Φ_uv v + P0_u p_{n−1} + P1_u p_n,   P0 = Γ₁ − Γ₂/h,  P1 = Γ₂/h
//! v_n = Φ_vu u + Φ_vv v + P0_v p_{n−1} + P1_v p_n
//! a_n = M⁻¹ p_n − (M⁻¹C) v_n − (M⁻¹K) u_n
//! ```
//!
//! (`11N²` multiply-adds). [`Stepper::step`], given `p_n` only, takes
//! `p_{n−1} = M a_{n−1} + C v_{n−1} + K u_{n−1}`, which is the load of the previous step
//! whenever the state came from this scheme (its acceleration always satisfies the
//! equation of motion), at `3N²` more. After a known-acceleration start with an
//! inconsistent `a0`, or a state handed over from another scheme, pass the previous load.
//! Needs an invertible `M`.

use nalgebra::{ComplexField, SMatrix, SVector};

use crate::kernel::{StartOps, checked_rows, start_operators};
use crate::kinematics::check_time_step_as;
use crate::linalg::expm::{Blk, blk_expm, norm1};
use crate::linalg::lu::Lu;
use crate::linalg::{
    Mat, add_scaled, finite_as, first_error, fits, fits_alone, identity, round_rows, scaled,
};
use crate::macros::mck_fn;
use crate::{Error, Real, State, Stepper};

/// `y += A x` for a row-major `A`.
#[inline(always)]
fn mac<T: Real, const N: usize>(y: &mut [T; N], a: &[[T; N]; N], x: &[T; N]) {
    for i in 0..N {
        let mut s = T::zero();
        for j in 0..N {
            s += a[i][j] * x[j];
        }
        y[i] += s;
    }
}

/// The exact-discretization stepper (see the module docs).
///
/// Same state, start-up and interface as [`Linear`](crate::Linear); `11N²`
/// multiply-adds a step with the previous load given, `14N²` without. Size: `14N² + 1`
/// values of `T` (the `M⁻¹` blocks double as the start-up operators).
///
/// ```
/// use aemstep::{Exact, Stepper};
/// use aemstep::{matrix, vector};
/// // u'' + 25 u = 0 with a step as long as a third of the period: still exact.
/// let h = 0.4;
/// let sys = Exact::<f64, 1>::new(&matrix![1.0], &matrix![0.0], &matrix![25.0], h)?;
/// let mut s = sys.start(&vector![1.0], &vector![0.0], &vector![0.0])?;
/// for _ in 0..100 {
///     sys.step(&mut s, &vector![0.0]);
/// }
/// assert!((s.u()[0] - (5.0 * 40.0f64).cos()).abs() < 1e-12);
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Exact<T, const N: usize> {
    h: T,
    /// `[Φ_uu, Φ_uv, P0_u, P1_u]` and `[Φ_vu, Φ_vv, P0_v, P1_v]` (read by the observer's
    /// state-space form).
    pub(crate) au: [[[T; N]; N]; 4],
    pub(crate) av: [[[T; N]; N]; 4],
    /// `M, C, K` (the previous load of a one-sample step).
    mck: [[[T; N]; N]; 3],
    /// `M⁻¹, M⁻¹C, M⁻¹K` (equation of motion, and start-up; always `Some`).
    start: Option<StartOps<T, N>>,
}

/// The blocks of the matrix exponential every exact (hold) discretization of
/// `M u'' + C u' + K u = p` reads: with `F = [[0, I], [−M⁻¹K, −M⁻¹C]]`, row `r` (`0`: `u`,
/// `1`: `v`) of `[Φ, Γ₁ᵉ, Γ₂ᵉ]`, `Γ₁ᵉ = ∫₀ʰ e^{F s} ds [0; M⁻¹]`,
/// `Γ₂ᵉ = ∫₀ʰ e^{F s} (h − s) ds [0; M⁻¹]` — `[Φ_r0, Φ_r1, Γ₁ᵉ_r, Γ₂ᵉ_r]`, from one
/// exponential (Van Loan) of `h [[0, I, 0, 0], [−M⁻¹K, −M⁻¹C, M⁻¹, 0], [0, 0, 0, I], 0]`,
/// balanced by `D = diag(1, σ, τ₁, τ₂)` and unbalanced after. [`Exact`] forms the
/// first-order hold from all four; the zero-order hold
/// ([`StateSpace::zero_order_hold`](crate::observer::StateSpace::zero_order_hold)) takes
/// `Φ` and `Γ₁ᵉ`. Cost: about `(4N)³ (19 + s)` flops, three `16N²` `f64` temporaries.
fn exponential_blocks<const N: usize>(
    mi: &Mat<N, N>,
    mic: &Mat<N, N>,
    mik: &Mat<N, N>,
    hf: f64,
) -> [[Mat<N, N>; 4]; 2] {
    // Balancing D = diag(1, σ, τ1, τ2): block (i, j) scales by d_j / d_i.
    let kn = norm1(mik);
    let cn = norm1(mic);
    let sigma = if kn > 0.0 {
        <f64 as ComplexField>::sqrt(kn)
    } else {
        1.0 / hf
    };
    let theta = (sigma * hf).max(cn * hf);
    let tau1 = sigma * theta / (norm1(mi) * hf);
    let tau2 = tau1 * theta / hf;
    let d = [1.0, sigma, tau1, tau2];
    let z = [[0.0; N]; N];
    let mut x: Blk<N> = [[z; 4]; 4];
    let id: Mat<N, N> = identity();
    x[0][1] = add_scaled(&z, hf * d[1] / d[0], &id);
    x[1][0] = add_scaled(&z, -hf * d[0] / d[1], mik);
    x[1][1] = add_scaled(&z, -hf, mic);
    x[1][2] = add_scaled(&z, hf * d[2] / d[1], mi);
    x[2][3] = add_scaled(&z, hf * d[3] / d[2], &id);
    let mut work: Blk<N> = [[z; 4]; 4];
    let mut e: Blk<N> = [[z; 4]; 4];
    blk_expm(&mut x, &mut work, &mut e);
    // Undo the balancing: E_ij = (d_i / d_j) E'_ij, for block rows u, v.
    let blk = |i: usize, j: usize| add_scaled(&z, d[i] / d[j], &e[i][j]);
    [0, 1].map(|r| [blk(r, 0), blk(r, 1), blk(r, 2), blk(r, 3)])
}

/// What every exact (hold) discretization starts from: `M, C, K` (row-major, checked
/// finite), the time step `h` (s, checked for the scalar type whose largest finite value
/// is `max`), the factorization of `M` and its start-up operators `M⁻¹, M⁻¹C, M⁻¹K`, and
/// the blocks of the exponential ([`exponential_blocks`]).
pub(crate) struct Exponential<const N: usize> {
    pub m: Mat<N, N>,
    pub c: Mat<N, N>,
    pub k: Mat<N, N>,
    pub h: f64,
    pub lu_m: Lu<N>,
    pub start: StartOps<f64, N>,
    pub blocks: [[Mat<N, N>; 4]; 2],
}

/// Check `M, C, K, h` and form the [`Exponential`] (shared by [`Exact::new`] and the
/// zero-order hold of the state-space form).
///
/// Errors, in this order: [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`],
/// [`Error::OperatorOverflow`] (a start-up operator beyond `max`),
/// [`Error::SingularMass`]. Cost: that of [`exponential_blocks`] plus `M`'s LU.
pub(crate) fn exponential<const N: usize>(
    m: &SMatrix<f64, N, N>,
    c: &SMatrix<f64, N, N>,
    k: &SMatrix<f64, N, N>,
    h: f64,
    max: f64,
) -> Result<Exponential<N>, Error> {
    let (m, c, k) = checked_rows(m, c, k)?;
    let h = check_time_step_as(h, max)?;
    let (lu_m, st) = start_operators(&m, &c, &k, max)?.ok_or(Error::SingularMass)?;
    let blocks = exponential_blocks(&st.minv, &st.minv_c, &st.minv_k, h);
    Ok(Exponential {
        m,
        c,
        k,
        h,
        lu_m,
        start: st,
        blocks,
    })
}

impl<T: Real, const N: usize> Exact<T, N> {
    mck_fn! {
        /// Compute the exact step operators for step `h` (s). Computed in `f64`, rounded
        /// once to `T`.
        ///
        /// Errors: [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`],
        /// [`Error::SingularMass`] (`M` singular: the first-order form needs `M⁻¹`),
        /// [`Error::OperatorOverflow`], [`Error::OperatorUnderflow`] (an operator beyond the
        /// range of `T`, or its largest entry subnormal there).
        ///
        /// Cost: about `(4N)³ (19 + s)` flops, `s = ⌈log₂(2‖hF‖)⌉` squarings (balanced norm,
        /// e.g. `s ≈ 14` for `ω_max h = 10⁴`), and three `16N²` `f64` temporaries on the
        /// stack (`384 KB` at `N = 50`, `1.5 MB` at `N = 100`: use a large stack there).
        pub fn new(m, c, k, h: f64) {
            let Exponential {
                m,
                c,
                k,
                h: hf,
                start: st,
                blocks,
                ..
            } = exponential(m, c, k, h, T::MAX)?;
            let mut under = None;
            let mut au = [[[T::zero(); N]; N]; 4];
            let mut av = [[[T::zero(); N]; N]; 4];
            for (r, out) in [(0usize, &mut au), (1usize, &mut av)] {
                let [phi_u, phi_v, g1, g2] = blocks[r];
                // P0 = Γ₁ − Γ₂/h multiplies p_{n−1} = M a + C v + K u; P1 = Γ₂/h multiplies p_n.
                let p0 = add_scaled(&g1, -1.0 / hf, &g2);
                let p1 = scaled(1.0 / hf, &g2);
                // Representable in `T` (overflow now, underflow after every block is seen):
                // `P1 = Γ₂/h` is never zero for a regular `M`; the others are judged alone.
                let fit = [
                    fits_alone(&phi_u, T::MAX),
                    fits_alone(&phi_v, T::MAX),
                    fits_alone(&p0, T::MAX),
                    fits(&p1, &m, T::MAX),
                ];
                match first_error(fit) {
                    Some(Error::OperatorOverflow) => return Err(Error::OperatorOverflow),
                    Some(e) => under = Some(e),
                    None => {}
                }
                *out = [
                    round_rows(&phi_u),
                    round_rows(&phi_v),
                    round_rows(&p0),
                    round_rows(&p1),
                ];
            }
            if ![&m, &c, &k].iter().all(|x| finite_as(x, T::MAX)) {
                return Err(Error::OperatorOverflow);
            }
            if let Some(e) = under {
                return Err(e);
            }
            Ok(Self {
                h: T::from_f64_rounded(hf),
                au,
                av,
                mck: [round_rows(&m), round_rows(&c), round_rows(&k)],
                start: Some(st.round()),
            })
        }
    }
}

impl<T: Real, const N: usize> Stepper<T, N> for Exact<T, N> {
    type Input = SVector<T, N>;
    type State = State<T, N>;

    #[inline]
    fn time_step(&self) -> T {
        self.h
    }

    crate::stepper::full_order_state!(start);

    /// The step with `p_{n−1} = M a + C v + K u` recovered from the state (see the module
    /// docs). Cost: `14N²` multiply-adds.
    #[inline]
    fn step(&self, s: &mut State<T, N>, p: &SVector<T, N>) {
        let mut p_prev = [T::zero(); N];
        let x = [s.a.into(), s.v.into(), s.u.into()];
        for b in 0..3 {
            mac(&mut p_prev, &self.mck[b], &x[b]);
        }
        self.step_with_previous_input(s, &p_prev.into(), p);
    }

    /// The exact step for the load linear between `p_prev` and `p`. Cost: `11N²`
    /// multiply-adds.
    #[inline]
    fn step_with_previous_input(
        &self,
        s: &mut State<T, N>,
        p_prev: &SVector<T, N>,
        p: &SVector<T, N>,
    ) {
        let x: [[T; N]; 4] = [s.u.into(), s.v.into(), (*p_prev).into(), (*p).into()];
        let mut u = [T::zero(); N];
        let mut v = [T::zero(); N];
        for b in 0..4 {
            mac(&mut u, &self.au[b], &x[b]);
            mac(&mut v, &self.av[b], &x[b]);
        }
        let Some(eom) = &self.start else {
            return; // unreachable: `Exact::new` always sets it
        };
        let mut a = [T::zero(); N];
        mac(&mut a, &eom.minv, &x[3]);
        for i in 0..N {
            let mut acc = a[i];
            for j in 0..N {
                acc -= eom.minv_c[i][j] * v[j] + eom.minv_k[i][j] * u[j];
            }
            a[i] = acc;
        }
        s.u = u.into();
        s.v = v.into();
        s.a = a.into();
        s.n = s.n.wrapping_add(1);
    }
}
