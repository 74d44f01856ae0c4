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
//! operation fewer per degree of freedom, and less rounding in `f32` where it matters —
//! at ωh ≤ 10⁻² (many steps per period) the `f32` state after 10⁵ steps is 1.7 to 60 times
//! closer to the `f64` recurrence than with the textbook `u + h v + (h²/4) a`; at larger
//! ωh the two are within 1.4× (`tests/kinematics.rs`). Every stepper —
//! [`Linear`](crate::Linear), [`Newmark`](crate::Newmark),
//! [`LinearInput`](crate::LinearInput), [`Modal`](crate::Modal),
//! [`Nonlinear`](crate::Nonlinear), [`Varying`](crate::Varying) — uses these functions.

use nalgebra::SVector;

use crate::{Error, Real};

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

/// `x` rounded to the scalar type whose largest finite value is `max` (`f32` or `f64`, the
/// only [`Real`] types), in `const` contexts.
const fn rounded_as(x: f64, max: f64) -> f64 {
    if max < f64::MAX { x as f32 as f64 } else { x }
}

/// [`check_time_step`] in the scalar type the kinematics are rounded to (largest finite
/// value `max`, e.g. [`Real::MAX`]): also `h`, `h/2` and `h²/4` finite, at most `max` and
/// nonzero once rounded. (`h = 1e58` and `h = 1e-30` pass in `f64` but not in `f32`, where
/// `h` overflows or `h²/4` rounds to zero: an `f32` stepper built from them had infinite or
/// vanishing kinematics. Found by fuzzing.)
///
/// Errors: [`Error::InvalidTimeStep`].
pub(crate) const fn check_time_step_as(h: f64, max: f64) -> Result<f64, Error> {
    let h = match check_time_step(h) {
        Ok(h) => h,
        Err(e) => return Err(e),
    };
    let xs = [h, 0.5 * h, 0.25 * h * h];
    let mut i = 0;
    while i < xs.len() {
        let r = rounded_as(xs[i], max);
        if !(r.is_finite() && r != 0.0 && xs[i] <= max) {
            return Err(Error::InvalidTimeStep);
        }
        i += 1;
    }
    Ok(h)
}

/// The predictor–corrector of the Newmark family, written once: every stepper calls these
/// provided methods. Implemented by [`AemKinematics`] (β = 1/4, γ = 1/2: three stored
/// coefficients, so a step loads three) and [`NewmarkKinematics`] (any β, γ: five).
pub(crate) trait Kinematics<T: Real>: Copy {
    /// `h`.
    fn h(&self) -> T;
    /// `(1 − γ) h`.
    fn c_v(&self) -> T;
    /// `(β + 1/2 − γ) h²`.
    fn c_u(&self) -> T;
    /// `γ h`.
    fn gamma_h(&self) -> T;
    /// `β h²`.
    fn beta_h2(&self) -> T;

    /// `(v̂, û)` of one degree of freedom from `(u, v, a)`. 2 multiply-adds + 1.
    #[inline(always)]
    fn predict(&self, u: T, v: T, a: T) -> (T, T) {
        let vh = v + self.c_v() * a;
        (vh, u + self.h() * vh - self.c_u() * a)
    }

    /// `(v_n, u_n)` of one degree of freedom from `(v̂, û)` and the new acceleration `q`.
    #[inline(always)]
    fn correct(&self, vh: T, uh: T, q: T) -> (T, T) {
        (vh + self.gamma_h() * q, uh + self.beta_h2() * q)
    }

    /// [`Kinematics::predict`] for every degree of freedom: `(v̂, û)`.
    #[inline(always)]
    fn predict_all<const N: usize>(
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
    fn correct_all<const N: usize>(
        &self,
        vh: &SVector<T, N>,
        uh: &SVector<T, N>,
        q: &SVector<T, N>,
    ) -> (SVector<T, N>, SVector<T, N>) {
        let mut v = SVector::<T, N>::zeros();
        let mut u = SVector::<T, N>::zeros();
        for j in 0..N {
            (v[j], u[j]) = self.correct(vh[j], uh[j], q[j]);
        }
        (v, u)
    }
}

/// The AEM's kinematics (β = 1/4, γ = 1/2: `q` constant on the step at the mean of its
/// end values): `h`, `h/2`, `h²/4`, computed in `f64` and rounded once to `T`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct AemKinematics<T> {
    pub h: T,
    pub half_h: T,
    pub quarter_h2: T,
}

