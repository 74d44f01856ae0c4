//! Stability and accuracy of a scheme on the single-degree-of-freedom oscillator
//! `u'' + 2ξω u' + ω² u = 0` (spec §4, paper eqs. 24–36), for any stepper of the crate.
//!
//! A linear stepper maps the state `(u, v, a)` linearly when the load is zero; its
//! **amplification matrix** is read off by stepping the three unit states
//! ([`amplification_matrix`]). It is returned in the dimensionless coordinates
//! `(u, h v, h² a)`, in which its entries are functions of `s = ωh` and `ξ` only, so that
//! eigenvalues are computed without the `h`-dependent scaling of the raw matrix.
//!
//! From its eigenvalues ([`eigenvalues`], [`spectral_radius`]) and the principal
//! (oscillatory) root `λ = r e^{iφ}`:
//!
//! ```text
//! period elongation   PE = s √(1 − ξ²) / φ − 1               (0 for the exact scheme)
//! algorithmic damping ξ̄ = −ln r / √(φ² + ln² r),  Δξ = ξ̄ − ξ  (0 for the exact scheme)
//! ```
//!
//! (`ξ̄` is the damping ratio of the continuous oscillator whose exact flow over one step
//! has the eigenvalue `λ`; for small damping it equals the spec's `−ln r/φ`.)
//!
//! Accuracy: `r` and the spectral radius to a few ulps; the phase `φ` to about `16ε/s`
//! absolute (it comes from `√(4c − b²)`, a difference of O(1) coefficients), so the period
//! elongation is resolved to about `16ε/s²` — 4·10⁻¹² at `s = 0.01`, useless below
//! `s ≈ 10⁻⁴`.
//!
//! [`sdof`] builds the `f64` stepper of a [`Scheme`] for given `s`, `ξ` and does all of
//! this. Everything here is `no_std` and allocation-free; cost is a few hundred flops
//! plus the construction of a 1-DOF stepper.

use nalgebra::{ComplexField, RealField, SVector, matrix};

use crate::{
    AForm, Error, Exact, GeneralizedAlpha, KrAlpha, Linear, Newmark, Real, State, Stepper,
};

/// A `3×3` matrix, row-major (`a[i][j]`: row `i`, column `j`); rows and columns ordered
/// `u, h v, h² a`.
pub type Matrix3 = [[f64; 3]; 3];

/// A complex number `(re, im)`.
pub type Complex = (f64, f64);

/// The amplification matrix of a 1-DOF stepper (free vibration, `p = 0`), in the
/// dimensionless coordinates `(u, h v, h² a)`, computed in `f64` from three steps of the
/// stepper in its own scalar type `T` (so an `f32` stepper's rounded operators are what is
/// analysed).
///
/// Cost: three steps and `O(1)` flops.
pub fn amplification_matrix<T: Real, S>(stepper: &S) -> Matrix3
where
    S: Stepper<T, 1, Input = SVector<T, 1>, State = State<T, 1>>,
{
    let h = stepper.time_step().as_f64();
    // Raw columns: the images of the unit states e_u, e_v, e_a.
    let mut raw = [[0.0; 3]; 3];
    for j in 0..3 {
        let e = |k: usize| SVector::<T, 1>::new(if k == j { T::one() } else { T::zero() });
        let mut s = State::unchecked(e(0), e(1), e(2), 0);
        stepper.step(&mut s, &SVector::<T, 1>::zeros());
        raw[0][j] = s.u()[0].as_f64();
        raw[1][j] = s.v()[0].as_f64();
        raw[2][j] = s.a()[0].as_f64();
    }
    // x = D y with D = diag(1, 1/h, 1/h²): A_y = D⁻¹ A_x D.
    let d = [1.0, 1.0 / h, 1.0 / (h * h)];
    let mut a = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            a[i][j] = raw[i][j] * (d[j] / d[i]);
        }
    }
    a
}

fn cbrt(x: f64) -> f64 {
    if x == 0.0 {
        0.0
    } else {
        let r = <f64 as ComplexField>::powf(x.abs(), 1.0 / 3.0);
        // One Newton step on r³ = |x| recovers the last bits.
        let r = r - (r * r * r - x.abs()) / (3.0 * r * r);
        if x < 0.0 { -r } else { r }
    }
}

fn sqrt(x: f64) -> f64 {
    <f64 as ComplexField>::sqrt(x)
}

/// Polish a real root of `λ³ + c2 λ² + c1 λ + c0` by Newton's method (two steps).
fn polish(mut x: f64, c2: f64, c1: f64, c0: f64) -> f64 {
    for _ in 0..2 {
        let f = ((x + c2) * x + c1) * x + c0;
        let df = (3.0 * x + 2.0 * c2) * x + c1;
        if df != 0.0 {
            let nx = x - f / df;
            if nx.is_finite() {
                x = nx;
            }
        }
    }
    x
}

