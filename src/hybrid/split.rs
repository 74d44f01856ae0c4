//! The split step of a KR-α (or Chen–Ricles) scheme with part of the restoring force
//! measured: command first, then complete with the force read back.

use nalgebra::{SMatrix, SVector};

use crate::macros::mck_fn;
use crate::schemes::kr_alpha::CHEN_RICLES;
use crate::stepper::start_fn;
use crate::{AlphaParameters, Error, KrAlpha, Param, Real, State, StepInput, Stepper};

/// A KR-α step split in two for real-time hybrid simulation: the displacement command of
/// `t_{n+1}` from the committed state, then the step completed with the restoring force
/// measured at that command (Kolay & Ricles 2014; Chen & Ricles 2008).
///
/// The structure's restoring force is `K_num u + r(t)`: a linear numerical part `K_num`
/// that the step computes itself, and a part `r` given each step — the force measured on a
/// physical specimen (mapped to the degrees of freedom), plus the forces of any nonlinear
/// numerical part (e.g. a [`Law`](crate::hysteresis::Law) evaluated at the command's
/// deformation). The operators `α1, α3` are built from `M, C` and `K`, the stiffness the
/// scheme assumes for the whole structure (the numerical part and the specimen's initial
/// stiffness):
///
/// ```text
/// command:   u_{n+1} = u_n + h v_n + h² α2 a_n,   v_{n+1} = v_n + h α1 a_n
/// complete:  M (I − α3) a_{n+1} = p̄ − r̄ − C v̄ − K_num ū − M α3 a_n
/// x̄ = (1 − α_f) x_{n+1} + α_f x_n  for x = u, v, p, r
/// ```
///
/// with `α1, α2, α3` and `(α_m, α_f, β, γ)` of [`KrAlpha`] (`r_n, p_n` are kept in
/// [`SplitState`]). With `r = (K − K_num) u` exactly, the step is [`KrAlpha`]'s
/// (`tests/hybrid.rs`: equal to rounding). For a specimen that softens (tangent stiffness
/// below the one in `K`) the scheme stays stable; one that hardens beyond `K` makes it
/// conditionally stable (`docs/hybrid.md` measures the limit).
///
/// Cost: [`Split::command`] `N²` multiply-adds + `3N`; [`Split::complete`] `5N² + O(N)`
/// (it recomputes the command from the committed state, so the two cannot disagree). No
/// allocation, no panic. Size: that of a [`KrAlpha`].
///
/// ```
/// use aemstep::hybrid::Split;
/// use aemstep::{matrix, vector};
/// // 1 DOF, m = 1, k = 25 of which 15 numerical and a "specimen" spring of 10, h = 1/1024 s
/// let sys = Split::<f64, 1>::new(
///     &matrix![1.0], &matrix![0.1], &matrix![25.0], &matrix![15.0], 1.0 / 1024.0, 0.9,
/// )?;
/// let mut s = sys.start(&vector![0.01], &vector![0.0], &vector![10.0 * 0.01], &vector![0.0])?;
/// for _ in 0..1024 {
///     let d = sys.command(&s); // displacement sent to the actuator
///     let force = 10.0 * d[0]; // force read back from the specimen
///     sys.complete(&mut s, &vector![force], &vector![0.0])?;
/// }
/// // A NaN force is refused and changes nothing.
/// let before = s;
/// assert_eq!(
///     sys.complete(&mut s, &vector![f64::NAN], &vector![0.0]),
///     Err(aemstep::Error::NonFiniteForce)
/// );
/// assert_eq!(s, before);
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Split<T, const N: usize> {
    /// The KR-α operators with `G K_num` (and the start's `M⁻¹ K_num`) in place of `G K`.
    kr: KrAlpha<T, N>,
}

/// The committed state of a [`Split`] run: `u, v, a` at `t_n` (as [`State`], `v` the
/// scheme's velocity variable), and the given restoring force `r_n` and load `p_n` the
/// next step weights with `α_f`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SplitState<T, const N: usize> {
    state: State<T, N>,
    r: SVector<T, N>,
    p: SVector<T, N>,
}

