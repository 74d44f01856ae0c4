//! Many analyses at once: `L` nonlinear time-history analyses of one yielding
//! [`ShearBuilding`] advanced together, one analysis per SIMD lane, bit for bit the `L`
//! single analyses of [`Nonlinear::try_step_with_history`].
//!
//! Incremental dynamic analysis, stripes and fragility studies run the same structure under
//! many records or intensities. One analysis cannot go much faster than its Newton solve's
//! dependency chain (`docs/performance.md`); `L` independent analyses can share every
//! instruction. [`LaneStepper`] keeps each quantity of the `L` analyses side by side,
//! structure-of-arrays (`[T; L]` per degree of freedom: [`LaneState`], [`LaneHistory`]),
//! and writes every operation of the single analysis as a plain loop over the lanes, which
//! the compiler turns into packed instructions (`f64 × 2` on SSE2, `× 4` with AVX, and
//! `× 8` with AVX-512 when a lane array fills its 512-bit register, chosen at run time by
//! the crate's one dispatch point; `f32` twice as wide); elsewhere the same loops run as
//! they are.
//!
//! **The same bits as one analysis.** Every lane performs exactly the operations of the
//! single step, in the same order: the predictor and corrector ([`Nonlinear`]'s
//! kinematics), the storey laws ([`LaneLaw::trial_lanes`]: a branch of the law becomes a
//! per-lane select between both branches, each computed as the law computes it), `C v`
//! and `M q` on three diagonals, the residual and the convergence tests, the Newton matrix
//! and its `L D Lᵀ` solve (a lane whose matrix is not positive definite takes the same
//! pivoted LU as the single step). Packed `add`/`mul`/`div`/`max`/compare round each lane
//! as the scalar instruction does and Rust never fuses a multiply and an add, so the
//! results are identical at any `L` and on any CPU feature level (`tests/lanes.rs`; the
//! unit test runs every level the CPU has).
//!
//! **Formed once.** In a step where every storey of every lane is on its elastic branch,
//! the Newton matrix `M + b C + c K₀` is the same numbers every time: for a law that states
//! its elastic tangent ([`LaneLaw::elastic_tangent`]: [`Bilinear`](crate::hysteresis::Bilinear)),
//! [`LaneStepper::run`] forms its `L D Lᵀ` factors once, by the operations a step would use,
//! and the step takes them instead (the same bits); otherwise the step assembles the tangent
//! and factors it, as the single step does.
//!
//! **Masks.** Newton iterates until every lane is done; a lane that has converged (or
//! spent its budget) is committed and frozen while the others iterate. A lane that fails
//! (not converged, non-finite force or state, singular Newton matrix, non-finite load) is
//! left bit-identical, as the single step leaves its state, and reports its error; the
//! other lanes go on. A lane outside the `active` mask (a finished, shorter record; an
//! analysis that failed) is not touched. [`LaneStepper::run`] drives records of different
//! lengths from rest and reports each lane's failure with its step.
//!
//! A building whose damping matrix is not symmetric tridiagonal (dense `C`) is stepped
//! lane by lane with the single step (the same results, without the packed arithmetic).
//!
//! Cost per step, `k` the largest Newton iteration count of the active lanes: that of
//! one single step of `k` iterations ([`Nonlinear`]: `(k + 1)` trials and `26N k` flops),
//! each operation on `L` lanes at once; in [`LaneStepper::run`], an all-elastic iteration's
//! solve is the substitution only (about `5N` flops instead of about `30N` and `N`
//! divisions).
//! Stack: about twelve `N × L` arrays of `T` and the lanes' trial histories. No
//! allocation, no panic.
//!
//! ```
//! use aemstep::hysteresis::{Bilinear, ShearBuilding};
//! use aemstep::lanes::LaneStepper;
//! use aemstep::{models, NewtonSettings};
//!
//! let law = Bilinear::<f64>::new(1e8, 2e5, 0.05)?;
//! let (m, k) = models::shear_building([1e5; 3], [1e8; 3]);
//! let (a0, a1) = models::rayleigh_coefficients(13.0, 36.0, 0.02);
//! let building = ShearBuilding::new([1e5; 3], [law; 3], &models::rayleigh(&m, &k, a0, a1))?;
//!
//! // Four intensities of one sine pulse, records of 400, 400, 300 and 200 steps.
//! let stepper = LaneStepper::<f64, 3, 4>::new(0.005, NewtonSettings::default())?;
//! let scale = [2.0, 4.0, 6.0, 8.0];
//! let mut peak = [0.0f64; 4];
//! let outcome = stepper.run(
//!     &building,
//!     [400, 400, 300, 200],
//!     |lane, n| scale[lane] * (8.0 * 0.005 * n as f64).sin(),
//!     |state, stepped| {
//!         for (lane, p) in peak.iter_mut().enumerate() {
//!             if stepped[lane] {
//!                 *p = p.max(state.u()[2][lane].abs()); // roof displacement
//!             }
//!         }
//!     },
//! );
//! assert!(outcome.iter().all(|o| o.is_ok()));
//! assert!(peak[1] > peak[0]);
//! # Ok::<(), aemstep::Error>(())
//! ```

use nalgebra::SVector;

use crate::hysteresis::{BoucWen, Friction, HistoryModel, Law, LawTrial, Parallel, ShearBuilding};
use crate::kinematics::{AemKinematics, Kinematics, check_time_step_as};
use crate::linalg::lu::solve_in_place;
use crate::{
    Error, Iterations, NewtonReport, NewtonSettings, Nonlinear, Real, State, SymTridiagonal,
};

/// The committed histories of `L` analyses of an `N`-storey building: `[storey][lane]`.
pub type LaneHistory<H, const N: usize, const L: usize> = [[H; L]; N];

/// What one step of [`LaneStepper::step`] did in each lane: `None` for a lane outside the
/// `active` mask (untouched), else the lane's result as
/// [`Nonlinear::try_step_with_history`] returns it.
pub type LaneReports<T, const L: usize> = [Option<Result<NewtonReport<T>, Error>>; L];

/// One storey law's trials in `L` lanes: what [`Law::trial`] returns, each field a lane
/// array.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LaneTrial<T, H, const L: usize> {
    /// The forces `f` (force units).
    pub force: [T; L],
    /// The consistent tangent stiffnesses `∂f/∂d` (force per deformation).
    pub stiffness: [T; L],
    /// The tangent dampings `∂f/∂ḋ` (force per deformation rate).
    pub damping: [T; L],
    /// The trial histories.
    pub history: [H; L],
    /// Each lane on an inelastic branch.
    pub inelastic: [bool; L],
}

