//! The linear AEM kernel: `M u'' + C u' + K u = p(t)` with constant `M, C, K`.
//!
//! With `q = u''` taken as the mean of its end values on each step (paper §2, eqs. 19–23)
//! and the equation of motion enforced at `t_n`, eliminating `v_n, u_n` gives
//!
//! ```text
//! v̂ = v_{n−1} + (h/2) q_{n−1}             û = u_{n−1} + h v_{n−1} + (h²/4) q_{n−1}
//! q_n = G p_n − (G C) v̂ − (G K) û          G = (M + (h/2) C + (h²/4) K)⁻¹
//! v_n = v̂ + (h/2) q_n                      u_n = û + (h²/4) q_n
//! ```
//!
//! `G`, `GC`, `GK` are computed once, in `f64`, and rounded once to `T`. A step costs
//! `3N²` multiply-adds plus `7N` for the kinematics. The same numbers, in the paper's
//! literal `U_n = A U_{n−1} + b p_n` form, come from [`Linear::a_form`].

use nalgebra::{SMatrix, SVector};

use crate::ops;
use crate::scalar::initial_inputs_finite;
use crate::{AForm, Error, Real, State, Stepper};

/// Operators for the start-up acceleration `q0 = M⁻¹ p0 − (M⁻¹C) v0 − (M⁻¹K) u0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct StartOps<T, const N: usize> {
    pub minv: [[T; N]; N],
    pub minv_c: [[T; N]; N],
    pub minv_k: [[T; N]; N],
}

/// The linear constant-coefficient AEM stepper (paper Algorithm 1, eliminated form).
///
/// `T` is `f32` or `f64`; `N` the number of degrees of freedom. Build it once with
/// [`Linear::new`] (run time, from `nalgebra` matrices) or [`Linear::from_rows`]
/// (`const fn`, from row-major arrays: operators computed by the compiler into flash);
/// then [`Stepper::start`] and [`Stepper::step`].
///
/// Size: `6N² + 3` values of `T` (`3N²` for stepping, `3N²` for start-up).
///
/// ```
/// use aemstep::{Linear, Stepper};
/// use nalgebra::{matrix, vector};
///
/// // u'' + 25 u = 0 (paper Example 1), h = 0.01 s
/// let sys = Linear::new(&matrix![1.0], &matrix![0.0], &matrix![25.0], 0.01)?;
/// let mut s = sys.start(&vector![1.0], &vector![0.0], &vector![0.0])?;
/// for _ in 0..100 {
///     sys.step(&mut s, &vector![0.0]);
/// }
/// assert!((s.u()[0] - 5.0f64.cos()).abs() < 2e-3); // t = 1 s, O(h²) phase error
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
// `repr(C)` with `ops` first: the step addresses every operator value as a small
// immediate offset from `self` (Thumb-2 `vldr` reaches ±1020 bytes).
#[repr(C)]
pub struct Linear<T, const N: usize> {
    /// The step operators, interleaved by row so that row `i` of all three is one
    /// contiguous run of `3N` values: `ops[i] = [G[i], −(GC)[i], −(GK)[i]]`
    /// (`G = M_eff⁻¹`). `q_i` is then a single multiply-accumulate chain over that run
    /// (negation is exact, so the values are those of `G`, `GC`, `GK`).
    ops: [[[T; N]; 3]; N],
    h: T,
    half_h: T,
    quarter_h2: T,
    start: Option<StartOps<T, N>>,
}

/// `SMatrix` (column-major) to a row-major `f64` array (exact).
pub(crate) fn rows_f64<T: Real, const R: usize, const C: usize>(
    a: &SMatrix<T, R, C>,
) -> [[f64; C]; R] {
    core::array::from_fn(|i| core::array::from_fn(|j| a[(i, j)].as_f64()))
}

/// Round a row-major `f64` array once to `T`.
pub(crate) fn round_rows<T: Real, const R: usize, const C: usize>(
    a: &[[f64; C]; R],
) -> [[T; C]; R] {
    a.map(|row| row.map(T::from_f64_rounded))
}

