//! The matrix exponential of a `4×4` block matrix of `N×N` blocks (the Van Loan
//! augmented matrix of the exact scheme), by scaling and squaring a Taylor polynomial.
//! Run time only (`f64`).

use super::{Mat, identity};

/// A `4×4` block matrix of `N×N` `f64` blocks.
pub(crate) type Blk<const N: usize> = [[Mat<N, N>; 4]; 4];

const TAYLOR_DEGREE: u32 = 18;

fn blk_mul<const N: usize>(a: &Blk<N>, b: &Blk<N>, out: &mut Blk<N>) {
    for bi in 0..4 {
        for bj in 0..4 {
            let o = &mut out[bi][bj];
            *o = [[0.0; N]; N];
            for bk in 0..4 {
                let (x, y) = (&a[bi][bk], &b[bk][bj]);
                for i in 0..N {
                    for k in 0..N {
                        let xik = x[i][k];
                        if xik != 0.0 {
                            for j in 0..N {
                                o[i][j] += xik * y[k][j];
                            }
                        }
                    }
                }
            }
        }
    }
}

/// Max column sum (1-norm) of the full `4N×4N` matrix.
fn blk_norm1<const N: usize>(a: &Blk<N>) -> f64 {
    let mut best = 0.0f64;
    for bj in 0..4 {
        for j in 0..N {
            let mut s = 0.0;
            for bi in 0..4 {
                for i in 0..N {
                    s += a[bi][bj][i][j].abs();
                }
            }
            best = best.max(s);
        }
    }
    best
}

pub(crate) fn norm1<const N: usize>(a: &Mat<N, N>) -> f64 {
    let mut best = 0.0f64;
    for j in 0..N {
        let mut s = 0.0;
        for i in 0..N {
            s += a[i][j].abs();
        }
        best = best.max(s);
    }
    best
}

/// `exp(X)` in place by scaling and squaring a Taylor polynomial (`X` is overwritten).
/// `work` and `out` are scratch; the result is left in `out`.
pub(crate) fn blk_expm<const N: usize>(x: &mut Blk<N>, work: &mut Blk<N>, out: &mut Blk<N>) {
    let theta = blk_norm1(x);
    // Smallest s with θ/2^s ≤ 1/2: the Taylor remainder is then below 0.5^19/19! ≈ 2e-23.
    let mut squarings = 0u32;
    let mut scaled = theta;
    while scaled > 0.5 && squarings < 1100 {
        scaled *= 0.5;
        squarings += 1;
    }
    let mut f = 1.0;
    for _ in 0..squarings {
        f *= 0.5; // exact: a power of two
    }
    for row in x.iter_mut() {
        for b in row.iter_mut() {
            *b = b.map(|r| r.map(|v| v * f));
        }
    }
    // Horner: E = I + X/1 (I + X/2 (I + … (I + X/d))).
    let z = [[0.0; N]; N];
    let id: Blk<N> = core::array::from_fn(|i| {
        core::array::from_fn(|j| if i == j { identity::<N>() } else { z })
    });
    *out = id;
    for d in (1..=TAYLOR_DEGREE).rev() {
        blk_mul(x, out, work);
        let inv = 1.0 / d as f64;
        for bi in 0..4 {
            for bj in 0..4 {
                for i in 0..N {
                    for j in 0..N {
                        let idv = if bi == bj && i == j { 1.0 } else { 0.0 };
                        out[bi][bj][i][j] = idv + inv * work[bi][bj][i][j];
                    }
                }
            }
        }
    }
    for _ in 0..squarings {
        blk_mul(out, out, work);
        core::mem::swap(out, work);
    }
}
