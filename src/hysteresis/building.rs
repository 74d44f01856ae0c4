//! A hysteretic shear building: storey springs from one [`Law`] plus linear damping.

use nalgebra::{SMatrix, SVector};

use super::{HistoryModel, Law, LawTrial, Trial};
use crate::linalg::Rows;
use crate::{Error, Real, SymTridiagonal, Tangent, TridiagonalTangent};

/// An `N`-storey shear building with lumped masses, a hysteretic storey spring of law `L`
/// in every storey (ground storey first) and a constant linear damping matrix `C` (e.g.
/// [`models::rayleigh`](crate::models::rayleigh) of the initial stiffness, or storey
/// dashpots):
///
/// ```text
/// M u'' + C u' + F_s(u, u'; history) = p,    F_s,i = f_i − f_{i+1}   (f_{N+1} = 0)
/// f_i = L_i(δ_i, δ̇_i),   δ_i = u_i − u_{i−1}   (u_0 = 0, the ground)
/// ```
///
/// DOF `i` is the displacement of floor `i + 1` relative to the ground; base excitation is
/// `p = −M ι a_g` ([`ShearBuilding::ground_load`]). The history is one law history per
/// storey; the branch signature sets bit `i mod 64` when storey `i` is inelastic.
///
/// Cost: a trial is `N` law trials and `C v`: `5N` flops when `C` is symmetric tridiagonal
/// (storey dashpots, Rayleigh damping of the storey stiffness), `N²` multiply-adds
/// otherwise. With a tridiagonal `C` the [`Nonlinear`](crate::Nonlinear) stepper takes
/// each trial with its tangent ([`HistoryModel::trial_tridiagonal`], `4N` flops more, no
/// law evaluated twice) and solves the Newton systems in `O(N)`: a step of `k` Newton
/// iterations costs `(k + 1)` trials (`N` law trials and about `24N` flops each) and
/// `26N k` flops. With a dense `C`, `k (N³/3 + 6N² + 2N law trials)`.
///
/// ```
/// use aemstep::hysteresis::{Bilinear, HistoryModel, ShearBuilding};
/// use aemstep::{models, NewtonSettings, Nonlinear};
/// use aemstep::nalgebra::SVector;
///
/// // 3 storeys, 1e5 kg and 1e8 N/m each, yielding at 2e5 N, 5 % hardening, 2 % Rayleigh.
/// let law = Bilinear::<f64>::new(1e8, 2e5, 0.05)?;
/// let (m, k) = models::shear_building([1e5; 3], [1e8; 3]);
/// let (a0, a1) = models::rayleigh_coefficients(13.0, 36.0, 0.02);
/// let building = ShearBuilding::new([1e5; 3], [law; 3], &models::rayleigh(&m, &k, a0, a1))?;
///
/// let stepper = Nonlinear::<f64, 3>::new(0.005, NewtonSettings::default())?;
/// let zero = SVector::zeros();
/// let (mut s, mut history) = stepper.start_with_history(
///     &building, &zero, &zero, &building.ground_load(0.0), &building.initial_history())?;
/// for n in 1..=400 {
///     let ag = 6.0 * (8.0 * 0.005 * n as f64).sin(); // m/s², a strong sine pulse
///     stepper.try_step_with_history(&building, &mut s, &mut history, &building.ground_load(ag))?;
/// }
/// assert!(history.iter().any(|h| h.plastic != 0.0)); // it yielded
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShearBuilding<T, L, const N: usize> {
    masses: SVector<T, N>,
    damping: SMatrix<T, N, N>,
    /// `damping` on its three diagonals, when it is symmetric tridiagonal (every other
    /// entry zero): then `C v` costs `5N` flops and the Newton systems are solved in `O(N)`
    /// ([`HistoryModel::trial_tridiagonal`]).
    band: Option<SymTridiagonal<T, N>>,
    laws: [L; N],
}

