//! Bouc–Wen smooth hysteresis, its internal variable integrated by the trapezoidal rule in
//! the deformation.

use nalgebra::ComplexField;

use super::{Law, LawTrial, fits, positive, unit_ratio};
use crate::{Error, Real};

/// Iterations allowed for the internal variable of one trial: Newton, with bisection steps
/// where it leaves its bracket or crawls (a bracket of width `|Δ|/u_y` halves to rounding
/// within about 120 of them).
const MAX_ITERATIONS: u32 = 200;

/// Bouc–Wen hysteresis: `f = α k d + (1 − α) f_y z`, with the dimensionless hysteretic
/// variable `z` governed (rate-independently, `A = 1`) by
///
/// ```text
/// dz/dd = g(z, sgn ḋ) / u_y,   g(z, s) = 1 − |z|ⁿ (β sgn(s z) + γ),   u_y = f_y / k
/// ```
///
/// so the initial stiffness is `k`, the post-yield stiffness tends to `α k`, and `z` tends
/// to `z_max = (β + γ)^{−1/n}` under monotonic loading (`1` for `β + γ = 1`, when `f_y` is
/// the force at which the hysteretic part saturates).
///
/// **Integration over a step** (deformation `d₀ → d`, `Δ = d − d₀`, `s = sgn Δ`): the
/// trapezoidal rule in the deformation,
///
/// ```text
/// z = z₀ + (Δ / 2u_y) (g(z₀, s) + g(z, s)),
/// ```
///
/// second order in `Δ` and so in the time step, solved for `z` by a scalar Newton from the
/// explicit Euler predictor (converged to `4ε` relative). Its residual has slope `≥ 1` in
/// `z` whenever `|γ| ≤ β` (required), so the root is unique; it lies between `z₀` and the
/// predictor (`g` is monotone in `z`), and an iterate that leaves that bracket, or a Newton
/// step that does not halve, is replaced by bisection, so the solve converges for any
/// exponent and step.
/// The consistent tangent is the exact derivative of that update,
///
/// ```text
/// ∂f/∂d = α k + (1 − α) k (g(z₀, s) + g(z, s)) / (2 (1 − (Δ/2u_y) ∂g/∂z (z, s))).
/// ```
///
/// **Cost per trial**: a few Newton iterations of ~15 flops (`n = 1` or `2`; otherwise two
/// `powf` each; at most 200 with bisection steps); no panic. A trial whose solve does not
/// converge (not seen: the bracket of width `|Δ|/u_y` halves to rounding within the budget)
/// or whose data is not finite returns a NaN force, which the stepper reports as
/// [`Error::NonFiniteForce`] without taking the step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoucWen<T> {
    ak: T,
    cz: T,
    inv_uy: T,
    half_inv_uy: T,
    beta: T,
    gamma: T,
    n: T,
    /// `1` or `2` for the exponents computed without `powf`, else `0`.
    n_kind: u8,
    /// `min(1, z_max)`, `z_max = (β + γ)^{−1/n}`: the scale of `z` the inner solve's
    /// tolerance is relative to.
    z_scale: T,
}

/// The history of a [`BoucWen`] law: the committed deformation and hysteretic variable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoucWenHistory<T> {
    /// Deformation `d` at the end of the last accepted step.
    pub deformation: T,
    /// Hysteretic variable `z` (dimensionless, `|z| ≤ z_max`).
    pub z: T,
}

impl<T: Real> BoucWen<T> {
    /// A Bouc–Wen law with initial stiffness `k` (force/deformation, finite, `> 0`), yield
    /// force `fy` (finite, `> 0`), post-yield ratio `alpha` (finite, in `[0, 1)`), shape
    /// parameters `beta` (finite, `> 0`) and `gamma` (finite, `|γ| ≤ β`), and exponent `n`
    /// (finite, `≥ 1`; `1` and `2` avoid `powf`). A common choice is `β = γ = 1/2`, `n = 1`
    /// (unloading is then linear with stiffness `k`).
    ///
    /// Errors: [`Error::InvalidMaterial`] for any parameter out of its range or not finite;
    /// [`Error::OperatorOverflow`] if a coefficient does not fit `T`. Cost: O(1).
    pub fn new(k: f64, fy: f64, alpha: f64, beta: f64, gamma: f64, n: f64) -> Result<Self, Error> {
        if !(positive(k)
            && positive(fy)
            && unit_ratio(alpha)
            && positive(beta)
            && gamma.is_finite()
            && gamma.abs() <= beta
            && n.is_finite()
            && n >= 1.0)
        {
            return Err(Error::InvalidMaterial);
        }
        let c = [
            alpha * k,
            (1.0 - alpha) * fy,
            k / fy,
            0.5 * k / fy,
            beta,
            gamma,
            n,
        ];
        fits::<T>(&c)?;
        // z lives on the scale of z_max (tiny for a huge β + γ: a tolerance of 4ε in
        // absolute terms stopped at z = 3e-16 where z_max = 6e-48; found by fuzzing). Kept
        // a normal number of `T` (above 1e-37 in f32, 1e-300 in f64).
        let z_max = if beta + gamma > 0.0 {
            <f64 as ComplexField>::powf(beta + gamma, -1.0 / n)
        } else {
            f64::INFINITY
        };
        let floor = if T::MAX < f64::MAX { 1e-37 } else { 1e-300 };
        let z_scale = T::from_f64_rounded(z_max.min(1.0).max(floor));
        let r = T::from_f64_rounded;
        Ok(Self {
            ak: r(c[0]),
            cz: r(c[1]),
            inv_uy: r(c[2]),
            half_inv_uy: r(c[3]),
            beta: r(c[4]),
            gamma: r(c[5]),
            n: r(c[6]),
            n_kind: if n == 1.0 {
                1
            } else if n == 2.0 {
                2
            } else {
                0
            },
            z_scale,
        })
    }

