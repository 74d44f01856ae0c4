//! The observers' build-time arithmetic on flat row-major `f64` slices with explicit
//! dimensions: the one implementation behind the const-generic [`SteadyState`](super::SteadyState)
//! (which calls it with its stack arrays, `as_flattened`) and the run-time-sized
//! [`DynSteadyState`](super::DynSteadyState) (feature `std`, heap buffers). Same checks in
//! the same order, the same arithmetic, so both give bit-identical gains at every size both
//! serve (`tests/runtime_size_observer.rs`).
//!
//! Every function is `const fn` (a `static` observer's gain is still computed by the
//! compiler) and allocation-free: temporaries are scratch slices the caller owns. A matrix
//! `a` of `r×c` is `a[i * c + j]`, row `i`, column `j`.

use crate::Error;
use crate::linalg::lu::{factor, row_scales_flat, solve_flat};
use crate::linalg::{add_scaled_flat, all_finite_flat, copy_flat, max_abs_flat, sqrt};

use super::riccati::{A_SMALL, RICCATI_MAX_ITERATIONS, RICCATI_RESIDUAL_UNITS};

/// Newton refinements of the doubling's solution at most ([`refine`]).
const RICCATI_REFINEMENTS: u32 = 3;

/// A residual at or below this many units (of [`RICCATI_RESIDUAL_UNITS`]'s `(2S + 5) ε`)
/// is not refined: rounding in evaluating it is about one unit.
const RICCATI_RESIDUAL_REFINE: f64 = 4.0;

/// `r = op(a) · op(b)` (`rows×cols`, inner dimension `inner`), `op(a) = aᵀ` when `at`
/// (`a` stored `inner×rows`), `op(b) = bᵀ` when `bt` (`b` stored `cols×inner`): each entry
/// summed from `+0` over `k` ascending, the order of the array product
/// [`linalg::mul`](crate::linalg::mul) of the transposed copies. Cost: `rows·inner·cols`
/// multiply-adds.
///
/// The innermost loops run flat indices over contiguous rows (row `i` of `r`, or row `j`
/// of a stored `bᵀ`) up to an end asserted once per row to lie within the slice, so the
/// compiler drops that row's bounds check; only the other operand's stays (in the fuzz
/// build each bounds check is a traced call, and this product was most of the
/// estimation and control targets' time). Each entry still sees the same additions in the
/// same order (bit for bit, see the test), and the compiler's evaluator (a `static`
/// observer) counts the same loop iterations as for the plain triple loop. No slice is
/// cut: a `split_at` per row is a dozen calls to the evaluator, and cutting the rows so
/// put a `static` observer of 22 states, which the triple loop builds, over its limit.
#[allow(clippy::too_many_arguments)]
pub(crate) const fn mul_into(
    r: &mut [f64],
    a: &[f64],
    at: bool,
    b: &[f64],
    bt: bool,
    rows: usize,
    inner: usize,
    cols: usize,
) {
    // op(a)_ik = a[i·ai + k·ak]; the lengths read once (in the compiler's evaluator each
    // call is a step).
    let (ai, ak) = if at { (1, rows) } else { (inner, 1) };
    let (r_len, b_len) = (r.len(), b.len());
    let mut i = 0;
    while i < rows {
        let (r0, rend) = (i * cols, i * cols + cols);
        assert!(rend <= r_len);
        if bt {
            // r_ij = Σ_k op(a)_ik b_jk: row j of the stored `b` is contiguous.
            let (mut p, mut b0) = (r0, 0);
            while p < rend {
                let bend = b0 + inner;
                assert!(bend <= b_len);
                let (mut s, mut q, mut x) = (0.0, b0, i * ai);
                while q < bend {
                    s += a[x] * b[q];
                    x += ak;
                    q += 1;
                }
                r[p] = s;
                b0 = bend;
                p += 1;
            }
        } else if inner == 0 {
            let mut p = r0;
            while p < rend {
                r[p] = 0.0;
                p += 1;
            }
        } else {
            // Row i of r accumulates op(a)_ik · (row k of b), k ascending: entry (i, j)
            // is +0 + op(a)_i0 b_0j, then + op(a)_i1 b_1j, … as the sum above.
            assert!(cols <= b_len);
            let (aik, mut p, mut q) = (a[i * ai], r0, 0);
            while p < rend {
                r[p] = 0.0 + aik * b[q];
                p += 1;
                q += 1;
            }
            let (mut k, mut q0) = (1, cols);
            while k < inner {
                let aik = a[i * ai + k * ak];
                assert!(q0 + cols <= b_len);
                let (mut p, mut q) = (r0, q0);
                while p < rend {
                    r[p] += aik * b[q];
                    p += 1;
                    q += 1;
                }
                q0 += cols;
                k += 1;
            }
        }
        i += 1;
    }
}

