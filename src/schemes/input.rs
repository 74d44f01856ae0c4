//! Inputs through an influence matrix: `M u'' + C u' + K u = B w(t)`.
//!
//! Many loads enter a structure through a few signals: base excitation
//! `p = −M ι a_g(t)` is one signal (`B = −M ι`, `I = 1`), a shaker or an actuator pair a
//! few more. With `B` (`N×I`) known once, the linear AEM step
//!
//! ```text
//! q_n = G p_n − (G C) v̂ − (G K) û,     G = (M + (h/2) C + (h²/4) K)⁻¹
//! ```
//!
//! takes `G p_n = (G B) w_n` with `G B` precomputed (a solve with `B`): `N·I`
//! multiply-adds instead of `N²`, so a step costs `2N² + N·I + 7N` instead of `3N² + 7N`.
//! The sequence is the one [`Linear`](crate::Linear) gives for `p_n = B w_n`, up to
//! rounding.

use nalgebra::{SMatrix, SVector};

use crate::kernel::{StartOps, input_kernel_operators, input_step, interleave};
use crate::kinematics::AemKinematics;
use crate::linalg::op_rows::OpRows;
use crate::linalg::{self, Mat, Rows, finite_as, rows_f64};
use crate::macros::mck_fn;
use crate::scalar::initial_inputs_finite;
use crate::stepper::start_fn;
use crate::{Error, Real, State, Stepper};

/// The linear AEM stepper for loads `p(t) = B w(t)` entering through an influence matrix
/// `B` (`N×I`, `I` input signals).
///
/// Same scheme and same results as [`Linear`](crate::Linear) fed `p_n = B w_n` (to
/// rounding), at `2N² + N·I + 7N` multiply-adds a step instead of `3N² + 7N`. Build it
/// with [`LinearInput::new`] (run time) or `LinearInput::from_rows_f32`/`_f64` (`const fn`,
/// operators computed by the compiler into flash; bit-identical), then
/// [`Stepper::start`] and [`Stepper::step`] with the inputs `w`.
///
/// Size: `2N² + N·I + 5` values of `T` for stepping, `2N² + N·I` more for start-up.
///
/// ```
/// use aemstep::{models, LinearInput, Stepper};
/// use aemstep::vector;
///
/// // The benchmark 5-storey building under base acceleration a_g: B = −M ι.
/// let (m, c, k) = models::five_storey_building();
/// let b = models::base_excitation(&m);
/// let sys = LinearInput::<f64, 5, 1>::from_rows_f64(m, c, k, b, 0.02)?;
/// let mut s = sys.start(&Default::default(), &Default::default(), &vector![0.0])?;
/// sys.step(&mut s, &vector![0.1 * 9.80665]); // a_g = 0.1 g
/// assert!(s.u()[4] < 0.0); // the roof lags behind the ground
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearInput<T, const N: usize, const I: usize> {
    /// Row `i`: `[−GC[i], −GK[i]]`, in the target's layout.
    ops: OpRows<T, N, 2>,
    /// `G·B`, row-major `N×I`.
    gb: [[T; I]; N],
    kin: AemKinematics<T>,
    start: Option<InputStart<T, N, I>>,
    condition: f64,
}

/// Start-up operators `M⁻¹B` and `M⁻¹C`, `M⁻¹K` for `q0 = M⁻¹(B w0 − C v0 − K u0)`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct InputStart<T, const N: usize, const I: usize> {
    minv_b: [[T; I]; N],
    ops: StartOps<T, N>,
}

/// The `f64` operators: the kernel's, with `G B` and `M⁻¹ B`.
struct InputOps<const N: usize, const I: usize> {
    gb: Mat<N, I>,
    gc: Mat<N, N>,
    gk: Mat<N, N>,
    kin: AemKinematics<f64>,
    start: Option<(Mat<N, I>, StartOps<f64, N>)>,
    condition: f64,
}

