//! A real-time hybrid test on the host: a 3-storey shear building (floor masses 100 t,
//! storey stiffness 100 MN/m, 5 % Rayleigh damping in modes 1 and 2 from
//! `models::natural_frequencies`) under El Centro 1940 NS, whose storey 2 is a "physical"
//! specimen — bilinear, yielding at 1.2 MN, 5 % post-yield stiffness — behind an emulated
//! actuator with a 10 ms delay. The model steps with `hybrid::Split` (KR-α, ρ∞ = 0.9, h =
//! 1/1024 s); `hybrid::StoreySpecimen` maps the floor displacements onto the actuator
//! (`u₂ − u₁`) and the load cell's force back onto floors 1 and 2 (`−f`, `+f`).
//!
//! Three runs: the reference with no actuator (the specimen's force at the model's command),
//! the delayed actuator uncompensated, and with second-order polynomial extrapolation over
//! the delay. Prints the peak storey drifts (m), the actuator's tracking error (m: the
//! displacement reached against the one the model wanted) and the peak specimen force (kN).
//!
//! Run: `cargo run --release --example hybrid_loop [RECORD]` (RECORD: one acceleration in g
//! per line, `#` comments, dt = 0.02 s; default `data/elcentro-ns-1940.txt`).

use aemstep::hybrid::{Actuator, Polynomial, Split, StoreySpecimen};
use aemstep::hysteresis::Bilinear;
use aemstep::models::{self, Rows};
use aemstep::nalgebra::SVector;
use aemstep::prelude::*;

const N: usize = 3;
const MASS: f64 = 1.0e5; // kg, every floor
const STIFFNESS: f64 = 1.0e8; // N/m, every storey
const SPECIMEN: usize = 1; // storey 2, between floors 1 and 2
const YIELD: f64 = 1.2e6; // N, the specimen's yield force
const XI: f64 = 0.05; // damping ratio in modes 1 and 2
const H: f64 = 1.0 / 1024.0; // s, the real-time step
const DELAY: f64 = 0.010; // s, the actuator's delay
const DT: f64 = 0.02; // s, the record's sample interval
const G: f64 = 9.80665; // m/s² per g

/// The model: masses, the whole building's stiffness (what the operators assume) and the
/// numerical part (storey 2 removed), all `const`.
const M_K: (Rows<N>, Rows<N>) = models::shear_building([MASS; N], [STIFFNESS; N]);
const K_NUM: Rows<N> = {
    let mut ks = [STIFFNESS; N];
    ks[SPECIMEN] = 0.0;
    models::shear_building([MASS; N], ks).1
};
const W: [f64; N] = aemstep::unwrap_const!(models::natural_frequencies(&M_K.0, &M_K.1));
const AB: (f64, f64) = models::rayleigh_coefficients(W[0], W[1], XI);
const C: Rows<N> = models::rayleigh(&M_K.0, &M_K.1, AB.0, AB.1);

/// What a run measured.
struct Run {
    drift: [f64; N],
    tracking: f64,
    force: f64,
}

