//! The control trade-off scene (issue 33, scenes 2 and 3): the 5-storey building of
//! `aemstep::models::five_storey_building` under El Centro NS, an ideal force actuator
//! between the ground and floor 1, an LQG controller on three absolute accelerometers
//! (floors 1, 3 and 5) with the delivered force as its known input.
//!
//! Shared by `xtask/src/bin/control_tradeoff.rs` (the page `docs/control-tradeoff.md`, the
//! sweeps) and `tests/control_tradeoff.rs` (the fast checks on a short segment). The plant
//! is stepped here from its exact zero-order-hold model (the force held from the sample
//! after it was computed, the ground record held over each of its 0.02 s samples); the
//! closed loop's spectral radius is written here from the equations and computed by
//! nalgebra's eigenvalues, independently of the crate's controller.
#![allow(dead_code)] // each includer uses a different subset

use aemstep::control::{Controller, DesignModel, Lqr, Weights};
use aemstep::modal::Damping;
use aemstep::models::{self, Rows, base_excitation, storey_drifts};
use aemstep::nalgebra::{DMatrix, SMatrix, SVector};
use aemstep::observer::{Measurement, Observer, Outputs, StateSpace, SteadyState};
use aemstep::{Error, Real};

/// Standard gravity (m/s²).
pub const G: f64 = 9.80665;
/// The building's weight `W = Σ m_i g` (N): the normalization of the force criteria.
pub const WEIGHT: f64 = 5.0 * models::FIVE_STOREY_MASS * G;
/// The actuator's force limit (N): 50 % of the weight.
pub const LIMIT: f64 = 0.5 * WEIGHT;
/// The unit of force of the control loop (N): the models' input, the controller's
/// measured force and command are in MN, and the weights and noise per MN. The
/// regulator's closed-loop certificate gives the same verdict in newtons
/// (`tests/control_lqr.rs`, `certificate_is_independent_of_units`).
pub const FORCE_UNIT: f64 = 1.0e6;
/// The accelerometers: absolute accelerations of floors 1, 3 and 5 (0-based DOFs).
pub const SENSORS: [usize; O] = [0, 2, 4];
/// The number of accelerometers.
pub const O: usize = 3;
/// Accelerometer noise assumed by the observer (m/s², standard deviation).
pub const SENSOR_SIGMA: f64 = 0.05;
/// The ground acceleration as the observer's process noise (m/s², standard deviation).
pub const GROUND_SIGMA: f64 = 1.0;
/// The recovery noise (MN, standard deviation) in the actuator's direction (Doyle & Stein
/// 1979, "Robustness with observers"), which buys the robustness to the stiffness.
pub const RECOVERY: f64 = 0.2;
/// The drift weight `Q_y = I` (1/m²); the sweep moves `R` (1/MN²).
pub const QY: f64 = 1.0;
/// The chosen design's force weight `R` (1/MN²).
pub const R_CHOSEN: f64 = 3.0e-4;
/// The sweep of the force weight `R` (1/MN²), lightest control last: the page's
/// trade-off table, and the designs `tests/control_lqr.rs` certifies in other units.
pub const SWEEP: [f64; 10] = [
    3.0e-5, 1.0e-4, 2.0e-4, 3.0e-4, 5.0e-4, 1.0e-3, 2.0e-3, 5.0e-3, 1.0e-2, 1.0e-1,
];
/// The decision weight on the delayed model, relative to `R`.
pub const DECISION: f64 = 1.0e-3;
/// The record's sample interval (s).
pub const RECORD_DT: f64 = 0.02;

/// `M`, `C`, `K` of the building with storey stiffness scaled by `scale` (`C` the nominal
/// building's: the controller does not know the change, and neither does the damping).
pub fn mck(scale: f64) -> (Rows<5>, Rows<5>, Rows<5>) {
    let (m, c, k) = models::five_storey_building();
    (m, c, k.map(|row| row.map(|v| v * scale)))
}

/// The zero-order-hold models at step `h` (s) of the force on floor 1 (in [`FORCE_UNIT`]) and of the ground
/// acceleration, on the plant of stiffness `scale`.
pub fn zoh(scale: f64, h: f64) -> (StateSpace<5, 10, 1>, StateSpace<5, 10, 1>) {
    let (m, c, k) = mck(scale);
    let mat = |r| models::matrix_of::<f64, 5>(&r);
    let bf = SMatrix::<f64, 5, 1>::from_fn(|i, _| if i == 0 { FORCE_UNIT } else { 0.0 });
    let bg = SMatrix::<f64, 5, 1>::from_fn(|i, _| base_excitation(&m)[i][0]);
    (
        StateSpace::zero_order_hold(&mat(m), &mat(c), &mat(k), &bf, h).unwrap(),
        StateSpace::zero_order_hold(&mat(m), &mat(c), &mat(k), &bg, h).unwrap(),
    )
}

