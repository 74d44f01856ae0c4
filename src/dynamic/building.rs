//! The yielding shear building with its number of storeys chosen at run time:
//! [`DynShearBuilding`] stepped by [`DynNonlinear`], the const-generic
//! [`ShearBuilding`](crate::hysteresis::ShearBuilding) and
//! [`Nonlinear::try_step_with_history`](crate::Nonlinear::try_step_with_history) on heap
//! slices, through the same per-step functions.

use std::vec;
use std::vec::Vec;

use nalgebra::{DMatrix, DVectorView, SVectorView};

use crate::hysteresis::{Bands, EnergyAccount, Law, check_building, storeys_flat};
use crate::kinematics::{AemKinematics, Kinematics};
use crate::linalg::lu::solve_in_place_flat;
use crate::linalg::tridiagonal::{mul_flat, solve_positive_flat};
use crate::nonlinear::{Progress, jacobian_flat, norm_inf_flat};
use crate::{Error, NewtonReport, NewtonSettings, Nonlinear, Real};

/// An `N`-storey shear building of storey law `L` with `N` chosen at run time (feature
/// `std`): [`ShearBuilding`](crate::hysteresis::ShearBuilding) on the heap, the same
/// equations, checks and arithmetic,
///
/// ```text
/// M u'' + C u' + F_s(u, u'; history) = p,    F_s,i = f_i − f_{i+1}   (f_{N+1} = 0)
/// f_i = L_i(δ_i, δ̇_i),   δ_i = u_i − u_{i−1}   (u_0 = 0, the ground)
/// ```
///
/// with floor masses `M = diag(m)` (kg), a constant damping matrix `C` (N·s/m) and DOF `i`
/// the displacement (m) of floor `i + 1` relative to the ground. Stepped by
/// [`DynNonlinear`]; bit-identical to `Nonlinear<T, N>` stepping `ShearBuilding<T, L, N>`
/// at every size both serve (`tests/runtime_size.rs`).
///
/// Size: `4N` values of `T` and `N` laws, `N²` more when `C` is not symmetric tridiagonal.
/// Cost of a trial: `N` law trials and about `24N` flops with a tridiagonal `C`; with a
/// full `C`, `N²` multiply-adds more (and `N³/3` a Newton iteration).
///
/// A 37-storey building (no const-generic build serves it) under a sine pulse:
///
/// ```
/// use aemstep::hysteresis::{Bilinear, BilinearHistory};
/// use aemstep::nalgebra::DMatrix;
/// use aemstep::{DynNonlinear, DynShearBuilding, NewtonSettings};
///
/// let n = 37;
/// // 1e5 kg floors, 1e8 N/m storeys yielding at 2e5 N, 5 % hardening; C = 0.2 M + 0.002 K.
/// let k = DMatrix::from_fn(n, n, |i, j| match (i.abs_diff(j), i + 1 < n) {
///     (0, true) => 2e8,
///     (0, false) => 1e8,
///     (1, _) => -1e8,
///     _ => 0.0,
/// });
/// let c = DMatrix::from_fn(n, n, |i, j| 0.002 * k[(i, j)] + if i == j { 0.2 * 1e5 } else { 0.0 });
/// let laws = vec![Bilinear::<f64>::new(1e8, 2e5, 0.05)?; n];
/// let building = DynShearBuilding::new(&vec![1e5; n], laws, &c)?;
/// let stepper = DynNonlinear::<f64>::new(0.005, NewtonSettings::default())?;
/// let (zero, mut p) = (vec![0.0; n], vec![0.0; n]);
/// let mut s = stepper.start(&building, &zero, &zero, &zero)?;
/// for step in 1..=400 {
///     let ag = 6.0 * (8.0 * 0.005 * step as f64).sin(); // m/s²
///     building.ground_load(ag, &mut p);
///     stepper.try_step(&building, &mut s, &p)?;
/// }
/// assert!(s.history().iter().any(|h: &BilinearHistory<f64>| h.plastic != 0.0)); // it yielded
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct DynShearBuilding<T, L> {
    masses: Vec<T>,
    /// `M`'s off-diagonal: zeros (the banded products read it as the const path does).
    zeros: Vec<T>,
    /// `C` on its three diagonals (`[diagonal, off]`) when symmetric tridiagonal.
    band: Option<[Vec<T>; 2]>,
    /// `C` and `M` column by column, when `C` is not tridiagonal (the dense path).
    dense: Option<[Vec<T>; 2]>,
    laws: Vec<L>,
}