/// A storey [`Law`] evaluated in `L` lanes at once, bit for bit as `L` calls of
/// [`Law::trial`]. The default calls [`Law::trial`] lane by lane (exact by construction,
/// not packed); [`Bilinear`](crate::hysteresis::Bilinear) computes both of its branches in
/// every lane and selects, so its trials run as packed instructions.
pub trait LaneLaw<T: Real>: Law<T> {
    /// The tangent `(stiffness, damping)` that every trial on the elastic branch
    /// (`inelastic == false`) returns, whatever the deformation and history, when the law
    /// has one: then [`LaneStepper::run`] forms the Newton matrix of an all-elastic
    /// building once instead of every step (the same numbers, so the same bits). `None`
    /// (the default): the law's elastic tangent varies, and the matrix is formed every
    /// solve. Cost: O(1).
    fn elastic_tangent(&self) -> Option<(T, T)> {
        None
    }

    /// The trials at deformations `d` and rates `rate` from the `committed` histories, one
    /// lane each. Cost: `L` law trials.
    #[inline(always)]
    fn trial_lanes<const L: usize>(
        &self,
        committed: &[Self::History; L],
        d: &[T; L],
        rate: &[T; L],
    ) -> LaneTrial<T, Self::History, L> {
        let t: [LawTrial<T, Self::History>; L] =
            core::array::from_fn(|l| self.trial(&committed[l], d[l], rate[l]));
        LaneTrial {
            force: core::array::from_fn(|l| t[l].force),
            stiffness: core::array::from_fn(|l| t[l].stiffness),
            damping: core::array::from_fn(|l| t[l].damping),
            history: core::array::from_fn(|l| t[l].history),
            inelastic: core::array::from_fn(|l| t[l].inelastic),
        }
    }
}

impl<T: Real> LaneLaw<T> for BoucWen<T> {}
impl<T: Real> LaneLaw<T> for Friction<T> {}
impl<T: Real, A: Law<T>, B: Law<T>> LaneLaw<T> for Parallel<A, B> {}

/// The states of `L` analyses with `N` degrees of freedom, structure-of-arrays: `u`, `v`,
/// `a` as `[dof][lane]`, and each lane's step count.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LaneState<T, const N: usize, const L: usize> {
    u: [[T; L]; N],
    v: [[T; L]; N],
    a: [[T; L]; N],
    n: [u64; L],
}

impl<T: Real, const N: usize, const L: usize> LaneState<T, N, L> {
    /// The `L` states side by side (lane `l` is `states[l]`). Cost: `3 N L` copies.
    pub fn from_states(states: &[State<T, N>; L]) -> Self {
        Self {
            u: core::array::from_fn(|i| core::array::from_fn(|l| states[l].u[i])),
            v: core::array::from_fn(|i| core::array::from_fn(|l| states[l].v[i])),
            a: core::array::from_fn(|i| core::array::from_fn(|l| states[l].a[i])),
            n: core::array::from_fn(|l| states[l].n),
        }
    }

    /// The state of lane `lane` (`< L`), `None` past the last lane. Cost: `3N` copies.
    pub fn lane(&self, lane: usize) -> Option<State<T, N>> {
        if lane >= L {
            return None;
        }
        let col = |x: &[[T; L]; N]| SVector::<T, N>::from_fn(|i, _| x[i][lane]);
        Some(State::unchecked(
            col(&self.u),
            col(&self.v),
            col(&self.a),
            self.n[lane],
        ))
    }

    /// Replace lane `lane`'s state (`lane < L`; a lane past the last is ignored). Cost:
    /// `3N` copies.
    pub fn set_lane(&mut self, lane: usize, state: &State<T, N>) {
        if lane >= L {
            return;
        }
        for i in 0..N {
            self.u[i][lane] = state.u[i];
            self.v[i][lane] = state.v[i];
            self.a[i][lane] = state.a[i];
        }
        self.n[lane] = state.n;
    }

    /// Displacements `u[dof][lane]` (displacement units). Cost: none.
    pub fn u(&self) -> &[[T; L]; N] {
        &self.u
    }

    /// Velocities `v[dof][lane]`. Cost: none.
    pub fn v(&self) -> &[[T; L]; N] {
        &self.v
    }

    /// Accelerations `a[dof][lane]`. Cost: none.
    pub fn a(&self) -> &[[T; L]; N] {
        &self.a
    }

    /// Each lane's step count `n` (its time is `n h`). Cost: none.
    pub fn steps(&self) -> &[u64; L] {
        &self.n
    }
}

/// A lane's analysis that failed in [`LaneStepper::run`]: the step and the error (its
/// state and history are those after the last successful step).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Failure {
    /// The step that failed (`0`: the start).
    pub step: u64,
    /// Its error, as the single analysis reports it.
    pub error: Error,
}

/// The lane-batched nonlinear stepper of a [`ShearBuilding`]: `L` analyses with `N`
/// storeys, in `f32` or `f64`, each lane bit for bit the [`Nonlinear`] stepper built from
/// the same `h` and settings (see the [module](self)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LaneStepper<T, const N: usize, const L: usize> {
    single: Nonlinear<T, N>,
    kin: AemKinematics<T>,
}

/// Sizes and time step only, as [`Nonlinear`] prints.
#[cfg(feature = "defmt")]
impl<T: Real + defmt::Format, const N: usize, const L: usize> defmt::Format
    for LaneStepper<T, N, L>
{
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(
            f,
            "LaneStepper {{ N: {=usize}, L: {=usize}, h: {} }}",
            N,
            L,
            self.single.time_step()
        )
    }
}

/// The per-lane quantities of one Newton step, `[dof][lane]` unless noted.
struct Work<T, H, const N: usize, const L: usize> {
    vh: [[T; L]; N],
    uh: [[T; L]; N],
    q: [[T; L]; N],
    u: [[T; L]; N],
    v: [[T; L]; N],
    force: [[T; L]; N],
    history: [[H; L]; N],
    /// Each storey's tangent stiffness and damping (`[storey][lane]`), assembled into
    /// the Newton matrix's bands only when a solve needs them ([`Tangent::of`]).
    stiffness: [[T; L]; N],
    damping: [[T; L]; N],
    /// The branch signatures (bit `i mod 64`: storey `i` inelastic), formed for reports.
    branch: [u64; L],
    /// Some storey inelastic, in each lane.
    inelastic: [bool; L],
    /// The factors of an all-elastic trial's Newton matrix, when formed beforehand.
    elastic: Option<ElasticSolve<T, N, L>>,
}

