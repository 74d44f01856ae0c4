//! The step kernel of the constant-coefficient Newmark family (the AEM and
//! [`Newmark`](crate::Newmark)), and the blocked matrix–vector products it runs on.
//!
//! Operators are rows `[G[i], −GC[i], −GK[i]]` with `G = (M + γh C + βh² K)⁻¹`, each
//! multiplying `x = (p, v̂, û)` as one multiply-accumulate chain; stored in the target's
//! layout ([`OpRows`]).

use nalgebra::SVector;

use crate::kinematics::{AemKinematics, Kinematics, NewmarkKinematics, check_time_step_as};
use crate::linalg::lu::{Lu, condition_flat, factor, row_scales_flat, solve_flat};
use crate::linalg::op_rows::OpRows;
use crate::linalg::{
    Mat, add_scaled_flat, all_finite, all_finite_flat, copy_flat, first_error, fits_flat, identity,
    round_rows, rows_f64,
};
use crate::scalar::initial_inputs_finite;
use crate::{Error, Param, Real, State};

/// The operators of a constant-coefficient Newmark-family stepper, rounded to `T`: the
/// storage of [`Linear`](crate::Linear) (β = 1/4, γ = 1/2) and
/// [`Newmark`](crate::Newmark).
#[derive(Clone, Copy, Debug, PartialEq)]
// `repr(C)` with `ops` first: the step addresses every operator value as a small
// immediate offset from `self` (Thumb-2 `vldr` reaches ±1020 bytes).
#[repr(C)]
pub(crate) struct Kernel<T, const N: usize, K> {
    /// Row `i`: `[G[i], −GC[i], −GK[i]]` (negation is exact), in the target's layout.
    pub ops: OpRows<T, N, 3>,
    /// [`AemKinematics`] or [`NewmarkKinematics`].
    pub kin: K,
    pub start: Option<StartOps<T, N>>,
    /// `κ₁` of the row-equilibrated effective matrix ([`condition_flat`]).
    pub condition: f64,
}

impl<const N: usize> KernelOps<N> {
    /// The kernel with every operator rounded once to `T` (run time), with the given
    /// kinematics (already rounded).
    pub(crate) fn round<T: Real, K>(&self, kin: K) -> Kernel<T, N, K> {
        let one = T::one();
        let (g, gc, gk) = (
            round_rows(&self.g),
            round_rows(&self.gc),
            round_rows(&self.gk),
        );
        Kernel {
            ops: interleave([&g, &gc, &gk], [one, -one, -one]),
            kin,
            start: self.start.as_ref().map(|(_, s)| s.round()),
            condition: self.condition,
        }
    }

    /// The AEM kernel (β = 1/4, γ = 1/2), rounded to `T`.
    pub(crate) fn round_aem<T: Real>(&self) -> Kernel<T, N, AemKinematics<T>> {
        self.round(self.aem.round())
    }

    /// The general Newmark kernel, rounded to `T`.
    pub(crate) fn round_newmark<T: Real>(&self) -> Kernel<T, N, NewmarkKinematics<T>> {
        self.round(self.kin.round())
    }
}

impl<T: Real, const N: usize> Kernel<T, N, AemKinematics<T>> {
    /// The AEM kernel of `M, C, K, h` (run time; bit-identical to `from_rows_aem`): the
    /// one build behind `Linear::new` and `CompensatedLinear::new`.
    pub(crate) fn aem(
        m: &nalgebra::SMatrix<f64, N, N>,
        c: &nalgebra::SMatrix<f64, N, N>,
        k: &nalgebra::SMatrix<f64, N, N>,
        h: f64,
    ) -> Result<Self, Error> {
        let (m, c, k) = (rows_f64(m), rows_f64(c), rows_f64(k));
        Ok(newmark_operators(&m, &c, &k, h, 0.25, 0.5, T::MAX)?.round_aem())
    }
}

impl<T: Real, const N: usize, K> Kernel<T, N, K> {
    /// `G = M_eff⁻¹`, `N×N`. Cost: `N²` reads.
    pub(crate) fn effective_inverse(&self) -> nalgebra::SMatrix<T, N, N> {
        nalgebra::SMatrix::from_fn(|i, j| self.ops.get(i, 0, j))
    }
}