/// The two-mode models (`StateSpace::from_rows_modal`, the AEM of each mode) of the force
/// and of the ground acceleration on the nominal building at step `h`.
pub fn modal(h: f64) -> (StateSpace<5, 4, 1>, StateSpace<5, 4, 1>) {
    let (m, _, k) = models::five_storey_building();
    let w = models::natural_frequencies(&m, &k).unwrap();
    let (a0, a1) = models::rayleigh_coefficients(w[0], w[1], models::FIVE_STOREY_DAMPING);
    let d = Damping::Rayleigh { a0, a1 };
    let mut bf = [[0.0]; 5];
    bf[0][0] = FORCE_UNIT;
    (
        StateSpace::from_rows_modal(m, k, d, bf, [0, 1], h).unwrap(),
        StateSpace::from_rows_modal(m, k, d, base_excitation(&m), [0, 1], h).unwrap(),
    )
}

/// The accelerometers of a model whose input is the force: `M⁻¹ (B f − C v − K u)`, the
/// absolute acceleration (the ground's own term cancels: `M (ü + ι a_g) = B f − C v − K u`).
pub fn sensors<const S: usize>(ss: &StateSpace<5, S, 1>) -> Measurement<S, 1, O> {
    ss.outputs(&Outputs::accelerations(Outputs::<5, 1, O>::select(SENSORS)))
        .unwrap()
}

/// A design: the regulator's gain `[K_x K_u]` (`K_u = 0` for a design that ignores the
/// computation delay) and the observer's gain.
pub struct Design<const S: usize, const Z: usize> {
    /// `K` (`1×Z`, `Z = S + 1`).
    pub gain: SMatrix<f64, 1, Z>,
    /// `L` (`S×O`).
    pub observer: SMatrix<f64, S, O>,
    /// The regulator's certified spectral-radius bound (on its own design model).
    pub radius_bound: f64,
}

/// The LQG design on the models `ss` (force) and `ssg` (ground): drifts weighted by
/// `Q_y = QY·I`, the force (MN) by `r` (1/MN²); on the delayed model (`delay_aware`) or on the plain one
/// (the delay then left out of the design, present in the loop).
pub fn design<const S: usize, const Z: usize>(
    ss: &StateSpace<5, S, 1>,
    ssg: &StateSpace<5, S, 1>,
    r: f64,
    delay_aware: bool,
) -> Result<Design<S, Z>, Error> {
    design_with(ss, ssg, r, delay_aware, SENSOR_SIGMA, RECOVERY)
}

/// [`design`] with the observer's accelerometer noise `sensor_sigma` (m/s²) and recovery
/// noise `recovery` (MN) given.
pub fn design_with<const S: usize, const Z: usize>(
    ss: &StateSpace<5, S, 1>,
    ssg: &StateSpace<5, S, 1>,
    r: f64,
    delay_aware: bool,
    sensor_sigma: f64,
    recovery: f64,
) -> Result<Design<S, Z>, Error> {
    let drifts = ss.outputs(&Outputs::displacements(storey_drifts::<5>()))?;
    let mut qy = [[0.0; 5]; 5];
    for (i, row) in qy.iter_mut().enumerate() {
        row[i] = QY;
    }
    let w = Weights::outputs(&drifts, &qy, &[[r]]);
    let plant = DesignModel::from_state_space(ss);
    let (gain, radius_bound) = if delay_aware {
        let lqr = Lqr::from_parts(&plant.delayed::<Z>()?, &w.delayed(&[[DECISION * r]])?)?;
        (lqr.gain_matrix(), lqr.radius_bound)
    } else {
        let lqr: Lqr<S, 1> = Lqr::from_parts(&plant, &w)?;
        let k = lqr.gain_matrix();
        (
            SMatrix::from_fn(|_, j| if j < S { k[(0, j)] } else { 0.0 }),
            lqr.radius_bound,
        )
    };
    let q = SMatrix::<f64, S, S>::from_fn(|i, j| {
        ssg.input_noise(&[[GROUND_SIGMA * GROUND_SIGMA]])[i][j]
            + ss.input_noise(&[[recovery * recovery]])[i][j]
    }) + SMatrix::identity() * 1e-14;
    let rn = SMatrix::<f64, O, O>::identity() * sensor_sigma * sensor_sigma;
    let kf = SteadyState::new(ss, &sensors(ss), &q, &rn)?;
    Ok(Design {
        gain,
        observer: kf.gain_matrix(),
        radius_bound,
    })
}

