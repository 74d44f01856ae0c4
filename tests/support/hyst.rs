//! Runs of the hysteretic building under El Centro with an energy account kept
//! independently of the stepper: every energy is a quadrature of sampled powers or a
//! function of the committed history, written here from the law's parameters.
//! Shared by `tests/hysteresis.rs` and `xtask/src/bin/hysteresis_report.rs`.
#![allow(dead_code, clippy::type_complexity)]

use aemstep::hysteresis::{HistoryModel, Law, ShearBuilding};
use aemstep::nalgebra::{SMatrix, SVector};
use aemstep::{NewtonSettings, Nonlinear, Real, State};

use super::{building, elcentro};

/// Newton tolerance of the building runs.
pub const TOL: f64 = 1e-12;

/// Ground acceleration (m/s²) at step `n` of step `h = DT / r`: the record linear between
/// its samples (0 after its end).
pub fn ground(n: u64, r: u64) -> f64 {
    let ag = &elcentro::AG_F64;
    let (i, k) = ((n / r) as usize, n % r);
    let a = |j: usize| ag.get(j).copied().unwrap_or(0.0);
    if k == 0 {
        a(i)
    } else {
        let th = k as f64 / r as f64;
        (1.0 - th) * a(i) + th * a(i + 1)
    }
}

/// Yield drift `u_y` of storey `i` (m).
pub fn yield_drift(i: usize) -> f64 {
    building::YIELD[i] / building::STIFFNESS
}

/// The building at rest, started with step `h = DT / r` under the record's first sample.
pub fn start<L: Law<f64>>(
    stepper: &Nonlinear<f64, 3>,
    b: &ShearBuilding<f64, L, 3>,
    r: u64,
) -> (State<f64, 3>, [L::History; 3]) {
    let zero = SVector::<f64, 3>::zeros();
    stepper
        .start_with_history(
            b,
            &zero,
            &zero,
            &b.ground_load(ground(0, r)),
            &b.initial_history(),
        )
        .unwrap()
}

/// What one run gives.
#[derive(Clone, Debug, Default)]
pub struct Run {
    /// Floor displacements at every record sample (t = i·DT).
    pub u: Vec<[f64; 3]>,
    /// Energies at the end (J): input, kinetic, recoverable strain, viscous, hysteretic.
    pub input: f64,
    pub kinetic: f64,
    pub recoverable: f64,
    pub viscous: f64,
    pub hysteretic: f64,
    /// max over the run of |E_in − (E_k + E_s + E_v + E_h)| / max E_in.
    pub closure: f64,
    /// The same balance with the scheme's own (midpoint) quadratures: closes to the
    /// Newton tolerance (the AEM conserves this discrete energy exactly).
    pub discrete_closure: f64,
    /// Largest storey ductility max |δ| / u_y.
    pub ductility: f64,
    pub newton_iterations: u64,
    pub branch_changes: u64,
    pub steps: u64,
}

