//! The discrete state-space form of every linear scheme, for `x = [u; v]` (or `[η; η']`,
//! or `[u; v; a]` for generalized-α).
//!
//! Every linear scheme of the crate advances its state by a linear map of the previous
//! state and of the input samples at both ends of the step (load `p = B w`):
//!
//! ```text
//! x_n = Φ x_{n−1} + Γ₀ w_{n−1} + Γ₁ w_n          y_n = H x_n + D w_n
//! ```
//!
//! **Newmark (β, γ)** ([`Newmark`](crate::Newmark); the AEM [`Linear`](crate::Linear),
//! [`LinearInput`](crate::LinearInput) is β = 1/4, γ = 1/2): the stepper's new
//! acceleration solves `M_eff q_n = B w_n − C v̂ − K û` with `M_eff = M + γh C + βh² K`,
//! `v_n = v̂ + γh q_n`, `u_n = û + βh² q_n`, so `M q_n + C v_n + K u_n = B w_n`: the
//! acceleration of every step (and of the start) satisfies the equation of motion,
//! `a_{n−1} = M⁻¹ (B w_{n−1} − C v − K u)`, and is no state of its own. Substituted into
//! the predictor `v̂ = v + (1 − γ)h a`, `û = u + h v̂ − (β + 1/2 − γ)h² a` and the corrector,
//! it gives `Φ, Γ₀, Γ₁` blockwise on `x = [u; v]` (`S = 2N`). Formed in `f64` by two
//! factorizations (`M` and `M_eff`) and solves with right-hand sides `K, C, B` — no
//! explicit inverse is multiplied. ([`StateSpace::newmark`], [`StateSpace::aem`].)
//!
//! **Generalized-α** ([`GeneralizedAlpha`](crate::GeneralizedAlpha), HHT-α): the
//! stepper's acceleration solves `(1 − α_m) M a_n + α_m M a_{n−1} + (1 − α_f)(C v_n +
//! K u_n) + α_f (C v + K u) = p̄`, not the equation of motion at `t_n`, so it is a state
//! of its own: `x = [u; v; a]` (`S = 3N`). With `G = M_eff⁻¹`, `M_eff = (1 − α_m) M +
//! (1 − α_f)(γh C + βh² K)`, the stepper's operators give the `a` row
//! `a_n = −GK u + A_v v + A_a a + G p̄`; the load `p̄ = α_f B w_{n−1} + (1 − α_f) B w_n`
//! gives `Γ₀ = α_f (…) GB`, `Γ₁ = (1 − α_f)(…) GB`, and the Newmark predictor–corrector
//! the `u` and `v` rows (`u_n = û + βh² a_n`, `v_n = v̂ + γh a_n`). ([`StateSpace::generalized_alpha`].)
//!
//! **Exact** ([`Exact`](crate::Exact)): the blocks of its matrix exponential, the
//! first-order-hold load `p = B w` linear over the step. **Zero-order hold**
//! ([`StateSpace::zero_order_hold`]): the same exponential with the input held over the
//! step at its first sample (`Γ₀ = ∫₀ʰ e^{F s} ds [0; M⁻¹] B`, `Γ₁ = 0`). **Modal**
//! ([`Modal`](crate::Modal)): the scalar AEM of each kept mode, `x = [η; η']` (`2R` values);
//! each of the four `R×R` blocks of `Φ` is diagonal.
//!
//! Outputs: `y = Y_u u + Y_v v + Y_a a + Y_w w` ([`Outputs`]) — displacements, drifts,
//! velocities, relative or absolute accelerations — become `H = Y_u U + Y_v V + Y_a A_x`,
//! `D = Y_a A_w + Y_w` through the maps `u = U x`, `v = V x`, `a = A_x x + A_w w` of the
//! model ([`StateSpace::outputs`]); an acceleration output has a direct feedthrough `D`.
//! `a` is the physical acceleration `M⁻¹ (B w − C v − K u)` for every scheme (for
//! generalized-α too: what an accelerometer measures, not the scheme's variable).

use nalgebra::{SMatrix, SVector};

use super::flat::{identity_into, mul_into};
use crate::kernel::{StartOps, Terms, input_kernel_operators, start_operators};
use crate::kinematics::NewmarkKinematics;
use crate::linalg::lu::{Lu, row_scales, solve_flat};
use crate::linalg::{
    Mat, Rows, add_scaled, all_finite, identity, mul, put, rows_f64, scaled, transpose,
};
use crate::linalg::{add_scaled_flat, all_finite_flat, copy_flat};
use crate::macros::mck_fn;
use crate::modal::{Damping, lowest_modes, modal_operators};
use crate::schemes::alpha_operators;
use crate::schemes::{Exponential, exponential};
use crate::stepper::start_fn;
use crate::{AlphaParameters, Error, Exact};

/// The discrete state-space model of a linear scheme with `N` degrees of freedom, state
/// size `S` (`2N`; `3N` for generalized-α; `2R` for `R` modes) and `I` inputs, all in `f64`
/// (row-major: `phi[i][j]` is row `i`, column `j`):
///
/// ```text
/// x_n = Φ x_{n−1} + Γ₀ w_{n−1} + Γ₁ w_n,      u = U x,  v = V x,  a = A_x x + A_w w
/// ```
///
/// `x = [u; v]` (m, m/s for a building), `[u; v; a]` (generalized-α; m/s² for `a`) or,
/// modal, `[η; η']`. Plain matrices a user can check; [`StateSpace::outputs`] makes the
/// output matrices of any [`Outputs`]. Built by [`StateSpace::aem`],
/// [`StateSpace::newmark`], [`StateSpace::generalized_alpha`], [`StateSpace::exact`],
/// [`StateSpace::zero_order_hold`], [`StateSpace::modal`] (run time) or the `const fn`
/// [`StateSpace::from_rows_aem`], [`StateSpace::from_rows_newmark`],
/// [`StateSpace::from_rows_generalized_alpha`], [`StateSpace::from_rows_modal`] (in a
/// `static`: computed by the compiler). Each reproduces its stepper to rounding
/// (`tests/state_space.rs`); the zero-order hold, which has no stepper, its closed form
/// and an independent exponential (`tests/zoh.rs`).
///
/// Size: `S² + 2S·I + N·(3S + I) + 1` values of `f64` (a build-time object: the
/// observers keep only what they step with).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StateSpace<const N: usize, const S: usize, const I: usize> {
    /// `Φ` (`S×S`), the state transition over one step.
    pub phi: [[f64; S]; S],
    /// `Γ₀` (`S×I`), multiplies the input at the start of the step, `w_{n−1}`.
    pub gamma0: [[f64; I]; S],
    /// `Γ₁` (`S×I`), multiplies the input at the end of the step, `w_n`.
    pub gamma1: [[f64; I]; S],
    /// `U` (`N×S`): the displacements `u = U x`.
    pub dof_u: [[f64; S]; N],
    /// `V` (`N×S`): the velocities `v = V x`.
    pub dof_v: [[f64; S]; N],
    /// `A_x` (`N×S`): the accelerations (relative to the base) `a = A_x x + A_w w`, the
    /// physical `M⁻¹ (B w − C v − K u)` for every builder (zero columns on the `a` block
    /// of a generalized-α state).
    pub dof_a: [[f64; S]; N],
    /// `A_w` (`N×I`): the accelerations' direct dependence on the input.
    pub dof_a_input: [[f64; I]; N],
    /// The time step `h` (s).
    pub time_step: f64,
}

