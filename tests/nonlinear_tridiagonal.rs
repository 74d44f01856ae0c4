//! The tridiagonal Newton path of `Nonlinear` (`HistoryModel::trial_tridiagonal`): the same
//! steps as the dense path (LU with partial pivoting on the dense tangent), its fallback to
//! pivoting when `J` is not positive definite, its errors, and the banded products.
//!
//! The dense path is the independent check: it forms `J` from `HistoryModel::tangent` and
//! factors it by pivoted LU, sharing nothing with the `L D Lᵀ` solve but the equations.

#[path = "support/checks.rs"]
mod checks;
#[path = "../scenes/modal/elcentro.rs"]
mod elcentro;
mod support;

use aemstep::hysteresis::{Bilinear, BoucWen, HistoryModel, ShearBuilding, Trial};
use aemstep::nalgebra::{SMatrix, SVector};
use aemstep::{
    Error, NewtonSettings, Nonlinear, SymTridiagonal, Tangent, TridiagonalTangent, models,
};
use checks::bits;
use support::Rng;

const EPS: f64 = f64::EPSILON;

/// A model seen without its tridiagonal trials: the stepper takes the dense path.
struct Dense<'a, M>(&'a M);

impl<const N: usize, M: HistoryModel<f64, N>> HistoryModel<f64, N> for Dense<'_, M> {
    type History = M::History;
    fn initial_history(&self) -> M::History {
        self.0.initial_history()
    }
    fn mass(&self) -> SMatrix<f64, N, N> {
        self.0.mass()
    }
    fn trial(
        &self,
        h: &M::History,
        u: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> Trial<f64, N, M::History> {
        self.0.trial(h, u, v)
    }
    fn tangent(
        &self,
        h: &M::History,
        u: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> Option<Tangent<f64, N>> {
        self.0.tangent(h, u, v)
    }
}

/// El Centro NS ×2 (m/s²) linearly interpolated to h = DT/4 = 0.005 s, sample `n`.
fn ground(n: usize) -> f64 {
    let (i, k) = (n / 4, n % 4);
    let a = &elcentro::AG_F64;
    if i + 1 >= a.len() {
        return 0.0;
    }
    2.0 * (a[i] + (k as f64 / 4.0) * (a[i + 1] - a[i]))
}

fn five_storey<L: aemstep::hysteresis::Law<f64> + Copy>(law: L) -> ShearBuilding<f64, L, 5> {
    let (m, c, _) = models::five_storey_building();
    ShearBuilding::new(models::floor_masses(&m), [law; 5], &c).unwrap()
}

/// Run a model over El Centro ×2 at h = 0.005 s; the displacement history.
fn run<M: HistoryModel<f64, 5>>(model: &M, steps: usize, tol: f64) -> Vec<SVector<f64, 5>> {
    let stepper = Nonlinear::<f64, 5>::new(0.005, NewtonSettings::up_to(50, tol)).unwrap();
    let z = SVector::zeros();
    let m = SVector::<f64, 5>::from_fn(|i, _| model.mass()[(i, i)]);
    let load = |ag: f64| m * -ag;
    let (mut s, mut h) = stepper
        .start_with_history(model, &z, &z, &load(ground(0)), &model.initial_history())
        .unwrap();
    let mut out = Vec::with_capacity(steps);
    for n in 1..=steps {
        stepper
            .try_step_with_history(model, &mut s, &mut h, &load(ground(n)))
            .unwrap();
        out.push(*s.u());
    }
    out
}

/// The yielding 5-storey building (bilinear and Bouc–Wen storeys) over the whole record:
/// the tridiagonal path follows the dense one to the Newton tolerance.
///
/// Both solve the same equations from the same predictor; their Newton corrections differ
/// by rounding (`κ(J) ε`, `κ(J) < 10` here) and each converged step leaves a residual of at
/// most the tolerance `τ = 1e-12`. The trapezoidal rule does not amplify a perturbation
/// (its spectral radius is 1), so over `n` steps the two drift apart by at most about
/// `n τ` relative to the response, a random walk in practice: measured 1.2e-15 of the peak
/// (bilinear and Bouc–Wen) over 15 976 steps, bound `n τ = 1.6e-8` — far above, as a bound
/// from the tolerance is; so a second bound from rounding alone, `2¹² ε` (the measured
/// values are 5.4 and 5.2 ε).
#[test]
fn tridiagonal_path_follows_the_dense_path() {
    let steps = (elcentro::SAMPLES - 1) * 4;
    let tol = 1e-12;
    let bilinear = five_storey(Bilinear::<f64>::new(1e8, 3e6, 0.05).unwrap());
    let bouc_wen = five_storey(BoucWen::<f64>::new(1e8, 3e6, 0.05, 0.5, 0.5, 2.0).unwrap());
    type History = Vec<SVector<f64, 5>>;
    let cases: [(&str, History, History); 2] = [
        (
            "bilinear",
            run(&bilinear, steps, tol),
            run(&Dense(&bilinear), steps, tol),
        ),
        (
            "Bouc–Wen",
            run(&bouc_wen, steps, tol),
            run(&Dense(&bouc_wen), steps, tol),
        ),
    ];
    for (name, band, dense) in cases {
        let peak = dense.iter().fold(0.0f64, |p, u| p.max(u.amax()));
        let worst = band
            .iter()
            .zip(&dense)
            .fold(0.0f64, |w, (a, b)| w.max((a - b).amax()));
        println!(
            "{name}: tridiagonal vs dense {:.2e} of the peak {peak:.4} m",
            worst / peak
        );
        assert!(peak > 0.05, "{name}: the building must yield (peak {peak})");
        assert!(worst <= steps as f64 * tol * peak, "{name}: {worst:e}");
        assert!(
            worst <= 4096.0 * EPS * peak,
            "{name}: {worst:e} (rounding bound)"
        );
    }
}

/// A chain of masses joined by springs of negative stiffness (a snap-through, linearized):
/// `J = M + (h²/4) K` is indefinite, the `L D Lᵀ` solve declines, and the step pivots on the
/// same `J`: every entry of `J`, `M q` and `F` is formed the same way on both paths, and
/// LU on a tridiagonal matrix only adds exact zeros, so the two are bit-identical.
struct Chain {
    k: [f64; 3],
}

impl Chain {
    fn band(&self) -> SymTridiagonal<f64, 3> {
        let k = self.k;
        SymTridiagonal {
            diagonal: SVector::from([k[0] + k[1], k[1] + k[2], k[2]]),
            off: SVector::from([0.0, -k[1], -k[2]]),
        }
    }
}

impl HistoryModel<f64, 3> for Chain {
    type History = ();
    fn initial_history(&self) {}
    fn mass(&self) -> SMatrix<f64, 3, 3> {
        SMatrix::identity()
    }
    fn trial(&self, _: &(), u: &SVector<f64, 3>, _: &SVector<f64, 3>) -> Trial<f64, 3, ()> {
        Trial {
            force: self.band().mul(u),
            history: (),
            branch: 0,
        }
    }
    fn tangent(&self, _: &(), _: &SVector<f64, 3>, _: &SVector<f64, 3>) -> Option<Tangent<f64, 3>> {
        Some(Tangent {
            stiffness: self.band().to_matrix(),
            damping: SMatrix::zeros(),
        })
    }
    fn trial_tridiagonal(
        &self,
        h: &(),
        u: &SVector<f64, 3>,
        v: &SVector<f64, 3>,
        tangent: &mut TridiagonalTangent<f64, 3>,
    ) -> Option<Trial<f64, 3, ()>> {
        *tangent = TridiagonalTangent {
            mass: SymTridiagonal {
                diagonal: SVector::repeat(1.0),
                off: SVector::zeros(),
            },
            stiffness: self.band(),
            damping: SymTridiagonal {
                diagonal: SVector::zeros(),
                off: SVector::zeros(),
            },
        };
        Some(self.trial(h, u, v))
    }
}

#[test]
fn indefinite_newton_matrix_pivots_like_the_dense_path() {
    let chain = Chain {
        k: [-300.0, -500.0, -200.0],
    };
    let stepper = Nonlinear::<f64, 3>::new(0.1, NewtonSettings::up_to(4, 1e-12)).unwrap();
    // J = I + 0.0025 K has a negative pivot (1 − 2 = −1 in the first row): the L D Lᵀ
    // solve must decline.
    let c = 0.0025;
    assert!(1.0 + c * (chain.k[0] + chain.k[1]) < 0.0);
    let z = SVector::zeros();
    let u0 = SVector::from([1e-3, -2e-3, 5e-4]);
    let mut a = stepper.start(&aemstep_model(&chain), &u0, &z, &z).unwrap();
    let mut b = a;
    for n in 1..=20 {
        let p = SVector::from([0.0, (0.3 * n as f64).sin(), 0.0]);
        stepper
            .try_step_with_history(&chain, &mut a, &mut (), &p)
            .unwrap();
        stepper
            .try_step_with_history(&Dense(&chain), &mut b, &mut (), &p)
            .unwrap();
        assert_eq!(bits(&a), bits(&b), "step {n}");
    }
    assert!(
        a.u().amax() > 1e3 * u0.amax(),
        "the chain must run away: {}",
        a.u()
    );
}

/// `Chain` as a memoryless [`aemstep::Model`] for [`Nonlinear::start`].
fn aemstep_model(chain: &Chain) -> impl aemstep::Model<f64, 3> + '_ {
    struct M<'a>(&'a Chain);
    impl aemstep::Model<f64, 3> for M<'_> {
        fn mass(&self) -> SMatrix<f64, 3, 3> {
            SMatrix::identity()
        }
        fn force(&self, u: &SVector<f64, 3>, _: &SVector<f64, 3>) -> SVector<f64, 3> {
            self.0.band().mul(u)
        }
    }
    M(chain)
}

