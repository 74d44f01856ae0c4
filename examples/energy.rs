//! What the nonlinear AEM stepper does to energy, measured (README, "Nonlinear and
//! time-varying systems"). The paper claims energy conservation; this prints what the
//! scheme actually does on its own conservative examples:
//!
//! - Example 6, the pendulum `θ'' + sin θ = 0` (l = g = 9.81, θ0 = 0.4π, E0 = −29.74);
//! - Example 7, the elastic pendulum with gravity, h = 0.01 s to t = 1000 s, in f64 and f32;
//! - Example 7 without gravity: the step sweep where the energy stops being bounded.
//!
//! Run: `cargo run --release --example energy`

use aemstep::{Model, NewtonSettings, Nonlinear, Real, Tangent};
use nalgebra::{SMatrix, SVector, matrix, vector};

const G: f64 = 9.81;
const L: f64 = 3.0443;
const EA: f64 = 1.0e4;
const MASS: f64 = 6.667;
const X_SPEED: f64 = 7.72;

fn r<T: Real>(x: f64) -> T {
    T::from_f64_rounded(x)
}

/// `θ'' + (g/l) sin θ = 0` with `l = g`.
struct Pendulum;

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

/// `m u'' + (EA/L)(1 − L/r) u = (0, m g)`, `y` downward from the pivot.
struct Elastic;

impl<T: Real> Model<T, 2> for Elastic {
    fn mass(&self) -> SMatrix<T, 2, 2> {
        SMatrix::identity() * r::<T>(MASS)
    }
    fn force(&self, u: &SVector<T, 2>, _v: &SVector<T, 2>) -> SVector<T, 2> {
        u * (r::<T>(EA / L) * (T::one() - r::<T>(L) / u.norm()))
    }
    fn tangent(&self, u: &SVector<T, 2>, _v: &SVector<T, 2>) -> Option<Tangent<T, 2>> {
        let (k, l, len) = (r::<T>(EA / L), r::<T>(L), u.norm());
        Some(Tangent {
            stiffness: SMatrix::<T, 2, 2>::identity() * (k * (T::one() - l / len))
                + u * u.transpose() * (k * l / (len * len * len)),
            damping: SMatrix::zeros(),
        })
    }
}

fn elastic_energy(u: &SVector<f64, 2>, v: &SVector<f64, 2>, g: f64) -> f64 {
    let stretch = u.norm() - L;
    0.5 * MASS * v.norm_squared() + 0.5 * EA / L * stretch * stretch - MASS * g * u[1]
}

/// Max |E − E0| (J) in each of `windows` equal windows of the run, or the step at which
/// the run failed; and the first time the stretch |r − L| exceeds L.
struct Run {
    window_max: Vec<f64>,
    failed: Option<(u64, aemstep::Error)>,
    blow_up: Option<f64>,
    max_iterations: u32,
}

fn elastic<T: Real>(h: f64, t_end: f64, g: f64, windows: usize) -> Run {
    let st = Nonlinear::<T, 2>::new(
        r(h),
        NewtonSettings::up_to(50, NewtonSettings::<T>::default_tolerance()),
    )
    .expect("valid settings");
    let p = vector![T::zero(), r::<T>(MASS * g)];
    let (u0, v0) = (vector![0.0, L], vector![X_SPEED, 0.0]);
    let mut s = st
        .start(&Elastic, &u0.map(r::<T>), &v0.map(r::<T>), &p)
        .expect("finite start");
    let e0 = elastic_energy(&u0, &v0, g);
    let steps = (t_end / h).round() as u64;
    let mut run = Run {
        window_max: vec![0.0; windows],
        failed: None,
        blow_up: None,
        max_iterations: 0,
    };
    for n in 1..=steps {
        match st.try_step(&Elastic, &mut s, &p) {
            Ok(rep) => run.max_iterations = run.max_iterations.max(rep.iterations),
            Err(e) => {
                run.failed = Some((n, e));
                break;
            }
        }
        let (u, v) = (s.u().map(|x| x.as_f64()), s.v().map(|x| x.as_f64()));
        let w = (((n - 1) * windows as u64) / steps) as usize;
        let de = (elastic_energy(&u, &v, g) - e0).abs();
        run.window_max[w] = run.window_max[w].max(de);
        if run.blow_up.is_none() && (u.norm() - L).abs() > L {
            run.blow_up = Some(n as f64 * h);
        }
    }
    run
}