/// At rest: as `SplitState::at_rest_f32`/`at_rest_f64`, for any `T`.
impl<T: Real, const N: usize> Default for SplitState<T, N> {
    fn default() -> Self {
        Self {
            state: State::default(),
            r: SVector::zeros(),
            p: SVector::zeros(),
        }
    }
}

macro_rules! split_state_at_rest {
    ($t:ident, $at_rest:ident, $zeros:ident) => {
        impl<const N: usize> SplitState<$t, N> {
            /// At rest at step 0: `u = v = a = 0`, no restoring force, no load.
            /// `const fn`, for a `static`; equal to `SplitState::default()` and to
            /// [`Split::start`] from rest with `r0 = p0 = 0`. Cost: none in a `static`.
            pub const fn $at_rest() -> Self {
                Self {
                    state: State::$at_rest(),
                    r: crate::state::$zeros(),
                    p: crate::state::$zeros(),
                }
            }
        }
    };
}
split_state_at_rest!(f32, at_rest_f32, zeros_f32);
split_state_at_rest!(f64, at_rest_f64, zeros_f64);

impl<T: Real, const N: usize> SplitState<T, N> {
    /// The kinematic state at `t_n`. Cost: none.
    pub fn state(&self) -> &State<T, N> {
        &self.state
    }

    /// The given restoring force `r_n` committed with the last step (force units). Cost:
    /// none.
    pub fn restoring_force(&self) -> &SVector<T, N> {
        &self.r
    }

    /// The load `p_n` committed with the last step (force units). Cost: none.
    pub fn load(&self) -> &SVector<T, N> {
        &self.p
    }
}

impl<T: Real, const N: usize> Split<T, N> {
    mck_fn! {
        /// The split KR-α step with high-frequency spectral radius `rho_inf ∈ [0, 1]`, for
        /// `M u'' + C u' + K_num u + r(t) = p(t)` with step `h` (s). `k` is the stiffness the
        /// operators assume for the whole structure (numerical part plus the specimen's initial
        /// stiffness), `k_num` the linear numerical part the step computes itself (zero when
        /// every spring is given through `r`). Units as [`KrAlpha::new`]; computed in `f64`,
        /// rounded once to `T`, bit-identical to [`Split::from_rows_f32`] / `from_rows_f64`.
        ///
        /// Errors: as [`KrAlpha::new`] (`k_num` checked for finiteness with `M, C, K`; its
        /// operator `G K_num` must fit `T`).
        ///
        /// Cost: about `10N³` flops in `f64`.
        pub fn new(m, c, k, k_num: &SMatrix<f64, N, N>, h: f64, rho_inf: f64) {
            let p = AlphaParameters::chung_hulbert(rho_inf)?;
            KrAlpha::with_rest(m, c, k, k_num, h, p).map(|kr| Self { kr })
        }
    }

    mck_fn! {
        /// The split Chen–Ricles step (`α_m = α_f = 0`, `γ = 1/2`, `β = 1/4`). Arguments,
        /// errors and cost as [`Split::new`] without `rho_inf`.
        pub fn chen_ricles(m, c, k, k_num: &SMatrix<f64, N, N>, h: f64) {
            KrAlpha::with_rest(m, c, k, k_num, h, CHEN_RICLES).map(|kr| Self { kr })
        }
    }

    /// The scheme's parameters `(α_m, α_f, β, γ)`. Cost: O(1).
    pub fn parameters(&self) -> AlphaParameters {
        self.kr.parameters()
    }

    start_fn! {
        /// The state at `t = 0` from `u0, v0` (m, m/s), the given restoring force `r0`
        /// measured at `u0` and the load `p0` (force units): `a0 = M⁻¹ (p0 − r0 − C v0 −
        /// K_num u0)` and the velocity variable `v0 − γh α1 a0` (second order from any state,
        /// as [`KrAlpha`]'s start).
        ///
        /// Errors: [`Error::NonFiniteInput`] (`u0, v0` or `p0`), [`Error::NonFiniteForce`]
        /// (`r0`), [`Error::NonFiniteState`] (`a0` overflows). Cost: `4N²` multiply-adds.
        pub fn start(&self, u0, v0, r0: &SVector<T, N>, p0: &SVector<T, N>) -> SplitState<T, N> {
            if !(u0.is_finite() && v0.is_finite() && p0.is_finite()) {
                return Err(Error::NonFiniteInput);
            }
            if !r0.is_finite() {
                return Err(Error::NonFiniteForce);
            }
            let net = p0 - r0;
            if !net.is_finite() {
                return Err(Error::NonFiniteState);
            }
            let state = self.kr.start(u0, v0, &net)?;
            Ok(SplitState {
                state,
                r: *r0,
                p: *p0,
            })
        }
    }

