//! An independent reference for the MR-damper benchmark of Dyke, Spencer, Sain & Carlson
//! (1996), *Modeling and control of magnetorheological dampers for seismic response
//! reduction*, Smart Mater. Struct. 5:565–575: a 3-storey shear model with one MR damper
//! between the ground and the first floor.
//!
//! Written from the equations (not calling `aemstep`): the structure, the Bouc–Wen damper
//! with voltage-dependent `α` and `c₀` and the first-order filter on the command voltage,
//! as one first-order ODE of 8 states `y = [x₁ x₂ x₃ ẋ₁ ẋ₂ ẋ₃ z u]`, integrated by the
//! classical fixed-step RK4; the ground acceleration linearly interpolated between record
//! samples; the command voltage held over each step (the law is called at each step's
//! start with the state and the damper force there).
//!
//! ```text
//! M ẍ + C ẋ + K x = Γ f − M Λ ẍ_g,         Γ = [−1 0 0]ᵀ, Λ = [1 1 1]ᵀ
//! f = c₀(u) ẋ₁ + α(u) z,                     c₀ = c₀a + c₀b u,  α = αa + αb u
//! ż = −γ |ẋ₁| z |z|ⁿ⁻¹ − β ẋ₁ |z|ⁿ + A ẋ₁
//! u̇ = −η (u − v)
//! ```
//!
//! `x` floor displacements relative to the ground (m), `f` the damper force (N), `v` the
//! command voltage (V), `u` the filtered voltage (V). SI units throughout.
//!
//! The PARAMETER VALUES in `STRUCTURE` and `DAMPER` are NOT verified against the paper:
//! the stored text of the paper the search tool returned holds its abstract only (see
//! `docs/control-benchmark-data.md`). `STRUCTURE` is the commonly restated model, recalled
//! (UNVERIFIED); `DAMPER` is the set quoted by the literature citing the paper,
//! corroborated as that page states, not read from the paper's text.
#![allow(dead_code, clippy::needless_range_loop)]

/// The shear structure: floor masses (kg), stiffness and damping matrices (N/m, N·s/m).
#[derive(Clone, Copy, Debug)]
pub struct Structure {
    pub m: [f64; 3],
    pub k: [[f64; 3]; 3],
    pub c: [[f64; 3]; 3],
}

/// The damper (SI units): `c₀a` (N·s/m), `c₀b` (N·s/(m·V)), `αa` (N/m), `αb` (N/(m·V)),
/// `γ`, `β` (m⁻ⁿ), `A` (–), `n` (–), `η` (s⁻¹), `V_max` (V).
#[derive(Clone, Copy, Debug)]
pub struct Damper {
    pub c0a: f64,
    pub c0b: f64,
    pub alpha_a: f64,
    pub alpha_b: f64,
    pub gamma: f64,
    pub beta: f64,
    pub a: f64,
    pub n: f64,
    pub eta: f64,
    pub v_max: f64,
}

/// UNVERIFIED (recalled restatement, see the module doc): 98.3 kg a floor;
/// `K = 10⁵ [12.0 −6.84 0; −6.84 13.7 −6.84; 0 −6.84 6.84]` N/m;
/// `C = [175 −50 0; −50 100 −50; 0 −50 50]` N·s/m.
pub const STRUCTURE: Structure = Structure {
    m: [98.3, 98.3, 98.3],
    k: [
        [12.0e5, -6.84e5, 0.0],
        [-6.84e5, 13.7e5, -6.84e5],
        [0.0, -6.84e5, 6.84e5],
    ],
    c: [
        [175.0, -50.0, 0.0],
        [-50.0, 100.0, -50.0],
        [0.0, -50.0, 50.0],
    ],
};

/// The Bouc–Wen damper of Dyke et al. (1996), SI: `αa = 1.0872e5 N/m`,
/// `αb = 4.9616e5 N/(m·V)`, `c₀a = 4.40 N·s/m`, `c₀b = 44.0 N·s/(m·V)`, `n = 1`, `A = 1.2`,
/// `γ = β = 300 m⁻¹`, `η = 50 s⁻¹`, `V_max = 2.25 V`. Quoted by the literature citing the
/// paper; corroborated as stated in `docs/control-benchmark-data.md` (a public MATLAB
/// script with the same `A`, `n`, `γ`, `β`, `η`, for a 10× larger damper); not read from
/// the paper's text.
///
/// (The set this constant held before, `c₀a = 21.0 N·s/cm`, `αa = 140 N/cm`,
/// `γ = β = 363 cm⁻²`, `A = 301`, `n = 2`, `η = 190 s⁻¹`, is the one usually quoted for the
/// phenomenological model of Spencer et al. (1997), not this paper's Bouc–Wen.)
pub const DAMPER: Damper = Damper {
    c0a: 4.40,
    c0b: 44.0,
    alpha_a: 1.0872e5,
    alpha_b: 4.9616e5,
    gamma: 300.0,
    beta: 300.0,
    a: 1.2,
    n: 1.0,
    eta: 50.0,
    v_max: 2.25,
};

