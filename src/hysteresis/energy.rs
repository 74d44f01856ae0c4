//! The energy account of a hysteretic shear building run.

use nalgebra::SVector;

use super::{Law, ShearBuilding};
use crate::{Error, Real, State};

/// The energy balance of a [`ShearBuilding`] run, kept step by step beside it (fixed size,
/// no allocation):
///
/// ```text
/// E₀ + E_in = E_k + E_s + E_v + E_h + error
/// E_in = ∫ p·du      E_k = ½ vᵀ M v      E_s = Σ recoverable strain energy of the storeys
/// E_v = ∫ (C v)·du   E_h = Σᵢ ∫ fᵢ dδᵢ − (E_s − E_s,₀)   (hysteretic: dissipated by the laws)
/// ```
///
/// with `E₀ = E_k + E_s` at the start. Units: J when the building and loads are SI (kg, N/m,
/// N·s/m, N, m).
///
/// **Quadrature**: each integral is summed per step as mean force times increment,
/// `½(p_{n−1} + p_n)·(u_n − u_{n−1})` (likewise `C v` and the storey forces `fᵢ` against
/// the drifts `δᵢ`): the trapezoidal rule in time, second order (`O(h²)` against the exact
/// integrals), since the AEM step has `u_n − u_{n−1} = (h/2)(v_{n−1} + v_n)`. With it the
/// AEM's discrete balance is exact: the `error` is the equation of motion's residual at
/// the ends of the steps (the Newton tolerance) and rounding, not the quadrature — a
/// diagnostic of the run, while the energies themselves carry the method's `O(h²)` error.
/// A friction law's force counts in `fᵢ`, so its work is hysteretic (it stores nothing).
///
/// Cost per [`EnergyAccount::step`]: `N` law trials, `N²` multiply-adds (`C v`), `5N`.
///
/// ```
/// use aemstep::hysteresis::{Bilinear, EnergyAccount, HistoryModel, ShearBuilding};
/// use aemstep::nalgebra::SVector;
/// use aemstep::{NewtonSettings, Nonlinear, models};
///
/// let law = Bilinear::<f64>::new(1e8, 2e5, 0.05)?;
/// let (m, k) = models::shear_building([1e5; 3], [1e8; 3]);
/// let (a0, a1) = models::rayleigh_coefficients(13.0, 36.0, 0.02);
/// let building =
///     ShearBuilding::new(models::floor_masses(&m), [law; 3], &models::rayleigh(&m, &k, a0, a1))?;
/// let h = 0.005;
/// let stepper = Nonlinear::<f64, 3>::new(h, NewtonSettings::default())?;
/// let zero = SVector::zeros();
/// let p0 = building.ground_load(0.0);
/// let (mut s, mut history) =
///     stepper.start_with_history(&building, &zero, &zero, &p0, &building.initial_history())?;
/// let mut account = EnergyAccount::start(&building, &s, &history, &p0);
/// for n in 1..=400 {
///     let p = building.ground_load(6.0 * (8.0 * h * n as f64).sin()); // m/s²
///     let previous = history;
///     stepper.try_step_with_history(&building, &mut s, &mut history, &p)?;
///     account.step(&building, &previous, &s, &history, &p);
/// }
/// println!(
///     "E_in = {:.0} J: kinetic {:.0}, recoverable {:.0}, viscous {:.0}, hysteretic {:.0} J",
///     account.input, account.kinetic, account.recoverable, account.viscous, account.hysteretic
/// );
/// assert!(account.hysteretic > 0.0); // it yielded
/// assert!(account.max_balance_error()? <= 1e-6 * account.max_input());
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnergyAccount<T, const N: usize> {
    /// `E₀`: kinetic plus recoverable energy at the start (J).
    pub initial: T,
    /// `E_in = ∫ p·du`: work of the loads since the start (J).
    pub input: T,
    /// `E_k = ½ vᵀ M v` now (J).
    pub kinetic: T,
    /// `E_s`: the storeys' recoverable strain energy now
    /// ([`ShearBuilding::recoverable_energy`], J).
    pub recoverable: T,
    /// `E_v = ∫ (C v)·du`: dissipated by the linear damping since the start (J).
    pub viscous: T,
    /// `E_h`: dissipated by the storey laws since the start (J): their work less the
    /// change of their recoverable energy.
    pub hysteretic: T,
    storey_work: T,
    recoverable0: T,
    max_input: T,
    max_error: T,
    u: SVector<T, N>,
    load: SVector<T, N>,
    damping_force: SVector<T, N>,
    storey_force: SVector<T, N>,
}

impl<T: Real, const N: usize> EnergyAccount<T, N> {
    /// The account at the start of a run: the `state` and `history` a stepper's
    /// `start_with_history` returned, and the `load` it started with (N). Cost: as a step.
    pub fn start<L: Law<T>>(
        building: &ShearBuilding<T, L, N>,
        state: &State<T, N>,
        history: &[L::History; N],
        load: &SVector<T, N>,
    ) -> Self {
        let (u, v) = (state.u(), state.v());
        let kinetic = kinetic(building, v);
        let recoverable = building.recoverable_energy(history, u);
        let storeys = building.storeys(history, u, v);
        Self::begin(
            kinetic,
            recoverable,
            [
                *u,
                *load,
                building.damping() * v,
                SVector::from_fn(|i, _| storeys[i].force),
            ],
        )
    }