    start_fn! {
        /// The state at `t = 0` with a known acceleration `a0` and velocity variable `v0` (the
        /// papers' start; right for a state saved from this scheme), the given force `r0` and
        /// load `p0`.
        ///
        /// Errors: [`Error::NonFiniteInput`] (`u0, v0, a0, p0`), [`Error::NonFiniteForce`]
        /// (`r0`). Cost: O(N).
        pub fn start_with_acceleration(&self, u0, v0, a0: &SVector<T, N>, r0: &SVector<T, N>, p0: &SVector<T, N>)
            -> SplitState<T, N>
        {
            if !p0.is_finite() {
                return Err(Error::NonFiniteInput);
            }
            let state = self.kr.start_with_acceleration(u0, v0, a0)?;
            if !r0.is_finite() {
                return Err(Error::NonFiniteForce);
            }
            Ok(SplitState {
                state,
                r: *r0,
                p: *p0,
            })
        }
    }

    /// The displacement command `u_{n+1} = u_n + h v_n + h² α2 a_n` (m) for the next
    /// sample, from the committed state alone: send it to the actuator (and evaluate the
    /// numerical nonlinear part there), then call [`Split::complete`]. Calling it again
    /// gives the same value. Cost: `N²` multiply-adds + `3N`.
    pub fn command(&self, s: &SplitState<T, N>) -> SVector<T, N> {
        self.kr.next_displacement(&s.state)
    }

    /// Complete the step to `t_{n+1}`: `r` is the given restoring force at the command (the
    /// specimen's measured force mapped to the degrees of freedom, plus the numerical
    /// nonlinear part's), `p = p(t_{n+1})` the load. Commits the new state with `r` and
    /// `p`; on error nothing changes (a missing force sample: call again with the next
    /// one, or hold the last).
    ///
    /// Errors: [`Error::NonFiniteForce`] (`r` NaN or infinite), [`Error::NonFiniteInput`]
    /// (`p`), [`Error::NonFiniteState`] (the step overflows). Cost: `5N²` multiply-adds +
    /// `O(N)`; no allocation, no panic.
    pub fn complete(
        &self,
        s: &mut SplitState<T, N>,
        r: &SVector<T, N>,
        p: &SVector<T, N>,
    ) -> Result<(), Error> {
        if !r.is_finite() {
            return Err(Error::NonFiniteForce);
        }
        if !p.is_finite() {
            return Err(Error::NonFiniteInput);
        }
        let (net_prev, net) = (s.p - s.r, p - r);
        let mut next = s.state;
        self.kr.step_with_previous_input(&mut next, &net_prev, &net);
        if !(net.is_finite() && next.is_finite()) {
            return Err(Error::NonFiniteState);
        }
        s.state = next;
        s.r = *r;
        s.p = *p;
        Ok(())
    }

    /// The operators as a plain [`KrAlpha`] of `M, C, K` with `K_num` for its stiffness
    /// term: stepping it with the load `p − r` is the split step. Cost: none.
    pub fn scheme(&self) -> &KrAlpha<T, N> {
        &self.kr
    }
}