/// A model whose tridiagonal trials break at a chosen call: a NaN force, a NaN tangent
/// entry or a NaN mass entry.
struct Breaks<'a, M> {
    inner: &'a M,
    at: u32,
    what: u8,
    calls: core::cell::Cell<u32>,
}

impl<M: HistoryModel<f64, 5>> HistoryModel<f64, 5> for Breaks<'_, M> {
    type History = M::History;
    fn initial_history(&self) -> M::History {
        self.inner.initial_history()
    }
    fn mass(&self) -> SMatrix<f64, 5, 5> {
        self.inner.mass()
    }
    fn trial(
        &self,
        h: &M::History,
        u: &SVector<f64, 5>,
        v: &SVector<f64, 5>,
    ) -> Trial<f64, 5, M::History> {
        self.inner.trial(h, u, v)
    }
    fn tangent(
        &self,
        h: &M::History,
        u: &SVector<f64, 5>,
        v: &SVector<f64, 5>,
    ) -> Option<Tangent<f64, 5>> {
        self.inner.tangent(h, u, v)
    }
    fn trial_tridiagonal(
        &self,
        h: &M::History,
        u: &SVector<f64, 5>,
        v: &SVector<f64, 5>,
        tangent: &mut TridiagonalTangent<f64, 5>,
    ) -> Option<Trial<f64, 5, M::History>> {
        let mut t = self.inner.trial_tridiagonal(h, u, v, tangent)?;
        let n = self.calls.get() + 1;
        self.calls.set(n);
        if n == self.at {
            match self.what {
                0 => t.force[2] = f64::NAN,
                1 => tangent.stiffness.off[3] = f64::INFINITY,
                _ => tangent.mass.diagonal[4] = f64::NAN,
            }
        }
        Some(t)
    }
}

