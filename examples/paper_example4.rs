//! The main job: paper Example 4 (3-DOF, fully populated M and K, Caughey damping with
//! modal ratios 0.3, 0.05, 0.09), stepped by `Linear` in f64 and f32 and by the paper's
//! literal A-form, against the exact modal-superposition solution.
//!
//! Run: `cargo run --release --example paper_example4`
//!
//! Stands alone: `aemstep` and its re-exported `nalgebra` only. The exact solution is written
//! here from the equations (mass-normalized modes, one closed-form damped oscillator per
//! mode), not from the crate's code.

use aemstep::nalgebra::{Matrix3, Vector3};
use aemstep::{Linear, Real, State, Stepper};

/// Paper Example 4: `(M, K, ξ, u0, v0, p)`: the modal damping ratios ξ in ascending
/// frequency, and the step load `p` (applied for t > 0).
type Example4 = (
    Matrix3<f64>,
    Matrix3<f64>,
    [f64; 3],
    Vector3<f64>,
    Vector3<f64>,
    Vector3<f64>,
);

fn example4() -> Example4 {
    let m = Matrix3::new(52.0, 10.0, 20.0, 10.0, 150.0, 30.0, 20.0, 30.0, 441.0);
    let k = Matrix3::new(
        1472.0, 407.0, 5553.0, 407.0, 1001.0, 4154.0, 5553.0, 4154.0, 43516.0,
    );
    let u0 = Vector3::new(10.0, 1.0, 5.0);
    let v0 = Vector3::new(0.0, 50.0, 20.0);
    let p = Vector3::new(10.0, 10.0, 10.0);
    (m, k, [0.3, 0.05, 0.09], u0, v0, p)
}

/// The damping matrix printed in the paper for Example 4.
fn example4_printed_c() -> Matrix3<f64> {
    Matrix3::new(
        34.3199, 27.9975, 89.4615, 27.9975, 172.1296, 50.4249, 89.4615, 50.4249, 770.3077,
    )
}

/// Exact modal-superposition solution of `M u'' + C u' + K u = p` (constant `p` for t > 0)
/// with Caughey damping `C = M Φ diag(2 ξ_r ω_r) Φᵀ M`, `Φ` the mass-normalized modes.
struct ModalExact {
    phi: Matrix3<f64>,
    w: [f64; 3],
    xi: [f64; 3],
    c: Matrix3<f64>,
    eta0: Vector3<f64>,
    deta0: Vector3<f64>,
    pm: Vector3<f64>,
}

impl ModalExact {
    fn new(
        m: &Matrix3<f64>,
        k: &Matrix3<f64>,
        xi: [f64; 3],
        u0: &Vector3<f64>,
        v0: &Vector3<f64>,
        p: &Vector3<f64>,
    ) -> Self {
        // K φ = ω² M φ through M = L Lᵀ: (L⁻¹ K L⁻ᵀ) y = ω² y, φ = L⁻ᵀ y.
        let l = m.cholesky().expect("M is SPD").l();
        let li = l.try_inverse().expect("L invertible");
        let eig = (li * k * li.transpose()).symmetric_eigen();
        let mut idx = [0, 1, 2];
        idx.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
        let y = Matrix3::from_fn(|r, c| eig.eigenvectors[(r, idx[c])]);
        let phi = li.transpose() * y;
        let w = idx.map(|i| eig.eigenvalues[i].sqrt());
        let d = Matrix3::from_diagonal(&Vector3::from_fn(|i, _| 2.0 * xi[i] * w[i]));
        let c = m * phi * d * phi.transpose() * m;
        Self {
            phi,
            w,
            xi,
            c,
            eta0: phi.transpose() * m * u0,
            deta0: phi.transpose() * m * v0,
            pm: phi.transpose() * p,
        }
    }