/// `dst += s · srcᵀ` (`dst` `rows×cols`, `src` `cols×rows`), entry by entry as
/// [`add_scaled_flat`] does with a transposed copy.
pub(crate) const fn add_transposed(dst: &mut [f64], s: f64, src: &[f64], rows: usize, cols: usize) {
    let mut i = 0;
    while i < rows {
        let mut j = 0;
        while j < cols {
            dst[i * cols + j] += s * src[j * rows + i];
            j += 1;
        }
        i += 1;
    }
}

/// `dst = srcᵀ` (`src` `rows×cols`).
pub(crate) const fn transpose_into(dst: &mut [f64], src: &[f64], rows: usize, cols: usize) {
    let mut i = 0;
    while i < rows {
        let mut j = 0;
        while j < cols {
            dst[j * rows + i] = src[i * cols + j];
            j += 1;
        }
        i += 1;
    }
}

/// `dst = |src|` entry by entry.
pub(crate) const fn abs_into(dst: &mut [f64], src: &[f64]) {
    let mut i = 0;
    while i < src.len() {
        dst[i] = src[i].abs();
        i += 1;
    }
}

/// `dst = I` (`n×n`).
pub(crate) const fn identity_into(dst: &mut [f64], n: usize) {
    let mut i = 0;
    while i < n * n {
        dst[i] = if i % (n + 1) == 0 { 1.0 } else { 0.0 };
        i += 1;
    }
}

/// `a ← (a + aᵀ)/2` in place (`n×n`).
pub(crate) const fn symmetrize_flat(a: &mut [f64], n: usize) {
    let mut i = 0;
    while i < n {
        let mut j = 0;
        while j < i {
            let m = 0.5 * (a[i * n + j] + a[j * n + i]);
            a[i * n + j] = m;
            a[j * n + i] = m;
            j += 1;
        }
        i += 1;
    }
}

/// `|a_ij − a_ji| ≤ rel · max|a|` for every pair (`n×n`; not a finiteness check).
pub(crate) const fn is_symmetric_flat(a: &[f64], n: usize, rel: f64) -> bool {
    let tol = rel * max_abs_flat(a);
    let mut i = 0;
    while i < n {
        let mut j = 0;
        while j < i {
            if (a[i * n + j] - a[j * n + i]).abs() > tol {
                return false;
            }
            j += 1;
        }
        i += 1;
    }
    true
}

/// `a` symmetric to `64 ε max|a|` and all finite.
pub(crate) const fn symmetric_flat(a: &[f64], n: usize) -> bool {
    all_finite_flat(a) && is_symmetric_flat(a, n, 64.0 * f64::EPSILON)
}

/// The Cholesky factor `L` (lower, into `l`, `n×n`; the strict upper part is not written)
/// of a symmetric `m`; `false` unless every pivot exceeds `n ε max|m|`. The one
/// factorization behind [`cholesky`](crate::linalg::cholesky::cholesky). Cost: `n³/6`.
pub(crate) const fn cholesky_flat(m: &[f64], n: usize, l: &mut [f64]) -> bool {
    let tiny = n as f64 * f64::EPSILON * max_abs_flat(m);
    let mut j = 0;
    while j < n {
        let s = minus_dot(m[j * n + j], l, j * n, j * n, j);
        if s.is_nan() || s <= tiny {
            return false;
        }
        let d = sqrt(s);
        l[j * n + j] = d;
        let mut i = j + 1;
        while i < n {
            l[i * n + j] = minus_dot(m[i * n + j], l, i * n, j * n, j) / d;
            i += 1;
        }
        j += 1;
    }
    true
}

/// `s − Σ_{k<len} l[a + k] l[b + k]`, subtracted term by term in `k` order.
const fn minus_dot(mut s: f64, l: &[f64], a: usize, b: usize, len: usize) -> f64 {
    let mut k = 0;
    while k < len {
        s -= l[a + k] * l[b + k];
        k += 1;
    }
    s
}

/// `a` (`n×n`) is a covariance: finite, symmetric and positive semidefinite (a Cholesky
/// factorization of `a + δI`, `δ = 16 n ε max|a|`), as
/// [`is_covariance`](super::kalman_core::is_covariance) judges it; `b`, `l`: `n²` scratch.
pub(crate) const fn is_covariance_flat(a: &[f64], n: usize, b: &mut [f64], l: &mut [f64]) -> bool {
    if !symmetric_flat(a, n) {
        return false;
    }
    let delta = 16.0 * n as f64 * f64::EPSILON * max_abs_flat(a) + f64::MIN_POSITIVE;
    copy_flat(b, a);
    let mut i = 0;
    while i < n {
        b[i * n + i] += delta;
        i += 1;
    }
    cholesky_flat(b, n, l)
}

