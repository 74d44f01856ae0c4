//! Independent references for the tests and host examples: closed-form solutions, an
//! independent Newmark loop, the paper's literal 3N×3N operators, random systems.
//! Nothing here calls the code under test.
#![allow(
    dead_code,
    clippy::needless_range_loop,
    clippy::type_complexity,
    clippy::too_many_arguments
)]

use nalgebra::{DMatrix, DVector, SMatrix, SVector};

/// Deterministic xorshift64* generator (no dependency, same numbers everywhere).
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    /// The generator started from the raw state `state` (no mixing of the seed).
    pub fn from_state(state: u64) -> Self {
        Rng(state)
    }
    /// Uniform in [-1, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
        (x as f64) / (1u64 << 52) as f64 - 1.0
    }
}

/// A random well-conditioned, stable, fully populated system: `M`, `K` symmetric positive
/// definite, `C = 0.02 K + 0.1 M + G` with a skew (gyroscopic, energy-neutral) part `G`, so
/// `C` is not symmetric.
pub fn random_system<const N: usize>(
    rng: &mut Rng,
) -> (SMatrix<f64, N, N>, SMatrix<f64, N, N>, SMatrix<f64, N, N>) {
    let mut r = || SMatrix::<f64, N, N>::from_fn(|_, _| rng.uniform());
    let (a, b, s) = (r(), r(), r());
    let id = SMatrix::<f64, N, N>::identity();
    let m = a * a.transpose() / N as f64 + id;
    let k = (b * b.transpose() / N as f64 + id) * 40.0;
    let c = k * 0.02 + m * 0.1 + (s - s.transpose()) * 0.1;
    (m, c, k)
}

/// A smooth multi-frequency load `p(t)` for DOF `i`.
pub fn test_load(i: usize, t: f64) -> f64 {
    let i = i as f64;
    (1.3 * t + 0.7 * i).sin() + 0.5 * (4.1 * t - 0.3 * i).cos() + 0.2 * (0.37 * t * (1.0 + i)).sin()
}

/// Exact response of `u'' + 2ξω u' + ω² u = p` (constant `p` for t > 0; `0 ≤ ξ < 1`):
/// returns `(u, v)` at `t`.
pub fn sdof_exact(w: f64, xi: f64, u0: f64, v0: f64, p: f64, t: f64) -> (f64, f64) {
    let wd = w * (1.0 - xi * xi).sqrt();
    let us = p / (w * w);
    let a = u0 - us;
    let b = (v0 + xi * w * a) / wd;
    let e = (-xi * w * t).exp();
    let (s, c) = (wd * t).sin_cos();
    let u = us + e * (a * c + b * s);
    let v = e * ((-xi * w) * (a * c + b * s) + (-a * wd * s + b * wd * c));
    (u, v)
}

/// Mass-normalized modes of `K φ = ω² M φ` (`M` SPD, `K` symmetric), ascending `ω`.
pub fn modes<const N: usize>(
    m: &SMatrix<f64, N, N>,
    k: &SMatrix<f64, N, N>,
) -> (SMatrix<f64, N, N>, [f64; N]) {
    // Dynamic matrices: nalgebra's generic `symmetric_eigen` needs type-level N − 1.
    let d = |a: &SMatrix<f64, N, N>| DMatrix::from_fn(N, N, |i, j| a[(i, j)]);
    let l = d(m).cholesky().expect("M is SPD").l();
    let li = l.try_inverse().expect("L invertible");
    let li = SMatrix::<f64, N, N>::from_fn(|i, j| li[(i, j)]);
    let eig = d(&(li * k * li.transpose())).symmetric_eigen();
    let mut idx: [usize; N] = core::array::from_fn(|i| i);
    idx.sort_by(|&i, &j| eig.eigenvalues[i].partial_cmp(&eig.eigenvalues[j]).unwrap());
    let y = SMatrix::<f64, N, N>::from_fn(|r, c| eig.eigenvectors[(r, idx[c])]);
    let phi = li.transpose() * y;
    let w = core::array::from_fn(|i| eig.eigenvalues[idx[i]].sqrt());
    (phi, w)
}

/// Exact modal-superposition solution of `M u'' + C u' + K u = p` (constant `p` for t > 0)
/// with classical (Caughey) damping `C = M Φ diag(2 ξ_r ω_r) Φᵀ M`.
pub struct ModalExact<const N: usize> {
    pub phi: SMatrix<f64, N, N>,
    pub w: [f64; N],
    pub xi: [f64; N],
    pub c: SMatrix<f64, N, N>,
    eta0: [f64; N],
    deta0: [f64; N],
    pm: [f64; N],
}

