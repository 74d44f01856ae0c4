//! Bilinear elastic–plastic law with linear kinematic hardening, by return mapping.

use super::{Law, LawTrial, check_elastic_plastic, rounded};
use crate::{Error, Real};

/// Bilinear hysteresis with linear kinematic hardening: elastic stiffness `k`, yield force
/// `f_y`, post-yield stiffness `α k`.
///
/// With plastic deformation `d_p` (the history) and back force `H d_p`,
/// `H = α k / (1 − α)`, one step is the return mapping
///
/// ```text
/// f_tr = k (d − d_p),   ξ = f_tr − H d_p
/// |ξ| ≤ f_y:  f = f_tr,                                     ∂f/∂d = k         (elastic)
/// |ξ| > f_y:  Δγ = (|ξ| − f_y)/(k + H),  d_p += sgn(ξ) Δγ,
///             f = f_tr − k sgn(ξ) Δγ,                       ∂f/∂d = α k       (plastic)
/// ```
///
/// exact for any deformation increment (the law is rate-independent and piecewise linear),
/// and `∂f/∂d` is its consistent tangent. The loop of a cycle `±U` (`U > u_y = f_y/k`) is a
/// parallelogram of area `4 f_y (1 − α)(U − u_y)`.
///
/// Cost per trial: 8 flops and 2 comparisons; no panic.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bilinear<T> {
    k: T,
    fy: T,
    hard: T,
    one_minus_alpha: T,
    /// `(1 − α)/k = 1/(k + H)`.
    compliance_p: T,
    kt: T,
}

/// The history of a [`Bilinear`] law: the plastic deformation `d_p` (deformation units;
/// the back force is `H d_p`).
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BilinearHistory<T> {
    /// Plastic deformation `d_p`.
    pub plastic: T,
}

/// Virgin: as `BilinearHistory::at_rest_f32`/`at_rest_f64`, for any `T`.
impl<T: Real> Default for BilinearHistory<T> {
    fn default() -> Self {
        Self { plastic: T::zero() }
    }
}

macro_rules! bilinear_history_at_rest {
    ($t:ident, $at_rest:ident) => {
        impl BilinearHistory<$t> {
            /// The virgin history, `d_p = 0`: `const fn`, for a `static` (e.g.
            /// `[BilinearHistory::at_rest_f32(); N]` for a shear building); equal to
            /// `BilinearHistory::default()` and to the law's
            /// [`Law::initial_history`]. Cost: none.
            pub const fn $at_rest() -> Self {
                Self { plastic: 0.0 }
            }
        }
    };
}
bilinear_history_at_rest!(f32, at_rest_f32);
bilinear_history_at_rest!(f64, at_rest_f64);

impl<T: Real> Bilinear<T> {
    /// A bilinear law with elastic stiffness `k` (force/deformation, finite, `> 0`), yield
    /// force `fy` (force, finite, `> 0`) and post-yield stiffness ratio `alpha` (finite, in
    /// `[0, 1)`; `0` is elastic–perfectly plastic). Coefficients are computed in `f64` and
    /// rounded once to `T`.
    ///
    /// Errors: [`Error::InvalidMaterial`] for any parameter out of its range or not
    /// finite; [`Error::OperatorOverflow`] if a coefficient does not fit `T` (e.g.
    /// `k > f32::MAX` in `f32`). Cost: O(1).
    pub fn new(k: f64, fy: f64, alpha: f64) -> Result<Self, Error> {
        check_elastic_plastic(k, fy, alpha)?;
        let [k, fy, hard, one_minus_alpha, compliance_p, kt] = rounded::<T, 6>([
            k,
            fy,
            alpha * k / (1.0 - alpha),
            1.0 - alpha,
            (1.0 - alpha) / k,
            alpha * k,
        ])?;
        Ok(Self {
            k,
            fy,
            hard,
            one_minus_alpha,
            compliance_p,
            kt,
        })
    }

    /// The elastic stiffness `k` (force/deformation). Cost: O(1).
    pub fn stiffness(&self) -> T {
        self.k
    }

    /// The yield force `f_y` (force). Cost: O(1).
    pub fn yield_force(&self) -> T {
        self.fy
    }

    /// The post-yield (tangent) stiffness `α k` (force/deformation). Cost: O(1).
    pub fn post_yield_stiffness(&self) -> T {
        self.kt
    }

    /// The hardening modulus `H = α k/(1 − α)` (force/deformation; the back force is
    /// `H d_p`). Cost: O(1).
    pub fn hardening(&self) -> T {
        self.hard
    }
}

impl<T: Real> Law<T> for Bilinear<T> {
    type History = BilinearHistory<T>;

    fn initial_history(&self) -> BilinearHistory<T> {
        BilinearHistory { plastic: T::zero() }
    }

