//! The paper's conservative nonlinear examples and the runs that track their energy:
//! Example 6, the pendulum `θ'' + sin θ = 0` (l = g = 9.81), and Example 7, the elastic
//! pendulum. Shared by `tests/nonlinear.rs` (which asserts on the runs) and
//! `xtask/src/bin/energy.rs` (which prints them).
#![allow(dead_code)]

use aemstep::{Error, Model, NewtonSettings, Nonlinear, Real, Tangent};
use nalgebra::{SMatrix, SVector, matrix, vector};

/// Gravity (m/s²); the pendulum's length is the same number, so `g/l = 1`.
pub const G: f64 = 9.81;

fn r<T: Real>(x: f64) -> T {
    T::from_f64_rounded(x)
}

/// The largest entry of `errors`, and the largest over the first tenth of the `steps` a
/// run was asked for (steps `n` with `10 n ≤ steps`).
pub fn max_and_first_tenth(errors: &[f64], steps: u64) -> (f64, f64) {
    let all = errors.iter().fold(0.0, |m: f64, &e| m.max(e));
    let tenth = errors.len().min((steps / 10) as usize);
    (all, errors[..tenth].iter().fold(0.0, |m: f64, &e| m.max(e)))
}

// ---------------------------------------------------------------- Example 6: pendulum

/// `θ'' + (g/l) sin θ = 0` with `l = g = 9.81` (so `g/l = 1`).
pub struct Pendulum;

impl Model<f64, 1> for Pendulum {
    fn mass(&self) -> SMatrix<f64, 1, 1> {
        matrix![1.0]
    }
    fn force(&self, u: &SVector<f64, 1>, _v: &SVector<f64, 1>) -> SVector<f64, 1> {
        vector![u[0].sin()]
    }
    fn tangent(&self, u: &SVector<f64, 1>, _v: &SVector<f64, 1>) -> Option<Tangent<f64, 1>> {
        Some(Tangent {
            stiffness: matrix![u[0].cos()],
            damping: matrix![0.0],
        })
    }
}

/// The pendulum's initial angle (at rest): 0.4π.
pub const THETA0: f64 = 0.4 * std::f64::consts::PI;

/// Energy `−g l cos θ + (l θ')² / 2` (per unit mass).
pub fn pendulum_energy(theta: f64, omega: f64) -> f64 {
    -G * G * theta.cos() + 0.5 * G * G * omega * omega
}

/// The pendulum from θ0 at rest, step `h`, to `t_end` (default Newton settings):
/// `(θ_n, θ'_n)` for n = 1..=steps.
pub fn pendulum_run(h: f64, t_end: f64) -> Vec<(f64, f64)> {
    let st = Nonlinear::<f64, 1>::new(h, NewtonSettings::default()).unwrap();
    let mut s = st
        .start(&Pendulum, &vector![THETA0], &vector![0.0], &vector![0.0])
        .unwrap();
    (1..=(t_end / h).round() as u64)
        .map(|_| {
            st.try_step(&Pendulum, &mut s, &vector![0.0]).unwrap();
            (s.u()[0], s.v()[0])
        })
        .collect()
}

// ---------------------------------------------------------------- Example 7: elastic pendulum

/// Paper data: L = 3.0443 m, EA = 1e4 N, m = 6.667 kg; initial sideways speed 7.72 m/s.
pub const EL_L: f64 = 3.0443;
pub const EL_EA: f64 = 1.0e4;
pub const EL_M: f64 = 6.667;
pub const EL_SPEED: f64 = 7.72;
/// Initial kinetic energy m·7.72²/2 = 198.7 J, the scale energy errors are quoted against
/// (the total energy itself is −0.44 J, close to zero).
pub const EL_KE0: f64 = 0.5 * EL_M * EL_SPEED * EL_SPEED;

/// Elastic (soft) pendulum: `m u'' + (EA/L)(1 − L/r) u = (0, m g)`, `u = (x, y)`, `y`
/// downward from the pivot, `r = |u|`. The tangent is optional so both Jacobian paths run.
pub struct Elastic {
    pub analytic: bool,
}

