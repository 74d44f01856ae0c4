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
//! takes `G p_n = (G B) w_n` with `G B` precomputed: `N·I` multiply-adds instead of `N²`,
//! so a step costs `2N² + N·I + 7N` instead of `3N² + 7N`. The sequence is the one
//! [`Linear`](crate::Linear) gives for `p_n = B w_n`, up to rounding (`G B` is formed
//! once in `f64`).

use nalgebra::{SMatrix, SVector};

use crate::linear::{round_rows, rows_f64};
use crate::ops::{self, Mat};
use crate::scalar::initial_inputs_finite;
use crate::{Error, Real, State};

/// Start-up operators `M⁻¹B`, `M⁻¹C`, `M⁻¹K` for `q0 = M⁻¹(B w0 − C v0 − K u0)`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct InputStart<T, const N: usize, const I: usize> {
    minv_b: [[T; I]; N],
    minv_c: [[T; N]; N],
    minv_k: [[T; N]; N],
}

/// The linear AEM stepper for loads `p(t) = B w(t)` entering through an influence matrix
/// `B` (`N×I`, `I` input signals).
///
/// Same scheme and same results as [`Linear`](crate::Linear) fed `p_n = B w_n` (to
/// rounding: the product `G B` is formed once in `f64`), at `2N² + N·I + 7N`
/// multiply-adds a step instead of `3N² + 7N`. Build it with [`LinearInput::new`] (run
/// time) or `LinearInput::from_rows` (`const fn`, operators computed by the compiler into
/// flash), then [`LinearInput::start`] and [`LinearInput::step`].
///
/// Size: `2N² + N·I + 3` values of `T` for stepping, `2N² + N·I` more for start-up.
///
/// ```
/// use aemstep::{models, LinearInput};
/// use nalgebra::vector;
///
/// // The benchmark 5-storey building under base acceleration a_g: B = −M ι.
/// let (m, c, k) = models::five_storey_building();
/// let b: [[f64; 1]; 5] = core::array::from_fn(|i| [-m[i].iter().sum::<f64>()]);
/// let sys = LinearInput::<f64, 5, 1>::from_rows(m, c, k, b, 0.02)?;
/// let mut s = sys.start(&Default::default(), &Default::default(), &vector![0.0])?;
/// sys.step(&mut s, &vector![0.1 * 9.80665]); // a_g = 0.1 g
/// assert!(s.u()[4] < 0.0); // the roof lags behind the ground
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearInput<T, const N: usize, const I: usize> {
    h: T,
    half_h: T,
    quarter_h2: T,
    /// `G·B`, row-major `N×I`.
    gb: [[T; I]; N],
    /// `G·C`, row-major.
    gc: [[T; N]; N],
    /// `G·K`, row-major.
    gk: [[T; N]; N],
    start: Option<InputStart<T, N, I>>,
}

/// The `f64` operators: `(G B, G C, G K, start)`.
type InputOps<const N: usize, const I: usize> = (
    [[f64; I]; N],
    Mat<N>,
    Mat<N>,
    Option<([[f64; I]; N], Mat<N>, Mat<N>)>,
);

/// Check `B` and build every operator in `f64` (`const`, shared by both constructors).
const fn input_operators<const N: usize, const I: usize>(
    m: &Mat<N>,
    c: &Mat<N>,
    k: &Mat<N>,
    b: &[[f64; I]; N],
    h: f64,
) -> Result<InputOps<N, I>, Error> {
    if !ops::all_finite_rect(b) {
        return Err(Error::NonFiniteInput);
    }
    let op = match ops::operators(m, c, k, h) {
        Ok(op) => op,
        Err(e) => return Err(e),
    };
    let start = match op.start {
        Some((mi, mc, mk)) => Some((ops::mul_rect(&mi, b), mc, mk)),
        None => None,
    };
    Ok((ops::mul_rect(&op.g, b), op.gc, op.gk, start))
}

impl<T: Real, const N: usize, const I: usize> LinearInput<T, N, I> {
    /// Precompute the step operators for `M u'' + C u' + K u = B w(t)` with step `h` (s).
    ///
    /// `M, C, K` are `N×N` (as for [`Linear::new`](crate::Linear::new)), `B` is `N×I`.
    /// Computed in `f64`, rounded once to `T`.
    ///
    /// Errors: [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`],
    /// [`Error::SingularEffectiveMatrix`].
    ///
    /// Cost: about `5N³ + 2N²·I` flops in `f64`, a few `N×N` `f64` temporaries on the stack.
    pub fn new(
        m: &SMatrix<T, N, N>,
        c: &SMatrix<T, N, N>,
        k: &SMatrix<T, N, N>,
        b: &SMatrix<T, N, I>,
        h: T,
    ) -> Result<Self, Error> {
        let hf = h.as_f64();
        let (gb, gc, gk, start) =
            input_operators(&rows_f64(m), &rows_f64(c), &rows_f64(k), &rows_f64(b), hf)?;
        Ok(Self {
            h,
            half_h: T::from_f64_rounded(0.5 * hf),
            quarter_h2: T::from_f64_rounded(0.25 * hf * hf),
            gb: round_rows(&gb),
            gc: round_rows(&gc),
            gk: round_rows(&gk),
            start: start.map(|(mb, mc, mk)| InputStart {
                minv_b: round_rows(&mb),
                minv_c: round_rows(&mc),
                minv_k: round_rows(&mk),
            }),
        })
    }

