//! Virtual sensing on the 5-storey building under El Centro: every inter-storey drift
//! estimated from two accelerometers (floors 2 and 5) and the measured ground acceleration,
//! with a model whose storey-1 stiffness is 10 % off the "true" structure's.
//!
//! Writes `docs/observer.md` (the table: error of each estimator against the truth, per
//! storey) and `docs/observer.svg` (storey-1 drift: truth, observer estimate, open-loop
//! model). The scene's constants (noise, seed, covariances) are in
//! `scenes/observer/scene.rs`, shared with the firmware and the tests.
//!
//! Run: `cargo run --release -p xtask --bin observer_building [DIR]` (default `docs`;
//! `scripts/check_docs.py` regenerates into a temporary directory and compares).

#[path = "../../../scenes/modal/elcentro.rs"]
mod elcentro;
#[path = "../plot.rs"]
mod plot;
#[path = "../../../scenes/observer/scene.rs"]
mod scene;

use std::fmt::Write as _;

use aemstep::models::base_excitation;
use aemstep::nalgebra::{SMatrix, SVector};
use aemstep::observer::{Kalman, Observer, Readout};
use aemstep::{LinearInput, Real, Stepper};
use plotters::prelude::*;

/// Drift histories (m), `[step][storey]`.
type Drifts = Vec<[f64; 5]>;

/// The truth's drifts and the accelerometer samples (`y[n]` for `n ≥ 1`; `y[0]` unused).
fn truth(ag: &[f64]) -> (Drifts, Vec<[f64; 2]>, [f64; 2]) {
    let (m, c, k) = scene::TRUTH;
    let sys =
        LinearInput::<f64, 5, 1>::from_rows_f64(m, c, k, base_excitation(&m), scene::H).unwrap();
    let z = SVector::zeros();
    let mut s = sys.start(&z, &z, &SVector::from([ag[0]])).unwrap();
    let mut noise = scene::Noise::new();
    let drift =
        |u: &SVector<f64, 5>| core::array::from_fn(|i| u[i] - if i > 0 { u[i - 1] } else { 0.0 });
    let (mut d, mut y) = (vec![drift(s.u())], vec![[f64::NAN; 2]]);
    let mut peak = [0.0f64; 2];
    for &a in &ag[1..] {
        sys.step(&mut s, &SVector::from([a]));
        d.push(drift(s.u()));
        let acc: [f64; 5] = (*s.a()).into();
        y.push(scene::measure(&acc, a, &mut noise));
        for (p, &dof) in peak.iter_mut().zip(&scene::SENSORS) {
            *p = p.max((acc[dof] + a).abs());
        }
    }
    (d, y, peak)
}

/// The open-loop model (the nominal building, no measurement).
fn open_loop(ag: &[f64]) -> Drifts {
    let (m, c, k) = scene::MODEL;
    let sys =
        LinearInput::<f64, 5, 1>::from_rows_f64(m, c, k, base_excitation(&m), scene::H).unwrap();
    let z = SVector::zeros();
    let mut s = sys.start(&z, &z, &SVector::from([ag[0]])).unwrap();
    let mut d = vec![[0.0; 5]];
    for &a in &ag[1..] {
        sys.step(&mut s, &SVector::from([a]));
        let u = s.u();
        d.push(core::array::from_fn(|i| {
            u[i] - if i > 0 { u[i - 1] } else { 0.0 }
        }));
    }
    d
}

/// A fixed-gain observer's drift estimates, in `T`.
fn observe<T: Real, const S: usize>(
    obs: &Observer<T, S, 1, 2>,
    drift: &Readout<T, S, 1, 5>,
    ag: &[f64],
    y: &[[f64; 2]],
) -> Drifts {
    let r = T::from_f64_rounded;
    let mut e = obs.start_at_rest(&SVector::from([r(ag[0])])).unwrap();
    let mut d = vec![[0.0; 5]];
    for n in 1..ag.len() {
        let w = SVector::from([r(ag[n])]);
        obs.try_step(&mut e, &w, &SVector::from([r(y[n][0]), r(y[n][1])]))
            .unwrap();
        let z = drift.read(e.x(), &w);
        d.push(core::array::from_fn(|i| z[i].as_f64()));
    }
    d
}