/// Check `B` and build every operator in `f64` (`const`, shared by both constructors).
const fn input_operators<const N: usize, const I: usize>(
    m: &Rows<N>,
    c: &Rows<N>,
    k: &Rows<N>,
    b: &Mat<N, I>,
    h: f64,
    max: f64,
) -> Result<InputOps<N, I>, Error> {
    let (op, gb, minv_b) = match input_kernel_operators(m, c, k, b, h, 0.25, 0.5, max) {
        Ok(ops) => ops,
        Err(e) => return Err(e),
    };
    let start = match (minv_b, op.start) {
        (Some(mb), Some((_, s))) => Some((mb, s)),
        _ => None,
    };
    let start_ok = match &start {
        Some((mb, _)) => finite_as(mb, max),
        None => true,
    };
    if !(finite_as(&gb, max) && start_ok) {
        return Err(Error::OperatorOverflow);
    }
    Ok(InputOps {
        gb,
        gc: op.gc,
        gk: op.gk,
        kin: op.aem,
        start,
        condition: op.condition,
    })
}

impl<T: Real, const N: usize, const I: usize> LinearInput<T, N, I> {
    mck_fn! {
        /// Precompute the step operators for `M u'' + C u' + K u = B w(t)` with step `h` (s).
        ///
        /// `M, C, K` are `N×N` (as for [`Linear::new`](crate::Linear::new)), `B` is `N×I`, all
        /// in `f64`; computed in `f64`, rounded once to `T`.
        ///
        /// Errors: [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`],
        /// [`Error::SingularEffectiveMatrix`], [`Error::OperatorOverflow`], [`Error::OperatorUnderflow`].
        ///
        /// Cost: about `4N³ + 2N²·I` flops in `f64`, a few `N×N` `f64` temporaries on the stack.
        pub fn new(m, c, k, b: &SMatrix<f64, N, I>, h: f64) {
            let op = input_operators(
                &rows_f64(m),
                &rows_f64(c),
                &rows_f64(k),
                &rows_f64(b),
                h,
                T::MAX,
            )?;
            let (gc, gk): ([[T; N]; N], [[T; N]; N]) =
                (linalg::round_rows(&op.gc), linalg::round_rows(&op.gk));
            Ok(Self {
                ops: interleave([&gc, &gk], [-T::one(), -T::one()]),
                gb: linalg::round_rows(&op.gb),
                kin: op.kin.round(),
                start: op.start.map(|(mb, s)| InputStart {
                    minv_b: linalg::round_rows(&mb),
                    ops: s.round(),
                }),
                condition: op.condition,
            })
        }
    }

    /// How close the effective matrix is to singular: `κ₁` of the row-equilibrated
    /// effective matrix (each row divided by the size of the terms it was assembled from),
    /// computed once in `f64`; see [`Linear::condition`](crate::Linear::condition). Cost:
    /// O(1).
    pub fn condition(&self) -> f64 {
        self.condition
    }

    /// `G·B = (M + (h/2) C + (h²/4) K)⁻¹ B`, `N×I`.
    pub fn input_operator(&self) -> SMatrix<T, N, I> {
        SMatrix::from_fn(|i, j| self.gb[i][j])
    }
}