/// Const-fn construction, for operators computed at compile time into flash.
macro_rules! const_ctor {
    ($t:ident, $from_rows:ident, $from_rows_cr:ident) => {
        impl<const N: usize> Split<$t, N> {
            /// `const fn` twin of [`Split::new`]: `M, C, K, K_num` as row-major `f64`
            /// arrays ([`Rows`](crate::models::Rows)), `h` in seconds, `rho_inf ∈ [0, 1]`.
            /// Bit-identical to [`Split::new`]:
            ///
            /// ```
            /// use aemstep::hybrid::Split;
            /// static SYS: Split<f32, 1> = match Split::from_rows_f32(
            ///     [[1.0]], [[0.1]], [[25.0]], [[15.0]], 1.0 / 1024.0, 0.9,
            /// ) {
            ///     Ok(s) => s,
            ///     Err(e) => panic!("{}", e.as_str()),
            /// };
            /// assert_eq!(SYS.time_step(), 1.0 / 1024.0);
            /// ```
            ///
            /// Errors: as [`Split::new`].
            pub const fn $from_rows(
                m: crate::models::Rows<N>,
                c: crate::models::Rows<N>,
                k: crate::models::Rows<N>,
                k_num: crate::models::Rows<N>,
                h: f64,
                rho_inf: f64,
            ) -> Result<Self, Error> {
                let p = match AlphaParameters::chung_hulbert(rho_inf) {
                    Ok(p) => p,
                    Err(e) => return Err(e),
                };
                match KrAlpha::<$t, N>::from_params(&m, &c, &k, &k_num, h, p) {
                    Ok(kr) => Ok(Self { kr }),
                    Err(e) => Err(e),
                }
            }

            /// `const fn` twin of [`Split::chen_ricles`] (arguments as
            /// [`Split::from_rows_f32`] without `rho_inf`). Errors: as [`Split::new`].
            pub const fn $from_rows_cr(
                m: crate::models::Rows<N>,
                c: crate::models::Rows<N>,
                k: crate::models::Rows<N>,
                k_num: crate::models::Rows<N>,
                h: f64,
            ) -> Result<Self, Error> {
                match KrAlpha::<$t, N>::from_params(&m, &c, &k, &k_num, h, CHEN_RICLES) {
                    Ok(kr) => Ok(Self { kr }),
                    Err(e) => Err(e),
                }
            }

            /// The time step `h` (s), usable in `const` contexts. Cost: none.
            pub const fn time_step(&self) -> $t {
                self.kr.time_step()
            }
        }
    };
}
const_ctor!(f32, from_rows_f32, from_rows_chen_ricles_f32);
const_ctor!(f64, from_rows_f64, from_rows_chen_ricles_f64);

/// A storey specimen on two degrees of freedom of a shear-type model, for [`Split`]: the
/// mapping an experimental setup does (OpenFresco's, for one actuator across a storey)
/// between the model's floor displacements and the one actuator and load cell of the
/// specimen.
///
/// Storey `i` (`0 ≤ i < N`, DOFs ground storey first, as
/// [`shear_building`](crate::models::shear_building)) joins floor `i − 1` below to floor
/// `i` above; storey `0` joins the ground to floor `0`. With `L` the row `e_iᵀ − e_{i−1}ᵀ` (`e_{−1} = 0`):
///
/// ```text
/// command (deformation):   d = L u = u_i − u_{i−1}            (u_{−1} = 0, the ground)
/// restoring force:         r = Lᵀ f:  r_i = +f,  r_{i−1} = −f (storey 0: r_0 = f only)
/// stiffness it adds:       Lᵀ k L:    +k at (i, i) and (i−1, i−1), −k at (i, i−1), (i−1, i)
/// ```
///
/// `f` is the force the load cell reads, positive when it resists a positive deformation
/// (for a linear specimen `f = k d`). `r` is the transpose of the command, so the specimen's
/// work is the model's (`r · δu = f δd`); for `i > 0` its entries sum to zero (the storey is
/// internal: no net force on the structure). Give [`Split`] `K_num` without the storey and
/// `K` with [`StoreySpecimen::stiffness`] of its initial stiffness added; a linear specimen
/// of stiffness `k` then reproduces the all-numerical model to rounding
/// (`tests/storey_specimen.rs`).
///
/// ```
/// use aemstep::hybrid::{Split, StoreySpecimen};
/// use aemstep::models::{self, Rows};
/// use aemstep::vector;
///
/// // 3 storeys (kg, N/m); storey 2 (index 1, between floors 0 and 1) is the specimen.
/// let (m, k_all) = models::shear_building([1.0e5; 3], [1.0e8; 3]);
/// let (_, k_num) = models::shear_building([1.0e5; 3], [1.0e8, 0.0, 1.0e8]);
/// let storey = StoreySpecimen::<3>::new(1)?;
/// let k = models::add(&k_num, &storey.stiffness(1.0e8)); // what the operators assume
/// assert_eq!(k, k_all);
/// let c = models::rayleigh(&m, &k, 0.0, 2e-3);
/// let sys = Split::<f64, 3>::from_rows_f64(m, c, k, k_num, 1.0 / 1024.0, 0.9)?;
/// let zero = vector![0.0, 0.0, 0.0];
/// let mut s = sys.start(&zero, &zero, &zero, &zero)?;
/// for n in 0..100 {
///     let p = vector![0.0, 0.0, if n < 10 { 1.0e5 } else { 0.0 }]; // N, at the roof
///     let d = storey.command(&sys.command(&s)); // m, to the actuator across storey 2
///     let f = 1.0e8 * d; // N, the load cell (here a linear specimen)
///     sys.complete(&mut s, &storey.force(f), &p)?;
/// }
/// let r = storey.force(1.0);
/// assert_eq!((r[0], r[1], r[2]), (-1.0, 1.0, 0.0));
/// # Ok::<(), aemstep::Error>(())
/// ```
///
/// Cost: [`StoreySpecimen::command`] one subtraction, [`StoreySpecimen::force`] `N`
/// stores; no allocation, no panic. Size: one `usize`.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StoreySpecimen<const N: usize> {
    storey: usize,
}