/// `Kernel::<f32, N, AemKinematics<f32>>::from_ops` (and `f64`): the `const` twin of
/// [`KernelOps::round_aem`], for the `const fn` constructors (bit-identical to it); and
/// the `const` twin, per scalar, of the start-up rounding every scheme's `const fn` shares
/// (`StartOps::rounded`).
macro_rules! const_kernel {
    ($t:ident) => {
        impl<const N: usize> Kernel<$t, N, AemKinematics<$t>> {
            /// The AEM kernel of `M, C, K, h` (`const`): the checks and operators of
            /// [`newmark_operators`] with β = 1/4, γ = 1/2, rounded once (the one build
            /// behind `Linear::from_rows_f32`/`_f64` and `CompensatedLinear::from_rows_f32`/`_f64`).
            pub(crate) const fn from_rows_aem(
                m: &Mat<N, N>,
                c: &Mat<N, N>,
                k: &Mat<N, N>,
                h: f64,
            ) -> Result<Self, Error> {
                match newmark_operators(m, c, k, h, 0.25, 0.5, $t::MAX as f64) {
                    Ok(op) => Ok(Self::from_ops(&op)),
                    Err(e) => Err(e),
                }
            }

            pub(crate) const fn from_ops(op: &KernelOps<N>) -> Self {
                let (g, gc, gk) = (
                    crate::linalg::const_round!($t, rows op.g),
                    crate::linalg::const_round!($t, rows op.gc),
                    crate::linalg::const_round!($t, rows op.gk),
                );
                let mut ops = [[[0.0; N]; 3]; N];
                let mut i = 0;
                while i < N {
                    let mut j = 0;
                    while j < N {
                        ops[i][0][j] = g[i][j];
                        ops[i][1][j] = -gc[i][j];
                        ops[i][2][j] = -gk[i][j];
                        j += 1;
                    }
                    i += 1;
                }
                Self {
                    ops: OpRows::new(ops),
                    kin: crate::linalg::const_round!($t, kin op.aem),
                    start: match &op.start {
                        Some((_, s)) => Some(StartOps::<$t, N>::rounded(s)),
                        None => None,
                    },
                    condition: op.condition,
                }
            }
        }

        impl<const N: usize> StartOps<$t, N> {
            /// The `const` twin of [`StartOps::round`]: each operator rounded once to the
            /// scalar (bit-identical to it). Cost: `3N²` conversions.
            pub(crate) const fn rounded(s: &StartOps<f64, N>) -> Self {
                Self {
                    minv: crate::linalg::const_round!($t, rows s.minv),
                    minv_c: crate::linalg::const_round!($t, rows s.minv_c),
                    minv_k: crate::linalg::const_round!($t, rows s.minv_k),
                }
            }
        }
    };
}
const_kernel!(f32);
const_kernel!(f64);