impl<T: Real> Model<T, 2> for Elastic {
    fn mass(&self) -> SMatrix<T, 2, 2> {
        SMatrix::identity() * r::<T>(EL_M)
    }
    fn force(&self, u: &SVector<T, 2>, _v: &SVector<T, 2>) -> SVector<T, 2> {
        let k = r::<T>(EL_EA / EL_L);
        let len = u.norm();
        u * (k * (T::one() - r::<T>(EL_L) / len))
    }
    fn tangent(&self, u: &SVector<T, 2>, _v: &SVector<T, 2>) -> Option<Tangent<T, 2>> {
        // ∂F/∂u = k (1 − L/r) I + k L / r³ u uᵀ
        let k = r::<T>(EL_EA / EL_L);
        let l = r::<T>(EL_L);
        let len = u.norm();
        let stiffness = SMatrix::<T, 2, 2>::identity() * (k * (T::one() - l / len))
            + u * u.transpose() * (k * l / (len * len * len));
        self.analytic.then(|| Tangent {
            stiffness,
            damping: SMatrix::zeros(),
        })
    }
}

/// Total energy `m |v|²/2 + (EA/L)(r − L)²/2 − m g y`.
pub fn elastic_energy(u: &SVector<f64, 2>, v: &SVector<f64, 2>, g: f64) -> f64 {
    let stretch = u.norm() - EL_L;
    0.5 * EL_M * v.norm_squared() + 0.5 * EL_EA / EL_L * stretch * stretch - EL_M * g * u[1]
}

/// One elastic-pendulum run: every completed step's energy error and position.
pub struct ElasticRun {
    /// Steps asked for.
    pub steps: u64,
    /// |E − E0| (J) after each completed step.
    pub energy_error: Vec<f64>,
    /// Position after each completed step.
    pub trajectory: Vec<SVector<f64, 2>>,
    /// The step at which Newton failed, and why (the run stops there).
    pub failed: Option<(u64, Error)>,
    pub max_iterations: u32,
}

impl ElasticRun {
    /// (max |E − E0| over the run, the same over the first tenth of it).
    pub fn energy(&self) -> (f64, f64) {
        max_and_first_tenth(&self.energy_error, self.steps)
    }
    /// The first time (s) the stretch |r − L| exceeds L, at step `h`.
    pub fn blow_up(&self, h: f64) -> Option<f64> {
        self.trajectory
            .iter()
            .position(|u| (u.norm() - EL_L).abs() > EL_L)
            .map(|n| (n + 1) as f64 * h)
    }
}

/// Elastic pendulum from (0, L) with x' = 7.72 m/s, gravity `g`, step `h`, to `t_end`
/// (Newton up to 50 iterations at the default tolerance of `T`).
pub fn elastic_run<T: Real>(model: &Elastic, h: f64, t_end: f64, g: f64) -> ElasticRun {
    let st = Nonlinear::<T, 2>::new(
        r(h),
        NewtonSettings::up_to(50, NewtonSettings::<T>::default_tolerance()),
    )
    .unwrap();
    let p = vector![T::zero(), r::<T>(EL_M * g)];
    let (u0, v0) = (vector![0.0, EL_L], vector![EL_SPEED, 0.0]);
    let mut s = st
        .start(model, &u0.map(r::<T>), &v0.map(r::<T>), &p)
        .unwrap();
    let e0 = elastic_energy(&u0, &v0, g);
    let mut run = ElasticRun {
        steps: (t_end / h).round() as u64,
        energy_error: Vec::new(),
        trajectory: Vec::new(),
        failed: None,
        max_iterations: 0,
    };
    for n in 1..=run.steps {
        match st.try_step(model, &mut s, &p) {
            Ok(rep) => run.max_iterations = run.max_iterations.max(rep.iterations),
            Err(e) => {
                run.failed = Some((n, e));
                break;
            }
        }
        let (u, v) = (s.u().map(|x| x.as_f64()), s.v().map(|x| x.as_f64()));
        run.energy_error
            .push((elastic_energy(&u, &v, g) - e0).abs());
        run.trajectory.push(u);
    }
    run
}