/// What is measured or estimated: `y = Y_u u + Y_v v + Y_a a + Y_w w`, `O` outputs of a
/// model with `N` degrees of freedom and `I` inputs (row-major `f64`). Fill the fields or
/// use the `const` helpers ([`Outputs::displacements`], [`Outputs::absolute_accelerations`],
/// …); combine kinds by filling several fields.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outputs<const N: usize, const I: usize, const O: usize> {
    /// `Y_u` (`O×N`): weights of the displacements (e.g. [`storey_drifts`](crate::models::storey_drifts)).
    pub u: [[f64; N]; O],
    /// `Y_v` (`O×N`): weights of the velocities.
    pub v: [[f64; N]; O],
    /// `Y_a` (`O×N`): weights of the accelerations (relative to the base).
    pub a: [[f64; N]; O],
    /// `Y_w` (`O×I`): weights of the inputs (e.g. the ground acceleration of an absolute
    /// acceleration).
    pub w: [[f64; I]; O],
}

impl<const N: usize, const I: usize, const O: usize> Outputs<N, I, O> {
    /// No output weight at all (fill the fields from here).
    pub const fn zero() -> Self {
        Self {
            u: [[0.0; N]; O],
            v: [[0.0; N]; O],
            a: [[0.0; N]; O],
            w: [[0.0; I]; O],
        }
    }

    /// `y = Y u`: displacements or drifts (rows of `y`, e.g.
    /// [`storey_drifts`](crate::models::storey_drifts)).
    pub const fn displacements(y: [[f64; N]; O]) -> Self {
        let mut o = Self::zero();
        o.u = y;
        o
    }

    /// `y = Y v`: velocities (or drift rates).
    pub const fn velocities(y: [[f64; N]; O]) -> Self {
        let mut o = Self::zero();
        o.v = y;
        o
    }

    /// `y = Y a`: accelerations relative to the base.
    pub const fn accelerations(y: [[f64; N]; O]) -> Self {
        let mut o = Self::zero();
        o.a = y;
        o
    }

    /// `y = Y (a + ι a_g)`: absolute accelerations under base excitation (the
    /// accelerometer's reading), where input `input` is the ground acceleration `a_g` and
    /// `ι = (1, …, 1)` (every DOF moves with the ground, as
    /// [`base_excitation`](crate::models::base_excitation)). An `input ≥ I` adds nothing
    /// (relative accelerations).
    pub const fn absolute_accelerations(y: [[f64; N]; O], input: usize) -> Self {
        let mut o = Self::accelerations(y);
        if input < I {
            // `Y ι`: each row's sum, in the order of the columns (`ι` is exact).
            let y_iota = mul(&y, &[[1.0]; N]);
            let mut r = 0;
            while r < O {
                o.w[r][input] = y_iota[r][0];
                r += 1;
            }
        }
        o
    }

    /// Rows of the `N×N` identity selected by `dofs`: `[[0, 1, 0, …], …]` for DOF 1 etc.
    /// An index `≥ N` gives a zero row.
    pub const fn select(dofs: [usize; O]) -> [[f64; N]; O] {
        let mut y = [[0.0; N]; O];
        let mut r = 0;
        while r < O {
            if dofs[r] < N {
                y[r][dofs[r]] = 1.0;
            }
            r += 1;
        }
        y
    }
}

/// The output matrices `y = H x + D w` of [`Outputs`] on a [`StateSpace`] (`f64`,
/// row-major): what an observer measures or a [`Readout`](crate::observer::Readout)
/// estimates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measurement<const S: usize, const I: usize, const O: usize> {
    /// `H` (`O×S`).
    pub h: [[f64; S]; O],
    /// `D` (`O×I`), the direct feedthrough (nonzero for acceleration outputs).
    pub d: [[f64; I]; O],
}

impl<const S: usize, const I: usize, const O: usize> Measurement<S, I, O> {
    /// `H` as a `nalgebra` matrix.
    pub fn h_matrix(&self) -> SMatrix<f64, O, S> {
        crate::linalg::matrix_t(&self.h)
    }
    /// `D` as a `nalgebra` matrix.
    pub fn d_matrix(&self) -> SMatrix<f64, O, I> {
        crate::linalg::matrix_t(&self.d)
    }
}

/// The blocks of one Newmark step (β, γ; the AEM is β = 1/4, γ = 1/2) in `f64`:
/// `u_n = uu u + uv v + u0 w_{n−1} + u1 w_n`, same for `v_n`; `a = au u + av v + aw w`
/// (the equation of motion).
struct NewmarkBlocks<const N: usize, const I: usize> {
    uu: Mat<N, N>,
    uv: Mat<N, N>,
    vu: Mat<N, N>,
    vv: Mat<N, N>,
    u0: Mat<N, I>,
    v0: Mat<N, I>,
    u1: Mat<N, I>,
    v1: Mat<N, I>,
    au: Mat<N, N>,
    av: Mat<N, N>,
    aw: Mat<N, I>,
}

/// `a + s·b` for `N×C` blocks (local shorthand).
const fn axpy<const R: usize, const C: usize>(a: &Mat<R, C>, s: f64, b: &Mat<R, C>) -> Mat<R, C> {
    add_scaled(a, s, b)
}

/// The Newmark step (β, γ) as blocks (see the module docs): factorizations of `M` and
/// `M_eff = M + γh C + βh² K`, solves. The checks of
/// [`newmark_operators`](crate::kernel::newmark_operators) (the steppers'), after `B`'s
/// ([`input_kernel_operators`], as [`LinearInput`](crate::LinearInput)'s).
const fn newmark_blocks<const N: usize, const I: usize>(
    m: &Rows<N>,
    c: &Rows<N>,
    k: &Rows<N>,
    b: &Mat<N, I>,
    h: f64,
    beta: f64,
    gamma: f64,
) -> Result<NewmarkBlocks<N, I>, Error> {
    let (op, gb, minv_b) = match input_kernel_operators(m, c, k, b, h, beta, gamma, f64::MAX) {
        Ok(ops) => ops,
        Err(e) => return Err(e),
    };
    let (aw, st) = match (minv_b, op.start) {
        (Some(aw), Some((_, st))) => (aw, st),
        _ => return Err(Error::SingularMass),
    };
    let z = [[0.0; N]; N];
    let zi = [[0.0; I]; N];
    let mut bl = NewmarkBlocks {
        uu: z,
        uv: z,
        vu: z,
        vv: z,
        u0: zi,
        v0: zi,
        u1: zi,
        v1: zi,
        au: z,
        av: z,
        aw,
    };
    let (mut t0, mut t1, mut t2, mut t3, mut t4) = (z, z, z, z, z);
    let (mut w0, mut w1, mut w2) = (zi, zi, zi);
    let (lu, perm) = op.lu.parts();
    blocks_flat(
        &Terms::of(m, c, k),
        &BlockInputs {
            minv_k: st.minv_k.as_flattened(),
            minv_c: st.minv_c.as_flattened(),
            aw: aw.as_flattened(),
            gb: gb.as_flattened(),
            lu,
            perm,
            kin: &op.kin,
            inputs: I,
        },
        [
            bl.uu.as_flattened_mut(),
            bl.uv.as_flattened_mut(),
            bl.vu.as_flattened_mut(),
            bl.vv.as_flattened_mut(),
            bl.au.as_flattened_mut(),
            bl.av.as_flattened_mut(),
        ],
        [
            bl.u0.as_flattened_mut(),
            bl.v0.as_flattened_mut(),
            bl.u1.as_flattened_mut(),
            bl.v1.as_flattened_mut(),
        ],
        [
            t0.as_flattened_mut(),
            t1.as_flattened_mut(),
            t2.as_flattened_mut(),
            t3.as_flattened_mut(),
            t4.as_flattened_mut(),
        ],
        [
            w0.as_flattened_mut(),
            w1.as_flattened_mut(),
            w2.as_flattened_mut(),
        ],
    );
    Ok(bl)
}