/// The `const fn` twins `from_rows_f32` / `from_rows_f64` and the `const` `time_step` of a
/// scheme stored as `{ kernel: Kernel<T, N, AemKinematics<T>> }`
/// ([`Linear`](crate::Linear), [`CompensatedLinear`](crate::CompensatedLinear)): one
/// build, [`Kernel::from_rows_aem`], behind both scalars and both schemes; each scheme
/// passes the docs of its `from_rows_*`.
macro_rules! aem_const_ctors {
    ($scheme:ident, $(#[$doc:meta])*) => {
        $crate::kernel::aem_const_ctors!(@one $scheme, f32, from_rows_f32, $(#[$doc])*);
        $crate::kernel::aem_const_ctors!(@one $scheme, f64, from_rows_f64, $(#[$doc])*);
    };
    (@one $scheme:ident, $t:ident, $from_rows:ident, $(#[$doc:meta])*) => {
        impl<const N: usize> $scheme<$t, N> {
            $(#[$doc])*
            pub const fn $from_rows(
                m: $crate::linalg::Rows<N>,
                c: $crate::linalg::Rows<N>,
                k: $crate::linalg::Rows<N>,
                h: f64,
            ) -> Result<Self, $crate::Error> {
                type K<T> = $crate::kinematics::AemKinematics<T>;
                match $crate::kernel::Kernel::<$t, N, K<$t>>::from_rows_aem(&m, &c, &k, h) {
                    Ok(kernel) => Ok(Self { kernel }),
                    Err(e) => Err(e),
                }
            }

            /// The time step `h` (s), usable in `const` contexts: the same value as
            /// [`Stepper::time_step`](crate::Stepper::time_step), which generic code (`S:
            /// Stepper<T, N>`) still calls. Cost: none.
            pub const fn time_step(&self) -> $t {
                self.kernel.kin.h
            }
        }
    };
}
pub(crate) use aem_const_ctors;

/// `impl Stepper` for a scheme stored as `{ kernel: Kernel<T, N, K> }`
/// ([`Linear`](crate::Linear), [`Newmark`](crate::Newmark)).
macro_rules! kernel_stepper {
    ($scheme:ident) => {
        impl<T: $crate::Real, const N: usize> $crate::Stepper<T, N> for $scheme<T, N> {
            type Input = nalgebra::SVector<T, N>;
            type State = $crate::State<T, N>;

            #[inline]
            fn time_step(&self) -> T {
                $crate::kinematics::Kinematics::h(&self.kernel.kin)
            }

            /// Cost: `3N²` multiply-adds + `7N` (the kernel module's `newmark_step`).
            #[inline]
            fn step(&self, s: &mut $crate::State<T, N>, p: &nalgebra::SVector<T, N>) {
                $crate::kernel::newmark_step(&self.kernel.ops, &self.kernel.kin, s, p);
            }

            $crate::stepper::full_order_state!(kernel.start);
        }

        impl<T: $crate::Real, const N: usize> $scheme<T, N> {
            /// How close the effective matrix `M + γh C + βh² K` is to singular: `κ₁` of
            /// the row-equilibrated matrix (each row divided by the size of the terms it
            /// was assembled from), computed once in `f64` from the matrix and its
            /// inverse. About `log₁₀ κ` of the 16 digits of `f64` (7 of `f32`) are lost
            /// in the operators; a matrix with `κ ≳ 1/(N ε)` is rejected as
            /// [`Error::SingularEffectiveMatrix`](crate::Error::SingularEffectiveMatrix).
            /// Cost: O(1).
            pub fn condition(&self) -> f64 {
                self.kernel.condition
            }
        }
    };
}
pub(crate) use kernel_stepper;

/// One step of the Newmark family in eliminated form over interleaved operator rows:
///
/// ```text
/// (v̂, û) = predict(u, v, a)       q = G p − GC v̂ − GK û       (v, u) = correct(v̂, û, q)
/// ```
///
/// Cost: `3N²` multiply-adds + `7N`; branch-free, panic-free.
#[inline(always)]
pub(crate) fn newmark_step<T: Real, const N: usize, K: Kinematics<T>>(
    ops: &OpRows<T, N, 3>,
    kin: &K,
    s: &mut State<T, N>,
    p: &SVector<T, N>,
) {
    // x = (p, v̂, û): the vector every interleaved operator row multiplies.
    let mut x = [[T::zero(); N]; 3];
    for j in 0..N {
        x[0][j] = p[j];
        (x[1][j], x[2][j]) = kin.predict(s.u[j], s.v[j], s.a[j]);
    }
    ops.mat_vec(&x, s.a.as_mut_slice());
    // A separate pass with constant indices (once unrolled), so v̂, û are used straight
    // from registers.
    for j in 0..N {
        (s.v[j], s.u[j]) = kin.correct(x[1][j], x[2][j], s.a[j]);
    }
    s.n = s.n.wrapping_add(1);
}

/// The rounding errors a compensated step carries with the state: `u + du`, `v + dv` is
/// the state to about twice the working precision.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Lows<T, const N: usize> {
    pub du: SVector<T, N>,
    pub dv: SVector<T, N>,
}

/// `(s, e)` with `s = fl(a + b)` and `s + e = a + b` exactly (Knuth's two-sum: 6 adds, no
/// branch, any magnitudes).
#[inline(always)]
pub(crate) fn two_sum<T: Real>(a: T, b: T) -> (T, T) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// [`newmark_step`] with every addition to the state compensated: the predictor's and the
/// corrector's additions to `v` and `u` are made by [`two_sum`], and their rounding
/// errors go where the exact arithmetic would put them. Those of the predictor `(v̂, û)`
/// enter `q` through the operators (`−GC e_v̂ − GK e_û`, so `q` is consistent with the
/// unrounded predictor), those of the corrector are carried in `lo` to the next step:
///
/// ```text
/// v̂ + e_v̂ = v + ((1 − γ)h a + dv)           û + e_û = u + (h v̂ − c_u a + h e_v̂ + du)
/// q = G p − GC v̂ − GK û − (GC e_v̂ + GK e_û)
/// v_n + dv' = v̂ + (γh q + e_v̂)               u_n + du' = û + (βh² q + e_û)
/// ```
///
/// Cost: [`newmark_step`]'s `3N²` multiply-adds, plus `2N²` (the errors through `GC`,
/// `GK`) and about `34N` (four two-sums and the increments per degree of freedom);
/// branch-free, panic-free.
#[inline(always)]
pub(crate) fn newmark_step_compensated<T: Real, const N: usize, K: Kinematics<T>>(
    ops: &OpRows<T, N, 3>,
    kin: &K,
    s: &mut State<T, N>,
    lo: &mut Lows<T, N>,
    p: &SVector<T, N>,
) {
    let mut x = [[T::zero(); N]; 3];
    // The predictor's rounding errors (e_v̂, e_û) in blocks 1 and 2 (block 0 is not read).
    let mut e = [[T::zero(); N]; 3];
    for j in 0..N {
        x[0][j] = p[j];
        let a = s.a[j];
        (x[1][j], e[1][j]) = two_sum(s.v[j], kin.c_v() * a + lo.dv[j]);
        let du = (kin.h() * x[1][j] - kin.c_u() * a) + (kin.h() * e[1][j] + lo.du[j]);
        (x[2][j], e[2][j]) = two_sum(s.u[j], du);
    }
    let mut q = [T::zero(); N];
    ops.mat_vec(&x, &mut q);
    // −GC e_v̂ − GK e_û (the stored blocks are already negated), by the same product.
    let mut q_lo = [T::zero(); N];
    ops.mat_vec_from(1, &e, &mut q_lo);
    for j in 0..N {
        let qj = q[j] + q_lo[j];
        (s.v[j], lo.dv[j]) = two_sum(x[1][j], kin.gamma_h() * qj + e[1][j]);
        (s.u[j], lo.du[j]) = two_sum(x[2][j], kin.beta_h2() * qj + e[2][j]);
        s.a[j] = qj;
    }
    s.n = s.n.wrapping_add(1);
}

/// One AEM step with the load through an influence matrix, `q = (GB) w − GC v̂ − GK û`
/// ([`LinearInput`](crate::LinearInput)): `gb` is `N×I`, `ops[i] = [−GC[i], −GK[i]]`.
///
/// Cost: `2N² + N·I` multiply-adds + `7N`; branch-free, panic-free.
#[inline(always)]
pub(crate) fn input_step<T: Real, const N: usize, const I: usize, K: Kinematics<T>>(
    gb: &[[T; I]; N],
    ops: &OpRows<T, N, 2>,
    kin: &K,
    s: &mut State<T, N>,
    w: &SVector<T, I>,
) {
    let mut x = [[T::zero(); N]; 2];
    for j in 0..N {
        (x[0][j], x[1][j]) = kin.predict(s.u[j], s.v[j], s.a[j]);
    }
    ops.mat_vec(&x, s.a.as_mut_slice());
    for j in 0..N {
        let mut q = s.a[j];
        for k in 0..I {
            q += gb[j][k] * w[k];
        }
        s.a[j] = q;
        (s.v[j], s.u[j]) = kin.correct(x[0][j], x[1][j], q);
    }
    s.n = s.n.wrapping_add(1);
}

/// `y = A x` for a row-major `A` (`R×C`). `R·C` multiply-adds.
#[inline(always)]
pub(crate) fn mat_vec<T: Real, const R: usize, const C: usize>(
    a: &[[T; C]; R],
    x: &SVector<T, C>,
) -> SVector<T, R> {
    SVector::from_fn(|i, _| dot(&a[i], x.as_slice()))
}

/// `Σ a_j x_j`, from zero, in index order (over the common length): one row of
/// [`mat_vec`], and of the run-time-sized start (`std`). `len` multiply-adds.
#[inline(always)]
pub(crate) fn dot<T: Real>(a: &[T], x: &[T]) -> T {
    let mut s = T::zero();
    for (&a, &x) in a.iter().zip(x) {
        s += a * x;
    }
    s
}

/// Row `i`: `[s_0 A_0[i], …, s_{K−1} A_{K−1}[i]]` (e.g. `[G[i], −GC[i], −GK[i]]`), in the
/// target's layout: the storage of the kernel's operators.
pub(crate) fn interleave<T: Real, const N: usize, const K: usize>(
    blocks: [&[[T; N]; N]; K],
    signs: [T; K],
) -> OpRows<T, N, K> {
    OpRows::new(core::array::from_fn(|i| {
        core::array::from_fn(|b| blocks[b][i].map(|x| signs[b] * x))
    }))
}

/// Operators for the start-up acceleration `q0 = M⁻¹ p0 − (M⁻¹C) v0 − (M⁻¹K) u0`
/// (paper eq. 40).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct StartOps<T, const N: usize> {
    pub minv: [[T; N]; N],
    pub minv_c: [[T; N]; N],
    pub minv_k: [[T; N]; N],
}

impl<const N: usize> StartOps<f64, N> {
    /// Rounded once to `T` (run time).
    pub(crate) fn round<T: Real>(&self) -> StartOps<T, N> {
        StartOps {
            minv: round_rows(&self.minv),
            minv_c: round_rows(&self.minv_c),
            minv_k: round_rows(&self.minv_k),
        }
    }
}

/// The factorization of `M` and the `StartOps` of `(M, C, K)`; `None` when `M` is singular to working
/// precision. Errors: [`Error::OperatorOverflow`] if an operator is not finite or exceeds
/// `max` (the largest finite value of the scalar type it will be rounded to).
pub(crate) const fn start_operators<const N: usize>(
    m: &Mat<N, N>,
    c: &Mat<N, N>,
    k: &Mat<N, N>,
    max: f64,
) -> Result<Option<(Lu<N>, StartOps<f64, N>)>, Error> {
    let mut arrays = StartArrays::<N>::new();
    let ident = identity::<N>();
    match start_operators_flat(
        &Terms::of(m, c, k),
        ident.as_flattened(),
        max,
        &mut arrays.buffers(),
    ) {
        Ok(regular) => Ok(arrays.finish(regular)),
        Err(e) => Err(e),
    }
}

/// The arrays of one factorization of a const-generic build, lent as [`Factored`].
pub(crate) struct FactorArrays<const N: usize> {
    a: Mat<N, N>,
    lu: Mat<N, N>,
    scales: [f64; N],
    pivot_scales: [f64; N],
    perm: [usize; N],
}

impl<const N: usize> FactorArrays<N> {
    const fn new() -> Self {
        Self {
            a: [[0.0; N]; N],
            lu: [[0.0; N]; N],
            scales: [0.0; N],
            pivot_scales: [0.0; N],
            perm: [0; N],
        }
    }

    const fn factored(&mut self) -> Factored<'_> {
        Factored {
            a: self.a.as_flattened_mut(),
            scales: &mut self.scales,
            lu: self.lu.as_flattened_mut(),
            pivot_scales: &mut self.pivot_scales,
            perm: &mut self.perm,
        }
    }
}

/// The arrays of [`start_operators`], lent as [`StartBuffers`].
pub(crate) struct StartArrays<const N: usize> {
    f: FactorArrays<N>,
    ops: StartOps<f64, N>,
}

impl<const N: usize> StartArrays<N> {
    const fn new() -> Self {
        let z = [[0.0; N]; N];
        Self {
            f: FactorArrays::new(),
            ops: StartOps {
                minv: z,
                minv_c: z,
                minv_k: z,
            },
        }
    }

    const fn buffers(&mut self) -> StartBuffers<'_> {
        StartBuffers {
            f: self.f.factored(),
            minv: self.ops.minv.as_flattened_mut(),
            minv_c: self.ops.minv_c.as_flattened_mut(),
            minv_k: self.ops.minv_k.as_flattened_mut(),
        }
    }

    /// The factorization of `M` and the operators, if `M` is `regular`.
    const fn finish(self, regular: bool) -> Option<(Lu<N>, StartOps<f64, N>)> {
        if regular {
            Some((Lu::from_parts(self.f.lu, self.f.perm), self.ops))
        } else {
            None
        }
    }
}

/// The output buffers of [`start_operators_flat`]: the factorization of `M` and the
/// row-major `n×n` `M⁻¹`, `M⁻¹C`, `M⁻¹K`.
pub(crate) struct StartBuffers<'a> {
    pub f: Factored<'a>,
    pub minv: &'a mut [f64],
    pub minv_c: &'a mut [f64],
    pub minv_k: &'a mut [f64],
}

/// [`start_operators`] into the buffers `b` (`ident`: the `n×n` identity): the one
/// start-up build of both sizes. `Ok(false)` when `M` is singular to working precision.
/// Errors: as [`start_operators`].
pub(crate) const fn start_operators_flat(
    t: &Terms<'_>,
    ident: &[f64],
    max: f64,
    b: &mut StartBuffers<'_>,
) -> Result<bool, Error> {
    let n = b.f.perm.len();
    copy_flat(b.f.a, t.m);
    row_scales_flat(t.m, b.f.scales);
    if !b.f.factor() {
        return Ok(false);
    }
    b.f.solve(ident, n, b.minv);
    b.f.solve(t.c, n, b.minv_c);
    b.f.solve(t.k, n, b.minv_k);
    // Overflow anywhere before underflow anywhere (the same verdict whatever the order).
    let fit = [
        fits_flat(b.minv, t.m, max),
        fits_flat(b.minv_c, t.c, max),
        fits_flat(b.minv_k, t.k, max),
    ];
    match first_error(fit) {
        Some(e) => Err(e),
        None => Ok(true),
    }
}

/// The `f64` operators of the Newmark-family kernel: `G = M_eff⁻¹`, `G C`, `G K` with
/// `M_eff = M + γh C + βh² K`, the kinematics, and the start-up operators.
pub(crate) struct KernelOps<const N: usize> {
    pub g: Mat<N, N>,
    pub gc: Mat<N, N>,
    pub gk: Mat<N, N>,
    /// The kinematics of (β, γ), and of the AEM (used when β = 1/4, γ = 1/2).
    pub kin: NewmarkKinematics<f64>,
    pub aem: AemKinematics<f64>,
    /// The factorization of `M_eff`, for further solves (e.g. `G B`).
    pub lu: Lu<N>,
    /// `κ₁` of the row-equilibrated `M_eff` ([`condition_flat`]).
    pub condition: f64,
    /// The factorization of `M` (if regular) and the start-up operators.
    pub start: Option<(Lu<N>, StartOps<f64, N>)>,
}

/// The row scales of `M + wc C + wk K`: for each row, the largest
/// `|M_ij| + |wc|·|C_ij| + |wk|·|K_ij|`, the size of the terms the row is assembled from
/// (a row that cancels to rounding noise is singular, see [`Lu::new`]).
pub(crate) const fn terms_scales<const N: usize>(
    m: &Mat<N, N>,
    c: &Mat<N, N>,
    k: &Mat<N, N>,
    wc: f64,
    wk: f64,
) -> [f64; N] {
    let mut s = [0.0f64; N];
    terms_scales_flat(&Terms::of(m, c, k), wc, wk, &mut s);
    s
}

/// Row-major `n×n` `M, C, K` as flat slices: the data of an operator build of any size.
pub(crate) struct Terms<'a> {
    pub m: &'a [f64],
    pub c: &'a [f64],
    pub k: &'a [f64],
}

impl<'a> Terms<'a> {
    /// The const-generic arrays, flattened.
    pub(crate) const fn of<const N: usize>(
        m: &'a Mat<N, N>,
        c: &'a Mat<N, N>,
        k: &'a Mat<N, N>,
    ) -> Self {
        Self {
            m: m.as_flattened(),
            c: c.as_flattened(),
            k: k.as_flattened(),
        }
    }
}

/// [`terms_scales`] into `s` (`n = s.len()`): the one loop both sizes use.
pub(crate) const fn terms_scales_flat(t: &Terms<'_>, wc: f64, wk: f64, s: &mut [f64]) {
    let n = s.len();
    let mut i = 0;
    while i < n {
        s[i] = 0.0;
        let mut j = 0;
        while j < n {
            let x = i * n + j;
            let t = t.m[x].abs() + wc.abs() * t.c[x].abs() + wk.abs() * t.k[x].abs();
            if t > s[i] {
                s[i] = t;
            }
            j += 1;
        }
        i += 1;
    }
}

/// The range verdict of an operator build: the [`fits`] checks of its operators `fit` and
/// whether its scalar coefficients fit (`coefficients_fit`, e.g. the kinematics'). An
/// operator's overflow first, then a coefficient's overflow ([`Error::OperatorOverflow`]
/// both), then an operator's underflow — overflow anywhere before underflow anywhere,
/// whatever the order of the checks (`const fn`). Cost: `L` comparisons.
pub(crate) const fn range_verdict<const L: usize>(
    fit: [Result<(), Error>; L],
    coefficients_fit: bool,
) -> Result<(), Error> {
    match first_error(fit) {
        Some(Error::OperatorOverflow) => Err(Error::OperatorOverflow),
        _ if !coefficients_fit => Err(Error::OperatorOverflow),
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// The effective matrix `M_eff = M + wc C + wk K` of an implicit scheme (`m` already
/// weighted where the scheme weights it), checked finite, with the row scales of its terms
/// ([`terms_scales`]) and its factorization: the one effective-matrix build of the Newmark
/// family, generalized-α and KR-α (`const fn`).
///
/// Errors: [`Error::OperatorOverflow`] (`M_eff` not finite),
/// [`Error::SingularEffectiveMatrix`] (singular to working precision against its terms).
/// Cost: `N³/3` flops for the LU and `O(N²)`.
pub(crate) const fn effective_lu<const N: usize>(
    m: &Mat<N, N>,
    c: &Mat<N, N>,
    k: &Mat<N, N>,
    wc: f64,
    wk: f64,
) -> Result<(Mat<N, N>, [f64; N], Lu<N>), Error> {
    let mut f = FactorArrays::<N>::new();
    match effective_lu_flat(&Terms::of(m, c, k), wc, wk, &mut f.factored()) {
        Ok(()) => Ok((f.a, f.scales, Lu::from_parts(f.lu, f.perm))),
        Err(e) => Err(e),
    }
}

/// A row-major `n×n` matrix (`a`), the row scales of its terms, and its factorization
/// ([`factor`]: `lu`, the permuted scales, `perm`): the output buffers of one
/// factorization of an operator build of any size (`n = perm.len()`).
pub(crate) struct Factored<'a> {
    pub a: &'a mut [f64],
    pub scales: &'a mut [f64],
    pub lu: &'a mut [f64],
    pub pivot_scales: &'a mut [f64],
    pub perm: &'a mut [usize],
}

impl Factored<'_> {
    /// Factorize `a` with `scales` into `lu` ([`factor`]); `false` if singular to working
    /// precision.
    const fn factor(&mut self) -> bool {
        copy_flat(self.lu, self.a);
        copy_flat(self.pivot_scales, self.scales);
        factor(self.lu, self.perm.len(), self.pivot_scales, self.perm)
    }

    /// `x = A⁻¹ B` (`B` row-major `n×c`) by the factors ([`solve_flat`]).
    pub(crate) const fn solve(&self, b: &[f64], c: usize, x: &mut [f64]) {
        solve_flat(self.lu, self.perm, b, c, x);
    }
}

/// [`effective_lu`] into the buffers `f` (`n = f.perm.len()`): the one effective-matrix
/// build of both sizes. Errors: as [`effective_lu`].
pub(crate) const fn effective_lu_flat(
    t: &Terms<'_>,
    wc: f64,
    wk: f64,
    f: &mut Factored<'_>,
) -> Result<(), Error> {
    // (M + wc C) + wk K, entry by entry.
    copy_flat(f.a, t.m);
    add_scaled_flat(f.a, wc, t.c);
    add_scaled_flat(f.a, wk, t.k);
    if !all_finite_flat(f.a) {
        return Err(Error::OperatorOverflow);
    }
    terms_scales_flat(t, wc, wk, f.scales);
    if f.factor() {
        Ok(())
    } else {
        Err(Error::SingularEffectiveMatrix)
    }
}

/// Check `M, C, K, h, β, γ` and build the kernel's operators by factorizing `M_eff` and
/// solving (paper eqs. 19–23 in eliminated form for β = 1/4, γ = 1/2). `max`: the
/// largest finite value of the scalar type the operators will be rounded to.
///
/// Errors: [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`],
/// [`Error::InvalidParameter`] (β or γ negative or not finite),
/// [`Error::SingularEffectiveMatrix`], [`Error::OperatorOverflow`],
/// [`Error::OperatorUnderflow`].
pub(crate) const fn newmark_operators<const N: usize>(
    m: &Mat<N, N>,
    c: &Mat<N, N>,
    k: &Mat<N, N>,
    h: f64,
    beta: f64,
    gamma: f64,
    max: f64,
) -> Result<KernelOps<N>, Error> {
    let z = [[0.0; N]; N];
    let (mut eff, mut g, mut gc, mut gk) = (FactorArrays::<N>::new(), z, z, z);
    let mut start = StartArrays::<N>::new();
    let ident = identity::<N>();
    let mut b = Buffers {
        eff: eff.factored(),
        g: g.as_flattened_mut(),
        gc: gc.as_flattened_mut(),
        gk: gk.as_flattened_mut(),
        start: start.buffers(),
    };
    let built = match newmark_operators_flat(
        &Terms::of(m, c, k),
        ident.as_flattened(),
        h,
        beta,
        gamma,
        max,
        &mut b,
    ) {
        Ok(built) => built,
        Err(e) => return Err(e),
    };
    Ok(KernelOps {
        g,
        gc,
        gk,
        kin: built.kin,
        aem: built.aem,
        lu: Lu::from_parts(eff.lu, eff.perm),
        condition: built.condition,
        start: start.finish(built.start),
    })
}

/// The output buffers of [`newmark_operators_flat`] (row-major, `n×n` unless said): the
/// effective matrix and its factorization, `G`, `GC`, `GK`, and the start-up operators.
pub(crate) struct Buffers<'a> {
    pub eff: Factored<'a>,
    pub g: &'a mut [f64],
    pub gc: &'a mut [f64],
    pub gk: &'a mut [f64],
    pub start: StartBuffers<'a>,
}