impl<T: Real, L: Law<T>, const N: usize> ShearBuilding<T, L, N> {
    /// A building with floor masses `masses` (kg, finite, `> 0`, ground storey first),
    /// storey laws `laws` and damping matrix `damping` (`N×N` row-major, N·s/m, finite),
    /// rounded once to `T`.
    ///
    /// Errors: [`Error::NonFiniteInput`] (a mass or damping entry not finite),
    /// [`Error::MassNotSpd`] (a mass `≤ 0`), [`Error::OperatorOverflow`] (a mass or
    /// damping entry does not fit `T`), [`Error::OperatorUnderflow`] (a mass below the
    /// smallest normal number of `T`: subnormal or rounded to zero, e.g. `6e-322` kg in
    /// `f32`, whose start then failed with a singular mass). Cost: O(N²).
    pub fn new(masses: [f64; N], laws: [L; N], damping: &Rows<N>) -> Result<Self, Error> {
        let tridiagonal = check_building::<T>(&masses, damping.as_flattened())?;
        let band = tridiagonal.then(|| SymTridiagonal {
            diagonal: SVector::from_fn(|i, _| T::from_f64_rounded(damping[i][i])),
            off: SVector::from_fn(|i, _| {
                if i == 0 {
                    T::zero()
                } else {
                    T::from_f64_rounded(damping[i][i - 1])
                }
            }),
        });
        Ok(Self {
            masses: SVector::from_fn(|i, _| T::from_f64_rounded(masses[i])),
            damping: SMatrix::from_fn(|i, j| T::from_f64_rounded(damping[i][j])),
            band,
            laws,
        })
    }

    /// `C` on its three diagonals when it is symmetric tridiagonal (the banded Newton
    /// path, [`HistoryModel::trial_tridiagonal`]), else `None`. Cost: O(1).
    pub(crate) fn band(&self) -> Option<&SymTridiagonal<T, N>> {
        self.band.as_ref()
    }

    /// The storey laws, ground storey first. Cost: O(1).
    pub fn laws(&self) -> &[L; N] {
        &self.laws
    }

    /// The damping matrix `C` (N·s/m). Cost: O(1).
    pub fn damping(&self) -> &SMatrix<T, N, N> {
        &self.damping
    }

    /// The load of a ground acceleration `ag` (m/s²): `p = −M ι a_g`. Cost: `N` flops.
    pub fn ground_load(&self, ag: T) -> SVector<T, N> {
        self.masses * (-ag)
    }

    /// Storey drifts `δ_i = u_i − u_{i−1}` (`u_{−1} = 0`) of a floor vector. Cost: `N`.
    /// [`models::drifts`](crate::models::drifts) is the same without naming the type.
    pub fn drifts(x: &SVector<T, N>) -> SVector<T, N> {
        crate::models::drifts(x)
    }

    /// The floor masses (kg), ground storey first: the diagonal of
    /// [`HistoryModel::mass`]. Cost: O(1).
    pub fn masses(&self) -> &SVector<T, N> {
        &self.masses
    }

    /// The `N` storey law trials at floor displacements `u`, velocities `v` from the
    /// committed history. Cost: `N` law trials.
    #[inline]
    pub fn storeys(
        &self,
        committed: &[L::History; N],
        u: &SVector<T, N>,
        v: &SVector<T, N>,
    ) -> [LawTrial<T, L::History>; N] {
        let (d, r) = (Self::drifts(u), Self::drifts(v));
        core::array::from_fn(|i| self.laws[i].trial(&committed[i], d[i], r[i]))
    }

    /// The trial at `(u, v)`: the `N` storey laws at the drifts and drift rates, the force
    /// `C v + F_s` (`C v` on the three diagonals when `C` is tridiagonal, `5N` flops, the
    /// same value as the dense product, whose other terms are exact zeros; else dense,
    /// `N²`), the trial history, and — when `tangent` is given (tridiagonal `C` only) —
    /// `M`, `∂F/∂u`, `∂F/∂v` on three diagonals. One pass over the storeys, nothing
    /// stored between the law calls and the assembly.
    #[inline(always)]
    fn fused(
        &self,
        committed: &[L::History; N],
        u: &SVector<T, N>,
        v: &SVector<T, N>,
        tangent: Option<&mut TridiagonalTangent<T, N>>,
    ) -> Trial<T, N, [L::History; N]> {
        let mut force = match &self.band {
            Some(band) => band.mul(v).data.0[0],
            None => (self.damping * v).data.0[0],
        };
        let mut history = *committed;
        let bands = tangent.map(Bands::of);
        let branch = storeys_flat(
            &self.laws,
            committed,
            (&u.data.0[0], &v.data.0[0]),
            &mut force,
            &mut history,
            bands,
        );
        Trial {
            force: SVector::from(force),
            history,
            branch,
        }
    }

