//! Linear equations of motion with time-varying coefficients,
//! `M(t) u'' + C(t) u' + K(t) u = p(t)` (paper §3).
//!
//! The step is the linear one with the coefficients evaluated at `t_n = n·h`:
//!
//! ```text
//! v̂ = v_{n−1} + (h/2) q_{n−1},   û = u_{n−1} + h v_{n−1} + (h²/4) q_{n−1}
//! (M_n + (h/2) C_n + (h²/4) K_n) q_n = p_n − C_n v̂ − K_n û
//! v_n = v̂ + (h/2) q_n,            u_n = û + (h²/4) q_n
//! ```
//!
//! The effective matrix changes every step, so it is assembled and factorized (LU with
//! partial pivoting) every step. **Cost per step**: one coefficient evaluation, `N³/3 + 5N²`
//! multiply-adds (assembly `2N²`, `C v̂` and `K û` `2N²`, LU `N³/3`, substitutions `N²`).
//! Stack: about four `N×N` matrices of `T`.

use core::marker::PhantomData;

use nalgebra::{SMatrix, SVector};

use crate::kinematics::{AemKinematics, Kinematics, check_time_step_as};
use crate::linalg::lu::solve_in_place_scaled;
use crate::nonlinear::initial_from_equation;
use crate::scalar::initial_inputs_finite;
use crate::{Error, Real, State};

/// The coefficient matrices at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coefficients<T, const N: usize> {
    /// Mass `M(t)`, `N×N`.
    pub mass: SMatrix<T, N, N>,
    /// Damping `C(t)`, `N×N`.
    pub damping: SMatrix<T, N, N>,
    /// Stiffness `K(t)`, `N×N`.
    pub stiffness: SMatrix<T, N, N>,
}

/// Coefficients `M(t), C(t), K(t)` supplied per step. Implemented for every closure
/// `Fn(T) -> Coefficients<T, N>`.
pub trait TimeVarying<T: Real, const N: usize> {
    /// The coefficients at time `t` (s). Must not panic; NaN/∞ entries are reported as
    /// [`Error::NonFiniteInput`].
    fn coefficients(&self, t: T) -> Coefficients<T, N>;
}

impl<T: Real, const N: usize, F: Fn(T) -> Coefficients<T, N>> TimeVarying<T, N> for F {
    fn coefficients(&self, t: T) -> Coefficients<T, N> {
        self(t)
    }
}

/// The AEM stepper for `M(t) u'' + C(t) u' + K(t) u = p(t)` (paper §3) with `N` degrees of
/// freedom, in `f32` or `f64`. It holds only `h`; the coefficients are passed to every
/// call and evaluated at the end of the step, `t_n = n·h` (from the step count):
///
/// ```text
/// v̂ = v_{n−1} + (h/2) q_{n−1},   û = u_{n−1} + h v_{n−1} + (h²/4) q_{n−1}
/// (M_n + (h/2) C_n + (h²/4) K_n) q_n = p_n − C_n v̂ − K_n û      (LU, every step)
/// v_n = v̂ + (h/2) q_n,            u_n = û + (h²/4) q_n
/// ```
///
/// **Cost per step**: one coefficient evaluation and `N³/3 + 5N²` multiply-adds. Stack:
/// about four `N×N` matrices of `T`.
///
/// ```
/// use aemstep::{Coefficients, Varying};
/// use aemstep::{matrix, vector};
///
/// // u'' + (1 + t/10) u = 0: a stiffening oscillator.
/// let coeffs = |t: f64| Coefficients {
///     mass: matrix![1.0],
///     damping: matrix![0.0],
///     stiffness: matrix![1.0 + 0.1 * t],
/// };
/// let stepper = Varying::<f64, 1>::new(0.01)?;
/// let mut s = stepper.start(&coeffs, &vector![1.0], &vector![0.0], &vector![0.0])?;
/// for _ in 0..100 {
///     stepper.try_step(&coeffs, &mut s, &vector![0.0])?;
/// }
/// assert_eq!(s.steps(), 100);
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Varying<T, const N: usize> {
    kin: AemKinematics<T>,
    _n: PhantomData<[T; N]>,
}

fn finite_coefficients<T: Real, const N: usize>(k: &Coefficients<T, N>) -> bool {
    k.mass
        .iter()
        .chain(k.damping.iter())
        .chain(k.stiffness.iter())
        .all(|x| x.is_finite())
}

