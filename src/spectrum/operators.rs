//! The step operators of one damped oscillator, in `const fn` `f64`.
//!
//! The oscillator `u'' + 2ζω u' + ω² u = −a_g(t)` (relative displacement `u`, ground
//! acceleration `a_g`) is stepped over a sub-step `h` on which `a_g` is linear, from `g` at
//! the start to `g + δ` at the end. Both schemes give the end state as a linear map
//!
//! ```text
//! u₁ = uu·u₀ + uv·v₀ + ug·g + ud·δ
//! v₁ = vu·u₀ + vv·v₀ + vg·g + vd·δ
//! ```
//!
//! - exact (piecewise-linear load): the map is the matrix exponential of the augmented
//!   system `[[hA, hb, 0], [0, 0, 1], [0, 0, 0]]` (state, load, load increment), computed
//!   by scaling and squaring a 20-term Taylor series; it is exact for a load linear on the
//!   sub-step, up to rounding (a few units of `f64` roundoff per squaring);
//! - AEM (Newmark average acceleration): the acceleration is the mean of its end values
//!   on the sub-step and the equation of motion holds at the end; second order.
//!
//! Everything here is `const fn` so a `static` bank is evaluated by the compiler and its
//! operators sit in flash. Cost: about 1 000 `f64` flops per oscillator (exact), 50 (AEM).

/// The linear map of one sub-step (see the module documentation), `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SdofOps {
    pub uu: f64,
    pub uv: f64,
    pub ug: f64,
    pub ud: f64,
    pub vu: f64,
    pub vv: f64,
    pub vg: f64,
    pub vd: f64,
}

type M4 = [[f64; 4]; 4];

const fn mul4(a: &M4, b: &M4) -> M4 {
    let mut r = [[0.0; 4]; 4];
    let mut i = 0;
    while i < 4 {
        let mut j = 0;
        while j < 4 {
            let mut s = 0.0;
            let mut k = 0;
            while k < 4 {
                s += a[i][k] * b[k][j];
                k += 1;
            }
            r[i][j] = s;
            j += 1;
        }
        i += 1;
    }
    r
}

/// `exp(m)` by scaling (to a row-sum norm ≤ 1/2, by an exact power of two) and squaring
/// a 20-term Taylor series (truncation below 2⁻²⁰/20! relative).
pub(crate) const fn expm4(m: &M4) -> M4 {
    let mut norm = 0.0;
    let mut i = 0;
    while i < 4 {
        let mut s = 0.0;
        let mut j = 0;
        while j < 4 {
            s += m[i][j].abs();
            j += 1;
        }
        if s > norm {
            norm = s;
        }
        i += 1;
    }
    let mut squarings = 0;
    let mut scale = 1.0;
    while norm * scale > 0.5 && squarings < 200 {
        scale *= 0.5;
        squarings += 1;
    }
    let mut a = [[0.0; 4]; 4];
    let mut i = 0;
    while i < 4 {
        let mut j = 0;
        while j < 4 {
            a[i][j] = m[i][j] * scale;
            j += 1;
        }
        i += 1;
    }
    let mut r = [[0.0; 4]; 4];
    let mut term = [[0.0; 4]; 4];
    let mut i = 0;
    while i < 4 {
        r[i][i] = 1.0;
        term[i][i] = 1.0;
        i += 1;
    }
    let mut k = 1;
    while k <= 20 {
        term = mul4(&term, &a);
        let inv = 1.0 / k as f64;
        let mut i = 0;
        while i < 4 {
            let mut j = 0;
            while j < 4 {
                term[i][j] *= inv;
                r[i][j] += term[i][j];
                j += 1;
            }
            i += 1;
        }
        k += 1;
    }
    let mut s = 0;
    while s < squarings {
        r = mul4(&r, &r);
        s += 1;
    }
    r
}

/// Exact (piecewise-linear load) sub-step of length `h` for `ω = w`, `2ζω = c2`.
///
/// The exponential is taken of the balanced system in `(ωu, v)` (norm about `ωh` rather
/// than `ω²h`), so few squarings are needed and their error amplification stays small;
/// the map is scaled back to `(u, v)` afterwards.
pub(crate) const fn exact(w: f64, c2: f64, h: f64) -> SdofOps {
    let m = [
        [0.0, w * h, 0.0, 0.0],
        [-w * h, -c2 * h, -h, 0.0],
        [0.0, 0.0, 0.0, 1.0],
        [0.0, 0.0, 0.0, 0.0],
    ];
    let e = expm4(&m);
    SdofOps {
        uu: e[0][0],
        uv: e[0][1] / w,
        ug: e[0][2] / w,
        ud: e[0][3] / w,
        vu: e[1][0] * w,
        vv: e[1][1],
        vg: e[1][2],
        vd: e[1][3],
    }
}