/// What the Newmark blocks are formed from (flat, row-major; `n = perm.len()`): the
/// start-up operators `M⁻¹K`, `M⁻¹C`, `A_w = M⁻¹B`, `G B = M_eff⁻¹ B`, the factors of
/// `M_eff` and the kinematic coefficients.
pub(crate) struct BlockInputs<'a> {
    pub(crate) minv_k: &'a [f64],
    pub(crate) minv_c: &'a [f64],
    pub(crate) aw: &'a [f64],
    pub(crate) gb: &'a [f64],
    pub(crate) lu: &'a [f64],
    pub(crate) perm: &'a [usize],
    pub(crate) kin: &'a NewmarkKinematics<f64>,
    /// Inputs `I` (columns of `aw`, `gb`).
    pub(crate) inputs: usize,
}

/// `dst = 0 + s·src` (the arrays' `scaled`, entry by entry).
const fn set_scaled(dst: &mut [f64], s: f64, src: &[f64]) {
    let mut i = 0;
    while i < dst.len() {
        dst[i] = 0.0;
        i += 1;
    }
    add_scaled_flat(dst, s, src);
}

/// `dst = a + s·b`.
const fn set_axpy(dst: &mut [f64], a: &[f64], s: f64, b: &[f64]) {
    copy_flat(dst, a);
    add_scaled_flat(dst, s, b);
}

/// The Newmark step's blocks (module docs) on flat slices: the one arithmetic of the
/// const-generic [`StateSpace::from_rows_newmark`] and the run-time-sized
/// [`DynStateSpace`](super::DynStateSpace). `sq = [uu, uv, vu, vv, au, av]` (`n×n`),
/// `wi = [u0, v0, u1, v1]` (`n×I`) are written; `tn` (`n×n`) and `ti` (`n×I`) are
/// scratch. Cost: about `8n³ + 6n²·I` flops.
pub(crate) const fn blocks_flat(
    t: &Terms<'_>,
    x: &BlockInputs<'_>,
    sq: [&mut [f64]; 6],
    wi: [&mut [f64]; 4],
    tn: [&mut [f64]; 5],
    ti: [&mut [f64]; 3],
) {
    let (n, ni, kin) = (x.perm.len(), x.inputs, x.kin);
    let [uu, uv, vu, vv, au, av] = sq;
    let [u0, v0, u1, v1] = wi;
    let [vh_u, vh_v, uh_u, uh_v, tmp] = tn;
    let [vh_w, uh_w, tmp_i] = ti;
    // The equation of motion: a = −M⁻¹K u − M⁻¹C v + M⁻¹B w.
    set_scaled(au, -1.0, x.minv_k);
    set_scaled(av, -1.0, x.minv_c);
    // Predictor: v̂ = v + c_v a, û = u + h v̂ − c_u a.
    set_scaled(vh_u, kin.c_v, au);
    identity_into(vh_v, n);
    add_scaled_flat(vh_v, kin.c_v, av);
    set_scaled(vh_w, kin.c_v, x.aw);
    identity_into(uh_u, n);
    add_scaled_flat(uh_u, kin.h, vh_u);
    add_scaled_flat(uh_u, -kin.c_u, au);
    set_scaled(uh_v, kin.h, vh_v);
    add_scaled_flat(uh_v, -kin.c_u, av);
    set_scaled(uh_w, kin.h, vh_w);
    add_scaled_flat(uh_w, -kin.c_u, x.aw);
    // q = M_eff⁻¹ (B w_n − C v̂ − K û), corrector u_n = û + β h² q, v_n = v̂ + γ h q.
    let (bh2, gh) = (kin.beta_h2, kin.gamma_h);
    // u, v columns: the right-hand side into `tmp`, q into `uu` then the blocks.
    rhs_q(t, vh_u, uh_u, n, n, x, [tmp, vu]);
    set_axpy(uu, uh_u, bh2, vu);
    copy_flat(tmp, vu);
    set_axpy(vu, vh_u, gh, tmp);
    rhs_q(t, vh_v, uh_v, n, n, x, [tmp, vv]);
    set_axpy(uv, uh_v, bh2, vv);
    copy_flat(tmp, vv);
    set_axpy(vv, vh_v, gh, tmp);
    // w columns.
    rhs_q(t, vh_w, uh_w, n, ni, x, [tmp_i, u1]);
    set_axpy(u0, uh_w, bh2, u1);
    set_axpy(v0, vh_w, gh, u1);
    set_scaled(u1, bh2, x.gb);
    set_scaled(v1, gh, x.gb);
}

/// `q = M_eff⁻¹ ((0 − C v̂) − K û)` for `c` columns into `out[1]` (`out[0]` scratch).
const fn rhs_q(
    t: &Terms<'_>,
    vh: &[f64],
    uh: &[f64],
    n: usize,
    c: usize,
    x: &BlockInputs<'_>,
    out: [&mut [f64]; 2],
) {
    let [rhs, q] = out;
    mul_into(q, t.c, false, vh, false, n, n, c);
    set_scaled(rhs, -1.0, q);
    mul_into(q, t.k, false, uh, false, n, n, c);
    add_scaled_flat(rhs, -1.0, q);
    solve_flat(x.lu, x.perm, rhs, c, q);
}

impl<const N: usize, const S: usize, const I: usize> StateSpace<N, S, I> {
    /// A model with every matrix zero (filled by the builders).
    const fn zero(h: f64) -> Self {
        Self {
            phi: [[0.0; S]; S],
            gamma0: [[0.0; I]; S],
            gamma1: [[0.0; I]; S],
            dof_u: [[0.0; S]; N],
            dof_v: [[0.0; S]; N],
            dof_a: [[0.0; S]; N],
            dof_a_input: [[0.0; I]; N],
            time_step: h,
        }
    }

    /// The full-state form of [`Linear`](crate::Linear) / [`LinearInput`](crate::LinearInput)
    /// (the AEM) for `M u'' + C u' + K u = B w(t)`, `x = [u; v]`, `S = 2N` (`const fn`; see
    /// the module docs for the derivation). `M, C, K` are `N×N`, `B` is `N×I`, row-major
    /// `f64`; `h` in s. The same data as the steppers' `from_rows_f32`/`_f64`. The same numbers, bit
    /// for bit, as [`StateSpace::from_rows_newmark`] with β = 1/4, γ = 1/2.
    ///
    /// **Matrices are row-major** (`m[i][j]`: row `i`, column `j`; [`Rows`](crate::models::Rows)); to pass
    /// nalgebra data use [`models::rows_of`](crate::models::rows_of), and to convert these
    /// arrays to nalgebra use [`models::matrix_of`](crate::models::matrix_of), not `SMatrix::from`,
    /// which reads columns.
    ///
    /// Errors: [`Error::StateSizeMismatch`] (`S ≠ 2N`), [`Error::NonFiniteInput`],
    /// [`Error::InvalidTimeStep`], [`Error::SingularEffectiveMatrix`],
    /// [`Error::SingularMass`] (the state-space form needs `a = M⁻¹(…)`),
    /// [`Error::OperatorOverflow`].
    ///
    /// Cost: about `12N³ + 4N²·I` `f64` flops and a few `N×N` temporaries on the stack.
    pub const fn from_rows_aem(
        m: Rows<N>,
        c: Rows<N>,
        k: Rows<N>,
        b: [[f64; I]; N],
        h: f64,
    ) -> Result<Self, Error> {
        Self::from_rows_newmark(m, c, k, b, h, 0.25, 0.5)
    }