impl<T: Real, H: Copy, const N: usize, const L: usize> Work<T, H, N, L> {
    /// Scratch for a step from the committed `history` (every field is written before it
    /// is read; zeros and the committed histories only make it initialised).
    fn new(history: &[[H; L]; N], elastic: Option<ElasticSolve<T, N, L>>) -> Self {
        let zero = [[T::zero(); L]; N];
        Self {
            vh: zero,
            uh: zero,
            q: zero,
            u: zero,
            v: zero,
            force: zero,
            history: *history,
            stiffness: zero,
            damping: zero,
            branch: [0; L],
            inelastic: [false; L],
            elastic,
        }
    }
}

/// The tangent's stiffness and damping bands (diagonal, off-diagonal; `[dof][lane]`).
struct Tangent<T, const N: usize, const L: usize> {
    k_diag: [[T; L]; N],
    k_off: [[T; L]; N],
    c_diag: [[T; L]; N],
    c_off: [[T; L]; N],
}

impl<T: Real, const N: usize, const L: usize> Tangent<T, N, L> {
    /// The bands from the storeys' tangents, summed in the order of [`ShearBuilding`]'s
    /// trial (storey by storey: its own DOF, then the one below), on the damping band.
    #[inline(always)]
    fn of(band: &SymTridiagonal<T, N>, stiffness: &[[T; L]; N], damping: &[[T; L]; N]) -> Self {
        let mut t = Self {
            k_diag: [[T::zero(); L]; N],
            k_off: [[T::zero(); L]; N],
            c_diag: lanes_of(&band.diagonal),
            c_off: lanes_of(&band.off),
        };
        for i in 0..N {
            for l in 0..L {
                t.k_diag[i][l] += stiffness[i][l];
                t.c_diag[i][l] += damping[i][l];
            }
            if i > 0 {
                for l in 0..L {
                    t.k_diag[i - 1][l] += stiffness[i][l];
                    t.k_off[i][l] -= stiffness[i][l];
                    t.c_diag[i - 1][l] += damping[i][l];
                    t.c_off[i][l] -= damping[i][l];
                }
            }
        }
        t
    }

    /// Every band entry, in every lane, finite (one whole-batch test).
    #[inline(always)]
    fn finite(&self) -> bool {
        all_finite(&self.k_diag, 0)
            && all_finite(&self.c_diag, 0)
            && all_finite(&self.k_off, 1)
            && all_finite(&self.c_off, 1)
    }

    /// `J = M + b ∂F/∂v + c ∂F/∂u` (diagonal, off-diagonal) and its scale
    /// `max(|M| + b |∂F/∂v| + c |∂F/∂u|)`, term by term as the single step (`M` diagonal).
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    fn newton_matrix(
        &self,
        m_diag: &[[T; L]; N],
        b: T,
        c: T,
    ) -> ([[T; L]; N], [[T; L]; N], [T; L]) {
        let mut scale = [T::zero(); L];
        let mut j_diag = [[T::zero(); L]; N];
        let mut j_off = [[T::zero(); L]; N];
        for i in 0..N {
            for l in 0..L {
                let (m, d, k) = (m_diag[i][l], self.c_diag[i][l], self.k_diag[i][l]);
                j_diag[i][l] = m + b * d + c * k;
                scale[l] = scale[l].max(m.abs() + b * d.abs() + c * k.abs());
            }
            if i > 0 {
                for l in 0..L {
                    let (m, d, k) = (T::zero(), self.c_off[i][l], self.k_off[i][l]);
                    j_off[i][l] = m + b * d + c * k;
                    scale[l] = scale[l].max(m.abs() + b * d.abs() + c * k.abs());
                }
            }
        }
        (j_diag, j_off, scale)
    }
}

/// The Newton matrix's `L D Lᵀ` factors when every storey is on its elastic branch (whose
/// tangent [`LaneLaw::elastic_tangent`] states): the same values in every lane and every
/// step, so [`LaneStepper::run`] forms them once. Bit for bit what [`solve`] forms from an
/// all-elastic trial (the same operations on the same numbers); `None` when that solve
/// would not take `L D Lᵀ` (a tangent entry not finite, a pivot too small).
struct ElasticSolve<T, const N: usize, const L: usize> {
    factors: Factors<T, N, L>,
    j_off: [[T; L]; N],
}

impl<T: Real, const N: usize, const L: usize> LaneStepper<T, N, L> {
    /// A stepper with time step `h` (s) and Newton settings, as [`Nonlinear::new`].
    ///
    /// Errors: as [`Nonlinear::new`]. Cost: O(1).
    pub fn new(h: f64, settings: NewtonSettings<T>) -> Result<Self, Error> {
        let single = Nonlinear::new(h, settings)?;
        // The kinematics exactly as `Nonlinear::new` rounds them.
        let kin = AemKinematics::new(check_time_step_as(h, T::MAX)?)?.round();
        Ok(Self { single, kin })
    }

    /// The single-analysis stepper every lane reproduces. Cost: none.
    pub fn single(&self) -> &Nonlinear<T, N> {
        &self.single
    }

    /// Lane `l`'s load `p = −M ι a_g` for ground accelerations `ag[l]` (m/s²), as
    /// [`ShearBuilding::ground_load`] forms it. Cost: `N L` multiplications.
    pub fn ground_loads<Lw: Law<T>>(
        building: &ShearBuilding<T, Lw, N>,
        ag: &[T; L],
    ) -> [[T; L]; N] {
        let m = building.masses();
        core::array::from_fn(|i| core::array::from_fn(|l| m[i] * (-ag[l])))
    }

    /// Advance every lane in `active` by one step under its load `p[dof][lane]`, as
    /// [`Nonlinear::try_step_with_history`] advances one analysis: each lane's state and
    /// history are committed only when its step converged to a finite state, and left
    /// bit-identical otherwise. Lanes outside `active` are not touched.
    ///
    /// Returns each lane's report or error ([`LaneReports`]; errors as
    /// [`Nonlinear::try_step_with_history`]). Cost: see the [module](self).
    pub fn step<Lw: LaneLaw<T>>(
        &self,
        building: &ShearBuilding<T, Lw, N>,
        state: &mut LaneState<T, N, L>,
        history: &mut LaneHistory<Lw::History, N, L>,
        p: &[[T; L]; N],
        active: [bool; L],
    ) -> LaneReports<T, L> {
        let mut w = Work::new(history, None);
        // `inline(always)`: the closure's body must be inlined into the AVX-compiled
        // caller of the dispatch, else it is one out-of-line SSE2 function called from
        // it and the lanes never run 4 wide (measured: the whole step was SSE2 code).
        crate::linalg::wide_lanes(
            L * core::mem::size_of::<T>(),
            #[inline(always)]
            || self.step_with::<Lw, true>(building, state, history, p, active, &mut w),
        )
    }