    /// An account at a start with kinetic and recoverable energies `kinetic`,
    /// `recoverable` (J), every integral zero, and `[u, load, C v, storey forces]` there.
    fn begin(
        kinetic: T,
        recoverable: T,
        [u, load, damping_force, storey_force]: [SVector<T, N>; 4],
    ) -> Self {
        Self {
            initial: kinetic + recoverable,
            input: T::zero(),
            kinetic,
            recoverable,
            viscous: T::zero(),
            hysteretic: T::zero(),
            storey_work: T::zero(),
            recoverable0: recoverable,
            max_input: T::zero(),
            max_error: T::zero(),
            u,
            load,
            damping_force,
            storey_force,
        }
    }

    /// Account for one accepted step: `previous` is the history committed before it,
    /// `state` and `history` the ones it committed, `load` its end load (N). Call it only
    /// after a step succeeded (a failed step changed nothing, so there is nothing to
    /// account). Cost: `N` law trials and `N² + 12N` flops.
    pub fn step<L: Law<T>>(
        &mut self,
        building: &ShearBuilding<T, L, N>,
        previous: &[L::History; N],
        state: &State<T, N>,
        history: &[L::History; N],
        load: &SVector<T, N>,
    ) {
        let half = T::from_f64_rounded(0.5);
        let (u, v) = (state.u(), state.v());
        let du = u - self.u;
        let damping_force = building.damping() * v;
        // The storey forces at the accepted (u, v): the trial from the history before the
        // step, which is the one the stepper accepted.
        let storeys = building.storeys(previous, u, v);
        let storey_force = SVector::<T, N>::from_fn(|i, _| storeys[i].force);
        let d_drift = crate::models::drifts(&du);
        let works = [
            (self.load + load).dot(&du) * half,
            (self.damping_force + damping_force).dot(&du) * half,
            (self.storey_force + storey_force).dot(&d_drift) * half,
        ];
        self.u = *u;
        self.load = *load;
        self.damping_force = damping_force;
        self.storey_force = storey_force;
        self.settle(
            works,
            kinetic(building, v),
            building.recoverable_energy(history, u),
        );
    }
    /// The end of an accounted step: the works of the step (`input`, `viscous`, `storey`:
    /// mean force times increment, J) added, the kinetic and recoverable energies now,
    /// `E_h`, the running maxima. The one update of this account and the run-time-sized
    /// one (`std`, which keeps an `EnergyAccount<T, 0>` for its totals).
    #[inline]
    pub(crate) fn settle(&mut self, [input, viscous, storey]: [T; 3], kinetic: T, recoverable: T) {
        self.input += input;
        self.viscous += viscous;
        self.storey_work += storey;
        self.kinetic = kinetic;
        self.recoverable = recoverable;
        self.hysteretic = self.storey_work - (self.recoverable - self.recoverable0);
        self.max_input = self.max_input.max(self.input.abs());
        // Not `max`, which drops a NaN: a non-finite balance sticks (`max_balance_error`).
        let e = self.balance_error().abs();
        #[allow(clippy::eq_op)]
        let nan = e != e;
        if e > self.max_error || nan {
            self.max_error = e;
        }
    }

    /// `E₀ + E_in − (E_k + E_s + E_v + E_h)` now (J). Cost: 5 flops.
    pub fn balance_error(&self) -> T {
        self.initial + self.input
            - (self.kinetic + self.recoverable + self.viscous + self.hysteretic)
    }

    /// The largest `|balance_error|` over the steps accounted so far (J).
    ///
    /// Errors: [`Error::NonFiniteState`] if the balance of a step accounted was NaN or
    /// infinite (an energy overflowed, or a NaN reached the account): the largest error
    /// is then unknown, not the largest of the finite ones. Cost: O(1).
    pub fn max_balance_error(&self) -> Result<T, Error> {
        if self.max_error.is_finite() {
            Ok(self.max_error)
        } else {
            Err(Error::NonFiniteState)
        }
    }

    /// The largest `|E_in|` over the steps accounted so far (J): the scale to judge the
    /// balance error against. Cost: O(1).
    pub fn max_input(&self) -> T {
        self.max_input
    }
}

impl<T: Real> EnergyAccount<T, 0> {
    /// The totals of a run-time-sized account (`std`) at its start: `E_k` and `E_s` there,
    /// every integral zero.
    #[cfg(feature = "std")]
    pub(crate) fn totals(kinetic: T, recoverable: T) -> Self {
        Self::begin(kinetic, recoverable, [SVector::zeros(); 4])
    }
}

/// `½ vᵀ M v` with the lumped masses.
fn kinetic<T: Real, L: Law<T>, const N: usize>(
    building: &ShearBuilding<T, L, N>,
    v: &SVector<T, N>,
) -> T {
    let m = building.masses();
    (0..N).fold(T::zero(), |e, i| e + m[i] * v[i] * v[i]) * T::from_f64_rounded(0.5)
}
