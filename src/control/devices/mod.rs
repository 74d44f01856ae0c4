//! Control devices: the force a device delivers at its deformation, rate and held command,
//! with fixed-size history committed only when a step succeeds, and the structure they act
//! on.
//!
//! A [`Device`] is a [`Law`](crate::hysteresis::Law) that also takes the command (volts
//! or newtons) held over the step and the step `h`: the magnetorheological dampers filter
//! their voltage over the step, an actuator lags its command. [`Coupled`] puts one device
//! between two degrees of freedom (or one and the ground) of a structure (a
//! [`LinearStructure`], or any [`HistoryModel`], e.g. the hysteretic
//! [`ShearBuilding`](crate::hysteresis::ShearBuilding)) and is itself a [`HistoryModel`]:
//! the crate's [`Nonlinear`] stepper advances structure and device
//! together, and a failed step changes neither state, history nor command. The command is
//! set by the caller between steps ([`Coupled::set_command`]), clipped into the device's
//! range.
//!
//! The devices:
//!
//! - [`MrDamper`]: the Bouc–Wen MR damper of Dyke, Spencer, Sain & Carlson (1996), with
//!   voltage-dependent `α`, `c₀` and the first-order filter on the command voltage.
//! - [`MrPhenomenological`]: the modified (phenomenological) model of Spencer, Dyke, Sain &
//!   Carlson (1997), with its internal displacement `y`, integrated implicitly.
//! - [`ForceActuator`]: an ideal force actuator with force and stroke saturation and an
//!   optional first-order lag.
//! - [`Viscous`]: a linear viscous damper (passive baseline).
//!
//! Passive baselines of a controllable damper are constant commands:
//! [`Coupled::passive_off`] (the lowest command, 0 V) and [`Coupled::passive_on`] (the
//! highest, the saturation voltage). A tuned mass damper or an active mass driver is a
//! mass added to the structure: [`mass_damper`] returns the augmented `M`, `C`, `K` and
//! the force input vector; the driver's actuator is a [`ForceActuator`] between the floor
//! and the added mass.
//!
//! A 1-storey frame (1000 kg, 1e6 N/m, 2 % damping) with an MR damper to the ground, the
//! damper switched to full voltage after 0.5 s of a sine ground motion:
//!
//! ```
//! use aemstep::control::{Coupled, Link, LinearStructure, MrDamper, MrParameters};
//! use aemstep::hysteresis::HistoryModel;
//! use aemstep::nalgebra::SVector;
//! use aemstep::NewtonSettings;
//!
//! let damper = MrDamper::<f64>::new(&MrParameters {
//!     c0a: 2.0e3, c0b: 4.0e3, alpha_a: 2.0e5, alpha_b: 4.0e5,
//!     gamma: 3.0e4, beta: 3.0e4, a: 120.0, n: 2.0, eta: 50.0, v_max: 2.25,
//! })?;
//! let frame = LinearStructure::<f64, 1>::new(&[[1000.0]], &[[2.0 * 0.02 * 1000.0 * 31.6]], &[[1e6]])?;
//! let mut model = Coupled::passive_off(frame, damper, Link::Ground(0), 0.002)?;
//! let stepper = model.nonlinear(NewtonSettings::default())?;
//! let zero = SVector::zeros();
//! let (mut s, mut history) =
//!     stepper.start_with_history(&model, &zero, &zero, &zero, &model.initial_history())?;
//! for n in 1..=500 {
//!     if n == 250 {
//!         model.set_command(2.25)?; // volts, held from the next step on
//!     }
//!     let ag = 3.0 * (2.0 * std::f64::consts::PI * 4.0 * 0.002 * n as f64).sin(); // m/s²
//!     stepper.try_step_with_history(&model, &mut s, &mut history, &SVector::from([-1000.0 * ag]))?;
//! }
//! assert!(model.delivered_force(&history).is_finite());
//! # Ok::<(), aemstep::Error>(())
//! ```

mod mass;
mod mr;
mod simple;

pub use mass::{MassDamper, mass_damper};
pub use mr::{
    MrDamper, MrHistory, MrParameters, MrPhenomenological, PhenomenologicalHistory,
    PhenomenologicalParameters,
};
pub use simple::{ActuatorHistory, ForceActuator, Viscous};

use nalgebra::{SMatrix, SVector};

