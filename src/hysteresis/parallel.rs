//! Two laws side by side in one storey (e.g. an elastic–plastic frame and a friction
//! damper).

use super::{Law, LawTrial};
use crate::Real;

/// Two laws acting in parallel on the same deformation: `f = f_a + f_b`, tangents added,
/// both histories kept, inelastic when either is. E.g. a storey whose frame is
/// [`Bilinear`](super::Bilinear) with a [`Friction`](super::Friction) damper across it.
///
/// Each law's constructor checks that its own coefficients and largest hysteretic force fit
/// `T`; their sum may not (`f_y + f_s` beyond `T::MAX`): such a trial's force is `±∞`, and
/// the stepper reports [`Error::NonFiniteForce`](crate::Error::NonFiniteForce) without
/// taking the step.
///
/// Cost per trial: one trial of each law and 3 additions; no panic.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Parallel<A, B>(pub A, pub B);

impl<T: Real, A: Law<T>, B: Law<T>> Law<T> for Parallel<A, B> {
    type History = (A::History, B::History);

    fn initial_history(&self) -> Self::History {
        (self.0.initial_history(), self.1.initial_history())
    }

    #[inline]
    fn trial(&self, committed: &Self::History, d: T, rate: T) -> LawTrial<T, Self::History> {
        let a = self.0.trial(&committed.0, d, rate);
        let b = self.1.trial(&committed.1, d, rate);
        LawTrial {
            force: a.force + b.force,
            stiffness: a.stiffness + b.stiffness,
            damping: a.damping + b.damping,
            history: (a.history, b.history),
            inelastic: a.inelastic || b.inelastic,
        }
    }

    /// The sum of both laws' recoverable energies.
    fn recoverable_energy(&self, history: &Self::History, d: T) -> T {
        self.0.recoverable_energy(&history.0, d) + self.1.recoverable_energy(&history.1, d)
    }
}