/// `[G[i], −GC[i], −GK[i]]` for every row `i` (the storage of [`Linear`]).
pub(crate) fn interleave<T: Real, const N: usize>(
    g: &[[T; N]; N],
    gc: &[[T; N]; N],
    gk: &[[T; N]; N],
) -> [[[T; N]; 3]; N] {
    core::array::from_fn(|i| [g[i], gc[i].map(|x| -x), gk[i].map(|x| -x)])
}

/// `y = A x` for a row-major `A`.
#[inline(always)]
pub(crate) fn mat_vec<T: Real, const N: usize>(
    a: &[[T; N]; N],
    x: &SVector<T, N>,
) -> SVector<T, N> {
    SVector::from_fn(|i, _| {
        let mut s = T::zero();
        for j in 0..N {
            s += a[i][j] * x[j];
        }
        s
    })
}

impl<T: Real, const N: usize> Linear<T, N> {
    /// Precompute the step operators for `M u'' + C u' + K u = p(t)` with step `h` (s).
    ///
    /// `M, C, K` are `N×N`, fully populated, not necessarily symmetric. `M` may be
    /// singular as long as `M + (h/2) C + (h²/4) K` is not (then start with
    /// [`Stepper::start_with_acceleration`]). Computed in `f64`, rounded once to `T`.
    ///
    /// Errors: [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`] (`h ≤ 0` or not
    /// finite), [`Error::SingularEffectiveMatrix`].
    ///
    /// Cost: about `5N³` flops in `f64` and four `N×N` `f64` temporaries on the stack.
    pub fn new(
        m: &SMatrix<T, N, N>,
        c: &SMatrix<T, N, N>,
        k: &SMatrix<T, N, N>,
        h: T,
    ) -> Result<Self, Error> {
        let hf = h.as_f64();
        let op = ops::operators(&rows_f64(m), &rows_f64(c), &rows_f64(k), hf)?;
        Ok(Self {
            h,
            half_h: T::from_f64_rounded(0.5 * hf),
            quarter_h2: T::from_f64_rounded(0.25 * hf * hf),
            ops: interleave(&round_rows(&op.g), &round_rows(&op.gc), &round_rows(&op.gk)),
            start: match op.start {
                Some((mi, mc, mk)) => Some(StartOps {
                    minv: round_rows(&mi),
                    minv_c: round_rows(&mc),
                    minv_k: round_rows(&mk),
                }),
                None => None,
            },
        })
    }

    /// `G = (M + (h/2) C + (h²/4) K)⁻¹`.
    pub fn effective_inverse(&self) -> SMatrix<T, N, N> {
        SMatrix::from_fn(|i, j| self.ops[i][0][j])
    }

    /// The paper's literal form `U_n = A U_{n−1} + b p_n` of this stepper (`12N²`
    /// multiply-adds a step): the reference the fast form is tested against, and a way to
    /// inspect the amplification operator. Cost to build: about `6N³` flops in `T`.
    pub fn a_form(&self) -> AForm<T, N> {
        let block = |b: usize, sign: T| self.ops.map(|row| row[b].map(|x| sign * x));
        let one = T::one();
        let (g, gc, gk) = (block(0, one), block(1, -one), block(2, -one));
        AForm::from_operators(self.h, &g, &gc, &gk, self.start)
    }
}