use crate::hysteresis::{HistoryModel, LawTrial, Trial};
use crate::kinematics::check_time_step_as;
use crate::linalg::Rows;
use crate::{Error, NewtonSettings, Nonlinear, Param, Real, Tangent, TridiagonalTangent};
#[cfg(feature = "defmt")]
use defmt::{Format, Formatter, write};

/// A control device `f(d, ḋ, command; history)` between two points of a structure, with
/// deformation `d` and rate `ḋ`: a uniaxial [`Law`](crate::hysteresis::Law) that also
/// takes the command held over the step and the step `h`.
///
/// `f` is the *internal* force, as a storey spring's: positive when it resists a positive
/// deformation (it enters the structure's internal force `F` with `+f` at the first point
/// and `−f` at the second). A trial is a pure function of the committed history: Newton
/// may evaluate any number of trials, and only the stepper commits one (the returned
/// [`LawTrial::history`] of the accepted step). Methods must not panic: a non-finite
/// command, `h` or deformation gives a non-finite force, which the stepper reports as
/// [`Error::NonFiniteForce`] without taking the step.
pub trait Device<T: Real> {
    /// The internal variables (hysteretic variable, filtered voltage, internal
    /// displacement, the force last delivered): plain data.
    type History: Copy + PartialEq + core::fmt::Debug;

    /// The history at rest (zero deformation, zero command). Cost: O(1).
    fn initial_history(&self) -> Self::History;

    /// The history at rest with `command` held since long before `t = 0` (zero
    /// deformation; a damper's filtered voltage at the command): what
    /// [`Coupled`]'s initial history holds, so that a start with the command on (e.g.
    /// [`Coupled::passive_on`]) does not spend the stepper's start-up trial charging the
    /// voltage filter. The default is [`Device::initial_history`] (a device without a
    /// command state). Cost: O(1).
    fn settled_history(&self, command: T) -> Self::History {
        let _ = command;
        self.initial_history()
    }

    /// The range `[lowest, highest]` of the command (volts for a damper, newtons for an
    /// actuator); [`Coupled::set_command`] clips into it. Cost: O(1).
    fn command_limits(&self) -> (T, T);

    /// Force, consistent tangents `∂f/∂d`, `∂f/∂ḋ` of the discrete update and the trial
    /// history at deformation `d` and rate `rate` at the step's end, from the `committed`
    /// history at its start, with `command` held over the step of `h` seconds.
    /// [`LawTrial::inelastic`] is set on a saturated or hysteretic branch.
    fn trial(
        &self,
        committed: &Self::History,
        d: T,
        rate: T,
        command: T,
        h: T,
    ) -> LawTrial<T, Self::History>;

    /// The force delivered at the end of the step that committed `history` (the measured
    /// device force of a control loop), internal-force sign. Cost: O(1).
    fn delivered_force(&self, history: &Self::History) -> T;
}

/// Where a device acts: its deformation is `d = u_i − u_j`, or `d = u_i` to the ground.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Link {
    /// Between degree of freedom `i` and the ground: `d = u_i`.
    Ground(usize),
    /// Between degrees of freedom `i` and `j` (`i ≠ j`): `d = u_i − u_j`.
    Between(usize, usize),
}

impl Link {
    /// `(i, Some(j))` or `(i, None)` for the ground.
    fn ends(self) -> (usize, Option<usize>) {
        match self {
            Link::Ground(i) => (i, None),
            Link::Between(i, j) => (i, Some(j)),
        }
    }
}

// A `Coupled` reaches its structure's vectors and matrices only through these two, at its
// link's ends: `get`/`get_mut`, never an index that could panic in a step. `Coupled::new`
// refuses a link out of range, so the `None` arms are never taken; each caller still
// answers them with a refusal (a NaN force or deformation, which the stepper reports as
// `Error::NonFiniteForce`; no tangent, no band), not with a wrong result.

/// `*entry += x`; `false` (nothing changed) where there is no entry.
fn add_to<T: Real>(entry: Option<&mut T>, x: T) -> bool {
    entry.map(|e| *e += x).is_some()
}

/// `*entry -= x`; `false` (nothing changed) where there is no entry.
fn sub_from<T: Real>(entry: Option<&mut T>, x: T) -> bool {
    entry.map(|e| *e -= x).is_some()
}

/// A linear structure `M u'' + C u' + K u = p` of `N` degrees of freedom as a memoryless
/// [`HistoryModel`] (`History = ()`), the structure of a [`Coupled`] model.
///
/// Cost: a trial is `2N²` multiply-adds; its tangent is `(K, C)` (copied).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearStructure<T, const N: usize> {
    mass: SMatrix<T, N, N>,
    damping: SMatrix<T, N, N>,
    stiffness: SMatrix<T, N, N>,
}