impl<const N: usize> StoreySpecimen<N> {
    /// The specimen is storey `storey` (`0 ≤ storey < N`; `0` stands on the ground).
    ///
    /// Errors: [`Error::InvalidParameter`] for `storey ≥ N`. Cost: O(1); `const`.
    pub const fn new(storey: usize) -> Result<Self, Error> {
        if storey >= N {
            return Err(Error::InvalidParameter(Param::Storey));
        }
        Ok(Self { storey })
    }

    /// The storey index `i` (the specimen joins DOF `i − 1`, or the ground for `i = 0`, to
    /// DOF `i`). Cost: none.
    pub const fn storey(&self) -> usize {
        self.storey
    }

    /// The actuator command, the storey's deformation `u_i − u_{i−1}` (m when `u` is), of
    /// the floor displacements `u` (e.g. [`Split::command`]'s). Cost: one subtraction.
    pub fn command<T: Real>(&self, u: &SVector<T, N>) -> T {
        let i = self.storey;
        match i.checked_sub(1) {
            Some(below) => u[i] - u[below],
            None => u[i],
        }
    }

    /// The restoring force vector (N when `f` is) of a load-cell force `f`: `+f` on DOF
    /// `i`, `−f` on DOF `i − 1` (none for the ground storey), zero elsewhere; the `r` of
    /// [`Split::complete`] (add those of several specimens with
    /// [`StoreySpecimen::add_force`]). Cost: `N` stores.
    pub fn force<T: Real>(&self, f: T) -> SVector<T, N> {
        let mut r = SVector::<T, N>::zeros();
        self.add_force(&mut r, f);
        r
    }

    /// Add the force vector of [`StoreySpecimen::force`] to `r` (several specimens, or a
    /// specimen beside a numerical nonlinear part). Cost: two additions.
    pub fn add_force<T: Real>(&self, r: &mut SVector<T, N>, f: T) {
        let i = self.storey;
        r[i] += f;
        if let Some(below) = i.checked_sub(1) {
            r[below] -= f;
        }
    }

    /// The stiffness matrix `Lᵀ k L` (row-major, N/m when `k` is) a storey spring of
    /// stiffness `k` adds to the model's: add the specimen's initial stiffness to `K_num`
    /// for the `K` the [`Split`] operators assume ([`models::add`](crate::models::add)).
    /// Cost: `N²` stores; `const`.
    pub const fn stiffness(&self, k: f64) -> crate::models::Rows<N> {
        let mut a = [[0.0; N]; N];
        let i = self.storey;
        a[i][i] = k;
        if i > 0 {
            a[i - 1][i - 1] = k;
            a[i][i - 1] = -k;
            a[i - 1][i] = -k;
        }
        a
    }
}