/// The full Kalman filter's drift estimates (f64), from rest with `P0 = 0`.
fn kalman(ag: &[f64], y: &[[f64; 2]]) -> Drifts {
    let q = SMatrix::<f64, 10, 10>::from_fn(|i, j| scene::Q[i][j]);
    let r = SMatrix::<f64, 2, 2>::from_fn(|i, j| scene::R[i][j]);
    let kal = Kalman::<f64, 10, 1, 2>::new(&scene::MODEL_SS, &scene::MEAS, &q, &r).unwrap();
    let drift = Readout::<f64, 10, 1, 5>::new(&scene::DRIFT_OUT).unwrap();
    let mut s = kal
        .start(
            &SVector::zeros(),
            &SMatrix::zeros(),
            &SVector::from([ag[0]]),
        )
        .unwrap();
    let mut d = vec![[0.0; 5]];
    for n in 1..ag.len() {
        let w = SVector::from([ag[n]]);
        kal.try_step(&mut s, &w, &SVector::from(y[n])).unwrap();
        let z = drift.read(s.estimate().x(), &w);
        d.push(z.into());
    }
    d
}

/// `(rms, peak)` of the error per storey (m).
fn errors(est: &Drifts, truth: &Drifts) -> [(f64, f64); 5] {
    core::array::from_fn(|i| {
        let (mut ss, mut pk) = (0.0f64, 0.0f64);
        for (e, t) in est.iter().zip(truth) {
            let d = e[i] - t[i];
            ss += d * d;
            pk = pk.max(d.abs());
        }
        ((ss / truth.len() as f64).sqrt(), pk)
    })
}

fn plot(
    path: &str,
    ag_len: usize,
    series: &[(&str, &Drifts, RGBColor)],
) -> Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::new(path, (1000, 820)).into_drawing_area();
    root.fill(&WHITE)?;
    let (top, bottom) = root.split_vertically(500);
    let t_end = 30.0;
    let n_end = ((t_end / scene::H) as usize).min(ag_len);
    let truth = series[0].1;
    let peak = truth[..n_end].iter().fold(0.0f64, |m, d| m.max(d[0].abs())) * 1e3;
    // Top: the drifts; bottom: each estimate's error against the truth.
    for (area, err) in [(&top, false), (&bottom, true)] {
        let lim = if err {
            series[1..]
                .iter()
                .flat_map(|(_, d, _)| {
                    d[..n_end]
                        .iter()
                        .zip(truth)
                        .map(|(a, b)| (a[0] - b[0]).abs())
                })
                .fold(0.0f64, f64::max)
                * 1.3e3
        } else {
            1.3 * peak
        };
        let caption = if err {
            "Error against the truth"
        } else {
            "Storey-1 drift, 5-storey building under El Centro (model: storey 1 10 % too stiff)"
        };
        let mut chart = plot::chart(area, caption, 0.0..t_end, -lim..lim)?;
        chart
            .configure_mesh()
            .x_desc("t (s)")
            .y_desc(if err { "error (mm)" } else { "drift (mm)" })
            .draw()?;
        for &(name, d, col) in series.iter().skip(usize::from(err)) {
            let pts: Vec<(f64, f64)> = d[..n_end]
                .iter()
                .zip(truth)
                .enumerate()
                .map(|(n, (x, t))| {
                    (
                        n as f64 * scene::H,
                        (x[0] - if err { t[0] } else { 0.0 }) * 1e3,
                    )
                })
                .collect();
            let style = col.stroke_width(if name.starts_with("truth") { 3 } else { 1 });
            plot::line(&mut chart, name, pts, style)?;
        }
        plot::legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    }
    root.present()?;
    Ok(())
}

/// The page opens with code a user can paste (compiled and run by `scripts/downstream.py`).
const USE_IT: &str = r##"## Use it

