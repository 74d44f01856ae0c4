//! Coulomb friction regularized in the velocity.

use super::{Law, LawTrial, positive, rounded};
use crate::{Error, Param, Real};

/// A friction device: Coulomb friction of slip force `f_s`, regularized in the velocity,
///
/// ```text
/// f = f_s tanh(ḋ / v_r),   ∂f/∂ḋ = (f_s / v_r) (1 − tanh²(ḋ / v_r)),   ∂f/∂d = 0,
/// ```
///
/// Coulomb's law `f = f_s sgn ḋ` as `v_r → 0`. Memoryless (`History = ()`); it dissipates
/// all its work. For `d = U sin ωt` the work of one cycle is
/// `4 f_s U (1 − π² v_r² / (24 U² ω²) + O(v_r⁴))`: the regularization costs a fraction
/// `(π²/24)(v_r/(Uω))²` of Coulomb's loop. `v_r` trades that against the Newton matrix
/// entry `(h/2) f_s / v_r`: keep `v_r` well below the sliding velocities of interest, but
/// not so small that `(h/2) f_s / v_r` dwarfs the mass it acts on — there Newton can bounce
/// on the `tanh` and the step is refused (`tests/hysteresis.rs` shows one at three times the
/// storey mass; at a third of that Newton converges in under three iterations a step).
///
/// Cost per trial: one `tanh` and 4 flops; no panic.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Friction<T> {
    fs: T,
    inv_vr: T,
    vr: T,
}

impl<T: Real> Friction<T> {
    /// Slip force `fs` (force, finite, `> 0`) and regularization velocity `vr`
    /// (deformation per second, finite, `> 0`).
    ///
    /// Errors: [`Error::InvalidMaterial`]; [`Error::OperatorOverflow`] if a coefficient
    /// does not fit `T`. Cost: O(1).
    pub fn new(fs: f64, vr: f64) -> Result<Self, Error> {
        if !positive(fs) {
            return Err(Error::InvalidMaterial(Param::FrictionForce));
        }
        if !positive(vr) {
            return Err(Error::InvalidMaterial(Param::ReferenceVelocity));
        }
        // `f_s / v_r` too: the trial's damping `(f_s / v_r)(1 − tanh²)` was `∞ · 0 = NaN`
        // with `v_r = 1.25e-308` (found by fuzzing).
        let [fs, inv_vr, vr, _] = rounded::<T, 4>([fs, 1.0 / vr, vr, fs / vr])?;
        Ok(Self { fs, inv_vr, vr })
    }

    /// The slip force `f_s` (force). Cost: O(1).
    pub fn slip_force(&self) -> T {
        self.fs
    }
}

impl<T: Real> Law<T> for Friction<T> {
    type History = ();

    fn initial_history(&self) {}

    #[inline]
    fn trial(&self, _: &(), _d: T, rate: T) -> LawTrial<T, ()> {
        let t = (rate * self.inv_vr).tanh();
        LawTrial {
            force: self.fs * t,
            stiffness: T::zero(),
            damping: self.fs * self.inv_vr * (T::one() - t * t),
            history: (),
            inelastic: rate.abs() > self.vr,
        }
    }

    /// `0`: friction stores no energy.
    fn recoverable_energy(&self, _: &(), _d: T) -> T {
        T::zero()
    }
}
