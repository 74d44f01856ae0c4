//! Semi-active laws: the command voltage of magnetorheological (MR) dampers from the
//! force each damper measurably delivers.
//!
//! A semi-active device cannot push: it only resists motion, more or less. Each law here
//! turns what the sensors give (the measured damper forces `f`, and a desired force, a
//! state estimate or the damper deformations) into an on/off command `v ∈ {0, V_max}` per
//! damper:
//!
//! - [`ClippedOptimal`]: Dyke, Spencer, Sain & Carlson (1996), *Modeling and control of
//!   magnetorheological dampers for seismic response reduction*, Smart Mater. Struct. 5:
//!   `v_i = V_max H((f_ci − f_i) f_i)`, with `f_c` the optimal (e.g. H2/LQG) force;
//! - [`Lyapunov`]: the Lyapunov law as Jansen & Dyke (2000), *Semiactive control strategies
//!   for MR dampers: comparative study*, J. Eng. Mech. 126(8), state it after McClamroch &
//!   Gavin (1995): `v_i = V_max H(−zᵀ P B_i f_i)`;
//! - [`ModulatedFriction`]: modulated homogeneous friction (Inaudi 1997, in the form of
//!   Jansen & Dyke 2000): `v_i = V_max H(f_ci − |f_i|)`, `f_ci = g_n |P[Δ_i]|`, `P[·]` the
//!   most recent local extremum of damper `i`'s deformation `Δ_i`.
//!
//! `H` is the Heaviside step, taken here as **strict**: `H(x) = 1` for `x > 0`, `0` for
//! `x ≤ 0` (NaN is refused before). So a law whose argument is exactly zero (a damper
//! force `f_i = 0`, a measured force equal to the desired one, a zero state) commands
//! 0 V: the damper is only switched on when the rule's condition holds strictly. Every
//! law decides by the *sign* of its argument, computed from the signs of the factors (not
//! by forming a product that could overflow or be `∞ · 0`).
//!
//! Fixed cost, no allocation, no panic. Bad input is a typed error that changes nothing:
//! a non-finite measured or desired force, state or deformation is
//! [`Error::NonFiniteInput`]; the stateful [`ModulatedFriction`] keeps its history on
//! error. Sizes are const generics: `D` dampers, `S` states.

use nalgebra::{SMatrix, SVector};

use crate::hysteresis::{positive, rounded};
use crate::{Error, Param, Real};

/// `V_max` checked (finite, `> 0`, else [`Param::Saturation`]) and rounded to `T`.
fn checked_v_max<T: Real>(v_max: f64) -> Result<T, Error> {
    if !positive(v_max) {
        return Err(Error::InvalidParameter(Param::Saturation));
    }
    let [v] = rounded::<T, 1>([v_max])?;
    if v > T::zero() {
        Ok(v)
    } else {
        // A positive `f64` below `T`'s smallest subnormal rounds to zero.
        Err(Error::InvalidParameter(Param::Saturation))
    }
}

/// `V_max` when `a · b > 0` strictly (the two factors nonzero and of one sign), else zero:
/// the strict Heaviside step of the product, decided by signs (no overflow, no `∞ · 0`).
#[inline]
fn on_if_same_sign<T: Real>(a: T, b: T, v_max: T) -> T {
    let zero = T::zero();
    if (a > zero && b > zero) || (a < zero && b < zero) {
        v_max
    } else {
        zero
    }
}

fn all_finite<T: Real, const D: usize>(x: &SVector<T, D>) -> bool {
    x.iter().all(|v| v.is_finite())
}

/// The input check of every law's command: both vectors finite, else
/// [`Error::NonFiniteInput`].
fn finite_inputs<T: Real, const A: usize, const D: usize>(
    a: &SVector<T, A>,
    measured: &SVector<T, D>,
) -> Result<(), Error> {
    if all_finite(a) && all_finite(measured) {
        Ok(())
    } else {
        Err(Error::NonFiniteInput)
    }
}

/// `v_i = V_max H(a_i f_i)` for every damper, by signs ([`on_if_same_sign`]).
fn same_sign_commands<T: Real, const D: usize>(
    a: &SVector<T, D>,
    measured: &SVector<T, D>,
    v_max: T,
) -> SVector<T, D> {
    a.zip_map(measured, |x, f| on_if_same_sign(x, f, v_max))
}

