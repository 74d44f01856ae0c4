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
//! `docs/control-benchmark-data.md`). They are the values commonly restated for this
//! benchmark, recalled, and marked UNVERIFIED until checked against the paper's Section 4.
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

/// UNVERIFIED (recalled restatement, see the module doc), converted from the cm-based
/// units they are usually quoted in: `c₀a = 21.0 N·s/cm`, `c₀b = 3.50 N·s/(cm·V)`,
/// `αa = 140 N/cm`, `αb = 695 N/(cm·V)`, `γ = β = 363 cm⁻²`, `A = 301`, `n = 2`,
/// `η = 190 s⁻¹`, `V_max = 2.25 V`.
pub const DAMPER: Damper = Damper {
    c0a: 21.0e2,
    c0b: 3.50e2,
    alpha_a: 140.0e2,
    alpha_b: 695.0e2,
    gamma: 363.0e4,
    beta: 363.0e4,
    a: 301.0,
    n: 2.0,
    eta: 190.0,
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
/// starts at `t` with state `y` and damper force `f` there. Returns the peaks (checked at
/// every step's end, and at `t = 0`).
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
