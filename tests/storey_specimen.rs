//! `hybrid::StoreySpecimen` (issue 31): a storey specimen on two degrees of freedom of a
//! shear-type model for `hybrid::Split` — the command `u_i − u_{i−1}`, the force vector
//! `+f` at DOF `i`, `−f` at DOF `i − 1` (`i = 0`: the ground), the stiffness `Lᵀ k L` it
//! adds. Checked against the incidence row `L` written here, for equilibrium, and by a
//! linear specimen reproducing the all-numerical `KrAlpha` run of the whole building.
#![allow(clippy::needless_range_loop)]

use aemstep::hybrid::{Split, StoreySpecimen};
use aemstep::models::{self, Rows, base_excitation};
use aemstep::nalgebra::{SMatrix, SVector};
use aemstep::{Error, KrAlpha, Param, Real, Stepper};

const EPS: f64 = f64::EPSILON;
const B: (Rows<5>, Rows<5>, Rows<5>) = models::five_storey_building();
const K1: f64 = models::FIVE_STOREY_STIFFNESS;

/// The incidence row of storey `i` (`L u = u_i − u_{i−1}`), written from the definition.
fn incidence<const N: usize>(i: usize) -> [f64; N] {
    let mut l = [0.0; N];
    l[i] = 1.0;
    if i > 0 {
        l[i - 1] = -1.0;
    }
    l
}

/// Command `L u`, force `Lᵀ f`, stiffness `Lᵀ k L`, each against `L`; the force vector of an
/// inner storey sums to exactly zero (equilibrium: the specimen is internal), that of the
/// ground storey to `f` (its reaction is the ground's); `add_force` accumulates.
#[test]
fn mapping_is_the_storey_incidence_and_in_equilibrium() {
    let u = SVector::<f64, 5>::from([0.013, -0.021, 0.0345, 0.05, -0.0125]);
    for i in 0..5 {
        let s = StoreySpecimen::<5>::new(i).unwrap();
        assert_eq!(s.storey(), i);
        let l = incidence::<5>(i);
        let d = if i > 0 { u[i] - u[i - 1] } else { u[i] };
        assert_eq!(s.command(&u).to_bits(), d.to_bits());
        for f in [1.0, -3.5e6, 0.1] {
            let r = s.force(f);
            for j in 0..5 {
                assert_eq!(r[j], l[j] * f, "storey {i}, DOF {j}");
            }
            let sum: f64 = r.iter().sum();
            assert_eq!(sum, if i > 0 { 0.0 } else { f }, "storey {i}");
            // Virtual work: r · u = f (L u), to rounding of the two products.
            assert!((r.dot(&u) - f * s.command(&u)).abs() <= 2.0 * EPS * (f * u.amax()).abs());
        }
        let k = s.stiffness(K1);
        for a in 0..5 {
            for b in 0..5 {
                assert_eq!(k[a][b], l[a] * K1 * l[b], "storey {i}: ({a}, {b})");
            }
        }
        let mut r = s.force(2.0);
        s.add_force(&mut r, 3.0);
        assert_eq!(r, s.force(5.0));
    }
    // Every storey's stiffness added to nothing is the shear building's K (exact: sums of
    // ±k and 0).
    let mut k = [[0.0; 5]; 5];
    for i in 0..5 {
        k = models::add(&k, &StoreySpecimen::<5>::new(i).unwrap().stiffness(K1));
    }
    assert_eq!(k, B.2);
    assert_eq!(
        StoreySpecimen::<5>::new(5),
        Err(Error::InvalidParameter(Param::Storey))
    );
    assert_eq!(
        StoreySpecimen::<0>::new(0),
        Err(Error::InvalidParameter(Param::Storey))
    );
    const TOP: StoreySpecimen<5> = aemstep::unwrap_const!(StoreySpecimen::new(4));
    assert_eq!(TOP.storey(), 4);
}

/// A strong ground pulse (m/s²) at step `n` of `h`.
fn pulse(n: usize, h: f64) -> f64 {
    let t = n as f64 * h;
    6.0 * (-((t - 0.6) / 0.25).powi(2)).exp() * (11.0 * t).sin()
}

