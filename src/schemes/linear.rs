//! The linear AEM kernel: `M u'' + C u' + K u = p(t)` with constant `M, C, K`.
//!
//! With `q = u''` taken as the mean of its end values on each step (paper §2, eqs. 19–23)
//! and the equation of motion enforced at `t_n`, eliminating `v_n, u_n` gives
//!
//! ```text
//! v̂ = v_{n−1} + (h/2) q_{n−1}             û = u_{n−1} + h v̂ − (h²/4) q_{n−1}
//! q_n = G p_n − (G C) v̂ − (G K) û          G = (M + (h/2) C + (h²/4) K)⁻¹
//! v_n = v̂ + (h/2) q_n                      u_n = û + (h²/4) q_n
//! ```
//!
//! `G`, `GC`, `GK` are computed once, in `f64` (LU of the effective matrix and solves),
//! and rounded once to `T`. A step costs `3N²` multiply-adds plus `7N` for the kinematics
//! ([`crate::kinematics`]). The same numbers, in the paper's literal
//! `U_n = A U_{n−1} + b p_n` form, come from [`Linear::a_form`].

use nalgebra::SMatrix;

use crate::kernel::{Kernel, aem_const_ctors, kernel_stepper};
use crate::kinematics::AemKinematics;
use crate::macros::mck_fn;
use crate::{AForm, Error, Real};

/// The linear constant-coefficient AEM stepper (paper Algorithm 1, eliminated form).
///
/// `T` is `f32` or `f64`; `N` the number of degrees of freedom. Build it once with
/// [`Linear::new`] (run time, from `nalgebra` matrices) or [`Linear::from_rows_f32`]
/// (`const fn`, from row-major arrays: operators computed by the compiler into flash).
/// Both take the data in `f64` and round the operators once, so they are bit-identical.
/// Then [`Stepper::start`](crate::Stepper::start) and [`Stepper::step`](crate::Stepper::step) (or the checked [`Stepper::try_step`](crate::Stepper::try_step)).
///
/// Size: `6N² + 5` values of `T` (`3N²` for stepping, `3N²` for start-up).
///
/// ```
/// use aemstep::{Linear, Stepper};
/// use aemstep::{matrix, vector};
///
/// // u'' + 25 u = 0 (paper Example 1), h = 0.01 s
/// let sys = Linear::<f64, 1>::new(&matrix![1.0], &matrix![0.0], &matrix![25.0], 0.01)?;
/// let mut s = sys.start(&vector![1.0], &vector![0.0], &vector![0.0])?;
/// for _ in 0..100 {
///     sys.step(&mut s, &vector![0.0]);
/// }
/// assert!((s.u()[0] - 5.0f64.cos()).abs() < 2e-3); // t = 1 s, O(h²) phase error
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(transparent)]
pub struct Linear<T, const N: usize> {
    /// `G, GC, GK` interleaved by row (`[G[i], −GC[i], −GK[i]]`, `G = M_eff⁻¹`): `q_i` is a
    /// single multiply-accumulate chain over one contiguous run of `3N` values.
    kernel: Kernel<T, N, AemKinematics<T>>,
}

impl<T: Real, const N: usize> Linear<T, N> {
    mck_fn! {
        /// Precompute the step operators for `M u'' + C u' + K u = p(t)` with step `h` (s).
        ///
        /// `M, C, K` are `N×N` in `f64` (whatever `T`: the operators are computed in `f64`
        /// and rounded once, so the same data gives bit-identical operators through
        /// [`Linear::from_rows_f32`]), fully populated, not necessarily symmetric. `M` may be
        /// singular as long as `M + (h/2) C + (h²/4) K` is not (then start with
        /// [`Stepper::start_with_acceleration`](crate::Stepper::start_with_acceleration)).
        ///
        /// Errors: [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`] (`h ≤ 0`, not finite,
        /// or `h²` out of range), [`Error::SingularEffectiveMatrix`] (singular to working
        /// precision against the size of its terms `|M| + (h/2)|C| + (h²/4)|K|`),
        /// [`Error::OperatorOverflow`] (an operator does not fit `T`), [`Error::OperatorUnderflow`]
        /// (an operator from nonzero data is zero or subnormal in `T`).
        ///
        /// Cost: about `4N³` flops in `f64` and a few `N×N` `f64` temporaries on the stack.
        pub fn new(m, c, k, h: f64) {
            Kernel::aem(m, c, k, h).map(|kernel| Self { kernel })
        }
    }