/// Each break gives its variant — the same as the dense path gives for the same bad
/// value — and leaves the state and the history bit-identical, at the first trial of a
/// step (the predictor) and at a later one.
#[test]
fn broken_tridiagonal_trials_give_typed_errors_and_change_nothing() {
    let building = five_storey(Bilinear::<f64>::new(1e8, 3e6, 0.05).unwrap());
    let stepper = Nonlinear::<f64, 5>::new(0.005, NewtonSettings::up_to(50, 1e-12)).unwrap();
    let z = SVector::zeros();
    let (mut s, mut h) = stepper
        .start_with_history(&building, &z, &z, &z, &building.initial_history())
        .unwrap();
    // Into the strong motion, until a step yields (changes the history).
    let mut n = 0;
    loop {
        n += 1;
        let before = h;
        let p = building.ground_load(ground(n));
        stepper
            .try_step_with_history(&building, &mut s, &mut h, &p)
            .unwrap();
        if h != before {
            break;
        }
        assert!(n < 4000, "the building never yielded");
    }
    let p = building.ground_load(ground(n + 1));
    for (what, expected) in [
        (0, Error::NonFiniteForce),
        (1, Error::NonFiniteForce),
        (2, Error::NonFiniteInput),
    ] {
        for at in [1, 2] {
            let broken = Breaks {
                inner: &building,
                at,
                what,
                calls: core::cell::Cell::new(0),
            };
            let (mut s1, mut h1) = (s, h);
            let got = stepper.try_step_with_history(&broken, &mut s1, &mut h1, &p);
            // The tangent is read only where a system is solved: a break at the last
            // (converged) trial leaves nothing to solve and the step succeeds.
            if what == 1 && at == 2 {
                assert!(got.is_ok(), "{got:?}");
                continue;
            }
            assert_eq!(got, Err(expected), "break {what} at trial {at}");
            assert_eq!(bits(&s1), bits(&s), "state changed (break {what} at {at})");
            assert_eq!(h1, h, "history changed (break {what} at {at})");
        }
    }
}