impl<T: Real, const N: usize> Varying<T, N> {
    /// A stepper with time step `h` (s, `f64`; the kinematics are rounded once to `T`).
    ///
    /// Errors: [`Error::InvalidTimeStep`] (`h` not finite or `≤ 0`). Cost: O(1).
    pub fn new(h: f64) -> Result<Self, Error> {
        Ok(Self {
            kin: AemKinematics::new(check_time_step_as(h, T::MAX)?)?.round(),
            _n: PhantomData,
        })
    }

    /// The time step `h` (s).
    pub fn time_step(&self) -> T {
        self.kin.h
    }

    /// The state at `t = 0` with `q0 = M(0)⁻¹ (p0 − C(0) v0 − K(0) u0)` (paper eq. 40).
    ///
    /// Errors: [`Error::NonFiniteInput`] (inputs or coefficients), [`Error::SingularMass`]
    /// (then use [`Varying::start_with_acceleration`]), [`Error::NonFiniteState`].
    /// Cost: one coefficient evaluation and one `N×N` LU solve.
    pub fn start<Co: TimeVarying<T, N> + ?Sized>(
        &self,
        coefficients: &Co,
        u0: &SVector<T, N>,
        v0: &SVector<T, N>,
        p0: &SVector<T, N>,
    ) -> Result<State<T, N>, Error> {
        let finite = initial_inputs_finite(u0, v0, p0);
        let k = coefficients.coefficients(T::zero());
        if !(finite && finite_coefficients(&k)) {
            return Err(Error::NonFiniteInput);
        }
        initial_from_equation(u0, v0, &k.mass, p0 - k.damping * v0 - k.stiffness * u0)
    }

    start_with_acceleration! {
        /// The state at `t = 0` with a known initial acceleration `a0` (for singular `M(0)`).
    }

    /// Advance `state` from `t_{n−1}` to `t_n = n·h` under the load `p_n = p(t_n)`, with
    /// the coefficients evaluated at `t_n`.
    ///
    /// Errors (each leaves `state` bit-identical): [`Error::NonFiniteInput`] (`p_n` or a
    /// coefficient), [`Error::SingularEffectiveMatrixAtStep`] naming `n` when
    /// `M_n + (h/2) C_n + (h²/4) K_n` is singular to working precision (pivot at most
    /// `N·ε·max|entry|`), [`Error::NonFiniteState`].
    ///
    /// Cost: one coefficient evaluation, `N³/3 + 5N²` multiply-adds; no allocation, no
    /// panic.
    pub fn try_step<Co: TimeVarying<T, N> + ?Sized>(
        &self,
        coefficients: &Co,
        state: &mut State<T, N>,
        p: &SVector<T, N>,
    ) -> Result<(), Error> {
        let n = state.n.wrapping_add(1);
        let t = T::from_f64_rounded(n as f64 * self.kin.h.as_f64());
        let k = coefficients.coefficients(t);
        if !(finite_coefficients(&k) && p.iter().all(|x| x.is_finite())) {
            return Err(Error::NonFiniteInput);
        }
        let (b, c) = (self.kin.half_h, self.kin.quarter_h2);
        let (vh, uh) = self.kin.predict_all(&state.u, &state.v, &state.a);
        let mut meff = k.mass + k.damping * b + k.stiffness * c;
        // Row scales: the size of the terms each row of M + (h/2) C + (h²/4) K is
        // assembled from (a row that cancels to rounding is singular).
        // (Column-major arrays with loop-bounded indices: no bounds-check panic path.)
        let (ma, da, ka) = (&k.mass.data.0, &k.damping.data.0, &k.stiffness.data.0);
        let mut scales = SVector::<T, N>::zeros();
        for j in 0..N {
            for i in 0..N {
                let t = ma[j][i].abs() + b * da[j][i].abs() + c * ka[j][i].abs();
                scales.data.0[0][i] = scales.data.0[0][i].max(t);
            }
        }
        let mut q = p - k.damping * vh - k.stiffness * uh;
        if !solve_in_place_scaled(&mut meff, &mut q, &scales) {
            return Err(Error::SingularEffectiveMatrixAtStep { step: n });
        }
        let (v, u) = self.kin.correct_all(&vh, &uh, &q);
        let next = State::unchecked(u, v, q, n);
        if !next.is_finite() {
            return Err(Error::NonFiniteState);
        }
        *state = next;
        Ok(())
    }
}