    mck_fn! {
        /// [`StateSpace::from_rows_aem`] from `nalgebra` matrices (run time; same numbers).
        ///
        /// Errors and cost: as [`StateSpace::from_rows_aem`].
        pub fn aem(m, c, k, b: &SMatrix<f64, N, I>, h: f64) {
            Self::from_rows_aem(rows_f64(m), rows_f64(c), rows_f64(k), rows_f64(b), h)
        }
    }

    /// The full-state form of [`Newmark`](crate::Newmark) with parameters `beta` (β ≥ 0) and
    /// `gamma` (γ ≥ 0) for `M u'' + C u' + K u = B w(t)`, `x = [u; v]`, `S = 2N`
    /// (`const fn`; derivation in the module docs). `M, C, K` are `N×N`, `B` is `N×I`,
    /// row-major `f64`; `h` in s. Reproduces the stepper driven with `p_n = B w_n` from
    /// any state whose acceleration satisfies the equation of motion — its start
    /// (`Stepper::start`) and every state after a step.
    ///
    /// **Matrices are row-major** (`m[i][j]`: row `i`, column `j`; [`Rows`](crate::models::Rows)); to pass
    /// nalgebra data use [`models::rows_of`](crate::models::rows_of), and to convert these
    /// arrays to nalgebra use [`models::matrix_of`](crate::models::matrix_of), not `SMatrix::from`,
    /// which reads columns.
    ///
    /// Errors: [`Error::StateSizeMismatch`] (`S ≠ 2N`), [`Error::NonFiniteInput`] (also for
    /// `B`), then those of [`Newmark::new`](crate::Newmark::new) for the same data, in its
    /// order ([`Error::InvalidTimeStep`], [`Error::InvalidParameter`],
    /// [`Error::SingularEffectiveMatrix`], [`Error::OperatorOverflow`]), and
    /// [`Error::SingularMass`] (the state-space form needs `a = M⁻¹(…)`).
    ///
    /// Cost: about `12N³ + 4N²·I` `f64` flops and a few `N×N` temporaries on the stack.
    pub const fn from_rows_newmark(
        m: Rows<N>,
        c: Rows<N>,
        k: Rows<N>,
        b: [[f64; I]; N],
        h: f64,
        beta: f64,
        gamma: f64,
    ) -> Result<Self, Error> {
        if S != 2 * N {
            return Err(Error::StateSizeMismatch);
        }
        let bl = match newmark_blocks(&m, &c, &k, &b, h, beta, gamma) {
            Ok(bl) => bl,
            Err(e) => return Err(e),
        };
        let phi = [[&bl.uu, &bl.uv], [&bl.vu, &bl.vv]];
        let ss = Self::from_uv_blocks(h, phi, [&bl.u0, &bl.v0], [&bl.u1, &bl.v1]);
        ss.full_outputs(&bl.au, &bl.av, bl.aw)
    }

    mck_fn! {
        /// [`StateSpace::from_rows_newmark`] from `nalgebra` matrices (run time; same numbers).
        ///
        /// Errors and cost: as [`StateSpace::from_rows_newmark`].
        #[allow(clippy::too_many_arguments)] // the stepper's arguments, plus B
        pub fn newmark(m, c, k, b: &SMatrix<f64, N, I>, h: f64, beta: f64, gamma: f64) {
            Self::from_rows_newmark(
                rows_f64(m),
                rows_f64(c),
                rows_f64(k),
                rows_f64(b),
                h,
                beta,
                gamma,
            )
        }
    }

    /// The form of [`GeneralizedAlpha`](crate::GeneralizedAlpha) (and HHT-α) with
    /// parameters `params` for `M u'' + C u' + K u = B w(t)`: `x = [u; v; a]`, `S = 3N`,
    /// where `a` is the scheme's own acceleration variable, which does not satisfy the
    /// equation of motion (`const fn`; derivation in the module docs). `M, C, K` are `N×N`,
    /// `B` is `N×I`, row-major `f64`; `h` in s. Reproduces
    /// [`Stepper::step_with_previous_input`](crate::Stepper::step_with_previous_input)
    /// with `p_{n−1} = B w_{n−1}`, `p_n = B w_n` (the textbook scheme: the load at
    /// `t_{n−α_f}`, so `Γ₀ ≠ 0`). The stepper's `step(p)` takes `p_{n−1} = p_n`: its form
    /// has `Γ₀ + Γ₁` in place of `Γ₁` and no `Γ₀`. Start from
    /// [`StateSpace::initial_state`], what the stepper's `start` computes.
    ///
    /// **Matrices are row-major** (`m[i][j]`: row `i`, column `j`; [`Rows`](crate::models::Rows)); to pass
    /// nalgebra data use [`models::rows_of`](crate::models::rows_of), and to convert these
    /// arrays to nalgebra use [`models::matrix_of`](crate::models::matrix_of), not `SMatrix::from`,
    /// which reads columns.
    ///
    /// Outputs: the acceleration map `a = A_x x + A_w w` ([`StateSpace::outputs`]) is the
    /// *physical* acceleration `M⁻¹ (B w − C v − K u)`, what an accelerometer measures (the
    /// columns of the `a` block of `A_x` are zero). The scheme's acceleration variable is
    /// the last `N` entries of `x`; read it with `H = [0 0 Y]` written by hand.
    ///
    /// Errors: [`Error::StateSizeMismatch`] (`S ≠ 3N`), [`Error::NonFiniteInput`] (also for
    /// `B`), then those of
    /// [`GeneralizedAlpha::with_parameters`](crate::GeneralizedAlpha::with_parameters) for
    /// the same data, in its order ([`Error::InvalidTimeStep`],
    /// [`Error::InvalidParameter`], [`Error::SingularEffectiveMatrix`],
    /// [`Error::OperatorOverflow`]), and [`Error::SingularMass`] (the acceleration output
    /// and the start need `M⁻¹`).
    ///
    /// Cost: about `14N³ + 4N²·I` `f64` flops and a few `N×N` temporaries on the stack.
    pub const fn from_rows_generalized_alpha(
        m: Rows<N>,
        c: Rows<N>,
        k: Rows<N>,
        b: [[f64; I]; N],
        h: f64,
        params: AlphaParameters,
    ) -> Result<Self, Error> {
        if let Err(e) = Self::check_input(3 * N, &b) {
            return Err(e);
        }
        let op = match alpha_operators(&m, &c, &k, h, &params, f64::MAX) {
            Ok(op) => op,
            Err(e) => return Err(e),
        };
        let (lu_m, st) = match op.start {
            Some(s) => s,
            None => return Err(Error::SingularMass),
        };
        let kin = op.kin;
        let id: Mat<N, N> = identity();
        // The new acceleration: a_n = −GK u + A_v v + A_a a + G p̄, p̄ = α_f B w_{n−1} +
        // (1 − α_f) B w_n (G B by a solve).
        let au = scaled(-1.0, &op.gk);
        let gb = op.lu.solve(&b);
        let a0 = scaled(params.alpha_f, &gb);
        let a1 = scaled(1.0 - params.alpha_f, &gb);
        // Predictor: v̂ = v + c_v a, û = u + h v̂ − c_u a (blocks on (u, v, a)).
        let vh_a = scaled(kin.c_v, &id);
        let uh_v = scaled(kin.h, &id);
        let uh_a = axpy(&scaled(kin.h, &vh_a), -kin.c_u, &id);
        // Corrector: u_n = û + β h² a_n, v_n = v̂ + γ h a_n.
        let (bh2, gh) = (kin.beta_h2, kin.gamma_h);
        let mut ss = Self::zero(h);
        put(&mut ss.phi, &axpy(&id, bh2, &au), 0, 0);
        put(&mut ss.phi, &axpy(&uh_v, bh2, &op.av), 0, N);
        put(&mut ss.phi, &axpy(&uh_a, bh2, &op.aa), 0, 2 * N);
        put(&mut ss.phi, &scaled(gh, &au), N, 0);
        put(&mut ss.phi, &axpy(&id, gh, &op.av), N, N);
        put(&mut ss.phi, &axpy(&vh_a, gh, &op.aa), N, 2 * N);
        put(&mut ss.phi, &au, 2 * N, 0);
        put(&mut ss.phi, &op.av, 2 * N, N);
        put(&mut ss.phi, &op.aa, 2 * N, 2 * N);
        put(&mut ss.gamma0, &scaled(bh2, &a0), 0, 0);
        put(&mut ss.gamma0, &scaled(gh, &a0), N, 0);
        put(&mut ss.gamma0, &a0, 2 * N, 0);
        put(&mut ss.gamma1, &scaled(bh2, &a1), 0, 0);
        put(&mut ss.gamma1, &scaled(gh, &a1), N, 0);
        put(&mut ss.gamma1, &a1, 2 * N, 0);
        ss.physical_outputs(&lu_m, &st, &b)
    }