/// The three eigenvalues of a real `3×3` matrix, from its characteristic polynomial
/// (real roots by Cardano or the trigonometric form, polished by Newton; the complex pair,
/// if any, by deflation, so that its modulus² is a product of coefficients and keeps full
/// relative accuracy). Order: the real root first, then the pair `(re, +im), (re, −im)`
/// (or three real roots in descending order).
///
/// Cost: about 100 flops.
pub fn eigenvalues(a: &Matrix3) -> [Complex; 3] {
    let tr = a[0][0] + a[1][1] + a[2][2];
    let minors = (a[0][0] * a[1][1] - a[0][1] * a[1][0])
        + (a[0][0] * a[2][2] - a[0][2] * a[2][0])
        + (a[1][1] * a[2][2] - a[1][2] * a[2][1]);
    let det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
        - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
        + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    let (c2, c1, c0) = (-tr, minors, -det);
    // Depressed cubic x³ + p x + q, λ = x − c2/3.
    let sh = c2 / 3.0;
    let p = c1 - c2 * sh;
    let q = (2.0 * sh * sh - c1) * sh + c0;
    let disc = (q / 2.0) * (q / 2.0) + (p / 3.0) * (p / 3.0) * (p / 3.0);
    if disc > 0.0 || p >= 0.0 {
        // One real root.
        let sd = sqrt(disc.max(0.0));
        let w = cbrt(-q / 2.0 - if q >= 0.0 { sd } else { -sd });
        let x = if w != 0.0 { w - p / (3.0 * w) } else { 0.0 };
        let r = polish(x - sh, c2, c1, c0);
        // Deflate: λ³ + c2 λ² + c1 λ + c0 = (λ − r)(λ² + b λ + c).
        let b = c2 + r;
        let c = c1 + r * b;
        let dq = b * b - 4.0 * c;
        if dq < 0.0 {
            let re = -b / 2.0;
            let im = sqrt(-dq) / 2.0;
            [(r, 0.0), (re, im), (re, -im)]
        } else {
            let sq = sqrt(dq);
            let l1 = -(b + if b >= 0.0 { sq } else { -sq }) / 2.0;
            let l2 = if l1 != 0.0 { c / l1 } else { 0.0 };
            let mut roots = [r, l1, l2];
            roots.sort_unstable_by(|x, y| y.partial_cmp(x).unwrap_or(core::cmp::Ordering::Equal));
            roots.map(|x| (x, 0.0))
        }
    } else {
        // Three real roots (p < 0).
        let m = 2.0 * sqrt(-p / 3.0);
        let arg = ((3.0 * q) / (p * m)).clamp(-1.0, 1.0);
        let theta = <f64 as ComplexField>::acos(arg) / 3.0;
        let tau = 2.0 * core::f64::consts::PI / 3.0;
        let mut roots = [0.0f64; 3];
        for (k, x) in roots.iter_mut().enumerate() {
            let xk = m * <f64 as ComplexField>::cos(theta - tau * k as f64);
            *x = polish(xk - sh, c2, c1, c0);
        }
        roots.sort_unstable_by(|x, y| y.partial_cmp(x).unwrap_or(core::cmp::Ordering::Equal));
        roots.map(|x| (x, 0.0))
    }
}

/// `|z|`.
pub fn modulus(z: Complex) -> f64 {
    <f64 as ComplexField>::hypot(z.0, z.1)
}

/// The spectral radius `max |λ|` of a `3×3` matrix (see [`eigenvalues`]). For a
/// complex pair it is `√c` with `c` the product of the pair, so it is accurate to a few
/// ulps even where the pair is nearly double (`λ ≈ −1` at `s → ∞`).
pub fn spectral_radius(a: &Matrix3) -> f64 {
    let ev = eigenvalues(a);
    ev.iter().map(|&z| modulus(z)).fold(0.0, f64::max)
}

/// What the analysis of one scheme at one `(s, ξ)` gives.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SdofProperties {
    /// `s = ωh`.
    pub s: f64,
    /// Damping ratio `ξ` of the oscillator.
    pub xi: f64,
    /// Amplification matrix in `(u, h v, h² a)` coordinates.
    pub matrix: Matrix3,
    /// `max |λ|`: `≤ 1` for a stable scheme.
    pub spectral_radius: f64,
    /// The principal root `r e^{iφ}` as `(r, φ)`, `φ ∈ (0, π]`: the complex eigenvalue of
    /// largest modulus with positive imaginary part; `None` if every eigenvalue is real
    /// (e.g. central difference beyond `s = 2`).
    pub principal: Option<(f64, f64)>,
}

impl SdofProperties {
    /// Analyse an amplification matrix for the oscillator with `s = ωh` and ratio `xi`.
    pub fn from_matrix(matrix: Matrix3, s: f64, xi: f64) -> Self {
        let ev = eigenvalues(&matrix);
        let spectral_radius = ev.iter().map(|&z| modulus(z)).fold(0.0, f64::max);
        let principal = ev
            .iter()
            .filter(|z| z.1 > 0.0)
            .map(|&z| (modulus(z), <f64 as RealField>::atan2(z.1, z.0)))
            .fold(None, |best: Option<(f64, f64)>, x| match best {
                Some(b) if b.0 >= x.0 => Some(b),
                _ => Some(x),
            });
        Self {
            s,
            xi,
            matrix,
            spectral_radius,
            principal,
        }
    }

