//! Optimal state feedback: the discrete linear–quadratic regulator on a zero-order-hold
//! design model, with the one-sample computation delay built in.
//!
//! # Timing
//!
//! A digital controller samples the structure at `t_k`, computes while the step runs, and
//! its DAC holds the result from `t_{k+1}` to `t_{k+2}`. Over `[t_k, t_{k+1})` the plant
//! feels the force `u_{k−1}` computed from the previous sample:
//!
//! ```text
//! x_{k+1} = Φ x_k + Γ u_{k−1}            (Φ, Γ: the zero-order hold of the plant)
//! z_k = [x_k; u_{k−1}],   z_{k+1} = [Φ Γ; 0 0] z_k + [0; I] u_k        (Z = S + I states)
//! ```
//!
//! [`DesignModel::delayed`] builds the second form; the regulator designed on it,
//! `u_k = −K z_k = −K_x x_k − K_u u_{k−1}`, is what the [`Controller`](super::Controller)
//! steps. Without the delay (`u_k` acts from `t_k`: an analog loop, or a computation that
//! is negligible against the step) design on [`DesignModel`] itself.
//!
//! # The regulator
//!
//! For the cost `Σ_k x_kᵀ Q x_k + 2 x_kᵀ S u_k + u_kᵀ R u_k` the optimal control is
//! `u_k = −K x_k`,
//!
//! ```text
//! P = Φᵀ P Φ − (Φᵀ P Γ + S)(R + Γᵀ P Γ)⁻¹(Γᵀ P Φ + Sᵀ) + Q,     K = (R + Γᵀ P Γ)⁻¹(Γᵀ P Φ + Sᵀ)
//! ```
//!
//! the dual of the Kalman filter's equation (`Φ → Φᵀ`, `H → Γᵀ`): [`Lqr`] hands it, with
//! the cross weight taken out (`Φ̄ = Φ − Γ R⁻¹ Sᵀ`, `Q̄ = Q − S R⁻¹ Sᵀ`: the same `P`), to
//! the observer's verified doubling solver ([`SteadyState`]), then certifies the closed
//! loop `Φ − Γ K` itself (a Lyapunov certificate with its rounding bounded, below).
//!
//! Output weighting ([`Weights::outputs`]): on `y = C x + D u` with weight `Q_y`,
//! `Q = Cᵀ Q_y C`, `S = Cᵀ Q_y D`, `R + Dᵀ Q_y D` — drifts (`D = 0`) or absolute
//! accelerations, which the control force feeds through.
//!
//! ```
//! use aemstep::control::{DesignModel, Lqr, Weights};
//! use aemstep::models::{self, storey_drifts};
//! use aemstep::observer::{Outputs, StateSpace};
//! use aemstep::nalgebra::SMatrix;
//!
//! // A 3-storey shear building, an actuator between the ground and floor 1, h = 5 ms.
//! let (m, k) = models::shear_building([1.0e3; 3], [1.0e6; 3]);
//! let c = models::rayleigh(&m, &k, 0.1, 0.002);
//! let mat = |r| models::matrix_of::<f64, 3>(&r);
//! let b = SMatrix::<f64, 3, 1>::new(1.0, 0.0, 0.0);
//! let ss = StateSpace::<3, 6, 1>::zero_order_hold(&mat(m), &mat(c), &mat(k), &b, 0.005)?;
//! // Drifts weighted (1/m² ↔ 1/N²).
//! let drifts = ss.outputs(&Outputs::displacements(storey_drifts::<3>()))?;
//! let w = Weights::outputs(&drifts, &[[1.0e12, 0.0, 0.0], [0.0, 1.0e12, 0.0], [0.0, 0.0, 1.0e12]], &[[1.0]]);
//! // The one-sample computation delay: z = [x; u_{k−1}].
//! let plant = DesignModel::from_state_space(&ss);
//! let design: DesignModel<7, 1> = plant.delayed()?;
//! let lqr = Lqr::from_parts(&design, &w.delayed(&[[1.0e-3]])?)?;
//! assert!(lqr.radius_bound < 1.0);
//! # Ok::<(), aemstep::Error>(())
//! ```

use nalgebra::SMatrix;

use crate::kinematics::check_time_step;
use crate::linalg::cholesky::cholesky;
use crate::linalg::expm::{Blk, blk_expm};
use crate::linalg::{
    Mat, add_scaled, all_finite, identity, max_abs, mul, put, rows_f64, scaled, sqrt, transpose,
};
use crate::observer::{
    Measurement, StateSpace, SteadyState, abs_of, balance, bare_model, definite_lu, inf_norm,
    is_covariance, stein, symmetrize,
};
use crate::{Error, Param};

