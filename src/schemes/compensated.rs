//! The AEM step with a compensated state update, for long real-time runs in `f32`.
//!
//! [`Linear`](crate::Linear) adds an increment that is small against the state (`h v`
//! against `u` at many steps per period) and rounds the sum: the rounding errors are
//! systematic, so an undamped `f32` oscillator's amplitude drifts over 10⁸ steps.
//! [`CompensatedLinear`] runs the same operators and adds the increments by two-sum,
//! carrying each addition's rounding error with the state ([`CompensatedState`]) into the
//! next step. The measured drift of both is in `docs/drift.md`.

use nalgebra::{SMatrix, SVector};

use crate::kernel::{Kernel, Lows, aem_const_ctors, initial_state, newmark_step_compensated};
use crate::kinematics::{AemKinematics, Kinematics};
use crate::macros::mck_fn;
use crate::stepper::start_fn;
use crate::{Error, Real, State, Stepper};

/// The state of a [`CompensatedLinear`]: the working-precision [`State`] and the rounding
/// errors of its `u` and `v` (`u + du` is the displacement to about twice the working
/// precision). Plain data (`Copy`, `5N + 1` words).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompensatedState<T, const N: usize> {
    state: State<T, N>,
    lo: Lows<T, N>,
}

impl<T: Real, const N: usize> CompensatedState<T, N> {
    /// The working-precision state (`u`, `v` rounded, `a`, step count). Cost: none.
    pub fn state(&self) -> &State<T, N> {
        &self.state
    }
    /// The carried rounding error of `u` (same units as `u`; at most about half a unit in
    /// the last place of `u`, after a step). Cost: none.
    pub fn u_low(&self) -> &SVector<T, N> {
        &self.lo.du
    }
    /// The carried rounding error of `v` (same units as `v`). Cost: none.
    pub fn v_low(&self) -> &SVector<T, N> {
        &self.lo.dv
    }
    /// A state with zero carried errors (e.g. one restored from a saved [`State`]).
    pub fn from_state(state: State<T, N>) -> Self {
        Self {
            state,
            lo: Lows {
                du: SVector::zeros(),
                dv: SVector::zeros(),
            },
        }
    }
}

crate::state::step_state!(
    CompensatedState<N>,
    |self| self.state.is_finite()
        && self
            .lo
            .du
            .iter()
            .chain(self.lo.dv.iter())
            .all(|x| x.is_finite()),
    state.n
);

/// The AEM ([`Linear`](crate::Linear)'s operators, bit-identical) with the state update
/// compensated: for long undamped runs in `f32`, where the plain update's rounding drifts
/// the amplitude (`docs/drift.md`).
///
/// Same constructors' data and errors as [`Linear::new`](crate::Linear::new); state
/// [`CompensatedState`]. A step costs `5N²` multiply-adds + about `34N` operations
/// (plain: `3N² + 7N`): the rounding errors of the predictor go through `GC`, `GK` too,
/// so `q` is consistent with the unrounded state. Size as [`Linear`](crate::Linear).
///
/// What it buys (`docs/drift.md`, 10⁸ `f32` steps of an undamped oscillator): the
/// amplitude drift falls from up to 2.8e-3 to below 1e-4 at ωh ≤ 1; at ωh = 100 it is
/// larger than the plain update's. The phase error is the same as the plain update's: it
/// comes from the operators' rounding to `f32`, not from the state update.
///
/// ```
/// use aemstep::{CompensatedLinear, Stepper};
/// use aemstep::{matrix, vector};
/// let sys = CompensatedLinear::<f32, 1>::new(&matrix![1.0], &matrix![0.0], &matrix![1.0], 1e-2)?;
/// let mut s = sys.start(&vector![1.0], &vector![0.0], &vector![0.0])?;
/// for _ in 0..1000 {
///     sys.step(&mut s, &vector![0.0]);
/// }
/// let st = sys.full_state(&s);
/// assert!((st.u()[0].powi(2) + st.v()[0].powi(2) - 1.0).abs() < 1e-6);
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(transparent)]
pub struct CompensatedLinear<T, const N: usize> {
    kernel: Kernel<T, N, AemKinematics<T>>,
}

impl<T: Real, const N: usize> CompensatedLinear<T, N> {
    mck_fn! {
        /// Precompute the operators of [`Linear::new`](crate::Linear::new) (same arguments:
        /// `M, C, K` `N×N` in `f64`, step `h` in s; computed in `f64`, rounded once to `T`).
        ///
        /// Errors: as [`Linear::new`](crate::Linear::new). Cost: about `4N³` flops in `f64`.
        pub fn new(m, c, k, h: f64) {
            Kernel::aem(m, c, k, h).map(|kernel| Self { kernel })
        }
    }

    /// `κ₁` of the row-equilibrated effective matrix, as
    /// [`Linear::condition`](crate::Linear::condition). Cost: O(1).
    pub fn condition(&self) -> f64 {
        self.kernel.condition
    }

    /// `G = (M + (h/2) C + (h²/4) K)⁻¹` (bit-identical to
    /// [`Linear::effective_inverse`](crate::Linear::effective_inverse)).
    pub fn effective_inverse(&self) -> SMatrix<T, N, N> {
        self.kernel.effective_inverse()
    }
}

// Const-fn construction, for operators computed at compile time into flash.
aem_const_ctors!(
    CompensatedLinear,
    /// `const fn` twin of [`CompensatedLinear::new`] (row-major `f64` arrays, `h`
    /// in s), bit-identical to it and to
    /// [`Linear::from_rows_f32`](crate::Linear::from_rows_f32)'s operators. Size limit at
    /// compile time and errors: as [`Linear::from_rows_f32`](crate::Linear::from_rows_f32).
    ///
    /// **Matrices are row-major** (`m[i][j]`: row `i`, column `j`); convert with
    /// [`models::matrix_of`](crate::models::matrix_of) /
    /// [`models::rows_of`](crate::models::rows_of), not `SMatrix::from`, which
    /// reads columns.
);

impl<T: Real, const N: usize> Stepper<T, N> for CompensatedLinear<T, N> {
    type Input = SVector<T, N>;
    type State = CompensatedState<T, N>;

    #[inline]
    fn time_step(&self) -> T {
        self.kernel.kin.h()
    }

    start_fn! {
        /// As [`Stepper::start`]; the carried errors start at zero.
        fn start(&self, u0, v0, p0: &SVector<T, N>) -> CompensatedState<T, N> {
            initial_state(self.kernel.start.as_ref(), u0, v0, p0)
                .map(CompensatedState::from_state)
        }
    }

    start_fn! {
        fn start_with_acceleration(&self, u0, v0, a0: &SVector<T, N>) -> CompensatedState<T, N> {
            State::initial_given(u0, v0, a0).map(CompensatedState::from_state)
        }
    }

    /// Cost: `5N²` multiply-adds + about `34N` (see the type's docs).
    #[inline]
    fn step(&self, s: &mut CompensatedState<T, N>, p: &SVector<T, N>) {
        newmark_step_compensated(
            &self.kernel.ops,
            &self.kernel.kin,
            &mut s.state,
            &mut s.lo,
            p,
        );
    }

    /// The state with the carried errors added (`u + du`, `v + dv`, rounded). Cost: `2N`.
    fn full_state(&self, s: &CompensatedState<T, N>) -> State<T, N> {
        State::unchecked(
            s.state.u + s.lo.du,
            s.state.v + s.lo.dv,
            s.state.a,
            s.state.n,
        )
    }
}