/// Const-fn construction, for operators computed at compile time into flash.
macro_rules! const_ctor {
    ($t:ident, $from_rows:ident) => {
        impl<const N: usize, const I: usize> LinearInput<$t, N, I> {
            /// `const fn` twin of [`LinearInput::new`]: `M, C, K` (`N×N`) and `B` (`N×I`)
            /// as row-major `f64` arrays, `h` in seconds; bit-identical to
            /// [`LinearInput::new`] given the same values. In a `static`, no factorization
            /// code is linked in.
            ///
            /// **Matrices are row-major** (`m[i][j]`: row `i`, column `j`; [`Rows`](crate::models::Rows)); to pass
            /// nalgebra data use [`models::rows_of`](crate::models::rows_of), and to convert these
            /// arrays to nalgebra use [`models::matrix_of`](crate::models::matrix_of), not `SMatrix::from`,
            /// which reads columns.
            ///
            /// **Size limit at compile time**, as for
            /// [`Linear::from_rows_f32`](crate::Linear::from_rows_f32): measured with rustc 1.95,
            /// `LinearInput<f32, N, 1>` compiles in a `static` up to `N = 63` and stops at 64
            /// with the `long_running_const_eval` lint (allow it at the firmware's crate
            /// root, or build at run time with [`LinearInput::new`]).
            ///
            /// Errors: as [`LinearInput::new`].
            pub const fn $from_rows(
                m: Rows<N>,
                c: Rows<N>,
                k: Rows<N>,
                b: Mat<N, I>,
                h: f64,
            ) -> Result<Self, Error> {
                let op = match input_operators(&m, &c, &k, &b, h, $t::MAX as f64) {
                    Ok(op) => op,
                    Err(e) => return Err(e),
                };
                let (gc, gk) = (
                    linalg::const_round!($t, rows op.gc),
                    linalg::const_round!($t, rows op.gk),
                );
                let mut ops = [[[0.0; N]; 2]; N];
                let mut i = 0;
                while i < N {
                    let mut j = 0;
                    while j < N {
                        ops[i][0][j] = -gc[i][j];
                        ops[i][1][j] = -gk[i][j];
                        j += 1;
                    }
                    i += 1;
                }
                Ok(Self {
                    ops: OpRows::new(ops),
                    gb: linalg::const_round!($t, rows op.gb),
                    kin: linalg::const_round!($t, kin op.kin),
                    start: match op.start {
                        Some((mb, s)) => Some(InputStart {
                            minv_b: linalg::const_round!($t, rows mb),
                            ops: StartOps::<$t, N>::rounded(&s),
                        }),
                        None => None,
                    },
                    condition: op.condition,
                })
            }

            /// The time step `h` (s), usable in `const` contexts: the same value as
            /// [`Stepper::time_step`](crate::Stepper::time_step), which generic code still
            /// calls. Cost: none.
            pub const fn time_step(&self) -> $t {
                self.kin.h
            }
        }
    };
}
const_ctor!(f32, from_rows_f32);
const_ctor!(f64, from_rows_f64);

impl<T: Real, const N: usize, const I: usize> Stepper<T, N> for LinearInput<T, N, I> {
    type Input = SVector<T, I>;
    type State = State<T, N>;

    #[inline]
    fn time_step(&self) -> T {
        self.kin.h
    }

    start_fn! {
        /// The state at `t = 0` with `q0 = M⁻¹ (B w0 − C v0 − K u0)` (paper eq. 40).
        /// Cost: `2N² + N·I` multiply-adds.
        fn start(&self, u0, v0, w0: &SVector<T, I>) -> State<T, N> {
            // A non-finite input first, as every start in the crate (found by fuzzing).
            if !initial_inputs_finite(u0, v0, w0) {
                return Err(Error::NonFiniteInput);
            }
            let st = self.start.as_ref().ok_or(Error::SingularMass)?;
            let mv = |a: &[[T; N]; N], x: &SVector<T, N>| crate::kernel::mat_vec(a, x);
            let a0 = crate::kernel::mat_vec(&st.minv_b, w0)
                - mv(&st.ops.minv_c, v0)
                - mv(&st.ops.minv_k, u0);
            State::initial_computed(u0, v0, a0)
        }
    }

    crate::stepper::full_order_state!();

    /// Cost: `2N² + N·I` multiply-adds + `7N`; fixed, no allocation, no panic.
    #[inline]
    fn step(&self, s: &mut State<T, N>, w: &SVector<T, I>) {
        input_step(&self.gb, &self.ops, &self.kin, s, w);
    }
}