    /// The time step `h` (s).
    pub fn time_step(&self) -> T {
        self.h
    }

    /// `G·B = (M + (h/2) C + (h²/4) K)⁻¹ B`, `N×I`.
    pub fn input_operator(&self) -> SMatrix<T, N, I> {
        SMatrix::from_fn(|i, j| self.gb[i][j])
    }

    /// The state at `t = 0` with `q0 = M⁻¹ (B w0 − C v0 − K u0)` (paper eq. 40).
    ///
    /// Errors: [`Error::NonFiniteInput`]; [`Error::SingularMass`] if `M` is singular (then
    /// use [`LinearInput::start_with_acceleration`]); [`Error::NonFiniteState`].
    /// Cost: `2N² + N·I` multiply-adds.
    pub fn start(
        &self,
        u0: &SVector<T, N>,
        v0: &SVector<T, N>,
        w0: &SVector<T, I>,
    ) -> Result<State<T, N>, Error> {
        let ops = self.start.as_ref().ok_or(Error::SingularMass)?;
        if !initial_inputs_finite(u0, v0, w0) {
            return Err(Error::NonFiniteInput);
        }
        let a0 = SVector::<T, N>::from_fn(|i, _| {
            let mut s = T::zero();
            for j in 0..I {
                s += ops.minv_b[i][j] * w0[j];
            }
            for j in 0..N {
                s -= ops.minv_c[i][j] * v0[j] + ops.minv_k[i][j] * u0[j];
            }
            s
        });
        State::initial_computed(u0, v0, a0)
    }

    /// The state at `t = 0` with a known initial acceleration `a0`.
    ///
    /// Errors: [`Error::NonFiniteInput`].
    pub fn start_with_acceleration(
        &self,
        u0: &SVector<T, N>,
        v0: &SVector<T, N>,
        a0: &SVector<T, N>,
    ) -> Result<State<T, N>, Error> {
        State::initial_given(u0, v0, a0)
    }

    /// Advance `state` from `t_{n−1}` to `t_n` under the input `w_n = w(t_n)`.
    ///
    /// Cost: `2N² + N·I` multiply-adds + `7N`; fixed, no allocation, no panic. A NaN
    /// input gives a NaN state: use [`LinearInput::try_step`] where that must not happen.
    #[inline]
    pub fn step(&self, s: &mut State<T, N>, w: &SVector<T, I>) {
        let (half_h, h, quarter_h2) = (self.half_h, self.h, self.quarter_h2);
        let mut vh = [T::zero(); N];
        let mut uh = [T::zero(); N];
        for j in 0..N {
            vh[j] = s.v[j] + half_h * s.a[j];
            uh[j] = s.u[j] + h * s.v[j] + quarter_h2 * s.a[j];
        }
        for i in 0..N {
            let (gb, gc, gk) = (&self.gb[i], &self.gc[i], &self.gk[i]);
            let mut q = T::zero();
            for j in 0..I {
                q += gb[j] * w[j];
            }
            for j in 0..N {
                q -= gc[j] * vh[j] + gk[j] * uh[j];
            }
            s.a[i] = q;
            s.v[i] = vh[i] + half_h * q;
            s.u[i] = uh[i] + quarter_h2 * q;
        }
        s.n = s.n.wrapping_add(1);
    }

    /// [`LinearInput::step`], committed only if the new state is finite.
    ///
    /// Errors: [`Error::NonFiniteState`], leaving `state` bit-identical.
    /// Cost: one step plus a copy and a scan of `3N` values.
    pub fn try_step(&self, state: &mut State<T, N>, w: &SVector<T, I>) -> Result<(), Error> {
        let mut next = *state;
        self.step(&mut next, w);
        if next.is_finite() {
            *state = next;
            Ok(())
        } else {
            Err(Error::NonFiniteState)
        }
    }
}

/// Const-fn construction, for operators computed at compile time into flash.
macro_rules! const_ctor {
    ($t:ident) => {
        impl<const N: usize, const I: usize> LinearInput<$t, N, I> {
            /// `const fn` twin of [`LinearInput::new`]: `M, C, K` (`N×N`) and `B` (`N×I`)
            /// as row-major `f64` arrays, `h` in seconds. Computes in `f64` and rounds
            /// once, so the result is bit-identical to [`LinearInput::new`] given the same
            /// values. In a `static`, no inversion code is linked in.
            ///
            /// Errors: as [`LinearInput::new`].
            pub const fn from_rows(
                m: [[f64; N]; N],
                c: [[f64; N]; N],
                k: [[f64; N]; N],
                b: [[f64; I]; N],
                h: f64,
            ) -> Result<Self, Error> {
                let (gb, gc, gk, start) = match input_operators(&m, &c, &k, &b, h) {
                    Ok(op) => op,
                    Err(e) => return Err(e),
                };
                Ok(Self {
                    h: h as $t,
                    half_h: (0.5 * h) as $t,
                    quarter_h2: (0.25 * h * h) as $t,
                    gb: ops::const_round!($t, rows gb),
                    gc: ops::const_round!($t, rows gc),
                    gk: ops::const_round!($t, rows gk),
                    start: match start {
                        Some((mb, mc, mk)) => Some(InputStart {
                            minv_b: ops::const_round!($t, rows mb),
                            minv_c: ops::const_round!($t, rows mc),
                            minv_k: ops::const_round!($t, rows mk),
                        }),
                        None => None,
                    },
                })
            }
        }
    };
}
const_ctor!(f32);
const_ctor!(f64);
