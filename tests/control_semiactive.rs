//! The semi-active laws of `aemstep::control::semiactive` on constructed cases, each
//! checked against the published formula written here independently (not by calling the
//! crate's code):
//!
//! - clipped-optimal, Dyke, Spencer, Sain & Carlson (1996): `v = V_max H((f_c − f) f)`;
//! - Lyapunov, Jansen & Dyke (2000): `v_i = V_max H(−zᵀ P B_i f_i)`;
//! - modulated homogeneous friction, Jansen & Dyke (2000): `v_i = V_max H(f_ci − |f_i|)`,
//!   `f_ci = g_n |P[Δ_i]|`.
//!
//! `H` strict (`H(0) = 0`), as the module documents. The laws' outputs are exactly `0` or
//! `V_max`, so every comparison is exact.

use aemstep::control::{ClippedOptimal, Lyapunov, ModulatedFriction};
use aemstep::nalgebra::{Matrix2, Matrix2x1, SMatrix, SVector, Vector1, Vector2, Vector3};
use aemstep::{Error, Param};

const VMAX: f64 = 2.25;

/// The strict Heaviside step of the papers' formulas, as this test's convention.
fn heaviside(x: f64) -> f64 {
    if x > 0.0 { 1.0 } else { 0.0 }
}

/// Clipped-optimal, formed literally: the product of the paper (moderate values only).
fn clipped_reference(fc: f64, f: f64) -> f64 {
    VMAX * heaviside((fc - f) * f)
}

#[test]
fn clipped_optimal_every_branch_and_the_equalities() {
    let law = ClippedOptimal::<f64, 1>::new(VMAX).unwrap();
    // (desired, measured, expected): the branches of "smaller magnitude and same sign".
    let cases = [
        (100.0, 40.0, VMAX),   // same sign, |f| < |f_c|: on
        (100.0, 140.0, 0.0),   // same sign, |f| > |f_c|: off
        (100.0, -40.0, 0.0),   // opposite signs: off
        (-100.0, -40.0, VMAX), // negative side, |f| < |f_c|: on
        (-100.0, -140.0, 0.0), // negative side, |f| > |f_c|: off
        (-100.0, 40.0, 0.0),   // opposite signs: off
        (100.0, 100.0, 0.0),   // equality f = f_c: H(0) = 0, off
        (100.0, 0.0, 0.0),     // f = 0 (damper at rest): H(0) = 0, off
        (0.0, 10.0, 0.0),      // f_c = 0: (0 − f) f < 0, off
        (0.0, 0.0, 0.0),       // both zero
    ];
    for (fc, f, want) in cases {
        let v = law.command(&Vector1::new(fc), &Vector1::new(f)).unwrap()[0];
        assert_eq!(v, want, "f_c = {fc}, f = {f}");
        assert_eq!(v, clipped_reference(fc, f), "f_c = {fc}, f = {f}");
    }
}

#[test]
fn clipped_optimal_several_dampers_and_a_sweep_match_the_formula() {
    let law = ClippedOptimal::<f64, 3>::new(VMAX).unwrap();
    let v = law
        .command(
            &Vector3::new(100.0, -100.0, 50.0),
            &Vector3::new(40.0, -140.0, -5.0),
        )
        .unwrap();
    assert_eq!(v, Vector3::new(VMAX, 0.0, 0.0));
    // A grid of forces (N) crossing every sign and equality: each damper independently.
    let grid = [-300.0, -120.5, -100.0, -3.0, 0.0, 2.5, 100.0, 120.5, 300.0];
    let mut on = 0;
    for &fc in &grid {
        for &f in &grid {
            let fc3 = Vector3::new(fc, -fc, fc);
            let f3 = Vector3::new(f, -f, -f);
            let v = law.command(&fc3, &f3).unwrap();
            for i in 0..3 {
                assert_eq!(
                    v[i],
                    clipped_reference(fc3[i], f3[i]),
                    "{fc} {f} damper {i}"
                );
            }
            on += (v[0] > 0.0) as usize;
        }
    }
    // Both branches are exercised: on for the pairs of one sign with |f| < |f_c| (2 × 6
    // of the 81 pairs of the grid's first damper).
    assert_eq!(on, 12);
}