/// A ground-acceleration record: samples (m/s²) at `dt` (s), played at `time_scale` times
/// its recorded duration (`0.2`: five times the recorded rate) and multiplied by
/// `amplitude`. Zero after its end.
#[derive(Clone, Copy, Debug)]
pub struct Record<'a> {
    pub ag: &'a [f64],
    pub dt: f64,
    pub time_scale: f64,
    pub amplitude: f64,
}

impl Record<'_> {
    /// The model time step between samples (s).
    pub fn model_dt(&self) -> f64 {
        self.dt * self.time_scale
    }
    /// The duration in model time (s).
    pub fn duration(&self) -> f64 {
        (self.ag.len() - 1) as f64 * self.model_dt()
    }
    /// The ground acceleration at model time `t` (m/s²), linear between samples.
    pub fn at(&self, t: f64) -> f64 {
        let s = t / self.model_dt();
        if s < 0.0 {
            return 0.0;
        }
        let i = s.floor() as usize;
        if i + 1 >= self.ag.len() {
            return if i + 1 == self.ag.len() && s == i as f64 {
                self.amplitude * self.ag[i]
            } else {
                0.0
            };
        }
        let w = s - i as f64;
        self.amplitude * ((1.0 - w) * self.ag[i] + w * self.ag[i + 1])
    }
}

/// What the damper is in a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Attached {
    /// No damper: the bare structure (the paper's "uncontrolled").
    No,
    /// The damper, commanded by the law given to [`simulate`].
    Yes,
}

/// Peak responses over a run (absolute values): floor displacements relative to the ground
/// (m), inter-storey drifts (m, storey 1 = floor 1 − ground), absolute floor accelerations
/// (m/s²), damper force (N).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Peaks {
    pub displacement: [f64; 3],
    pub drift: [f64; 3],
    pub acceleration: [f64; 3],
    pub force: f64,
}

/// The damper force and the rates of `z` and `u` (the damper's part of the ODE).
pub fn damper_rates(d: &Damper, xdot: f64, z: f64, u: f64, v: f64) -> (f64, f64, f64) {
    let c0 = d.c0a + d.c0b * u;
    let alpha = d.alpha_a + d.alpha_b * u;
    let f = c0 * xdot + alpha * z;
    let zn1 = z.abs().powf(d.n - 1.0);
    let zdot = -d.gamma * xdot.abs() * z * zn1 - d.beta * xdot * zn1 * z.abs() + d.a * xdot;
    let udot = -d.eta * (u - v);
    (f, zdot, udot)
}

/// The state's rate at `t` with the command `v` held; also returns the damper force and the
/// relative floor accelerations.
pub fn rates(
    s: &Structure,
    d: &Damper,
    attached: Attached,
    ag: f64,
    y: &[f64; 8],
    v: f64,
) -> ([f64; 8], f64, [f64; 3]) {
    let (f, zdot, udot) = match attached {
        Attached::Yes => damper_rates(d, y[3], y[6], y[7], v),
        Attached::No => (0.0, 0.0, 0.0),
    };
    let mut acc = [0.0; 3];
    for i in 0..3 {
        let mut r = -s.m[i] * ag;
        for j in 0..3 {
            r -= s.c[i][j] * y[3 + j] + s.k[i][j] * y[j];
        }
        if i == 0 {
            r -= f; // Γ = [−1 0 0]ᵀ: the damper resists the first floor's motion
        }
        acc[i] = r / s.m[i];
    }
    (
        [y[3], y[4], y[5], acc[0], acc[1], acc[2], zdot, udot],
        f,
        acc,
    )
}