impl<const N: usize> ModalExact<N> {
    pub fn new(
        m: &SMatrix<f64, N, N>,
        k: &SMatrix<f64, N, N>,
        xi: [f64; N],
        u0: &SVector<f64, N>,
        v0: &SVector<f64, N>,
        p: &SVector<f64, N>,
    ) -> Self {
        let (phi, w) = modes(m, k);
        let d = SMatrix::<f64, N, N>::from_diagonal(&SVector::from_fn(|i, _| 2.0 * xi[i] * w[i]));
        let c = m * phi * d * phi.transpose() * m;
        let eta0 = phi.transpose() * m * u0;
        let deta0 = phi.transpose() * m * v0;
        let pm = phi.transpose() * p;
        Self {
            phi,
            w,
            xi,
            c,
            eta0: eta0.into(),
            deta0: deta0.into(),
            pm: pm.into(),
        }
    }
    pub fn u(&self, t: f64) -> SVector<f64, N> {
        let eta = SVector::<f64, N>::from_fn(|r, _| {
            sdof_exact(
                self.w[r],
                self.xi[r],
                self.eta0[r],
                self.deta0[r],
                self.pm[r],
                t,
            )
            .0
        });
        self.phi * eta
    }
}

/// Paper Example 4: `(M, K, u0, v0, p)` and the modal damping ratios (ascending frequency).
pub fn example4() -> (
    SMatrix<f64, 3, 3>,
    SMatrix<f64, 3, 3>,
    [f64; 3],
    SVector<f64, 3>,
    SVector<f64, 3>,
    SVector<f64, 3>,
) {
    let m = SMatrix::<f64, 3, 3>::new(52.0, 10.0, 20.0, 10.0, 150.0, 30.0, 20.0, 30.0, 441.0);
    let k = SMatrix::<f64, 3, 3>::new(
        1472.0, 407.0, 5553.0, 407.0, 1001.0, 4154.0, 5553.0, 4154.0, 43516.0,
    );
    let u0 = SVector::<f64, 3>::new(10.0, 1.0, 5.0);
    let v0 = SVector::<f64, 3>::new(0.0, 50.0, 20.0);
    let p = SVector::<f64, 3>::new(10.0, 10.0, 10.0);
    (m, k, [0.3, 0.05, 0.09], u0, v0, p)
}

/// The damping matrix printed in the paper for Example 4.
pub fn example4_printed_c() -> SMatrix<f64, 3, 3> {
    SMatrix::<f64, 3, 3>::new(
        34.3199, 27.9975, 89.4615, 27.9975, 172.1296, 50.4249, 89.4615, 50.4249, 770.3077,
    )
}

/// Newmark's average-acceleration rule in the textbook incremental displacement form
/// (effective stiffness `K̂ = K + γ/(βh) C + M/(βh²)`, β = 1/4, γ = 1/2), written
/// independently of the crate. Returns `(u_n, v_n, a_n)` for `n = 0..=steps`.
pub fn newmark_aa(
    m: &DMatrix<f64>,
    c: &DMatrix<f64>,
    k: &DMatrix<f64>,
    h: f64,
    u0: &DVector<f64>,
    v0: &DVector<f64>,
    load: impl Fn(f64) -> DVector<f64>,
    steps: usize,
) -> Vec<(DVector<f64>, DVector<f64>, DVector<f64>)> {
    let (beta, gamma) = (0.25, 0.5);
    let a0 = m
        .clone()
        .lu()
        .solve(&(load(0.0) - c * v0 - k * u0))
        .expect("M regular");
    let khat = k + c * (gamma / (beta * h)) + m * (1.0 / (beta * h * h));
    let lu = khat.lu();
    let a1 = m * (1.0 / (beta * h * h)) + c * (gamma / (beta * h));
    let a2 = m * (1.0 / (beta * h)) + c * (gamma / beta - 1.0);
    let a3 = m * (1.0 / (2.0 * beta) - 1.0) + c * (h * (gamma / (2.0 * beta) - 1.0));
    let mut out = vec![(u0.clone(), v0.clone(), a0)];
    for n in 1..=steps {
        let (u, v, a) = out.last().unwrap().clone();
        let phat = load(n as f64 * h) + &a1 * &u + &a2 * &v + &a3 * &a;
        let un = lu.solve(&phat).expect("K̂ regular");
        let vn = (&un - &u) * (gamma / (beta * h))
            + &v * (1.0 - gamma / beta)
            + &a * (h * (1.0 - gamma / (2.0 * beta)));
        let an = (&un - &u) * (1.0 / (beta * h * h))
            - &v * (1.0 / (beta * h))
            - &a * (1.0 / (2.0 * beta) - 1.0);
        out.push((un, vn, an));
    }
    out
}

