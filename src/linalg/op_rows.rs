//! The step operators' storage and the one matrix–vector product every step runs on.
//!
//! An operator of the linear steps is `N` rows of `K` blocks of `N` columns (e.g.
//! `[G[i], −GC[i], −GK[i]]`, `K = 3`), multiplying `x = (x_0, …, x_{K−1})`. Row `i` of the
//! product is **one chain**, in column order, a rounding after every multiply and every add
//! (Rust never fuses):
//!
//! ```text
//! q_i = ((a_i,0 x_0 + a_i,1 x_1) + a_i,2 x_2) + … + a_i,KN−1 x_KN−1
//! ```
//!
//! so every target computes the same bits. Targets differ only in how the values are laid
//! out and how many chains run side by side:
//!
//! - **Row layout** (Cortex-M and every target but x86-64): row by row, each row one
//!   contiguous run of `KN` values, summed two rows at a time ([`dots`]: the loop the
//!   Cortex-M4F cost table is measured with; 2 rows is what keeps f32 at or below 3
//!   instructions a multiply-add at N = 6 and 12, 3 or 4 rows spill registers).
//! - **Column-blocked layout** (x86-64): blocks of `W` rows stored column by column, so the
//!   `W` values of one column are adjacent: one packed load feeds 2 (`f64`) or 4 (`f32`)
//!   lanes of independent chains, multiplied by one broadcast `x` value, with no shuffle.
//!   `W` = 16 `f64` or 32 `f32` rows: 8 packed chains in flight, enough to cover the add
//!   latency (3 cycles) on both add pipes. The `N mod W` rows left over join the first
//!   block (up to `1.5 W` rows, 12 packed chains: still in registers) or, when there are
//!   `W/2` or more, form it; every `N < 1.5 W` is one block. No row runs alone: a lone
//!   chain of `3N` dependent adds is what made the row layout slow on the host (measured
//!   4.8 multiply-adds per ns at N = 100, against ≈ 13 for the pipes; see
//!   `docs/performance.md`).
//!
//! `cargo test --lib op_rows` checks both layouts bit for bit against a serial fold for
//! every block shape up to N = 100; `scripts/qemu.sh` checks host and Cortex-M4F runs
//! bit-identical.

use crate::Real;

/// Whether this target stores operators column-blocked (x86-64) or by rows.
const COLUMN_BLOCKED: bool = cfg!(target_arch = "x86_64");

/// Rows of a column block for a scalar of `bytes` bytes: 8 packed chains of 16 bytes
/// (16 `f64`, 32 `f32`); 0 on row-layout targets.
const fn wide_rows(bytes: usize) -> usize {
    if COLUMN_BLOCKED { 8 * 16 / bytes } else { 0 }
}

/// Rows of the first column block (blocks of `w` rows follow): all `n` if `n < 1.5 w`;
/// else `w + n mod w` if `n mod w < w/2`; else `n mod w`.
const fn first_block(n: usize, w: usize) -> usize {
    if 2 * n < 3 * w {
        n
    } else if 2 * (n % w) < w {
        w + n % w
    } else {
        n % w
    }
}

/// Rows of a column block of the run-time-sized operators ([`wide_rows`] of x86-64, on
/// every target: their layout and product are the same code everywhere).
#[cfg(feature = "std")]
pub(crate) const fn dyn_wide_rows(bytes: usize) -> usize {
    8 * 16 / bytes
}

/// Position in the flat storage (`K·N²` values) of row `i`, flat column `c` (`b·N + j`),
/// in the row layout (`w = 0`) or the column-blocked one with blocks of `w` rows.
pub(crate) const fn flat_index(n: usize, k: usize, i: usize, c: usize, w: usize) -> usize {
    let kn = k * n;
    if w == 0 {
        return i * kn + c;
    }
    let b0 = first_block(n, w);
    if i < b0 {
        return c * b0 + i;
    }
    let r = i - b0;
    (b0 + (r / w) * w) * kn + c * w + r % w
}