/// An LU factorization of `n×n` `f64`: factors, permutation and row scales (slices of
/// `n²`, `n`, `n`).
pub(crate) struct LuFlat<'a> {
    /// `L` and `U`, row-major.
    pub(crate) lu: &'a mut [f64],
    /// The row permutation.
    pub(crate) perm: &'a mut [usize],
    /// The row scales (permuted).
    pub(crate) scales: &'a mut [f64],
}

impl LuFlat<'_> {
    /// Factorize `a` with its own row scales (as [`lu_of`](super::state_space::lu_of));
    /// `false` if singular to working precision.
    pub(crate) const fn factor_of(&mut self, a: &[f64], n: usize) -> bool {
        copy_flat(self.lu, a);
        row_scales_flat(a, self.scales);
        factor(self.lu, n, self.scales, self.perm)
    }

    /// `x = A⁻¹ b` for `b` of `c` columns.
    pub(crate) const fn solve(&self, b: &[f64], c: usize, x: &mut [f64]) {
        solve_flat(self.lu, self.perm, b, c, x);
    }
}

/// [`definite_lu`](super::kalman_core::definite_lu) on flat slices: `a` finite, symmetric,
/// with a Cholesky factorization (`l`: `n²` scratch) and an LU (into `lu`).
pub(crate) const fn definite_lu_flat(
    a: &[f64],
    n: usize,
    l: &mut [f64],
    lu: &mut LuFlat<'_>,
) -> bool {
    symmetric_flat(a, n) && cholesky_flat(a, n, l) && lu.factor_of(a, n)
}

/// `max_i Σ_j |a_ij|` (`n×n`; NaN if an entry is NaN).
pub(crate) const fn inf_norm_flat(a: &[f64], n: usize) -> f64 {
    let mut m = 0.0f64;
    let mut i = 0;
    while i < n {
        let mut s = 0.0;
        let mut j = 0;
        while j < n {
            s += a[i * n + j].abs();
            j += 1;
        }
        if s > m || s.is_nan() {
            m = s;
        }
        i += 1;
    }
    m
}

/// [`balance`](super::riccati::balance) in place: `b ← D⁻¹ b D`, `d` the diagonal of `D`
/// (powers of two, as LAPACK's `gebal`).
pub(crate) const fn balance_flat(b: &mut [f64], d: &mut [f64], n: usize) {
    let mut i = 0;
    while i < n {
        d[i] = 1.0;
        i += 1;
    }
    let mut sweep = 0;
    while sweep < 64 {
        let mut changed = false;
        let mut i = 0;
        while i < n {
            let (mut c, mut r) = (0.0f64, 0.0f64);
            let mut j = 0;
            while j < n {
                if j != i {
                    c += b[j * n + i].abs();
                    r += b[i * n + j].abs();
                }
                j += 1;
            }
            if c > 0.0 && r > 0.0 && c.is_finite() && r.is_finite() {
                let s = c + r;
                let mut f = 1.0f64;
                let mut steps = 0;
                while c < 0.5 * r && steps < 2100 {
                    f *= 2.0;
                    c *= 2.0;
                    r *= 0.5;
                    steps += 1;
                }
                while c >= 2.0 * r && steps < 2100 {
                    f *= 0.5;
                    c *= 0.5;
                    r *= 2.0;
                    steps += 1;
                }
                let di = d[i] * f;
                if c + r < 0.95 * s && f.is_normal() && di.is_normal() {
                    let mut j = 0;
                    while j < n {
                        b[j * n + i] *= f;
                        b[i * n + j] /= f;
                        j += 1;
                    }
                    d[i] = di;
                    changed = true;
                }
            }
            i += 1;
        }
        if !changed {
            break;
        }
        sweep += 1;
    }
}

/// `n×n` scratch of the Riccati solve: eight matrices, a vector and an LU.
pub(crate) struct Scratch<'a> {
    /// Scratch matrices (`n²` each).
    pub(crate) m: [&'a mut [f64]; 8],
    /// Scratch vector (`n`).
    pub(crate) d: &'a mut [f64],
    /// An `n×n` factorization.
    pub(crate) lu: LuFlat<'a>,
}

/// What one turn of an iterative solve did: go on, finished, or broke down.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Turn {
    /// Not finished: take another turn.
    Again,
    /// Finished with a usable result.
    Done,
    /// Broke down (or, for Stein, the closed loop is not certified stable).
    Failed,
}

/// Squarings of the Stein iteration at most ([`stein_flat`]).
const STEIN_TURNS: u32 = 64;

/// The start of [`stein_flat`]: `A` balanced into `m[0]` (`D` into `d`) and `W` in balanced
/// coordinates into `x`.
pub(crate) const fn stein_begin(
    a: &[f64],
    w: &[f64],
    n: usize,
    x: &mut [f64],
    s: &mut Scratch<'_>,
) {
    let [b, ..] = &mut s.m;
    let d = &mut *s.d;
    copy_flat(b, a);
    balance_flat(b, d, n);
    let mut i = 0;
    while i < n {
        let mut j = 0;
        while j < n {
            x[i * n + j] = w[i * n + j] / d[i] / d[j];
            j += 1;
        }
        i += 1;
    }
}