    /// The step of [`LaneStepper::step`] on the scratch `w` (with the all-elastic factors
    /// when [`LaneStepper::run`] formed them, [`ElasticSolve`]), inside the caller's
    /// dispatch. `REPORT`: the reports' correction and branch changes are formed (`step`);
    /// without (`run`, which reads only the errors), the correction is formed only where
    /// it decides convergence.
    #[inline(always)]
    fn step_with<Lw: LaneLaw<T>, const REPORT: bool>(
        &self,
        building: &ShearBuilding<T, Lw, N>,
        state: &mut LaneState<T, N, L>,
        history: &mut LaneHistory<Lw::History, N, L>,
        p: &[[T; L]; N],
        active: [bool; L],
        w: &mut Work<T, Lw::History, N, L>,
    ) -> LaneReports<T, L> {
        if let Some(band) = building.band() {
            return self.banded::<Lw, REPORT>(building, band, state, history, p, active, w);
        }
        // A dense-damping building: each active lane by the single step.
        core::array::from_fn(|l| {
            if !active[l] {
                return None;
            }
            let mut s = state.lane(l)?;
            let mut h: [Lw::History; N] = core::array::from_fn(|i| history[i][l]);
            let pl = SVector::<T, N>::from_fn(|i, _| p[i][l]);
            let out = self
                .single
                .try_step_with_history(building, &mut s, &mut h, &pl);
            if out.is_ok() {
                state.set_lane(l, &s);
                for (i, hi) in h.iter().enumerate() {
                    history[i][l] = *hi;
                }
            }
            Some(out)
        })
    }

    /// The factors of the Newton matrix of an all-elastic trial (see [`ElasticSolve`]):
    /// `None` for a dense-damping building, a law without [`LaneLaw::elastic_tangent`],
    /// or a matrix the `L D Lᵀ` solve declines. Cost: one solve's factorisation.
    fn elastic_solve<Lw: LaneLaw<T>>(
        &self,
        building: &ShearBuilding<T, Lw, N>,
    ) -> Option<ElasticSolve<T, N, L>> {
        let band = building.band()?;
        let mut stiffness = [[T::zero(); L]; N];
        let mut damping = [[T::zero(); L]; N];
        for (i, law) in building.laws().iter().enumerate() {
            let (k, d) = law.elastic_tangent()?;
            (stiffness[i], damping[i]) = ([k; L], [d; L]);
        }
        let t = Tangent::of(band, &stiffness, &damping);
        let m_diag: [[T; L]; N] = lanes_of(building.masses());
        let (j_diag, j_off, scale) = t.newton_matrix(&m_diag, self.kin.half_h, self.kin.quarter_h2);
        let (factors, positive) = factor(&j_diag, &j_off, &scale);
        (t.finite() && all(&positive)).then_some(ElasticSolve { factors, j_off })
    }

    /// The trial of every lane at `(w.u, w.v)` from the committed `history`: `C v` on
    /// the band, the storeys' forces, histories, branches and tangent bands, in the order
    /// of [`ShearBuilding`]'s trial.
    #[inline(always)]
    fn trial<Lw: LaneLaw<T>, const REPORT: bool>(
        building: &ShearBuilding<T, Lw, N>,
        band: &SymTridiagonal<T, N>,
        history: &LaneHistory<Lw::History, N, L>,
        w: &mut Work<T, Lw::History, N, L>,
    ) {
        band_mul(band, &w.v, &mut w.force);
        if REPORT {
            w.branch = [0; L];
        }
        // A local (kept in a register): or-ing into `w` stalled on store forwarding.
        let mut inelastic = [false; L];
        let laws = building.laws();
        for i in 0..N {
            // δ_i = u_i − u_{i−1} (δ_0 = u_0), as the building's trial.
            let (mut d, mut r) = (w.u[i], w.v[i]);
            if i > 0 {
                for l in 0..L {
                    d[l] = w.u[i][l] - w.u[i - 1][l];
                    r[l] = w.v[i][l] - w.v[i - 1][l];
                }
            }
            let s = laws[i].trial_lanes(&history[i], &d, &r);
            for l in 0..L {
                w.force[i][l] += s.force[l];
                inelastic[l] |= s.inelastic[l];
            }
            if REPORT {
                for l in 0..L {
                    w.branch[l] |= u64::from(s.inelastic[l]) << (i % 64);
                }
            }
            if i > 0 {
                for l in 0..L {
                    w.force[i - 1][l] -= s.force[l];
                }
            }
            w.stiffness[i] = s.stiffness;
            w.damping[i] = s.damping;
            w.history[i] = s.history;
        }
        w.inelastic = inelastic;
    }