    /// The strain energy recoverable by elastic unloading of every storey, at floor
    /// displacements `u` and their committed `history` (J). Cost: `N` law calls.
    pub fn recoverable_energy(&self, history: &[L::History; N], u: &SVector<T, N>) -> T {
        let d = Self::drifts(u);
        (0..N).fold(T::zero(), |e, i| {
            e + self.laws[i].recoverable_energy(&history[i], d[i])
        })
    }
}

impl<T: Real, L: Law<T>, const N: usize> HistoryModel<T, N> for ShearBuilding<T, L, N> {
    type History = [L::History; N];

    fn initial_history(&self) -> [L::History; N] {
        core::array::from_fn(|i| self.laws[i].initial_history())
    }

    fn mass(&self) -> SMatrix<T, N, N> {
        SMatrix::from_diagonal(&self.masses)
    }

    fn trial(
        &self,
        committed: &[L::History; N],
        u: &SVector<T, N>,
        v: &SVector<T, N>,
    ) -> Trial<T, N, [L::History; N]> {
        self.fused(committed, u, v, None)
    }

    fn tangent(
        &self,
        committed: &[L::History; N],
        u: &SVector<T, N>,
        v: &SVector<T, N>,
    ) -> Option<Tangent<T, N>> {
        // The storeys' tangents on three diagonals (as the tridiagonal trial assembles
        // them), then `C` added densely: `C` may be full.
        let storeys = self.storeys(committed, u, v);
        let mut t = TridiagonalTangent {
            mass: SymTridiagonal::zero(),
            stiffness: SymTridiagonal::zero(),
            damping: SymTridiagonal::zero(),
        };
        let mut bands = Bands::of(&mut t);
        for (i, s) in storeys.iter().enumerate() {
            add_storey(&mut bands, i, s.stiffness, s.damping);
        }
        Some(Tangent {
            stiffness: t.stiffness.to_matrix(),
            damping: self.damping + t.damping.to_matrix(),
        })
    }

    /// The trial with `M`, `∂F/∂u`, `∂F/∂v` on three diagonals, from the same `N` law
    /// trials (the tangent costs `4N` flops more, no law is evaluated twice); `None` when
    /// the damping matrix is not symmetric tridiagonal.
    #[inline]
    fn trial_tridiagonal(
        &self,
        committed: &[L::History; N],
        u: &SVector<T, N>,
        v: &SVector<T, N>,
        tangent: &mut TridiagonalTangent<T, N>,
    ) -> Option<Trial<T, N, [L::History; N]>> {
        let band = self.band.as_ref()?;
        // `M` and `C`'s band; `fused` adds the storeys' tangents to them.
        tangent.mass = SymTridiagonal {
            diagonal: self.masses,
            off: SVector::zeros(),
        };
        tangent.damping = *band;
        tangent.stiffness = SymTridiagonal::zero();
        Some(self.fused(committed, u, v, Some(tangent)))
    }
}

/// The checks of a shear building's floor masses (kg) and damping matrix (row-major
/// `N×N`, N·s/m) in the documented order of [`ShearBuilding::new`]; `Ok(true)` when the
/// damping matrix is symmetric tridiagonal (every other entry zero). The one check of the
/// const-generic and the run-time-sized (`std`) buildings. Cost: O(N²).
///
/// Errors: [`Error::NonFiniteInput`], [`Error::MassNotSpd`], [`Error::OperatorOverflow`],
/// [`Error::OperatorUnderflow`].
pub(crate) fn check_building<T: Real>(masses: &[f64], damping: &[f64]) -> Result<bool, Error> {
    let n = masses.len();
    if !masses.iter().chain(damping).all(|x| x.is_finite()) {
        return Err(Error::NonFiniteInput);
    }
    if masses.iter().any(|&m| m <= 0.0) {
        return Err(Error::MassNotSpd);
    }
    super::fits::<T>(masses)?;
    let smallest = if T::MAX < f64::MAX {
        f64::from(f32::MIN_POSITIVE)
    } else {
        f64::MIN_POSITIVE
    };
    if masses.iter().any(|&m| m < smallest) {
        return Err(Error::OperatorUnderflow);
    }
    for row in damping.chunks(n.max(1)) {
        super::fits::<T>(row)?;
    }
    Ok((0..n).all(|i| {
        (0..n).all(|j| i.abs_diff(j) <= 1 || damping[i * n + j] == 0.0)
            && (i == 0 || damping[i * n + i - 1] == damping[(i - 1) * n + i])
    }))
}

