//! Incremental dynamic analysis of the yielding 5-storey building (`scenes/ida/building.rs`)
//! over a suite of six records — El Centro 1940 NS (the repository's one real record), its
//! time reversal, and four seeded synthetic records (filtered white noise) — by
//! hunt-and-fill (`aemstep::ida::hunt_fill`, 12 runs a record, intensity `Sa(T₁)`,
//! collapse at 9 cm of storey drift or a failed analysis), the 16/50/84 % fractiles; and
//! the constant-ductility inelastic spectra of El Centro (μ = 1, 2, 4, 6, 0.05–3 s,
//! `spectrum::inelastic::Yielding`).
//!
//! Writes `docs/ida.md`, `docs/ida.svg` and `docs/ida_spectra.svg`. Deterministic (no
//! timing).
//!
//! Run: `cargo run --release -p xtask --bin ida [DIR]` (default `docs`;
//! `scripts/check_docs.py` regenerates into a temporary directory and compares).

#[path = "../../../scenes/modal/elcentro.rs"]
mod elcentro;
#[path = "../../../scenes/ida/building.rs"]
mod ida_scene;
#[path = "../plot.rs"]
mod plot;

use std::fmt::Write as _;

use aemstep::ida::{self, Collapse, Curve, Fractiles, HuntFill, OnFailure};
use aemstep::models;
use aemstep::records::{self, G};
use aemstep::spectrum::inelastic::{Outcome, Search, Yielding};
use plotters::prelude::*;

/// Threads of the batch (the results do not depend on it).
const THREADS: usize = 2;
/// The collapse drift (m): 3 % of a 3 m storey, three times the yield drift.
const COLLAPSE_DRIFT: f64 = 0.09;
/// Damping ratio of `Sa(T₁)` and of the inelastic spectra.
const ZETA: f64 = 0.05;
/// Periods of the inelastic spectra.
const P: usize = 60;
/// Target ductilities of the inelastic spectra (1: the elastic strength).
const MUS: [f64; 4] = [1.0, 2.0, 4.0, 6.0];
/// The EDP levels of the fractile table (m).
const LEVELS: [f64; 7] = [0.005, 0.01, 0.02, 0.03, 0.045, 0.06, 0.09];
/// The fractiles.
const QS: [f64; 3] = [0.16, 0.5, 0.84];

/// The code block the page opens with (compiled as a doctest through `src/lib.rs` and by
/// `scripts/downstream.py` in a crate depending on aemstep alone).
const USE_IT: &str = r#"```rust
use aemstep::hysteresis::{Bilinear, HistoryModel, ShearBuilding};
use aemstep::ida::{self, Collapse, HuntFill, OnFailure};
use aemstep::nalgebra::SVector;
use aemstep::records::{self, Record};
use aemstep::{Error, NewtonSettings, Nonlinear, models};

// The records: from PEER files, `Record::read_at2("RSN6_IMPVALL.I_I-ELC180.AT2")?`, or
// text (`Record::from_at2`, `Record::from_column`); here two made-up ones, in g at 0.02 s.
let suite: Vec<Record> = (1..=2)
    .map(|k| Record {
        title: format!("made-up {k}"),
        dt: 0.02,
        samples: (0..500).map(|n| 0.3 * (n as f64 * 0.02 * 9.0 / k as f64).sin()).collect(),
    })
    .collect();

// The model: the 5-storey building, every storey bilinear (yield drift 3 cm, 5 % hardening).
let (m, c, _k) = models::five_storey_building();
let law = Bilinear::<f64>::new(models::FIVE_STOREY_STIFFNESS, 3.0e6, 0.05)?;
let building = ShearBuilding::new(models::floor_masses(&m), [law; 5], &c)?;
let stepper = Nonlinear::<f64, 5>::new(0.02, NewtonSettings::up_to(50, 1e-12))?;