    /// `G = (M + (h/2) C + (h²/4) K)⁻¹`.
    pub fn effective_inverse(&self) -> SMatrix<T, N, N> {
        self.kernel.effective_inverse()
    }

    /// The paper's literal form `U_n = A U_{n−1} + b p_n` of this stepper (`12N²`
    /// multiply-adds a step): the reference the fast form is tested against, and a way to
    /// inspect the amplification operator. Cost to build: about `6N³` flops in `T`.
    ///
    /// Its blocks are products in `T` of this stepper's operators and `h`, and can
    /// overflow where those do not (e.g. `(h/2) G` with `G = 1e251`, `h = 1e147`, found by
    /// fuzzing): [`Linear::try_a_form`] checks them.
    pub fn a_form(&self) -> AForm<T, N> {
        let ops = &self.kernel.ops;
        let block = |b: usize, sign: T| -> [[T; N]; N] {
            core::array::from_fn(|i| core::array::from_fn(|j| sign * ops.get(i, b, j)))
        };
        let one = T::one();
        let (g, gc, gk) = (block(0, one), block(1, -one), block(2, -one));
        AForm::from_operators(self.kernel.kin.h, &g, &gc, &gk, self.kernel.start)
    }

    /// [`Linear::a_form`], checked: every block of `A` and `b` finite.
    ///
    /// Errors: [`Error::OperatorOverflow`] (a block overflows `T`). Cost: that of
    /// [`Linear::a_form`] and a scan of its `12N²` entries.
    pub fn try_a_form(&self) -> Result<AForm<T, N>, Error> {
        let af = self.a_form();
        if af.is_finite() {
            Ok(af)
        } else {
            Err(Error::OperatorOverflow)
        }
    }
}

// Const-fn construction, for operators computed at compile time into flash.
aem_const_ctors!(
    Linear,
    /// `const fn` twin of [`Linear::new`]: `M, C, K` as row-major `f64` arrays
    /// (`m[i][j]` is row `i`, column `j`), `h` in seconds. Bit-identical to
    /// [`Linear::new`] given the same values. `from_rows_f32` builds a
    /// `Linear<f32, N>`, `from_rows_f64` a `Linear<f64, N>`: the scalar in the name
    /// lets a typed `static` infer `N` with no turbofish.
    ///
    /// **Matrices are row-major** (`m[i][j]`: row `i`, column `j`; [`Rows`](crate::models::Rows)); to pass
    /// nalgebra data use [`models::rows_of`](crate::models::rows_of), and to convert these
    /// arrays to nalgebra use [`models::matrix_of`](crate::models::matrix_of), not `SMatrix::from`,
    /// which reads columns.
    ///
    /// In a `static`, the operators are evaluated by the compiler and no
    /// factorization code is linked in:
    ///
    /// ```
    /// use aemstep::Linear;
    /// static SYS: Linear<f32, 1> = match Linear::from_rows_f32(
    ///     [[1.0]], [[0.28]], [[4.0]], 0.002,
    /// ) {
    ///     Ok(s) => s,
    ///     Err(e) => panic!("{}", e.as_str()),
    /// };
    /// assert_eq!(SYS.time_step(), 0.002);
    /// ```
    ///
    /// **Size limit at compile time.** The compiler evaluates about `4N³` flops;
    /// past a budget of evaluation steps rustc stops the build with the
    /// `long_running_const_eval` lint (deny by default). Measured with rustc 1.95:
    /// `Linear<f32, N>` compiles in a `static` up to `N = 63` and stops at 64 (the
    /// largest size is pinned by `tests/constructors.rs`). Larger `N` needs
    /// `#![allow(long_running_const_eval)]` at the crate root of the firmware, or
    /// [`Linear::new`] at run time.
    ///
    /// Errors: as [`Linear::new`].
);

kernel_stepper!(Linear);