/// `N` operator rows of `K` blocks of `N` values, stored in this target's layout (see the
/// module docs); read by [`OpRows::get`], multiplied by [`OpRows::mat_vec`]. The same
/// `K·N²` values, only permuted: `size_of` is that of `[[[T; N]; K]; N]`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(transparent)]
pub(crate) struct OpRows<T, const N: usize, const K: usize>([[[T; N]; K]; N]);

impl<T: Copy, const N: usize, const K: usize> OpRows<T, N, K> {
    /// Rows of this scalar's column blocks (0: row layout).
    const WIDE: usize = wide_rows(core::mem::size_of::<T>());

    /// Store `rows` (`rows[i][b][j]`: row `i`, block `b`, column `j`) in this target's
    /// layout. `const`: the `from_rows` constructors lay operators out in flash.
    pub(crate) const fn new(rows: [[[T; N]; K]; N]) -> Self {
        if Self::WIDE == 0 {
            Self(rows)
        } else {
            Self(layout(rows, Self::WIDE))
        }
    }

    /// Row `i`, block `b`, column `j` (panics out of range: internal use with loop
    /// indices). Cost: an index computation (a plain load in the row layout).
    #[inline(always)]
    pub(crate) fn get(&self, i: usize, b: usize, j: usize) -> T {
        if Self::WIDE == 0 {
            return self.0[i][b][j];
        }
        let f = flat_index(N, K, i, b * N + j, Self::WIDE);
        self.0[f / (K * N)][(f / N) % K][f % N]
    }
}

/// `rows` permuted into the layout of blocks of `w` rows (`w = 0`: unchanged).
const fn layout<T: Copy, const N: usize, const K: usize>(
    rows: [[[T; N]; K]; N],
    w: usize,
) -> [[[T; N]; K]; N] {
    let mut out = rows;
    let mut i = 0;
    while i < N {
        let mut b = 0;
        while b < K {
            let mut j = 0;
            while j < N {
                let f = flat_index(N, K, i, b * N + j, w);
                out[f / (K * N)][(f / N) % K][f % N] = rows[i][b][j];
                j += 1;
            }
            b += 1;
        }
        i += 1;
    }
    out
}

impl<T: Real, const N: usize, const K: usize> OpRows<T, N, K> {
    /// Every value finite (in any layout). Cost: `K·N²` comparisons.
    pub(crate) fn all_finite(&self) -> bool {
        self.0
            .as_flattened()
            .as_flattened()
            .iter()
            .all(|x| x.is_finite())
    }

    /// `out[i] = Σ rows[i] · x`, each row one chain in column order (module docs).
    /// `out` has `N` values (a shorter one gets only the rows it has room for). Cost:
    /// `K·N²` multiply-adds; no branch on the data, no panic.
    #[inline(always)]
    pub(crate) fn mat_vec(&self, x: &[[T; N]; K], out: &mut [T]) {
        self.mat_vec_from(0, x, out);
    }

    /// `out[i] = Σ rows[i][from..] · x[from..]`: the product of blocks `from..K` only (the
    /// first `from` blocks of `x` are not read), each row one chain in column order from
    /// block `from`'s first product, as [`OpRows::mat_vec`] (which is `from = 0`). For a
    /// product by a vector that is zero in the first blocks (the compensated step's
    /// rounding errors) at the speed of the main product. Cost: `(K − from)·N²`
    /// multiply-adds; `from ≥ K` gives zeros; no branch on the data, no panic.
    #[inline(always)]
    pub(crate) fn mat_vec_from(&self, from: usize, x: &[[T; N]; K], out: &mut [T]) {
        match Self::WIDE {
            32 => wide_blocks::<T, N, K, 32>(&self.0, from, x, out),
            16 => wide_blocks::<T, N, K, 16>(&self.0, from, x, out),
            _ => row_pairs(&self.0, from, x, out),
        }
    }
}