/// One AEM (average-acceleration) sub-step from `(u, v)` with load `g → g + δ`: the
/// reference [`aem`]'s closed form is tested against.
#[cfg(test)]
const fn aem_apply(w2: f64, c2: f64, h: f64, u: f64, v: f64, g: f64, d: f64) -> (f64, f64) {
    let q0 = -g - c2 * v - w2 * u;
    let meff = 1.0 + 0.5 * h * c2 + 0.25 * h * h * w2;
    let q1 = (-(g + d) - c2 * (v + 0.5 * h * q0) - w2 * (u + h * v + 0.25 * h * h * q0)) / meff;
    (
        u + h * v + 0.25 * h * h * (q0 + q1),
        v + 0.5 * h * (q0 + q1),
    )
}

/// AEM sub-step of length `h` for `ω² = w2`, `2ζω = c2`: the map of [`aem_apply`] in
/// closed form. With `D = 1 + (h/2) c2 + (h²/4) w2`,
///
/// ```text
/// uu = (1 + (h/2) c2 − (h²/4) w2)/D   uv = h/D   ug = −(h²/2)/D   ud = −(h²/4)/D
/// vu = −h w2/D   vv = (1 − (h/2) c2 − (h²/4) w2)/D   vg = −h/D   vd = −(h/2)/D
/// ```
///
/// (Formed by applying the step to unit inputs, as before, `uu` came from
/// `1 + h v − (h²/4)·w2·(…)` terms of size `(ωh)²/4` that cancel to about `−1`: at
/// `ωh ≈ 5e14` it was off by `1e13`, and a bank stepped 10 m/s² to a displacement of
/// `1e98`. Found by fuzzing.)
pub(crate) const fn aem(w2: f64, c2: f64, h: f64) -> SdofOps {
    let (a, b) = (0.5 * h * c2, 0.25 * h * h * w2);
    let d = 1.0 + a + b;
    SdofOps {
        uu: (1.0 + a - b) / d,
        uv: h / d,
        ug: -(0.5 * h * h) / d,
        ud: -(0.25 * h * h) / d,
        vu: -(h * w2) / d,
        vv: (1.0 - a - b) / d,
        vg: -h / d,
        vd: -(0.5 * h) / d,
    }
}

/// The map of a whole sample interval (load `a0 → a0 + d`) made of `n` sub-steps `sub`
/// (each with load increment `d/n`), in the same form: coefficients on `(u0, v0, a0, d)`.
/// Cost: `16n` flops.
pub(crate) const fn compose(sub: &SdofOps, n: u16) -> SdofOps {
    // u, v, g, δ as coefficient vectors over the basis (u0, v0, a0, d)
    let mut cu = [1.0, 0.0, 0.0, 0.0];
    let mut cv = [0.0, 1.0, 0.0, 0.0];
    let mut g = [0.0, 0.0, 1.0, 0.0];
    let dl = [0.0, 0.0, 0.0, 1.0 / n as f64];
    let mut k = 0;
    while k < n {
        let mut nu = [0.0; 4];
        let mut nv = [0.0; 4];
        let mut j = 0;
        while j < 4 {
            nu[j] = sub.uu * cu[j] + sub.uv * cv[j] + sub.ug * g[j] + sub.ud * dl[j];
            nv[j] = sub.vu * cu[j] + sub.vv * cv[j] + sub.vg * g[j] + sub.vd * dl[j];
            g[j] += dl[j];
            j += 1;
        }
        cu = nu;
        cv = nv;
        k += 1;
    }
    SdofOps {
        uu: cu[0],
        uv: cu[1],
        ug: cu[2],
        ud: cu[3],
        vu: cv[0],
        vv: cv[1],
        vg: cv[2],
        vd: cv[3],
    }
}