/// One turn of [`stein_flat`] after [`stein_begin`]: `Done` (with `x` scaled back) once the
/// balanced power `A_k` is small, `Failed` on a power or a sum that is not finite, else
/// `x ← x + A_k x A_kᵀ`, `A_{k+1} = A_k²` and `Again`. Cost: `3 n³` multiply-adds.
pub(crate) const fn stein_turn(n: usize, x: &mut [f64], s: &mut Scratch<'_>) -> Turn {
    let [b, t1, t2, ..] = &mut s.m;
    let d = &*s.d;
    let nrm = inf_norm_flat(b, n);
    if !nrm.is_finite() || !all_finite_flat(x) {
        return Turn::Failed;
    }
    if nrm <= A_SMALL {
        let mut i = 0;
        while i < n {
            let mut j = 0;
            while j < n {
                x[i * n + j] = x[i * n + j] * d[i] * d[j];
                j += 1;
            }
            i += 1;
        }
        return if all_finite_flat(x) {
            Turn::Done
        } else {
            Turn::Failed
        };
    }
    mul_into(t1, x, false, b, true, n, n, n);
    mul_into(t2, b, false, t1, false, n, n, n);
    add_scaled_flat(x, 1.0, t2);
    mul_into(t1, b, false, b, false, n, n, n);
    copy_flat(b, t1);
    Turn::Again
}

/// [`stein`](super::riccati::stein) on flat slices: `x = A x Aᵀ + W` by doubling in
/// balanced coordinates into `x`; `false` if `A` is not certified stable. Uses
/// `m[0..3]` and `d` of `s`.
pub(crate) const fn stein_flat(
    a: &[f64],
    w: &[f64],
    n: usize,
    x: &mut [f64],
    s: &mut Scratch<'_>,
) -> bool {
    stein_begin(a, w, n, x, s);
    let mut k = 0;
    while k < STEIN_TURNS {
        match stein_turn(n, x, s) {
            Turn::Again => {}
            Turn::Done => return true,
            Turn::Failed => return false,
        }
        k += 1;
    }
    false
}

/// One iteration of the doubling algorithm (see
/// [`doubling_solution`](super::riccati::doubling_solution)) in place on `(a, g, x)`:
/// `Failed` when `W` is singular or an iterate is not finite, `Done` once converged,
/// else `Again`. Uses `m[0..5]` and the LU of `s`. Cost: about `10 n³` flops.
pub(crate) const fn doubling_turn(
    a: &mut [f64],
    g: &mut [f64],
    x: &mut [f64],
    n: usize,
    s: &mut Scratch<'_>,
) -> Turn {
    let [w, wa, wg, t1, t2, ..] = &mut s.m;
    mul_into(t1, g, false, x, false, n, n, n);
    identity_into(w, n);
    add_scaled_flat(w, 1.0, t1);
    if !s.lu.factor_of(w, n) {
        return Turn::Failed;
    }
    s.lu.solve(a, n, wa);
    s.lu.solve(g, n, wg);
    // X₁ = sym(X + Aᵀ (X W⁻¹A)) into w.
    mul_into(t1, x, false, wa, false, n, n, n);
    mul_into(t2, a, true, t1, false, n, n, n);
    copy_flat(w, x);
    add_scaled_flat(w, 1.0, t2);
    symmetrize_flat(w, n);
    // G₁ = sym(G + A (W⁻¹G Aᵀ)) in place.
    mul_into(t1, wg, false, a, true, n, n, n);
    mul_into(t2, a, false, t1, false, n, n, n);
    add_scaled_flat(g, 1.0, t2);
    symmetrize_flat(g, n);
    // A₁ = A W⁻¹A into t1.
    mul_into(t1, a, false, wa, false, n, n, n);
    if !(all_finite_flat(w) && all_finite_flat(g) && all_finite_flat(t1)) {
        return Turn::Failed;
    }
    copy_flat(t2, w);
    add_scaled_flat(t2, -1.0, x);
    let diff = max_abs_flat(t2);
    copy_flat(x, w);
    copy_flat(a, t1);
    if diff <= 4.0 * f64::EPSILON * max_abs_flat(x) && inf_norm_flat(a, n) <= A_SMALL {
        Turn::Done
    } else {
        Turn::Again
    }
}

/// The doubling algorithm in place on `(a, g, x)`, at most `max` iterations of
/// [`doubling_turn`]: `Some((iterations, converged))`, `None` when it breaks down.
pub(crate) const fn doubling_flat(
    a: &mut [f64],
    g: &mut [f64],
    x: &mut [f64],
    n: usize,
    max: u32,
    s: &mut Scratch<'_>,
) -> Option<(u32, bool)> {
    let mut k = 0;
    while k < max {
        k += 1;
        match doubling_turn(a, g, x, n, s) {
            Turn::Again => {}
            Turn::Done => return Some((k, true)),
            Turn::Failed => return None,
        }
    }
    Some((k, false))
}