/// What [`newmark_operators_flat`] returns besides its buffers.
pub(crate) struct Built {
    pub kin: NewmarkKinematics<f64>,
    pub aem: AemKinematics<f64>,
    /// `κ₁` of the row-equilibrated `M_eff` ([`condition_flat`]).
    pub condition: f64,
    /// `M` is regular: the start-up operators are in the buffers.
    pub start: bool,
}

/// [`newmark_operators`] into the buffers `b` (`n = b.eff.perm.len()`, `ident` the `n×n`
/// identity): the one build of the Newmark-family operators, for the const-generic
/// kernels and, behind `std`, the run-time-sized one. Same checks, in the same order, and
/// the same arithmetic whatever the size. Errors: as [`newmark_operators`].
pub(crate) const fn newmark_operators_flat(
    t: &Terms<'_>,
    ident: &[f64],
    h: f64,
    beta: f64,
    gamma: f64,
    max: f64,
    b: &mut Buffers<'_>,
) -> Result<Built, Error> {
    if !(all_finite_flat(t.m) && all_finite_flat(t.c) && all_finite_flat(t.k)) {
        return Err(Error::NonFiniteInput);
    }
    if !(beta.is_finite() && gamma.is_finite() && beta >= 0.0 && gamma >= 0.0) {
        return Err(Error::InvalidParameter(Param::NewmarkBetaGamma));
    }
    let kin = match NewmarkKinematics::new(h, beta, gamma) {
        Ok(kin) => kin,
        Err(e) => return Err(e),
    };
    let aem = match AemKinematics::new(h) {
        Ok(kin) => kin,
        Err(e) => return Err(e),
    };
    // The kinematics must fit the scalar type too (found by fuzzing: `h = 1e58` in f32).
    if let Err(e) = check_time_step_as(h, max) {
        return Err(e);
    }
    if let Err(e) = effective_lu_flat(t, kin.gamma_h, kin.beta_h2, &mut b.eff) {
        return Err(e);
    }
    let n = b.eff.perm.len();
    b.eff.solve(ident, n, b.g);
    b.eff.solve(t.c, n, b.gc);
    b.eff.solve(t.k, n, b.gk);
    let fit = [
        fits_flat(b.g, b.eff.a, max),
        fits_flat(b.gc, t.c, max),
        fits_flat(b.gk, t.k, max),
    ];
    // Overflow (of an operator or of a kinematic coefficient) before underflow.
    if let Err(e) = range_verdict(fit, kin.fits(max)) {
        return Err(e);
    }
    let start = match start_operators_flat(t, ident, max, &mut b.start) {
        Ok(s) => s,
        Err(e) => return Err(e),
    };
    Ok(Built {
        kin,
        aem,
        condition: condition_flat(b.eff.a, b.g, b.eff.scales),
        start,
    })
}