impl AemKinematics<f64> {
    /// For step `h` (s). Errors: [`Error::InvalidTimeStep`].
    pub(crate) const fn new(h: f64) -> Result<Self, Error> {
        match check_time_step(h) {
            Ok(h) => Ok(Self {
                h,
                half_h: 0.5 * h,
                quarter_h2: 0.25 * h * h,
            }),
            Err(e) => Err(e),
        }
    }

    /// Rounded once to `T` (run time).
    pub(crate) fn round<T: Real>(&self) -> AemKinematics<T> {
        AemKinematics {
            h: T::from_f64_rounded(self.h),
            half_h: T::from_f64_rounded(self.half_h),
            quarter_h2: T::from_f64_rounded(self.quarter_h2),
        }
    }

    /// Rounded once to `f32` (`const`).
    pub(crate) const fn to_f32(self) -> AemKinematics<f32> {
        AemKinematics {
            h: self.h as f32,
            half_h: self.half_h as f32,
            quarter_h2: self.quarter_h2 as f32,
        }
    }

    /// Itself (`const`; the `f64` twin of [`AemKinematics::to_f32`]).
    pub(crate) const fn to_f64(self) -> AemKinematics<f64> {
        self
    }
}

impl<T: Real> Kinematics<T> for AemKinematics<T> {
    #[inline(always)]
    fn h(&self) -> T {
        self.h
    }
    #[inline(always)]
    fn c_v(&self) -> T {
        self.half_h
    }
    #[inline(always)]
    fn c_u(&self) -> T {
        self.quarter_h2
    }
    #[inline(always)]
    fn gamma_h(&self) -> T {
        self.half_h
    }
    #[inline(always)]
    fn beta_h2(&self) -> T {
        self.quarter_h2
    }
}

/// The kinematics of any Newmark member (β, γ): the five coefficients
/// `[h, (1 − γ) h, (β + 1/2 − γ) h², γ h, β h²]`, computed in `f64`, rounded once to `T`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct NewmarkKinematics<T> {
    pub h: T,
    pub c_v: T,
    pub c_u: T,
    pub gamma_h: T,
    pub beta_h2: T,
}

impl NewmarkKinematics<f64> {
    /// For step `h` (s) and parameters β, γ. Errors: [`Error::InvalidTimeStep`].
    pub(crate) const fn new(h: f64, beta: f64, gamma: f64) -> Result<Self, Error> {
        match check_time_step(h) {
            Ok(h) => Ok(Self {
                h,
                c_v: (1.0 - gamma) * h,
                c_u: (beta + 0.5 - gamma) * h * h,
                gamma_h: gamma * h,
                beta_h2: beta * h * h,
            }),
            Err(e) => Err(e),
        }
    }

    /// Every coefficient finite and at most `max` in size (the largest finite value of the
    /// scalar type they will be rounded to): with a large β or γ, `β h²` can overflow where
    /// `h²` does not.
    pub(crate) const fn fits(&self, max: f64) -> bool {
        crate::linalg::all_fit(
            &[self.h, self.c_v, self.c_u, self.gamma_h, self.beta_h2],
            max,
        )
    }

    /// Rounded once to `T` (run time).
    pub(crate) fn round<T: Real>(&self) -> NewmarkKinematics<T> {
        NewmarkKinematics {
            h: T::from_f64_rounded(self.h),
            c_v: T::from_f64_rounded(self.c_v),
            c_u: T::from_f64_rounded(self.c_u),
            gamma_h: T::from_f64_rounded(self.gamma_h),
            beta_h2: T::from_f64_rounded(self.beta_h2),
        }
    }
}

impl<T: Real> Kinematics<T> for NewmarkKinematics<T> {
    #[inline(always)]
    fn h(&self) -> T {
        self.h
    }
    #[inline(always)]
    fn c_v(&self) -> T {
        self.c_v
    }
    #[inline(always)]
    fn c_u(&self) -> T {
        self.c_u
    }
    #[inline(always)]
    fn gamma_h(&self) -> T {
        self.gamma_h
    }
    #[inline(always)]
    fn beta_h2(&self) -> T {
        self.beta_h2
    }
}