// One analysis: the record scaled by the intensity `im`; its EDP, the peak storey drift (m).
let analysis = |r: &Record, im: f64| -> Result<f64, Error> {
    let zero = SVector::<f64, 5>::zeros();
    let load = |n: usize| building.ground_load(im * records::G * r.samples[n]);
    let (mut s, mut history) =
        stepper.start_with_history(&building, &zero, &zero, &load(0), &building.initial_history())?;
    let mut peak = 0.0f64;
    for n in 1..r.samples.len() {
        stepper.try_step_with_history(&building, &mut s, &mut history, &load(n))?;
        peak = models::drifts(s.u()).iter().fold(peak, |p, d| p.max(d.abs()));
    }
    Ok(peak)
};

// Hunt and fill, 12 runs a record; collapse at 9 cm of drift or when Newton fails.
let settings = HuntFill {
    collapse: Collapse { edp: 0.09, on_failure: OnFailure::Collapse },
    ..HuntFill::DEFAULT
};
let progress = |done: usize, total: usize| eprint!("\r{done}/{total} runs");
let curves = ida::hunt_fill(&suite, &settings, 2, analysis, Some(&progress))?;
for (r, c) in suite.iter().zip(&curves) {
    assert!(c.points.len() <= settings.runs);
    println!("{}: collapse between scales {:?}", r.title, c.collapse);
}
// The 16, 50 and 84 % intensities at drifts of 1, 2 and 3 cm.
let f = ida::fractiles(&curves, &[0.01, 0.02, 0.03], &[0.16, 0.5, 0.84])?;
println!("median scale at 2 cm: {:?}", f.at(1, 1));
# Ok::<(), Box<dyn std::error::Error>>(())
```"#;

/// One record of the suite: ground acceleration (m/s², every 0.02 s).
struct Rec {
    name: String,
    kind: &'static str,
    ag: Vec<f64>,
    /// `Sa(T₁, 5 %)` (g).
    sa: f64,
}

/// splitmix64: a seeded stream of 64-bit words.
fn splitmix(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A synthetic record of 30 s at 0.02 s (m/s²): Gaussian white noise (splitmix64 and
/// Box–Muller, seed `seed`) through the Kanai–Tajimi filter (ω_g = 5π rad/s, ζ_g = 0.6,
/// integrated at 10 sub-steps a sample), times an envelope rising as t² to 2 s, flat to
/// 12 s, decaying as e^{−0.25(t−12)}; scaled to the peak `pga` (m/s²).
fn synthetic(seed: u64, pga: f64) -> Vec<f64> {
    let (wg, zg, sub) = (5.0 * std::f64::consts::PI, 0.6, 10);
    let dt = elcentro::DT / sub as f64;
    let mut state = seed;
    let mut uniform = || (splitmix(&mut state) >> 11) as f64 / (1u64 << 53) as f64;
    let (mut x, mut v) = (0.0f64, 0.0f64);
    let n = (30.0 / elcentro::DT) as usize;
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        // One standard normal a sample, held over its sub-steps (variance ∝ 1/dt).
        let (u1, u2) = (uniform().max(1e-300), uniform());
        let w = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
        let mut a = 0.0;
        for _ in 0..sub {
            let acc = -w - 2.0 * zg * wg * v - wg * wg * x;
            v += dt * acc;
            x += dt * v;
            a = -(2.0 * zg * wg * v + wg * wg * x);
        }
        let t = i as f64 * elcentro::DT;
        let env = if t < 2.0 {
            (t / 2.0) * (t / 2.0)
        } else if t < 12.0 {
            1.0
        } else {
            (-0.25 * (t - 12.0)).exp()
        };
        out.push(a * env);
    }
    let peak = out.iter().fold(0.0f64, |m, a| m.max(a.abs()));
    out.iter().map(|a| a * pga / peak).collect()
}

fn pga(ag: &[f64]) -> f64 {
    ag.iter().fold(0.0f64, |m, a| m.max(a.abs()))
}

/// The first-mode period of the uniform 5-storey shear building (s):
/// `ω₁ = 2 √(k/m) sin(π / (2(2N + 1)))`, exact for equal masses and stiffnesses.
fn first_period() -> f64 {
    let w1 = 2.0
        * (models::FIVE_STOREY_STIFFNESS / models::FIVE_STOREY_MASS).sqrt()
        * (std::f64::consts::PI / 22.0).sin();
    std::f64::consts::TAU / w1
}

fn suite(t1: f64) -> Result<Vec<Rec>, aemstep::Error> {
    // The real record through the AT2 reader (the same samples as the `.txt` the scenes use).
    let at2 = records::Record::from_at2(include_str!("../../../data/elcentro-ns-1940.AT2"))?;
    let el: Vec<f64> = at2.scaled(G)?;
    assert_eq!(el.as_slice(), &elcentro::AG_F64[..]);
    let mut list = vec![
        (
            "El Centro 1940 NS".to_string(),
            "real (data/elcentro-ns-1940.AT2)",
            el.clone(),
        ),
        (
            "El Centro reversed".to_string(),
            "derived: El Centro, time reversed",
            el.iter().rev().copied().collect(),
        ),
    ];
    for seed in 1..=4u64 {
        list.push((
            format!("synthetic {seed}"),
            "synthetic: filtered noise, seeded",
            synthetic(seed, pga(&el)),
        ));
    }
    list.into_iter()
        .map(|(name, kind, ag)| {
            let sa = ida::spectral_acceleration(&ag, elcentro::DT, t1, ZETA)? / G;
            Ok(Rec { name, kind, ag, sa })
        })
        .collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args().nth(1).unwrap_or_else(|| "docs".into());
    let t1 = first_period();
    let recs = suite(t1)?;
    let (bld, stepper) = (ida_scene::building()?, ida_scene::stepper()?);
    let analysis = |r: &Rec, im: f64| {
        ida_scene::peak_drift(
            &bld,
            &stepper,
            &r.ag,
            im / r.sa,
            ida_scene::steps(r.ag.len()),
        )
    };
    let settings = HuntFill {
        first: 0.05,
        step: 0.15,
        step_increment: 0.1,
        resolution: 0.05,
        runs: 12,
        collapse: Collapse {
            edp: COLLAPSE_DRIFT,
            on_failure: OnFailure::Collapse,
        },
    };
    let curves = ida::hunt_fill(&recs, &settings, THREADS, analysis, None)?;
    // El Centro sign-flipped: the building is symmetric, so the curve is the same.
    let flipped = Rec {
        name: "El Centro, sign flipped".into(),
        kind: "",
        ag: recs[0].ag.iter().map(|a| -a).collect(),
        sa: recs[0].sa,
    };
    let flip = ida::trace(&flipped, &settings, analysis)?;
    let same_bits = flip.points.len() == curves[0].points.len()
        && flip
            .points
            .iter()
            .zip(&curves[0].points)
            .all(|(a, b)| a.edp.to_bits() == b.edp.to_bits() && a.intensity == b.intensity);
    let levels: Vec<f64> = (0..=36).map(|i| i as f64 * 0.0025).collect();
    let fr = ida::fractiles(&curves, &levels, &QS)?;
    let table = ida::fractiles(&curves, &LEVELS, &QS)?;

    // Constant-ductility spectra of El Centro, EPP (α = 0), 5 %.
    let periods: [f64; P] =
        std::array::from_fn(|i| 0.05 * (3.0f64 / 0.05).powf(i as f64 / (P - 1) as f64));
    let bank = Yielding::<f64, P>::new(periods, [ZETA; P], 0.0, elcentro::DT)?;
    let el = &recs[0].ag;
    let elastic = bank.elastic_strength(el)?;
    let mut spectra: Vec<[f64; P]> = vec![elastic.map(|a| a / G)];
    let mut passes = Vec::new();
    let mut unconverged = 0;
    for &mu in &MUS[1..] {
        let cd = bank.constant_ductility(el, mu, &Search::DEFAULT)?;
        unconverged += cd
            .outcome
            .iter()
            .filter(|o| **o != Outcome::Converged)
            .count();
        passes.push(cd.passes);
        spectra.push(cd.yield_acceleration.map(|a| a / G));
    }

    let md = page(
        &recs,
        &curves,
        &settings,
        t1,
        same_bits,
        &table,
        &periods,
        &spectra,
        &passes,
        unconverged,
    );
    std::fs::write(format!("{dir}/ida.md"), md)?;
    plot_ida(&format!("{dir}/ida.svg"), &recs, &curves, &levels, &fr)?;
    plot_spectra(&format!("{dir}/ida_spectra.svg"), &periods, &spectra)?;
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn page(
    recs: &[Rec],
    curves: &[Curve],
    s: &HuntFill,
    t1: f64,
    same_bits: bool,
    table: &Fractiles,
    periods: &[f64; P],
    spectra: &[[f64; P]],
    passes: &[u32],
    unconverged: usize,
) -> String {
    let mut md = String::new();
    let runs: usize = curves.iter().map(|c| c.points.len()).sum();
    let steps: u64 = recs
        .iter()
        .zip(curves)
        .map(|(r, c)| ida_scene::steps(r.ag.len()) * c.points.len() as u64)
        .sum();
    let failed: usize = curves
        .iter()
        .flat_map(|c| &c.points)
        .filter(|p| p.error.is_some())
        .count();
    let _ = write!(
        md,
        "# Incremental dynamic analysis and inelastic spectra\n\n\
Produced by `cargo run --release -p xtask --bin ida` (deterministic IEEE arithmetic, no \
timing) — do not edit by hand.\n\n\
## Use it\n\n\
Records from PEER AT2 or one-column text (`aemstep::records`), any analysis as a closure \
from (record, intensity) to the EDP, hunt-and-fill over the suite on two threads with a \
progress callback, then the fractiles (feature `std`):\n\n{USE_IT}\n\n"
    );
    let _ = write!(
        md,
        "## The method\n\n\
**Hunt and fill** (`ida::hunt_fill`; one record: `ida::trace`), after Vamvatsikos and \
Cornell (2002, *Incremental dynamic analysis*, Earthquake Engng Struct. Dyn. 31(3), the \
tracing algorithm), with a fixed budget of runs a record, so the cost is known before the \
analysis starts:\n\n\
1. *hunt up*: the first intensity, then each the last plus a step that grows by a fixed \
increment every run, until a run collapses or the budget is spent (then the record \
never collapsed and its curve has no collapse bracket);\n\
2. *bracket*: bisection between the highest non-collapsing and the lowest collapsing \
intensity until they are at most the resolution apart, or the budget is spent;\n\
3. *fill*: the rest of the budget at the midpoints of the largest gaps between the \
non-collapsing intensities below the collapse (from zero), the largest first.\n\n\
**Collapse** (`ida::Collapse`): a peak drift of at least the collapse EDP, or a failed \
analysis (here: Newton not converging, `Error::NotConverged`) counted as collapse \
(`OnFailure::Collapse`; `OnFailure::Abort` returns the error instead). A collapse found \
inside the non-collapsing range (a non-monotone curve) lowers the collapse intensity.\n\n\
**Fractiles** (`ida::fractiles`): of the *intensity given the EDP*. Each curve, its \
non-collapsing points joined by straight lines from the origin, is read where it first \
reaches each EDP level; past its last point a collapsed curve stays at that intensity \
(the flatline); the quantile across records is linear between order statistics (numpy's \
default). The intensity at a given drift is finite for every record, collapsed or not; the \
drift at a given intensity is infinite past a record's collapse, which is why fractiles are \
taken this way round. A record that never collapsed and never reached a level is censored \
there: a fractile that depends on it is reported as NaN, not guessed.\n\n\
**Stripes** (`ida::stripes`): every record at every intensity of a list, one run a job, \
the same curves and fractiles.\n\n"
    );
    let _ = write!(
        md,
        "## The suite and the curves\n\n\
The building of `scenes/ida/building.rs`: the 5-storey shear building, every storey \
bilinear (yield drift 3 cm, 5 % hardening), 5 % Rayleigh damping, h = 5 ms, Newton to \
1e-12 in at most 50 iterations. First-mode period T₁ = {t1:.4} s (exact for the uniform \
shear building). Intensity: Sa(T₁, 5 %) in g; each record runs scaled by `Sa / Sa_record` \
(`ida::spectral_acceleration`). Hunt and fill: first {} g, step {} g growing by {} g a \
run, resolution {} g, {} runs a record; collapse at {} m of storey drift or a failed \
analysis. {} records on {THREADS} threads: {runs} runs, {steps} steps in all, {failed} \
runs failed (counted as collapse).\n\n\
Only El Centro is a recorded motion: the repository holds no other. The others are \
stated for what they are: El Centro reversed in time, and four synthetic records — \
Gaussian white noise (seeds 1 to 4) through a Kanai–Tajimi filter (ω_g = 5π rad/s, \
ζ_g = 0.6), an envelope (rising to 2 s, strong to 12 s, decaying after), 30 s, scaled to \
El Centro's peak. El Centro with its sign flipped is not in the suite: the building is \
symmetric, and its curve equals El Centro's bit for bit ({}).\n\n\
| record | kind | PGA (g) | Sa(T₁) (g) | runs | collapse between Sa (g) | peak drift of the last non-collapse (m) |\n\
|---|---|---:|---:|---:|---|---:|\n",
        s.first,
        s.step,
        s.step_increment,
        s.resolution,
        s.runs,
        COLLAPSE_DRIFT,
        recs.len(),
        if same_bits {
            "measured: identical"
        } else {
            "measured: NOT identical"
        },
    );
    for (r, c) in recs.iter().zip(curves) {
        let (bracket, last) = match c.collapse {
            Some([lo, hi]) => {
                let e = c
                    .points
                    .iter()
                    .filter(|p| !p.collapsed && p.intensity <= lo)
                    .map(|p| p.edp)
                    .next_back()
                    .unwrap_or(0.0);
                (format!("{lo:.4} – {hi:.4}"), format!("{e:.4}"))
            }
            None => ("none within the budget".into(), "—".into()),
        };
        let _ = writeln!(
            md,
            "| {} | {} | {:.4} | {:.4} | {} | {bracket} | {last} |",
            r.name,
            r.kind,
            pga(&r.ag) / G,
            r.sa,
            c.points.len(),
        );
    }
    let _ = write!(
        md,
        "\n![IDA curves of the six records and their 16/50/84 % fractiles](ida.svg)\n\n\
Fractiles of Sa(T₁) (g) given the peak storey drift:\n\n\
| drift (m) | 16 % | 50 % | 84 % |\n|---:|---:|---:|---:|\n"
    );
    for (j, e) in LEVELS.iter().enumerate() {
        let cell = |x: f64| {
            if x.is_nan() {
                "NaN".to_string()
            } else {
                format!("{x:.4}")
            }
        };
        let _ = writeln!(
            md,
            "| {e:.3} | {} | {} | {} |",
            cell(table.at(0, j).unwrap_or(f64::NAN)),
            cell(table.at(1, j).unwrap_or(f64::NAN)),
            cell(table.at(2, j).unwrap_or(f64::NAN))
        );
    }
    let _ = write!(
        md,
        "\n## Inelastic spectra of El Centro\n\n\
Constant-ductility strength spectra (`spectrum::inelastic::Yielding::constant_ductility`, \
the largest strength giving the target ductility, `Search::DEFAULT`): elastic–perfectly \
plastic, 5 % damping, {P} periods log-spaced from {:.2} s to {:.2} s; μ = 1 is the \
elastic strength (the pseudo-spectral acceleration). Yield strength per unit weight \
f_y/(m g); record passes per spectrum {}; periods not converged: {unconverged}.\n\n\
![constant-ductility spectra of El Centro](ida_spectra.svg)\n\n\
| T (s) | μ = 1 | μ = 2 | μ = 4 | μ = 6 | R at μ = 4 |\n|---:|---:|---:|---:|---:|---:|\n",
        periods[0],
        periods[P - 1],
        passes
            .iter()
            .map(|p| p.to_string())
            .collect::<Vec<_>>()
            .join(", "),
    );
    for i in (0..P).step_by(6).chain([P - 1]) {
        let _ = writeln!(
            md,
            "| {:.3} | {:.4} | {:.4} | {:.4} | {:.4} | {:.3} |",
            periods[i],
            spectra[0][i],
            spectra[1][i],
            spectra[2][i],
            spectra[3][i],
            spectra[0][i] / spectra[2][i],
        );
    }
    md
}

/// The IDA curves (thin, one colour each, with their flatlines) and the fractiles (black).
fn plot_ida(
    path: &str,
    recs: &[Rec],
    curves: &[Curve],
    levels: &[f64],
    fr: &Fractiles,
) -> plot::Res<()> {
    let root = SVGBackend::new(path, (1000, 600)).into_drawing_area();
    root.fill(&WHITE)?;
    let xmax = 100.0 * COLLAPSE_DRIFT * 1.1;
    let ymax = curves
        .iter()
        .flat_map(|c| &c.points)
        .filter(|p| !p.collapsed)
        .map(|p| p.intensity)
        .fold(0.0f64, f64::max)
        * 1.15;
    let mut ch = plot::chart(
        &root,
        "IDA curves: Sa(T1, 5 %) (g) against peak storey drift (cm)",
        0.0..xmax,
        0.0..ymax,
    )?;
    ch.configure_mesh()
        .x_desc("peak storey drift (cm)")
        .draw()?;
    let colours = [RED, BLUE, GREEN, MAGENTA, CYAN, RGBColor(255, 140, 0)];
    for (i, (r, c)) in recs.iter().zip(curves).enumerate() {
        let top = c.collapse.map_or(f64::INFINITY, |b| b[1]);
        let mut pts = vec![(0.0, 0.0)];
        pts.extend(
            c.points
                .iter()
                .filter(|p| !p.collapsed && p.intensity < top)
                .map(|p| (100.0 * p.edp, p.intensity)),
        );
        // The flatline, from the last non-collapsing point to the right edge.
        if let (Some(&(x, y)), Some(_)) = (pts.last(), c.collapse)
            && x < xmax
        {
            pts.push((xmax, y));
        }
        let style = colours[i % colours.len()].stroke_width(1);
        plot::line(&mut ch, r.name.clone(), pts.clone(), style)?;
        ch.draw_series(
            pts[1..]
                .iter()
                .filter(|(x, _)| *x < xmax)
                .map(|&(x, y)| Circle::new((x, y), 3, style.filled())),
        )?;
    }
    for (k, (q, w)) in QS.iter().zip([1, 3, 1]).enumerate() {
        let pts: Vec<(f64, f64)> = levels
            .iter()
            .zip(fr.curve(k).unwrap_or(&[]))
            .filter(|(_, y)| y.is_finite())
            .map(|(&e, &y)| (100.0 * e, y))
            .collect();
        plot::line(
            &mut ch,
            format!("{:.0} % fractile", 100.0 * q),
            pts,
            BLACK.stroke_width(w),
        )?;
    }
    plot::legend(&mut ch, SeriesLabelPosition::LowerRight)?;
    root.present()?;
    Ok(())
}

/// The constant-ductility spectra, f_y/(m g) against T.
fn plot_spectra(path: &str, periods: &[f64; P], spectra: &[[f64; P]]) -> plot::Res<()> {
    let root = SVGBackend::new(path, (1000, 500)).into_drawing_area();
    root.fill(&WHITE)?;
    let ymax = spectra[0].iter().fold(0.0f64, |m, &y| m.max(y)) * 1.1;
    let mut ch = plot::chart(
        &root,
        "El Centro 1940 NS: constant-ductility strength f_y/(m g), EPP, 5 %",
        0.0..3.0,
        0.0..ymax,
    )?;
    ch.configure_mesh().x_desc("period T (s)").draw()?;
    let colours = [BLACK, BLUE, GREEN, RED];
    for (k, mu) in MUS.iter().enumerate() {
        let pts = periods
            .iter()
            .zip(&spectra[k])
            .map(|(&t, &y)| (t, y))
            .collect();
        plot::line(
            &mut ch,
            format!("μ = {mu}"),
            pts,
            colours[k].stroke_width(2),
        )?;
    }
    plot::legend(&mut ch, SeriesLabelPosition::UpperRight)?;
    root.present()?;
    Ok(())
}