    mck_fn! {
        /// [`StateSpace::from_rows_generalized_alpha`] from `nalgebra` matrices (run time; same
        /// numbers). `params` from [`AlphaParameters::chung_hulbert`] (the
        /// [`GeneralizedAlpha::new`](crate::GeneralizedAlpha::new) of `ρ∞`),
        /// [`AlphaParameters::hht`] or written out.
        ///
        /// ```
        /// use aemstep::observer::StateSpace;
        /// use aemstep::{matrix, vector};
        /// use aemstep::{AlphaParameters, GeneralizedAlpha, Stepper};
        /// let (m, c, k, b, h) = (matrix![2.0], matrix![0.3], matrix![50.0], matrix![1.0], 0.01);
        /// let p = AlphaParameters::chung_hulbert(0.8)?;
        /// let ss = StateSpace::<1, 3, 1>::generalized_alpha(&m, &c, &k, &b, h, p)?;
        /// let sys = GeneralizedAlpha::<f64, 1>::with_parameters(&m, &c, &k, h, p)?;
        /// // x = [u; v; a] with the stepper's start-up acceleration.
        /// let (u0, v0, w0, w1) = (vector![0.1], vector![0.0], vector![1.0], vector![2.0]);
        /// let mut x = ss.initial_state(&u0, &v0, &w0)?;
        /// let mut s = sys.start(&u0, &v0, &(b * w0))?;
        /// assert!((x[2] - s.a()[0]).abs() <= 1e-14); // a0 = −2 m/s², to rounding
        /// x = ss.phi_matrix() * x + ss.gamma0_matrix() * w0 + ss.gamma1_matrix() * w1;
        /// sys.step_with_previous_input(&mut s, &(b * w0), &(b * w1));
        /// assert!((x[0] - s.u()[0]).abs() <= 1e-15 && (x[2] - s.a()[0]).abs() <= 1e-14);
        /// # Ok::<(), aemstep::Error>(())
        /// ```
        ///
        /// Errors and cost: as [`StateSpace::from_rows_generalized_alpha`].
        pub fn generalized_alpha(m, c, k, b: &SMatrix<f64, N, I>, h: f64, params: AlphaParameters) {
            Self::from_rows_generalized_alpha(
                rows_f64(m),
                rows_f64(c),
                rows_f64(k),
                rows_f64(b),
                h,
                params,
            )
        }
    }

    start_fn! {
        f64;
        /// The state at the start of a full-state model (every builder but the modal one) from
        /// displacements `u0` (m), velocities `v0` (m/s) and input `w0`: `[u0; v0]`, and for
        /// [`StateSpace::generalized_alpha`] (`S = 3N`) `[u0; v0; a0]` with
        /// `a0 = M⁻¹ (B w0 − C v0 − K u0)` — what the steppers' `start` computes. For a modal
        /// model use [`StateSpace::modal_coordinates`].
        ///
        /// Errors: [`Error::NonFiniteInput`]; [`Error::StateSizeMismatch`] for a model whose
        /// state does not begin with `[u; v]` (a modal model, `U ≠ [I 0 …]`).
        ///
        /// Cost: `N·(S + I)` flops and a scan of `U`, `V`.
        pub fn initial_state(&self, u0, v0, w0: &SVector<f64, I>) -> SVector<f64, S> {
            if !u0
                .iter()
                .chain(v0.iter())
                .chain(w0.iter())
                .all(|x| x.is_finite())
            {
                return Err(Error::NonFiniteInput);
            }
            let one = |c: bool| if c { 1.0 } else { 0.0 };
            let full = (0..N).all(|i| {
                (0..S).all(|j| self.dof_u[i][j] == one(j == i) && self.dof_v[i][j] == one(j == N + i))
            });
            if !full {
                return Err(Error::StateSizeMismatch);
            }
            let mut x = SVector::<f64, S>::zeros();
            for i in 0..N {
                x[i] = u0[i];
                x[N + i] = v0[i];
            }
            if S == 3 * N {
                // a0 = A_x x + A_w w0 (the a-block of A_x is zero, and so is that of x).
                for i in 0..N {
                    let mut a = 0.0;
                    for j in 0..S {
                        a += self.dof_a[i][j] * x[j];
                    }
                    for j in 0..I {
                        a += self.dof_a_input[i][j] * w0[j];
                    }
                    x[2 * N + i] = a;
                }
            }
            Ok(x)
        }
    }

    mck_fn! {
        /// The full-state form of [`Exact`] (matrix exponential, load `p = B w` linear over
        /// the step): `Φ` and the first-order-hold `Γ₀ = (Γ₁ᵉ − Γ₂ᵉ/h) B`, `Γ₁ = (Γ₂ᵉ/h) B` of
        /// the exponential, `x = [u; v]`, `S = 2N`; reproduces
        /// [`Stepper::step_with_previous_input`](crate::Stepper::step_with_previous_input) of
        /// [`Exact`] to rounding. Run time only.
        ///
        /// Errors: [`Error::StateSizeMismatch`], those of [`Exact::new`], and
        /// [`Error::NonFiniteInput`] for `B`.
        ///
        /// Cost: that of [`Exact::new`] plus `4N²·I` flops.
        pub fn exact(m, c, k, b: &SMatrix<f64, N, I>, h: f64) {
            let bb = rows_f64(b);
            Self::check_input(2 * N, &bb)?;
            let ex = Exact::<f64, N>::new(m, c, k, h)?;
            let (mm, cc, kk) = (rows_f64(m), rows_f64(c), rows_f64(k));
            let (lu_m, st) = start_operators(&mm, &cc, &kk, f64::MAX)?.ok_or(Error::SingularMass)?;
            let phi = [[&ex.au[0], &ex.au[1]], [&ex.av[0], &ex.av[1]]];
            let gamma0 = [&mul(&ex.au[2], &bb), &mul(&ex.av[2], &bb)];
            let gamma1 = [&mul(&ex.au[3], &bb), &mul(&ex.av[3], &bb)];
            let ss = Self::from_uv_blocks(h, phi, gamma0, gamma1);
            ss.physical_outputs(&lu_m, &st, &bb)
        }
    }