    /// The banded Newton step of every active lane (see [`LaneStepper::step`]).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)] // the step's operands, each a different borrow
    fn banded<Lw: LaneLaw<T>, const REPORT: bool>(
        &self,
        building: &ShearBuilding<T, Lw, N>,
        band: &SymTridiagonal<T, N>,
        state: &mut LaneState<T, N, L>,
        history: &mut LaneHistory<Lw::History, N, L>,
        p: &[[T; L]; N],
        active: [bool; L],
        w: &mut Work<T, Lw::History, N, L>,
    ) -> LaneReports<T, L> {
        let mut out: LaneReports<T, L> = [None; L];
        let settings = self.single.settings();
        let (b, c) = (self.kin.half_h, self.kin.quarter_h2);
        let (budget, fixed) = match settings.iterations {
            Iterations::UpTo(k) => (k, false),
            Iterations::Exactly(k) => (k, true),
        };
        let tol = settings.tolerance;
        let masses = building.masses();
        let m_coefficients: [T; N] = core::array::from_fn(|i| masses[i]);
        let m_diag: [[T; L]; N] = lanes_of(masses);
        // A lane still iterating.
        let mut running = active;
        let p_size = norm_inf(p);
        if !all_finite(p, 0) {
            let p_finite = finite(p, 0);
            for (l, run) in running.iter_mut().enumerate() {
                if *run && !p_finite[l] {
                    out[l] = Some(Err(Error::NonFiniteInput));
                    *run = false;
                }
            }
        }
        w.q = state.a;
        for i in 0..N {
            for l in 0..L {
                (w.vh[i][l], w.uh[i][l]) =
                    self.kin
                        .predict(state.u[i][l], state.v[i][l], state.a[i][l]);
            }
        }
        let mut iterations = 0u32;
        let mut last_delta = [T::zero(); L];
        let mut branch_changes = [0u32; L];
        let mut last_branch = [0u64; L];
        let mut mq = [[T::zero(); L]; N];
        let mut r = [[T::zero(); L]; N];
        while any(&running) {
            for i in 0..N {
                for l in 0..L {
                    (w.v[i][l], w.u[i][l]) = self.kin.correct(w.vh[i][l], w.uh[i][l], w.q[i][l]);
                }
            }
            Self::trial::<Lw, REPORT>(building, band, history, w);
            band_mul_coefficients(&m_coefficients, &[T::zero(); N], &w.q, &mut mq);
            // Whole-batch tests first: a lane's own test only when one fails (rare).
            if !all_finite(&w.force, 0) {
                let f_finite = finite(&w.force, 0);
                for l in 0..L {
                    if running[l] && !f_finite[l] {
                        out[l] = Some(Err(Error::NonFiniteForce));
                        running[l] = false;
                    }
                }
            }
            if REPORT {
                if iterations > 0 {
                    for l in 0..L {
                        branch_changes[l] += u32::from(w.branch[l] != last_branch[l]);
                    }
                }
                last_branch = w.branch;
            }
            for i in 0..N {
                for l in 0..L {
                    r[i][l] = mq[i][l] + w.force[i][l] - p[i][l];
                }
            }
            let residual = relative_residual(&r, &mq, &w.force, &p_size);
            // Without reports (`run`), the correction only decides a lane whose residual
            // did not: when every running lane's did, it is not formed.
            let decided = !REPORT
                && all::<L>(&core::array::from_fn(|l| {
                    !running[l] | (residual[l] <= tol)
                }));
            let correction: [T; L] = if iterations == 0 || decided {
                [T::zero(); L]
            } else {
                let (nq, nu, nv) = (norm_inf(&w.q), norm_inf(&w.u), norm_inf(&w.v));
                // Every branch computed in every lane, then selected (no per-lane jumps).
                core::array::from_fn(|l| {
                    let reference = nq[l].max(nu[l] / c).max(nv[l] / b);
                    let ratio = last_delta[l] / reference;
                    let moved = if reference > T::zero() {
                        ratio
                    } else {
                        T::one()
                    };
                    if last_delta[l] <= T::zero() {
                        T::zero()
                    } else {
                        moved
                    }
                })
            };
            // The lanes that finish here: their outcome as the single step's, and those
            // that converged to a finite state committed together (masked copies).
            let over = iterations >= budget;
            let converged: [bool; L] = core::array::from_fn(|l| {
                residual[l] <= tol || (iterations > 0 && correction[l] <= tol)
            });
            let finishing: [bool; L] =
                core::array::from_fn(|l| running[l] & (over | (!fixed & converged[l])));
            if any(&finishing) {
                let state_finite: [bool; L] = if all_finite_of([&w.u, &w.v, &w.q], 0) {
                    [true; L]
                } else {
                    let (fu, fv, fq) = (finite(&w.u, 0), finite(&w.v, 0), finite(&w.q, 0));
                    core::array::from_fn(|l| fu[l] && fv[l] && fq[l])
                };
                let mut commit = [false; L];
                for l in 0..L {
                    if !finishing[l] {
                        continue;
                    }
                    let converged = converged[l];
                    running[l] = false;
                    out[l] = Some(if !state_finite[l] {
                        Err(Error::NonFiniteState)
                    } else if !converged {
                        Err(Error::NotConverged)
                    } else {
                        commit[l] = true;
                        Ok(NewtonReport {
                            iterations,
                            residual: residual[l],
                            correction: correction[l],
                            converged,
                            branch_changes: branch_changes[l],
                        })
                    });
                }
                if any(&commit) {
                    Self::commit(state, history, w, &commit);
                }
            }
            if !any(&running) {
                break;
            }
            let mut delta = r;
            let cached = w
                .elastic
                .as_ref()
                .filter(|_| all::<L>(&core::array::from_fn(|l| !running[l] | !w.inelastic[l])));
            if let Some(e) = cached {
                substitute(&e.factors, &e.j_off, &mut delta);
            } else if let Some(failed) = solve(
                &Tangent::of(band, &w.stiffness, &w.damping),
                &m_diag,
                b,
                c,
                &running,
                &mut delta,
            ) {
                for (l, failed) in failed.iter().enumerate() {
                    if let (true, Some(e)) = (running[l], failed) {
                        out[l] = Some(Err(*e));
                        running[l] = false;
                    }
                }
            }
            for i in 0..N {
                for l in 0..L {
                    w.q[i][l] -= delta[i][l];
                }
            }
            last_delta = norm_inf(&delta);
            iterations += 1;
        }
        out
    }

    /// Commit the last iterate (state `(w.u, w.v, w.q)`, trial history) of every lane in
    /// `commit` (each converged to a finite state), as masked copies over all lanes.
    #[inline(always)]
    fn commit<H: Copy>(
        state: &mut LaneState<T, N, L>,
        history: &mut LaneHistory<H, N, L>,
        w: &Work<T, H, N, L>,
        commit: &[bool; L],
    ) {
        if all(commit) {
            // Every lane: plain copies (the usual case, every lane converging together).
            state.u = w.u;
            state.v = w.v;
            state.a = w.q;
            *history = w.history;
            for n in state.n.iter_mut() {
                *n = n.wrapping_add(1);
            }
            return;
        }
        for i in 0..N {
            for l in 0..L {
                let c = commit[l];
                state.u[i][l] = if c { w.u[i][l] } else { state.u[i][l] };
                state.v[i][l] = if c { w.v[i][l] } else { state.v[i][l] };
                state.a[i][l] = if c { w.q[i][l] } else { state.a[i][l] };
                history[i][l] = if c { w.history[i][l] } else { history[i][l] };
            }
        }
        for l in 0..L {
            state.n[l] = state.n[l].wrapping_add(u64::from(commit[l]));
        }
    }