/// `cos x` and `sin x` for `0 ≤ x ≤ π` by their Taylor series on `[0, π/2]` (reflected
/// about π/2 above it; 40 terms: truncation below 2⁴⁰/40! ≈ 10⁻³⁶), in `const fn`.
pub(crate) const fn cos_sin(x: f64) -> (f64, f64) {
    if x > core::f64::consts::FRAC_PI_2 {
        let (c, s) = cos_sin_taylor(core::f64::consts::PI - x);
        return (-c, s);
    }
    cos_sin_taylor(x)
}

const fn cos_sin_taylor(x: f64) -> (f64, f64) {
    let (mut c, mut s) = (0.0, 0.0);
    let mut term = 1.0; // x^k / k!
    let mut k = 0;
    while k < 40 {
        match k % 4 {
            0 => c += term,
            1 => s += term,
            2 => c -= term,
            _ => s -= term,
        }
        k += 1;
        term *= x / k as f64;
    }
    (c, s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Undamped free vibration over one step: `u₁ = cos ωh`, closed form.
    #[test]
    fn exact_matches_closed_form_free_vibration() {
        let (w, h) = (7.0, 0.05);
        let op = exact(w, 0.0, h);
        assert!((op.uu - (w * h).cos()).abs() < 4e-16);
        assert!((op.uv - (w * h).sin() / w).abs() < 4e-16);
        assert!((op.vu + w * (w * h).sin()).abs() < 4e-15);
        // constant unit load g = 1 (ground acceleration): u = −(1 − cos ωh)/ω²
        assert!((op.ug + (1.0 - (w * h).cos()) / (w * w)).abs() < 4e-16);
    }

    /// Two exact half steps compose to the exact whole step.
    #[test]
    fn composed_exact_substeps_equal_the_whole_step() {
        let (w, c2, h) = (40.0, 0.4, 0.02);
        let whole = exact(w, c2, h);
        let two = compose(&exact(w, c2, h / 2.0), 2);
        for (a, b) in [
            (whole.uu, two.uu),
            (whole.uv, two.uv),
            (whole.ug, two.ug),
            (whole.ud, two.ud),
            (whole.vu / w, two.vu / w),
            (whole.vv, two.vv),
            (whole.vg, two.vg),
            (whole.vd, two.vd),
        ] {
            assert!(
                (a - b).abs() <= 8.0 * f64::EPSILON * a.abs().max(b.abs()),
                "{a} {b}"
            );
        }
    }

    #[test]
    fn cos_sin_match_libm() {
        let mut x = 0.0;
        while x <= core::f64::consts::PI {
            let (c, s) = cos_sin(x);
            assert!(
                (c - x.cos()).abs() < 3e-16 && (s - x.sin()).abs() < 3e-16,
                "{x}"
            );
            x += 0.013;
        }
    }

    /// The closed-form AEM map is the step applied to unit inputs (to rounding, where that
    /// has no cancellation), and stays bounded at any `ωh` (the unit-input form did not).
    #[test]
    fn aem_closed_form_is_the_step() {
        for (w2, c2, h) in [
            (4.0, 0.1, 0.01),
            (400.0, 2.0, 0.05),
            (1.0, 0.0, 1.0),
            (1e4, 10.0, 0.02),
        ] {
            let op = aem(w2, c2, h);
            let cols = [
                aem_apply(w2, c2, h, 1.0, 0.0, 0.0, 0.0),
                aem_apply(w2, c2, h, 0.0, 1.0, 0.0, 0.0),
                aem_apply(w2, c2, h, 0.0, 0.0, 1.0, 0.0),
                aem_apply(w2, c2, h, 0.0, 0.0, 0.0, 1.0),
            ];
            let got = [
                (op.uu, op.vu),
                (op.uv, op.vv),
                (op.ug, op.vg),
                (op.ud, op.vd),
            ];
            for (a, b) in got.iter().zip(cols.iter()) {
                for (x, y) in [(a.0, b.0), (a.1, b.1)] {
                    assert!(
                        (x - y).abs() <= 1e-13 * (1.0 + y.abs()),
                        "{x} vs {y} at ω² = {w2}"
                    );
                }
            }
        }
        let w = 2.0 * core::f64::consts::PI / 2.220446049250313e-16;
        let op = aem(w * w, 2.0 * 0.18 * w, 1.643114108127686e-2);
        assert!(
            (op.uu + 1.0).abs() < 1e-6 && op.vv.abs() <= 1.0,
            "{}",
            op.uu
        );
    }
}