/// A sampled-data design model `x_{k+1} = Φ x_k + Γ u_k` (`S` states, `I` control
/// inputs; `f64`, row-major), the input held over each step (zero-order hold). Plain data:
/// fill the fields, or take them from a [`StateSpace`] ([`DesignModel::from_state_space`]);
/// [`DesignModel::delayed`] adds the one-sample computation delay. Size: `S² + S·I`
/// values of `f64` (a build-time object).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DesignModel<const S: usize, const I: usize> {
    /// `Φ` (`S×S`), the transition over one step.
    pub phi: [[f64; S]; S],
    /// `Γ` (`S×I`), the effect of the input held over the step (state units per input
    /// unit: m/N and m/s/N for a building driven by forces).
    pub gamma: [[f64; I]; S],
}

impl<const S: usize, const I: usize> DesignModel<S, I> {
    /// The design model of a discrete model whose input is held over each step:
    /// `Γ = Γ₀ + Γ₁`. For [`StateSpace::zero_order_hold`] (`Γ₁ = 0`) that is its `Γ`,
    /// exactly; for a two-ended model (the AEM, Newmark: `Γ₀ w_{k−1} + Γ₁ w_k`) a held input
    /// is the same sample at both ends of the step, so the step adds `(Γ₀ + Γ₁) u` (to the
    /// scheme's truncation error for an input that jumps at the samples). `const fn`;
    /// cost `S·I` additions. The matrices are checked where they are used.
    pub const fn from_state_space<const N: usize>(ss: &StateSpace<N, S, I>) -> Self {
        Self {
            phi: ss.phi,
            gamma: add_scaled(&ss.gamma0, 1.0, &ss.gamma1),
        }
    }

    /// The model with the one-sample computation delay: `z = [x; u_{k−1}]` (`Z = S + I`
    /// states), `Φ_z = [Φ Γ; 0 0]`, `Γ_z = [0; I]` (timing in the [module docs](self)).
    /// `const fn`.
    ///
    /// Errors: [`Error::StateSizeMismatch`] (`Z ≠ S + I`). Cost: `Z² + Z·I` copies.
    pub const fn delayed<const Z: usize>(&self) -> Result<DesignModel<Z, I>, Error> {
        if Z != S + I {
            return Err(Error::StateSizeMismatch);
        }
        let mut phi = [[0.0; Z]; Z];
        put(&mut phi, &self.phi, 0, 0);
        put(&mut phi, &self.gamma, 0, S);
        let mut gamma = [[0.0; I]; Z];
        put(&mut gamma, &identity::<I>(), S, 0);
        Ok(DesignModel { phi, gamma })
    }
}

impl<const S: usize, const I: usize> DesignModel<S, I> {
    /// A certified upper bound (`< 1`) on the spectral radius of the closed loop
    /// `Φ − Γ K` of the state feedback `u = −K x` (`gain`: `K`, `I×S`, input units per
    /// state unit), for any gain: the certificate [`Lqr::from_parts`] applies to its own
    /// (method there). It does not depend on the units: a diagonal scaling of the state
    /// and a scaling of the input (`Γ` and `K` scaled inversely) give the same verdict and
    /// bounds within the bisection's resolution (`2^-30` relative) of each other and of the
    /// spectral radius (`tests/control_lqr.rs`: newtons, kN, MN; metres and millimetres).
    /// `const fn`.
    ///
    /// ```
    /// use aemstep::control::DesignModel;
    /// use aemstep::Error;
    /// // A double integrator sampled at h = 0.1 s (position, velocity; force per unit mass).
    /// let plant = DesignModel { phi: [[1.0, 0.1], [0.0, 1.0]], gamma: [[0.005], [0.1]] };
    /// // A gain placing the poles at 0.9 ± 0.1i (|λ| = √0.82 = 0.905539), and the same
    /// // gain with its sign flipped (poles outside the unit circle).
    /// let rho = plant.radius_bound(&[[2.0, 1.9]])?;
    /// assert!(rho >= 0.82f64.sqrt() && rho < 0.905540);
    /// assert_eq!(plant.radius_bound(&[[-2.0, -1.9]]), Err(Error::NotStabilizing));
    /// # Ok::<(), aemstep::Error>(())
    /// ```
    ///
    /// Errors: [`Error::NonFiniteInput`] (`Φ`, `Γ` or `K` not finite),
    /// [`Error::OperatorOverflow`] (`Φ − Γ K` not finite), [`Error::NotStabilizing`] (not
    /// certified: a spectral radius at or above 1, or within rounding of it).
    ///
    /// Cost: `S²·I` flops for the closed loop and as much for its rounding bound, then
    /// the certificate's (in [`Lqr::from_parts`]: up to 41 Lyapunov certificates of about
    /// `3 S³` flops a squaring and `10 S³` more each).
    pub const fn radius_bound(&self, gain: &[[f64; S]; I]) -> Result<f64, Error> {
        if !(all_finite(&self.phi) && all_finite(&self.gamma) && all_finite(gain)) {
            return Err(Error::NonFiniteInput);
        }
        let a = closed_loop(&self.phi, &self.gamma, gain);
        if !all_finite(&a) {
            return Err(Error::OperatorOverflow);
        }
        match certified_radius(&self.phi, &self.gamma, gain, &a) {
            Some(b) => Ok(b),
            None => Err(Error::NotStabilizing),
        }
    }
}