impl<T: Real, L: Law<T>> DynShearBuilding<T, L> {
    /// A building with floor masses `masses` (kg, finite, `> 0`, ground storey first),
    /// storey laws `laws` (one a storey) and damping matrix `damping` (`N×N`, N·s/m,
    /// finite), rounded once to `T`: [`ShearBuilding::new`](crate::hysteresis::ShearBuilding::new)
    /// at a run-time size `N ≥ 1`.
    ///
    /// Errors: [`Error::StateSizeMismatch`] (`N = 0`, or `laws` or `damping` not of size
    /// `N`), then those of `ShearBuilding::new` in its order: [`Error::NonFiniteInput`],
    /// [`Error::MassNotSpd`], [`Error::OperatorOverflow`], [`Error::OperatorUnderflow`].
    /// Cost: O(N²); allocates the building.
    pub fn new(masses: &[f64], laws: Vec<L>, damping: &DMatrix<f64>) -> Result<Self, Error> {
        let n = masses.len();
        if n == 0 || laws.len() != n || damping.shape() != (n, n) {
            return Err(Error::StateSizeMismatch);
        }
        let rows = damping.transpose();
        let tridiagonal = check_building::<T>(masses, rows.as_slice())?;
        let round = |x: &[f64]| {
            x.iter()
                .map(|&x| T::from_f64_rounded(x))
                .collect::<Vec<T>>()
        };
        let c = |i: usize, j: usize| damping[(i, j)];
        let band = tridiagonal.then(|| {
            let off: Vec<f64> = (0..n)
                .map(|i| if i == 0 { 0.0 } else { c(i, i - 1) })
                .collect();
            let diagonal: Vec<f64> = (0..n).map(|i| c(i, i)).collect();
            [round(&diagonal), round(&off)]
        });
        let dense = (!tridiagonal).then(|| {
            let mass = DMatrix::from_fn(n, n, |i, j| if i == j { masses[i] } else { 0.0 });
            [round(damping.as_slice()), round(mass.as_slice())]
        });
        Ok(Self {
            masses: round(masses),
            zeros: vec![T::zero(); n],
            band,
            dense,
            laws,
        })
    }

    /// Storeys (degrees of freedom). Cost: none.
    pub fn size(&self) -> usize {
        self.masses.len()
    }

    /// The floor masses (kg), ground storey first. Cost: none.
    pub fn masses(&self) -> &[T] {
        &self.masses
    }

    /// The storey laws, ground storey first. Cost: none.
    pub fn laws(&self) -> &[L] {
        &self.laws
    }

    /// The load of a ground acceleration `ag` (m/s²), `p = −M ι a_g` (N), into `p` (`N`
    /// values; a shorter or longer `p` gets `min` of both). Cost: `N` flops, no allocation.
    pub fn ground_load(&self, ag: T, p: &mut [T]) {
        for (p, &m) in p.iter_mut().zip(&self.masses) {
            *p = m * (-ag);
        }
    }

    /// The history of the virgin building (nothing has yielded), one law history a
    /// storey. Cost: O(N); allocates.
    pub fn initial_history(&self) -> Vec<L::History> {
        self.laws.iter().map(|l| l.initial_history()).collect()
    }

    /// `force = C v + F_s` at `(u, v)` from the `committed` history, the trial history
    /// into `trial` and — on the banded path, with `tangent` — `∂F/∂u`, `∂F/∂v` on three
    /// diagonals: `ShearBuilding`'s trial. Returns the branch signature.
    fn trial(
        &self,
        committed: &[L::History],
        (u, v): (&[T], &[T]),
        force: &mut [T],
        trial: &mut [L::History],
        tangent: Option<Bands<'_, T>>,
    ) -> u64 {
        match (&self.band, &self.dense) {
            (Some([d, e]), _) => mul_flat(d, e, v, force),
            (None, Some([c, _])) => gemv(c, v, force),
            (None, None) => {}
        }
        trial.copy_from_slice(committed);
        storeys_flat(&self.laws, committed, (u, v), force, trial, tangent)
    }
}