/// The end of the doubling: `false` unless it `converged` to a covariance `x`; then `x`
/// plus `sym(q_cross)` when given (the a-priori covariance). Uses `m[0..3]` of `s`.
const fn doubling_finish(
    x: &mut [f64],
    n: usize,
    converged: bool,
    q_cross: Option<&[f64]>,
    s: &mut Scratch<'_>,
) -> bool {
    let [b, l, t, ..] = &mut s.m;
    if !(converged && is_covariance_flat(x, n, b, l)) {
        return false;
    }
    if let Some(q) = q_cross {
        copy_flat(t, q);
        symmetrize_flat(t, n);
        add_scaled_flat(x, 1.0, t);
        symmetrize_flat(x, n);
    }
    true
}

/// [`doubling_solution`](super::riccati::doubling_solution) on flat slices: the
/// a-priori covariance into `x` (plus `sym(q_cross)` when given) and the iterations;
/// `None` if the doubling breaks down, does not converge or stops at a non-covariance.
pub(crate) const fn doubling_solution_flat(
    start: [&mut [f64]; 3],
    n: usize,
    max: u32,
    q_cross: Option<&[f64]>,
    s: &mut Scratch<'_>,
) -> Option<u32> {
    let [a, g, x] = start;
    match doubling_flat(a, g, x, n, max, s) {
        Some((k, converged)) if doubling_finish(x, n, converged, q_cross, s) => Some(k),
        _ => None,
    }
}

/// The measurement side of the Riccati solve: `H` (`o×n`), `R` (`o×o`) and the cross
/// covariance `N` (`n×o`, `None` when absent or zero).
#[derive(Clone, Copy)]
pub(crate) struct Sensors<'a> {
    /// `H`, `o×n`.
    pub(crate) h: &'a [f64],
    /// `R`, `o×o`.
    pub(crate) r: &'a [f64],
    /// `N`, `n×o`.
    pub(crate) cross: Option<&'a [f64]>,
    /// Outputs `o`.
    pub(crate) o: usize,
}