/// Clipped-optimal control of `D` MR dampers (Dyke, Spencer, Sain & Carlson 1996):
///
/// ```text
/// v_i = V_max H((f_ci − f_i) f_i)
/// ```
///
/// `f_ci` the force an optimal controller asks of damper `i` (force), `f_i` the force the
/// damper measurably delivers (same units and sign convention), `v_i` its command
/// (voltage, `0` or `V_max`). The voltage is switched to `V_max` when the damper's force
/// is smaller in magnitude than the desired one *and* of its sign (so more voltage brings
/// `f_i` towards `f_ci`), and to zero otherwise. With the strict `H` of the
/// [module](self): at `f_i = f_ci` and at `f_i = 0` the command is 0 V (at rest a damper
/// produces no force, and the law waits for the passive force the motion develops, as the
/// paper's rule "smaller magnitude and same sign" reads).
///
/// Memoryless (a `Copy` value holding `V_max`). Cost: `D` subtractions and `4D`
/// comparisons per command.
///
/// ```
/// use aemstep::control::ClippedOptimal;
/// use aemstep::nalgebra::Vector1;
///
/// let law = ClippedOptimal::<f64, 1>::new(2.25)?;
/// // Desired 100 N, delivered 40 N of the same sign: switch on.
/// assert_eq!(law.command(&Vector1::new(100.0), &Vector1::new(40.0))?[0], 2.25);
/// // Delivered force beyond the desired one: switch off.
/// assert_eq!(law.command(&Vector1::new(100.0), &Vector1::new(140.0))?[0], 0.0);
/// # Ok::<(), aemstep::Error>(())
/// ```
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClippedOptimal<T, const D: usize> {
    v_max: T,
}

impl<T: Real, const D: usize> ClippedOptimal<T, D> {
    /// The law with the maximum command `v_max` (voltage, finite, `> 0`).
    ///
    /// Errors: [`Error::InvalidParameter`]`(`[`Param::Saturation`]`)` for `v_max` not
    /// finite or `≤ 0` (or below `T`'s smallest positive value);
    /// [`Error::OperatorOverflow`] if it exceeds `T::MAX`. Cost: O(1).
    pub fn new(v_max: f64) -> Result<Self, Error> {
        Ok(Self {
            v_max: checked_v_max(v_max)?,
        })
    }

    /// The maximum command `V_max` (voltage). Cost: O(1).
    pub fn v_max(&self) -> T {
        self.v_max
    }

    /// The commands `v` (voltage, each `0` or `V_max`) for the desired forces `desired`
    /// (`f_c`, force) and the measured forces `measured` (`f`, force) of the `D` dampers.
    ///
    /// Errors: [`Error::NonFiniteInput`] if an entry of either is NaN or infinite (nothing
    /// is returned, the law holds no state). Cost: `D` subtractions, `≤ 4D` comparisons.
    pub fn command(
        &self,
        desired: &SVector<T, D>,
        measured: &SVector<T, D>,
    ) -> Result<SVector<T, D>, Error> {
        // `f_c − f`, formed before the check (no panic on any input: NaN or `±∞` here is
        // refused next); it may overflow to `±∞` for huge finite forces, its sign right.
        let lag = desired - measured;
        finite_inputs(desired, measured)?;
        Ok(same_sign_commands(&lag, measured, self.v_max))
    }
}

/// The Lyapunov law for `D` MR dampers on a structure with `S` states (Jansen & Dyke
/// 2000, after McClamroch & Gavin 1995):
///
/// ```text
/// v_i = V_max H(−zᵀ P B_i f_i)
/// ```
///
/// `z` the (estimated) state of `ż = A z + B f + …` (units of the model), `B_i` the column
/// of `B` that multiplies damper `i`'s measured force `f_i` (force) in that equation, and
/// `P` the symmetric positive semidefinite solution of a Lyapunov equation
/// `Aᵀ P + P A = −Q` (the candidate `V = ½ zᵀ P z`, whose rate the dampers' contribution
/// `zᵀ P B f` lowers when negative). The voltage is switched on for damper `i` when
/// `zᵀ P B_i` and `f_i` have opposite signs (both nonzero), off otherwise (strict `H`).
///
/// The law stores `G = P B` (`S×D`, rounded once to `T` from its `f64` product), so a
/// command costs `S·D` multiply-adds and `4D` comparisons.
///
/// ```
/// use aemstep::control::Lyapunov;
/// use aemstep::nalgebra::{Matrix2, Matrix2x1, Vector1, Vector2};
///
/// // One oscillator z = [x; ẋ], the damper force on the mass: B = [0; −1/m] (m = 1).
/// let p = Matrix2::new(2.0, 0.5, 0.5, 1.0);
/// let b = Matrix2x1::new(0.0, -1.0);
/// let law = Lyapunov::<f64, 2, 1>::new(2.25, &p, &b)?;
/// // zᵀPB = −(0.5·x + ẋ) = −1.5 at z = [1; 1]; f = 10 N: −zᵀPB f = 15 > 0, on.
/// assert_eq!(law.command(&Vector2::new(1.0, 1.0), &Vector1::new(10.0))?[0], 2.25);
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lyapunov<T, const S: usize, const D: usize> {
    v_max: T,
    pb: SMatrix<T, S, D>,
}