/// `y = A x`, `A` column by column (`n×n`, `n = y.len()`): the column-ordered sums of
/// nalgebra's matrix–vector product, which the const-generic dense path uses (`A₀ x₀`
/// first, then `+ A_j x_j` column by column). Cost: `n²` multiply-adds.
fn gemv<T: Real>(a: &[T], x: &[T], y: &mut [T]) {
    for (j, (col, &xj)) in a.chunks_exact(y.len()).zip(x).enumerate() {
        for (y, &a) in y.iter_mut().zip(col) {
            *y = if j == 0 { a * xj } else { a * xj + *y };
        }
    }
}

/// The Newton stepper of [`Nonlinear`] (paper Algorithm 2) for a [`DynShearBuilding`]
/// (feature `std`): `h` (s) and the [`NewtonSettings`], the same predictor, Newton
/// iteration (the tridiagonal `L D Lᵀ` path with a symmetric tridiagonal `C`, pivoted LU
/// otherwise or when `J` is not positive definite), convergence test, checks and errors as
/// [`Nonlinear::try_step_with_history`], on slices.
///
/// A failed step leaves the [`DynBuildingState`] (state and history) bit-identical; a step
/// allocates nothing (the work space is allocated by [`DynNonlinear::start`]).
///
/// Cost per step of `k` Newton iterations: `(k + 1)` trials (`N` law trials and about
/// `24N` flops each) and `26N k` flops with a tridiagonal `C`; with a full `C`,
/// `k (N³/3 + 6N² + N law trials)` more. See [`DynShearBuilding`] for an example.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynNonlinear<T> {
    kin: AemKinematics<T>,
    settings: NewtonSettings<T>,
}

/// The state of a [`DynShearBuilding`] run: `u` (m), `v` (m/s), `a` (m/s²) at step `n`,
/// the storeys' committed history, and the Newton work space (allocated once, by
/// [`DynNonlinear::start`]: about `20N` values of `T`, `N` histories and `N²` values).
/// Two states are equal when their `u`, `v`, `a`, histories and step counts are.
#[derive(Clone, Debug)]
pub struct DynBuildingState<T, H> {
    u: Vec<T>,
    v: Vec<T>,
    a: Vec<T>,
    n: u64,
    history: Vec<H>,
    w: Work<T, H>,
}

impl<T: PartialEq, H: PartialEq> PartialEq for DynBuildingState<T, H> {
    fn eq(&self, o: &Self) -> bool {
        (&self.u, &self.v, &self.a, self.n, &self.history) == (&o.u, &o.v, &o.a, o.n, &o.history)
    }
}

/// The Newton work space of a step: the predictor, the iterate and its trial, the
/// tangent bands, `J` and the solve's scratch.
#[derive(Clone, Debug)]
struct Work<T, H> {
    /// `v̂`, `û`, the iterate `q`, `v_n`, `u_n`, `F`, `M q`, `r`/`δq`.
    vh: Vec<T>,
    uh: Vec<T>,
    q: Vec<T>,
    vn: Vec<T>,
    un: Vec<T>,
    f: Vec<T>,
    mq: Vec<T>,
    r: Vec<T>,
    /// `∂F/∂u`, `∂F/∂v` on three diagonals (`[diagonal, off]`).
    stiffness: [Vec<T>; 2],
    damping: [Vec<T>; 2],
    /// `J` on three diagonals, `1/d_i` of its `L D Lᵀ`, the right-hand side kept for the
    /// pivoted fallback, its row scales.
    j: [Vec<T>; 2],
    inv: Vec<T>,
    rhs: Vec<T>,
    scales: Vec<T>,
    /// `J` laid out densely (`N²`, column by column).
    dense: Vec<T>,
    /// The trial history of the iterate.
    trial: Vec<H>,
}

impl<T: Real, H: Copy> DynBuildingState<T, H> {
    super::state_accessors!();

    /// The storeys' committed history, ground storey first. Cost: none.
    pub fn history(&self) -> &[H] {
        &self.history
    }
}

impl<T: Real> DynNonlinear<T> {
    /// A stepper with time step `h` (s) and the given Newton settings:
    /// [`Nonlinear::new`], the same checks and rounding.
    ///
    /// Errors: [`Error::InvalidTimeStep`], [`Error::InvalidNewtonSettings`]. Cost: O(1).
    pub fn new(h: f64, settings: NewtonSettings<T>) -> Result<Self, Error> {
        let fixed = Nonlinear::<T, 1>::new(h, settings)?;
        Ok(Self {
            kin: fixed.kinematics(),
            settings,
        })
    }