/// The weights of the regulator's cost `Σ_k x_kᵀ Q x_k + 2 x_kᵀ S u_k + u_kᵀ R u_k`
/// (`f64`, row-major; units: `1/(state unit)²`, `1/(state unit · input unit)`,
/// `1/(input unit)²`, only their ratios matter). Valid: `Q` symmetric positive
/// semidefinite, `R` symmetric positive definite, the joint weight `[Q S; Sᵀ R]` positive
/// semidefinite (checked by [`Lqr::from_parts`]). Size: `S² + I² + S·I` values of `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Weights<const S: usize, const I: usize> {
    /// `Q` (`S×S`), the state weight.
    pub q: [[f64; S]; S],
    /// `R` (`I×I`), the input weight.
    pub r: [[f64; I]; I],
    /// `S` (`S×I`), the cross weight (zero for none).
    pub cross: [[f64; I]; S],
}

impl<const S: usize, const I: usize> Weights<S, I> {
    /// Every weight is finite. Cost: `S² + I² + S·I` comparisons.
    pub const fn is_finite(&self) -> bool {
        all_finite(&self.q) && all_finite(&self.r) && all_finite(&self.cross)
    }

    /// State and input weights, no cross weight. `const fn`, no check (see [`Weights`]).
    pub const fn new(q: &[[f64; S]; S], r: &[[f64; I]; I]) -> Self {
        Self {
            q: *q,
            r: *r,
            cross: [[0.0; I]; S],
        }
    }

    /// Output weighting on `y = C x + D u` (`meas`: `C = H`, `D` of the control model's
    /// [`StateSpace::outputs`], `O` outputs) with output weight `qy` (`O×O`, symmetric
    /// positive semidefinite, `1/(output unit)²`) plus the input weight `r`:
    /// `Q = Cᵀ Q_y C`, `S = Cᵀ Q_y D`, `R + Dᵀ Q_y D` — so the cost is
    /// `Σ y_kᵀ Q_y y_k + u_kᵀ R u_k`. For drifts `D = 0`; absolute accelerations feel the
    /// control force directly (`D = Y_a M⁻¹ B`) and need the cross term. `const fn`, no
    /// check (see [`Weights`]); cost `O(S²·O + S·O²)` flops.
    pub const fn outputs<const O: usize>(
        meas: &Measurement<S, I, O>,
        qy: &[[f64; O]; O],
        r: &[[f64; I]; I],
    ) -> Self {
        let qc = mul(qy, &meas.h);
        let qd = mul(qy, &meas.d);
        Self {
            q: symmetrize(&mul(&transpose(&meas.h), &qc)),
            r: symmetrize(&add_scaled(r, 1.0, &mul(&transpose(&meas.d), &qd))),
            cross: mul(&transpose(&meas.h), &qd),
        }
    }

    /// The weights on the delayed model's state `z = [x; u_{k−1}]` ([`DesignModel::delayed`],
    /// `Z = S + I`): the stage cost `[Q S; Sᵀ R]` of the state and of the force that acts
    /// over the step, `u_{k−1}` (the same cost as without the delay, for the force that is
    /// actually held), and `decision` (`I×I`, symmetric positive definite) on the command
    /// `u_k` as it is computed — it enters the physical cost only a step later, so the
    /// Riccati equation needs a weight of its own on it (small against `R`: `1e-3 R`, say;
    /// the design converges to the physical cost's as it goes to zero). `const fn`.
    ///
    /// Errors: [`Error::StateSizeMismatch`] (`Z ≠ S + I`). Cost: `Z²` copies.
    pub const fn delayed<const Z: usize>(
        &self,
        decision: &[[f64; I]; I],
    ) -> Result<Weights<Z, I>, Error> {
        if Z != S + I {
            return Err(Error::StateSizeMismatch);
        }
        let mut q = [[0.0; Z]; Z];
        put(&mut q, &self.q, 0, 0);
        put(&mut q, &self.cross, 0, S);
        put(&mut q, &transpose(&self.cross), S, 0);
        put(&mut q, &self.r, S, S);
        Ok(Weights {
            q,
            r: *decision,
            cross: [[0.0; I]; Z],
        })
    }
}