/// The controller of a design on the model `ss`, in `T`.
pub fn controller<T: Real, const S: usize, const Z: usize>(
    ss: &StateSpace<5, S, 1>,
    d: &Design<S, Z>,
) -> Result<Controller<T, S, 1, O>, Error> {
    let obs = Observer::new(ss, &sensors(ss), &d.observer)?;
    Controller::new(obs, &d.gain, &[LIMIT / FORCE_UNIT])
}

/// The responses of a run, at the controller's samples: peaks and RMS values over the
/// record (per storey / floor, then the largest).
#[derive(Clone, Copy, Debug, Default)]
pub struct Response {
    /// Peak inter-storey drift (m).
    pub drift: f64,
    /// Peak absolute floor acceleration (m/s²).
    pub accel: f64,
    /// Peak force (N).
    pub force: f64,
    /// Peak actuator stroke: floor 1's displacement relative to the ground (m).
    pub stroke: f64,
    /// Peak velocity of floor 1 relative to the ground (m/s).
    pub velocity: f64,
    /// Peak mechanical power `|f v₁|` (W).
    pub power: f64,
    /// RMS drift, acceleration, force, stroke, velocity, power (largest over storeys).
    pub rms: [f64; 6],
    /// The regulator's stage cost per sample, averaged over the run: the mean of
    /// `Σ_i d_i²` (m²) and of `f²` (MN²), so that `quad[0] + R·quad[1]` is the realized
    /// quadratic cost of a design of force weight `R`.
    pub quad: [f64; 2],
    /// Samples where the command saturated.
    pub saturated: usize,
}

impl Response {
    /// The realized quadratic cost per sample for the force weight `r` (1/MN²): the mean of
    /// `Σ_i d_i² + r f²` (m²).
    pub fn cost(&self, r: f64) -> f64 {
        self.quad[0] + r * self.quad[1]
    }
}

/// The static feedthrough of the force into the accelerometers that a reduced model
/// leaves out: `D` of the full model (`M⁻¹ B` at the sensors) minus the model's (its kept
/// modes' share), per MN. Known exactly from `M` and `B`: subtracting `ΔD f` from the
/// accelerometers before the observer keeps the residual modes' direct response to the
/// force out of the estimate.
pub fn residual_feedthrough<const S: usize>(model: &StateSpace<5, S, 1>) -> SMatrix<f64, O, 1> {
    let (full, _) = zoh(1.0, model.time_step);
    sensors(&full).d_matrix() - sensors(model).d_matrix()
}

/// El Centro (`ag`, m/s², at 0.02 s) on the plant of stiffness `scale` at the controller's
/// step `h` (`0.02/h` steps per record sample), closed by `ctl` (or open, `None`). At
/// sample `k` the plant's state `x_k` gives the measurements `y_k = H x_k + D f_k`, `f_k`
/// the force held over `[t_k, t_{k+1})` (the command of sample `k − 1`, delivered as
/// commanded), and the command returned is held from `t_{k+1}`. `None` if the controller
/// reports an error (a diverging loop).
pub fn run<T: Real, const S: usize>(
    scale: f64,
    h: f64,
    ag: &[f64],
    ctl: Option<&Controller<T, S, 1, O>>,
) -> Option<Response> {
    run_corrected(scale, h, ag, ctl, &SMatrix::zeros())
}

