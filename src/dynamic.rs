//! Models of any size on the host (feature `std`): the linear AEM stepper with its number
//! of degrees of freedom chosen at run time, [`DynLinear`], and the yielding shear building
//! with its number of storeys chosen at run time, [`DynShearBuilding`] stepped by
//! [`DynNonlinear`] (with [`DynEnergyAccount`]).
//!
//! `DynLinear` is the const-generic [`Linear`](crate::Linear) with heap storage, not a
//! second implementation: the operators are built by the same `const fn` build on flat
//! slices (the kernel's `newmark_operators_flat`, the LU's `factor` and `solve_flat`: the
//! same checks in the same order, the same arithmetic), rounded once to `T` the same way,
//! stored in the column-blocked layout and multiplied by the same per-row product
//! (`op_rows`' `wide_blocks_flat`), with the same predictor and corrector
//! (`Kinematics`). So at every size both serve, `DynLinear<T>` and `Linear<T, N>` give
//! bit-identical histories (`tests/runtime_size.rs` checks `u`, `v`, `a` at every sample).
//!
//! Likewise `DynNonlinear` is [`Nonlinear::try_step_with_history`](crate::Nonlinear::try_step_with_history)
//! on a [`ShearBuilding`](crate::hysteresis::ShearBuilding) with heap storage: the
//! const-generic Newton step calls its per-step arithmetic as functions on flat slices
//! (`#[inline(always)]`: the storey loop of the trial, the banded products, the assembly of
//! `J` on three diagonals, its `L D Lᵀ` solve and the pivoted LU fallback, the convergence
//! test, the building's checks) and the run-time-sized step calls the same functions in
//! the same order. Bit-identical `u`, `v`, `a`, histories and Newton reports at every size
//! both serve (`tests/runtime_size.rs`, every exposed law, tridiagonal and full damping,
//! `f64` and `f32`).
//!
//! Memory is allocated once, by [`DynLinear::new`] (`6N²` values of `T` and a few `N×N`
//! `f64` temporaries) and [`DynLinear::start`] (`7N` values of `T` in the state); by
//! [`DynShearBuilding::new`] (`4N` values, `N²` more for a full damping matrix) and
//! [`DynNonlinear::start`] (about `20N` values, `N` histories and `N²` values of Newton
//! work space); stepping allocates nothing.

mod building;

pub use building::{DynBuildingState, DynEnergyAccount, DynNonlinear, DynShearBuilding};

use std::vec;
use std::vec::Vec;

use nalgebra::DMatrix;

use crate::kernel::{Buffers, Factored, StartBuffers, Terms, dot, newmark_operators_flat};
use crate::kinematics::{AemKinematics, Kinematics};
use crate::linalg::identity_flat;
use crate::linalg::op_rows::{dyn_wide_rows, flat_index, wide_blocks_flat};
use crate::{Error, Real};

/// The linear constant-coefficient AEM stepper of [`Linear`](crate::Linear) (paper
/// Algorithm 1, eliminated form) for `M u'' + C u' + K u = p(t)` with `N` degrees of
/// freedom chosen at run time (feature `std`).
///
/// `T` is `f32` or `f64`. Build once with [`DynLinear::new`] (`M, C, K` as `N×N` `f64`
/// matrices, `h` in seconds), start with [`DynLinear::start`], then
/// [`DynLinear::try_step`] (checked) or [`DynLinear::step`] per sample. Same operators,
/// same checks and errors, same step arithmetic as `Linear<T, N>`: bit-identical histories
/// at any size both serve.
///
/// Size: `6N²` values of `T` (`3N²` for stepping, `3N²` for start-up) on the heap. A step
/// costs `3N²` multiply-adds plus `7N`, allocation-free.
///
/// ```
/// use aemstep::nalgebra::DMatrix;
/// use aemstep::DynLinear;
///
/// // A chain of 37 unit masses and springs (N/m, kg), h = 0.01 s, a unit load on the top.
/// let n = 37;
/// let m = DMatrix::<f64>::identity(n, n);
/// let c = DMatrix::<f64>::zeros(n, n);
/// let k = DMatrix::from_fn(n, n, |i, j| match i.abs_diff(j) {
///     0 => 2.0,
///     1 => -1.0,
///     _ => 0.0,
/// });
/// let sys = DynLinear::<f64>::new(&m, &c, &k, 0.01)?;
/// let (zero, mut p) = (vec![0.0; n], vec![0.0; n]);
/// p[n - 1] = 1.0;
/// let mut s = sys.start(&zero, &zero, &p)?;
/// for _ in 0..100 {
///     sys.try_step(&mut s, &p)?;
/// }
/// assert_eq!(s.steps(), 100);
/// assert!(s.u()[n - 1] > 0.0);
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct DynLinear<T> {
    /// Degrees of freedom.
    n: usize,
    /// Rows `[G[i], −GC[i], −GK[i]]` in the column-blocked layout of
    /// [`dyn_wide_rows`] rows (`3N²` values).
    ops: Vec<T>,
    kin: AemKinematics<T>,
    /// `M⁻¹`, `M⁻¹C`, `M⁻¹K`, row-major (`None`: `M` singular).
    start: Option<[Vec<T>; 3]>,
    condition: f64,
}

