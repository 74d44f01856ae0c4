//! A yielding shear building under El Centro: the 3-storey building of the hysteresis page
//! (`docs/hysteresis.md`; floor masses 100 t, storey stiffness 100 MN/m, bilinear storeys
//! yielding at 600, 500 and 350 kN with 5 % post-yield stiffness, 2 % Rayleigh damping),
//! stepped by `Nonlinear` through the 1940 NS record at h = 0.01 s.
//! Prints the peak storey drifts (m and % of a 3 m storey height), the peak base shear (kN)
//! and the storey ductilities.
//!
//! Run: `cargo run --release --example yielding_building [RECORD]` (RECORD: one acceleration
//! in g per line, `#` comments, dt = 0.02 s; default `data/elcentro-ns-1940.txt`).

use aemstep::hysteresis::{Bilinear, HistoryModel, ShearBuilding};
use aemstep::nalgebra::SVector;
use aemstep::{NewtonSettings, Nonlinear, models};

const N: usize = 3;
const MASS: f64 = 1.0e5; // kg, every floor
const STIFFNESS: f64 = 1.0e8; // N/m, every storey
const YIELD: [f64; N] = [6.0e5, 5.0e5, 3.5e5]; // N, ground storey first
const ALPHA: f64 = 0.05; // post-yield stiffness ratio
const XI: f64 = 0.02; // Rayleigh damping ratio in the first two elastic modes
const STOREY_HEIGHT: f64 = 3.0; // m (for drift ratios only)
const DT: f64 = 0.02; // s, the record's sample interval
const G: f64 = 9.80665; // m/s² per g

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let default = concat!(env!("CARGO_MANIFEST_DIR"), "/data/elcentro-ns-1940.txt");
    let path = std::env::args().nth(1).unwrap_or_else(|| default.into());
    let ag: Vec<f64> = std::fs::read_to_string(&path)?
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(|l| l.parse::<f64>().map(|a| a * G))
        .collect::<Result<_, _>>()?;

    // Rayleigh damping from the elastic frequencies of modes 1 and 2 (rad/s):
    // ω_r = 2 √(k/m) sin((2r − 1)π/(4N + 2)) for a uniform shear building.
    let (m, k) = models::shear_building([MASS; N], [STIFFNESS; N]);
    let root = (STIFFNESS / MASS).sqrt();
    let w = |r: f64| {
        2.0 * root * ((2.0 * r - 1.0) * core::f64::consts::PI / (4.0 * N as f64 + 2.0)).sin()
    };
    let (a0, a1) = models::rayleigh_coefficients(w(1.0), w(2.0), XI);
    let c = models::rayleigh(&m, &k, a0, a1);
    let laws = YIELD.map(|fy| Bilinear::new(STIFFNESS, fy, ALPHA));
    let laws = [laws[0]?, laws[1]?, laws[2]?];
    let building = ShearBuilding::<f64, _, N>::new([MASS; N], laws, &c)?;

    // h = DT / 2, the record linear between its samples.
    let h = DT / 2.0;
    let ground = |n: usize| {
        let (i, odd) = (n / 2, n % 2 == 1);
        let a = |j: usize| ag.get(j).copied().unwrap_or(0.0);
        if odd { 0.5 * (a(i) + a(i + 1)) } else { a(i) }
    };
    let stepper = Nonlinear::<f64, N>::new(h, NewtonSettings::up_to(30, 1e-10))?;
    let zero = SVector::<f64, N>::zeros();
    let (mut s, mut hist) = stepper.start_with_history(
        &building,
        &zero,
        &zero,
        &building.ground_load(ground(0)),
        &building.initial_history(),
    )?;
    let (mut drift, mut shear, mut t_shear) = ([0.0f64; N], 0.0f64, 0.0);
    for n in 1..2 * ag.len() - 1 {
        let p = building.ground_load(ground(n));
        stepper.try_step_with_history(&building, &mut s, &mut hist, &p)?;
        let d = ShearBuilding::<f64, Bilinear<f64>, N>::drifts(s.u());
        for i in 0..N {
            drift[i] = drift[i].max(d[i].abs());
        }
        // Base shear: the ground storey's restoring force at the committed state.
        let f0 = building.storeys(&hist, s.u(), s.v())[0].force.abs();
        if f0 > shear {
            (shear, t_shear) = (f0, n as f64 * h);
        }
    }

    println!(
        "Yielding 3-storey building under {path} ({:.2} s, h = {h} s)",
        ag.len() as f64 * DT
    );
    println!("  storey   peak drift (m)   drift ratio (%)   ductility (peak drift / yield drift)");
    for i in 0..N {
        println!(
            "  {:>6}   {:>14.5}   {:>15.3}   {:>9.2}",
            i + 1,
            drift[i],
            100.0 * drift[i] / STOREY_HEIGHT,
            drift[i] / (YIELD[i] / STIFFNESS)
        );
    }
    println!(
        "  peak base shear {:.1} kN at t = {t_shear:.2} s (ground-storey yield force {:.0} kN)",
        shear / 1e3,
        YIELD[0] / 1e3
    );
    Ok(())
}