    /// `L` analyses of the building from rest under ground accelerations
    /// `ground(lane, n)` (m/s², at `t = n h`, asked for `n = 0 ..= steps[lane]`), lane
    /// `l` for `steps[l]` steps: each started as [`Nonlinear::start_with_history`] from
    /// the virgin history, then stepped by [`LaneStepper::step`] until its record ends or
    /// a step fails. `observe(state, stepped)` is called after every step with the lanes
    /// that stepped in it (their states after the step).
    ///
    /// Returns each lane's outcome: `Ok` with the analysis completed, or its
    /// [`Failure`] (the others went on). Cost: `max(steps)` lane steps.
    pub fn run<Lw, G, O>(
        &self,
        building: &ShearBuilding<T, Lw, N>,
        steps: [u64; L],
        mut ground: G,
        observe: O,
    ) -> [Result<(), Failure>; L]
    where
        Lw: LaneLaw<T>,
        G: FnMut(usize, u64) -> T,
        O: FnMut(&LaneState<T, N, L>, &[bool; L]),
    {
        let mut outcome: [Result<(), Failure>; L] = [Ok(()); L];
        let zero = SVector::<T, N>::zeros();
        let virgin = building.initial_history();
        let mut history: LaneHistory<Lw::History, N, L> = core::array::from_fn(|i| [virgin[i]; L]);
        let mut state = LaneState {
            u: [[T::zero(); L]; N],
            v: [[T::zero(); L]; N],
            a: [[T::zero(); L]; N],
            n: [0; L],
        };
        for l in 0..L {
            let p0 = building.ground_load(ground(l, 0));
            match self
                .single
                .start_with_history(building, &zero, &zero, &p0, &virgin)
            {
                Ok((s, h)) => {
                    state.set_lane(l, &s);
                    for (i, hi) in h.iter().enumerate() {
                        history[i][l] = *hi;
                    }
                }
                Err(error) => outcome[l] = Err(Failure { step: 0, error }),
            }
        }
        let mut w = Work::new(&history, self.elastic_solve(building));
        let last = steps.iter().copied().max().unwrap_or(0);
        // The whole loop, with `ground` and `observe`, under the AVX dispatch (one call).
        crate::linalg::wide_lanes(
            L * core::mem::size_of::<T>(),
            #[inline(always)]
            || {
                self.steps(
                    building,
                    &mut state,
                    &mut history,
                    &mut w,
                    last,
                    steps,
                    &mut outcome,
                    ground,
                    observe,
                )
            },
        );
        outcome
    }

    /// [`LaneStepper::run`]'s steps `1 ..= last`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn steps<Lw, G, O>(
        &self,
        building: &ShearBuilding<T, Lw, N>,
        state: &mut LaneState<T, N, L>,
        history: &mut LaneHistory<Lw::History, N, L>,
        w: &mut Work<T, Lw::History, N, L>,
        last: u64,
        steps: [u64; L],
        outcome: &mut [Result<(), Failure>; L],
        mut ground: G,
        mut observe: O,
    ) where
        Lw: LaneLaw<T>,
        G: FnMut(usize, u64) -> T,
        O: FnMut(&LaneState<T, N, L>, &[bool; L]),
    {
        for n in 1..=last {
            let active: [bool; L] = core::array::from_fn(|l| outcome[l].is_ok() && n <= steps[l]);
            if !any(&active) {
                break;
            }
            let ag: [T; L] =
                core::array::from_fn(|l| if active[l] { ground(l, n) } else { T::zero() });
            let p = Self::ground_loads(building, &ag);
            let reports = self.step_with::<Lw, false>(building, state, history, &p, active, w);
            for (l, report) in reports.iter().enumerate() {
                if let Some(Err(error)) = report {
                    outcome[l] = Err(Failure {
                        step: n,
                        error: *error,
                    });
                }
            }
            let stepped: [bool; L] = core::array::from_fn(|l| matches!(reports[l], Some(Ok(_))));
            observe(state, &stepped);
        }
    }
}

/// The Newton correction `r ← J⁻¹ r` of every lane, `J = M + b ∂F/∂v + c ∂F/∂u` on the
/// bands of the last trial, as the single step forms and solves it: `L D Lᵀ`, and pivoted
/// LU of the same `J` in a lane where that declines. Returns `None` when every lane solved
/// by `L D Lᵀ` with a finite tangent (the usual case: one whole-batch test), else each
/// lane's error ([`Error::NonFiniteForce`] for a tangent entry,
/// [`Error::SingularJacobian`]).
#[inline(always)]
fn solve<T: Real, const N: usize, const L: usize>(
    w: &Tangent<T, N, L>,
    m_diag: &[[T; L]; N],
    b: T,
    c: T,
    running: &[bool; L],
    r: &mut [[T; L]; N],
) -> Option<[Option<Error>; L]> {
    let tangent_finite = w.finite();
    let (j_diag, j_off, scale) = w.newton_matrix(m_diag, b, c);
    let (factors, positive) = factor(&j_diag, &j_off, &scale);
    if tangent_finite && all(&positive) {
        substitute(&factors, &j_off, r);
        return None;
    }
    // Some lane declines: each lane's outcome, as the single step's.
    let mut failed = [None; L];
    let [kd, cd, ko, co] = [
        finite(&w.k_diag, 0),
        finite(&w.c_diag, 0),
        finite(&w.k_off, 1),
        finite(&w.c_off, 1),
    ];
    for (l, f) in failed.iter_mut().enumerate() {
        if !(kd[l] && cd[l] && ko[l] && co[l]) {
            *f = Some(Error::NonFiniteForce);
        }
    }
    let rhs = *r;
    substitute(&factors, &j_off, r);
    for l in 0..L {
        if positive[l] || failed[l].is_some() || !running[l] {
            continue;
        }
        // Not positive definite in this lane: pivot, on the same J.
        let j = SymTridiagonal::<T, N> {
            diagonal: SVector::from_fn(|i, _| j_diag[i][l]),
            off: SVector::from_fn(|i, _| j_off[i][l]),
        };
        let mut x = SVector::<T, N>::from_fn(|i, _| rhs[i][l]);
        if solve_in_place(&mut j.to_matrix(), &mut x, scale[l]) {
            for i in 0..N {
                r[i][l] = x[i];
            }
        } else {
            failed[l] = Some(Error::SingularJacobian);
        }
    }
    Some(failed)
}

/// The `L D Lᵀ` factors of every lane's symmetric tridiagonal `A` (diagonal `d`,
/// off-diagonal `e`): the multipliers `l_i = e_i / d_{i−1}` (as `e_i · (1/d_{i−1})`) and
/// the pivots' reciprocals, exactly as the single step's solve forms them.
struct Factors<T, const N: usize, const L: usize> {
    multiplier: [[T; L]; N],
    inverse: [[T; L]; N],
}