/// The state of a [`DynLinear`]: `u` (m), `v` (m/s), `a` (m/s²) at step `n`, and the
/// step's work space (allocated once, by [`DynLinear::start`]). Two states are equal when
/// their `u`, `v`, `a` and step counts are.
#[derive(Clone, Debug)]
pub struct DynState<T> {
    u: Vec<T>,
    v: Vec<T>,
    a: Vec<T>,
    n: u64,
    /// `x = (p, v̂, û)` (`3N`) and the new acceleration `q` (`N`).
    work: Vec<T>,
}

impl<T: PartialEq> PartialEq for DynState<T> {
    fn eq(&self, o: &Self) -> bool {
        (&self.u, &self.v, &self.a, self.n) == (&o.u, &o.v, &o.a, o.n)
    }
}

/// The accessors of a run-time-sized state with fields `u`, `v`, `a` (`Vec<T>`) and `n`
/// (steps): `u()`, `v()`, `a()`, `steps()`, `size()`. Expands inside its `impl` block.
macro_rules! state_accessors {
    () => {
        /// Displacements (m), `N` values. Cost: none.
        pub fn u(&self) -> &[T] {
            &self.u
        }

        /// Velocities (m/s), `N` values. Cost: none.
        pub fn v(&self) -> &[T] {
            &self.v
        }

        /// Accelerations (m/s²), `N` values. Cost: none.
        pub fn a(&self) -> &[T] {
            &self.a
        }

        /// Steps taken since the start (`t = steps · h`). Cost: none.
        pub fn steps(&self) -> u64 {
            self.n
        }

        /// Degrees of freedom. Cost: none.
        pub fn size(&self) -> usize {
            self.u.len()
        }
    };
}
use state_accessors;

impl<T: Real> DynState<T> {
    state_accessors!();

    fn new(u: Vec<T>, v: Vec<T>, a: Vec<T>) -> Result<Self, Error> {
        let n = u.len();
        let s = Self {
            u,
            v,
            a,
            n: 0,
            work: vec![T::zero(); 4 * n],
        };
        let finite = |x: &[T]| x.iter().all(|x| x.is_finite());
        if finite(&s.u) && finite(&s.v) && finite(&s.a) {
            Ok(s)
        } else {
            Err(Error::NonFiniteState)
        }
    }
}