impl<const S: usize, const I: usize> Weights<S, I> {
    /// The sampled-data design of a continuous one (Van Loan 1978, "Computing integrals
    /// involving the matrix exponential"): for `ẋ = F x + G u` with the input held over
    /// each step of `h` (s) and the continuous cost `∫ xᵀ Q_c x + 2 xᵀ N_c u + uᵀ R_c u dt`
    /// (`continuous`: `Q_c`, `N_c` in its `cross`, `R_c`, per second), the exact discrete
    /// model and weights of the same cost,
    ///
    /// ```text
    /// F̃ = [F G; 0 0],  W = [Q_c N_c; N_cᵀ R_c],  exp([−F̃ᵀ W; 0 F̃] h) = [· E₁₂; 0 E₂₂]
    /// E₂₂ = e^{F̃ h} = [Φ Γ; 0 I],   [Q_d S_d; S_dᵀ R_d] = E₂₂ᵀ E₁₂ = ∫₀ʰ e^{F̃ᵀτ} W e^{F̃τ} dτ
    /// ```
    ///
    /// so that the discrete regulator ([`Lqr`]) minimizes the continuous cost exactly over
    /// held inputs, and tends to the continuous regulator as `h → 0` (its gain differs by
    /// `O(h)`: `tests/control_lqr.rs` measures it). `F`, `G` row-major (`S×S`, `S×I`, units
    /// of 1/s and state units per input unit per s). `Z = S + I` (the exponential's size is
    /// `2Z`: the crate's one exponential, of `4×4` blocks of `Z×Z`, with its lower half
    /// left zero). The weights' validity is [`Lqr::from_parts`]'s to check (a valid
    /// continuous weight gives a valid discrete one). Run time.
    ///
    /// Errors: [`Error::StateSizeMismatch`] (`Z ≠ S + I`), [`Error::NonFiniteInput`],
    /// [`Error::InvalidTimeStep`] (`h` not finite and `> 0`), [`Error::OperatorOverflow`]
    /// (a result not finite). Cost: about `(4Z)³ (19 + s)` flops (`s` squarings:
    /// `log₂` of the scaled matrix's norm), three `16 Z²` `f64` temporaries on the stack.
    pub fn sampled<const Z: usize>(
        continuous: &Weights<S, I>,
        f: &[[f64; S]; S],
        g: &[[f64; I]; S],
        h: f64,
    ) -> Result<(DesignModel<S, I>, Weights<S, I>), Error> {
        if Z != S + I {
            return Err(Error::StateSizeMismatch);
        }
        if !(continuous.is_finite() && all_finite(f) && all_finite(g)) {
            return Err(Error::NonFiniteInput);
        }
        let h = check_time_step(h)?;
        // F̃ (Z×Z) and W (Z×Z); W scaled by a power of two near 1/max|W| (exact), which the
        // integral is linear in, so that the exponential's norm is set by F̃ h.
        let mut ft = [[0.0; Z]; Z];
        put(&mut ft, f, 0, 0);
        put(&mut ft, g, 0, S);
        let mut w = [[0.0; Z]; Z];
        put(&mut w, &continuous.q, 0, 0);
        put(&mut w, &continuous.cross, 0, S);
        put(&mut w, &transpose(&continuous.cross), S, 0);
        put(&mut w, &continuous.r, S, S);
        let wmax = max_abs(&w);
        let mut scale = 1.0f64;
        while wmax * scale > 2.0 && scale > f64::MIN_POSITIVE {
            scale *= 0.5;
        }
        while wmax > 0.0 && wmax * scale < 0.5 && scale < 1.0 / f64::MIN_POSITIVE {
            scale *= 2.0;
        }
        let z = [[0.0; Z]; Z];
        let mut x: Blk<Z> = [[z; 4]; 4];
        x[0][0] = scaled(-h, &transpose(&ft));
        x[0][1] = scaled(h * scale, &w);
        x[1][1] = scaled(h, &ft);
        let (mut work, mut e): (Blk<Z>, Blk<Z>) = ([[z; 4]; 4], [[z; 4]; 4]);
        blk_expm(&mut x, &mut work, &mut e);
        let e22 = e[1][1];
        let wd = symmetrize(&scaled(1.0 / scale, &mul(&transpose(&e22), &e[0][1])));
        let mut model = DesignModel {
            phi: [[0.0; S]; S],
            gamma: [[0.0; I]; S],
        };
        let mut weights = Weights::new(&[[0.0; S]; S], &[[0.0; I]; I]);
        let mut i = 0;
        while i < Z {
            let mut j = 0;
            while j < Z {
                match (i < S, j < S) {
                    (true, true) => {
                        model.phi[i][j] = e22[i][j];
                        weights.q[i][j] = wd[i][j];
                    }
                    (true, false) => {
                        model.gamma[i][j - S] = e22[i][j];
                        weights.cross[i][j - S] = wd[i][j];
                    }
                    (false, false) => weights.r[i - S][j - S] = wd[i][j],
                    (false, true) => {}
                }
                j += 1;
            }
            i += 1;
        }
        if all_finite(&model.phi) && all_finite(&model.gamma) && weights.is_finite() {
            Ok((model, weights))
        } else {
            Err(Error::OperatorOverflow)
        }
    }
}