/// [`Factors`] of every lane, and whether each lane's pivots are all finite and above
/// `N·ε·scale` (else its solve is unspecified).
#[inline(always)]
fn factor<T: Real, const N: usize, const L: usize>(
    d: &[[T; L]; N],
    e: &[[T; L]; N],
    scale: &[T; L],
) -> (Factors<T, N, L>, [bool; L]) {
    let n_eps = T::from_f64_rounded(N as f64) * T::default_epsilon();
    let tiny: [T; L] = core::array::from_fn(|l| n_eps * scale[l]);
    let mut accepted = [true; L];
    let mut f = Factors {
        multiplier: [[T::zero(); L]; N],
        inverse: [[T::zero(); L]; N],
    };
    let mut prev = [T::zero(); L];
    for i in 0..N {
        for l in 0..L {
            let li = e[i][l] * prev[l];
            let di = if i == 0 {
                d[0][l]
            } else {
                d[i][l] - li * e[i][l]
            };
            // `di − di == 0`: `di` finite (see `all_finite`).
            accepted[l] &= di > tiny[l] && finite_zero(di) == T::zero();
            prev[l] = T::one() / di;
            f.multiplier[i][l] = li;
            f.inverse[i][l] = prev[l];
        }
    }
    (f, accepted)
}

/// `x ← A⁻¹ x` in every lane from the [`Factors`] of `A` (off-diagonal `e`): forward and
/// back substitution in the single step's order.
#[inline(always)]
fn substitute<T: Real, const N: usize, const L: usize>(
    f: &Factors<T, N, L>,
    e: &[[T; L]; N],
    x: &mut [[T; L]; N],
) {
    for i in 1..N {
        for l in 0..L {
            x[i][l] -= f.multiplier[i][l] * x[i - 1][l];
        }
    }
    for i in (0..N).rev() {
        for l in 0..L {
            let upper = if i + 1 < N {
                e[i + 1][l] * x[i + 1][l]
            } else {
                T::zero()
            };
            x[i][l] = (x[i][l] - upper) * f.inverse[i][l];
        }
    }
}

/// `x − x`: `+0` exactly for a finite `x`, NaN for an infinite or NaN one (a packed
/// subtraction, where `is_finite` is an integer compare that AVX packs only 2 wide).
#[inline(always)]
#[allow(clippy::eq_op)] // `x − x` is the test, not a mistake
fn finite_zero<T: Real>(x: T) -> T {
    x - x
}

/// Every entry from DOF `from` on, in every lane, finite: one test of the whole batch
/// ([`all_finite_of`] of one array).
#[inline(always)]
fn all_finite<T: Real, const N: usize, const L: usize>(x: &[[T; L]; N], from: usize) -> bool {
    all_finite_of([x], from)
}

/// Every entry from DOF `from` on of every array in `xs`, in every lane, finite, with one
/// test: the lanes' sums of all the entries are finite only if every entry is (a NaN
/// makes a sum NaN, an infinity makes it infinite or NaN), so finite sums clear the batch
/// with packed additions and one packed `x − x == 0`. A sum that overflowed is a false
/// alarm; every caller then takes the exact per-lane test ([`finite`]), as for a
/// non-finite entry (rare either way).
#[inline(always)]
fn all_finite_of<T: Real, const N: usize, const L: usize, const K: usize>(
    xs: [&[[T; L]; N]; K],
    from: usize,
) -> bool {
    let mut sum = [T::zero(); L];
    for x in xs {
        for row in x.iter().skip(from) {
            for l in 0..L {
                sum[l] += row[l];
            }
        }
    }
    all_zero_finite(&sum)
}

/// Every lane's `x` finite: `x − x == 0` in every lane, and-ed without a short cut (a
/// short-circuiting `all` made the compiler sum the lanes one at a time, each with its
/// own jump).
#[inline(always)]
fn all_zero_finite<T: Real, const L: usize>(x: &[T; L]) -> bool {
    let mut ok = true;
    for &v in x {
        ok &= finite_zero(v) == T::zero();
    }
    ok
}

/// Some lane's flag set: or-ed over all lanes without a short cut (one packed test; a
/// short-circuiting `any` became a jump a lane).
#[inline(always)]
fn any<const L: usize>(x: &[bool; L]) -> bool {
    let mut a = false;
    for &v in x {
        a |= v;
    }
    a
}

/// Every lane's flag set, and-ed without a short cut (see [`any`]).
#[inline(always)]
fn all<const L: usize>(x: &[bool; L]) -> bool {
    let mut a = true;
    for &v in x {
        a &= v;
    }
    a
}

/// Each lane's entries from DOF `from` on are all finite.
#[inline(always)]
fn finite<T: Real, const N: usize, const L: usize>(x: &[[T; L]; N], from: usize) -> [bool; L] {
    let mut ok = [true; L];
    for row in x.iter().skip(from) {
        for l in 0..L {
            ok[l] &= row[l].is_finite();
        }
    }
    ok
}

/// A vector's entries, each repeated in every lane.
#[inline(always)]
fn lanes_of<T: Real, const N: usize, const L: usize>(x: &SVector<T, N>) -> [[T; L]; N] {
    core::array::from_fn(|i| [x[i]; L])
}

/// `y = A x` in every lane for the band `A`, as [`SymTridiagonal::mul`].
#[inline(always)]
fn band_mul<T: Real, const N: usize, const L: usize>(
    a: &SymTridiagonal<T, N>,
    x: &[[T; L]; N],
    y: &mut [[T; L]; N],
) {
    band_mul_coefficients(
        &core::array::from_fn(|i| a.diagonal[i]),
        &core::array::from_fn(|i| a.off[i]),
        x,
        y,
    );
}

/// `y = A x` in every lane, `A` symmetric tridiagonal with diagonal `d[i]` and
/// off-diagonal `e[i]` (the same in every lane), each row summed in column order as
/// [`SymTridiagonal::mul`].
#[inline(always)]
fn band_mul_coefficients<T: Real, const N: usize, const L: usize>(
    d: &[T; N],
    e: &[T; N],
    x: &[[T; L]; N],
    y: &mut [[T; L]; N],
) {
    for i in 0..N {
        for l in 0..L {
            let mut s = T::zero();
            if i > 0 {
                s = e[i] * x[i - 1][l];
            }
            s += d[i] * x[i][l];
            if i + 1 < N {
                s += e[i + 1] * x[i + 1][l];
            }
            y[i][l] = s;
        }
    }
}

