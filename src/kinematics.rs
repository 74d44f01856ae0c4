//! The predictor–corrector kinematics every stepper shares, and the one time-step check.
//!
//! The Newmark family (the AEM is β = 1/4, γ = 1/2) advances with the acceleration `q_n`
//! of the end of the step as the only unknown:
//!
//! ```text
//! predict   v̂ = v + (1 − γ) h a          û = u + h v̂ − (β + 1/2 − γ) h² a
//! correct   v_n = v̂ + γ h q_n             u_n = û + β h² q_n
//! ```
//!
//! `û` is formed from `v̂` (`= u + h v + (1/2 − β) h² a` in exact arithmetic): one
//! operation fewer per degree of freedom, and for the AEM it halves the rounding of `û` in
//! `f32` (the `h v` and `(h²/4) a` terms of the textbook order are summed as `h v̂`, one
//! rounded product instead of two; measured in `tests/kinematics.rs`). Every stepper —
//! [`Linear`](crate::Linear), [`Newmark`](crate::Newmark),
//! [`LinearInput`](crate::LinearInput), [`Modal`](crate::Modal),
//! [`Nonlinear`](crate::Nonlinear), [`Varying`](crate::Varying) — uses these functions.

use nalgebra::SVector;

use crate::{Error, Real};

/// The five coefficients of the kinematics, `[h, (1 − γ) h, (β + 1/2 − γ) h², γ h, β h²]`,
/// computed in `f64` and rounded once to `T`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Kinematics<T> {
    pub h: T,
    pub c_v: T,
    pub c_u: T,
    pub gamma_h: T,
    pub beta_h2: T,
}

/// The one time-step check: `h` finite and `> 0`, with `h²` neither overflowing nor
/// vanishing (so the kinematics stay finite and nonzero).
///
/// Errors: [`Error::InvalidTimeStep`].
pub(crate) const fn check_time_step(h: f64) -> Result<f64, Error> {
    let h2 = h * h;
    if h.is_finite() && h > 0.0 && h2.is_finite() && h2 > 0.0 {
        Ok(h)
    } else {
        Err(Error::InvalidTimeStep)
    }
}

impl Kinematics<f64> {
    /// The Newmark kinematics (β, γ) for step `h` (s). Errors: [`Error::InvalidTimeStep`].
    pub(crate) const fn newmark(h: f64, beta: f64, gamma: f64) -> Result<Self, Error> {
        let h = match check_time_step(h) {
            Ok(h) => h,
            Err(e) => return Err(e),
        };
        Ok(Self {
            h,
            c_v: (1.0 - gamma) * h,
            c_u: (beta + 0.5 - gamma) * h * h,
            gamma_h: gamma * h,
            beta_h2: beta * h * h,
        })
    }

    /// The AEM's kinematics (β = 1/4, γ = 1/2: `q` constant at the mean of its end
    /// values). Errors: [`Error::InvalidTimeStep`].
    pub(crate) const fn aem(h: f64) -> Result<Self, Error> {
        Self::newmark(h, 0.25, 0.5)
    }

    /// Rounded once to `T` (run time).
    pub(crate) fn round<T: Real>(&self) -> Kinematics<T> {
        Kinematics {
            h: T::from_f64_rounded(self.h),
            c_v: T::from_f64_rounded(self.c_v),
            c_u: T::from_f64_rounded(self.c_u),
            gamma_h: T::from_f64_rounded(self.gamma_h),
            beta_h2: T::from_f64_rounded(self.beta_h2),
        }
    }

    /// Rounded once to `f32` (`const`).
    pub(crate) const fn to_f32(self) -> Kinematics<f32> {
        Kinematics {
            h: self.h as f32,
            c_v: self.c_v as f32,
            c_u: self.c_u as f32,
            gamma_h: self.gamma_h as f32,
            beta_h2: self.beta_h2 as f32,
        }
    }

    /// Itself (`const`; the `f64` twin of [`Kinematics::to_f32`]).
    pub(crate) const fn to_f64(self) -> Kinematics<f64> {
        self
    }
}

impl<T: Real> Kinematics<T> {
    /// `(v̂, û)` of one degree of freedom from `(u, v, a)`. 2 multiply-adds + 1.
    #[inline(always)]
    pub(crate) fn predict(&self, u: T, v: T, a: T) -> (T, T) {
        let vh = v + self.c_v * a;
        (vh, u + self.h * vh - self.c_u * a)
    }

    /// `(v_n, u_n)` of one degree of freedom from `(v̂, û)` and the new acceleration `q`.
    #[inline(always)]
    pub(crate) fn correct(&self, vh: T, uh: T, q: T) -> (T, T) {
        (vh + self.gamma_h * q, uh + self.beta_h2 * q)
    }

    /// [`Kinematics::predict`] for every degree of freedom: `(v̂, û)`.
    #[inline(always)]
    pub(crate) fn predict_all<const N: usize>(
        &self,
        u: &SVector<T, N>,
        v: &SVector<T, N>,
        a: &SVector<T, N>,
    ) -> (SVector<T, N>, SVector<T, N>) {
        let mut vh = SVector::<T, N>::zeros();
        let mut uh = SVector::<T, N>::zeros();
        for j in 0..N {
            (vh[j], uh[j]) = self.predict(u[j], v[j], a[j]);
        }
        (vh, uh)
    }

    /// [`Kinematics::correct`] for every degree of freedom: `(v_n, u_n)`.
    #[inline(always)]
    pub(crate) fn correct_all<const N: usize>(
        &self,
        vh: &SVector<T, N>,
        uh: &SVector<T, N>,
        q: &SVector<T, N>,
    ) -> (SVector<T, N>, SVector<T, N>) {
        (vh + q * self.gamma_h, uh + q * self.beta_h2)
    }
}