/// The discrete linear–quadratic regulator of a [`DesignModel`] and its [`Weights`]
/// (`S` states, `I` inputs; all `f64`, row-major): the Riccati solution, the gain, and the
/// certified bound on the closed loop's spectral radius. A build-time object; the
/// [`Controller`](super::Controller) keeps only the gain.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Lqr<const S: usize, const I: usize> {
    /// A certified upper bound on the spectral radius of `Φ − Γ K` (`< 1`), from the
    /// Lyapunov certificate ([`Lqr::from_parts`], [`DesignModel::radius_bound`]): within
    /// `2^-30` (relative) of it, in any units.
    pub radius_bound: f64,
    /// Doubling iterations the Riccati solver took.
    pub iterations: u32,
    /// `K` (`I×S`): the control `u = −K x` (input units per state unit).
    pub gain: [[f64; S]; I],
    /// `P` (`S×S`): the stabilizing solution of the Riccati equation, the optimal
    /// cost-to-go `x₀ᵀ P x₀` (units of the cost per state unit squared).
    pub cost: [[f64; S]; S],
    /// `Φ − Γ K` (`S×S`), the closed loop.
    pub closed_loop: [[f64; S]; S],
}

impl<const S: usize, const I: usize> Lqr<S, I> {
    /// Solve the regulator's Riccati equation ([module docs](self)) and form the gain
    /// `K = (R + Γᵀ P Γ)⁻¹ (Γᵀ P Φ + Sᵀ)` (`const fn`: in a `static` the compiler computes
    /// it).
    ///
    /// ```
    /// use aemstep::control::{DesignModel, Lqr, Weights};
    /// // A lightly damped oscillator (ω = 2π rad/s) sampled at h = 0.01 s: Φ, Γ of its
    /// // zero-order hold, rounded.
    /// const PLANT: DesignModel<2, 1> = DesignModel {
    ///     phi: [[0.998, 0.00999], [-0.3944, 0.9960]],
    ///     gamma: [[5.0e-5], [0.00999]],
    /// };
    /// static LQR: Lqr<2, 1> = match Lqr::from_parts(
    ///     &PLANT, &Weights::new(&[[40.0, 0.0], [0.0, 1.0]], &[[0.01]])) {
    ///     Ok(l) => l,
    ///     Err(e) => panic!("{}", e.as_str()),
    /// };
    /// assert!(LQR.radius_bound < 1.0 && LQR.gain[0][1] > 0.0);
    /// ```
    ///
    /// The cross weight is taken out (`Φ̄ = Φ − Γ R⁻¹ Sᵀ`, `Q̄ = Q − S R⁻¹ Sᵀ`) and the
    /// equation handed, as the dual of the filter's, to the observer's doubling solver
    /// [`SteadyState::from_parts`] (which refines and verifies its solution). The closed
    /// loop `Φ − Γ K` of the gain formed here is then certified, in coordinates that do
    /// not depend on the units of the state or of the input ([`DesignModel::radius_bound`]):
    /// its rounded form `A` balanced by a diagonal similarity of powers of two
    /// (`B = D⁻¹ A D`, exact; LAPACK's `gebal` rule), the rounding of `A`'s formation bounded
    /// entrywise by `F = (I + 2) ε (|Φ| + |Γ||K|)` (invariant too) and scaled with it. For
    /// `B/β`: the Stein equation `Bᵀ X B − X = −I` solved ([`SteadyState`]'s doubling), `X`
    /// shown positive definite by a Cholesky factorization of `X − δI`
    /// (`δ = 2(S+1)² ε ‖X‖∞`, which covers the factorization's rounding), and the residual
    /// `E = Bᵀ X B − X + I` bounded with the rounding of its own evaluation and with `F`'s
    /// share (`e = ‖E‖_F + (2S+7) ε ‖|B|ᵀ|X||B| + |X| + I‖_F + ‖Fᵀ|X|(|B| + F)‖_F +
    /// ‖|B|ᵀ|X|F‖_F`). For an eigenvector `B v = λ v`, `(|λ|² − 1) v*Xv = −v*(I − E)v`, so
    /// every `|λ|² ≤ 1 − (1 − e)/‖X‖∞`. That is loose where `X` is large (a lightly damped
    /// loop), so the certificate of `B/β` (`ρ(A) ≤ β ρ(B/β)`) is bisected on `β` until the
    /// bracket is `2^-30` of its top (at most 40 times): [`Lqr::radius_bound`], within that
    /// resolution of the spectral radius (`tests/control_lqr.rs`: `2.6e-10` above `0.997063`;
    /// on the 5-storey designs of `docs/control-tradeoff.md`, at most `4.3e-10` above, with
    /// the force in N, kN or MN and the state in m or mm). Balancing is what makes it
    /// independent of units: on `A` itself, with the force in newtons, the Stein solution is
    /// dominated by the force's entry and its rounding swamped the metres' part (9 of the 10
    /// designs of that sweep were refused).
    ///
    /// Errors: [`Error::NonFiniteInput`] (a non-finite `Φ`, `Γ` or weight);
    /// [`Error::InvalidParameter`]`(`[`Param::Weight`]`)` (`Q` not symmetric positive
    /// semidefinite, `R` not symmetric positive definite, `[Q S; Sᵀ R]` not positive
    /// semidefinite); [`Error::RiccatiNotConverged`] (no stabilizing solution: a mode that
    /// is unstable and not controllable, or unstable and unweighted and marginal — or one
    /// the solver's verification refuses); [`Error::NotStabilizing`] (the gain's closed
    /// loop not certified: `X` not positive definite, or `e ≥ 1`);
    /// [`Error::OperatorOverflow`].
    ///
    /// Cost: that of [`SteadyState::from_parts`] for `S` states and `I` outputs (about
    /// `10 S³` flops a doubling iteration, 10–25 iterations, plus its verification), the
    /// gain (`S²·I + S·I² + I³`), and up to 41 certificates (each `3 S³` flops a squaring
    /// of the scaled closed loop, about `log₂(20/(1 − ρ/β))` of them, up to 64, and
    /// `10 S³` for the residual, its bounds and the factorization).
    pub const fn from_parts(
        model: &DesignModel<S, I>,
        weights: &Weights<S, I>,
    ) -> Result<Self, Error> {
        let (phi, gamma) = (&model.phi, &model.gamma);
        let (q, r, s) = (&weights.q, &weights.r, &weights.cross);
        if !(all_finite(phi) && all_finite(gamma) && weights.is_finite()) {
            return Err(Error::NonFiniteInput);
        }
        if !is_covariance(q, false) {
            return Err(Error::InvalidParameter(Param::Weight));
        }
        let lu_r = match definite_lu(r) {
            Some(lu) => lu,
            None => return Err(Error::InvalidParameter(Param::Weight)),
        };
        // The cross weight out: R⁻¹ Sᵀ (I×S), Φ̄ = Φ − Γ R⁻¹ Sᵀ, Q̄ = Q − S R⁻¹ Sᵀ (the
        // Schur complement: positive semidefinite iff the joint weight is).
        let rs = lu_r.solve(&transpose(s));
        let phi_bar = add_scaled(phi, -1.0, &mul(gamma, &rs));
        let q_bar = symmetrize(&add_scaled(q, -1.0, &mul(s, &rs)));
        if !(all_finite(&phi_bar) && all_finite(&q_bar)) {
            return Err(Error::OperatorOverflow);
        }
        if !is_covariance(&q_bar, false) {
            return Err(Error::InvalidParameter(Param::Weight));
        }
        // The dual filter problem: Φ_f = Φ̄ᵀ, H_f = Γᵀ, process noise Q̄, measurement
        // noise R. Its a-priori covariance is the regulator's P.
        let (dual, meas) = bare_model(transpose(&phi_bar), transpose(gamma), 1.0);
        let ss = match SteadyState::<S, I>::from_parts(&dual, &meas, &q_bar, r) {
            Ok(ss) => ss,
            Err(Error::InvalidCovariance) => return Err(Error::InvalidParameter(Param::Weight)),
            Err(e) => return Err(e),
        };
        let p = ss.covariance;
        // K = (R + Γᵀ P Γ)⁻¹ (Γᵀ P Φ + Sᵀ), in that order.
        let gtp = mul(&transpose(gamma), &p);
        let m = symmetrize(&add_scaled(r, 1.0, &mul(&gtp, gamma)));
        let lu_m = match definite_lu(&m) {
            Some(lu) => lu,
            None => return Err(Error::RiccatiNotConverged),
        };
        let gain = lu_m.solve(&add_scaled(&mul(&gtp, phi), 1.0, &transpose(s)));
        let closed_loop = closed_loop(phi, gamma, &gain);
        if !(all_finite(&gain) && all_finite(&closed_loop)) {
            return Err(Error::OperatorOverflow);
        }
        let radius_bound = match certified_radius(phi, gamma, &gain, &closed_loop) {
            Some(b) => b,
            None => return Err(Error::NotStabilizing),
        };
        Ok(Self {
            radius_bound,
            iterations: ss.iterations,
            gain,
            cost: p,
            closed_loop,
        })
    }

