//! Output feedback: the fixed-gain observer with the delivered force as its known input,
//! the regulator's gain, saturation, and the safe hold of the last output.
//!
//! Each sample `t_k` the caller passes the measurements `y_k` and the force the device
//! delivers from `t_k` on, `f_k` (measured: saturated, lagging — not the command, so a
//! saturating actuator does not wind the observer up). The controller
//!
//! ```text
//! x̂_k = Φ x̂_{k−1} + Γ₀ f_{k−1} + Γ₁ f_k + L (y_k − H x̂⁻ − D f_k)     (the Observer)
//! u_k = sat(−K_x x̂_k − K_u f_k)                                      (held from t_{k+1})
//! ```
//!
//! `K = [K_x K_u]` is the regulator of the delayed design model
//! ([`DesignModel::delayed`](super::DesignModel::delayed): `f_k` stands for `u_{k−1}`, the
//! force acting over the step), or `K_x` alone for a design without the delay.
//!
//! ```
//! use aemstep::control::{Controller, DesignModel, Lqr, Status, Weights};
//! use aemstep::models::{self, storey_drifts};
//! use aemstep::observer::{Observer, Outputs, StateSpace, SteadyState};
//! use aemstep::nalgebra::SMatrix;
//! use aemstep::vector;
//!
//! let (m, k) = models::shear_building([1.0e3; 2], [1.0e6; 2]);
//! let c = models::rayleigh(&m, &k, 0.1, 0.002);
//! let mat = |r| models::matrix_of::<f64, 2>(&r);
//! // The actuator's force on floor 1 (N), h = 5 ms.
//! let ss = StateSpace::<2, 4, 1>::zero_order_hold(
//!     &mat(m), &mat(c), &mat(k), &SMatrix::<f64, 2, 1>::new(1.0, 0.0), 0.005)?;
//! let drifts = ss.outputs(&Outputs::displacements(storey_drifts::<2>()))?;
//! let w = Weights::outputs(&drifts, &[[1.0e12, 0.0], [0.0, 1.0e12]], &[[1.0]]);
//! let lqr = Lqr::from_parts(&DesignModel::from_state_space(&ss).delayed::<5>()?, &w.delayed(&[[1e-3]])?)?;
//! // The roof's relative acceleration measured; the observer's gain from its Riccati equation.
//! let meas = ss.outputs(&Outputs::accelerations(Outputs::<2, 1, 1>::select([1])))?;
//! let kf = SteadyState::new(&ss, &meas, &(SMatrix::<f64, 4, 4>::identity() * 1e-12), &SMatrix::<f64, 1, 1>::new(1e-4))?;
//! let obs = Observer::<f32, 4, 1, 1>::new(&ss, &meas, &kf.gain_matrix())?;
//! let ctl = Controller::new(obs, &lqr.gain_matrix(), &[5.0e3])?;
//! let mut st = ctl.start_at_rest();
//! let cmd = ctl.try_step(&mut st, &vector![0.3], &vector![0.0], false)?;
//! assert_eq!(cmd.status, Status::Computed);
//! let held = ctl.try_step(&mut st, &vector![f32::NAN], &vector![0.0], false)?;
//! assert_eq!((held.status, held.force), (Status::MissingSample, cmd.force));
//! # Ok::<(), aemstep::Error>(())
//! ```

use nalgebra::{SMatrix, SVector};

use crate::linalg::{self, all_finite, finite_as, round_rows, rows_f64};
use crate::observer::{Estimate, Observer};
use crate::{Error, Param, Real, StepState};

/// Why the output is what it is ([`Command::status`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Status {
    /// The output was computed from this sample.
    Computed,
    /// A measurement was missing (a non-finite entry of `y`): the observer predicted
    /// without correcting, and the last safe output is held.
    MissingSample,
    /// The caller signalled that the loop overran its budget: the estimate advanced, the
    /// last safe output is held.
    Overrun,
}

/// What a step of the [`Controller`] returns: the output to hold from the next sample,
/// whether the computed command hit its limit, and why.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Command<T, const I: usize> {
    /// The output (input units, e.g. N), held by the caller's DAC from `t_{k+1}`: the new
    /// command if [`Status::Computed`], else the last safe output.
    pub force: [T; I],
    /// The computed command exceeded its limit in some input and was clipped to it.
    pub saturated: bool,
    /// Why the output is what it is.
    pub status: Status,
}