    /// The time step `h` (s). Cost: none.
    pub fn time_step(&self) -> T {
        self.kin.h
    }

    /// The Newton settings. Cost: none.
    pub fn settings(&self) -> NewtonSettings<T> {
        self.settings
    }

    /// The state at `t = 0` of the virgin building (its
    /// [`DynShearBuilding::initial_history`]) from `u0` (m), `v0` (m/s) and the load `p0`
    /// (N), each of `N` values, with `a0 = M⁻¹ (p0 − F(u0, v0))`:
    /// [`Nonlinear::start_with_history`], the same checks and arithmetic. The committed
    /// history is the trial history at `(u0, v0)`.
    ///
    /// Errors: [`Error::StateSizeMismatch`], [`Error::NonFiniteInput`],
    /// [`Error::NonFiniteForce`], [`Error::SingularMass`], [`Error::NonFiniteState`].
    /// Cost: one trial and an `N×N` LU solve; allocates the state and its work space.
    pub fn start<L: Law<T>>(
        &self,
        building: &DynShearBuilding<T, L>,
        u0: &[T],
        v0: &[T],
        p0: &[T],
    ) -> Result<DynBuildingState<T, L::History>, Error> {
        let n = building.size();
        if [u0, v0, p0].iter().any(|x| x.len() != n) {
            return Err(Error::StateSizeMismatch);
        }
        if ![u0, v0, p0].iter().all(|x| x.iter().all(|x| x.is_finite())) {
            return Err(Error::NonFiniteInput);
        }
        let zeros = || vec![T::zero(); n];
        let history0 = building.initial_history();
        let mut w = Work {
            vh: zeros(),
            uh: zeros(),
            q: zeros(),
            vn: zeros(),
            un: zeros(),
            f: zeros(),
            mq: zeros(),
            r: zeros(),
            stiffness: [zeros(), zeros()],
            damping: [zeros(), zeros()],
            j: [zeros(), zeros()],
            inv: zeros(),
            rhs: zeros(),
            scales: zeros(),
            dense: vec![T::zero(); n * n],
            trial: history0.clone(),
        };
        building.trial(&history0, (u0, v0), &mut w.f, &mut w.trial, None);
        if !w.f.iter().all(|x| x.is_finite()) {
            return Err(Error::NonFiniteForce);
        }
        // a0 = M⁻¹ (p0 − F): `initial_from_equation`'s LU of the dense M, row scales |m_i|.
        let mut a0: Vec<T> = p0.iter().zip(&w.f).map(|(&p, &f)| p - f).collect();
        for (i, m) in building.masses.iter().enumerate() {
            w.dense[i * n + i] = *m;
            w.scales[i] = T::zero().max(m.abs());
        }
        if !solve_in_place_flat(&mut w.dense, &mut a0, &mut w.scales) {
            return Err(Error::SingularMass);
        }
        let finite = |x: &[T]| x.iter().all(|x| x.is_finite());
        if !(finite(u0) && finite(v0) && finite(&a0)) {
            return Err(Error::NonFiniteState);
        }
        Ok(DynBuildingState {
            u: u0.to_vec(),
            v: v0.to_vec(),
            a: a0,
            n: 0,
            history: w.trial.clone(),
            w,
        })
    }

    /// Advance `s` from `t_{n−1}` to `t_n` under the load `p = p(t_n)` (N, `N` values),
    /// committing state and history together only when Newton converged to a finite state:
    /// [`Nonlinear::try_step_with_history`]. Returns the Newton report (`converged` always
    /// `true` on `Ok`).
    ///
    /// Errors (each leaves `s` bit-identical): [`Error::StateSizeMismatch`] (`p` or `s`
    /// not of the building's size), [`Error::NonFiniteInput`], [`Error::NonFiniteForce`],
    /// [`Error::SingularJacobian`], [`Error::NotConverged`], [`Error::NonFiniteState`].
    /// Cost: see [`DynNonlinear`]; no allocation, no panic.
    pub fn try_step<L: Law<T>>(
        &self,
        building: &DynShearBuilding<T, L>,
        s: &mut DynBuildingState<T, L::History>,
        p: &[T],
    ) -> Result<NewtonReport<T>, Error> {
        let n = building.size();
        if p.len() != n || s.u.len() != n || s.w.dense.len() != n * n {
            return Err(Error::StateSizeMismatch);
        }
        let report = self.iterate(building, s, p)?;
        if !report.converged {
            return Err(Error::NotConverged);
        }
        let w = &s.w;
        s.u.copy_from_slice(&w.un);
        s.v.copy_from_slice(&w.vn);
        s.a.copy_from_slice(&w.q);
        s.history.copy_from_slice(&w.trial);
        s.n = s.n.wrapping_add(1);
        Ok(report)
    }