/// The column-blocked product: on x86-64, operators of at least
/// [`MIN_BYTES`](super::avx::MIN_BYTES) through the run-time AVX choice ([`super::wide`]:
/// same bits), smaller ones on the inlined SSE2 loop, where the call would cost a fair
/// share of the step; elsewhere (never reached: no other target is column-blocked) plain.
#[inline(always)]
fn wide_blocks<T: Real, const N: usize, const K: usize, const W: usize>(
    ops: &[[[T; N]; K]; N],
    from: usize,
    x: &[[T; N]; K],
    out: &mut [T],
) {
    let (flat, xf) = (ops.as_flattened().as_flattened(), x.as_flattened());
    // `N`, `K` written in the closure (constants inside the AVX-compiled function too),
    // and the small sizes' product called directly (inlined, unrolled for the size).
    #[cfg(target_arch = "x86_64")]
    if K * N * N * core::mem::size_of::<T>() >= super::avx::MIN_BYTES {
        return super::wide(|| column_blocks_flat::<T, W>(flat, N, K, from, xf, out));
    }
    column_blocks_flat::<T, W>(flat, N, K, from, xf, out);
}

/// [`wide_blocks`] on the flat storage of `n` rows of `k` blocks (`flat`: `k·n²` values,
/// `xf`: `k·n`), sizes known at run time: the run-time-sized operators' product, the same
/// body ([`column_blocks_flat`]) as the const-generic one.
#[cfg(feature = "std")]
#[inline(always)]
pub(crate) fn wide_blocks_flat<T: Real, const W: usize>(
    flat: &[T],
    n: usize,
    k: usize,
    from: usize,
    xf: &[T],
    out: &mut [T],
) {
    // Through the run-time AVX choice from the same size on as the const-generic product.
    #[cfg(target_arch = "x86_64")]
    let large = k * n * n * core::mem::size_of::<T>() >= super::avx::MIN_BYTES;
    #[cfg(not(target_arch = "x86_64"))]
    let large = false;
    let mut product = || column_blocks_flat::<T, W>(flat, n, k, from, xf, out);
    if large {
        super::wide(product)
    } else {
        product()
    }
}

/// Rows in the row layout times `x` (blocks `from..K`): a single row first if their number
/// is odd, then pairs ([`dots`]).
#[inline(always)]
fn row_pairs<T: Real, const N: usize, const K: usize>(
    rows: &[[[T; N]; K]],
    from: usize,
    x: &[[T; N]; K],
    out: &mut [T],
) {
    let (single, pairs) = rows.as_rchunks::<2>();
    let (out_single, out_pairs) = out.as_rchunks_mut::<2>();
    for (row, o) in single.iter().zip(out_single) {
        [*o] = dots(core::array::from_ref(row), from, x);
    }
    for (rows, o) in pairs.iter().zip(out_pairs) {
        *o = dots(rows, from, x);
    }
}

/// Storage in the column-blocked layout with blocks of `W` rows (flat: `n` rows of `k`
/// blocks), times `x` (blocks `from..k`: the flat columns from `from·n` on): the first
/// block ([`first_block`] rows, dispatched to its size), then the blocks of `W`. The one
/// body both the const-generic and the run-time-sized products run.
#[inline(always)]
pub(super) fn column_blocks_flat<T: Real, const W: usize>(
    flat: &[T],
    n: usize,
    k: usize,
    from: usize,
    xf: &[T],
    out: &mut [T],
) {
    let kn = k * n;
    let b0 = first_block(n, W);
    let skip = from.saturating_mul(n);
    // Each block's columns, and `x`, from `skip` on (none if `skip ≥ K·N`).
    let xf = xf.get(skip..).unwrap_or(&[]);
    let (Some((first, rest)), Some((out_first, out_rest))) = (
        flat.split_at_checked(b0 * kn),
        out.split_at_mut_checked(b0.min(out.len())),
    ) else {
        return;
    };
    // One arm per size the first block can have (up to 1.5 W − 1 rows); `b0` is a
    // constant of `N`, so only its arm is compiled into a step.
    macro_rules! first {
        ($($r:literal)*) => {
            match b0 {
                $($r => {
                    if let Ok(o) = <&mut [T; $r]>::try_from(out_first) {
                        *o = column_block(first.as_chunks::<$r>().0.get(skip..).unwrap_or(&[]), xf);
                    }
                })*
                _ => {}
            }
        };
    }
    first!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30
        31 32 33 34 35 36 37 38 39 40 41 42 43 44 45 46 47);
    if kn == 0 {
        return;
    }
    let (cols, _) = rest.as_chunks::<W>();
    let (outs, _) = out_rest.as_chunks_mut::<W>();
    for (block, o) in cols.chunks_exact(kn).zip(outs) {
        *o = column_block(block.get(skip..).unwrap_or(&[]), xf);
    }
}

