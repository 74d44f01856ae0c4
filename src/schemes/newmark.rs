//! The Newmark family (β, γ): average acceleration, linear acceleration, central
//! difference and every other member, behind the same [`Stepper`] interface as
//! [`Linear`](crate::Linear).
//!
//! ```text
//! û = u_{n−1} + h v_{n−1} + (1/2 − β) h² a_{n−1}      v̂ = v_{n−1} + (1 − γ) h a_{n−1}
//! a_n = G p_n − (G C) v̂ − (G K) û                    G = (M + γh C + βh² K)⁻¹
//! u_n = û + β h² a_n                                  v_n = v̂ + γ h a_n
//! ```
//!
//! Second order iff γ = 1/2. Unconditionally stable iff 2β ≥ γ ≥ 1/2; otherwise stable for
//! `ωh ≤ 1/√(γ/2 − β)` (undamped), e.g. `ωh ≤ 2` for central difference, `ωh ≤ 2√3` for
//! linear acceleration. β = 1/4, γ = 1/2 is the AEM step itself.

use nalgebra::SMatrix;

use crate::kernel::{Kernel, kernel_stepper, newmark_operators};
use crate::kinematics::NewmarkKinematics;
use crate::linalg::rows_f64;
use crate::macros::mck_fn;
use crate::{Error, Real};

/// A Newmark-family stepper (β, γ) for constant `M, C, K`.
///
/// Same state, same start-up and the same `3N² + O(N)` multiply-adds a step as
/// [`Linear`](crate::Linear); switch with one line:
///
/// ```
/// use aemstep::{Linear, Newmark, Stepper};
/// use aemstep::{matrix, vector};
/// let (m, c, k, h) = (matrix![1.0], matrix![0.0], matrix![25.0], 0.01);
/// // let sys = Linear::new(&m, &c, &k, h)?;
/// let sys = Newmark::<f64, 1>::linear_acceleration(&m, &c, &k, h)?;
/// let mut s = sys.start(&vector![1.0], &vector![0.0], &vector![0.0])?;
/// for _ in 0..100 {
///     sys.step(&mut s, &vector![0.0]);
/// }
/// assert!((s.u()[0] - 5.0f64.cos()).abs() < 1e-3);
/// # let _ = Linear::<f64, 1>::new(&m, &c, &k, h)?;
/// # Ok::<(), aemstep::Error>(())
/// ```
///
/// Size: `6N² + 5` values of `T`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(transparent)]
pub struct Newmark<T, const N: usize> {
    /// The operators in `Linear`'s layout, `G = (M + γh C + βh² K)⁻¹`.
    kernel: Kernel<T, N, NewmarkKinematics<T>>,
}

impl<T: Real, const N: usize> Newmark<T, N> {
    mck_fn! {
        /// Precompute the step operators of the Newmark scheme with parameters `beta` (β ≥ 0)
        /// and `gamma` (γ ≥ 0) for `M u'' + C u' + K u = p(t)` with step `h` (s). Computed in
        /// `f64`, rounded once to `T`.
        ///
        /// Errors: [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`],
        /// [`Error::InvalidParameter`] (β or γ negative or not finite),
        /// [`Error::SingularEffectiveMatrix`] (`M + γh C + βh² K` singular to working
        /// precision against its terms; e.g. central difference with singular `M`),
        /// [`Error::OperatorOverflow`], [`Error::OperatorUnderflow`].
        ///
        /// Cost: about `5N³` flops in `f64`, four `N×N` `f64` temporaries on the stack.
        pub fn new(m, c, k, h: f64, beta: f64, gamma: f64) {
            let (m, c, k) = (rows_f64(m), rows_f64(c), rows_f64(k));
            let op = newmark_operators(&m, &c, &k, h, beta, gamma, T::MAX)?;
            Ok(Self {
                kernel: op.round_newmark(),
            })
        }
    }

    mck_fn! {
        /// Average acceleration (trapezoidal), β = 1/4, γ = 1/2: the same recurrence as the
        /// AEM [`Linear`](crate::Linear) (bit-identical operators). Errors: as [`Newmark::new`].
        pub fn average_acceleration(m, c, k, h: f64) {
            Self::new(m, c, k, h, 0.25, 0.5)
        }
    }

    mck_fn! {
        /// Linear acceleration, β = 1/6, γ = 1/2: second order, stable for `ωh ≤ 2√3`.
        /// Errors: as [`Newmark::new`].
        pub fn linear_acceleration(m, c, k, h: f64) {
            Self::new(m, c, k, h, 1.0 / 6.0, 0.5)
        }
    }

    mck_fn! {
        /// Central difference, β = 0, γ = 1/2: second order, stable for `ωh ≤ 2`
        /// (undamped). Needs `M + (h/2) C` invertible. Errors: as [`Newmark::new`].
        pub fn central_difference(m, c, k, h: f64) {
            Self::new(m, c, k, h, 0.0, 0.5)
        }
    }
}

kernel_stepper!(Newmark);