/// [`run`] with `correction · f_k` subtracted from the accelerometers before the controller
/// reads them ([`residual_feedthrough`]).
pub fn run_corrected<T: Real, const S: usize>(
    scale: f64,
    h: f64,
    ag: &[f64],
    ctl: Option<&Controller<T, S, 1, O>>,
    correction: &SMatrix<f64, O, 1>,
) -> Option<Response> {
    let hold = (RECORD_DT / h).round() as usize;
    let (ss, ssg) = zoh(scale, h);
    let floors = ss
        .outputs(&Outputs::accelerations(Outputs::<5, 1, 5>::select([
            0, 1, 2, 3, 4,
        ])))
        .unwrap();
    let meas = sensors(&ss);
    let (phi, gf, gg) = (ss.phi_matrix(), ss.gamma0_matrix(), ssg.gamma0_matrix());
    let (hm, dm, ha, da) = (
        meas.h_matrix(),
        meas.d_matrix(),
        floors.h_matrix(),
        floors.d_matrix(),
    );
    let drifts = models::matrix_of::<f64, 5>(&storey_drifts::<5>());
    let mut x = SVector::<f64, 10>::zeros();
    let mut f = 0.0f64;
    let mut st = ctl.map(|c| c.start_at_rest());
    let mut out = Response::default();
    let mut sq = [[0.0f64; 5]; 6];
    let mut n = 0usize;
    for &a in ag {
        for _ in 0..hold {
            let y = hm * x + (dm - correction) * f;
            // The responses at t_k, with the force acting from t_k.
            let d = drifts * x.fixed_rows::<5>(0);
            let acc = ha * x + da * f;
            let (u1, v1, fp) = (x[0], x[5], f * FORCE_UNIT);
            let p = fp * v1;
            out.drift = out.drift.max(d.amax());
            out.accel = out.accel.max(acc.amax());
            out.force = out.force.max(fp.abs());
            out.stroke = out.stroke.max(u1.abs());
            out.velocity = out.velocity.max(v1.abs());
            out.power = out.power.max(p.abs());
            for i in 0..5 {
                sq[0][i] += d[i] * d[i];
                sq[1][i] += acc[i] * acc[i];
            }
            sq[2][0] += fp * fp;
            out.quad[0] += d.norm_squared();
            out.quad[1] += f * f;
            sq[3][0] += u1 * u1;
            sq[4][0] += v1 * v1;
            sq[5][0] += p * p;
            n += 1;
            let mut next = 0.0;
            if let (Some(c), Some(s)) = (ctl, st.as_mut()) {
                let yt = y.map(T::from_f64_rounded);
                let cmd = c
                    .try_step(s, &yt, &SVector::from([T::from_f64_rounded(f)]), false)
                    .ok()?;
                out.saturated += usize::from(cmd.saturated);
                next = cmd.force[0].as_f64();
            }
            x = phi * x + gf * f + gg * a;
            f = next;
            if !x.iter().all(|v| v.is_finite()) {
                return None;
            }
        }
    }
    out.quad = out.quad.map(|v| v / n as f64);
    for (r, s) in out.rms.iter_mut().zip(&sq) {
        *r = s.iter().fold(0.0f64, |m, &v| m.max((v / n as f64).sqrt()));
    }
    Some(out)
}

/// The evaluation criteria of a controlled run against the uncontrolled one `open`
/// (definitions on the page): `[J1, J2, J3, J4, J5]` peaks, `[J6 … J10]` their RMS twins.
pub fn criteria(c: &Response, open: &Response) -> [f64; 10] {
    [
        c.drift / open.drift,
        c.accel / open.accel,
        c.force / WEIGHT,
        c.stroke / open.stroke,
        c.power / (WEIGHT * open.velocity),
        c.rms[0] / open.rms[0],
        c.rms[1] / open.rms[1],
        c.rms[2] / WEIGHT,
        c.rms[3] / open.rms[3],
        c.rms[5] / (WEIGHT * open.rms[4]),
    ]
}

/// The spectral radius of the closed loop of the plant of stiffness `scale` (step `h`) with
/// the unsaturated controller of design `d` on the model `ss`, from the equations, on
/// `ξ_k = [x_k; x̂_{k−1}; f_{k−1}; f_k]` (`10 + S + 2` states):
///
/// ```text
/// x_{k+1} = Φ_p x_k + Γ_p f_k
/// x̂⁻ = Φ x̂_{k−1} + Γ₀ f_{k−1} + Γ₁ f_k,   x̂_k = x̂⁻ + L (H_p x_k + D_p f_k − H x̂⁻ − D f_k)
/// f_{k+1} = −K_x x̂_k − K_u f_k
/// ```
///
/// Eigenvalues by nalgebra (Schur form).
pub fn closed_loop_radius<const S: usize, const Z: usize>(
    scale: f64,
    h: f64,
    ss: &StateSpace<5, S, 1>,
    d: &Design<S, Z>,
) -> f64 {
    closed_loop_radius_corrected(scale, h, ss, d, &SMatrix::zeros())
}