#[test]
fn clipped_optimal_decides_by_signs_without_overflow() {
    let law = ClippedOptimal::<f64, 1>::new(VMAX).unwrap();
    // f_c − f = 1e308 − (−1e308) overflows to +∞; f < 0: the product's sign is negative.
    let v = law
        .command(&Vector1::new(1e308), &Vector1::new(-1e308))
        .unwrap()[0];
    assert_eq!(v, 0.0);
    // Same sign, huge: (f_c − f) f = 1e308 · 1e307 overflows, its sign is positive.
    let v = law
        .command(&Vector1::new(1.1e308), &Vector1::new(1e307))
        .unwrap()[0];
    assert_eq!(v, VMAX);
    // f32 as well.
    let law32 = ClippedOptimal::<f32, 1>::new(VMAX).unwrap();
    let v = law32
        .command(&Vector1::new(3e38), &Vector1::new(1e38))
        .unwrap()[0];
    assert_eq!(v, VMAX as f32);
}

#[test]
fn clipped_optimal_refuses_bad_input() {
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, -0.0] {
        assert_eq!(
            ClippedOptimal::<f64, 1>::new(bad),
            Err(Error::InvalidParameter(Param::Saturation)),
            "{bad}"
        );
    }
    // Finite and positive in f64, but below f32's smallest subnormal / above f32::MAX.
    assert_eq!(
        ClippedOptimal::<f32, 1>::new(1e-50),
        Err(Error::InvalidParameter(Param::Saturation))
    );
    assert_eq!(
        ClippedOptimal::<f32, 1>::new(1e300),
        Err(Error::OperatorOverflow)
    );
    let law = ClippedOptimal::<f64, 2>::new(VMAX).unwrap();
    let ok = Vector2::new(1.0, 2.0);
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let b = Vector2::new(1.0, bad);
        assert_eq!(law.command(&b, &ok), Err(Error::NonFiniteInput));
        assert_eq!(law.command(&ok, &b), Err(Error::NonFiniteInput));
    }
    // The law holds no state: a refused command leaves it as it was.
    assert_eq!(law, ClippedOptimal::<f64, 2>::new(VMAX).unwrap());
    assert_eq!(law.v_max(), VMAX);
}

/// Lyapunov, formed literally: `−zᵀ P B_i f_i` summed in the paper's order.
fn lyapunov_reference<const S: usize, const D: usize>(
    p: &SMatrix<f64, S, S>,
    b: &SMatrix<f64, S, D>,
    z: &SVector<f64, S>,
    f: &SVector<f64, D>,
) -> SVector<f64, D> {
    SVector::from_fn(|i, _| {
        let mut s = 0.0;
        for r in 0..S {
            for c in 0..S {
                s += z[r] * p[(r, c)] * b[(c, i)];
            }
        }
        VMAX * heaviside(-s * f[i])
    })
}

#[test]
fn lyapunov_every_branch_against_the_formula() {
    // One oscillator z = [x; ẋ] (m = 1): ż = A z + B f with B = [0; −1] (the damper force
    // resists), P the solution of AᵀP + PA = −I for A = [0 1; −k −c], k = 4, c = 0.4:
    // closed form p12 = 1/(2k), p22 = (1 + p12·2)/(2c)… computed here by the 3×3 linear
    // system of the Lyapunov equation's distinct entries.
    let (k, c) = (4.0, 0.4);
    // AᵀP + PA = −I, P = [a b; b d]:
    //   (1,1): −2k b = −1            → b = 1/(2k)
    //   (1,2): a − c b − k d = 0
    //   (2,2): 2b − 2c d = −1        → d = (1 + 2b)/(2c)
    let pb_ = 1.0 / (2.0 * k);
    let pd = (1.0 + 2.0 * pb_) / (2.0 * c);
    let pa = c * pb_ + k * pd;
    let p = Matrix2::new(pa, pb_, pb_, pd);
    let a = Matrix2::new(0.0, 1.0, -k, -c);
    let residual = a.transpose() * p + p * a + Matrix2::identity();
    assert!(residual.abs().max() < 1e-14, "{residual}");
    let b = Matrix2x1::new(0.0, -1.0);
    let law = Lyapunov::<f64, 2, 1>::new(VMAX, &p, &b).unwrap();
    // zᵀ P B = −(b x + d ẋ): cases of each sign of it and of f, and the zeros.
    let cases = [
        (Vector2::new(0.0, 1.0), 10.0, VMAX), // zᵀPB < 0, f > 0: −zᵀPB f > 0, on
        (Vector2::new(0.0, 1.0), -10.0, 0.0), // zᵀPB < 0, f < 0: off
        (Vector2::new(0.0, -1.0), -10.0, VMAX),
        (Vector2::new(0.0, -1.0), 10.0, 0.0),
        (Vector2::new(0.0, 1.0), 0.0, 0.0),  // f = 0: H(0) = 0
        (Vector2::new(0.0, 0.0), 10.0, 0.0), // z = 0: H(0) = 0
        // zᵀPB = 0 off the origin: x = −(d/b) ẋ.
        (Vector2::new(-pd / pb_, 1.0), 10.0, 0.0),
    ];
    for (z, f, want) in cases {
        let v = law.command(&z, &Vector1::new(f)).unwrap()[0];
        let r = lyapunov_reference(&p, &b, &z, &Vector1::new(f))[0];
        assert_eq!(v, want, "z = {z:?}, f = {f}");
        if (z[0], z[1]) != (-pd / pb_, 1.0) {
            // (On the switching line the literal sum rounds to ±1 ulp: the law's `G = PB`
            // is exact there, so only the constructed expectation applies.)
            assert_eq!(v, r, "z = {z:?}, f = {f}");
        }
    }
}