/// Scratch of the output side (`o×n`, `o×o` matrices and an `o×o` LU).
pub(crate) struct OutScratch<'a> {
    /// `o×n` scratch (two).
    pub(crate) on: [&'a mut [f64]; 2],
    /// `o×o` scratch (three).
    pub(crate) oo: [&'a mut [f64]; 3],
    /// `n×o` scratch (two).
    pub(crate) no: [&'a mut [f64]; 2],
    /// An `o×o` factorization.
    pub(crate) lu: LuFlat<'a>,
}

/// [`gain_of`](super::riccati::gain_of) on flat slices: `L = (P Hᵀ + N) Σ⁻¹` into `gain`
/// (`n×o`); `false` if `Σ` is singular. Uses `on`, `oo` and the LU of `t`.
pub(crate) const fn gain_of_flat(
    p: &[f64],
    n: usize,
    sn: &Sensors<'_>,
    gain: &mut [f64],
    t: &mut OutScratch<'_>,
) -> bool {
    let o = sn.o;
    let [hp, sol] = &mut t.on;
    let [si, hh, hn] = &mut t.oo;
    // The innovation's parts (`innovation_parts`): H P (+ Nᵀ), R + H P Hᵀ (+ H N + Nᵀ Hᵀ).
    mul_into(hp, sn.h, false, p, false, o, n, n);
    mul_into(hh, hp, false, sn.h, true, o, n, o);
    copy_flat(si, sn.r);
    add_scaled_flat(si, 1.0, hh);
    if let Some(nx) = sn.cross {
        mul_into(hn, sn.h, false, nx, false, o, n, o);
        add_transposed(hp, 1.0, nx, o, n);
        copy_flat(hh, hn);
        add_transposed(hh, 1.0, hn, o, o);
        add_scaled_flat(si, 1.0, hh);
    }
    symmetrize_flat(si, o);
    if !t.lu.factor_of(si, o) {
        return false;
    }
    t.lu.solve(hp, n, sol);
    transpose_into(gain, sol, o, n);
    true
}

/// The Riccati equation's Joseph-form residual `A P Aᵀ + K R Kᵀ + Q − P` (into `res`),
/// the size of its terms (into `bound`) and the closed loop `A = Φ − Φ L H` (into `acl`),
/// as [`joseph_residual`](super::riccati) forms them. Uses `m[0..4]` of `s` and `t`.
#[allow(clippy::too_many_arguments)]
pub(crate) const fn joseph_residual_flat(
    phi: &[f64],
    q: &[f64],
    p: &[f64],
    l: &[f64],
    n: usize,
    sn: &Sensors<'_>,
    out: [&mut [f64]; 3],
    s: &mut Scratch<'_>,
    t: &mut OutScratch<'_>,
) {
    let o = sn.o;
    let [res, bound, acl] = out;
    let [t1, t2, t3, t4, ..] = &mut s.m;
    let [k, ka] = &mut t.no;
    let [rk, _] = &mut t.on;
    let [ra, ..] = &mut t.oo;
    mul_into(k, phi, false, l, false, n, n, o);
    mul_into(t1, k, false, sn.h, false, n, o, n);
    copy_flat(acl, phi);
    add_scaled_flat(acl, -1.0, t1);
    // res = A (P Aᵀ) + K (R Kᵀ) + Q − P.
    mul_into(t1, p, false, acl, true, n, n, n);
    mul_into(res, acl, false, t1, false, n, n, n);
    mul_into(rk, sn.r, false, k, true, o, o, n);
    mul_into(t1, k, false, rk, false, n, o, n);
    add_scaled_flat(res, 1.0, t1);
    add_scaled_flat(res, 1.0, q);
    add_scaled_flat(res, -1.0, p);
    // bound = |A| (|P| |A|ᵀ) + |K| (|R| |K|ᵀ) + |Q| + |P|.
    abs_into(t3, acl);
    abs_into(ka, k);
    abs_into(t2, p);
    mul_into(t1, t2, false, t3, true, n, n, n);
    mul_into(bound, t3, false, t1, false, n, n, n);
    abs_into(ra, sn.r);
    mul_into(rk, ra, false, ka, true, o, o, n);
    mul_into(t1, ka, false, rk, false, n, o, n);
    add_scaled_flat(bound, 1.0, t1);
    abs_into(t1, q);
    add_scaled_flat(bound, 1.0, t1);
    add_scaled_flat(bound, 1.0, t2);
    if let Some(nx) = sn.cross {
        // − A N Kᵀ − K Nᵀ Aᵀ, and 2 |A||N||K|ᵀ in the size.
        mul_into(t1, nx, false, k, true, n, o, n);
        mul_into(t2, acl, false, t1, false, n, n, n);
        copy_flat(t4, t2);
        add_transposed(t4, 1.0, t2, n, n);
        add_scaled_flat(res, -1.0, t4);
        // |N| into the n×o scratch `k` (K is no longer needed).
        abs_into(k, nx);
        mul_into(t1, k, false, ka, true, n, o, n);
        mul_into(t2, t3, false, t1, false, n, n, n);
        copy_flat(t4, t2);
        add_transposed(t4, 1.0, t2, n, n);
        add_scaled_flat(bound, 1.0, t4);
    }
}

/// The largest `|res_ij| / ((2S + 5) ε max(√(B_ii B_jj), B_ij))` (`∞` if any entry is not
/// finite, or nonzero where its scale is zero; `n×n`).
pub(crate) const fn residual_units_flat(res: &[f64], bound: &[f64], n: usize) -> f64 {
    let unit = (2 * n + 5) as f64 * f64::EPSILON;
    let mut worst = 0.0f64;
    let mut i = 0;
    while i < n {
        let mut j = 0;
        while j < n {
            let x = res[i * n + j].abs();
            let b = bound[i * n + j];
            if !(x.is_finite() && b.is_finite()) {
                return f64::INFINITY;
            }
            let mut scale = sqrt(bound[i * n + i]) * sqrt(bound[j * n + j]);
            if b > scale {
                scale = b;
            }
            if x > 0.0 {
                let u = x / (unit * scale);
                if u > worst || u.is_nan() {
                    worst = u;
                }
            }
            j += 1;
        }
        i += 1;
    }
    worst
}

/// The noise checks of the Riccati solve, in [`SteadyState`](super::SteadyState)'s
/// order: `q` a covariance, `r` positive definite ([`Error::InvalidCovariance`]), `H`
/// finite ([`Error::NonFiniteInput`]). On success the LU of `r` is in `t.lu`.
pub(crate) const fn check_noise(
    q: &[f64],
    n: usize,
    sn: &Sensors<'_>,
    s: &mut Scratch<'_>,
    t: &mut OutScratch<'_>,
) -> Result<(), Error> {
    let [b, l, ..] = &mut s.m;
    if !is_covariance_flat(q, n, b, l) {
        return Err(Error::InvalidCovariance);
    }
    let [lo, ..] = &mut t.oo;
    if !definite_lu_flat(sn.r, sn.o, lo, &mut t.lu) {
        return Err(Error::InvalidCovariance);
    }
    if !all_finite_flat(sn.h) {
        return Err(Error::NonFiniteInput);
    }
    Ok(())
}

/// The doubling's start without a cross covariance, `A₀ = Φᵀ`, `G₀ = sym(Hᵀ R⁻¹ H)`,
/// `X₀ = sym(Q)` into `(a, g, x)`, with the LU of `R` from [`check_noise`] in `t.lu`.
pub(crate) const fn plain_start(
    phi: &[f64],
    q: &[f64],
    n: usize,
    sn: &Sensors<'_>,
    start: [&mut [f64]; 3],
    t: &mut OutScratch<'_>,
) {
    let [a, g, x] = start;
    transpose_into(a, phi, n, n);
    let [rh, _] = &mut t.on;
    t.lu.solve(sn.h, n, rh);
    mul_into(g, sn.h, true, rh, false, n, sn.o, n);
    symmetrize_flat(g, n);
    copy_flat(x, q);
    symmetrize_flat(x, n);
}

/// Where a Riccati solve ([`RiccatiRun`]) stands.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Stage {
    /// Doubling iterations.
    Doubling,
    /// The start of a verification/refinement pass: the gain, the residual, the Stein start.
    Refine,
    /// Squarings of the pass's Stein equation.
    Stein,
    /// Done: the best iterate is the answer.
    Finished,
}

/// The buffers of a Riccati solve from its doubling start ([`RiccatiRun::advance`]).
pub(crate) struct RiccatiParts<'a, 'b> {
    /// `Φ` (`n×n`).
    pub(crate) phi: &'a [f64],
    /// `Q` (`n×n`).
    pub(crate) q: &'a [f64],
    /// States `n`.
    pub(crate) n: usize,
    /// The measurement side.
    pub(crate) sn: &'a Sensors<'a>,
    /// Whether the start is the cross-covariance one (the solution is then `Y + Q`).
    pub(crate) q_cross: bool,
    /// The doubling's start `(A, G, X)`; `A` then holds the closed loop, `X` the iterate `P`.
    pub(crate) start: [&'b mut [f64]; 3],
    /// `(P, L)`: the answer (`n×n`, `n×o`).
    pub(crate) out: (&'b mut [f64], &'b mut [f64]),
    /// The residual, its size, the Newton correction (`n×n`) and the best gain (`n×o`).
    pub(crate) work: [&'b mut [f64]; 4],
    /// `n×n` scratch.
    pub(crate) s: &'b mut Scratch<'b>,
    /// Output-side scratch.
    pub(crate) t: &'b mut OutScratch<'b>,
}

/// The solution `(P, L)` of the steady-state Kalman filter, one bounded piece of work at a
/// time ([`advance`](Self::advance)), so a caller can look at a stop flag between pieces
/// (the run-time-sized [`DynSteadyState`](super::DynSteadyState) from Python: Ctrl-C) while
/// the const path ([`solve_from_start`]) runs it through: the same pieces in the same order.
///
/// From the doubling's start in `(a, g, x)`: the doubling solution, then the verification
/// and up to three Newton (Hewer) refinements of
/// [`SteadyState::from_parts`](super::SteadyState::from_parts), keeping the best iterate.
pub(crate) struct RiccatiRun {
    stage: Stage,
    /// Doubling iterations taken.
    iterations: u32,
    /// The refinement pass.
    step: u32,
    /// Stein squarings taken in this pass.
    turns: u32,
    /// This pass's residual, in units.
    units: f64,
    has_best: bool,
    best_units: f64,
}

impl RiccatiRun {
    /// A solve at its start.
    pub(crate) const fn new() -> Self {
        Self {
            stage: Stage::Doubling,
            iterations: 0,
            step: 0,
            turns: 0,
            units: f64::INFINITY,
            has_best: false,
            best_units: f64::INFINITY,
        }
    }

    /// One piece of the solve: a doubling iteration (`10 n³` flops), the start of a
    /// verification pass (the gain and the residual, about `4 n³`), or a Stein squaring
    /// (`3 n³`). `None` while there is more to do; then `Some` of the doubling iterations,
    /// or [`Error::RiccatiNotConverged`] / [`Error::OperatorOverflow`], with `(P, L)` in
    /// `out`. Call it with the same buffers every time.
    pub(crate) const fn advance(
        &mut self,
        b: &mut RiccatiParts<'_, '_>,
    ) -> Option<Result<u32, Error>> {
        let n = b.n;
        let [a, g, p] = &mut b.start;
        let (cov, gain) = &mut b.out;
        let [res, bound, delta, best_gain] = &mut b.work;
        match self.stage {
            Stage::Doubling => {
                let mut converged = false;
                if self.iterations < RICCATI_MAX_ITERATIONS {
                    self.iterations += 1;
                    match doubling_turn(a, g, p, n, b.s) {
                        Turn::Again => return None,
                        Turn::Failed => return Some(Err(Error::RiccatiNotConverged)),
                        Turn::Done => converged = true,
                    }
                }
                let qc = if b.q_cross { Some(b.q) } else { None };
                if !doubling_finish(p, n, converged, qc, b.s) {
                    return Some(Err(Error::RiccatiNotConverged));
                }
                // `a` and `g` are free from here: `a` holds the closed loop.
                self.stage = Stage::Refine;
            }
            Stage::Refine => {
                if self.step > RICCATI_REFINEMENTS || !gain_of_flat(p, n, b.sn, gain, b.t) {
                    self.stage = Stage::Finished;
                } else if !all_finite_flat(gain) {
                    if !self.has_best && self.step == 0 {
                        return Some(Err(Error::OperatorOverflow));
                    }
                    self.stage = Stage::Finished;
                } else {
                    joseph_residual_flat(b.phi, b.q, p, gain, n, b.sn, [res, bound, a], b.s, b.t);
                    self.units = residual_units_flat(res, bound, n);
                    stein_begin(a, res, n, delta, b.s);
                    self.turns = 0;
                    self.stage = Stage::Stein;
                }
            }
            Stage::Stein => {
                if self.turns >= STEIN_TURNS {
                    self.stage = Stage::Finished;
                    return None;
                }
                self.turns += 1;
                match stein_turn(n, delta, b.s) {
                    Turn::Again => return None,
                    Turn::Failed => {
                        self.stage = Stage::Finished;
                        return None;
                    }
                    Turn::Done => {}
                }
                let better = if self.has_best {
                    self.units < self.best_units
                } else {
                    self.units <= f64::INFINITY
                };
                let [m0, m1, ..] = &mut b.s.m;
                if better && is_covariance_flat(p, n, m0, m1) {
                    copy_flat(cov, p);
                    copy_flat(best_gain, gain);
                    self.best_units = self.units;
                    self.has_best = true;
                }
                if self.units <= RICCATI_RESIDUAL_REFINE {
                    self.stage = Stage::Finished;
                } else {
                    add_scaled_flat(p, 1.0, delta);
                    symmetrize_flat(p, n);
                    self.step += 1;
                    self.stage = Stage::Refine;
                }
            }
            Stage::Finished => {
                return Some(
                    if self.has_best && self.best_units <= RICCATI_RESIDUAL_UNITS {
                        copy_flat(gain, best_gain);
                        Ok(self.iterations)
                    } else {
                        Err(Error::RiccatiNotConverged)
                    },
                );
            }
        }
        None
    }
}

/// The solution `(P, L)` of the steady-state Kalman filter ([`RiccatiRun`] run through),
/// written into `cov` and `gain` (`n×n`, `n×o`). Returns the doubling iterations. Errors:
/// [`Error::RiccatiNotConverged`], [`Error::OperatorOverflow`].
pub(crate) const fn solve_from_start(b: &mut RiccatiParts<'_, '_>) -> Result<u32, Error> {
    let mut run = RiccatiRun::new();
    loop {
        if let Some(r) = run.advance(b) {
            return r;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::mul_into;

    /// `mul_into` against the textbook triple loop written here (each entry `s = +0`, then
    /// `s += op(a)_ik · op(b)_kj` for `k` ascending), bit for bit, over sizes 0–9 in every
    /// transposition, with entries of every magnitude, signed zeros, infinities and NaN
    /// (a NaN result only has to be a NaN: its payload is not arithmetic).
    #[test]
    fn mul_into_is_the_triple_loop_bit_for_bit() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            match seed % 23 {
                0 => 0.0,
                1 => -0.0,
                2 => f64::INFINITY,
                3 => f64::NAN,
                4 => 1.0e300,
                _ => {
                    ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5)
                        * 10f64.powi((seed % 9) as i32 - 4)
                }
            }
        };
        for (rows, inner, cols) in
            (0..10).flat_map(|r| (0..10).flat_map(move |k| (0..10).map(move |c| (r, k, c))))
        {
            for (at, bt) in [(false, false), (false, true), (true, false), (true, true)] {
                let (mut a, mut b, mut r) = ([0.0; 81], [0.0; 81], [7.0; 81]);
                a.iter_mut().for_each(|x| *x = next());
                b.iter_mut().for_each(|x| *x = next());
                mul_into(&mut r, &a, at, &b, bt, rows, inner, cols);
                for i in 0..rows {
                    for j in 0..cols {
                        let mut s = 0.0_f64;
                        for k in 0..inner {
                            let x = if at {
                                a[k * rows + i]
                            } else {
                                a[i * inner + k]
                            };
                            let y = if bt {
                                b[j * inner + k]
                            } else {
                                b[k * cols + j]
                            };
                            s += x * y;
                        }
                        let got = r[i * cols + j];
                        assert!(
                            got.to_bits() == s.to_bits() || (got.is_nan() && s.is_nan()),
                            "{rows}x{inner}x{cols} at={at} bt={bt} ({i},{j}): {got:e} vs {s:e}"
                        );
                    }
                }
            }
        }
    }
}