Every storey drift of the 5-storey building from two accelerometers: the model, the
process-noise recipe, the steady-state Kalman gain, then one step per sample:

```rust
use aemstep::models::{self, base_excitation};
use aemstep::observer::{Observer, Outputs, Readout, StateSpace, SteadyState};
use aemstep::vector;

// The model: M, C, K (kg, N·s/m, N/m), input the ground acceleration (m/s²), h = 0.02 s.
let (m, c, k) = models::five_storey_building();
let h = 0.02;
let model = StateSpace::<5, 10, 1>::from_rows_aem(m, c, k, base_excitation(&m), h)?;
// Measured: absolute accelerations of floors 2 and 5 (m/s²). Estimated: storey drifts (m).
let sensors = Outputs::absolute_accelerations(Outputs::<5, 1, 2>::select([1, 4]), 0);
let meas = model.outputs(&sensors)?;
let drifts = model.outputs(&Outputs::<5, 1, 5>::displacements(models::storey_drifts()))?;

// Process noise Q: the model's error, seen as white forces of σ_f = 5e4 N on every floor.
// The same model with those forces as inputs (B = I) gives Q = (Γ₀ + Γ₁) σ_f² I (Γ₀ + Γ₁)ᵀ.
let (mut b, mut qw) = ([[0.0; 5]; 5], [[0.0; 5]; 5]);
for i in 0..5 {
    b[i][i] = 1.0;
    qw[i][i] = 5e4 * 5e4; // N²
}
let forces = StateSpace::<5, 10, 5>::from_rows_aem(m, c, k, b, h)?;
let q = forces.input_noise(&qw);
// The same forces reach the accelerometers (a = M⁻¹(f − C v − K u)): their share D Q_w Dᵀ
// of the measurement noise, and its cross covariance N with the process noise.
let at_sensors = forces.outputs(&Outputs::accelerations(Outputs::<5, 5, 2>::select([1, 4])))?;
let n = forces.input_cross_noise(&at_sensors, &qw);
let f = forces.feedthrough_noise(&at_sensors, &qw);
// Measurement noise R: each accelerometer's own variance ((m/s²)²) plus the forces' share.
let r = [[0.18 * 0.18 + f[0][0], f[0][1]], [f[1][0], 0.26 * 0.26 + f[1][1]]];

let gain = SteadyState::from_parts_cross(&model, &meas, &q, &r, &n)?; // `const fn` too
let observer = Observer::<f32, 10, 1, 2>::new(&model, &meas, &gain.gain_matrix())?;
let readout = Readout::<f32, 10, 1, 5>::new(&drifts)?;

let mut e = observer.start_at_rest(&vector![0.0])?;
// Each sample: the ground acceleration and the two accelerometers (m/s²).
let (a_g, y) = (vector![0.5], vector![0.1, 0.3]);
observer.try_step(&mut e, &a_g, &y)?; // S² + 2S·I + 2S·O + O·I multiply-adds
let drift = readout.read(e.x(), &a_g); // m, storeys 1..5
assert!(drift.iter().all(|d| d.is_finite()));
# Ok::<(), aemstep::Error>(())
```

## The building under El Centro