/// [`newmark_operators`] for a load `p = B w` entering through `B` (`N×I`): `B` checked
/// first ([`Error::NonFiniteInput`]), then the kernel's operators, with `G B` (a solve
/// with `M_eff`) and, when `M` is regular, `M⁻¹ B` (a solve with `M`). The one build
/// behind [`LinearInput`](crate::LinearInput) and the Newmark state-space form. Errors:
/// those of [`newmark_operators`], after `B`'s.
#[allow(clippy::too_many_arguments)] // newmark_operators' arguments, plus B
pub(crate) const fn input_kernel_operators<const N: usize, const I: usize>(
    m: &Mat<N, N>,
    c: &Mat<N, N>,
    k: &Mat<N, N>,
    b: &Mat<N, I>,
    h: f64,
    beta: f64,
    gamma: f64,
    max: f64,
) -> Result<(KernelOps<N>, Mat<N, I>, Option<Mat<N, I>>), Error> {
    if !all_finite(b) {
        return Err(Error::NonFiniteInput);
    }
    let op = match newmark_operators(m, c, k, h, beta, gamma, max) {
        Ok(op) => op,
        Err(e) => return Err(e),
    };
    let gb = op.lu.solve(b);
    let minv_b = match &op.start {
        Some((lu, _)) => Some(lu.solve(b)),
        None => None,
    };
    Ok((op, gb, minv_b))
}

