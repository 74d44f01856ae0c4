//! The split step of a KR-α (or Chen–Ricles) scheme with part of the restoring force
//! measured: command first, then complete with the force read back.

use nalgebra::{SMatrix, SVector};

use crate::linalg::rows_f64;
use crate::schemes::kr_alpha::{CHEN_RICLES, kr_operators};
use crate::{AlphaParameters, Error, KrAlpha, Real, State, StepInput, Stepper};

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
    pub fn new(
        m: &SMatrix<f64, N, N>,
        c: &SMatrix<f64, N, N>,
        k: &SMatrix<f64, N, N>,
        k_num: &SMatrix<f64, N, N>,
        h: f64,
        rho_inf: f64,
    ) -> Result<Self, Error> {
        Self::build(m, c, k, k_num, h, AlphaParameters::chung_hulbert(rho_inf)?)
    }

    /// The split Chen–Ricles step (`α_m = α_f = 0`, `γ = 1/2`, `β = 1/4`). Arguments,
    /// errors and cost as [`Split::new`] without `rho_inf`.
    pub fn chen_ricles(
        m: &SMatrix<f64, N, N>,
        c: &SMatrix<f64, N, N>,
        k: &SMatrix<f64, N, N>,
        k_num: &SMatrix<f64, N, N>,
        h: f64,
    ) -> Result<Self, Error> {
        Self::build(m, c, k, k_num, h, CHEN_RICLES)
    }

    fn build(
        m: &SMatrix<f64, N, N>,
        c: &SMatrix<f64, N, N>,
        k: &SMatrix<f64, N, N>,
        k_num: &SMatrix<f64, N, N>,
        h: f64,
        p: AlphaParameters,
    ) -> Result<Self, Error> {
        let (m, c, k, kn) = (rows_f64(m), rows_f64(c), rows_f64(k), rows_f64(k_num));
        let op = kr_operators(&m, &c, &k, &kn, h, &p, T::MAX)?;
        Ok(Self {
            kr: KrAlpha::from_ops(&op, p),
        })
    }

    /// The scheme's parameters `(α_m, α_f, β, γ)`. Cost: O(1).
    pub fn parameters(&self) -> AlphaParameters {
        self.kr.parameters()
    }

    /// The state at `t = 0` from `u0, v0` (m, m/s), the given restoring force `r0`
    /// measured at `u0` and the load `p0` (force units): `a0 = M⁻¹ (p0 − r0 − C v0 −
    /// K_num u0)` and the velocity variable `v0 − γh α1 a0` (second order from any state,
    /// as [`KrAlpha`]'s start).
    ///
    /// Errors: [`Error::NonFiniteInput`] (`u0, v0` or `p0`), [`Error::NonFiniteForce`]
    /// (`r0`), [`Error::NonFiniteState`] (`a0` overflows). Cost: `4N²` multiply-adds.
    pub fn start(
        &self,
        u0: &SVector<T, N>,
        v0: &SVector<T, N>,
        r0: &SVector<T, N>,
        p0: &SVector<T, N>,
    ) -> Result<SplitState<T, N>, Error> {
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

    /// The state at `t = 0` with a known acceleration `a0` and velocity variable `v0` (the
    /// papers' start; right for a state saved from this scheme), the given force `r0` and
    /// load `p0`.
    ///
    /// Errors: [`Error::NonFiniteInput`] (`u0, v0, a0, p0`), [`Error::NonFiniteForce`]
    /// (`r0`). Cost: O(N).
    pub fn start_with_acceleration(
        &self,
        u0: &SVector<T, N>,
        v0: &SVector<T, N>,
        a0: &SVector<T, N>,
        r0: &SVector<T, N>,
        p0: &SVector<T, N>,
    ) -> Result<SplitState<T, N>, Error> {
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