#[test]
fn lyapunov_two_dampers_sweep_against_the_formula() {
    // A 4-state model, two dampers; P symmetric positive definite (diagonally dominant).
    let p = SMatrix::<f64, 4, 4>::from_row_slice(&[
        4.0, 0.5, -0.3, 0.1, //
        0.5, 3.0, 0.2, -0.4, //
        -0.3, 0.2, 2.0, 0.3, //
        0.1, -0.4, 0.3, 1.5,
    ]);
    let b = SMatrix::<f64, 4, 2>::from_row_slice(&[0.0, 0.0, 0.0, 0.0, -1.0, 0.5, 0.0, -0.7]);
    let law = Lyapunov::<f64, 4, 2>::new(VMAX, &p, &b).unwrap();
    let mut on = [0usize; 2];
    let mut n = 0;
    for i in 0..7 {
        for j in 0..5 {
            let z = SVector::<f64, 4>::new(
                (i as f64 - 3.0) * 0.01,
                (j as f64 - 2.0) * 0.02,
                (i as f64 - j as f64) * 0.1,
                (i * j) as f64 * 0.05 - 0.4,
            );
            for f in [-50.0, -1.0, 1.0, 50.0] {
                let f2 = Vector2::new(f, -0.5 * f);
                let v = law.command(&z, &f2).unwrap();
                assert_eq!(v, lyapunov_reference(&p, &b, &z, &f2), "z = {z:?}, f = {f}");
                on[0] += (v[0] > 0.0) as usize;
                on[1] += (v[1] > 0.0) as usize;
                n += 1;
            }
        }
    }
    // Both branches of both dampers exercised.
    assert!(on.iter().all(|&k| k > 0 && k < n), "{on:?} of {n}");
}

#[test]
fn lyapunov_refuses_bad_input() {
    let p = Matrix2::new(2.0, 0.5, 0.5, 1.0);
    let b = Matrix2x1::new(0.0, -1.0);
    assert_eq!(
        Lyapunov::<f64, 2, 1>::new(0.0, &p, &b),
        Err(Error::InvalidParameter(Param::Saturation))
    );
    let weight = Err(Error::InvalidParameter(Param::Weight));
    let nonsym = Matrix2::new(2.0, 0.5, 0.6, 1.0);
    assert_eq!(Lyapunov::<f64, 2, 1>::new(VMAX, &nonsym, &b), weight);
    let negdiag = Matrix2::new(2.0, 0.5, 0.5, -1.0);
    assert_eq!(Lyapunov::<f64, 2, 1>::new(VMAX, &negdiag, &b), weight);
    let nan = Matrix2::new(2.0, f64::NAN, f64::NAN, 1.0);
    assert_eq!(Lyapunov::<f64, 2, 1>::new(VMAX, &nan, &b), weight);
    assert_eq!(
        Lyapunov::<f64, 2, 1>::new(VMAX, &p, &Matrix2x1::new(f64::NAN, 0.0)),
        Err(Error::NonFiniteInput)
    );
    // P B does not fit f32.
    assert_eq!(
        Lyapunov::<f32, 2, 1>::new(VMAX, &(p * 1e300), &b),
        Err(Error::OperatorOverflow)
    );
    let law = Lyapunov::<f64, 2, 1>::new(VMAX, &p, &b).unwrap();
    let copy = law;
    assert_eq!(
        law.command(&Vector2::new(f64::NAN, 0.0), &Vector1::new(1.0)),
        Err(Error::NonFiniteInput)
    );
    assert_eq!(
        law.command(&Vector2::new(1.0, 0.0), &Vector1::new(f64::NAN)),
        Err(Error::NonFiniteInput)
    );
    // zᵀPB overflows: 1.5e308 · (−0.5) + 1.5e308 · (−1) = −∞ (finite input, non-finite
    // result).
    assert_eq!(
        law.command(&Vector2::new(1.5e308, 1.5e308), &Vector1::new(1.0)),
        Err(Error::NonFiniteState)
    );
    assert_eq!(law, copy);
    assert_eq!(*law.gain(), p * b);
}

