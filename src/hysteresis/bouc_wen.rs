//! Bouc–Wen smooth hysteresis, its internal variable integrated by the trapezoidal rule in
//! the deformation.

use nalgebra::ComplexField;

use super::{Law, LawTrial, check_elastic_plastic, fits, positive, rounded};
use crate::{Error, Param, Real};

/// Iterations allowed for the internal variable of one trial: Newton, with bisection steps
/// where it leaves its bracket or crawls, and every other iteration from [`FREE_NEWTON`]
/// on. A bisection halves the count of floating-point numbers in the bracket, so the solve
/// ends within `FREE_NEWTON + 2·64 = 136` iterations for any bracket (in `f64`).
const MAX_ITERATIONS: u32 = 200;

/// Iterations of unforced Newton (safeguarded) before every other iteration bisects: a
/// Newton solve from the predictor converges within a few; one that has not by then is
/// crawling or cycling inside its bracket.
const FREE_NEWTON: u32 = 8;

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
/// step that does not halve, is replaced by bisection (in the ordering of the numbers, so
/// at any scale within 64 halvings), so the solve converges for any exponent and step.
/// `g` is evaluated in `w = (β + |γ|)^{1/n} |z|`, about 1 at saturation whatever `β`, `γ`
/// and `n`. For `γ < β` (unloading steeper than elastic, `g = 1 + (β − γ)|z|ⁿ`) a step that
/// carries `z` from the unloading branch through 0 is split there, the rule applied on each
/// smooth piece, and a loading slope below `−1` (`|z|` beyond `2^{1/n} z_max`: by rounding,
/// or a history set there) is taken as `−1`, its value at that bound; then `|z|` never
/// exceeds `max(|z₀|, 2^{1/n} z_max)` for `β + γ > 0`, under any path. (Unsplit, cyclic
/// steps of about `u_y` grew `z` without bound for `γ < 0`, and huge steps for
/// `0 ≤ γ < β` left `z` beyond the bound; with a slope below `−1` a huge step has no
/// bounded root, and `z` overflowed two steps later.) For `γ = −β`, `z` does
/// not saturate (`g = 1` on loading), and the unloading slope `1 + 2β |z|ⁿ` can leave
/// `T`: then the force or tangent is not finite and the stepper reports
/// [`Error::NonFiniteForce`].
/// The consistent tangent is the exact derivative of that update,
///
/// ```text
/// ∂f/∂d = α k + (1 − α) k (g(z₀, s) + g(z, s)) / (2 (1 − (Δ/2u_y) ∂g/∂z (z, s))).
/// ```
///
/// **Cost per trial**: a few Newton iterations of ~15 flops (`n = 1` or `2`; otherwise two
/// `powf` each; at most 136 with bisection steps; for a huge exponent, `n ε > 1e-3`, the
/// bracket is bisected to two neighbouring numbers); no panic. A trial whose
/// data is not finite, or whose `z` is beyond `T`, returns a non-finite force, which the
/// stepper reports as [`Error::NonFiniteForce`] without taking the step.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoucWen<T> {
    ak: T,
    cz: T,
    /// `(1 − α) k`: the hysteretic part's stiffness, `cz / u_y`.
    ck: T,
    inv_uy: T,
    half_inv_uy: T,
    /// `κ = (β + |γ|)^{1/n}`: `g` is evaluated in `w = κ |z|`, so that `|z|ⁿ (β ± γ) =
    /// wⁿ σ±` with `|σ±| ≤ 1`; `wⁿ` is about 1 where `z` saturates, however large or
    /// small `β` and `n` are (`|z|ⁿ` alone overflowed at `n = 950`, `z = 2.1`).
    kappa: T,
    /// `σ₊ = (β + γ)/(β + |γ|)` (loading, `s z > 0`), in `[0, 1]`.
    sigma_load: T,
    /// `σ₋ = (γ − β)/(β + |γ|)` (unloading), in `[−1, 0]`.
    sigma_unload: T,
    /// `γ < β`: steps from the unloading branch are split where `z` crosses 0.
    split_at_zero: bool,
    n: T,
    /// `1` or `2` for the exponents computed without `powf`, else `0`.
    n_kind: u8,
    /// `min(1, z_max)`, `z_max = (β + γ)^{−1/n}`: the scale of `z` the inner solve's
    /// tolerance is relative to.
    z_scale: T,
}