impl<T: Real, const N: usize> LinearStructure<T, N> {
    /// `M` (kg), `C` (N·s/m), `K` (N/m), row-major in `f64`, each entry finite, rounded
    /// once to `T` (`M` is factorized at the stepper's start, which reports a singular
    /// one).
    ///
    /// Errors: [`Error::NonFiniteInput`] (an entry not finite), [`Error::OperatorOverflow`]
    /// (an entry does not fit `T`). Cost: O(N²).
    pub fn new(m: &Rows<N>, c: &Rows<N>, k: &Rows<N>) -> Result<Self, Error> {
        let all = || m.iter().chain(c.iter()).chain(k.iter());
        if !all().flatten().all(|x| x.is_finite()) {
            return Err(Error::NonFiniteInput);
        }
        if !all().all(|row| crate::linalg::all_fit(row, T::MAX)) {
            return Err(Error::OperatorOverflow);
        }
        let round = |a: &Rows<N>| SMatrix::from_fn(|i, j| T::from_f64_rounded(a[i][j]));
        Ok(Self {
            mass: round(m),
            damping: round(c),
            stiffness: round(k),
        })
    }

    /// The damping matrix `C` (N·s/m). Cost: O(1).
    pub fn damping(&self) -> &SMatrix<T, N, N> {
        &self.damping
    }

    /// The stiffness matrix `K` (N/m). Cost: O(1).
    pub fn stiffness(&self) -> &SMatrix<T, N, N> {
        &self.stiffness
    }
}

impl<T: Real, const N: usize> HistoryModel<T, N> for LinearStructure<T, N> {
    type History = ();

    fn initial_history(&self) {}

    fn mass(&self) -> SMatrix<T, N, N> {
        self.mass
    }

    fn trial(&self, _: &(), u: &SVector<T, N>, v: &SVector<T, N>) -> Trial<T, N, ()> {
        Trial {
            force: self.damping * v + self.stiffness * u,
            history: (),
            branch: 0,
        }
    }

    fn tangent(&self, _: &(), _: &SVector<T, N>, _: &SVector<T, N>) -> Option<Tangent<T, N>> {
        Some(Tangent {
            stiffness: self.stiffness,
            damping: self.damping,
        })
    }
}

/// A structure `S` (a [`HistoryModel`] of `N` degrees of freedom) with one [`Device`] `D`
/// at a [`Link`], the device's command held over each step: a [`HistoryModel`] for
/// [`Nonlinear::try_step_with_history`], whose history is the pair (structure's, device's).
///
/// ```text
/// M u'' + F_S(u, u') + b f(bᵀu, bᵀu', command) = p,   b = e_i − e_j  (or e_i)
/// ```
///
/// The device is evaluated at the step's end with the command set before the step (the
/// held output of a controller's DAC) and the time step `h` given at construction: build
/// the stepper with [`Coupled::nonlinear`], which uses the same `h`. The tangent is the
/// structure's plus `∂f/∂d · b bᵀ` and `∂f/∂ḋ · b bᵀ`; the Newton systems stay tridiagonal
/// (`O(N)`, [`HistoryModel::trial_tridiagonal`]) when the structure's are and the device
/// links neighbouring degrees of freedom or degree of freedom 0 to the ground.
///
/// Bit 63 of the trial's branch signature is set when the device is on an inelastic branch
/// (hysteretic loading, saturation).
///
/// Cost of a trial: the structure's trial and one device trial; of a tangent, the
/// structure's tangent, one device trial and `4` additions.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coupled<T, S, D, const N: usize> {
    structure: S,
    device: D,
    link: Link,
    h: T,
    h64: f64,
    command: T,
}

impl<T: Real, S: HistoryModel<T, N>, D: Device<T>, const N: usize> Coupled<T, S, D, N> {
    /// `structure` with `device` at `link`, stepped with `h` (s, finite, `> 0`), the command
    /// at the device's lowest ([`Device::command_limits`]).
    ///
    /// Errors: [`Error::InvalidParameter`]`(`[`Param::Device`]`)` (a link index `≥ N`, or
    /// `i = j`), [`Error::InvalidTimeStep`]. Cost: O(1).
    pub fn new(structure: S, device: D, link: Link, h: f64) -> Result<Self, Error> {
        let (i, j) = link.ends();
        if i >= N || j.is_some_and(|j| j >= N || j == i) {
            return Err(Error::InvalidParameter(Param::Device));
        }
        let h64 = check_time_step_as(h, T::MAX)?;
        let command = device.command_limits().0;
        Ok(Self {
            structure,
            device,
            link,
            h: T::from_f64_rounded(h64),
            h64,
            command,
        })
    }