/// `‖x‖∞` of every lane, folded from zero in DOF order with `max` as the single step.
#[inline(always)]
fn norm_inf<T: Real, const N: usize, const L: usize>(x: &[[T; L]; N]) -> [T; L] {
    let mut s = [T::zero(); L];
    for row in x {
        for l in 0..L {
            s[l] = s[l].max(row[l].abs());
        }
    }
    s
}

/// `‖r‖∞ / max(‖M q‖∞, ‖F‖∞, ‖p‖∞)` of every lane, `0` where the denominator is zero.
#[inline(always)]
fn relative_residual<T: Real, const N: usize, const L: usize>(
    r: &[[T; L]; N],
    mq: &[[T; L]; N],
    f: &[[T; L]; N],
    p_size: &[T; L],
) -> [T; L] {
    let (nr, nm, nf) = (norm_inf(r), norm_inf(mq), norm_inf(f));
    core::array::from_fn(|l| {
        let scale = nm[l].max(nf[l]).max(p_size[l]);
        if scale > T::zero() {
            nr[l] / scale
        } else {
            T::zero()
        }
    })
}

#[cfg(test)]
mod tests {
    extern crate std;
    use std::vec::Vec;

    use super::*;
    use crate::hysteresis::Bilinear;
    use crate::linalg::avx::tests::at_each_level;
    use crate::models;

    /// The yielding 5-storey building of the benchmark IDA (bilinear storeys yielding at
    /// 3 MN), in `T`.
    fn building<T: Real>() -> ShearBuilding<T, Bilinear<T>, 5> {
        let (m, c, _k) = models::five_storey_building();
        let law = Bilinear::<T>::new(models::FIVE_STOREY_STIFFNESS, 3.0e6, 0.05).unwrap();
        let masses = models::floor_masses(&m);
        ShearBuilding::new(masses, [law; 5], &c).unwrap()
    }

    /// A ground acceleration (m/s²) at step `n` of lane `l`: two sines under a decaying
    /// envelope, from elastic (lane 0) to far past yield; lane 5's record is NaN at step
    /// 150 (that lane fails there); lengths differ by lane.
    fn ground<T: Real>(l: usize, n: u64) -> T {
        if l == 5 && n == 150 {
            return T::from_f64_rounded(f64::NAN);
        }
        let t = n as f64 * 0.005;
        let a =
            (1.0 + 2.5 * l as f64) * (-t / 2.0).exp() * ((7.0 * t).sin() + 0.5 * (19.0 * t).cos());
        T::from_f64_rounded(a)
    }

    /// Every lane's state after every step and its outcome, by `run`.
    #[allow(clippy::type_complexity)]
    fn lanes<T: Real, const L: usize>() -> (Vec<Vec<[T; 15]>>, [Result<(), Failure>; L]) {
        let b = building::<T>();
        let stepper = LaneStepper::<T, 5, L>::new(
            0.005,
            NewtonSettings::up_to(50, T::default_epsilon() * T::from_f64_rounded(1e4)),
        )
        .unwrap();
        let steps: [u64; L] = core::array::from_fn(|l| 300 + 40 * (l as u64 % 5));
        let mut seen = std::vec![Vec::new(); L];
        let out = stepper.run(&b, steps, ground::<T>, |s, stepped| {
            for l in 0..L {
                if stepped[l] {
                    seen[l].push(core::array::from_fn(|k| [s.u, s.v, s.a][k / 5][k % 5][l]));
                }
            }
        });
        (seen, out)
    }

    /// The same analyses one at a time by the single stepper.
    #[allow(clippy::type_complexity)]
    fn singles<T: Real, const L: usize>() -> (Vec<Vec<[T; 15]>>, [Result<bool, Failure>; L]) {
        let b = building::<T>();
        let lanes = LaneStepper::<T, 5, 1>::new(
            0.005,
            NewtonSettings::up_to(50, T::default_epsilon() * T::from_f64_rounded(1e4)),
        )
        .unwrap();
        let mut seen = Vec::new();
        let out = core::array::from_fn(|l| {
            let single = lanes.single();
            let zero = SVector::<T, 5>::zeros();
            let mut states = Vec::new();
            let outcome = (|| {
                let (mut s, mut h) = single
                    .start_with_history(
                        &b,
                        &zero,
                        &zero,
                        &b.ground_load(ground(l, 0)),
                        &b.initial_history(),
                    )
                    .map_err(|error| Failure { step: 0, error })?;
                for n in 1..=300 + 40 * (l as u64 % 5) {
                    single
                        .try_step_with_history(&b, &mut s, &mut h, &b.ground_load(ground(l, n)))
                        .map_err(|error| Failure { step: n, error })?;
                    states.push(core::array::from_fn(|k| [s.u, s.v, s.a][k / 5][k % 5]));
                }
                // The analysis yielded: some storey's history left the virgin one.
                Ok(std::format!("{h:?}") != std::format!("{:?}", b.initial_history()))
            })();
            seen.push(states);
            outcome
        });
        (seen, out)
    }

    /// `L` lanes at every dispatch level this CPU has (plain SSE2, AVX, AVX-512) give the
    /// single analyses' states bit for bit, in `f64` at L = 4 and 8 and `f32` at 8 and 16
    /// (the widths below, at and above a 512-bit register), including a failing lane.
    #[test]
    fn every_dispatch_level_gives_the_single_analyses_bits() {
        fn check<T: Real, const L: usize>() {
            let want = singles::<T, L>();
            assert!(want.1[5 % L].is_err() == (L > 5));
            // Lane 0 stays elastic, lanes 1 on yield: batches all elastic in some steps
            // (the factors formed once), mixed in others.
            assert!(want.1[0] == Ok(false), "{:?}", want.1);
            assert!(want.1[1..].iter().all(|o| *o != Ok(false)), "{:?}", want.1);
            let levels = at_each_level(lanes::<T, L>);
            assert!(!levels.is_empty());
            for (level, got) in levels {
                assert_eq!(
                    got.1,
                    want.1.map(|o| o.map(|_| ())),
                    "level {level}, L = {L}"
                );
                for l in 0..L {
                    // `{:?}` of a float round-trips: equal text is equal bits.
                    let (g, w) = (
                        std::format!("{:?}", got.0[l]),
                        std::format!("{:?}", want.0[l]),
                    );
                    assert!(g == w, "level {level}, L = {L}, lane {l}");
                }
            }
        }
        check::<f64, 4>();
        check::<f64, 8>();
        check::<f32, 8>();
        check::<f32, 16>();
    }
}