/// Modulated homogeneous friction, literally: the most recent local extremum of the sampled
/// deformation found by scanning the whole history (an independent formulation of the
/// peak operator `P[·]`: the last sample `Δ_k` with `(Δ_k − Δ_{k−1})(Δ_{k+1} − Δ_k) < 0`
/// after dropping repeated samples), then `v = V_max H(g_n |P| − |f|)`.
fn friction_reference(history: &[f64], gain: f64, f: f64) -> f64 {
    let mut h: Vec<f64> = vec![0.0]; // at rest before the first sample
    for &d in history {
        if d != *h.last().unwrap() {
            h.push(d);
        }
    }
    let mut peak = 0.0;
    for k in 1..h.len().saturating_sub(1) {
        if (h[k] - h[k - 1]) * (h[k + 1] - h[k]) < 0.0 {
            peak = h[k];
        }
    }
    VMAX * heaviside(gain * f64::abs(peak) - f.abs())
}

#[test]
fn modulated_friction_tracks_the_last_extremum_and_switches_by_it() {
    let g = 1000.0; // N/m
    let mut law = ModulatedFriction::<f64, 1>::new(VMAX, g).unwrap();
    // A deformation history (m) with reversals at 3 mm, −2 mm, a plateau and 1.5 mm.
    let history = [
        0.001, 0.002, 0.003, 0.0025, 0.0, -0.002, -0.002, -0.001, 0.0015, 0.0015, 0.001,
    ];
    let forces = [0.5, 1.0, 2.9, 2.9, 3.0, 3.1, 1.9, 2.0, 1.49, 1.5, 1.51];
    let expected_peak = [
        0.0, 0.0, 0.0, 0.003, 0.003, 0.003, 0.003, -0.002, -0.002, -0.002, 0.0015,
    ];
    let mut on = 0;
    for k in 0..history.len() {
        let v = law
            .command(&Vector1::new(history[k]), &Vector1::new(forces[k]))
            .unwrap()[0];
        assert_eq!(law.extremum()[0], expected_peak[k], "sample {k}");
        assert_eq!(
            v,
            friction_reference(&history[..=k], g, forces[k]),
            "sample {k}"
        );
        on += (v > 0.0) as usize;
    }
    // Off before the first reversal; on at 2.9 N < 3 N; off at the equality 3.0 N and
    // above; on at 1.9 N < 2 N; off at 2.0 N; on at 1.49 N, off at 1.5 N (equality) —
    // both branches and both equalities.
    assert_eq!(on, 4);
}

#[test]
fn modulated_friction_two_dampers_are_independent() {
    let mut law = ModulatedFriction::<f64, 2>::new(VMAX, 500.0).unwrap();
    let d1 = [0.01, 0.02, 0.015, 0.01];
    let d2 = [-0.01, -0.005, -0.002, -0.004];
    for k in 0..4 {
        let f = Vector2::new(4.0, 0.5);
        let v = law.command(&Vector2::new(d1[k], d2[k]), &f).unwrap();
        assert_eq!(v[0], friction_reference(&d1[..=k], 500.0, 4.0), "{k}");
        assert_eq!(v[1], friction_reference(&d2[..=k], 500.0, 0.5), "{k}");
    }
    assert_eq!(*law.extremum(), Vector2::new(0.02, -0.002));
}