    #[inline]
    fn trial(&self, committed: &BilinearHistory<T>, d: T, _rate: T) -> LawTrial<T, Self::History> {
        let dp = committed.plastic;
        // The whole trial at half scale: `f_h = k (d − d_p) / 2`, `ξ / 2`, the excess over
        // `f_y / 2`, doubled at the end. Halving and doubling are exact in the normal range,
        // so this rounds as the full-scale trial does (no cancellation of `k d − k d_p`),
        // while `d − d_p` (up to `2·T::MAX` with a tiny `k`) and `k (d − d_p)` (beyond
        // `T::MAX` on a reversal from a large plastic offset whose returned force is `±f_y`:
        // `f_y = 3e307`, an offset of `−1.7e299`, found by fuzzing) stay finite; only
        // subnormal forces lose a bit. Branch-free of any overflow test, so the Newton
        // loop's code is as before.
        let two = T::one() + T::one();
        let half = T::one() / two;
        let dp_h = dp * half;
        let f_h = self.k * (d * half - dp_h);
        let xi_h = f_h - self.hard * dp_h;
        let excess_h = xi_h.abs() - self.fy * half;
        if excess_h > T::zero() {
            let s = if xi_h > T::zero() {
                T::one()
            } else {
                -T::one()
            };
            return LawTrial {
                force: (f_h - s * self.one_minus_alpha * excess_h) * two,
                stiffness: self.kt,
                damping: T::zero(),
                history: BilinearHistory {
                    // `d_p + c·excess`: the new `d_p` lies between the committed one and `d`
                    // (plastic flow moves it toward `d`, never past), so it fits `T`.
                    plastic: (dp_h + s * self.compliance_p * excess_h) * two,
                },
                inelastic: true,
            };
        }
        // Elastic (a NaN trial lands here too and stays NaN in the force).
        LawTrial {
            force: f_h * two,
            stiffness: self.k,
            damping: T::zero(),
            history: *committed,
            inelastic: false,
        }
    }

    /// `f² / (2k)`, `f = k (d − d_p)`.
    fn recoverable_energy(&self, history: &BilinearHistory<T>, d: T) -> T {
        let e = d - history.plastic;
        self.k * e * e / (T::one() + T::one())
    }
}

/// Both branches of [`Law::trial`] in every lane, the result selected per lane: each value
/// computed by exactly the operations of the scalar trial, so every lane has its bits,
/// and the loop has no branch (packed instructions).
impl<T: Real> crate::lanes::LaneLaw<T> for Bilinear<T> {
    /// `(k, 0)`: the elastic branch's tangent is the initial stiffness, without damping.
    fn elastic_tangent(&self) -> Option<(T, T)> {
        Some((self.k, T::zero()))
    }

    #[inline(always)]
    fn trial_lanes<const L: usize>(
        &self,
        committed: &[BilinearHistory<T>; L],
        d: &[T; L],
        _rate: &[T; L],
    ) -> crate::lanes::LaneTrial<T, BilinearHistory<T>, L> {
        let two = T::one() + T::one();
        let half = T::one() / two;
        // The stiffnesses read once (a select between two fields read per lane became
        // a select of their addresses and eight scalar loads).
        let (k, kt) = (self.k, self.kt);
        // One operation over all lanes at a time (the compiler packs such loops; one loop
        // of the whole trial a lane was left scalar, with jumps).
        let dp_h: [T; L] = core::array::from_fn(|l| committed[l].plastic * half);
        let f_h: [T; L] = core::array::from_fn(|l| k * (d[l] * half - dp_h[l]));
        let xi_h: [T; L] = core::array::from_fn(|l| f_h[l] - self.hard * dp_h[l]);
        let excess_h: [T; L] = core::array::from_fn(|l| xi_h[l].abs() - self.fy * half);
        let s: [T; L] = core::array::from_fn(|l| {
            if xi_h[l] > T::zero() {
                T::one()
            } else {
                -T::one()
            }
        });
        let f_p: [T; L] =
            core::array::from_fn(|l| (f_h[l] - s[l] * self.one_minus_alpha * excess_h[l]) * two);
        let dp_p: [T; L] =
            core::array::from_fn(|l| (dp_h[l] + s[l] * self.compliance_p * excess_h[l]) * two);
        let plastic: [bool; L] = core::array::from_fn(|l| excess_h[l] > T::zero());
        crate::lanes::LaneTrial {
            force: core::array::from_fn(|l| if plastic[l] { f_p[l] } else { f_h[l] * two }),
            stiffness: core::array::from_fn(|l| if plastic[l] { kt } else { k }),
            damping: [T::zero(); L],
            history: core::array::from_fn(|l| BilinearHistory {
                plastic: if plastic[l] {
                    dp_p[l]
                } else {
                    committed[l].plastic
                },
            }),
            inelastic: plastic,
        }
    }
}