/// `R` rows stored column by column (`cols[c][r]`: row `r`, flat column `c`) times `x`:
/// lane `r` is row `r`'s chain, started from its first product and added column by column.
#[inline(always)]
fn column_block<T: Real, const R: usize>(cols: &[[T; R]], x: &[T]) -> [T; R] {
    let mut q = [T::zero(); R];
    let (Some((first, cols)), Some((&x0, x))) = (cols.split_first(), x.split_first()) else {
        return q;
    };
    for r in 0..R {
        q[r] = first[r] * x0;
    }
    for (col, &xc) in cols.iter().zip(x) {
        for r in 0..R {
            q[r] += col[r] * xc;
        }
    }
    q
}

/// `R` dot products of row-layout operator rows (each `K` blocks of `N`) with `x`: `R`
/// accumulators, so each `x` value is loaded once for `R` multiply-adds. Each sum starts
/// from its first product (no `0 +`), then accumulates block by block, column by column,
/// in order: row `r`'s result is
/// `((rows[r][0][0]·x[0][0] + rows[r][0][1]·x[0][1]) + …) + rows[r][K−1][N−1]·x[K−1][N−1]`,
/// the same chain as every other layout computes.
#[inline(always)]
fn dots<T: Real, const N: usize, const K: usize, const R: usize>(
    rows: &[[[T; N]; K]; R],
    from: usize,
    x: &[[T; N]; K],
) -> [T; R] {
    let mut q = [T::zero(); R];
    if N == 0 || from >= K {
        return q;
    }
    for r in 0..R {
        q[r] = rows[r][from][0] * x[from][0];
    }
    for b in from..K {
        let first = if b == from { 1 } else { 0 };
        for j in first..N {
            let xj = x[b][j];
            for r in 0..R {
                q[r] += rows[r][b][j] * xj;
            }
        }
    }
    q
}

#[cfg(test)]
mod tests {
    use super::{column_blocks_flat, flat_index, layout, row_pairs, wide_blocks};
    use crate::Real;

    fn flat<T, const N: usize, const K: usize>(a: &[[[T; N]; K]; N]) -> &[T] {
        a.as_flattened().as_flattened()
    }

    fn flat_x<T, const N: usize, const K: usize>(x: &[[T; N]; K]) -> &[T] {
        x.as_flattened()
    }

    /// Row `i` of `rows[.., from..] · x[from..]` as one serial chain, first product first:
    /// the order every layout and block shape must keep (zeros if `from ≥ K`).
    fn serial<T: Real, const N: usize, const K: usize>(
        rows: &[[[T; N]; K]; N],
        from: usize,
        x: &[[T; N]; K],
    ) -> [T; N] {
        core::array::from_fn(|i| {
            let (r, x) = (
                &rows[i].as_flattened()[from * N..],
                &x.as_flattened()[from * N..],
            );
            match (r.split_first(), x.split_first()) {
                (Some((r0, r)), Some((x0, x))) => {
                    r.iter().zip(x).fold(*r0 * *x0, |q, (&a, &b)| q + a * b)
                }
                _ => T::zero(),
            }
        })
    }