/// The paper's literal operators (eqs. 21–23): `L U_n = R U_{n−1} + E p_n` with
/// `U = (q, v, u)`, and `A = L⁻¹R` (3N×3N), `b = L⁻¹E` (3N×N) by a dense 3N×3N inverse.
pub fn literal_a_b(
    m: &DMatrix<f64>,
    c: &DMatrix<f64>,
    k: &DMatrix<f64>,
    h: f64,
) -> (DMatrix<f64>, DMatrix<f64>) {
    let n = m.nrows();
    let id = DMatrix::<f64>::identity(n, n);
    let (c1, c2) = (h * h / 2.0, h);
    let mut l = DMatrix::<f64>::zeros(3 * n, 3 * n);
    let mut r = DMatrix::<f64>::zeros(3 * n, 3 * n);
    let mut e = DMatrix::<f64>::zeros(3 * n, n);
    l.view_mut((0, 0), (n, n)).copy_from(m);
    l.view_mut((0, n), (n, n)).copy_from(c);
    l.view_mut((0, 2 * n), (n, n)).copy_from(k);
    l.view_mut((n, 0), (n, n)).copy_from(&(&id * (c1 / 2.0)));
    l.view_mut((n, n), (n, n)).copy_from(&(&id * -h));
    l.view_mut((n, 2 * n), (n, n)).copy_from(&id);
    l.view_mut((2 * n, 0), (n, n))
        .copy_from(&(&id * (-c2 / 2.0)));
    l.view_mut((2 * n, n), (n, n)).copy_from(&id);
    r.view_mut((n, 0), (n, n)).copy_from(&(&id * (-c1 / 2.0)));
    r.view_mut((n, 2 * n), (n, n)).copy_from(&id);
    r.view_mut((2 * n, 0), (n, n))
        .copy_from(&(&id * (c2 / 2.0)));
    r.view_mut((2 * n, n), (n, n)).copy_from(&id);
    e.view_mut((0, 0), (n, n)).copy_from(&id);
    let li = l.try_inverse().expect("L regular");
    (&li * r, li * e)
}

/// Row-major rows as a matrix.
pub fn sm<const R: usize, const C: usize>(a: &[[f64; C]; R]) -> SMatrix<f64, R, C> {
    SMatrix::from_fn(|i, j| a[i][j])
}

/// The Riccati residual `‖P − F(P)‖_max / ‖P‖_max`, `F(P) = ΦPΦᵀ − ΦPHᵀ(HPHᵀ+R)⁻¹HPΦᵀ + Q`,
/// written here with nalgebra (independent of the library's const code).
pub fn riccati_residual<const S: usize, const O: usize>(
    phi: &SMatrix<f64, S, S>,
    h: &SMatrix<f64, O, S>,
    q: &SMatrix<f64, S, S>,
    r: &SMatrix<f64, O, O>,
    p: &SMatrix<f64, S, S>,
) -> f64 {
    let si = h * p * h.transpose() + r;
    let k = phi * p * h.transpose() * si.try_inverse().unwrap();
    let f = phi * p * phi.transpose() - k * h * p * phi.transpose() + q;
    max_abs((p - f).iter()) / max_abs(p.iter())
}

/// Spectral radius of a real square matrix (complex eigenvalues, via nalgebra's Schur).
pub fn spectral_radius<const S: usize>(a: &SMatrix<f64, S, S>) -> f64 {
    let d = DMatrix::from_fn(S, S, |i, j| a[(i, j)]);
    d.complex_eigenvalues()
        .iter()
        .fold(0.0, |m, z| m.max(z.norm()))
}

/// `max_i |x_i|` over a trajectory of vectors.
pub fn max_abs<'a, I: IntoIterator<Item = &'a f64>>(xs: I) -> f64 {
    xs.into_iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// max |a_i − b_i| over the common length of two sampled histories.
pub fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Observed order `log(e1/e2)/log(h1/h2)`.
pub fn order(e1: f64, h1: f64, e2: f64, h2: f64) -> f64 {
    (e1 / e2).ln() / (h1 / h2).ln()
}