impl<T: Real, const S: usize, const D: usize> Lyapunov<T, S, D> {
    /// The law with maximum command `v_max` (voltage, finite, `> 0`), the Lyapunov matrix
    /// `p` (`S×S`, finite, symmetric to `8ε` of its largest entry, diagonal `≥ 0`: a
    /// necessary condition of semidefiniteness, which the law does not otherwise test —
    /// the solution of `Aᵀ P + P A = −Q` for a stable `A` and `Q ⪰ 0` is semidefinite) and
    /// the force input matrix `b` (`S×D`, finite, units of `ż` per unit force).
    ///
    /// Errors: [`Error::InvalidParameter`]`(`[`Param::Saturation`]`)` for `v_max`;
    /// [`Error::InvalidParameter`]`(`[`Param::Weight`]`)` for a `p` that is not finite,
    /// not symmetric or has a negative diagonal entry; [`Error::NonFiniteInput`] for a
    /// non-finite `b`; [`Error::OperatorOverflow`] if `P B` (computed in `f64`) or `v_max`
    /// does not fit `T`. Cost: `S²D` multiply-adds, once.
    pub fn new(v_max: f64, p: &SMatrix<f64, S, S>, b: &SMatrix<f64, S, D>) -> Result<Self, Error> {
        let v_max = checked_v_max(v_max)?;
        if !p.iter().all(|x| x.is_finite()) {
            return Err(Error::InvalidParameter(Param::Weight));
        }
        let scale = p.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let tol = 8.0 * f64::EPSILON * scale;
        for i in 0..S {
            if p[(i, i)] < 0.0 {
                return Err(Error::InvalidParameter(Param::Weight));
            }
            for j in 0..i {
                if (p[(i, j)] - p[(j, i)]).abs() > tol {
                    return Err(Error::InvalidParameter(Param::Weight));
                }
            }
        }
        if !b.iter().all(|x| x.is_finite()) {
            return Err(Error::NonFiniteInput);
        }
        let pb = p * b;
        if !pb.iter().all(|x| x.is_finite()) {
            return Err(Error::OperatorOverflow);
        }
        crate::hysteresis::fits::<T>(pb.as_slice())?;
        Ok(Self {
            v_max,
            pb: pb.map(T::from_f64_rounded),
        })
    }

    /// The maximum command `V_max` (voltage). Cost: O(1).
    pub fn v_max(&self) -> T {
        self.v_max
    }

    /// The stored `G = P B` (`S×D`): column `i` is `P B_i`. Cost: O(1).
    pub fn gain(&self) -> &SMatrix<T, S, D> {
        &self.pb
    }

    /// The commands `v` (voltage, each `0` or `V_max`) at the state `z` (`S`, the model's
    /// units) with the measured damper forces `measured` (`D`, force).
    ///
    /// Errors: [`Error::NonFiniteInput`] if an entry of `z` or `measured` is NaN or
    /// infinite; [`Error::NonFiniteState`] if some `zᵀ P B_i` overflows (finite but huge
    /// input). Nothing is returned on error; the law holds no state.
    /// Cost: `S·D` multiply-adds, `≤ 4D` comparisons.
    pub fn command(
        &self,
        z: &SVector<T, S>,
        measured: &SVector<T, D>,
    ) -> Result<SVector<T, D>, Error> {
        finite_inputs(z, measured)?;
        // −zᵀ P B_i, whose sign with f_i's decides.
        let s = -self.pb.tr_mul(z);
        if !all_finite(&s) {
            return Err(Error::NonFiniteState);
        }
        Ok(same_sign_commands(&s, measured, self.v_max))
    }
}

/// Modulated homogeneous friction for `D` MR dampers (Inaudi 1997, as Jansen & Dyke 2000
/// state it):
///
/// ```text
/// v_i = V_max H(f_ci − |f_i|),    f_ci = g_n |P[Δ_i]|
/// ```
///
/// `Δ_i` damper `i`'s deformation (length), `P[Δ_i]` its most recent local extremum, `g_n`
/// a positive gain (force per length), `f_i` the measured damper force (force). The
/// damper is switched on while its force is below the friction level set by the last
/// peak deformation, off otherwise (strict `H`: off at `|f_i| = f_ci`, and at rest, where
/// `P = 0`).
///
/// The extremum is tracked from the sampled deformation: each command compares `Δ_i` with
/// the previous sample; when the direction of travel reverses (an increment of the other
/// sign than the last nonzero one), the previous sample is the new extremum. Before the
/// first reversal `P[Δ_i] = 0` (the law starts at rest: previous sample 0, no direction).
/// This history (previous sample, direction, extremum per damper) is committed only when
/// a command succeeds: a refused command changes nothing.
///
/// Cost per command: `D` subtractions, one absolute value and `≤ 8` comparisons per damper.
///
/// ```
/// use aemstep::control::ModulatedFriction;
/// use aemstep::nalgebra::Vector1;
///
/// let mut law = ModulatedFriction::<f64, 1>::new(2.25, 1000.0)?; // g_n = 1000 N/m
/// let f = Vector1::new(1.0); // 1 N measured
/// for d in [0.001, 0.002, 0.003] {
///     assert_eq!(law.command(&Vector1::new(d), &f)?[0], 0.0); // no extremum yet
/// }
/// // Reversal: the extremum is 3 mm, f_c = 3 N > 1 N: on.
/// assert_eq!(law.command(&Vector1::new(0.0025), &f)?[0], 2.25);
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModulatedFriction<T, const D: usize> {
    v_max: T,
    gain: T,
    previous: SVector<T, D>,
    direction: [i8; D],
    extremum: SVector<T, D>,
}