    fn check<T: Real, const N: usize, const K: usize>() {
        let mut s = 0x2545_f491_4f6c_dd1d_u64 ^ (N * 31 + K) as u64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        };
        let mut next = || T::from_f64_rounded(next());
        let rows: [[[T; N]; K]; N] =
            core::array::from_fn(|_| core::array::from_fn(|_| core::array::from_fn(|_| next())));
        let x: [[T; N]; K] = core::array::from_fn(|_| core::array::from_fn(|_| next()));
        // Every starting block, the whole product (0) to none (K).
        for from in 0..=K {
            let want = serial(&rows, from, &x);
            for w in [0, 16, 32] {
                let stored = layout(rows, w);
                let mut out = [T::one(); N];
                match w {
                    0 => row_pairs(&stored, from, &x, &mut out),
                    16 => {
                        column_blocks_flat::<T, 16>(flat(&stored), N, K, from, flat_x(&x), &mut out)
                    }
                    _ => {
                        column_blocks_flat::<T, 32>(flat(&stored), N, K, from, flat_x(&x), &mut out)
                    }
                }
                for i in 0..N {
                    assert_eq!(
                        out[i].as_f64().to_bits(),
                        want[i].as_f64().to_bits(),
                        "N = {N}, K = {K}, from block {from}, row {i}, blocks of {w} rows"
                    );
                }
            }
        }
    }

    /// Every layout is bit-identical to the serial chain for every remainder of every
    /// block size and every starting block (host and Cortex-M therefore agree bit for
    /// bit: same chains, same order).
    #[test]
    fn both_layouts_sum_rows_in_serial_order() {
        macro_rules! sizes { ($($n:literal)*) => { $(
            check::<f64, $n, 3>(); check::<f32, $n, 3>();
            check::<f64, $n, 2>(); check::<f32, $n, 4>();
        )* } }
        sizes!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 23 24 25 31 32 33 40 47 48 50
            55 56 63 64 65 72 79 80 99 100);
    }

    /// The layout is a permutation: every flat position is hit exactly once.
    #[test]
    fn layout_is_a_permutation() {
        for w in [0, 16, 32] {
            for n in 1..=70 {
                for k in 1..=4 {
                    let mut seen = [false; 4 * 70 * 70];
                    for i in 0..n {
                        for c in 0..k * n {
                            let f = flat_index(n, k, i, c, w);
                            assert!(f < k * n * n && !seen[f], "n = {n}, k = {k}: {f}");
                            seen[f] = true;
                        }
                    }
                }
            }
        }
    }

    /// The AVX and SSE2 paths (`wide_blocks` against the plain loop) give the same bits, for operator sizes above the dispatch
    /// threshold, both block widths, first blocks of every kind, and the product of
    /// every block or all but the first.
    fn same_bits<T: Real, const N: usize, const K: usize, const W: usize>() {
        let mut ops = [[[T::zero(); N]; K]; N];
        let mut x = [[T::zero(); N]; K];
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64 ^ (N * 131 + K) as u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            // Values of mixed sign and magnitude, so every rounding matters.
            let m = (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            T::from_f64_rounded(m * 2f64.powi((seed % 40) as i32 - 20))
        };
        for v in ops.iter_mut().flatten().flatten() {
            *v = next();
        }
        for v in x.iter_mut().flatten() {
            *v = next();
        }
        for from in [0, 1] {
            let (mut plain, mut wide) = ([T::zero(); N], [T::zero(); N]);
            column_blocks_flat::<T, W>(flat(&ops), N, K, from, flat_x(&x), &mut plain);
            wide_blocks::<T, N, K, W>(&ops, from, &x, &mut wide);
            for (p, w) in plain.iter().zip(&wide) {
                assert_eq!(
                    p.as_f64().to_bits(),
                    w.as_f64().to_bits(),
                    "N = {N}, K = {K}, from block {from}"
                );
            }
        }
    }

    #[test]
    fn avx_path_is_bit_identical() {
        // Where the CPU has no AVX both calls run the SSE2 loop (and still must agree).
        same_bits::<f64, 16, 3, 16>();
        same_bits::<f64, 37, 3, 16>();
        same_bits::<f64, 100, 3, 16>();
        same_bits::<f64, 100, 4, 16>();
        same_bits::<f32, 50, 3, 32>();
        same_bits::<f32, 100, 3, 32>();
        same_bits::<f32, 100, 2, 32>();
    }
}