/// Step the building through the whole record with `h = DT / r`.
/// `dissipated(i, prev, next, d_prev, d_next)`: hysteretic work of storey `i` over a step
/// not stored in the history; `stored(i, hist)`: its part held in the history.
pub fn run<L: Law<f64>>(
    b: &ShearBuilding<f64, L, 3>,
    r: u64,
    settings: NewtonSettings<f64>,
    yield_drift: [f64; 3],
    dissipated: impl Fn(usize, &L::History, &L::History, f64, f64) -> f64,
    stored: impl Fn(usize, &L::History) -> f64,
) -> Run {
    type B<L> = ShearBuilding<f64, L, 3>;
    let h = elcentro::DT / r as f64;
    let stepper = Nonlinear::<f64, 3>::new(h, settings).unwrap();
    let m: SMatrix<f64, 3, 3> = b.mass();
    let c = *b.damping();
    let (mut s, mut hist) = start(&stepper, b, r);
    let steps = (elcentro::SAMPLES as u64 - 1) * r;
    let mut out = Run {
        u: vec![[0.0; 3]],
        ..Run::default()
    };
    let mut p_prev = b.ground_load(ground(0, r));
    let mut f_prev: [f64; 3] = [0.0; 3];
    let (mut e_in, mut e_v, mut e_d) = (0.0, 0.0, 0.0);
    let (mut d_in, mut d_v, mut d_s) = (0.0, 0.0, 0.0);
    let mut max_in: f64 = 0.0;
    for n in 1..=steps {
        let p = b.ground_load(ground(n, r));
        let (u0, v0) = (*s.u(), *s.v());
        let prev = hist;
        let report = stepper
            .try_step_with_history(b, &mut s, &mut hist, &p)
            .unwrap_or_else(|e| panic!("step {n}: {e}"));
        out.newton_iterations += report.iterations as u64;
        out.branch_changes += report.branch_changes as u64;
        let (u, v) = (*s.u(), *s.v());
        let storeys = b.storeys(&prev, &u, &v);
        let (dr0, dr) = (B::<L>::drifts(&u0), B::<L>::drifts(&u));
        let (vr0, vr) = (B::<L>::drifts(&v0), B::<L>::drifts(&v));
        // Trapezoidal quadratures of the sampled powers.
        e_in += 0.5 * h * (p.dot(&v) + p_prev.dot(&v0));
        e_v += 0.5 * h * (v.dot(&(c * v)) + v0.dot(&(c * v0)));
        // The scheme's own: mean force times increment.
        let vm = (v + v0) * 0.5;
        d_in += (p + p_prev).dot(&(u - u0)) * 0.5;
        d_v += h * vm.dot(&(c * vm));
        for i in 0..3 {
            e_d += dissipated(i, &prev[i], &hist[i], dr0[i], dr[i]);
            d_s += 0.5 * (storeys[i].force + f_prev[i]) * (dr[i] - dr0[i]);
            f_prev[i] = storeys[i].force;
            out.ductility = out.ductility.max(dr[i].abs() / yield_drift[i]);
        }
        let _ = vr0;
        let _ = vr;
        p_prev = p;
        let e_k = 0.5 * v.dot(&(m * v));
        let e_s = b.recoverable_energy(&hist, &u);
        let e_h = e_d + (0..3).map(|i| stored(i, &hist[i])).sum::<f64>();
        max_in = max_in.max(e_in.abs());
        out.closure = out.closure.max((e_in - (e_k + e_s + e_v + e_h)).abs());
        out.discrete_closure = out.discrete_closure.max((d_in - (e_k + d_v + d_s)).abs());
        if n % r == 0 {
            out.u.push([u[0], u[1], u[2]]);
        }
        (
            out.input,
            out.kinetic,
            out.recoverable,
            out.viscous,
            out.hysteretic,
        ) = (e_in, e_k, e_s, e_v, e_h);
    }
    out.closure /= max_in;
    out.discrete_closure /= max_in;
    out.steps = steps;
    out
}

/// The bilinear building (`building::bilinear`) at `h = DT / r`, Newton to [`TOL`]:
/// plastic dissipation `f_y |Δd_p|`; hardening energy `H d_p²/2` stored.
pub fn bilinear_run(r: u64) -> Run {
    let hard = building::ALPHA * building::STIFFNESS / (1.0 - building::ALPHA);
    run(
        &building::bilinear::<f64>().unwrap(),
        r,
        NewtonSettings::up_to(30, TOL),
        core::array::from_fn(yield_drift),
        |i, p, n, _, _| building::YIELD[i] * (n.plastic - p.plastic).abs(),
        |_, h| 0.5 * hard * h.plastic * h.plastic,
    )
}

/// The Bouc–Wen building (`building::bouc_wen`) at `h = DT / r`, Newton to [`TOL`]:
/// `(1 − α) f_y ∫ z dd` (trapezoid in d), minus the recoverable `(1 − α) f_y u_y z²/2`
/// held in z.
pub fn bouc_wen_run(r: u64) -> Run {
    let cz = |i: usize| (1.0 - building::ALPHA) * building::YIELD[i];
    run(
        &building::bouc_wen::<f64>().unwrap(),
        r,
        NewtonSettings::up_to(30, TOL),
        core::array::from_fn(yield_drift),
        |i, p, n, d0, d1| cz(i) * 0.5 * (p.z + n.z) * (d1 - d0),
        |i, h| -0.5 * cz(i) * yield_drift(i) * h.z * h.z,
    )
}