    /// `(g(z, s), ∂g/∂z)`.
    #[inline]
    fn g(&self, z: T, s: T) -> (T, T) {
        let a = z.abs();
        let (an1, an) = match self.n_kind {
            1 => (T::one(), a),
            2 => (a, a * a),
            _ => {
                let an1 = if a > T::zero() {
                    a.powf(self.n - T::one())
                } else {
                    T::zero()
                };
                (an1, an1 * a)
            }
        };
        let shape = if s * z > T::zero() {
            self.beta + self.gamma
        } else {
            self.gamma - self.beta
        };
        let sz = if z > T::zero() {
            T::one()
        } else if z < T::zero() {
            -T::one()
        } else {
            T::zero()
        };
        // |z|ⁿ · 0 is 0 even where |z|ⁿ overflows (γ = β makes the unloading shape 0; an
        // ∞ · 0 there gave a NaN slope, found by fuzzing).
        if shape == T::zero() {
            return (T::one(), T::zero());
        }
        (T::one() - an * shape, -self.n * an1 * sz * shape)
    }
}

impl<T: Real> Law<T> for BoucWen<T> {
    type History = BoucWenHistory<T>;

    fn initial_history(&self) -> BoucWenHistory<T> {
        BoucWenHistory {
            deformation: T::zero(),
            z: T::zero(),
        }
    }

    fn trial(&self, committed: &BoucWenHistory<T>, d: T, rate: T) -> LawTrial<T, Self::History> {
        let (d0, z0) = (committed.deformation, committed.z);
        let delta = d - d0;
        let one = T::one();
        // Direction of the step (of the rate when the step has not moved yet).
        let s = if delta > T::zero() || (delta == T::zero() && rate >= T::zero()) {
            one
        } else {
            -one
        };
        let (g0, _) = self.g(z0, s);
        let (z, dz_dd) = if delta == T::zero() {
            (z0, g0 * self.inv_uy)
        } else {
            let c = delta * self.half_inv_uy;
            let tol = T::from_f64_rounded(4.0) * T::default_epsilon();
            let half = T::from_f64_rounded(0.5);
            let mut z = z0 + (c + c) * g0;
            // The root lies between z0 and the predictor (g is monotone in z, against the
            // step's direction, so the residual changes sign between them): Newton safeguarded
            // by bisection on that bracket. (Unsafeguarded, a large exponent n sent an iterate
            // to |z|ⁿ = ∞ and the force to NaN at Δ = 3 u_y; found by fuzzing.)
            // Bisection also where Newton crawls (steps not halving: with n ≈ 950 each
            // Newton step from above shrinks z by only a factor 1 − 1/n), as `rtsafe`.
            let (mut lo, mut hi) = if z < z0 { (z, z0) } else { (z0, z) };
            let mut last = hi - lo;
            let mut converged = false;
            for _ in 0..MAX_ITERATIONS {
                let (g, dg) = self.g(z, s);
                let r = z - z0 - c * (g0 + g);
                if r > T::zero() {
                    hi = z;
                } else {
                    lo = z;
                }
                // (A slope that overflows is no Newton step: r/∞ = 0 looked converged; found
                // by fuzzing with n = 984 in f32.)
                let slope = one - c * dg;
                let step = r / slope;
                let next = z - step;
                if slope.is_finite() && next >= lo && next <= hi && (step + step).abs() <= last {
                    last = step.abs();
                    z = next;
                    if last <= tol * z.abs().max(self.z_scale) {
                        converged = true;
                        break;
                    }
                } else {
                    last = half * (hi - lo);
                    z = lo + last;
                }
                if hi - lo <= tol * lo.abs().max(hi.abs()).max(self.z_scale) {
                    converged = true;
                    break;
                }
            }
            if !converged {
                z = T::from_f64_rounded(f64::NAN);
            }
            let (g, dg) = self.g(z, s);
            (z, (g0 + g) * self.half_inv_uy / (one - c * dg))
        };
        LawTrial {
            force: self.ak * d + self.cz * z,
            stiffness: self.ak + self.cz * dz_dd,
            damping: T::zero(),
            history: BoucWenHistory { deformation: d, z },
            inelastic: s * z > T::zero(),
        }
    }

    /// `α k d²/2 + (1 − α) f_y u_y z²/2`.
    fn recoverable_energy(&self, history: &BoucWenHistory<T>, d: T) -> T {
        let half = T::from_f64_rounded(0.5);
        half * (self.ak * d * d + self.cz * history.z * history.z / self.inv_uy)
    }
}