    /// Period elongation `T̄/T_d − 1 = s √(1 − ξ²)/φ − 1` (`≈ s²/12` for the AEM at
    /// `ξ = 0`); `None` without an oscillatory root.
    pub fn period_elongation(&self) -> Option<f64> {
        let (_, phi) = self.principal?;
        Some(self.s * sqrt(1.0 - self.xi * self.xi) / phi - 1.0)
    }

    /// Algorithmic damping ratio `ξ̄ = −ln r / √(φ² + ln² r)`; `None` without an
    /// oscillatory root.
    pub fn algorithmic_damping(&self) -> Option<f64> {
        let (r, phi) = self.principal?;
        let lr = <f64 as ComplexField>::ln(r);
        Some(-lr / <f64 as ComplexField>::hypot(phi, lr))
    }

    /// Amplitude decay `Δξ = ξ̄ − ξ` (the paper's Fig. 3 measure; `0` for the AEM at
    /// `ξ = 0`); `None` without an oscillatory root.
    pub fn amplitude_decay(&self) -> Option<f64> {
        Some(self.algorithmic_damping()? - self.xi)
    }
}

/// The schemes of the crate, for [`sdof`].
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scheme {
    /// The AEM, eliminated form ([`Linear`]).
    Aem,
    /// The AEM, the paper's literal `A`, `b` form ([`AForm`]).
    AemAForm,
    /// [`Newmark`] with `beta`, `gamma`.
    Newmark {
        /// β ≥ 0.
        beta: f64,
        /// γ ≥ 0.
        gamma: f64,
    },
    /// Chung–Hulbert [`GeneralizedAlpha`] with high-frequency spectral radius `rho_inf`.
    GeneralizedAlpha {
        /// ρ∞ ∈ [0, 1].
        rho_inf: f64,
    },
    /// HHT-α ([`GeneralizedAlpha::hht`]), `alpha ∈ [−1/3, 0]`.
    Hht {
        /// α ∈ [−1/3, 0].
        alpha: f64,
    },
    /// The exact discretization ([`Exact`]).
    Exact,
    /// The explicit KR-α scheme ([`KrAlpha::new`]) with high-frequency spectral radius
    /// `rho_inf`: for linear systems the characteristic polynomial of
    /// [`Scheme::GeneralizedAlpha`] with the same `rho_inf`, so the same spectral radius,
    /// period elongation and amplitude decay (an explicit step at an implicit scheme's
    /// accuracy).
    KrAlpha {
        /// ρ∞ ∈ [0, 1].
        rho_inf: f64,
    },
    /// The Chen–Ricles algorithm ([`KrAlpha::chen_ricles`]): the AEM's (trapezoidal)
    /// principal roots, a third root `0`.
    ChenRicles,
}

/// Analyse `scheme` on `u'' + 2ξω u' + ω² u = 0` at `s = ωh` (built with `ω = 1`,
/// `h = s`, in `f64`).
///
/// Errors: those of the scheme's constructor (e.g. [`Error::InvalidTimeStep`] for
/// `s ≤ 0`, [`Error::InvalidParameter`]); [`Error::NonFiniteInput`] for a non-finite `ξ`.
pub fn sdof(scheme: Scheme, s: f64, xi: f64) -> Result<SdofProperties, Error> {
    let (m, c, k) = (matrix![1.0], matrix![2.0 * xi], matrix![1.0]);
    let a = match scheme {
        Scheme::Aem => amplification_matrix(&Linear::<f64, 1>::new(&m, &c, &k, s)?),
        Scheme::AemAForm => {
            let f: AForm<f64, 1> = Linear::new(&m, &c, &k, s)?.a_form();
            amplification_matrix(&f)
        }
        Scheme::Newmark { beta, gamma } => {
            amplification_matrix(&Newmark::<f64, 1>::new(&m, &c, &k, s, beta, gamma)?)
        }
        Scheme::GeneralizedAlpha { rho_inf } => {
            amplification_matrix(&GeneralizedAlpha::<f64, 1>::new(&m, &c, &k, s, rho_inf)?)
        }
        Scheme::Hht { alpha } => {
            amplification_matrix(&GeneralizedAlpha::<f64, 1>::hht(&m, &c, &k, s, alpha)?)
        }
        Scheme::Exact => amplification_matrix(&Exact::<f64, 1>::new(&m, &c, &k, s)?),
        Scheme::KrAlpha { rho_inf } => {
            amplification_matrix(&KrAlpha::<f64, 1>::new(&m, &c, &k, s, rho_inf)?)
        }
        Scheme::ChenRicles => amplification_matrix(&KrAlpha::<f64, 1>::chen_ricles(&m, &c, &k, s)?),
    };
    Ok(SdofProperties::from_matrix(a, s, xi))
}