impl<T: Real, const D: usize> ModulatedFriction<T, D> {
    /// The law with maximum command `v_max` (voltage, finite, `> 0`) and gain `gain`
    /// (`g_n`, force per length, finite, `> 0`), at rest.
    ///
    /// Errors: [`Error::InvalidParameter`]`(`[`Param::Saturation`]`)` for `v_max`;
    /// [`Error::InvalidParameter`]`(`[`Param::Weight`]`)` for `gain` not finite or `≤ 0`;
    /// [`Error::OperatorOverflow`] if either exceeds `T::MAX`. Cost: O(D).
    pub fn new(v_max: f64, gain: f64) -> Result<Self, Error> {
        let v_max = checked_v_max(v_max)?;
        if !positive(gain) {
            return Err(Error::InvalidParameter(Param::Weight));
        }
        let [g] = rounded::<T, 1>([gain])?;
        if g <= T::zero() {
            return Err(Error::InvalidParameter(Param::Weight));
        }
        Ok(Self {
            v_max,
            gain: g,
            previous: SVector::zeros(),
            direction: [0; D],
            extremum: SVector::zeros(),
        })
    }

    /// The maximum command `V_max` (voltage). Cost: O(1).
    pub fn v_max(&self) -> T {
        self.v_max
    }

    /// The gain `g_n` (force per length). Cost: O(1).
    pub fn gain(&self) -> T {
        self.gain
    }

    /// The most recent local extremum `P[Δ_i]` of each damper's deformation (length; `0`
    /// before the first reversal). Cost: O(1).
    pub fn extremum(&self) -> &SVector<T, D> {
        &self.extremum
    }

    /// The commands `v` (voltage, each `0` or `V_max`) for the deformations `deformation`
    /// (`Δ`, length) and measured forces `measured` (`f`, force) of this sample; the
    /// extremum tracking advances by one sample.
    ///
    /// Errors: [`Error::NonFiniteInput`] if an entry of either is NaN or infinite;
    /// [`Error::NonFiniteState`] if `g_n |P[Δ_i]|` overflows. On error the history is
    /// unchanged. Cost: see the type.
    pub fn command(
        &mut self,
        deformation: &SVector<T, D>,
        measured: &SVector<T, D>,
    ) -> Result<SVector<T, D>, Error> {
        finite_inputs(deformation, measured)?;
        let zero = T::zero();
        let mut direction = self.direction;
        let mut extremum = self.extremum;
        let mut v = SVector::<T, D>::zeros();
        for i in 0..D {
            let step = deformation[i] - self.previous[i];
            let d: i8 = if step > zero {
                1
            } else if step < zero {
                -1
            } else {
                0
            };
            if d != 0 {
                if direction[i] != 0 && d != direction[i] {
                    extremum[i] = self.previous[i];
                }
                direction[i] = d;
            }
            let fc = self.gain * extremum[i].abs();
            if !fc.is_finite() {
                return Err(Error::NonFiniteState);
            }
            v[i] = if fc > measured[i].abs() {
                self.v_max
            } else {
                zero
            };
        }
        self.previous = *deformation;
        self.direction = direction;
        self.extremum = extremum;
        Ok(v)
    }
}

#[cfg(feature = "defmt")]
mod fmt {
    use super::{Lyapunov, ModulatedFriction};
    use crate::Real;
    use crate::defmt_impls::format_impls;
    use defmt::{Format, Formatter, write};

    format_impls! {
        impl[T: Real + Format, const S: usize, const D: usize] Format for Lyapunov<T, S, D> => |s|
            "Lyapunov {{ v_max: {} V, P B (columns): {} }}",
            s.v_max, s.pb.as_slice();
        impl[T: Real + Format, const D: usize] Format for ModulatedFriction<T, D> => |s|
            "ModulatedFriction {{ v_max: {} V, gain: {}, previous: {}, extremum: {} }}",
            s.v_max, s.gain, s.previous.as_slice(), s.extremum.as_slice();
    }
}