/// `SymTridiagonal::mul` is the dense product, bit for bit, and a shear building's banded
/// trial equals its dense trial, tangent and mass entry for entry.
#[test]
fn banded_products_equal_dense_ones() {
    let mut rng = Rng::new(23);
    for _ in 0..200 {
        let a = SymTridiagonal::<f64, 6> {
            diagonal: SVector::from_fn(|_, _| range(&mut rng, -10.0, 10.0)),
            off: SVector::from_fn(|i, _| {
                if i == 0 {
                    0.0
                } else {
                    range(&mut rng, -10.0, 10.0)
                }
            }),
        };
        let dense = a.to_matrix();
        let x = SVector::<f64, 6>::from_fn(|_, _| range(&mut rng, -1.0, 1.0));
        assert_eq!(a.mul(&x), dense * x);
    }
    let building = five_storey(BoucWen::<f64>::new(1e8, 3e6, 0.05, 0.5, 0.5, 2.0).unwrap());
    let h = building.initial_history();
    let zero = SymTridiagonal {
        diagonal: SVector::zeros(),
        off: SVector::zeros(),
    };
    let mut t = TridiagonalTangent {
        mass: zero,
        stiffness: zero,
        damping: zero,
    };
    for _ in 0..50 {
        let u = SVector::<f64, 5>::from_fn(|_, _| range(&mut rng, -0.1, 0.1));
        let v = SVector::<f64, 5>::from_fn(|_, _| range(&mut rng, -1.0, 1.0));
        let banded = building.trial_tridiagonal(&h, &u, &v, &mut t).unwrap();
        let trial = building.trial(&h, &u, &v);
        assert_eq!(banded, trial);
        let dense = building.tangent(&h, &u, &v).unwrap();
        assert_eq!(t.stiffness.to_matrix(), dense.stiffness);
        assert_eq!(t.damping.to_matrix(), dense.damping);
        assert_eq!(t.mass.to_matrix(), building.mass());
    }
    // A damping matrix with a coupling beyond the neighbours keeps the dense path.
    let (m, mut c, _) = models::five_storey_building();
    c[0][2] = 1.0;
    c[2][0] = 1.0;
    let coupled = ShearBuilding::new(
        models::floor_masses(&m),
        [Bilinear::<f64>::new(1e8, 3e6, 0.05).unwrap(); 5],
        &c,
    )
    .unwrap();
    let u = SVector::repeat(0.01);
    assert!(
        coupled
            .trial_tridiagonal(&coupled.initial_history(), &u, &u, &mut t)
            .is_none()
    );
}

fn range(rng: &mut Rng, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * 0.5 * (rng.uniform() + 1.0)
}