    /// [`Lqr::from_parts`] with `nalgebra` matrices (run time; same numbers).
    ///
    /// Errors and cost: as [`Lqr::from_parts`].
    pub fn new(
        phi: &SMatrix<f64, S, S>,
        gamma: &SMatrix<f64, S, I>,
        weights: &Weights<S, I>,
    ) -> Result<Self, Error> {
        Self::from_parts(
            &DesignModel {
                phi: rows_f64(phi),
                gamma: rows_f64(gamma),
            },
            weights,
        )
    }

    /// `K` as a `nalgebra` matrix (`I×S`).
    pub fn gain_matrix(&self) -> SMatrix<f64, I, S> {
        SMatrix::from_fn(|i, j| self.gain[i][j])
    }

    /// `P` as a `nalgebra` matrix (`S×S`).
    pub fn cost_matrix(&self) -> SMatrix<f64, S, S> {
        SMatrix::from_fn(|i, j| self.cost[i][j])
    }

    /// The closed-loop poles, the eigenvalues of `Φ − Γ K` (complex, per step: a pole
    /// `λ` is the continuous `ln(λ)/h`), in the order of nalgebra's real Schur form; `None`
    /// if its QR iteration does not converge within `1000·S` sweeps. Every `|λ|` is at
    /// most [`Lqr::radius_bound`] (up to the eigen-solver's rounding). Host only (feature
    /// `std`: nalgebra's Schur form on the heap); cost
    /// about `10 S³` flops.
    #[cfg(feature = "std")]
    pub fn poles(&self) -> Option<[nalgebra::Complex<f64>; S]> {
        let a = nalgebra::DMatrix::<f64>::from_fn(S, S, |i, j| self.closed_loop[i][j]);
        let schur = nalgebra::Schur::try_new(a, f64::EPSILON, 1000 * S.max(1))?;
        let ev = schur.complex_eigenvalues();
        Some(core::array::from_fn(|i| ev[i]))
    }
}