fn main() {
    println!("Energy behaviour of the nonlinear AEM step (measured, not claimed)\n");

    // Example 6: the pendulum.
    let th0 = 0.4 * std::f64::consts::PI;
    let energy = |th: f64, w: f64| -G * G * th.cos() + 0.5 * G * G * w * w;
    let e0 = energy(th0, 0.0);
    println!("Example 6, pendulum (l = g, θ0 = 0.4π), E0 = {e0:.4} (paper: −29.74), t ≤ 100 s:");
    for h in [0.1, 0.01, 0.001] {
        let st = Nonlinear::<f64, 1>::new(h, NewtonSettings::default()).expect("valid");
        let mut s = st
            .start(&Pendulum, &vector![th0], &vector![0.0], &vector![0.0])
            .expect("finite start");
        let steps = (100.0 / h).round() as u64;
        let (mut first, mut all) = (0.0f64, 0.0f64);
        for n in 1..=steps {
            st.try_step(&Pendulum, &mut s, &vector![0.0])
                .expect("converges");
            let de = (energy(s.u()[0], s.v()[0]) - e0).abs();
            all = all.max(de);
            if n * 10 <= steps {
                first = all;
            }
        }
        println!(
            "  h = {h:<5}: max |E − E0| = {all:.3e} ({:.2e} of |E0|); first 10 s: {first:.3e}",
            all / e0.abs()
        );
    }

    // Example 7 with gravity, the paper's run.
    let ke0 = 0.5 * MASS * X_SPEED * X_SPEED;
    let e0 = elastic_energy(&vector![0.0, L], &vector![X_SPEED, 0.0], G);
    println!(
        "\nExample 7, elastic pendulum with gravity, h = 0.01 s, t ≤ 1000 s \
         (E0 = {e0:.3} J, initial kinetic energy KE0 = {ke0:.1} J):"
    );
    for (name, run) in [
        ("f64", elastic::<f64>(0.01, 1000.0, G, 10)),
        ("f32", elastic::<f32>(0.01, 1000.0, G, 10)),
    ] {
        let max = run.window_max.iter().cloned().fold(0.0, f64::max);
        let w: Vec<String> = run.window_max.iter().map(|x| format!("{x:.4}")).collect();
        println!(
            "  {name}: max |E − E0| = {max:.4} J ({:.2e} of KE0); per 100 s window: [{}] J; \
             Newton ≤ {} iterations{}",
            max / ke0,
            w.join(", "),
            run.max_iterations,
            run.failed
                .map_or(String::new(), |(n, e)| format!("; FAILED at step {n}: {e}"))
        );
    }

    // Example 7 without gravity: where does the energy stop being bounded?
    println!(
        "\nExample 7 without gravity, t ≤ 100 s (axial period 2π√(mL/EA) = {:.3} s); \
         bounded = max |E − E0| ≤ KE0:",
        2.0 * std::f64::consts::PI * (MASS * L / EA).sqrt()
    );
    let mut first_unbounded: Option<f64> = None;
    let mut always_unbounded_from: Option<f64> = None;
    let mut late_blow_ups = Vec::new();
    for i in 1..=80 {
        let h = 0.005 * i as f64;
        let run = elastic::<f64>(h, 100.0, 0.0, 10);
        let max = run.window_max.iter().cloned().fold(0.0, f64::max);
        let bounded = max <= ke0 && run.failed.is_none();
        if bounded {
            always_unbounded_from = None;
        } else {
            first_unbounded.get_or_insert(h);
            always_unbounded_from.get_or_insert(h);
            late_blow_ups.push((h, run.blow_up));
        }
        if h <= 0.2851 && (i % 10 == 0 || !bounded || h >= 0.2399) {
            println!(
                "  h = {h:.3}: max |E − E0| = {:.3e} KE0{}{}",
                max / ke0,
                run.blow_up
                    .map_or(String::new(), |t| format!(", stretch > L at t = {t:.1} s")),
                run.failed
                    .map_or(String::new(), |(n, e)| format!(", failed at step {n}: {e}"))
            );
        }
    }
    let from = always_unbounded_from.unwrap_or(f64::NAN);
    let times: Vec<f64> = late_blow_ups
        .iter()
        .filter(|(h, _)| *h >= from - 1e-9)
        .filter_map(|(_, t)| *t)
        .collect();
    println!(
        "  every h from {from:.3} to 0.400 s: stretch > L within {:.1}–{:.1} s",
        times.iter().cloned().fold(f64::INFINITY, f64::min),
        times.iter().cloned().fold(0.0, f64::max)
    );
    println!(
        "  first unbounded step on the 0.005 s grid: {:.3} s; unbounded for every step from {from:.3} s",
        first_unbounded.unwrap_or(f64::NAN)
    );
}