/// The 5-storey building, 4096 steps of h = 1/1024 s under the pulse: storey `i` a linear
/// specimen of the storey stiffness (its force `k (u_i − u_{i−1})` at the split's command,
/// mapped by `StoreySpecimen`), the rest numerical (`K_num = K − Lᵀ k L`), against the
/// all-numerical KR-α run of `K`. The same recurrence; only the rounding differs
/// (`G K_num ū + G r̄` against `G K ū`): measured ≤ 4.8e-15 of the largest displacement in `f64`,
/// ≤ 1.1e-6 in `f32` (printed); bound 16·N·ε of each (1.8e-14, 9.5e-6).
#[test]
fn linear_storey_specimen_is_the_all_numerical_run() {
    fn run<T: Real>(
        storey: usize,
        rho: Option<f64>,
        load: impl Fn(usize) -> SVector<T, 5>,
    ) -> (f64, f64) {
        let sm = |r: &Rows<5>| SMatrix::<f64, 5, 5>::from_fn(|i, j| r[i][j]);
        let spec = StoreySpecimen::<5>::new(storey).unwrap();
        // K_num: the building without storey `storey`, written from the storey stiffnesses.
        let mut ks = [K1; 5];
        ks[storey] = 0.0;
        let (_, k_num) = models::shear_building([models::FIVE_STOREY_MASS; 5], ks);
        assert_eq!(models::add(&k_num, &spec.stiffness(K1)), B.2);
        let (m, c, k, kn) = (sm(&B.0), sm(&B.1), sm(&B.2), sm(&k_num));
        let h = 1.0 / 1024.0;
        let (sys, all) = match rho {
            Some(r) => (
                Split::<T, 5>::new(&m, &c, &k, &kn, h, r).unwrap(),
                KrAlpha::<T, 5>::new(&m, &c, &k, h, r).unwrap(),
            ),
            None => (
                Split::<T, 5>::chen_ricles(&m, &c, &k, &kn, h).unwrap(),
                KrAlpha::<T, 5>::chen_ricles(&m, &c, &k, h).unwrap(),
            ),
        };
        let z = SVector::<T, 5>::zeros();
        let k1 = T::from_f64_rounded(K1);
        let mut s = sys.start(&z, &z, &z, &load(0)).unwrap();
        let mut a = all.start(&z, &z, &load(0)).unwrap();
        let (mut err, mut size) = (0.0f64, 0.0f64);
        for n in 1..=4096 {
            let d = spec.command(&sys.command(&s));
            sys.complete(&mut s, &spec.force(k1 * d), &load(n)).unwrap();
            all.try_step_with_previous_input(&mut a, &load(n - 1), &load(n))
                .unwrap();
            for i in 0..5 {
                let (x, y) = (s.state().u()[i].as_f64(), a.u()[i].as_f64());
                err = err.max((x - y).abs());
                size = size.max(y.abs());
            }
        }
        (err, size)
    }
    let iota = base_excitation(&B.0);
    let h = 1.0 / 1024.0;
    let load64 = |n: usize| SVector::<f64, 5>::from_fn(|i, _| iota[i][0] * pulse(n, h));
    let load32 = |n: usize| load64(n).cast::<f32>();
    for storey in [0, 2, 4] {
        for (name, rho) in [("KR-α ρ∞ = 0.9", Some(0.9)), ("Chen–Ricles", None)] {
            let (e64, s64) = run::<f64>(storey, rho, load64);
            let (e32, s32) = run::<f32>(storey, rho, load32);
            eprintln!(
                "storey {storey}, {name}: f64 {:.2e}, f32 {:.2e} (relative)",
                e64 / s64,
                e32 / s32
            );
            assert!(s64 > 1e-3, "the pulse must move the building");
            assert!(
                e64 <= 16.0 * 5.0 * EPS * s64,
                "storey {storey}, {name}: f64 {e64:e}"
            );
            assert!(
                e32 <= 16.0 * 5.0 * f64::from(f32::EPSILON) * s32,
                "storey {storey}, {name}: f32 {e32:e}"
            );
        }
    }
}