/// The closed loop `Φ − Γ K`, formed as `Φ − (Γ K)` (the order [`certified_radius`]'s
/// rounding bound assumes). Cost: `S²·I` multiply-adds.
const fn closed_loop<const S: usize, const I: usize>(
    phi: &Mat<S, S>,
    gamma: &Mat<S, I>,
    gain: &Mat<I, S>,
) -> Mat<S, S> {
    add_scaled(phi, -1.0, &mul(gamma, gain))
}

/// Most bisections of [`certified_radius`]'s tightening.
const RADIUS_BISECTIONS: u32 = 40;

/// [`certified_radius`] stops bisecting once its bracket on `β` is narrower than this
/// fraction of its upper end (`2^-30`).
const RADIUS_RESOLUTION: f64 = 9.313225746154785e-10;

/// A certified upper bound below 1 on the spectral radius of the closed loop
/// `Φ − Γ K` (exact, of the stored `Φ`, `Γ`, `K`), whose rounded form is `a` (formed
/// as `Φ − (Γ K)`), or `None`.
///
/// Three steps make it independent of the units of the state and of the input (a
/// diagonal similarity `T (Φ − Γ K) T⁻¹` has the same spectrum; scaling the input scales
/// `Γ` and `K` inversely):
///
/// 1. The rounding of `a`'s formation, entrywise: `|a − (Φ − Γ K)| ≤ (I + 2) ε (|Φ| + |Γ||K|)`
///    (a product of length `I` and a subtraction), a bound that is itself invariant
///    (`|Γ s⁻¹||s K| = |Γ||K|`, and a state scaling is a similarity of it).
/// 2. Balancing ([`balance`]): `B = D⁻¹ a D` with `D` powers of two, checked exact entry by
///    entry (else `D = I`); the formation bound is scaled with it. In newtons the delayed
///    model's state `[x; u_{k−1}]` mixes metres with 10⁵ N: the Stein solution of `a`
///    itself is then dominated by the force's entry, its `δ` and its rounding swamp the
///    metres' part, and the certificate failed for loops it certified in MN.
/// 3. The Lyapunov certificate of `B/β` ([`lyapunov_bound`], `ρ(a) ≤ β ρ(B/β)`), first at
///    `β = 1`, then with `β` bisected between 0 and the best bound so far until the bracket is
///    narrower than [`RADIUS_RESOLUTION`] of its top or [`RADIUS_BISECTIONS`] are done,
///    keeping the smallest certified bound: the bracket closes on the smallest `β` whose
///    certificate rounding still allows, so the bound is within that rounding (and the
///    resolution) of the spectral radius, whatever the units.
///
/// Cost: `S²·I` flops for the formation bound, `O(S²)` a balancing sweep, and up to 41
/// certificates (each `3 S³` flops a squaring of the scaled closed loop, about
/// `log₂(20/(1 − ρ/β))` of them, up to 64, and `10 S³` for the residual, its bounds and the
/// factorization).
pub(crate) const fn certified_radius<const S: usize, const I: usize>(
    phi: &Mat<S, S>,
    gamma: &Mat<S, I>,
    gain: &Mat<I, S>,
    a: &Mat<S, S>,
) -> Option<f64> {
    let size = add_scaled(&abs_of(phi), 1.0, &mul(&abs_of(gamma), &abs_of(gain)));
    let form = scaled((I + 2) as f64 * f64::EPSILON, &size);
    if !all_finite(&form) {
        return None;
    }
    let (_, d) = balance(a);
    let (b, f) = match (similar(a, &d), similar(&form, &d)) {
        (Some(b), Some(f)) => (b, f),
        _ => (*a, form),
    };
    let mut best = match lyapunov_bound(&b, &f, 1.0) {
        Some(v) => v,
        None => return None,
    };
    let (mut lo, mut hi) = (0.0f64, best);
    let mut k = 0;
    while k < RADIUS_BISECTIONS && hi - lo > RADIUS_RESOLUTION * hi {
        let mid = 0.5 * (lo + hi);
        if mid.is_nan() || mid <= 0.0 {
            break;
        }
        match lyapunov_bound(&b, &f, mid) {
            Some(v) => {
                if v < best {
                    best = v;
                }
                hi = mid;
            }
            None => lo = mid,
        }
        k += 1;
    }
    // A loop certified stable whose bound rounds up to 1 (within a few ε of marginal) is
    // refused: the bound is promised below 1 (found by the control fuzz target).
    if best < 1.0 { Some(best) } else { None }
}