/// max over the common samples and floors of |a − b|.
pub fn max_diff(a: &Run, b: &Run) -> f64 {
    a.u.iter()
        .zip(&b.u)
        .flat_map(|(x, y)| x.iter().zip(y).map(|(p, q)| (p - q).abs()))
        .fold(0.0, f64::max)
}

/// Root mean square over the common samples and floors of `a − b`.
pub fn rms_diff(a: &Run, b: &Run) -> f64 {
    let (s, n) =
        a.u.iter()
            .zip(&b.u)
            .flat_map(|(x, y)| x.iter().zip(y).map(|(p, q)| (p - q) * (p - q)))
            .fold((0.0, 0usize), |(s, n), e| (s + e, n + 1));
    (s / n as f64).sqrt()
}

/// The markdown table of `docs/hysteresis.md` for runs at `h = DT / rs[j]`: the header,
/// the separator, then one row per run. A row's orders use the two runs before it, so the
/// rows from the third on are fully determined by runs at halving steps.
pub fn table(rs: &[u64], runs: &[Run]) -> Vec<String> {
    let mut out = vec![
        "| h (s) | closure / max E_in | order | RMS ‖u_h − u_2h‖ (m) | order | Newton iterations / step | branch changes | max ductility | E_h / E_in | E_v / E_in |".to_string(),
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|".to_string(),
    ];
    let order = |a: f64, b: f64| format!("{:.2}", (a / b).log2());
    for (j, run) in runs.iter().enumerate() {
        let h = elcentro::DT / rs[j] as f64;
        let c_order = if j > 0 {
            order(runs[j - 1].closure, run.closure)
        } else {
            "—".into()
        };
        let diff = (j > 0).then(|| rms_diff(&runs[j - 1], run));
        let d_order = match diff {
            Some(d) if j > 1 => order(rms_diff(&runs[j - 2], &runs[j - 1]), d),
            _ => "—".into(),
        };
        out.push(format!(
            "| {h} | {:.2e} | {c_order} | {} | {d_order} | {:.2} | {} | {:.2} | {:.3} | {:.3} |",
            run.closure,
            diff.map_or("—".into(), |d| format!("{d:.2e}")),
            run.newton_iterations as f64 / run.steps as f64,
            run.branch_changes,
            run.ductility,
            run.hysteretic / run.input,
            run.viscous / run.input,
        ));
    }
    out
}

/// Roof displacement at every step, the largest storey ductility, and how many steps did
/// not converge within the settings.
pub fn roof<T: Real>(settings: NewtonSettings<T>, ag: &[T]) -> (Vec<f64>, f64, usize) {
    let b = building::bilinear::<T>().unwrap();
    let stepper = Nonlinear::<T, 3>::new(elcentro::DT, settings).unwrap();
    let z = SVector::zeros();
    let (mut s, mut h) = stepper
        .start_with_history(&b, &z, &z, &b.ground_load(ag[0]), &b.initial_history())
        .unwrap();
    let mut out = vec![0.0];
    let mut unconverged = 0;
    let mut ductility: f64 = 0.0;
    for &a in &ag[1..] {
        let (next, hist, report) = stepper
            .trial_step_with_history(&b, &s, &h, &b.ground_load(a))
            .unwrap();
        if !report.converged {
            unconverged += 1;
        }
        (s, h) = (next, hist);
        out.push(s.u()[2].as_f64());
        let d = [s.u()[0], s.u()[1] - s.u()[0], s.u()[2] - s.u()[1]];
        for (di, fy) in d.iter().zip(building::YIELD) {
            ductility = ductility.max(di.as_f64().abs() * building::STIFFNESS / fy);
        }
    }
    (out, ductility, unconverged)
}