/// [`closed_loop_radius`] with the accelerometers corrected as [`run_corrected`] does
/// (`D_p` becomes `D_p − correction`).
pub fn closed_loop_radius_corrected<const S: usize, const Z: usize>(
    scale: f64,
    h: f64,
    ss: &StateSpace<5, S, 1>,
    d: &Design<S, Z>,
    correction: &SMatrix<f64, O, 1>,
) -> f64 {
    let (ssp, _) = zoh(scale, h);
    let (mp, m) = (sensors(&ssp), sensors(ss));
    let (phi_p, g_p, h_p, d_p) = (
        ssp.phi_matrix(),
        ssp.gamma0_matrix(),
        mp.h_matrix(),
        mp.d_matrix(),
    );
    let (phi, g0, g1, hh, dd) = (
        ss.phi_matrix(),
        ss.gamma0_matrix(),
        ss.gamma1_matrix(),
        m.h_matrix(),
        m.d_matrix(),
    );
    let l = d.observer;
    let kx = SMatrix::<f64, 1, S>::from_fn(|_, j| d.gain[(0, j)]);
    let ku = d.gain[(0, S)];
    let ilh = SMatrix::<f64, S, S>::identity() - l * hh;
    let a1 = l * h_p;
    let a2 = ilh * phi;
    let a3 = ilh * g0;
    let a4 = ilh * g1 + l * (d_p - correction - dd);
    let n = 10 + S + 2;
    let (ix, if0, if1) = (10, 10 + S, 11 + S);
    let mut a = DMatrix::<f64>::zeros(n, n);
    a.view_mut((0, 0), (10, 10)).copy_from(&phi_p);
    a.view_mut((0, if1), (10, 1)).copy_from(&g_p);
    a.view_mut((ix, 0), (S, 10)).copy_from(&a1);
    a.view_mut((ix, ix), (S, S)).copy_from(&a2);
    a.view_mut((ix, if0), (S, 1)).copy_from(&a3);
    a.view_mut((ix, if1), (S, 1)).copy_from(&a4);
    a[(if0, if1)] = 1.0;
    a.view_mut((if1, 0), (1, 10)).copy_from(&(-kx * a1));
    a.view_mut((if1, ix), (1, S)).copy_from(&(-kx * a2));
    a[(if1, if0)] = -(kx * a3)[0];
    a[(if1, if1)] = -(kx * a4)[0] - ku;
    a.complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
}

/// The regulator's expected cost per sample under white ground acceleration of unit
/// variance, for the state feedback of design `d` (gain `[K_x K_u]`) on the delayed model
/// `z = [x; f_{k−1}]` of `ss` (which the loop has whatever the design assumed):
/// `tr(P Γ_g Γ_gᵀ)` with `P = A_Kᵀ P A_K + Q_z + Kᵀ R_d K`, `A_K = Φ_z − Γ_z K`,
/// `Q_z = [Cᵀ Q_y C 0; 0 R]` (the drifts and the force acting over the step),
/// `R_d = 10⁻³ R` (the decision weight), `Γ_g = [Γ_ground; 0]`. Written from the
/// equations: the Stein equation summed by doubling (`P ← P + Aᵀ P A`, `A ← A²`).
/// `None` if the loop is unstable (the sum does not converge). Units: m² per (m/s²)².
pub fn delayed_lq_cost(
    ss: &StateSpace<5, 10, 1>,
    ssg: &StateSpace<5, 10, 1>,
    d: &Design<10, 11>,
    r: f64,
) -> Option<f64> {
    let mut phi = SMatrix::<f64, 11, 11>::zeros();
    phi.fixed_view_mut::<10, 10>(0, 0)
        .copy_from(&ss.phi_matrix());
    phi.fixed_view_mut::<10, 1>(0, 10)
        .copy_from(&ss.gamma0_matrix());
    let mut gam = SMatrix::<f64, 11, 1>::zeros();
    gam[10] = 1.0;
    let mut gg = SMatrix::<f64, 11, 1>::zeros();
    gg.fixed_view_mut::<10, 1>(0, 0)
        .copy_from(&ssg.gamma0_matrix());
    let c = models::matrix_of::<f64, 5>(&storey_drifts::<5>());
    let mut qz = SMatrix::<f64, 11, 11>::zeros();
    let cx = SMatrix::<f64, 5, 10>::from_fn(|i, j| if j < 5 { c[(i, j)] } else { 0.0 });
    qz.fixed_view_mut::<10, 10>(0, 0)
        .copy_from(&(cx.transpose() * cx * QY));
    qz[(10, 10)] = r;
    let k = d.gain;
    let mut a = phi - gam * k;
    let mut p = qz + k.transpose() * k * (DECISION * r);
    for _ in 0..40 {
        p += a.transpose() * p * a;
        a = a * a;
        if !p.iter().all(|v| v.is_finite()) {
            return None;
        }
    }
    (a.amax() < 1e-6).then(|| (gg.transpose() * p * gg)[0])
}
