//! Symmetric eigen-decomposition by cyclic Jacobi rotations, in `const fn` (the modal
//! stepper's eigenproblem is solved by the compiler when its constructor runs in a
//! `static`).

use super::{Rows, sqrt};
use crate::Error;

/// The sweep budget of [`jacobi_eigen`]: far beyond what quadratic convergence needs; a
/// guard, not a tuning knob.
pub(crate) const JACOBI_MAX_SWEEPS: u32 = 64;

/// Eigen-decomposition of a symmetric `a` by cyclic Jacobi rotations: `(λ, V)` with
/// `a V = V diag(λ)`, `V` orthogonal (row-major), unsorted.
///
/// Jacobi rather than `nalgebra::SymmetricEigen`: the latter needs `Const<N>: DimSub<U1>`
/// bounds that a const-generic `N` cannot meet without leaking type-level integers into
/// every caller, and it is not `const`. Jacobi is backward stable, accurate to `O(ε‖a‖)`
/// and converges quadratically (≲ 10 sweeps for `N ≤ 50`); `≈ 4N³` flops a sweep.
/// [`Error::EigenNotConverged`] after `max_sweeps` sweeps (callers pass
/// [`JACOBI_MAX_SWEEPS`]).
pub(crate) const fn jacobi_eigen<const N: usize>(
    mut a: Rows<N>,
    max_sweeps: u32,
) -> Result<([f64; N], Rows<N>), Error> {
    let mut v = [[0.0; N]; N];
    let mut fro2 = 0.0;
    let mut i = 0;
    while i < N {
        v[i][i] = 1.0;
        let mut j = 0;
        while j < N {
            fro2 += a[i][j] * a[i][j];
            j += 1;
        }
        i += 1;
    }
    let fro = sqrt(fro2);
    let mut sweep = 0;
    while sweep < max_sweeps {
        let mut off = 0.0;
        let mut p = 0;
        while p < N {
            let mut q = 0;
            while q < N {
                if p != q {
                    off += a[p][q] * a[p][q];
                }
                q += 1;
            }
            p += 1;
        }
        if sqrt(off) <= f64::EPSILON * fro {
            let mut lam = [0.0; N];
            let mut i = 0;
            while i < N {
                lam[i] = a[i][i];
                i += 1;
            }
            return Ok((lam, v));
        }
        let mut p = 0;
        while p < N {
            let mut q = p + 1;
            while q < N {
                let apq = a[p][q];
                // Below rounding of the diagonal pair: already decoupled.
                if apq.abs() <= 0.25 * f64::EPSILON * sqrt((a[p][p] * a[q][q]).abs()) {
                    a[p][q] = 0.0;
                    a[q][p] = 0.0;
                    q += 1;
                    continue;
                }
                // Rotation zeroing a_pq: cot 2φ = θ, t = tan φ (the smaller root).
                let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
                let t = if theta.abs() > 1e150 {
                    0.5 / theta
                } else {
                    let t = 1.0 / (theta.abs() + sqrt(theta * theta + 1.0));
                    if theta < 0.0 { -t } else { t }
                };
                let c = 1.0 / sqrt(t * t + 1.0);
                let s = t * c;
                // Columns p, q of A and of V in one pass (V does not enter A's update),
                // then rows p, q of A.
                let mut k = 0;
                while k < N {
                    let (akp, akq) = (a[k][p], a[k][q]);
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                    let (vkp, vkq) = (v[k][p], v[k][q]);
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                    k += 1;
                }
                k = 0;
                while k < N {
                    let (apk, aqk) = (a[p][k], a[q][k]);
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                    k += 1;
                }
                // Zeroed by construction; store the exact zero, not its rounding.
                a[p][q] = 0.0;
                a[q][p] = 0.0;
                q += 1;
            }
            p += 1;
        }
        sweep += 1;
    }
    Err(Error::EigenNotConverged)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sweep guard: a matrix that needs rotations fails with `EigenNotConverged` when
    /// the budget is too small, and converges within the real budget.
    #[test]
    fn jacobi_reports_non_convergence_past_its_sweep_budget() {
        let a = [[2.0, 1.0, 0.5], [1.0, 3.0, 0.25], [0.5, 0.25, 4.0]];
        assert_eq!(
            jacobi_eigen(a, 0).map(|_| ()),
            Err(Error::EigenNotConverged)
        );
        assert_eq!(
            jacobi_eigen(a, 1).map(|_| ()),
            Err(Error::EigenNotConverged)
        );
        let (lam, _) = jacobi_eigen(a, JACOBI_MAX_SWEEPS).unwrap();
        // Trace and determinant are invariants: Σλ = 9, Πλ = det a = 19.375.
        assert!((lam.iter().sum::<f64>() - 9.0).abs() < 1e-14);
        assert!((lam.iter().product::<f64>() - 19.375).abs() < 1e-12);
    }
}