/// The tangent bands a trial adds its storeys to: `[diagonal, off]` of `∂F/∂u` and of
/// `∂F/∂v` (each `N` values; `off[0]` not written).
pub(crate) struct Bands<'a, T> {
    pub(crate) stiffness: [&'a mut [T]; 2],
    pub(crate) damping: [&'a mut [T]; 2],
}

impl<'a, T: Real> Bands<'a, T> {
    /// The stiffness and damping bands of `t`.
    #[inline(always)]
    fn of<const N: usize>(t: &'a mut TridiagonalTangent<T, N>) -> Self {
        let (k, c) = (&mut t.stiffness, &mut t.damping);
        Bands {
            stiffness: [&mut k.diagonal.data.0[0], &mut k.off.data.0[0]],
            damping: [&mut c.diagonal.data.0[0], &mut c.off.data.0[0]],
        }
    }
}

/// The storey loop of every shear-building trial, on slices of `N = laws.len()` values:
/// each storey's law at its drift `δ_i = u_i − u_{i−1}` and drift rate (`u_{−1} = 0`:
/// `δ_0 = u_0` exactly, as [`models::drifts`](crate::models::drifts)) from its `committed`
/// history, its force added to `force` (`+f_i` at `i`, `−f_i` at `i − 1`; `force` holds
/// `C v` on entry), its trial history into `history`, and — with `bands` — its tangent
/// added to them. Returns the branch signature (bit `i mod 64` set when storey `i` is
/// inelastic). The one loop of the const-generic [`ShearBuilding`] and the run-time-sized
/// one (`std`). Cost: `N` law trials and `2N` adds (`4N` more with `bands`).
#[inline(always)]
pub(crate) fn storeys_flat<T: Real, L: Law<T>>(
    laws: &[L],
    committed: &[L::History],
    (ua, va): (&[T], &[T]),
    force: &mut [T],
    history: &mut [L::History],
    mut bands: Option<Bands<'_, T>>,
) -> u64 {
    let mut branch = 0u64;
    let (mut u_below, mut v_below) = (T::zero(), T::zero());
    for i in 0..laws.len() {
        // δ_i = u_i − u_{i−1} (u_{−1} = 0: δ_0 = u_0 exactly), as `drifts`.
        let (d, r) = if i == 0 {
            (ua[0], va[0])
        } else {
            (ua[i] - u_below, va[i] - v_below)
        };
        (u_below, v_below) = (ua[i], va[i]);
        let s = laws[i].trial(&committed[i], d, r);
        force[i] += s.force;
        if i > 0 {
            force[i - 1] -= s.force;
        }
        if s.inelastic {
            branch |= 1 << (i % 64);
        }
        history[i] = s.history;
        if let Some(t) = bands.as_mut() {
            add_storey(t, i, s.stiffness, s.damping);
        }
    }
    branch
}

/// Add storey `i`'s tangent stiffness `k` and damping `c` (between floors `i − 1` and `i`;
/// floor `−1` the ground) to the stiffness and damping bands: `k` on the diagonal at `i`
/// and `i − 1`, `−k` off it. Cost: `4` additions.
#[inline(always)]
fn add_storey<T: Real>(t: &mut Bands<'_, T>, i: usize, k: T, c: T) {
    let [kd, ko] = &mut t.stiffness;
    let [cd, co] = &mut t.damping;
    kd[i] += k;
    cd[i] += c;
    if i > 0 {
        kd[i - 1] += k;
        ko[i] -= k;
        cd[i - 1] += c;
        co[i] -= c;
    }
}