/// `D⁻¹ a D` for `D = diag(d)` of powers of two, or `None` if an entry does not scale
/// exactly (a result that is not finite, or subnormal and rounded). Cost: `2 N²` flops.
const fn similar<const N: usize>(a: &Mat<N, N>, d: &[f64; N]) -> Option<Mat<N, N>> {
    let mut b = *a;
    let mut i = 0;
    while i < N {
        let mut j = 0;
        while j < N {
            let p = d[j] / d[i];
            let x = a[i][j] * p;
            if !(p.is_finite() && p > 0.0 && x.is_finite() && (x.is_normal() || x / p == a[i][j])) {
                return None;
            }
            b[i][j] = x;
            j += 1;
        }
        i += 1;
    }
    Some(b)
}

/// `β ρ_c`, `ρ_c` a certified bound below 1 on the spectral radius of `T/β`, where
/// `|T − b| ≤ f` entrywise (`b` the balanced closed loop, `f` its formation bound), or
/// `None`. With `Ã = fl(b/β)` and `F = f/β`: `Ãᵀ X Ã − X = −I` solved by doubling, `X`
/// positive definite with margin (a Cholesky factorization of `X − δI`,
/// `δ = 2(N+1)² ε ‖X‖∞`), the residual `E = Ãᵀ X Ã − X + I` bounded with the rounding of
/// its evaluation and of `Ã` itself (`(2N + 7) ε ‖|Ã|ᵀ|X||Ã| + |X| + I‖_F`) and with the
/// difference `T/β − Ã`'s share (`‖Fᵀ|X|(|Ã| + F)‖_F + ‖|Ã|ᵀ|X|F‖_F`): `e`. Then every
/// eigenvalue of `T/β` has `|λ|² ≤ 1 − (1 − e)/‖X‖∞`. Cost: about `3 N³` flops a squaring
/// (`log₂(20/(1 − ρ/β))` of them) and `10 N³` more.
const fn lyapunov_bound<const N: usize>(b: &Mat<N, N>, f: &Mat<N, N>, beta: f64) -> Option<f64> {
    let a = scaled(1.0 / beta, b);
    let at = transpose(&a);
    let id: Mat<N, N> = identity();
    // X = Ãᵀ X Ã + I.
    let x = match stein(&at, &id) {
        Some(x) => symmetrize(&x),
        None => return None,
    };
    let eps = f64::EPSILON;
    let xn = inf_norm(&x);
    if !(xn.is_finite() && xn > 0.0) {
        return None;
    }
    let mut shifted = x;
    let delta = 2.0 * ((N + 1) * (N + 1)) as f64 * eps * xn;
    let mut i = 0;
    while i < N {
        shifted[i][i] -= delta;
        i += 1;
    }
    if cholesky(&shifted).is_none() {
        return None;
    }
    let e = add_scaled(&add_scaled(&mul(&at, &mul(&x, &a)), -1.0, &x), 1.0, &id);
    let (aa, xa) = (abs_of(&a), abs_of(&x));
    let size = add_scaled(
        &add_scaled(&mul(&transpose(&aa), &mul(&xa, &aa)), 1.0, &xa),
        1.0,
        &id,
    );
    // The formation's share: (Ã + Δ)ᵀ X (Ã + Δ) − Ãᵀ X Ã, |Δ| ≤ F.
    let fs = scaled(1.0 / beta, f);
    let fx = mul(&transpose(&fs), &xa);
    let formation = frobenius(&mul(&fx, &add_scaled(&aa, 1.0, &fs))) + frobenius(&mul(&fx, &aa));
    let unit = (2 * N + 7) as f64 * eps;
    let bound = (frobenius(&e) + unit * frobenius(&size) + formation)
        * (1.0 + 4.0 * ((N * N + 2) as f64) * eps);
    if bound.is_nan() || bound >= 1.0 {
        return None;
    }
    // |λ|² ≤ 1 − (1 − e)/λ_max(X), λ_max(X) ≤ ‖X‖∞ (rounded up by its own sum's error).
    let lmax = xn * (1.0 + (N + 2) as f64 * eps);
    let r2 = (1.0 - (1.0 - bound) / lmax) + 4.0 * eps;
    let rho = if r2 > 0.0 {
        sqrt(r2) * (1.0 + 2.0 * eps)
    } else {
        sqrt(4.0 * eps)
    };
    if rho < 1.0 {
        Some(beta * rho * (1.0 + 2.0 * eps))
    } else {
        None
    }
}

/// The Frobenius norm (NaN-propagating).
const fn frobenius<const N: usize>(a: &Mat<N, N>) -> f64 {
    let mut s = 0.0;
    let mut i = 0;
    while i < N {
        let mut j = 0;
        while j < N {
            s += a[i][j] * a[i][j];
            j += 1;
        }
        i += 1;
    }
    sqrt(s)
}