    /// `Nonlinear`'s Newton iteration (`iterate`) into the work space of `s`, whose state
    /// and history it only reads: the last iterate `(u_n, v_n, q)`, its trial history and
    /// the report.
    fn iterate<L: Law<T>>(
        &self,
        building: &DynShearBuilding<T, L>,
        s: &mut DynBuildingState<T, L::History>,
        p: &[T],
    ) -> Result<NewtonReport<T>, Error> {
        if !p.iter().all(|x| x.is_finite()) {
            return Err(Error::NonFiniteInput);
        }
        let (b, c) = (self.kin.half_h, self.kin.quarter_h2);
        let w = &mut s.w;
        for j in 0..s.u.len() {
            (w.vh[j], w.uh[j]) = self.kin.predict(s.u[j], s.v[j], s.a[j]);
        }
        let mut newton = Progress::new(self.settings, norm_inf_flat(p), (b, c));
        w.q.copy_from_slice(&s.a);
        loop {
            for j in 0..w.q.len() {
                (w.vn[j], w.un[j]) = self.kin.correct(w.vh[j], w.uh[j], w.q[j]);
            }
            let branch = evaluate(building, &s.history, w);
            if !w.f.iter().all(|x| x.is_finite()) {
                return Err(Error::NonFiniteForce);
            }
            for ((r, (&mq, &f)), &p) in w.r.iter_mut().zip(w.mq.iter().zip(&w.f)).zip(p) {
                *r = mq + f - p;
            }
            let forces = [&w.r[..], &w.mq, &w.f];
            if let Some(report) = newton.judge(branch, forces, [&w.q[..], &w.un, &w.vn]) {
                let finite = |x: &[T]| x.iter().all(|x| x.is_finite());
                if !(finite(&w.un) && finite(&w.vn) && finite(&w.q)) {
                    return Err(Error::NonFiniteState);
                }
                return Ok(report);
            }
            solve(building, &s.history, w, b, c)?;
            for (q, &d) in w.q.iter_mut().zip(&w.r) {
                *q -= d;
            }
            newton.corrected(norm_inf_flat(&w.r));
        }
    }
}

/// The trial at the iterate `(u_n, v_n)` of `w` into `w.f`, `w.trial`, the tangent bands
/// (banded path) and `w.mq = M q`: `Linearization::evaluate` of the const path.
fn evaluate<T: Real, L: Law<T>>(
    building: &DynShearBuilding<T, L>,
    committed: &[L::History],
    w: &mut Work<T, L::History>,
) -> u64 {
    let uv = (&w.un[..], &w.vn[..]);
    if let Some([cd, co]) = &building.band {
        // `trial_tridiagonal`: C's band, the storeys' tangents added to it.
        w.damping[0].copy_from_slice(cd);
        w.damping[1].copy_from_slice(co);
        w.stiffness[0].fill(T::zero());
        w.stiffness[1].fill(T::zero());
        let [kd, ko] = &mut w.stiffness;
        let [dd, doff] = &mut w.damping;
        let bands = Bands {
            stiffness: [kd, ko],
            damping: [dd, doff],
        };
        let branch = building.trial(committed, uv, &mut w.f, &mut w.trial, Some(bands));
        mul_flat(&building.masses, &building.zeros, &w.q, &mut w.mq);
        return branch;
    }
    let branch = building.trial(committed, uv, &mut w.f, &mut w.trial, None);
    if let Some([_, m]) = &building.dense {
        gemv(m, &w.q, &mut w.mq);
    }
    branch
}