/// One classical RK4 step of `ẏ = g(t, y)`.
pub fn rk4<const K: usize>(
    t: f64,
    y: &[f64; K],
    h: f64,
    mut g: impl FnMut(f64, &[f64; K]) -> [f64; K],
) -> [f64; K] {
    let add = |a: &[f64; K], b: &[f64; K], s: f64| -> [f64; K] {
        let mut r = *a;
        for i in 0..K {
            r[i] += s * b[i];
        }
        r
    };
    let k1 = g(t, y);
    let k2 = g(t + h / 2.0, &add(y, &k1, h / 2.0));
    let k3 = g(t + h / 2.0, &add(y, &k2, h / 2.0));
    let k4 = g(t + h, &add(y, &k3, h));
    let mut r = *y;
    for i in 0..K {
        r[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
    r
}

/// Runs the benchmark from rest over the record (and `extra` seconds after it) with RK4 of
/// step `h` (s); `law(t, y, f)` returns the command voltage (V) held over the step that
/// starts at `t` with state `y` and damper force `f` there; the filtered voltage starts at
/// the first command (held since long before `t = 0`). Returns the peaks (checked at every
/// step's end, and at `t = 0`).
pub fn simulate(
    s: &Structure,
    d: &Damper,
    rec: &Record,
    attached: Attached,
    h: f64,
    extra: f64,
    mut law: impl FnMut(f64, &[f64; 8], f64) -> f64,
) -> Peaks {
    let steps = ((rec.duration() + extra) / h).round() as usize;
    let mut y = [0.0; 8];
    let mut p = Peaks::default();
    let mut t = 0.0;
    let mut v = law(0.0, &y, 0.0);
    // The first command held since long before t = 0: the filtered voltage starts at it
    // (0 V for the controllers, which command nothing at rest; V_max passive-on).
    y[7] = v;
    for n in 0..steps {
        y = rk4(t, &y, h, |tt, yy| {
            rates(s, d, attached, rec.at(tt), yy, v).0
        });
        t = (n + 1) as f64 * h;
        let ag = rec.at(t);
        // The force and accelerations at the step's end, with the command of the next step
        // (the force and `ẍ` do not depend on `v` directly: only `u̇` does).
        let (_, f, acc) = rates(s, d, attached, ag, &y, v);
        for i in 0..3 {
            p.displacement[i] = p.displacement[i].max(y[i].abs());
            let below = if i == 0 { 0.0 } else { y[i - 1] };
            p.drift[i] = p.drift[i].max((y[i] - below).abs());
            p.acceleration[i] = p.acceleration[i].max((acc[i] + ag).abs());
        }
        p.force = p.force.max(f.abs());
        v = law(t, &y, f);
    }
    p
}

/// The clipped-optimal controller of the benchmark's kind, built independently: a
/// continuous LQR gain on the linear structure with the damper force as its input (CARE by
/// Newton–Kleinman, each Lyapunov equation solved through its Kronecker form), a
/// steady-state Kalman–Bucy filter on the absolute floor accelerations with the measured
/// damper force as a known input and the ground acceleration as the process noise (the
/// dual CARE), and the switching law `v = V_max H((f_c − f) f)` written out here.
///
/// The WEIGHTS AND NOISE INTENSITIES ARE NOT THE PAPER'S (not obtained, see
/// `docs/control-benchmark-data.md`): they are the caller's.
pub mod lqg {
    use nalgebra::{DMatrix, DVector};

    /// `Acᵀ P + P Ac = −Qc` for `P`, through `(I ⊗ Acᵀ + Acᵀ ⊗ I) vec P = −vec Qc`.
    pub fn lyapunov(ac: &DMatrix<f64>, qc: &DMatrix<f64>) -> DMatrix<f64> {
        let n = ac.nrows();
        let at = ac.transpose();
        let eye = DMatrix::<f64>::identity(n, n);
        let big = eye.kronecker(&at) + at.kronecker(&eye);
        let rhs = -DVector::from_column_slice(qc.as_slice());
        let x = big
            .lu()
            .solve(&rhs)
            .expect("a stable Ac: the Kronecker sum is regular");
        let p = DMatrix::from_column_slice(n, n, x.as_slice());
        (&p + p.transpose()) * 0.5
    }

    /// The stabilizing solution `P` of `Aᵀ P + P A − P B R⁻¹ Bᵀ P + Q = 0` and the gain
    /// `K = R⁻¹ Bᵀ P`, by Newton–Kleinman from `K₀ = 0` (`A` must be stable), to a relative
    /// change of `P` below `1e-13`.
    pub fn care(
        a: &DMatrix<f64>,
        b: &DMatrix<f64>,
        q: &DMatrix<f64>,
        r: &DMatrix<f64>,
    ) -> (DMatrix<f64>, DMatrix<f64>) {
        let rinv = r.clone().try_inverse().expect("R positive definite");
        let mut k = DMatrix::<f64>::zeros(b.ncols(), a.nrows());
        let mut p = DMatrix::<f64>::zeros(a.nrows(), a.nrows());
        for _ in 0..100 {
            let ac = a - b * &k;
            let qc = q + k.transpose() * r * &k;
            let next = lyapunov(&ac, &qc);
            let change = (&next - &p).abs().max() / next.abs().max();
            p = next;
            k = &rinv * b.transpose() * &p;
            if change < 1e-13 {
                break;
            }
        }
        (p, k)
    }
}

/// The design of [`clipped_optimal`]: the LQR gain `K` (1×6) on `x = [x₁ x₂ x₃ ẋ₁ ẋ₂ ẋ₃]`
/// and the Kalman gain `L` (6×3), with the model they were built on.
pub struct Design {
    pub a: nalgebra::DMatrix<f64>,
    pub b: nalgebra::DMatrix<f64>,
    pub c: nalgebra::DMatrix<f64>,
    pub d: nalgebra::DMatrix<f64>,
    pub k: nalgebra::DMatrix<f64>,
    pub l: nalgebra::DMatrix<f64>,
    pub p: nalgebra::DMatrix<f64>,
    pub sigma: nalgebra::DMatrix<f64>,
}

/// Designs the controller on the linear structure (the damper force `f` its input, entering
/// as `Γ f`): LQR with `Q = q_disp · diag(1, 1, 1, 0, 0, 0)` (N²/m², on the floor
/// displacements) and `R = r` (1/N² scale); Kalman–Bucy with the ground acceleration as
/// white process noise of intensity `ground` ((m/s²)²·s) through `E = [0; −Λ]` and the
/// three absolute accelerations measured with noise intensity `sensor` each.
pub fn design(s: &Structure, q_disp: f64, r: f64, ground: f64, sensor: f64) -> Design {
    use nalgebra::DMatrix;
    let mut a = DMatrix::<f64>::zeros(6, 6);
    let mut b = DMatrix::<f64>::zeros(6, 1);
    let mut e = DMatrix::<f64>::zeros(6, 1);
    let mut c = DMatrix::<f64>::zeros(3, 6);
    let mut d = DMatrix::<f64>::zeros(3, 1);
    for i in 0..3 {
        a[(i, 3 + i)] = 1.0;
        for j in 0..3 {
            a[(3 + i, j)] = -s.k[i][j] / s.m[i];
            a[(3 + i, 3 + j)] = -s.c[i][j] / s.m[i];
            c[(i, j)] = a[(3 + i, j)];
            c[(i, 3 + j)] = a[(3 + i, 3 + j)];
        }
        e[(3 + i, 0)] = -1.0;
    }
    b[(3, 0)] = -1.0 / s.m[0];
    d[(0, 0)] = b[(3, 0)];
    let mut q = DMatrix::<f64>::zeros(6, 6);
    for i in 0..3 {
        q[(i, i)] = q_disp;
    }
    let (p, k) = lqg::care(&a, &b, &q, &DMatrix::from_element(1, 1, r));
    let w = &e * ground * e.transpose();
    let rv = DMatrix::<f64>::identity(3, 3) * sensor;
    let (sigma, lt) = lqg::care(&a.transpose(), &c.transpose(), &w, &rv);
    Design {
        a,
        b,
        c,
        d,
        k,
        l: lt.transpose(),
        p,
        sigma,
    }
}

/// The benchmark under clipped-optimal control: every `tc` seconds (a multiple of `h`) the
/// controller reads the three absolute floor accelerations and the damper force, forms
/// `f_c = −K x̂`, commands `v = V_max H((f_c − f) f)` (strict `H`: 0 V at `f = f_c` and at
/// `f = 0`), and advances its estimate `x̂̇ = A x̂ + B f + L (y − C x̂ − D f)` over `tc` with
/// the readings held (one RK4 step). The plant as in [`simulate`].
pub fn clipped_optimal(
    s: &Structure,
    d: &Damper,
    rec: &Record,
    h: f64,
    tc: f64,
    g: &Design,
) -> Peaks {
    let every = (tc / h).round() as usize;
    assert!(every >= 1 && ((every as f64) * h - tc).abs() < 1e-12 * tc);
    let mut xhat = [0.0_f64; 6];
    let mut calls = 0usize;
    let mut v = 0.0;
    simulate(s, d, rec, Attached::Yes, h, 1.0, |t, y, f| {
        let n = calls;
        calls += 1;
        if !n.is_multiple_of(every) {
            return v;
        }
        let ag = rec.at(t);
        let acc = rates(s, d, Attached::Yes, ag, y, v).2;
        let meas = [acc[0] + ag, acc[1] + ag, acc[2] + ag];
        let mut fc = 0.0;
        for j in 0..6 {
            fc -= g.k[(0, j)] * xhat[j];
        }
        let lag = fc - f;
        v = if lag * f > 0.0 { d.v_max } else { 0.0 };
        xhat = rk4(t, &xhat, tc, |_, xh| {
            let mut out = [0.0; 6];
            let mut innov = [0.0; 3];
            for i in 0..3 {
                innov[i] = meas[i] - g.d[(i, 0)] * f;
                for j in 0..6 {
                    innov[i] -= g.c[(i, j)] * xh[j];
                }
            }
            for i in 0..6 {
                out[i] = g.b[(i, 0)] * f;
                for j in 0..6 {
                    out[i] += g.a[(i, j)] * xh[j];
                }
                for m in 0..3 {
                    out[i] += g.l[(i, m)] * innov[m];
                }
            }
            out
        });
        v
    })
}