/// Const-fn construction, for operators computed at compile time into flash.
macro_rules! const_ctor {
    ($t:ident) => {
        impl<const N: usize> Linear<$t, N> {
            /// `const fn` twin of [`Linear::new`]: `M, C, K` as row-major `f64` arrays
            /// (`m[i][j]` is row `i`, column `j`), `h` in seconds. Computes in `f64` and
            /// rounds once to the target type, so the result is bit-identical to
            /// [`Linear::new`] given the same values.
            ///
            /// In a `static`, the operators are evaluated by the compiler and no inversion
            /// code is linked in:
            ///
            /// ```
            /// use aemstep::Linear;
            /// static SYS: Linear<f32, 1> = match Linear::<f32, 1>::from_rows(
            ///     [[1.0]], [[0.28]], [[4.0]], 0.002,
            /// ) {
            ///     Ok(s) => s,
            ///     Err(e) => panic!("{}", e.as_str()),
            /// };
            /// assert_eq!(SYS.time_step_const(), 0.002);
            /// ```
            ///
            /// Errors: as [`Linear::new`].
            pub const fn from_rows(
                m: [[f64; N]; N],
                c: [[f64; N]; N],
                k: [[f64; N]; N],
                h: f64,
            ) -> Result<Self, Error> {
                let op = match ops::operators(&m, &c, &k, h) {
                    Ok(op) => op,
                    Err(e) => return Err(e),
                };
                Ok(Self {
                    h: h as $t,
                    half_h: (0.5 * h) as $t,
                    quarter_h2: (0.25 * h * h) as $t,
                    ops: const_ctor!(@interleave $t, op.g, op.gc, op.gk),
                    start: match op.start {
                        Some((mi, mc, mk)) => Some(StartOps {
                            minv: ops::const_round!($t, rows mi),
                            minv_c: ops::const_round!($t, rows mc),
                            minv_k: ops::const_round!($t, rows mk),
                        }),
                        None => None,
                    },
                })
            }

            /// The time step `h` (s), in `const` contexts.
            pub const fn time_step_const(&self) -> $t {
                self.h
            }
        }
    };
    (@interleave $t:ident, $g:expr, $gc:expr, $gk:expr) => {{
        let (g, gc, gk) = ($g, $gc, $gk);
        let mut r = [[[0.0 as $t; N]; 3]; N];
        let mut i = 0;
        while i < N {
            let mut j = 0;
            while j < N {
                r[i][0][j] = g[i][j] as $t;
                r[i][1][j] = -(gc[i][j] as $t);
                r[i][2][j] = -(gk[i][j] as $t);
                j += 1;
            }
            i += 1;
        }
        r
    }};
}
const_ctor!(f32);
const_ctor!(f64);

impl<T: Real, const N: usize> Stepper<T, N> for Linear<T, N> {
    #[inline]
    fn time_step(&self) -> T {
        self.h
    }

    fn start(
        &self,
        u0: &SVector<T, N>,
        v0: &SVector<T, N>,
        p0: &SVector<T, N>,
    ) -> Result<State<T, N>, Error> {
        initial_state(self.start.as_ref(), u0, v0, p0)
    }

    /// Cost: `3N²` multiply-adds + `7N` (see the module docs for the recurrence).
    #[inline]
    fn step(&self, s: &mut State<T, N>, p: &SVector<T, N>) {
        let (h, half_h, quarter_h2) = (self.h, self.half_h, self.quarter_h2);
        // β = 1/4, γ = 1/2: (1 − γ) h = γ h = h/2, (β + 1/2 − γ) h² = β h² = h²/4.
        newmark_step(&self.ops, [h, half_h, quarter_h2, half_h, quarter_h2], s, p);
    }
}

/// One step of the Newmark family in eliminated form, shared by [`Linear`]
/// (β = 1/4, γ = 1/2: the AEM) and [`Newmark`](crate::Newmark), over interleaved operator
/// rows `ops[i] = [G[i], −GC[i], −GK[i]]`, `G = (M + γh C + βh² K)⁻¹`.
/// `c = [h, (1 − γ) h, (β + 1/2 − γ) h², γ h, β h²]`:
///
/// ```text
/// v̂ = v + (1 − γ) h a      û = u + h v̂ − (β + 1/2 − γ) h² a   (= u + h v + (1/2 − β) h² a)
/// a ← G p − GC v̂ − GK û    v ← v̂ + γ h a                     u ← û + β h² a
/// ```
///
/// Cost: `3N²` multiply-adds + `7N`; branch-free, panic-free.
#[inline(always)]
pub(crate) fn newmark_step<T: Real, const N: usize>(
    ops: &[[[T; N]; 3]; N],
    c: [T; 5],
    s: &mut State<T, N>,
    p: &SVector<T, N>,
) {
    let [h, c_v, c_u, gamma_h, beta_h2] = c;
    // x = (p, v̂, û): the vector every interleaved operator row multiplies.
    let mut x = [[T::zero(); N]; 3];
    for j in 0..N {
        let (u, v, a) = (s.u[j], s.v[j], s.a[j]);
        x[0][j] = p[j];
        // û from v̂ rather than from v: the same value up to rounding, one operation fewer.
        let vh = v + c_v * a;
        x[1][j] = vh;
        x[2][j] = u + h * vh - c_u * a;
    }
    // q = G p − GC v̂ − GK û, written to `a`. Rows go in blocks of `BLOCK`, so each value
    // of `x` loaded feeds `BLOCK` multiply-adds.
    mat_vec_blocked(ops, &x, s.a.as_mut_slice());
    // v = v̂ + γh q, u = û + βh² q. A separate pass with constant indices (once unrolled),
    // so v̂, û are used straight from registers.
    for j in 0..N {
        let q = s.a[j];
        s.v[j] = x[1][j] + gamma_h * q;
        s.u[j] = x[2][j] + beta_h2 * q;
    }
    s.n = s.n.wrapping_add(1);
}