/// `w.r ← J⁻¹ w.r` at the last evaluated iterate: `Linearization::solve` of the const
/// path (banded `L D Lᵀ`, pivoted LU of the same `J` when not positive definite; with a
/// full `C`, the dense tangent of `ShearBuilding::tangent` and pivoted LU).
///
/// Errors: [`Error::NonFiniteForce`] (a tangent entry), [`Error::SingularJacobian`].
fn solve<T: Real, L: Law<T>>(
    building: &DynShearBuilding<T, L>,
    committed: &[L::History],
    w: &mut Work<T, L::History>,
    b: T,
    c: T,
) -> Result<(), Error> {
    let n = w.r.len();
    let finite_band = |[d, e]: &[Vec<T>; 2]| {
        d.iter().all(|x| x.is_finite()) && e.iter().skip(1).all(|x| x.is_finite())
    };
    let scale = match (&building.band, &building.dense) {
        (Some(_), _) => {
            if !finite_band(&w.stiffness) || !finite_band(&w.damping) {
                return Err(Error::NonFiniteForce);
            }
            let [jd, jo] = &mut w.j;
            let scale = jacobian_flat(
                [&building.masses, &building.zeros],
                [&w.damping[0], &w.damping[1]],
                [&w.stiffness[0], &w.stiffness[1]],
                b,
                c,
                jd,
                jo,
            );
            w.rhs.copy_from_slice(&w.r);
            if solve_positive_flat(jd, jo, &mut w.r, &mut w.inv, scale) {
                return Ok(());
            }
            // Not positive definite (a softening storey): pivot, on the same J.
            w.r.copy_from_slice(&w.rhs);
            for col in 0..n {
                for row in 0..n {
                    w.dense[col * n + row] = match row.abs_diff(col) {
                        0 => jd[row],
                        1 => jo[row.max(col)],
                        _ => T::zero(),
                    };
                }
            }
            scale
        }
        (None, Some([cm, m])) => dense_jacobian(building, committed, w, [cm, m], b, c)?,
        (None, None) => return Err(Error::SingularJacobian),
    };
    w.scales.fill(scale);
    if !solve_in_place_flat(&mut w.dense, &mut w.r, &mut w.scales) {
        return Err(Error::SingularJacobian);
    }
    Ok(())
}

/// `J = M + b (C + ∂F_s/∂v) + c ∂F_s/∂u` densely into `w.dense` (column by column) from
/// the storeys' tangents at the iterate (`ShearBuilding::tangent`: `N` law trials), and
/// its entry scale, as the const path's `dense_solve`.
///
/// Errors: [`Error::NonFiniteForce`] (a tangent entry).
fn dense_jacobian<T: Real, L: Law<T>>(
    building: &DynShearBuilding<T, L>,
    committed: &[L::History],
    w: &mut Work<T, L::History>,
    [cm, m]: [&Vec<T>; 2],
    b: T,
    c: T,
) -> Result<T, Error> {
    let n = w.r.len();
    for band in w.stiffness.iter_mut().chain(w.damping.iter_mut()) {
        band.fill(T::zero());
    }
    let [kd, ko] = &mut w.stiffness;
    let [dd, doff] = &mut w.damping;
    let bands = Bands {
        stiffness: [kd, ko],
        damping: [dd, doff],
    };
    // The forces of this trial are not needed (`mq` as scratch): only its tangents.
    building.trial(
        committed,
        (&w.un, &w.vn),
        &mut w.mq,
        &mut w.trial,
        Some(bands),
    );
    let band = |[d, e]: &[Vec<T>; 2], row: usize, col: usize| match row.abs_diff(col) {
        0 => d[row],
        1 => e[row.max(col)],
        _ => T::zero(),
    };
    let mut scale = T::zero();
    for col in 0..n {
        for row in 0..n {
            let at = col * n + row;
            let k = band(&w.stiffness, row, col);
            let d = cm[at] + band(&w.damping, row, col);
            if !k.is_finite() || !d.is_finite() {
                return Err(Error::NonFiniteForce);
            }
            w.dense[at] = m[at] + d * b + k * c;
            scale = scale.max(m[at].abs() + b * d.abs() + c * k.abs());
        }
    }
    Ok(scale)
}