    /// The passive-off baseline: [`Coupled::new`] with the command held at the device's
    /// lowest (0 V for an MR damper). Errors and cost: as [`Coupled::new`].
    pub fn passive_off(structure: S, device: D, link: Link, h: f64) -> Result<Self, Error> {
        Self::new(structure, device, link, h)
    }

    /// The passive-on baseline: [`Coupled::new`] with the command held at the device's
    /// highest (the saturation voltage of an MR damper). Errors and cost: as
    /// [`Coupled::new`].
    pub fn passive_on(structure: S, device: D, link: Link, h: f64) -> Result<Self, Error> {
        let mut model = Self::new(structure, device, link, h)?;
        model.command = model.device.command_limits().1;
        Ok(model)
    }

    /// The [`Nonlinear`] stepper for this model: its `h` and `settings`.
    ///
    /// Errors: as [`Nonlinear::new`]. Cost: O(1).
    pub fn nonlinear(&self, settings: NewtonSettings<T>) -> Result<Nonlinear<T, N>, Error> {
        Nonlinear::new(self.h64, settings)
    }

    /// Hold `command` (volts or newtons, as the device takes it) over the next steps,
    /// clipped into [`Device::command_limits`]; returns the command held.
    ///
    /// Errors: [`Error::NonFiniteInput`] (`command` not finite); then the command held
    /// before is kept. Cost: O(1).
    pub fn set_command(&mut self, command: T) -> Result<T, Error> {
        if !command.is_finite() {
            return Err(Error::NonFiniteInput);
        }
        let (lo, hi) = self.device.command_limits();
        self.command = if command < lo {
            lo
        } else if command > hi {
            hi
        } else {
            command
        };
        Ok(self.command)
    }

    /// The command held over the next step. Cost: O(1).
    pub fn command(&self) -> T {
        self.command
    }

    /// The structure. Cost: O(1).
    pub fn structure(&self) -> &S {
        &self.structure
    }

    /// The device. Cost: O(1).
    pub fn device(&self) -> &D {
        &self.device
    }

    /// Where the device acts. Cost: O(1).
    pub fn link(&self) -> Link {
        self.link
    }

    /// The device's deformation `bᵀx` of a displacement (or velocity) vector `x`. Cost: one
    /// subtraction; no panic.
    pub fn deformation(&self, x: &SVector<T, N>) -> T {
        let (i, j) = self.link.ends();
        let d = match (x.get(i), j.map(|j| x.get(j))) {
            (Some(&xi), None) => Some(xi),
            (Some(&xi), Some(Some(&xj))) => Some(xi - xj),
            _ => None,
        };
        d.unwrap_or(T::from_f64_rounded(f64::NAN))
    }

    /// The force the device delivered at the end of the step that committed `history`
    /// ([`Device::delivered_force`]). Cost: O(1).
    pub fn delivered_force(&self, history: &(S::History, D::History)) -> T {
        self.device.delivered_force(&history.1)
    }

    /// The device's trial at `(u, v)` from its committed history.
    fn device_trial(
        &self,
        committed: &D::History,
        u: &SVector<T, N>,
        v: &SVector<T, N>,
    ) -> LawTrial<T, D::History> {
        self.device.trial(
            committed,
            self.deformation(u),
            self.deformation(v),
            self.command,
            self.h,
        )
    }

    /// `force + b f`, the pair history and the branch with bit 63 for the device.
    fn combine(
        &self,
        st: Trial<T, N, S::History>,
        dt: &LawTrial<T, D::History>,
    ) -> Trial<T, N, (S::History, D::History)> {
        let mut force = st.force;
        let (i, j) = self.link.ends();
        let placed = add_to(force.get_mut(i), dt.force)
            && j.is_none_or(|j| sub_from(force.get_mut(j), dt.force));
        if !placed {
            force = SVector::repeat(T::from_f64_rounded(f64::NAN));
        }
        Trial {
            force,
            history: (st.history, dt.history),
            branch: st.branch | (u64::from(dt.inelastic) << 63),
        }
    }
}

