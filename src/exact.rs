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
//! The shared [`State`] does not carry `p_{n−1}`; it is recovered exactly (in exact
//! arithmetic) from the state, `p_{n−1} = M a_{n−1} + C v_{n−1} + K u_{n−1}`, because this
//! scheme's acceleration always satisfies the equation of motion. The operators are
//! folded so that a step is
//!
//! ```text
//! u_n = A_uu u + A_uv v + A_ua a + B_u p_n,    v_n = A_vu u + A_vv v + A_va a + B_v p_n
//! a_n = M⁻¹ p_n − (M⁻¹C) v_n − (M⁻¹K) u_n
//! ```
//!
//! `11N²` multiply-adds a step. Needs an invertible `M`.

use nalgebra::{ComplexField, SMatrix, SVector};

use crate::linear::{StartOps, initial_state};
use crate::newmark::{check_inputs, mac, round_rows, round_start};
use crate::ops::{self, Mat};
use crate::{Error, Real, State, Stepper};

/// A `4×4` block matrix of `N×N` `f64` blocks.
type Blk<const N: usize> = [[Mat<N>; 4]; 4];

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

fn norm1<const N: usize>(a: &Mat<N>) -> f64 {
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

fn identity<const N: usize>() -> Mat<N> {
    let mut r = [[0.0; N]; N];
    for i in 0..N {
        r[i][i] = 1.0;
    }
    r
}

/// `exp(X)` in place by scaling and squaring a Taylor polynomial (`X` is overwritten).
/// `work` and `out` are scratch; the result is left in `out`.
fn blk_expm<const N: usize>(x: &mut Blk<N>, work: &mut Blk<N>, out: &mut Blk<N>) {
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
    let id: Blk<N> =
        core::array::from_fn(|i| core::array::from_fn(|j| if i == j { identity() } else { z }));
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

/// The exact-discretization stepper (see the module docs).
///
/// Same state, start-up and interface as [`Linear`](crate::Linear); `11N²`
/// multiply-adds a step. Size: `11N² + 1` values of `T` (the `M⁻¹` blocks double as the
/// start-up operators).
///
/// ```
/// use aemstep::{Exact, Stepper};
/// use nalgebra::{matrix, vector};
/// // u'' + 25 u = 0 with a step as long as a third of the period: still exact.
/// let h = 0.4;
/// let sys = Exact::new(&matrix![1.0], &matrix![0.0], &matrix![25.0], h)?;
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
    /// Rows: `[A_uu, A_uv, A_ua, B_u]` then `[A_vu, A_vv, A_va, B_v]`.
    au: [[[T; N]; N]; 4],
    av: [[[T; N]; N]; 4],
    /// `M⁻¹, M⁻¹C, M⁻¹K` (equation of motion, and start-up).
    eom: StartOps<T, N>,
}

impl<T: Real, const N: usize> Exact<T, N> {
    /// Compute the exact step operators for step `h` (s). Computed in `f64`, rounded
    /// once to `T`.
    ///
    /// Errors: [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`],
    /// [`Error::SingularMass`] (`M` singular: the first-order form needs `M⁻¹`).
    ///
    /// Cost: about `(4N)³ (19 + s)` flops, `s = ⌈log₂(2‖hF‖)⌉` squarings (balanced norm,
    /// e.g. `s ≈ 14` for `ω_max h = 10⁴`), and three `16N²` `f64` temporaries on the
    /// stack (`384 KB` at `N = 50`, `1.5 MB` at `N = 100`: use a large stack there).
    pub fn new(
        m: &SMatrix<T, N, N>,
        c: &SMatrix<T, N, N>,
        k: &SMatrix<T, N, N>,
        h: T,
    ) -> Result<Self, Error> {
        let (m, c, k, start) = check_inputs(m, c, k, h)?;
        let st = start.ok_or(Error::SingularMass)?;
        let hf = h.as_f64();
        let (mi, mic, mik) = (&st.minv, &st.minv_c, &st.minv_k);
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
        let id = identity::<N>();
        x[0][1] = ops::add_scaled(&z, hf * d[1] / d[0], &id);
        x[1][0] = ops::add_scaled(&z, -hf * d[0] / d[1], mik);
        x[1][1] = ops::add_scaled(&z, -hf, mic);
        x[1][2] = ops::add_scaled(&z, hf * d[2] / d[1], mi);
        x[2][3] = ops::add_scaled(&z, hf * d[3] / d[2], &id);
        let mut work: Blk<N> = [[z; 4]; 4];
        let mut e: Blk<N> = [[z; 4]; 4];
        blk_expm(&mut x, &mut work, &mut e);
        // Undo the balancing: E_ij = (d_i / d_j) E'_ij, for block rows u, v.
        let blk = |i: usize, j: usize| ops::add_scaled(&z, d[i] / d[j], &e[i][j]);
        let mut au = [[[T::zero(); N]; N]; 4];
        let mut av = [[[T::zero(); N]; N]; 4];
        for (r, out) in [(0usize, &mut au), (1usize, &mut av)] {
            let (phi_u, phi_v, g1, g2) = (blk(r, 0), blk(r, 1), blk(r, 2), blk(r, 3));
            // P0 = Γ₁ − Γ₂/h multiplies p_{n−1} = M a + C v + K u; P1 = Γ₂/h multiplies p_n.
            let p0 = ops::add_scaled(&g1, -1.0 / hf, &g2);
            let p1 = ops::add_scaled(&z, 1.0 / hf, &g2);
            out[0] = round_rows(&ops::add_scaled(&phi_u, 1.0, &ops::mul(&p0, &k)));
            out[1] = round_rows(&ops::add_scaled(&phi_v, 1.0, &ops::mul(&p0, &c)));
            out[2] = round_rows(&ops::mul(&p0, &m));
            out[3] = round_rows(&p1);
        }
        let all_finite = au
            .iter()
            .chain(av.iter())
            .all(|b| b.iter().all(|r| r.iter().all(|x| x.is_finite())));
        if !all_finite {
            return Err(Error::NonFiniteInput);
        }
        Ok(Self {
            h,
            au,
            av,
            eom: round_start(&st),
        })
    }
}

impl<T: Real, const N: usize> Stepper<T, N> for Exact<T, N> {
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
        initial_state(Some(&self.eom), u0, v0, p0)
    }

    /// Cost: `11N²` multiply-adds.
    #[inline]
    fn step(&self, s: &mut State<T, N>, p: &SVector<T, N>) {
        let x: [[T; N]; 4] = [s.u.into(), s.v.into(), s.a.into(), (*p).into()];
        let mut u = [T::zero(); N];
        let mut v = [T::zero(); N];
        for b in 0..4 {
            mac(&mut u, &self.au[b], &x[b]);
            mac(&mut v, &self.av[b], &x[b]);
        }
        let mut a = [T::zero(); N];
        mac(&mut a, &self.eom.minv, &x[3]);
        for i in 0..N {
            let mut acc = a[i];
            for j in 0..N {
                acc -= self.eom.minv_c[i][j] * v[j] + self.eom.minv_k[i][j] * u[j];
            }
            a[i] = acc;
        }
        s.u = u.into();
        s.v = v.into();
        s.a = a.into();
        s.n = s.n.wrapping_add(1);
    }
}