#[test]
fn modulated_friction_refuses_bad_input_and_keeps_its_history() {
    assert_eq!(
        ModulatedFriction::<f64, 1>::new(f64::NAN, 1.0),
        Err(Error::InvalidParameter(Param::Saturation))
    );
    for bad in [0.0, -2.0, f64::INFINITY, f64::NAN] {
        assert_eq!(
            ModulatedFriction::<f64, 1>::new(VMAX, bad),
            Err(Error::InvalidParameter(Param::Weight)),
            "{bad}"
        );
    }
    let mut law = ModulatedFriction::<f64, 2>::new(VMAX, 100.0).unwrap();
    for d in [0.01, 0.02, 0.01] {
        law.command(&Vector2::new(d, -d), &Vector2::new(0.0, 0.0))
            .unwrap();
    }
    let before = law;
    assert_eq!(
        law.command(&Vector2::new(f64::NAN, 0.0), &Vector2::new(1.0, 1.0)),
        Err(Error::NonFiniteInput)
    );
    assert_eq!(
        law.command(&Vector2::new(0.0, 0.0), &Vector2::new(1.0, f64::NAN)),
        Err(Error::NonFiniteInput)
    );
    assert_eq!(law, before);
    // g_n |P| overflows (finite input): refused, history kept.
    let mut big = ModulatedFriction::<f64, 1>::new(VMAX, 1e300).unwrap();
    for d in [1e10, 2e10] {
        big.command(&Vector1::new(d), &Vector1::new(0.0)).unwrap();
    }
    let before = big;
    assert_eq!(
        big.command(&Vector1::new(1e10), &Vector1::new(0.0)),
        Err(Error::NonFiniteState)
    );
    assert_eq!(big, before);
    // After refusals the law goes on as if they had not happened.
    let v = law
        .command(&Vector2::new(0.0, 0.0), &Vector2::new(1.0, 1.0))
        .unwrap();
    assert_eq!(v, Vector2::new(VMAX, VMAX)); // peaks ±0.02 m: f_c = 2 N > 1 N
}

/// The laws in `f32` take the same decisions as the `f64` formulas on values exact in both
/// (powers of two and small integers, so no rounding can move a sign or an equality).
#[test]
fn laws_in_f32_decide_like_the_formulas() {
    let clipped = ClippedOptimal::<f32, 1>::new(VMAX).unwrap();
    for (fc, f) in [
        (8.0, 2.0),
        (8.0, 16.0),
        (-8.0, -2.0),
        (8.0, 8.0),
        (8.0, 0.0),
    ] {
        let got = clipped
            .command(&Vector1::new(fc as f32), &Vector1::new(f as f32))
            .unwrap()[0];
        assert_eq!(got, clipped_reference(fc, f) as f32, "{fc} {f}");
    }
    let p = Matrix2::new(2.0, 0.5, 0.5, 1.0);
    let b = Matrix2x1::new(0.0, -1.0);
    let lyap = Lyapunov::<f32, 2, 1>::new(VMAX, &p, &b).unwrap();
    for (z, f) in [
        ((1.0, 1.0), 4.0),
        ((1.0, 1.0), -4.0),
        ((-2.0, 0.0), 4.0),
        ((0.0, 0.0), 1.0),
    ] {
        let zf = Vector2::new(z.0 as f32, z.1 as f32);
        let got = lyap.command(&zf, &Vector1::new(f as f32)).unwrap()[0];
        let want = lyapunov_reference(&p, &b, &Vector2::new(z.0, z.1), &Vector1::new(f))[0];
        assert_eq!(got, want as f32, "{z:?} {f}");
    }
    let mut friction = ModulatedFriction::<f32, 1>::new(VMAX, 4.0).unwrap();
    let history = [0.5, 1.0, 0.75, 0.25];
    let forces = [1.0, 1.0, 3.0, 4.0];
    for k in 0..4 {
        let got = friction
            .command(
                &Vector1::new(history[k] as f32),
                &Vector1::new(forces[k] as f32),
            )
            .unwrap()[0];
        let want = friction_reference(&history[..=k], 4.0, forces[k]) as f32;
        assert_eq!(got, want, "sample {k}");
    }
    assert_eq!(friction.extremum()[0], 1.0);
}