/// The state of a [`Controller`]: the observer's estimate, the last safe output, and the
/// count of overruns. Plain data.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ControlState<T, const S: usize, const I: usize> {
    estimate: Estimate<T, S, I>,
    output: [T; I],
    overruns: u64,
}

impl<T: Real, const S: usize, const I: usize> ControlState<T, S, I> {
    /// The observer's estimate (its [`Estimate::missing`] counts the missing samples).
    pub fn estimate(&self) -> &Estimate<T, S, I> {
        &self.estimate
    }
    /// The last safe output (input units).
    pub fn output(&self) -> &[T; I] {
        &self.output
    }
    /// Steps the caller signalled as overrun.
    pub fn overruns(&self) -> u64 {
        self.overruns
    }
}

/// An output-feedback (LQG) controller: a fixed-gain [`Observer`] (`S` states, `I`
/// control inputs as its known input, `O` measurements) and the regulator's gain
/// `K = [K_x K_u]` (`K_u` on the delivered force, zero without the delay), with a
/// symmetric force limit per input ([module docs](self)). `f32` or `f64`; every operator
/// rounded once from `f64`: [`Controller::new`] (run time) and the `const fn`
/// `from_parts_f32`/`_f64` are bit-identical, and a `static` controller sits in flash.
///
/// Cost of a step: the observer's (`S² + 2S·I + 2S·O + O·I` multiply-adds) plus
/// `S·I + I²` for the command, fixed whatever the status. Size: the observer's plus
/// `S·I + I² + I` values of `T`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Controller<T, const S: usize, const I: usize, const O: usize> {
    observer: Observer<T, S, I, O>,
    gain_x: [[T; S]; I],
    gain_u: [[T; I]; I],
    limit: [T; I],
}

/// Check a gain of `Z` columns (`S`, or `S + I` with the delay) and the limits, and split
/// the gain into `K_x` (`I×S`) and `K_u` (`I×I`, zero if `Z = S`).
#[allow(clippy::type_complexity)]
const fn split_gain<const S: usize, const I: usize, const Z: usize>(
    gain: &[[f64; Z]; I],
    limit: &[f64; I],
    max: f64,
) -> Result<([[f64; S]; I], [[f64; I]; I]), Error> {
    if Z != S && Z != S + I {
        return Err(Error::StateSizeMismatch);
    }
    if !all_finite(gain) {
        return Err(Error::NonFiniteInput);
    }
    let mut i = 0;
    while i < I {
        if !(limit[i].is_finite() && limit[i] > 0.0 && limit[i] <= max) {
            return Err(Error::InvalidParameter(Param::Saturation));
        }
        i += 1;
    }
    if !finite_as(gain, max) {
        return Err(Error::OperatorOverflow);
    }
    let mut kx = [[0.0; S]; I];
    let mut ku = [[0.0; I]; I];
    let mut i = 0;
    while i < I {
        let mut j = 0;
        while j < Z {
            if j < S {
                kx[i][j] = gain[i][j];
            } else {
                ku[i][j - S] = gain[i][j];
            }
            j += 1;
        }
        i += 1;
    }
    Ok((kx, ku))
}

impl<T: Real, const S: usize, const I: usize, const O: usize> Controller<T, S, I, O> {
    /// The controller of `observer` (whose known input is the delivered force) with the
    /// regulator gain `gain` (`I×Z`, e.g. [`Lqr::gain_matrix`](super::Lqr::gain_matrix):
    /// `Z = S + I` for a design on the delayed model, `Z = S` without the delay) and the
    /// force limits `limit` (`|u_i| ≤ limit_i`, input units, finite and `> 0`).
    ///
    /// Errors: [`Error::StateSizeMismatch`] (`Z` neither `S` nor `S + I`),
    /// [`Error::NonFiniteInput`] (a non-finite gain),
    /// [`Error::InvalidParameter`]`(`[`Param::Saturation`]`)` (a limit not finite, `≤ 0`, or
    /// beyond `T`'s range), [`Error::OperatorOverflow`] (a gain beyond `T`'s range).
    /// Cost: `O(S·I + I²)`.
    pub fn new<const Z: usize>(
        observer: Observer<T, S, I, O>,
        gain: &SMatrix<f64, I, Z>,
        limit: &[f64; I],
    ) -> Result<Self, Error> {
        let (kx, ku) = split_gain::<S, I, Z>(&rows_f64(gain), limit, T::MAX.as_f64())?;
        Ok(Self {
            observer,
            gain_x: round_rows(&kx),
            gain_u: round_rows(&ku),
            limit: core::array::from_fn(|i| T::from_f64_rounded(limit[i])),
        })
    }