/// Operator rows processed together by the steps ("block"), chosen per target. Any block
/// shape gives bit-identical results: each row's sum is the same chain of products in the
/// same order (see [`dots`]); blocks only interleave independent chains.
///
/// - Cortex-M (and every non-x86-64 target): 2 rows. On the Cortex-M4F this is what keeps
///   the f32 fast form at or below 3 instructions a multiply-add for N = 6 and 12; 3 or 4
///   rows spill registers at one size or the other.
/// - x86-64: 8 rows. A row's chain is serial (an add every 3-4 cycles), so the host needs
///   many chains in flight; LLVM puts pairs of rows in the lanes of one packed register,
///   so 8 rows are 4 packed chains. 2 rows leave the core waiting on the add latency
///   (measured: 2.2 multiply-adds per ns at N = 100, against 5+ with 8 rows).
#[cfg(not(target_arch = "x86_64"))]
const BLOCK: usize = 2;
#[cfg(target_arch = "x86_64")]
const BLOCK: usize = 8;

/// Columns of each row loaded together in [`dots`] (the products are still added one at a
/// time, in column order). On x86-64, 2: two rows' pairs of columns become one
/// `unpcklpd`/`unpckhpd` pair that puts both rows in the lanes of a packed register. On
/// Cortex-M, 1 (the loop the M4F cost table was measured with).
#[cfg(not(target_arch = "x86_64"))]
const CHUNK: usize = 1;
#[cfg(target_arch = "x86_64")]
const CHUNK: usize = 2;

/// `R` dot products of interleaved operator rows (each `K` blocks of `N`) with `x`: `R`
/// accumulators, so each `x` value is loaded once for `R` multiply-adds. Each sum starts
/// from its first product (no `0 +`), then accumulates block by block, column by column,
/// in order: row `r`'s result is
/// `((rows[r][0][0]·x[0][0] + rows[r][0][1]·x[0][1]) + …) + rows[r][K−1][N−1]·x[K−1][N−1]`
/// whatever `R` and [`CHUNK`] are, so every target computes the same bits.
#[inline(always)]
pub(crate) fn dots<T: Real, const N: usize, const K: usize, const R: usize>(
    rows: &[[[T; N]; K]; R],
    x: &[[T; N]; K],
) -> [T; R] {
    let mut q = [T::zero(); R];
    if N == 0 || K == 0 {
        return q;
    }
    for r in 0..R {
        q[r] = rows[r][0][0] * x[0][0];
    }
    if CHUNK == 1 {
        for b in 0..K {
            let first = if b == 0 { 1 } else { 0 };
            for j in first..N {
                let xj = x[b][j];
                for r in 0..R {
                    q[r] += rows[r][b][j] * xj;
                }
            }
        }
        return q;
    }
    // `CHUNK` columns at a time over each row's whole run of `K·N` values (the same order:
    // block by block, column by column): loaded together, added one after the other.
    let xf = x.as_flattened();
    let rf: [&[T]; R] = core::array::from_fn(|r| rows[r].as_flattened());
    let len = K * N;
    let mut j = 1;
    while j + CHUNK <= len {
        let xs: [T; CHUNK] = core::array::from_fn(|c| xf[j + c]);
        let rs: [[T; CHUNK]; R] = core::array::from_fn(|r| core::array::from_fn(|c| rf[r][j + c]));
        for c in 0..CHUNK {
            for r in 0..R {
                q[r] += rs[r][c] * xs[c];
            }
        }
        j += CHUNK;
    }
    // The last `(K·N − 1) mod CHUNK` columns.
    while j < len {
        for r in 0..R {
            q[r] += rf[r][j] * xf[j];
        }
        j += 1;
    }
    q
}

