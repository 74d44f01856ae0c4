//! The paper's literal form of the linear step: `U_n = A U_{n−1} + b p_n`,
//! `U = (q, v, u)` (paper eqs. 21–23, Algorithm 1).
//!
//! `A = L⁻¹R` is `3N×3N` and `b = L⁻¹E` is `3N×N`; they are stored as `N×N` blocks
//! (`[T; 3*N]` is not expressible on stable Rust). Block rows and columns are ordered
//! `q, v, u`. Built from a [`Linear`](crate::Linear) by
//! [`Linear::a_form`](crate::Linear::a_form); the blocks follow from the eliminated
//! operators `G, GC, GK` with `α = h/2`, `β = h²/4`:
//!
//! ```text
//! A_qq = −(α GC + β GK)   A_qv = −(GC + h GK)   A_qu = −GK           b_q = G
//! A_vq = α (I + A_qq)     A_vv = I + α A_qv      A_vu = α A_qu        b_v = α G
//! A_uq = β (I + A_qq)     A_uv = h I + β A_qv    A_uu = I + β A_qu    b_u = β G
//! ```
//!
//! A step costs `9N² + 3N² = 12N²` multiply-adds: four times the eliminated form. Its use
//! is as a reference and for inspection (e.g. the spectral radius of `A`).

use nalgebra::{SMatrix, SVector};

use crate::kernel::StartOps;
use crate::linalg::op_rows::OpRows;
use crate::{Real, State, Stepper};

/// The amplification operator `A` and load operator `b` of the linear AEM step, as
/// `N×N` blocks; a [`Stepper`] in its own right (`12N²` multiply-adds a step).
///
/// Size: `12N² + 3N² + 1` values of `T` (the `3N²` are the start-up operators).
#[derive(Clone, Copy, Debug, PartialEq)]
// `repr(C)` with the operator first: every operator load is a small immediate offset.
#[repr(C)]
pub struct AForm<T, const N: usize> {
    /// `rows[r]`, row `i`: `[A_r0[i], A_r1[i], A_r2[i], b_r[i]]`, row `i` of block row `r`
    /// (0 = q, 1 = v, 2 = u) of `[A | b]`, `4N` values that multiply `(q, v, u, p)`; in
    /// the target's layout.
    rows: [OpRows<T, N, 4>; 3],
    h: T,
    start: Option<StartOps<T, N>>,
}

impl<T: Real, const N: usize> AForm<T, N> {
    pub(crate) fn from_operators(
        h: T,
        g: &[[T; N]; N],
        gc: &[[T; N]; N],
        gk: &[[T; N]; N],
        start: Option<StartOps<T, N>>,
    ) -> Self {
        let two = T::one() + T::one();
        let alpha = h / two;
        let beta = h * h / (two * two);
        let z = [[T::zero(); N]; N];
        let mut a = [[z; 3]; 3];
        let mut b = [z; 3];
        for i in 0..N {
            for j in 0..N {
                let id = if i == j { T::one() } else { T::zero() };
                let qq = -(alpha * gc[i][j] + beta * gk[i][j]);
                let qv = -(gc[i][j] + h * gk[i][j]);
                let qu = -gk[i][j];
                a[0][0][i][j] = qq;
                a[0][1][i][j] = qv;
                a[0][2][i][j] = qu;
                a[1][0][i][j] = alpha * (id + qq);
                a[1][1][i][j] = id + alpha * qv;
                a[1][2][i][j] = alpha * qu;
                a[2][0][i][j] = beta * (id + qq);
                a[2][1][i][j] = h * id + beta * qv;
                a[2][2][i][j] = id + beta * qu;
                b[0][i][j] = g[i][j];
                b[1][i][j] = alpha * g[i][j];
                b[2][i][j] = beta * g[i][j];
            }
        }
        let rows = core::array::from_fn(|r| {
            OpRows::new(core::array::from_fn(|i| {
                [a[r][0][i], a[r][1][i], a[r][2][i], b[r][i]]
            }))
        });
        Self { rows, h, start }
    }

    /// Block `A_{rc}` (`r, c` in `0..3`: 0 = q, 1 = v, 2 = u), or `None` if out of range.
    pub fn a_block(&self, r: usize, c: usize) -> Option<SMatrix<T, N, N>> {
        if c >= 3 {
            return None; // the 4th column block of `rows` is b
        }
        let blk = self.rows.get(r)?;
        Some(SMatrix::from_fn(|i, j| blk.get(i, c, j)))
    }

    /// Every entry of every block is finite.
    pub(crate) fn is_finite(&self) -> bool {
        self.rows.iter().all(|r| r.all_finite())
    }

    /// Block `b_r` (`r` in `0..3`), or `None` if out of range.
    pub fn b_block(&self, r: usize) -> Option<SMatrix<T, N, N>> {
        let blk = self.rows.get(r)?;
        Some(SMatrix::from_fn(|i, j| blk.get(i, 3, j)))
    }
}

impl<T: Real, const N: usize> Stepper<T, N> for AForm<T, N> {
    type Input = SVector<T, N>;
    type State = State<T, N>;

    fn time_step(&self) -> T {
        self.h
    }

    crate::stepper::full_order_state!(start);

    /// Cost: `12N²` multiply-adds.
    #[inline]
    fn step(&self, s: &mut State<T, N>, p: &SVector<T, N>) {
        let x = [s.a.into(), s.v.into(), s.u.into(), (*p).into()];
        let mut new = [[T::zero(); N]; 3];
        for (rows, out) in self.rows.iter().zip(new.iter_mut()) {
            rows.mat_vec(&x, out);
        }
        let [a, v, u] = new;
        s.a = a.into();
        s.v = v.into();
        s.u = u.into();
        s.n = s.n.wrapping_add(1);
    }
}