    /// The observer.
    pub fn observer(&self) -> &Observer<T, S, I, O> {
        &self.observer
    }

    /// The start at rest: `x̂ = 0`, no force delivered, output zero.
    pub fn start_at_rest(&self) -> ControlState<T, S, I> {
        ControlState {
            estimate: Estimate {
                x: SVector::zeros(),
                w: SVector::zeros(),
                n: 0,
                missing: 0,
            },
            output: [T::zero(); I],
            overruns: 0,
        }
    }

    /// One sample: advance the estimate with the measurements `y` (a non-finite entry is a
    /// missing sample) and the force delivered from this sample on, `measured_force`
    /// (finite, input units), then compute the command `u = sat(−K_x x̂ − K_u f)`.
    /// `overrun` (the caller's clock: the loop overran its budget) and a missing sample
    /// hold the last safe output, reported in [`Command::status`] (a missing sample takes
    /// precedence); otherwise the new command becomes the safe output.
    ///
    /// Errors (each leaves `state` bit-identical): [`Error::NonFiniteInput`]
    /// (`measured_force` not finite), [`Error::NonFiniteState`] (the estimate or the
    /// command would not be finite), [`Error::StepCountOverflow`]. Cost: fixed, as
    /// [`Controller`] states; no allocation, no panic.
    // Always inlined: a loop calls it once a sample, and the call's own entry, exit and
    // spills cost a few percent of the step.
    #[inline(always)]
    #[must_use = "the output to hold from the next sample, or why the step was refused"]
    pub fn try_step(
        &self,
        state: &mut ControlState<T, S, I>,
        y: &SVector<T, O>,
        measured_force: &SVector<T, I>,
        overrun: bool,
    ) -> Result<Command<T, I>, Error> {
        // The observer's update on a copy, committed only if every check passes: the
        // checks of `Observer::try_step`, each made once and none by a second scan. The
        // observer adds 1 to its count of missing samples exactly when `y` has a
        // non-finite entry, so the count's last bit tells whether the sample is present;
        // the finiteness of the input and of the new estimate rides on the command's
        // (below).
        let est = state.estimate;
        let mut e = est;
        self.observer.step(&mut e, measured_force, y);
        let present = (e.missing ^ est.missing) & 1 == 0;
        // Room for one more step in the estimate's counters (`Observer::try_step`'s
        // check): the count of missing samples never passes the step count (both start at
        // 0, [`Controller::start_at_rest`], and only this step advances them), so room in
        // the step count is room in both.
        let counted = est.n != u64::MAX;
        let overruns = state.overruns.checked_add(u64::from(overrun));
        let mut u = [T::zero(); I];
        let mut saturated = false;
        let mut finite = true;
        for (i, ui) in u.iter_mut().enumerate() {
            let mut s = -T::zero();
            for j in 0..S {
                s -= self.gain_x[i][j] * e.x[j];
            }
            for j in 0..I {
                s -= self.gain_u[i][j] * measured_force[j];
            }
            // Within the limit: finite, kept. Beyond it: clipped if finite (NaN fails
            // `|s| ≤ lim` too, and is refused below).
            let lim = self.limit[i];
            let within = s.abs() <= lim;
            saturated |= !within;
            if !within {
                finite &= s.is_finite();
                s = if s > lim { lim } else { -lim };
            }
            *ui = s;
        }
        // Every `x̂_j` and every `f_j` enters row 0's sum through a finite gain (checked at
        // construction), and a non-finite term (`±∞`, or NaN, also `0·∞`) leaves every
        // IEEE sum it enters non-finite: a finite command proves a finite input and a
        // finite estimate (`e.w` is the input). Without an input (`I = 0`, no sum) the
        // estimate is scanned.
        let finite = if I == 0 { e.is_finite() } else { finite };
        let Some(overruns) = overruns.filter(|_| finite && counted) else {
            return Err(self.refusal(measured_force, counted, finite));
        };
        let status = if !present {
            Status::MissingSample
        } else if overrun {
            Status::Overrun
        } else {
            Status::Computed
        };
        if status == Status::Computed {
            state.output = u;
        }
        state.estimate = e;
        state.overruns = overruns;
        Ok(Command {
            force: state.output,
            saturated,
            status,
        })
    }