"##;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let ag = &elcentro::AG_F64[..];
    let (truth, y, peak) = truth(ag);
    let open = open_loop(ag);
    let gain = scene::GAIN.gain;
    let obs64 = Observer::<f64, 10, 1, 2>::from_parts_f64(&scene::MODEL_SS, &scene::MEAS, &gain)?;
    let obs32 = Observer::<f32, 10, 1, 2>::from_parts_f32(&scene::MODEL_SS, &scene::MEAS, &gain)?;
    let est64 = observe(
        &obs64,
        &Readout::<f64, 10, 1, 5>::from_parts_f64(&scene::DRIFT_OUT)?,
        ag,
        &y,
    );
    let est32 = observe(
        &obs32,
        &Readout::<f32, 10, 1, 5>::from_parts_f32(&scene::DRIFT_OUT)?,
        ag,
        &y,
    );
    let modal = Observer::<f64, 4, 1, 2>::from_parts_f64(
        &scene::MODAL_SS,
        &scene::MODAL_MEAS,
        &scene::MODAL_GAIN.gain,
    )?;
    let est_modal = observe(
        &modal,
        &Readout::<f64, 4, 1, 5>::from_parts_f64(&scene::MODAL_DRIFT_OUT)?,
        ag,
        &y,
    );
    let est_kal = kalman(ag, &y);

    let peak_truth: [f64; 5] =
        core::array::from_fn(|i| truth.iter().fold(0.0f64, |m, d| m.max(d[i].abs())));
    let rows: [(&str, &Drifts); 5] = [
        ("open-loop model (no measurement)", &open),
        (
            "fixed-gain observer, `f64` (`Observer<f64, 10, 1, 2>`)",
            &est64,
        ),
        ("fixed-gain observer, `f32` (the firmware's)", &est32),
        (
            "modal observer, R = 2 (`Observer<f64, 4, 1, 2>`)",
            &est_modal,
        ),
        ("Kalman filter, `f64` (`Kalman<f64, 10, 1, 2>`)", &est_kal),
    ];
    let mut md = String::new();
    writeln!(
        md,
        "# Virtual sensing: every storey drift from two accelerometers"
    )?;
    writeln!(md)?;
    writeln!(
        md,
        "Generated by `cargo run --release -p xtask --bin observer_building` — do not edit by hand."
    )?;
    writeln!(md)?;
    md.push_str(USE_IT);
    writeln!(
        md,
        "The benchmark 5-storey building (`models::five_storey_building`) under the El Centro 1940 NS record"
    )?;
    writeln!(
        md,
        "(h = {} s, {} samples). The \"true\" structure has a storey-1 stiffness {} % below the model's.",
        scene::H,
        ag.len(),
        ((1.0 - scene::TRUE_STOREY_1) * 100.0).round()
    )?;
    writeln!(
        md,
        "Measured: the ground acceleration (the model's input, exact) and the absolute accelerations of floors 2"
    )?;
    writeln!(
        md,
        "and 5 with white noise of {} % of each sensor's peak (σ = {:.4} and {:.4} m/s²; peaks {:.4}, {:.4} m/s²;",
        scene::NOISE_FRACTION * 100.0,
        scene::SIGMA_Y[0],
        scene::SIGMA_Y[1],
        peak[0],
        peak[1]
    )?;
    writeln!(
        md,
        "Irwin–Hall normal samples from xorshift64*, seed {}). Estimated: every inter-storey drift.",
        scene::SEED
    )?;
    writeln!(md)?;
    writeln!(
        md,
        "The observer is `x̂ ← x̂⁻ + L (y − H x̂⁻ − D w)` on the AEM's discrete model (`observer::StateSpace`), with"
    )?;
    writeln!(
        md,
        "the steady-state Kalman gain `L` (`observer::SteadyState`, solved by the compiler: {} doubling iterations)",
        scene::GAIN.iterations
    )?;
    writeln!(
        md,
        "for process noise = white forces of σ_f = {:.0e} N on every floor (what the model error looks like to it)",
        scene::SIGMA_F
    )?;
    writeln!(
        md,
        "and the accelerometer noise above. The modal observer keeps 2 of the 5 modes (4 states); the Kalman filter"
    )?;
    writeln!(
        md,
        "propagates its covariance (Joseph form) from `P0 = 0`. All start at rest, as the truth does."
    )?;
    writeln!(md)?;
    writeln!(
        md,
        "Error against the truth's drift, per storey: RMS over the record / peak, in mm."
    )?;
    writeln!(md)?;
    write!(md, "| estimator |")?;
    for i in 1..=5 {
        write!(md, " storey {i} RMS / peak |")?;
    }
    writeln!(md)?;
    writeln!(md, "|---|{}", "---:|".repeat(5))?;
    write!(md, "| truth's drift (peak, not an error) |")?;
    for p in peak_truth {
        write!(md, " {:.2} |", p * 1e3)?;
    }
    writeln!(md)?;
    for (name, d) in rows {
        write!(md, "| {name} |")?;
        for (rms, pk) in errors(d, &truth) {
            write!(md, " {:.3} / {:.3} |", rms * 1e3, pk * 1e3)?;
        }
        writeln!(md)?;
    }
    writeln!(md)?;
    let (o, f) = (errors(&open, &truth), errors(&est64, &truth));
    writeln!(
        md,
        "Reading: the observer cuts the RMS drift error of storeys 2–5 by {:.1}–{:.1}× and of storey 1 by {:.1}×. Storey 1",
        (1..5)
            .map(|i| o[i].0 / f[i].0)
            .fold(f64::INFINITY, f64::min),
        (1..5).map(|i| o[i].0 / f[i].0).fold(0.0, f64::max),
        o[0].0 / f[0].0
    )?;
    writeln!(
        md,
        "carries the model error itself (its stiffness), which no accelerometer sees directly: the estimate there"
    )?;
    writeln!(
        md,
        "is as good as the model's storey-1 spring, corrected only through the floors above. Two modes do as well as"
    )?;
    writeln!(
        md,
        "the full model here (the record excites mainly the first two), at a quarter of the cost. `f32` and `f64`"
    )?;
    writeln!(
        md,
        "agree to the digits shown (the firmware's bound against the host's `f64` run: `scenes/observer/reference.rs`),"
    )?;
    writeln!(
        md,
        "and the full Kalman filter's gain reaches the steady state within a few steps, so it matches the fixed gain."
    )?;
    writeln!(md)?;
    let madds = |s: usize| s * s + 2 * s + 2 * s * 2 + 2;
    writeln!(
        md,
        "Cost of a step: fixed-gain observer `S² + 2S·I + 2S·O + O·I` multiply-adds = {} (full, S = 10) and",
        madds(10)
    )?;
    writeln!(
        md,
        "{} (modal, S = 4); the Kalman filter about `3S³` (≈ 3 900). On the Cortex-M4F: `docs/cortex-m4-cost.md`",
        madds(4)
    )?;
    writeln!(
        md,
        "(rows `observer_full`, `observer_modal2`, from `examples/firmware/qemu_observer.rs`)."
    )?;
    writeln!(md)?;
    writeln!(
        md,
        "The observers run on the discrete model of any linear scheme, plain `f64` matrices a user can check:"
    )?;
    writeln!(
        md,
        "`StateSpace::aem` / `from_rows_aem` (`Linear`, `LinearInput`), `newmark` / `from_rows_newmark` (`Newmark`,"
    )?;
    writeln!(
        md,
        "any β, γ), `generalized_alpha` / `from_rows_generalized_alpha` (`GeneralizedAlpha`, HHT-α: its acceleration is"
    )?;
    writeln!(
        md,
        "a state of its own, `x = [u; v; a]`, `S = 3N`, started by `StateSpace::initial_state`), `exact` (`Exact`) and"
    )?;
    writeln!(
        md,
        "`modal` / `from_rows_modal` (`Modal`). Each reproduces its stepper to rounding (`tests/state_space.rs`,"
    )?;
    writeln!(
        md,
        "`tests/observer.rs`); the acceleration output is the physical `M⁻¹ (B w − C v − K u)` for every scheme."
    )?;
    writeln!(md)?;
    writeln!(
        md,
        "![storey-1 drift: truth, observer, open loop; and their errors](observer.svg)"
    )?;
    print!("{md}");
    // The output directory: `docs` unless given (scripts/check_docs.py regenerates into a
    // temporary directory and compares).
    let dir = std::env::args().nth(1).unwrap_or_else(|| "docs".into());
    std::fs::create_dir_all(&dir)?;
    std::fs::write(format!("{dir}/observer.md"), &md)?;
    plot(
        &format!("{dir}/observer.svg"),
        ag.len(),
        &[
            ("truth", &truth, RGBColor(0, 0, 0)),
            ("observer estimate (f32)", &est32, RGBColor(220, 50, 40)),
            ("open-loop model", &open, RGBColor(40, 90, 220)),
        ],
    )?;
    Ok(())
}