    mck_fn! {
        /// The zero-order-hold discretization (`x = [u; v]`, `S = 2N`): the input held
        /// constant over each step at its sample from the step's start, as a DAC or a
        /// sample-and-hold drives it and as sampled-data models are written,
        ///
        /// ```text
        /// x_n = Φ x_{n−1} + Γ w_{n−1},   Φ = e^{F h},   Γ = ∫₀ʰ e^{F s} ds · [0; M⁻¹] B,
        /// F = [[0, I], [−M⁻¹K, −M⁻¹C]]
        /// ```
        ///
        /// exactly (no truncation error, only rounding) — so in the two-ended form
        /// `Γ₀ = Γ`, `Γ₁ = 0` (for the filters of [`estimation`](crate::estimation):
        /// `B = Γ`, `D̃ = D`). `Φ` and `Γ` are blocks of the one matrix exponential (Van
        /// Loan) that [`Exact`] reads, so `Φ` is its `Φ` bit for bit and `Γ` its `Γ₁ᵉ B`. The outputs are those of every full-state builder:
        /// `u = U x`, `v = V x`, `a = M⁻¹ (B w − C v − K u)` — the acceleration at `t_n` with
        /// the sample `w_n` that is held from `t_n` on (the right limit at a switch of the
        /// input), so an acceleration output has the direct feedthrough `D = Y_a M⁻¹ B`, the
        /// standard `y_n = H x_n + D w_n` of a sampled system. [`StateSpace::exact`] is the
        /// first-order hold (the input linear between its samples). Run time only.
        ///
        /// ```
        /// use aemstep::observer::StateSpace;
        /// use aemstep::matrix;
        /// // u'' + ω² u = w/m, ω = 5 rad/s, m = 2 kg, h = 0.1 s: Γ = [(1 − cos ωh)/ω²; sin(ωh)/ω] / m.
        /// let (w, h) = (5.0f64, 0.1);
        /// let ss = StateSpace::<1, 2, 1>::zero_order_hold(
        ///     &matrix![2.0], &matrix![0.0], &matrix![2.0 * w * w], &matrix![1.0], h)?;
        /// assert!((ss.phi[0][0] - (w * h).cos()).abs() < 1e-15);
        /// assert!((ss.gamma0[0][0] - (1.0 - (w * h).cos()) / (w * w) / 2.0).abs() < 1e-16);
        /// assert!((ss.gamma0[1][0] - (w * h).sin() / w / 2.0).abs() < 1e-16);
        /// assert_eq!(ss.gamma1, [[0.0], [0.0]]);
        /// # Ok::<(), aemstep::Error>(())
        /// ```
        ///
        /// Errors: [`Error::StateSizeMismatch`] (`S ≠ 2N`), [`Error::NonFiniteInput`] (`M`,
        /// `C`, `K` or `B`), [`Error::InvalidTimeStep`], [`Error::SingularMass`],
        /// [`Error::OperatorOverflow`].
        ///
        /// Cost: about `(4N)³ (19 + s)` `f64` flops (`s` squarings, as [`Exact::new`]) plus
        /// `4N²·I`, and three `16N²` `f64` temporaries on the stack.
        pub fn zero_order_hold(m, c, k, b: &SMatrix<f64, N, I>, h: f64) {
            let bb = rows_f64(b);
            Self::check_input(2 * N, &bb)?;
            // Φ and Γ₁ᵉ = ∫₀ʰ e^{F s} ds [0; M⁻¹] of the exponential `Exact` reads.
            let Exponential {
                h: hf,
                lu_m,
                start: st,
                blocks: [[phi_uu, phi_uv, gu, _], [phi_vu, phi_vv, gv, _]],
                ..
            } = exponential(m, c, k, h, f64::MAX)?;
            let phi = [[&phi_uu, &phi_uv], [&phi_vu, &phi_vv]];
            let gamma0 = [&mul(&gu, &bb), &mul(&gv, &bb)];
            let zero = [[0.0; I]; N];
            let ss = Self::from_uv_blocks(hf, phi, gamma0, [&zero, &zero]);
            ss.physical_outputs(&lu_m, &st, &bb)
        }
    }

    /// The form of [`Modal`](crate::Modal) keeping the modes `modes` (indices in ascending
    /// frequency, `R` of them, `S = 2R`): `x = [η; η']`, each mode the scalar AEM of
    /// `η'' + 2ξω η' + ω² η = Γ w`, so each of the four `R×R` blocks of `Φ` is diagonal
    /// (`const fn`). Same data and checks as `Modal::from_rows_with_modes_f64`; `U = [Φ_R 0]`,
    /// `V = [0 Φ_R]`, `A_x = [−Φ_R ω², −Φ_R 2ξω]`, `A_w = Φ_R Γ`.
    ///
    /// **Matrices are row-major** (`m[i][j]`: row `i`, column `j`; [`Rows`](crate::models::Rows)); to pass
    /// nalgebra data use [`models::rows_of`](crate::models::rows_of), and to convert these
    /// arrays to nalgebra use [`models::matrix_of`](crate::models::matrix_of), not `SMatrix::from`,
    /// which reads columns.
    ///
    /// Errors: [`Error::StateSizeMismatch`] (`S ≠ 2R`) and those of
    /// [`Modal::new`](crate::Modal::new).
    ///
    /// Cost: that of the modal build (`O(N³)`) plus `O(R·(N + I))`.
    pub const fn from_rows_modal<const R: usize>(
        m: Rows<N>,
        k: Rows<N>,
        damping: Damping<N>,
        b: [[f64; I]; N],
        modes: [usize; R],
        h: f64,
    ) -> Result<Self, Error> {
        if S != 2 * R {
            return Err(Error::StateSizeMismatch);
        }
        let op = match modal_operators::<N, R, I, 0>(&m, &k, &damping, &b, &[], &modes, h, f64::MAX)
        {
            Ok(op) => op,
            Err(e) => return Err(e),
        };
        let mut ss = Self::zero(h);
        let mut r = 0;
        while r < R {
            let bl = match newmark_blocks::<1, I>(
                &[[1.0]],
                &[[op.c[r]]],
                &[[op.k[r]]],
                &[op.gamma[r]],
                h,
                0.25,
                0.5,
            ) {
                Ok(bl) => bl,
                Err(e) => return Err(e),
            };
            ss.phi[r][r] = bl.uu[0][0];
            ss.phi[r][R + r] = bl.uv[0][0];
            ss.phi[R + r][r] = bl.vu[0][0];
            ss.phi[R + r][R + r] = bl.vv[0][0];
            ss.gamma0[r] = bl.u0[0];
            ss.gamma0[R + r] = bl.v0[0];
            ss.gamma1[r] = bl.u1[0];
            ss.gamma1[R + r] = bl.v1[0];
            let mut i = 0;
            while i < N {
                let p = op.phi[i][r];
                ss.dof_u[i][r] = p;
                ss.dof_v[i][R + r] = p;
                ss.dof_a[i][r] = -p * op.k[r];
                ss.dof_a[i][R + r] = -p * op.c[r];
                let mut j = 0;
                while j < I {
                    ss.dof_a_input[i][j] += p * op.gamma[r][j];
                    j += 1;
                }
                i += 1;
            }
            r += 1;
        }
        if ss.all_finite() {
            Ok(ss)
        } else {
            Err(Error::OperatorOverflow)
        }
    }