impl<T: Real, S: HistoryModel<T, N>, D: Device<T>, const N: usize> HistoryModel<T, N>
    for Coupled<T, S, D, N>
{
    type History = (S::History, D::History);

    /// The structure's virgin history and the device settled at the current command
    /// ([`Device::settled_history`]).
    fn initial_history(&self) -> Self::History {
        (
            self.structure.initial_history(),
            self.device.settled_history(self.command),
        )
    }

    fn mass(&self) -> SMatrix<T, N, N> {
        self.structure.mass()
    }

    fn trial(
        &self,
        committed: &(S::History, D::History),
        u: &SVector<T, N>,
        v: &SVector<T, N>,
    ) -> Trial<T, N, (S::History, D::History)> {
        let st = self.structure.trial(&committed.0, u, v);
        let dt = self.device_trial(&committed.1, u, v);
        self.combine(st, &dt)
    }

    /// The structure's tangent plus the device's `∂f/∂d`, `∂f/∂ḋ` on `b bᵀ`; `None` when
    /// the structure gives none (finite differences of the whole trial).
    fn tangent(
        &self,
        committed: &(S::History, D::History),
        u: &SVector<T, N>,
        v: &SVector<T, N>,
    ) -> Option<Tangent<T, N>> {
        let mut t = self.structure.tangent(&committed.0, u, v)?;
        let dt = self.device_trial(&committed.1, u, v);
        let (i, j) = self.link.ends();
        for (m, x) in [
            (&mut t.stiffness, dt.stiffness),
            (&mut t.damping, dt.damping),
        ] {
            let placed = add_to(m.get_mut((i, i)), x)
                && j.is_none_or(|j| {
                    add_to(m.get_mut((j, j)), x)
                        && sub_from(m.get_mut((i, j)), x)
                        && sub_from(m.get_mut((j, i)), x)
                });
            if !placed {
                return None;
            }
        }
        Some(t)
    }

    /// The structure's tridiagonal trial with the device added to the bands, when the
    /// device links neighbours (`|i − j| = 1`) or degree of freedom 0 to the ground; `None`
    /// otherwise or when the structure's is `None`.
    fn trial_tridiagonal(
        &self,
        committed: &(S::History, D::History),
        u: &SVector<T, N>,
        v: &SVector<T, N>,
        tangent: &mut TridiagonalTangent<T, N>,
    ) -> Option<Trial<T, N, (S::History, D::History)>> {
        let (i, j) = self.link.ends();
        let banded = match j {
            None => i == 0,
            Some(j) => i.abs_diff(j) == 1,
        };
        // In range too (always, for a link `Coupled::new` took), before `tangent` is
        // written: a `None` leaves it as it was.
        if !(banded && i.max(j.unwrap_or(i)) < N) {
            return None;
        }
        let st = self
            .structure
            .trial_tridiagonal(&committed.0, u, v, tangent)?;
        let dt = self.device_trial(&committed.1, u, v);
        for (band, x) in [
            (&mut tangent.stiffness, dt.stiffness),
            (&mut tangent.damping, dt.damping),
        ] {
            let placed = add_to(band.diagonal.get_mut(i), x)
                && j.is_none_or(|j| {
                    add_to(band.diagonal.get_mut(j), x) && sub_from(band.off.get_mut(i.max(j)), x)
                });
            if !placed {
                return None;
            }
        }
        Some(self.combine(st, &dt))
    }
}