/// The history of a [`BoucWen`] law: the committed deformation and hysteretic variable.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoucWenHistory<T> {
    /// Deformation `d` at the end of the last accepted step.
    pub deformation: T,
    /// Hysteretic variable `z` (dimensionless; within `2^{1/n} z_max` when `β + γ > 0`).
    pub z: T,
}

/// Virgin: as `BoucWenHistory::at_rest_f32`/`at_rest_f64`, for any `T`.
impl<T: Real> Default for BoucWenHistory<T> {
    fn default() -> Self {
        Self {
            deformation: T::zero(),
            z: T::zero(),
        }
    }
}

macro_rules! bouc_wen_history_at_rest {
    ($t:ident, $at_rest:ident) => {
        impl BoucWenHistory<$t> {
            /// The virgin history, `d = 0`, `z = 0`: `const fn`, for a `static`; equal to
            /// `BoucWenHistory::default()` and to the law's [`Law::initial_history`].
            /// Cost: none.
            pub const fn $at_rest() -> Self {
                Self {
                    deformation: 0.0,
                    z: 0.0,
                }
            }
        }
    };
}
bouc_wen_history_at_rest!(f32, at_rest_f32);
bouc_wen_history_at_rest!(f64, at_rest_f64);

impl<T: Real> BoucWen<T> {
    /// A Bouc–Wen law with initial stiffness `k` (force/deformation, finite, `> 0`), yield
    /// force `fy` (finite, `> 0`), post-yield ratio `alpha` (finite, in `[0, 1)`), shape
    /// parameters `beta` (finite, `> 0`) and `gamma` (finite, `|γ| ≤ β`), and exponent `n`
    /// (finite, `≥ 1`; `1` and `2` avoid `powf`). A common choice is `β = γ = 1/2`, `n = 1`
    /// (unloading is then linear with stiffness `k`).
    ///
    /// Errors: [`Error::InvalidMaterial`] for any parameter out of its range or not finite;
    /// [`Error::OperatorOverflow`] if a coefficient does not fit `T`, or if the largest
    /// hysteretic force the law can produce, `(1 − α) f_y 2^{1/n} z_max` (for `β + γ > 0`),
    /// does not (e.g. `f_y = f64::MAX`, `β = 1`, `γ = 1/2`, `n = 1`: `1.33 f_y`). Cost: O(1).
    pub fn new(k: f64, fy: f64, alpha: f64, beta: f64, gamma: f64, n: f64) -> Result<Self, Error> {
        check_elastic_plastic(k, fy, alpha)?;
        if !(positive(beta)
            && gamma.is_finite()
            && gamma.abs() <= beta
            && n.is_finite()
            && n >= 1.0)
        {
            return Err(Error::InvalidMaterial(Param::BoucWenShape));
        }
        // β + |γ| ≤ 2β may overflow f64: then halved (the ratios are the same, κ gains
        // the factor 2^{1/n}).
        let (m, kappa) = if (beta + gamma.abs()).is_finite() {
            let m = beta + gamma.abs();
            (m, <f64 as ComplexField>::powf(m, 1.0 / n))
        } else {
            let m = 0.5 * beta + 0.5 * gamma.abs();
            let two = <f64 as ComplexField>::powf(2.0, 1.0 / n);
            (m, <f64 as ComplexField>::powf(m, 1.0 / n) * two)
        };
        let half = if (beta + gamma.abs()).is_finite() {
            1.0
        } else {
            0.5
        };
        let c = rounded::<T, 9>([
            alpha * k,
            (1.0 - alpha) * fy,
            (1.0 - alpha) * k,
            k / fy,
            0.5 * k / fy,
            kappa,
            (half * beta + half * gamma) / m,
            (half * gamma - half * beta) / m,
            n,
        ])?;
        // The largest hysteretic force the law can produce, `(1 − α) f_y |z|` with `|z|`
        // within `2^{1/n} z_max` (β + γ > 0; for γ = −β, `z` does not saturate and the
        // stepper reports the force that leaves `T`): it must fit `T` too, else a step
        // whose `z` nears saturation has an infinite force (found by fuzzing: f_y =
        // f64::MAX, α = 1.8e-3, β = 1, γ = 0.5, n = 1, force ≈ 1.33 f64::MAX).
        if beta + gamma > 0.0 {
            fits::<T>(&[hysteretic_force_bound(alpha, fy, beta + gamma, n)])?;
        }
        // z lives on the scale of z_max (tiny for a huge β + γ: a tolerance of 4ε in
        // absolute terms stopped at z = 3e-16 where z_max = 6e-48; found by fuzzing). Kept
        // a normal number of `T` (at least its `MIN_POSITIVE`), so `4ε z_scale` is not zero;
        // the bisection in the ordering of the numbers reaches any scale within its budget.
        let z_max = if beta + gamma > 0.0 {
            <f64 as ComplexField>::powf(beta + gamma, -1.0 / n)
        } else {
            f64::INFINITY
        };
        let floor = if T::MAX < f64::MAX {
            f64::from(f32::MIN_POSITIVE)
        } else {
            f64::MIN_POSITIVE
        };
        let z_scale = T::from_f64_rounded(z_max.min(1.0).max(floor));
        Ok(Self {
            ak: c[0],
            cz: c[1],
            ck: c[2],
            inv_uy: c[3],
            half_inv_uy: c[4],
            kappa: c[5],
            sigma_load: c[6],
            sigma_unload: c[7],
            n: c[8],
            split_at_zero: gamma < beta,
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

    /// `(g(z, s), ∂g/∂z)`, evaluated in `w = κ |z|`: `g = 1 − wⁿ σ±`,
    /// `∂g/∂z = −n wⁿ⁻¹ sgn(z) σ± κ`.
    #[inline]
    fn g(&self, z: T, s: T) -> (T, T) {
        let sigma = if s * z > T::zero() {
            self.sigma_load
        } else {
            self.sigma_unload
        };
        // wⁿ · 0 is 0 even where wⁿ overflows (γ = β makes the unloading shape 0; an
        // ∞ · 0 there gave a NaN slope, found by fuzzing).
        if sigma == T::zero() {
            return (T::one(), T::zero());
        }
        let a = z.abs() * self.kappa;
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
        let sz = if z > T::zero() {
            T::one()
        } else if z < T::zero() {
            -T::one()
        } else {
            T::zero()
        };
        (
            T::one() - an * sigma,
            -self.n * an1 * sz * sigma * self.kappa,
        )
    }

    /// The trapezoidal update's `z` and `u_y dz/dd` for a step with `c = Δ/(2u_y) ≠ 0` from
    /// `z₀` (`g₀ = g(z₀, s)`): the root of `r(z) = z − z₀ − c (g₀ + g(z))`, which has slope
    /// `1 − c ∂g/∂z ≥ 1` and lies between `z₀` and the predictor `z₀ + 2c g₀`.
    ///
    /// Newton, safeguarded by bisection on that bracket (`rtsafe`): a Newton iterate that
    /// leaves the bracket, or a step that does not halve, is replaced by a bisection step,
    /// and from iteration [`FREE_NEWTON`] on every other iteration bisects. The bisection
    /// halves the bracket in the *ordering* of the floating-point numbers (the midpoint of
    /// their bit patterns read as integers), not in value: within one binade that is the
    /// arithmetic midpoint, across binades it halves the exponent range, so any bracket —
    /// `[0, 3]` around a root of `1e-100`, or one end at `±∞` — is down to two adjacent
    /// numbers within 64 bisections in `f64` (32 in `f32`), and the solve ends within
    /// `FREE_NEWTON + 2·64` iterations. (A value bisection needed about 380 halvings to go
    /// from `3` to a root of `1e-100` to `4ε`, beyond the budget of 200, and the force was
    /// NaN; found by fuzzing with `β = 8.5e199`.)
    ///
    /// For `|c| > 1` the residual is divided by `|c|` — `(z − z₀)/|c| − sgn c (g₀ + g(z))`,
    /// the same sign — so that a step of `c = ±∞` (a deformation increment or `Δ/u_y` beyond
    /// `T`) solves its limit `g(z) = −g₀` instead of `∞ − ∞`. A root beyond the largest
    /// finite number is `±∞` (the force is then not finite and the stepper reports
    /// [`Error::NonFiniteForce`]); a NaN `c` or residual gives NaN.
    #[inline]
    fn solve(&self, z0: T, g0: T, c: T, s: T) -> (T, T) {
        let zero = T::zero();
        let one = T::one();
        let nan = T::from_f64_rounded(f64::NAN);
        if g0 == zero {
            // r(z₀) = 0: z₀ is the root (saturated exactly).
            return (z0, zero);
        }
        if c.as_f64().is_nan() || g0.as_f64().is_nan() || z0.as_f64().is_nan() {
            return (nan, nan);
        }
        let big = c.abs() > one;
        // r/|c| = a z − a z₀ − b (g₀ + g) for |c| > 1.
        let (a, b) = if big {
            (one / c.abs(), if c > zero { one } else { -one })
        } else {
            (one, c)
        };
        let residual = |z: T, g: T| {
            if big {
                a * z - a * z0 - b * (g0 + g)
            } else {
                z - z0 - c * (g0 + g)
            }
        };
        let tol = T::from_f64_rounded(4.0) * T::default_epsilon();
        let zp = z0 + (c + c) * g0;
        if zp.as_f64().is_nan() {
            return (nan, nan);
        }
        let (mut lo, mut hi) = if zp < z0 { (zp, z0) } else { (z0, zp) };
        let mut z = if zp.is_finite() { zp } else { midpoint(lo, hi) };
        let mut last = hi - lo;
        let mut converged = false;
        // With a huge exponent (one ulp of z changes wⁿ by more than 0.1 %: n ε > 1e-3), g
        // changes by a factor e^(n δ) over a relative δ of z, and a z within 4ε of the
        // root could have g = −3e209 where the root has g ≈ −1; committed, that g₀ sent the
        // next step's z to the other side (n = 7e17, found by fuzzing), and Newton's step
        // there, r/r′ ≈ z/n, looks converged 34 numbers away from the root (n = 6.8e15).
        // There the bracket is bisected down to two neighbouring numbers, and z is the one
        // with the smaller residual.
        let exact = self.n * T::default_epsilon() > T::from_f64_rounded(1e-3);
        for i in 0..MAX_ITERATIONS {
            let (g, dg) = self.g(z, s);
            let r = residual(z, g);
            if r > zero {
                hi = z;
            } else if r <= zero {
                lo = z;
            } else {
                break; // NaN
            }
            // (A slope that overflows is no Newton step: r/∞ = 0 looked converged; found
            // by fuzzing with n = 984 in f32.)
            let slope = if big { a - b * dg } else { one - c * dg };
            let step = r / slope;
            let next = z - step;
            let bisect = i >= FREE_NEWTON && (i - FREE_NEWTON) % 2 == 1;
            if !bisect
                && slope.is_finite()
                && slope > zero
                && next >= lo
                && next <= hi
                && (step + step).abs() <= last
            {
                last = step.abs();
                z = next;
                if !exact && last <= tol * z.abs().max(self.z_scale) {
                    converged = true;
                    break;
                }
            } else {
                let m = midpoint(lo, hi);
                last = (m - z).abs();
                z = m;
            }
            let finite = lo.is_finite() && hi.is_finite();
            if (!exact && finite && hi - lo <= tol * lo.abs().max(hi.abs()).max(self.z_scale))
                || key(hi).wrapping_sub(key(lo)) as u64 <= 1
            {
                converged = true;
                // A bracket [MAX, ∞]: the root is beyond the finite numbers.
                if !finite {
                    z = if lo.is_finite() { hi } else { lo };
                }
                break;
            }
        }
        if !converged {
            return (nan, nan);
        }
        let (mut g, mut dg) = self.g(z, s);
        let near = tol * z.abs().max(self.z_scale);
        if exact && lo.is_finite() && hi.is_finite() {
            // The bracket is two neighbouring numbers: the one with the smaller residual.
            let (gl, dgl) = self.g(lo, s);
            let (gh, dgh) = self.g(hi, s);
            (z, g, dg) = if residual(lo, gl).abs() <= residual(hi, gh).abs() {
                (lo, gl, dgl)
            } else {
                (hi, gh, dgh)
            };
        }
        if !(g.is_finite() && dg.is_finite()) && z.is_finite() {
            // With a huge exponent g jumps from 0 to −∞ within one ulp of z_max (n = 8e83:
            // wⁿ overflows at w = 1 + 2ε), and a z converged there had a NaN tangent (found
            // by fuzzing): take the nearest number within the tolerance where g is finite
            // (the root is as well resolved there, and the next step's g₀ is finite).
            let k = key(z);
            for e in [from_key::<T>(k - 1), from_key::<T>(k + 1), lo, hi] {
                let (ge, dge) = self.g(e, s);
                if ge.is_finite() && dge.is_finite() && (e - z).abs() <= near + near {
                    (z, g, dg) = (e, ge, dge);
                    break;
                }
            }
        }
        // u_y dz/dd = (g₀ + g)/(2 (1 − c ∂g/∂z)), for |c| > 1 with numerator and
        // denominator divided by |c| (at c = ±∞ the root has g = −g₀ and the increment does
        // not move z). In units of 1/u_y, which is not formed: with n = 2.9e17, z within
        // its tolerance of saturation has g ≈ −1e250, the denominator is as large, and
        // (g₀ + g)/(2u_y) was −∞ at u_y = 8e-265 (found by fuzzing).
        let (num, den) = if big {
            ((g0 + g) * a, a - b * dg)
        } else {
            (g0 + g, one - c * dg)
        };
        let half = T::from_f64_rounded(0.5);
        let slope = if num == zero { zero } else { num * half / den };
        (z, slope)
    }
}

/// `(1 − α) f_y 2^{1/n} z_max`, `z_max = (β + γ)^{−1/n}` (`bg = β + γ > 0`): the largest
/// `|(1 − α) f_y z|` along any path from the virgin history. `(2/bg)^{1/n}` directly where
/// `2/bg` is finite (exact to rounding); else (`bg < 1.1e-308`) through logarithms, `∞`
/// where it overflows `f64`.
fn hysteretic_force_bound(alpha: f64, fy: f64, bg: f64, n: f64) -> f64 {
    let ratio = 2.0 / bg;
    if ratio.is_finite() {
        (1.0 - alpha) * fy * <f64 as ComplexField>::powf(ratio, 1.0 / n)
    } else {
        let ln = <f64 as ComplexField>::ln;
        <f64 as ComplexField>::exp(ln((1.0 - alpha) * fy) + (ln(2.0) - ln(bg)) / n)
    }
}

/// `x`'s place in the ordering of the numbers of `T`: an integer, increasing with `x`,
/// consecutive for adjacent numbers (`±0` are both `0`; `±∞` are one past `±MAX`). The
/// sign-magnitude bit pattern made two's complement. (Not called with NaN.)
#[inline]
fn key<T: Real>(x: T) -> i64 {
    if T::MAX < f64::MAX {
        let b = (x.as_f64() as f32).to_bits();
        let m = i64::from(b & 0x7fff_ffff);
        if b >> 31 == 1 { -m } else { m }
    } else {
        let b = x.as_f64().to_bits();
        let m = (b & 0x7fff_ffff_ffff_ffff) as i64;
        if b >> 63 == 1 { -m } else { m }
    }
}

/// The number of `T` whose [`key`] is `k` (the inverse of `key`, `+0` for `0`).
#[inline]
fn from_key<T: Real>(k: i64) -> T {
    let m = k.unsigned_abs();
    let x = if T::MAX < f64::MAX {
        let b = (m as u32) | if k < 0 { 1 << 31 } else { 0 };
        f64::from(f32::from_bits(b))
    } else {
        f64::from_bits(m | if k < 0 { 1 << 63 } else { 0 })
    };
    T::from_f64_rounded(x)
}

/// The midpoint of `[lo, hi]` in the ordering of the numbers (`lo ≤ hi`, not NaN): the
/// number halfway by [`key`] (rounded down), so a bisection halves the count of numbers
/// in the bracket.
#[inline]
fn midpoint<T: Real>(lo: T, hi: T) -> T {
    let (a, b) = (key(lo), key(hi));
    from_key((a >> 1) + (b >> 1) + (a & b & 1))
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
        // The loading slope is at least −1 within |z| ≤ 2^{1/n} z_max, where every step
        // keeps z; below −1 only by rounding (κ |z| one ulp beyond its bound) or from a
        // history set beyond it. There a step of c = Δ/2u_y has no bounded root: g(z)
        // stays ≤ 1, so the trapezoidal rule's z − z₀ = c (g₀ + g) ≈ −c (g₀ + 1) grew with
        // c (g₀ = −1 − 4e-16 and c = 2e142 gave z = −1e127, the next step z = −∞; found
        // by fuzzing). The slope is taken as −1, its value at the bound: the root is then
        // between 0 and z₀.
        let g0 = if g0 < -one { -one } else { g0 };
        let c = delta * self.half_inv_uy;
        // A step whose Δ/2u_y underflows to 0 does not move z either: its tangent is the
        // limit g₀/u_y. (Solved, 1 − c ∂g/∂z was 1 − 0·∞ = NaN where ∂g/∂z overflows:
        // Δ = 2.8e-44 at u_y = 1.2e6 in f32, with κ = 2e38 for β = 8e229; found by fuzzing.)
        // The slope is kept in units of 1/u_y (`slope = u_y dz/dd`) and the tangent is
        // α k + (1 − α) k · slope: g₀/u_y alone was ∞ at u_y = 1.1e-308, g₀ = 2.3, where the
        // tangent is 2.4e3 (found by fuzzing).
        let (z, slope) = if c == T::zero() {
            (z0, g0)
        } else {
            // γ < β: a step from the unloading branch that carries z through 0 is split
            // there (the trapezoidal rule on each smooth piece). Unsplit, its explicit half
            // took the unloading slope g₀ = 1 + ρ wⁿ (ρ = (β − γ)/(β + γ) > 0) over the
            // whole step and overshot on the other side to wⁿσ₊ = 2 + ρ wⁿσ₊(z₀), past the
            // bound 2: for γ < 0 (ρ > 1) cyclic steps of a few u_y grew z without bound to a
            // force of ∞ (found by testing the fuzz finding's neighbourhood); for γ ≥ 0
            // huge steps left z beyond the bound, with a loading slope below −1 (found by
            // testing the fuzz finding of the clamp above). Split, z stays within
            // max(|z₀|, 2^{1/n} z_max).
            // (c* = −z₀/(g₀ + 1): the increment that brings z₀ to 0, where g = 1.)
            let c_zero = -z0 / (g0 + one);
            if self.split_at_zero && s * z0 < T::zero() && c.abs() > c_zero.abs() {
                self.solve(T::zero(), one, c - c_zero, s)
            } else {
                self.solve(z0, g0, c, s)
            }
        };
        LawTrial {
            force: self.ak * d + self.cz * z,
            stiffness: self.ak + self.ck * slope,
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