impl<T: Real> DynLinear<T> {
    /// Precompute the step operators for `M u'' + C u' + K u = p(t)` with step `h` (s):
    /// [`Linear::new`](crate::Linear::new) at a run-time size `N` (the rows of `m`).
    ///
    /// `M, C, K` are `N×N` in `f64` (the operators are computed in `f64` and rounded once
    /// to `T`), fully populated, not necessarily symmetric; `N ≥ 1`. `M` may be singular as
    /// long as `M + (h/2) C + (h²/4) K` is not (then start with
    /// [`DynLinear::start_with_acceleration`]).
    ///
    /// Errors: [`Error::StateSizeMismatch`] (a matrix not `N×N`, or `N = 0`), then those of
    /// [`Linear::new`](crate::Linear::new), in its order: [`Error::NonFiniteInput`],
    /// [`Error::InvalidTimeStep`], [`Error::SingularEffectiveMatrix`],
    /// [`Error::OperatorOverflow`], [`Error::OperatorUnderflow`].
    ///
    /// Cost: about `4N³` flops in `f64`; `16N²` `f64` of temporaries and the `6N²` values
    /// of `T` kept, on the heap.
    pub fn new(
        m: &DMatrix<f64>,
        c: &DMatrix<f64>,
        k: &DMatrix<f64>,
        h: f64,
    ) -> Result<Self, Error> {
        let n = m.nrows();
        if n == 0 || [m, c, k].iter().any(|a| a.shape() != (n, n)) {
            return Err(Error::StateSizeMismatch);
        }
        let rows = |a: &DMatrix<f64>| a.transpose().as_slice().to_vec();
        let (m, c, k) = (rows(m), rows(c), rows(k));
        let terms = Terms {
            m: &m,
            c: &c,
            k: &k,
        };
        let square = || vec![0.0f64; n * n];
        let mut ident = square();
        identity_flat(&mut ident, n);
        let (mut meff, mut lu, mut g, mut gc, mut gk) =
            (square(), square(), square(), square(), square());
        let (mut ma, mut mlu, mut minv, mut minv_c, mut minv_k) =
            (square(), square(), square(), square(), square());
        let (mut scales, mut pivot_scales, mut mscales, mut mpivot_scales) =
            (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let (mut perm, mut mperm) = (vec![0usize; n], vec![0usize; n]);
        let mut b = Buffers {
            eff: Factored {
                a: &mut meff,
                scales: &mut scales,
                lu: &mut lu,
                pivot_scales: &mut pivot_scales,
                perm: &mut perm,
            },
            g: &mut g,
            gc: &mut gc,
            gk: &mut gk,
            start: StartBuffers {
                f: Factored {
                    a: &mut ma,
                    scales: &mut mscales,
                    lu: &mut mlu,
                    pivot_scales: &mut mpivot_scales,
                    perm: &mut mperm,
                },
                minv: &mut minv,
                minv_c: &mut minv_c,
                minv_k: &mut minv_k,
            },
        };
        let built = newmark_operators_flat(&terms, &ident, h, 0.25, 0.5, T::MAX, &mut b)?;
        // Rounded once to T, as `KernelOps::round` (the sign after rounding: exact).
        let w = dyn_wide_rows(core::mem::size_of::<T>());
        let mut ops = vec![T::zero(); 3 * n * n];
        let (one, blocks) = (T::one(), [&g, &gc, &gk]);
        for i in 0..n {
            for (bk, (block, sign)) in blocks.iter().zip([one, -one, -one]).enumerate() {
                for j in 0..n {
                    let x = sign * T::from_f64_rounded(block[i * n + j]);
                    ops[flat_index(n, 3, i, bk * n + j, w)] = x;
                }
            }
        }
        let round = |a: &[f64]| a.iter().map(|&x| T::from_f64_rounded(x)).collect();
        Ok(Self {
            n,
            ops,
            kin: built.aem.round(),
            start: built
                .start
                .then(|| [round(&minv), round(&minv_c), round(&minv_k)]),
            condition: built.condition,
        })
    }

    /// Degrees of freedom `N`. Cost: none.
    pub fn size(&self) -> usize {
        self.n
    }

    /// The time step `h` (s). Cost: none.
    pub fn time_step(&self) -> T {
        self.kin.h()
    }

    /// `κ₁` of the row-equilibrated effective matrix, as
    /// [`Linear::condition`](crate::Linear::condition). Cost: none.
    pub fn condition(&self) -> f64 {
        self.condition
    }

    /// `G = (M + (h/2) C + (h²/4) K)⁻¹`, `N×N`. Cost: `N²` reads and an allocation.
    pub fn effective_inverse(&self) -> DMatrix<T> {
        let w = dyn_wide_rows(core::mem::size_of::<T>());
        DMatrix::from_fn(self.n, self.n, |i, j| {
            self.ops[flat_index(self.n, 3, i, j, w)]
        })
    }

    /// The state at `t = 0` from `u0` (m), `v0` (m/s) and the load `p0` (N), each of `N`
    /// values: `a0 = M⁻¹ p0 − (M⁻¹C) v0 − (M⁻¹K) u0` (paper eq. 40), as
    /// [`Stepper::start`](crate::Stepper::start) of `Linear`.
    ///
    /// Errors: [`Error::StateSizeMismatch`] (a vector not of `N` values),
    /// [`Error::NonFiniteInput`], [`Error::SingularMass`], [`Error::NonFiniteState`].
    /// Cost: `3N²` multiply-adds; allocates the state (`7N` values).
    pub fn start(&self, u0: &[T], v0: &[T], p0: &[T]) -> Result<DynState<T>, Error> {
        self.sizes(&[u0, v0, p0])?;
        if ![u0, v0, p0].iter().all(|x| x.iter().all(|x| x.is_finite())) {
            return Err(Error::NonFiniteInput);
        }
        let [minv, minv_c, minv_k] = self.start.as_ref().ok_or(Error::SingularMass)?;
        let n = self.n;
        let a0 = (0..n)
            .map(|i| {
                let row = |a: &[T], x: &[T]| dot(&a[i * n..(i + 1) * n], x);
                row(minv, p0) - row(minv_c, v0) - row(minv_k, u0)
            })
            .collect();
        DynState::new(u0.to_vec(), v0.to_vec(), a0)
    }

    /// The state at `t = 0` with a known initial acceleration `a0` (m/s²), as
    /// [`Stepper::start_with_acceleration`](crate::Stepper::start_with_acceleration).
    ///
    /// Errors: [`Error::StateSizeMismatch`], [`Error::NonFiniteInput`]. Cost: allocates
    /// the state (`7N` values).
    pub fn start_with_acceleration(
        &self,
        u0: &[T],
        v0: &[T],
        a0: &[T],
    ) -> Result<DynState<T>, Error> {
        self.sizes(&[u0, v0, a0])?;
        DynState::new(u0.to_vec(), v0.to_vec(), a0.to_vec()).map_err(|_| Error::NonFiniteInput)
    }

    /// Advance `s` from `t_{n−1}` to `t_n` under the load `p = p(t_n)` (N, `N` values), as
    /// [`Stepper::step`](crate::Stepper::step): unchecked numerics (a NaN load gives a NaN
    /// state; [`DynLinear::try_step`] refuses it).
    ///
    /// Errors: [`Error::StateSizeMismatch`] (`p` or `s` not of this size; `s` unchanged).
    /// Cost: `3N²` multiply-adds + `7N`; no allocation, no panic.
    pub fn step(&self, s: &mut DynState<T>, p: &[T]) -> Result<(), Error> {
        self.sizes(&[p, &s.u])?;
        self.advance(s, p);
        self.commit(s);
        Ok(())
    }

    /// [`DynLinear::step`], checked, as [`Stepper::try_step`](crate::Stepper::try_step):
    /// `s` changes only if the load and the new state are finite.
    ///
    /// Errors: [`Error::StateSizeMismatch`], [`Error::NonFiniteInput`] (a load not
    /// finite), [`Error::NonFiniteState`] (the new state overflows); `s` unchanged on
    /// error. Cost: that of [`DynLinear::step`] and `4N` comparisons.
    pub fn try_step(&self, s: &mut DynState<T>, p: &[T]) -> Result<(), Error> {
        self.sizes(&[p, &s.u])?;
        if !p.iter().all(|x| x.is_finite()) {
            return Err(Error::NonFiniteInput);
        }
        self.advance(s, p);
        let n = self.n;
        let (x, q) = s.work.split_at(3 * n);
        let finite = (0..n).all(|j| {
            let (v, u) = self.kin.correct(x[n + j], x[2 * n + j], q[j]);
            v.is_finite() && u.is_finite() && q[j].is_finite()
        });
        if !finite {
            return Err(Error::NonFiniteState);
        }
        self.commit(s);
        Ok(())
    }

    /// `Error::StateSizeMismatch` unless every slice has `N` values.
    fn sizes(&self, xs: &[&[T]]) -> Result<(), Error> {
        if xs.iter().all(|x| x.len() == self.n) {
            Ok(())
        } else {
            Err(Error::StateSizeMismatch)
        }
    }

    /// `x = (p, v̂, û)` and `q = G p − GC v̂ − GK û` into the work space (the state is
    /// not changed): the kernel's `newmark_step` up to the corrector.
    #[inline]
    fn advance(&self, s: &mut DynState<T>, p: &[T]) {
        let n = self.n;
        let (x, q) = s.work.split_at_mut(3 * n);
        for j in 0..n {
            x[j] = p[j];
            (x[n + j], x[2 * n + j]) = self.kin.predict(s.u[j], s.v[j], s.a[j]);
        }
        match dyn_wide_rows(core::mem::size_of::<T>()) {
            32 => wide_blocks_flat::<T, 32>(&self.ops, n, 3, 0, x, q),
            _ => wide_blocks_flat::<T, 16>(&self.ops, n, 3, 0, x, q),
        }
    }

    /// The corrector from the work space into the state, and the step count.
    #[inline]
    fn commit(&self, s: &mut DynState<T>) {
        let n = self.n;
        let (x, q) = s.work.split_at(3 * n);
        for j in 0..n {
            s.a[j] = q[j];
            (s.v[j], s.u[j]) = self.kin.correct(x[n + j], x[2 * n + j], q[j]);
        }
        s.n = s.n.wrapping_add(1);
    }
}