    /// Why [`Controller::try_step`] refuses a step, in the order of its checks: a
    /// non-finite input, then no room in the estimate's counters, then a non-finite
    /// estimate or command, then no room in the count of overruns. Off the step's path.
    #[cold]
    #[inline(never)]
    fn refusal(&self, measured_force: &SVector<T, I>, counted: bool, finite: bool) -> Error {
        if !measured_force.iter().all(|v| v.is_finite()) {
            Error::NonFiniteInput
        } else if !counted {
            Error::StepCountOverflow
        } else if !finite {
            Error::NonFiniteState
        } else {
            Error::StepCountOverflow
        }
    }
}

/// Const-fn construction: the gain and limits rounded by the compiler into flash.
macro_rules! const_ctor {
    ($t:ident, $from_parts:ident) => {
        impl<const S: usize, const I: usize, const O: usize> Controller<$t, S, I, O> {
            /// `const fn` twin of [`Controller::new`] with the gain as row-major `f64`
            /// (`I×Z`, e.g. [`Lqr::gain`](super::Lqr::gain)); bit-identical to it.
            ///
            /// ```
            /// use aemstep::control::Controller;
            /// use aemstep::models;
            /// use aemstep::observer::{Observer, Outputs, StateSpace};
            /// const B: (models::Rows<1>, models::Rows<1>) = models::shear_building([1.0e3], [4.0e4]);
            /// const SS: StateSpace<1, 2, 1> =
            ///     match StateSpace::from_rows_aem(B.0, [[40.0]], B.1, [[1.0]], 0.01) {
            ///         Ok(s) => s,
            ///         Err(e) => panic!("{}", e.as_str()),
            ///     };
            /// // The velocity measured, an open-loop observer, velocity feedback of 400 N·s/m.
            /// static CTL: Controller<f32, 2, 1, 1> = match SS.outputs(&Outputs::velocities([[1.0]])) {
            ///     Ok(meas) => match Observer::<f32, 2, 1, 1>::from_parts_f32(&SS, &meas, &[[0.0]; 2]) {
            ///         Ok(obs) => match Controller::from_parts_f32(obs, &[[0.0, 400.0]], &[1.0e3]) {
            ///             Ok(c) => c,
            ///             Err(e) => panic!("{}", e.as_str()),
            ///         },
            ///         Err(e) => panic!("{}", e.as_str()),
            ///     },
            ///     Err(e) => panic!("{}", e.as_str()),
            /// };
            /// let mut st = CTL.start_at_rest();
            /// let cmd = CTL.try_step(&mut st, &aemstep::vector![0.0], &aemstep::vector![0.0], false)?;
            /// assert_eq!(cmd.force, [0.0]);
            /// # Ok::<(), aemstep::Error>(())
            /// ```
            ///
            /// Errors: as [`Controller::new`].
            pub const fn $from_parts<const Z: usize>(
                observer: Observer<$t, S, I, O>,
                gain: &[[f64; Z]; I],
                limit: &[f64; I],
            ) -> Result<Self, Error> {
                let (kx, ku) = match split_gain::<S, I, Z>(gain, limit, $t::MAX as f64) {
                    Ok(k) => k,
                    Err(e) => return Err(e),
                };
                Ok(Self {
                    observer,
                    gain_x: linalg::const_round!($t, rows kx),
                    gain_u: linalg::const_round!($t, rows ku),
                    limit: linalg::const_round!($t, vec * limit),
                })
            }
        }
    };
}
const_ctor!(f32, from_parts_f32);
const_ctor!(f64, from_parts_f64);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::observer::{Outputs, StateSpace};

    /// The step as it was before the overhead was cut (observer's checked step on a copy,
    /// the command scanned, `y` scanned for the status): the specification the fused
    /// step must match bit for bit, errors and all. A regression oracle, not an
    /// independent derivation.
    fn reference<T: Real, const S: usize, const I: usize, const O: usize>(
        c: &Controller<T, S, I, O>,
        state: &mut ControlState<T, S, I>,
        y: &SVector<T, O>,
        measured_force: &SVector<T, I>,
        overrun: bool,
    ) -> Result<Command<T, I>, Error> {
        let mut e = state.estimate;
        c.observer.try_step(&mut e, measured_force, y)?;
        // Each row summed from −0 in the order `try_step` sums it, checked, then clipped.
        let sums: [T; I] = core::array::from_fn(|i| {
            let s = (0..S).fold(-T::zero(), |s, j| s - c.gain_x[i][j] * e.x[j]);
            (0..I).fold(s, |s, j| s - c.gain_u[i][j] * measured_force[j])
        });
        if !sums.iter().all(|s| s.is_finite()) {
            return Err(Error::NonFiniteState);
        }
        let saturated = sums.iter().zip(&c.limit).any(|(s, &lim)| s.abs() > lim);
        let u: [T; I] = core::array::from_fn(|i| {
            let (s, lim) = (sums[i], c.limit[i]);
            if s > lim {
                lim
            } else if s < -lim {
                -lim
            } else {
                s
            }
        });
        let status = match (y.iter().all(|v| v.is_finite()), overrun) {
            (false, _) => Status::MissingSample,
            (true, true) => Status::Overrun,
            (true, false) => Status::Computed,
        };
        let overruns = match state.overruns.checked_add(u64::from(overrun)) {
            Some(n) => n,
            None => return Err(Error::StepCountOverflow),
        };
        let output = if status == Status::Computed {
            u
        } else {
            state.output
        };
        state.estimate = e;
        state.output = output;
        state.overruns = overruns;
        Ok(Command {
            force: output,
            saturated,
            status,
        })
    }

    /// Every value of a state or a result as bits (`f64` widening is exact).
    fn bits<T: Real>(v: impl IntoIterator<Item = T>) -> impl Iterator<Item = u64> {
        v.into_iter().map(|x| x.as_f64().to_bits())
    }

    fn same_state<T: Real, const S: usize, const I: usize>(
        a: &ControlState<T, S, I>,
        b: &ControlState<T, S, I>,
    ) -> bool {
        bits(a.estimate.x.iter().copied()).eq(bits(b.estimate.x.iter().copied()))
            && bits(a.estimate.w.iter().copied()).eq(bits(b.estimate.w.iter().copied()))
            && bits(a.output).eq(bits(b.output))
            && (a.estimate.n, a.estimate.missing, a.overruns)
                == (b.estimate.n, b.estimate.missing, b.overruns)
    }

    fn same_result<T: Real, const I: usize>(
        a: &Result<Command<T, I>, Error>,
        b: &Result<Command<T, I>, Error>,
    ) -> bool {
        match (a, b) {
            (Ok(a), Ok(b)) => {
                bits(a.force).eq(bits(b.force))
                    && (a.saturated, a.status) == (b.saturated, b.status)
            }
            (Err(a), Err(b)) => a == b,
            _ => false,
        }
    }

    /// Values that exercise every branch: ordinary, beyond the limit, overflowing the
    /// estimate, not finite.
    fn pick<T: Real>(r: u64, scale: f64) -> T {
        let v = match r % 16 {
            0 => f64::NAN,
            1 => f64::INFINITY,
            2 => f64::NEG_INFINITY,
            3 => 1.0e30,
            4 => -T::MAX.as_f64(),
            5 => 0.0,
            6 => -0.0,
            k => scale * (k as f64 - 11.0),
        };
        T::from_f64_rounded(v)
    }

    /// Runs the fused step and the reference side by side from the same states over a
    /// pseudo-random sweep of inputs and starting counters, and counts the outcomes
    /// (each must occur, or the sweep proves nothing).
    fn sweep<T: Real, const S: usize, const I: usize, const O: usize>(
        c: &Controller<T, S, I, O>,
        rare: u32,
    ) -> [u32; 5] {
        let mut seen = [0u32; 5];
        let mut r: u64 = 0x2545_f491_4f6c_dd1d;
        let mut next = || {
            r ^= r << 13;
            r ^= r >> 7;
            r ^= r << 17;
            r
        };
        let mut run = c.start_at_rest();
        for k in 0..20_000u32 {
            // Bad values rarely, so the runs also go long between refusals.
            let mut draw = |scale| {
                let v = next();
                if v % u64::from(rare) == 0 {
                    pick::<T>(v >> 8, scale)
                } else {
                    pick::<T>(7 + (v >> 8) % 9, scale)
                }
            };
            let y = SVector::<T, O>::from_fn(|_, _| draw(0.3));
            let f = SVector::<T, I>::from_fn(|_, _| draw(2.0));
            let overrun = next() % 5 == 0;
            // Now and then the counters at their limits (the count of missing samples
            // never above the step count, as in any state `try_step` can reach).
            let mut st = run;
            match next() % 40 {
                0 => st.estimate.n = u64::MAX,
                1 => (st.estimate.n, st.estimate.missing) = (u64::MAX, u64::MAX),
                2 => (st.estimate.n, st.estimate.missing) = (u64::MAX - 1, u64::MAX - 1),
                3 => st.overruns = u64::MAX,
                _ => {}
            }
            let mut a = st;
            let mut b = st;
            let ra = c.try_step(&mut a, &y, &f, overrun);
            let rb = reference(c, &mut b, &y, &f, overrun);
            assert!(
                same_result(&ra, &rb) && same_state(&a, &b),
                "step {k}: {ra:?} / {rb:?}"
            );
            if ra.is_err() {
                assert!(
                    same_state(&a, &st),
                    "step {k}: a refused step changed the state"
                );
            }
            seen[match ra {
                Ok(Command {
                    saturated: true, ..
                }) => 0,
                Ok(Command {
                    status: Status::Computed,
                    ..
                }) => 1,
                Ok(_) => 2,
                Err(Error::NonFiniteState) => 3,
                Err(_) => 4,
            }] += 1;
            // Restart from rest when the run has left every finite value behind.
            run = if ra.is_ok() && a.estimate.x.iter().all(|x| x.as_f64().abs() < 1e3) {
                a
            } else {
                c.start_at_rest()
            };
        }
        seen
    }

    /// An SDOF (1 kg, 2 % damping at 1 Hz), its velocity measured, force in, `h` = 10 ms:
    /// `I` inputs through `b`.
    fn controller<T: Real, const I: usize, const Z: usize>(
        b: [f64; I],
        gain: [[f64; Z]; I],
        limit: [f64; I],
    ) -> Controller<T, 2, I, 1> {
        let w = 2.0 * core::f64::consts::PI;
        let ss = StateSpace::<1, 2, I>::from_rows_aem([[1.0]], [[0.04 * w]], [[w * w]], [b], 0.01)
            .unwrap();
        let meas = ss.outputs(&Outputs::velocities([[1.0]])).unwrap();
        let obs = Observer::new(&ss, &meas, &SMatrix::from([[0.5, 3.0]])).unwrap();
        Controller::new(obs, &SMatrix::<f64, Z, I>::from(gain).transpose(), &limit).unwrap()
    }

    /// The fused step against the step it replaced: the same commands, statuses, errors
    /// and states, bit for bit, for one input with and without the delay, two inputs, and
    /// none; `f32` and `f64`.
    #[test]
    fn fused_step_is_bit_identical_to_the_checked_composition() {
        fn all<T: Real>() {
            let one = sweep(&controller::<T, 1, 3>([1.0], [[40.0, 2.0, 0.3]], [50.0]), 6);
            let direct = sweep(&controller::<T, 1, 2>([1.0], [[40.0, 2.0]], [50.0]), 6);
            let two = sweep(
                &controller::<T, 2, 4>(
                    [1.0, -0.5],
                    [[40.0, 2.0, 0.3, 0.0], [-10.0, 0.0, 0.0, 0.2]],
                    [50.0, 10.0],
                ),
                6,
            );
            let none = sweep(&controller::<T, 0, 2>([], [], []), 6);
            for (name, seen) in [("one", one), ("direct", direct), ("two", two)] {
                assert!(seen.iter().all(|&n| n > 0), "{name}: {seen:?}");
            }
            // Without an input nothing saturates; the rest occurs.
            assert!(none[1..].iter().all(|&n| n > 0), "none: {none:?}");
        }
        all::<f32>();
        all::<f64>();
    }
}