/// `out = rows · x` for `N` interleaved rows: the first `N mod BLOCK` rows in pairs (and
/// one single row if that is odd), then blocks of [`BLOCK`] rows. (With `BLOCK = 2` that
/// is the remainder row first, then pairs.)
#[inline(always)]
pub(crate) fn mat_vec_blocked<T: Real, const N: usize, const K: usize>(
    rows: &[[[T; N]; K]; N],
    x: &[[T; N]; K],
    out: &mut [T],
) {
    let (rest, blocks) = rows.as_rchunks::<BLOCK>();
    let (out_rest, out_blocks) = out.as_rchunks_mut::<BLOCK>();
    let (single, pairs) = rest.as_rchunks::<2>();
    let (out_single, out_pairs) = out_rest.as_rchunks_mut::<2>();
    for (row, o) in single.iter().zip(out_single) {
        [*o] = dots(core::array::from_ref(row), x);
    }
    for (rows, o) in pairs.iter().zip(out_pairs) {
        *o = dots(rows, x);
    }
    for (rows, o) in blocks.iter().zip(out_blocks) {
        *o = dots(rows, x);
    }
}

/// `q0 = M⁻¹ p0 − (M⁻¹C) v0 − (M⁻¹K) u0` and the state at step 0; `ops` is `None` when
/// `M` is singular ([`Error::SingularMass`]).
pub(crate) fn initial_state<T: Real, const N: usize>(
    ops: Option<&StartOps<T, N>>,
    u0: &SVector<T, N>,
    v0: &SVector<T, N>,
    p0: &SVector<T, N>,
) -> Result<State<T, N>, Error> {
    let ops = ops.ok_or(Error::SingularMass)?;
    if !initial_inputs_finite(u0, v0, p0) {
        return Err(Error::NonFiniteInput);
    }
    let a0 = mat_vec(&ops.minv, p0) - mat_vec(&ops.minv_c, v0) - mat_vec(&ops.minv_k, u0);
    State::initial_computed(u0, v0, a0)
}

#[cfg(test)]
mod block_tests {
    use super::mat_vec_blocked;
    use crate::Real;

    /// Row `i` of `rows · x` as one serial chain, first product first: the order every
    /// block shape must keep.
    fn serial<T: Real, const N: usize, const K: usize>(
        rows: &[[[T; N]; K]; N],
        x: &[[T; N]; K],
    ) -> [T; N] {
        core::array::from_fn(|i| {
            let (r, x) = (rows[i].as_flattened(), x.as_flattened());
            r[1..]
                .iter()
                .zip(&x[1..])
                .fold(r[0] * x[0], |q, (&a, &b)| q + a * b)
        })
    }

    fn check<T: Real, const N: usize>() {
        let mut s = 0x2545_f491_4f6c_dd1d_u64 ^ N as u64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        };
        let mut next = || T::from_f64_rounded(next());
        let rows: [[[T; N]; 3]; N] =
            core::array::from_fn(|_| core::array::from_fn(|_| core::array::from_fn(|_| next())));
        let x: [[T; N]; 3] = core::array::from_fn(|_| core::array::from_fn(|_| next()));
        let mut out = [T::zero(); N];
        mat_vec_blocked(&rows, &x, &mut out);
        let want = serial(&rows, &x);
        for i in 0..N {
            assert_eq!(
                out[i].as_f64().to_bits(),
                want[i].as_f64().to_bits(),
                "N = {N}, row {i}"
            );
        }
    }

    /// Bit-identical to the serial chain for every remainder of every block size (host
    /// and Cortex-M therefore agree bit for bit: same chains, same order).
    #[test]
    fn blocked_rows_sum_in_serial_order() {
        macro_rules! sizes { ($($n:literal)*) => { $( check::<f64, $n>(); check::<f32, $n>(); )* } }
        sizes!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 25 50 99 100);
    }
}