    /// `u(t)`: each modal coordinate solves `η'' + 2ξω η' + ω² η = p_r` in closed form.
    fn u(&self, t: f64) -> Vector3<f64> {
        let eta = Vector3::from_fn(|r, _| {
            let (w, xi) = (self.w[r], self.xi[r]);
            let wd = w * (1.0 - xi * xi).sqrt();
            let a = self.eta0[r] - self.pm[r] / (w * w);
            let b = (self.deta0[r] + xi * w * a) / wd;
            let (s, c) = (wd * t).sin_cos();
            self.pm[r] / (w * w) + (-xi * w * t).exp() * (a * c + b * s)
        });
        self.phi * eta
    }
}

/// Max |u − u_exact| over 0 ≤ t ≤ 5 and the response at t = 1, 2, …, 5.
fn run<T: Real, S: Stepper<T, 3, Input = Vector3<T>, State = State<T, 3>>>(
    sys: &S,
    exact: &ModalExact,
    show: bool,
) -> f64 {
    let (_, _, _, u0, v0, p) = example4();
    let cv = |a: &Vector3<f64>| a.map(T::from_f64_rounded);
    let h = sys.time_step().as_f64();
    let mut s = sys
        .start(&cv(&u0), &cv(&v0), &cv(&p))
        .expect("M is regular");
    let steps = (5.0 / h).round() as u64;
    let mut err = 0.0f64;
    for n in 1..=steps {
        sys.try_step(&mut s, &cv(&p)).expect("finite load");
        let t = n as f64 * h;
        let ue = exact.u(t);
        let u = s.u().map(|x| x.as_f64());
        err = err.max((u - ue).abs().max());
        if show && (n as f64 * h).fract().abs() < 1e-9 {
            println!(
                "  t = {t:.0}   u = ({:9.5}, {:9.5}, {:9.5})   exact = ({:9.5}, {:9.5}, {:9.5})",
                u[0], u[1], u[2], ue[0], ue[1], ue[2]
            );
        }
    }
    err
}

/// Observed order of convergence between two step sizes.
fn order(e1: f64, h1: f64, e2: f64, h2: f64) -> f64 {
    (e1 / e2).ln() / (h1 / h2).ln()
}

fn main() {
    let (m, k, xi, u0, v0, p) = example4();
    let exact = ModalExact::new(&m, &k, xi, &u0, &v0, &p);
    println!(
        "Paper Example 4: M u'' + C u' + K u = 10 (1,1,1)ᵀ H(t), u0 = (10, 1, 5), v0 = (0, 50, 20)"
    );
    println!(
        "  natural frequencies ω = ({:.4}, {:.4}, {:.4}) rad/s; Caughey C vs the paper's printed C: max |ΔC| = {:.1e}",
        exact.w[0],
        exact.w[1],
        exact.w[2],
        (exact.c - example4_printed_c()).abs().max()
    );
    println!("\nLinear<f64, 3>, h = 0.01 s:");
    let sys = Linear::<f64, _>::new(&m, &exact.c, &k, 0.01).expect("valid system");
    run(&sys, &exact, true);

    println!("\nmax |u − u_exact| over 0 ≤ t ≤ 5 (max |u| ≈ 17.3):");
    println!(
        "  {:>8} {:>13} {:>13} {:>13} {:>8}",
        "h (s)", "Linear f64", "AForm f64", "Linear f32", "order"
    );
    let mut prev: Option<(f64, f64)> = None;
    for h in [0.02, 0.01, 0.005, 0.0025] {
        let fast = Linear::<f64, _>::new(&m, &exact.c, &k, h).expect("valid system");
        let e64 = run(&fast, &exact, false);
        let ea = run(&fast.a_form(), &exact, false);
        let f32sys = Linear::<f32, 3>::new(&m, &exact.c, &k, h).expect("valid");
        let e32 = run(&f32sys, &exact, false);
        let ord = prev.map_or(String::from("—"), |(e, hp)| {
            format!("{:.3}", order(e, hp, e64, h))
        });
        println!("  {h:>8} {e64:>13.4e} {ea:>13.4e} {e32:>13.4e} {ord:>8}");
        prev = Some((e64, h));
    }
    println!(
        "\nThe error falls 4× per halving of h: second order, as the trapezoidal rule it equals."
    );
}