/// `M, C, K` as row-major `f64`, checked finite ([`Error::NonFiniteInput`]): the data
/// check of the schemes built outside [`newmark_operators`].
pub(crate) fn checked_rows<const N: usize>(
    m: &nalgebra::SMatrix<f64, N, N>,
    c: &nalgebra::SMatrix<f64, N, N>,
    k: &nalgebra::SMatrix<f64, N, N>,
) -> Result<(Mat<N, N>, Mat<N, N>, Mat<N, N>), Error> {
    let (m, c, k) = (rows_f64(m), rows_f64(c), rows_f64(k));
    if all_finite(&m) && all_finite(&c) && all_finite(&k) {
        Ok((m, c, k))
    } else {
        Err(Error::NonFiniteInput)
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
    // A non-finite input first, as every start in the crate (found by fuzzing).
    if !initial_inputs_finite(u0, v0, p0) {
        return Err(Error::NonFiniteInput);
    }
    let ops = ops.ok_or(Error::SingularMass)?;
    let a0 = mat_vec(&ops.minv, p0) - mat_vec(&ops.minv_c, v0) - mat_vec(&ops.minv_k, u0);
    State::initial_computed(u0, v0, a0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The verdict the three operator builds share, as its docs state it: an operator's
    /// overflow, then a coefficient's overflow, then an operator's underflow, whatever the
    /// order of the checks.
    #[test]
    fn range_verdict_overflow_before_underflow() {
        let (o, u) = (Err(Error::OperatorOverflow), Err(Error::OperatorUnderflow));
        assert_eq!(range_verdict([u, Ok(()), o], true), o);
        assert_eq!(range_verdict([o, u], false), o);
        assert_eq!(range_verdict([u, Ok(())], false), o);
        assert_eq!(range_verdict([Ok(()), u], true), u);
        assert_eq!(range_verdict([Ok(()); 3], false), o);
        assert_eq!(range_verdict([Ok(()); 3], true), Ok(()));
    }

    /// `effective_lu` forms `M + wc C + wk K` entry by entry in that order, refuses a
    /// non-finite sum before factorizing, and a matrix whose rows cancel to rounding.
    #[test]
    fn effective_lu_sum_and_refusals() {
        let (m, c, k) = (
            [[2.0, 0.0], [0.0, 1.0]],
            [[0.5, 0.1], [0.1, 0.5]],
            [[4.0, -1.0], [-1.0, 3.0]],
        );
        let (wc, wk) = (0.005, 2.5e-5);
        let (meff, _, _) = effective_lu(&m, &c, &k, wc, wk).unwrap();
        for i in 0..2 {
            for j in 0..2 {
                assert_eq!(meff[i][j], m[i][j] + wc * c[i][j] + wk * k[i][j]);
            }
        }
        let big = [[f64::MAX, 0.0], [0.0, f64::MAX]];
        assert_eq!(
            effective_lu(&big, &big, &k, 1.0, 0.0).err(),
            Some(Error::OperatorOverflow)
        );
        // M + 1·(−M): every row cancels exactly.
        let neg = [[-2.0, 0.0], [0.0, -1.0]];
        assert_eq!(
            effective_lu(&m, &neg, &k, 1.0, 0.0).err(),
            Some(Error::SingularEffectiveMatrix)
        );
    }
}