    /// [`StateSpace::from_rows_modal`] with the `R` lowest modes, from `nalgebra`
    /// matrices (run time; same numbers).
    ///
    /// Errors and cost: as [`StateSpace::from_rows_modal`].
    pub fn modal<const R: usize>(
        m: &SMatrix<f64, N, N>,
        k: &SMatrix<f64, N, N>,
        damping: &Damping<N>,
        b: &SMatrix<f64, N, I>,
        h: f64,
    ) -> Result<Self, Error> {
        Self::from_rows_modal::<R>(
            rows_f64(m),
            rows_f64(k),
            *damping,
            rows_f64(b),
            lowest_modes(),
            h,
        )
    }

    /// The modal coordinates `[η; η']` of a full state `(u, v)`, `η = Φ_Rᵀ M u` (exact when
    /// `u` lies in the span of the kept modes), for a model from
    /// [`StateSpace::from_rows_modal`]. `m` is the mass matrix it was built with.
    ///
    /// Cost: `2N²` + `2N·R` flops.
    pub fn modal_coordinates(
        &self,
        m: &SMatrix<f64, N, N>,
        u: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> SVector<f64, S> {
        // Φ_Rᵀ = the rows of U (u = Φ_R η): η = (U-block)ᵀ M u.
        let (mu, mv) = (m * u, m * v);
        SMatrix::from_fn(|s, _| {
            let mut e = 0.0;
            for i in 0..N {
                e += self.dof_u[i][s] * mu[i] + self.dof_v[i][s] * mv[i];
            }
            e
        })
    }

    /// Check a full-state builder's shape (`S` must be `states`) and its `B`
    /// ([`Error::StateSizeMismatch`], then [`Error::NonFiniteInput`]). Cost: a scan of `B`.
    const fn check_input(states: usize, b: &Mat<N, I>) -> Result<(), Error> {
        if S != states {
            return Err(Error::StateSizeMismatch);
        }
        if !all_finite(b) {
            return Err(Error::NonFiniteInput);
        }
        Ok(())
    }

    /// A full-state model `x = [u; v]` with step `h` (s) from its `N×N` blocks
    /// `phi = [[Φ_uu, Φ_uv], [Φ_vu, Φ_vv]]` and the `N×I` blocks `[u; v]` of `Γ₀`, `Γ₁`
    /// (the outputs still zero). Cost: copies.
    const fn from_uv_blocks(
        h: f64,
        phi: [[&Mat<N, N>; 2]; 2],
        gamma0: [&Mat<N, I>; 2],
        gamma1: [&Mat<N, I>; 2],
    ) -> Self {
        let mut ss = Self::zero(h);
        put(&mut ss.phi, phi[0][0], 0, 0);
        put(&mut ss.phi, phi[0][1], 0, N);
        put(&mut ss.phi, phi[1][0], N, 0);
        put(&mut ss.phi, phi[1][1], N, N);
        put(&mut ss.gamma0, gamma0[0], 0, 0);
        put(&mut ss.gamma0, gamma0[1], N, 0);
        put(&mut ss.gamma1, gamma1[0], 0, 0);
        put(&mut ss.gamma1, gamma1[1], N, 0);
        ss
    }

    /// [`Self::full_outputs`] with the physical acceleration `M⁻¹ (B w − C v − K u)` from the
    /// factorization `lu_m` of `M` and the start-up operators `st` (`M⁻¹K`, `M⁻¹C`).
    const fn physical_outputs(
        self,
        lu_m: &Lu<N>,
        st: &StartOps<f64, N>,
        b: &Mat<N, I>,
    ) -> Result<Self, Error> {
        let (au, av) = (scaled(-1.0, &st.minv_k), scaled(-1.0, &st.minv_c));
        self.full_outputs(&au, &av, lu_m.solve(b))
    }

    /// The output maps of a full-state model (`u`, `v` the first `2N` states;
    /// `a = A_u u + A_v v + A_w w`), then the check that every matrix is finite
    /// ([`Error::OperatorOverflow`] if not).
    const fn full_outputs(
        mut self,
        au: &Mat<N, N>,
        av: &Mat<N, N>,
        aw: [[f64; I]; N],
    ) -> Result<Self, Error> {
        let id: Mat<N, N> = identity();
        put(&mut self.dof_u, &id, 0, 0);
        put(&mut self.dof_v, &id, 0, N);
        put(&mut self.dof_a, au, 0, 0);
        put(&mut self.dof_a, av, 0, N);
        self.dof_a_input = aw;
        if self.all_finite() {
            Ok(self)
        } else {
            Err(Error::OperatorOverflow)
        }
    }

    /// Every entry of every matrix is finite.
    const fn all_finite(&self) -> bool {
        all_finite(&self.phi)
            && all_finite(&self.gamma0)
            && all_finite(&self.gamma1)
            && all_finite(&self.dof_u)
            && all_finite(&self.dof_v)
            && all_finite(&self.dof_a)
            && all_finite(&self.dof_a_input)
    }

    /// The output matrices `H = Y_u U + Y_v V + Y_a A_x`, `D = Y_a A_w + Y_w` of `outputs`
    /// (`const fn`).
    ///
    /// Errors: [`Error::NonFiniteInput`] (a non-finite weight). Cost: `3O·N·S + O·N·I` flops.
    pub const fn outputs<const O: usize>(
        &self,
        outputs: &Outputs<N, I, O>,
    ) -> Result<Measurement<S, I, O>, Error> {
        let (mut h, mut d) = ([[0.0; S]; O], [[0.0; I]; O]);
        let (mut th, mut td) = ([[0.0; S]; O], [[0.0; I]; O]);
        match outputs_flat(
            [
                outputs.u.as_flattened(),
                outputs.v.as_flattened(),
                outputs.a.as_flattened(),
                outputs.w.as_flattened(),
            ],
            [
                self.dof_u.as_flattened(),
                self.dof_v.as_flattened(),
                self.dof_a.as_flattened(),
                self.dof_a_input.as_flattened(),
            ],
            [N, S, I, O],
            [h.as_flattened_mut(), d.as_flattened_mut()],
            [th.as_flattened_mut(), td.as_flattened_mut()],
        ) {
            Ok(()) => Ok(Measurement { h, d }),
            Err(e) => Err(e),
        }
    }

    /// The process-noise covariance of a white input noise held over each step:
    /// `Q = (Γ₀ + Γ₁) Q_w (Γ₀ + Γ₁)ᵀ` (`S×S`) for an input-noise covariance `Q_w`
    /// (`I×I`, input units squared). For unmodelled forces on every DOF, build the model
    /// with `B = I` (`I = N`) and `Q_w = σ_f² I`. `const fn`; cost `S²·I + S·I²` flops.
    ///
    /// The noise model: the noise input is `η_n` over step `n` (independent from step to
    /// step, `E η ηᵀ = Q_w`) at both of its ends, so the step adds `q_n = (Γ₀ + Γ₁) η_n`;
    /// a sensor at `t_n` reads the input the step ended with, `D η_n`. Where the outputs
    /// have a feedthrough of the noise input (accelerometers under unmodelled floor
    /// forces) the measurement noise is correlated with `q_n`: give the filters
    /// [`StateSpace::input_cross_noise`] as their cross covariance and add
    /// [`StateSpace::feedthrough_noise`] to `R` ([module docs](super), "Noise that reaches
    /// the sensors", derives it and checks it by simulation).
    pub const fn input_noise(&self, qw: &[[f64; I]; I]) -> [[f64; S]; S] {
        let (mut q, mut g, mut gq) = ([[0.0; S]; S], [[0.0; I]; S], [[0.0; I]; S]);
        input_noise_flat(
            [self.gamma0.as_flattened(), self.gamma1.as_flattened()],
            qw.as_flattened(),
            [S, I],
            q.as_flattened_mut(),
            [g.as_flattened_mut(), gq.as_flattened_mut()],
        );
        q
    }

    /// The feedthrough companion of [`StateSpace::input_noise`]: the cross covariance
    /// `N = E q_n r_nᵀ = (Γ₀ + Γ₁) Q_w Dᵀ` (`S×O`) of the process noise `q_n` with the part
    /// `D η_n` of the measurement noise that the same noise input puts in the sensors
    /// (noise model in [`StateSpace::input_noise`]). `meas` is the sensors' measurement of
    /// *this* (noise-input) model: its `D` maps the noise input to the outputs. For
    /// accelerometers under unmodelled floor forces: `Outputs::accelerations` of the
    /// sensors' DOFs on the model with `B = I` (a known ground input's own terms belong to
    /// the model of the known input). For the filters' `cross` argument
    /// ([`SteadyState::from_parts_cross`](super::SteadyState::from_parts_cross),
    /// [`Kalman::with_cross`](super::Kalman::with_cross)). `const fn`; cost
    /// `S·I² + S·I·O` flops.
    pub const fn input_cross_noise<const O: usize>(
        &self,
        meas: &Measurement<S, I, O>,
        qw: &[[f64; I]; I],
    ) -> [[f64; O]; S] {
        let gq = mul(&add_scaled(&self.gamma0, 1.0, &self.gamma1), qw);
        mul(&gq, &transpose(&meas.d))
    }

    /// The measurement noise `D Q_w Dᵀ` (`O×O`, output units squared) that a white input
    /// noise of covariance `Q_w` puts in the sensors through the feedthrough `D` of `meas`
    /// (the noise-input model's measurement, as in [`StateSpace::input_cross_noise`]): add
    /// it to the sensors' own noise to form `R`. `const fn`; cost `O·I² + O²·I` flops.
    pub const fn feedthrough_noise<const O: usize>(
        &self,
        meas: &Measurement<S, I, O>,
        qw: &[[f64; I]; I],
    ) -> [[f64; O]; O] {
        mul(&mul(&meas.d, qw), &transpose(&meas.d))
    }

    /// `Φ` as a `nalgebra` matrix.
    pub fn phi_matrix(&self) -> SMatrix<f64, S, S> {
        crate::linalg::matrix_t(&self.phi)
    }
    /// `Γ₀` as a `nalgebra` matrix.
    pub fn gamma0_matrix(&self) -> SMatrix<f64, S, I> {
        crate::linalg::matrix_t(&self.gamma0)
    }
    /// `Γ₁` as a `nalgebra` matrix.
    pub fn gamma1_matrix(&self) -> SMatrix<f64, S, I> {
        crate::linalg::matrix_t(&self.gamma1)
    }
}

/// A model with no known input, `x_n = Φ x_{n−1}`, `y_n = H x_n` (`S` states, `O`
/// outputs, time step `h` in s), for [`SteadyState`](crate::observer::SteadyState): a stage
/// of the dual filter, the augmented model, the regulator's dual problem
/// ([`control::Lqr`](crate::control::Lqr)). Cost: a copy.
pub(crate) const fn bare_model<const S: usize, const O: usize>(
    phi: [[f64; S]; S],
    h: [[f64; S]; O],
    time_step: f64,
) -> (StateSpace<0, S, 0>, Measurement<S, 0, O>) {
    let model = StateSpace::<0, S, 0> {
        phi,
        gamma0: [[0.0; 0]; S],
        gamma1: [[0.0; 0]; S],
        dof_u: [],
        dof_v: [],
        dof_a: [],
        dof_a_input: [],
        time_step,
    };
    (
        model,
        Measurement {
            h,
            d: [[0.0; 0]; O],
        },
    )
}

/// Factorize a matrix for a solve, each row judged against its own size (`None` if
/// singular to working precision).
pub(crate) const fn lu_of<const N: usize>(a: &Mat<N, N>) -> Option<Lu<N>> {
    Lu::new(a, &row_scales(a))
}

/// `H = Y_u U + Y_v V + Y_a A_x`, `D = Y_w + Y_a A_w` on flat slices (`y = [Y_u, Y_v, Y_a,
/// Y_w]`, `maps = [U, V, A_x, A_w]`, `dims = [N, S, I, O]`; `out = [H, D]`, `tmp` the same
/// shapes): the one output build of [`StateSpace::outputs`] and the run-time-sized
/// [`DynStateSpace::outputs`](super::DynStateSpace::outputs). Errors:
/// [`Error::NonFiniteInput`] (a weight), [`Error::OperatorOverflow`].
pub(crate) const fn outputs_flat(
    y: [&[f64]; 4],
    maps: [&[f64]; 4],
    dims: [usize; 4],
    out: [&mut [f64]; 2],
    tmp: [&mut [f64]; 2],
) -> Result<(), Error> {
    let [yu, yv, ya, yw] = y;
    let [mu, mv, ma, mw] = maps;
    let [n, s, i, o] = dims;
    let [h, d] = out;
    let [th, td] = tmp;
    if !(all_finite_flat(yu) && all_finite_flat(yv) && all_finite_flat(ya) && all_finite_flat(yw)) {
        return Err(Error::NonFiniteInput);
    }
    mul_into(h, yu, false, mu, false, o, n, s);
    mul_into(th, yv, false, mv, false, o, n, s);
    add_scaled_flat(h, 1.0, th);
    mul_into(th, ya, false, ma, false, o, n, s);
    add_scaled_flat(h, 1.0, th);
    copy_flat(d, yw);
    mul_into(td, ya, false, mw, false, o, n, i);
    add_scaled_flat(d, 1.0, td);
    if all_finite_flat(h) && all_finite_flat(d) {
        Ok(())
    } else {
        Err(Error::OperatorOverflow)
    }
}

/// `Q = (Γ₀ + Γ₁) Q_w (Γ₀ + Γ₁)ᵀ` on flat slices (`gamma = [Γ₀, Γ₁]`, `dims = [S, I]`;
/// `tmp`: two `S×I`): the one arithmetic of [`StateSpace::input_noise`] and the
/// run-time-sized [`DynStateSpace::input_noise`](super::DynStateSpace::input_noise).
pub(crate) const fn input_noise_flat(
    gamma: [&[f64]; 2],
    qw: &[f64],
    dims: [usize; 2],
    q: &mut [f64],
    tmp: [&mut [f64]; 2],
) {
    let [s, i] = dims;
    let [g, gq] = tmp;
    copy_flat(g, gamma[0]);
    add_scaled_flat(g, 1.0, gamma[1]);
    mul_into(gq, g, false, qw, false, s, i, i);
    mul_into(q, gq, false, g, true, s, i, s);
}