/// The energy balance of a [`DynShearBuilding`] run (feature `std`):
/// [`EnergyAccount`](crate::hysteresis::EnergyAccount) at a run-time size, the same
/// balance, quadrature and order of operations,
///
/// ```text
/// E₀ + E_in = E_k + E_s + E_v + E_h + error
/// E_in = ∫ p·du      E_k = ½ vᵀ M v      E_s = Σ recoverable strain energy of the storeys
/// E_v = ∫ (C v)·du   E_h = Σᵢ ∫ fᵢ dδᵢ − (E_s − E_s,₀)
/// ```
///
/// each integral by the trapezoidal rule per step. Units: J with SI inputs. It keeps the
/// history committed before the step itself, so [`DynEnergyAccount::step`] takes only the
/// state after it.
///
/// Size: `12N` values of `T` and `N` histories, allocated by
/// [`DynEnergyAccount::start`]. Cost per step: `N` law trials (the storey forces) and `N`
/// recoverable energies, `C v` (`5N` flops with a tridiagonal `C`, `N²` otherwise) and
/// `15N` flops; no allocation.
///
/// ```
/// use aemstep::hysteresis::Bilinear;
/// use aemstep::nalgebra::DMatrix;
/// use aemstep::{DynEnergyAccount, DynNonlinear, DynShearBuilding, NewtonSettings};
///
/// let n = 11;
/// let c = DMatrix::from_fn(n, n, |i, j| if i == j { 2e4 } else { 0.0 }); // N·s/m
/// let building = DynShearBuilding::new(&vec![1e5; n], vec![Bilinear::<f64>::new(1e8, 2e5, 0.05)?; n], &c)?;
/// let stepper = DynNonlinear::<f64>::new(0.005, NewtonSettings::default())?;
/// let (zero, mut p) = (vec![0.0; n], vec![0.0; n]);
/// let mut s = stepper.start(&building, &zero, &zero, &zero)?;
/// let mut account = DynEnergyAccount::start(&building, &s, &zero);
/// for step in 1..=400 {
///     building.ground_load(6.0 * (8.0 * 0.005 * step as f64).sin(), &mut p); // N
///     stepper.try_step(&building, &mut s, &p)?;
///     account.step(&building, &s, &p);
/// }
/// let e = account.totals();
/// assert!(e.hysteretic > 0.0); // it yielded
/// assert!(e.max_balance_error()? <= 1e-6 * e.max_input());
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct DynEnergyAccount<T, H> {
    /// The energies (their fields and methods; its own vectors are empty).
    totals: EnergyAccount<T, 0>,
    /// At the last accounted step: `u`, the load, `C v`, the storey forces `f_i`, the
    /// committed history.
    u: Vec<T>,
    load: Vec<T>,
    damping_force: Vec<T>,
    storey_force: Vec<T>,
    history: Vec<H>,
    /// Scratch: the new `C v` and `f_i`, `du`, its drifts, a sum of two vectors.
    new_damping: Vec<T>,
    new_storey: Vec<T>,
    du: Vec<T>,
    d_drift: Vec<T>,
    sum: Vec<T>,
}

impl<T: Real, H: Copy> DynEnergyAccount<T, H> {
    /// The account at the start of a run: the state [`DynNonlinear::start`] returned and
    /// the load `load` (N, `N` values) it started with. Cost: as a step; allocates.
    pub fn start<L: Law<T, History = H>>(
        building: &DynShearBuilding<T, L>,
        state: &DynBuildingState<T, H>,
        load: &[T],
    ) -> Self {
        let n = building.size();
        let zeros = || vec![T::zero(); n];
        let (u, v) = (state.u(), state.v());
        let kinetic = kinetic(building, v);
        let recoverable = recoverable(building, state.history(), u);
        let mut a = Self {
            totals: EnergyAccount::totals(kinetic, recoverable),
            u: u.to_vec(),
            load: load.to_vec(),
            damping_force: zeros(),
            storey_force: zeros(),
            history: state.history().to_vec(),
            new_damping: zeros(),
            new_storey: zeros(),
            du: zeros(),
            d_drift: zeros(),
            sum: zeros(),
        };
        damping_force(building, v, &mut a.damping_force);
        storey_forces(building, &a.history, u, v, &mut a.storey_force);
        a
    }