#[cfg(feature = "defmt")]
crate::defmt_impls::format_impls! {
    impl[T: Real + Format, const N: usize] Format for LinearStructure<T, N> => |s|
        "LinearStructure {{ mass (columns): {}, damping (columns): {}, stiffness (columns): {} }}",
        s.mass.as_slice(), s.damping.as_slice(), s.stiffness.as_slice();
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SymTridiagonal;
    use crate::hysteresis::{Bilinear, ShearBuilding};

    /// A 3-storey shear building (300 kg, 3e5 N/m, storey dashpots of 400 N·s/m: its
    /// tangent is tridiagonal) with a 50 N·s/m viscous damper at `link`, built past
    /// `Coupled::new`'s check (a link it refuses too).
    fn model(link: Link) -> Coupled<f64, ShearBuilding<f64, Bilinear<f64>, 3>, Viscous<f64>, 3> {
        let c = 400.0;
        let cc = [[2.0 * c, -c, 0.0], [-c, 2.0 * c, -c], [0.0, -c, c]];
        let law = Bilinear::new(3e5, 1e12, 0.0).unwrap();
        let building = ShearBuilding::new([300.0; 3], [law; 3], &cc).unwrap();
        Coupled {
            structure: building,
            device: Viscous::new(50.0).unwrap(),
            link,
            h: 1e-3,
            h64: 1e-3,
            command: 0.0,
        }
    }

    fn bands(x: f64) -> TridiagonalTangent<f64, 3> {
        let b = SymTridiagonal {
            diagonal: SVector::repeat(x),
            off: SVector::repeat(x),
        };
        TridiagonalTangent {
            mass: b,
            stiffness: b,
            damping: b,
        }
    }

    /// Every link `Coupled::new` takes: the force, the tangent and the bands are the
    /// structure's plus `b f`, `∂f/∂ḋ · b bᵀ` written out here by index from
    /// `b = e_i − e_j`, bit for bit.
    #[test]
    fn coupled_places_the_device_at_its_link() {
        let u = SVector::<f64, 3>::from([1e-3, -2e-3, 4e-3]);
        let v = SVector::from([0.3, 0.1, -0.2]);
        let c = 50.0;
        for link in [
            Link::Ground(0),
            Link::Ground(2),
            Link::Between(0, 1),
            Link::Between(2, 1),
            Link::Between(2, 0),
        ] {
            let m = model(link);
            assert!(Coupled::new(m.structure, m.device, link, 1e-3).is_ok());
            let (i, j) = link.ends();
            let (d, rate) = match j {
                None => (u[i], v[i]),
                Some(j) => (u[i] - u[j], v[i] - v[j]),
            };
            assert_eq!(m.deformation(&u).to_bits(), d.to_bits());
            let f = c * rate;
            let h = m.initial_history();
            let mut force = m.structure.trial(&h.0, &u, &v).force;
            force[i] += f;
            if let Some(j) = j {
                force[j] -= f;
            }
            assert_eq!(m.trial(&h, &u, &v).force, force, "{link:?}");
            let mut damping = m.structure.tangent(&h.0, &u, &v).unwrap().damping;
            damping[(i, i)] += c;
            if let Some(j) = j {
                damping[(j, j)] += c;
                damping[(i, j)] -= c;
                damping[(j, i)] -= c;
            }
            assert_eq!(m.tangent(&h, &u, &v).unwrap().damping, damping, "{link:?}");
            let mut band = bands(0.0);
            let banded = m.trial_tridiagonal(&h, &u, &v, &mut band);
            assert_eq!(
                banded.is_some(),
                matches!(
                    link,
                    Link::Ground(0) | Link::Between(0, 1) | Link::Between(2, 1)
                )
            );
            if banded.is_some() {
                assert_eq!(band.damping.to_matrix(), damping, "{link:?}");
            }
        }
    }

    /// A link out of range (which `Coupled::new` refuses, so only a literal builds it):
    /// no index panics; the deformation and the force are NaN, there is no tangent and no
    /// band (the bands untouched), and the stepper refuses the step with a typed error,
    /// the state unchanged.
    #[test]
    fn a_link_out_of_range_is_refused_not_a_panic() {
        let u = SVector::<f64, 3>::from([1e-3, -2e-3, 4e-3]);
        let v = SVector::from([0.3, 0.1, -0.2]);
        for link in [Link::Ground(3), Link::Between(3, 2), Link::Between(1, 7)] {
            let m = model(link);
            assert_eq!(
                Coupled::new(m.structure, m.device, link, 1e-3).err(),
                Some(Error::InvalidParameter(Param::Device))
            );
            let h = m.initial_history();
            assert!(m.deformation(&u).is_nan());
            assert!(m.trial(&h, &u, &v).force.iter().all(|f| f.is_nan()));
            assert_eq!(m.tangent(&h, &u, &v), None);
            let mut band = bands(7.0);
            assert!(m.trial_tridiagonal(&h, &u, &v, &mut band).is_none());
            assert_eq!(band, bands(7.0));
            let stepper = m.nonlinear(NewtonSettings::default()).unwrap();
            let z = SVector::zeros();
            let mut state = crate::State {
                u: z,
                v: z,
                a: z,
                n: 0,
            };
            let mut history = h;
            let before = (state, history);
            assert_eq!(
                stepper.try_step_with_history(&m, &mut state, &mut history, &SVector::repeat(1.0)),
                Err(Error::NonFiniteForce),
                "{link:?}"
            );
            assert_eq!((state, history), before);
        }
    }
}