fn run(
    ground: &dyn Fn(usize) -> f64,
    steps: usize,
    actuator: Option<(&Actuator<f64, 16>, Option<&Polynomial<f64>>)>,
) -> Result<Run, aemstep::Error> {
    let sys = Split::<f64, N>::from_rows_f64(M_K.0, C, M_K.1, K_NUM, H, 0.9)?;
    let storey = StoreySpecimen::<N>::new(SPECIMEN)?;
    let specimen = Bilinear::<f64>::new(STIFFNESS, YIELD, 0.05)?;
    let mut hist = specimen.initial_history();
    let load = |n: usize| SVector::<f64, N>::repeat(-MASS * ground(n)); // N
    let zero = SVector::<f64, N>::zeros();
    let mut s = sys.start(&zero, &zero, &zero, &load(0))?;
    let (mut act, mut cs) = (
        actuator.map(|(a, _)| a.rest(0.0)),
        actuator.and_then(|(_, c)| c).map(|c| c.rest(0.0)),
    );
    let mut out = Run {
        drift: [0.0; N],
        tracking: 0.0,
        force: 0.0,
    };
    let mut measured = 0.0; // m, the displacement the actuator reached at the last sample
    for n in 1..=steps {
        let target = storey.command(&sys.command(&s)); // m, storey 2 at t_{n+1}
        let reached = match (actuator, act.as_mut()) {
            (Some((a, comp)), Some(st)) => {
                let command = match (comp, cs.as_mut()) {
                    (Some(c), Some(cst)) => c.command(cst, target, measured)?,
                    _ => target,
                };
                a.step(st, command)?
            }
            _ => target,
        };
        let t = specimen.trial(&hist, reached, 0.0); // N, the load cell
        sys.complete(&mut s, &storey.force(t.force), &load(n))?;
        hist = t.history;
        measured = reached;
        out.tracking = out.tracking.max((reached - target).abs());
        out.force = out.force.max(t.force.abs());
        for (p, d) in out
            .drift
            .iter_mut()
            .zip(models::drifts(s.state().u()).iter())
        {
            *p = p.max(d.abs());
        }
    }
    Ok(out)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let default = concat!(env!("CARGO_MANIFEST_DIR"), "/data/elcentro-ns-1940.txt");
    let path = std::env::args().nth(1).unwrap_or_else(|| default.into());
    let ag: Vec<f64> = std::fs::read_to_string(&path)?
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(|l| l.parse::<f64>().map(|a| a * G))
        .collect::<Result<_, _>>()?;
    // The record linear between its samples, at the real-time rate (m/s²).
    let ground = |n: usize| {
        let t = n as f64 * H / DT;
        let (i, f) = (t as usize, t.fract());
        let a = |j: usize| ag.get(j).copied().unwrap_or(0.0);
        (1.0 - f) * a(i) + f * a(i + 1)
    };
    let steps = ((ag.len() - 1) as f64 * DT / H) as usize;

    let actuator = Actuator::<f64, 16>::new(H, DELAY, 0.0)?;
    let comp = Polynomial::<f64>::new(2, H, DELAY)?;
    println!(
        "3-storey building (m = {:.0} t, k = {:.0} MN/m a storey, T1 = {:.3} s), storey {} a \
         bilinear specimen (f_y = {:.0} kN); h = 1/{:.0} s, actuator delay {:.0} ms; {} steps",
        MASS / 1e3,
        STIFFNESS / 1e6,
        2.0 * core::f64::consts::PI / W[0],
        SPECIMEN + 1,
        YIELD / 1e3,
        1.0 / H,
        DELAY * 1e3,
        steps
    );
    println!(
        "{:<34} {:>26} {:>20} {:>20}",
        "run", "peak drift (m) 1 / 2 / 3", "tracking error (m)", "specimen force (kN)"
    );
    let runs = [
        ("reference: no actuator", run(&ground, steps, None)?),
        (
            "10 ms delay, uncompensated",
            run(&ground, steps, Some((&actuator, None)))?,
        ),
        (
            "10 ms delay, polynomial order 2",
            run(&ground, steps, Some((&actuator, Some(&comp))))?,
        ),
    ];
    for (name, r) in &runs {
        println!(
            "{:<34} {:>8.4} /{:>7.4} /{:>7.4} {:>20.2e} {:>20.1}",
            name,
            r.drift[0],
            r.drift[1],
            r.drift[2],
            r.tracking,
            r.force / 1e3
        );
    }
    let reference = &runs[0].1;
    for (name, r) in &runs[1..] {
        let err = (0..N)
            .map(|i| (r.drift[i] - reference.drift[i]).abs() / reference.drift[i])
            .fold(0.0f64, f64::max);
        println!(
            "{name}: peak drift off the reference by {:.2} %",
            100.0 * err
        );
    }
    Ok(())
}