    /// Account for one accepted step: `state` after it, `load` its end load (N, `N`
    /// values). Call it only after a step succeeded. Cost: see [`DynEnergyAccount`]; no
    /// allocation.
    pub fn step<L: Law<T, History = H>>(
        &mut self,
        building: &DynShearBuilding<T, L>,
        state: &DynBuildingState<T, H>,
        load: &[T],
    ) {
        let half = T::from_f64_rounded(0.5);
        let (u, v) = (state.u(), state.v());
        for ((du, &u), &u0) in self.du.iter_mut().zip(u).zip(&self.u) {
            *du = u - u0;
        }
        damping_force(building, v, &mut self.new_damping);
        // The storey forces at the accepted (u, v) from the history before the step.
        storey_forces(building, &self.history, u, v, &mut self.new_storey);
        for i in 0..self.du.len() {
            self.d_drift[i] = if i == 0 {
                self.du[0]
            } else {
                self.du[i] - self.du[i - 1]
            };
        }
        let dot = |sum: &mut [T], a: &[T], b: &[T], x: &[T]| {
            for ((s, &a), &b) in sum.iter_mut().zip(a).zip(b) {
                *s = a + b;
            }
            // nalgebra sums fixed sizes 2, 3 and 4 in its own order (the const account's
            // `dot`): the same views here give the same bits at every size.
            fn fixed<T: Real, const K: usize>(a: &[T], b: &[T]) -> T {
                SVectorView::<T, K>::from_slice(a).dot(&SVectorView::<T, K>::from_slice(b))
            }
            match x.len() {
                2 => fixed::<T, 2>(sum, x),
                3 => fixed::<T, 3>(sum, x),
                4 => fixed::<T, 4>(sum, x),
                n => DVectorView::from_slice(sum, n).dot(&DVectorView::from_slice(x, n)),
            }
        };
        let works = [
            dot(&mut self.sum, &self.load, load, &self.du) * half,
            dot(
                &mut self.sum,
                &self.damping_force,
                &self.new_damping,
                &self.du,
            ) * half,
            dot(
                &mut self.sum,
                &self.storey_force,
                &self.new_storey,
                &self.d_drift,
            ) * half,
        ];
        self.u.copy_from_slice(u);
        self.load.copy_from_slice(load);
        core::mem::swap(&mut self.damping_force, &mut self.new_damping);
        core::mem::swap(&mut self.storey_force, &mut self.new_storey);
        self.history.copy_from_slice(state.history());
        self.totals.settle(
            works,
            kinetic(building, v),
            recoverable(building, state.history(), u),
        );
    }

    /// The energies now (J): `input`, `kinetic`, `recoverable`, `viscous`, `hysteretic`,
    /// `initial`, and [`balance_error`](EnergyAccount::balance_error),
    /// [`max_balance_error`](EnergyAccount::max_balance_error),
    /// [`max_input`](EnergyAccount::max_input), as an [`EnergyAccount`] of the totals
    /// (whose own per-floor vectors are empty). Cost: none.
    pub fn totals(&self) -> &EnergyAccount<T, 0> {
        &self.totals
    }
}

/// `½ vᵀ M v` with the lumped masses, summed in floor order as the const account.
fn kinetic<T: Real, L: Law<T>>(building: &DynShearBuilding<T, L>, v: &[T]) -> T {
    building
        .masses
        .iter()
        .zip(v)
        .fold(T::zero(), |e, (&m, &v)| e + m * v * v)
        * T::from_f64_rounded(0.5)
}

/// The storeys' recoverable energy at `u` and `history`, summed in storey order.
fn recoverable<T: Real, L: Law<T>>(
    building: &DynShearBuilding<T, L>,
    history: &[L::History],
    u: &[T],
) -> T {
    (0..u.len()).fold(T::zero(), |e, i| {
        let d = if i == 0 { u[0] } else { u[i] - u[i - 1] };
        e + building.laws[i].recoverable_energy(&history[i], d)
    })
}

/// `C v` into `out`: the band product with a tridiagonal `C` (the dense product's value:
/// its other terms are exact zeros), else nalgebra's column order.
fn damping_force<T: Real, L: Law<T>>(building: &DynShearBuilding<T, L>, v: &[T], out: &mut [T]) {
    match (&building.band, &building.dense) {
        (Some([d, e]), _) => mul_flat(d, e, v, out),
        (None, Some([c, _])) => gemv(c, v, out),
        (None, None) => {}
    }
}

/// The storey forces `f_i` (not assembled) at `(u, v)` from `history`.
fn storey_forces<T: Real, L: Law<T>>(
    building: &DynShearBuilding<T, L>,
    history: &[L::History],
    u: &[T],
    v: &[T],
    out: &mut [T],
) {
    for i in 0..out.len() {
        let (d, r) = if i == 0 {
            (u[0], v[0])
        } else {
            (u[i] - u[i - 1], v[i] - v[i - 1])
        };
        out[i] = building.laws[i].trial(&history[i], d, r).force;
    }
}
