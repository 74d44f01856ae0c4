//! A small incremental dynamic analysis (feature `std`): the yielding 3-storey building of
//! `examples/yielding_building.rs` (floor masses 100 t, storey stiffness 100 MN/m, bilinear
//! storeys yielding at 600, 500 and 350 kN, 5 % post-yield stiffness, 2 % Rayleigh damping
//! from `models::natural_frequencies`, storeys 3 m high) under El Centro 1940 NS read from
//! `data/elcentro-ns-1940.AT2` (`records::Record`), and the same record reversed in time (a
//! derived record, stated as such: the repository holds no other recorded motion), each
//! scaled to a stripe of peak ground accelerations on the batch pool (`ida::stripes`).
//!
//! Prints each record's IDA curve: the intensity, the peak ground acceleration (g), against
//! the peak storey drift ratio (%), and the collapse bracket (collapse: a drift ratio of 4 %,
//! or Newton failing).
//!
//! Run: `cargo run --release --features std --example ida [RECORD.AT2]`.

use aemstep::hysteresis::{Bilinear, ShearBuilding};
use aemstep::ida::{self, Collapse, OnFailure};
use aemstep::models::{self, Rows};
use aemstep::nalgebra::SVector;
use aemstep::prelude::*;
use aemstep::records::{self, Record};
use aemstep::{Error, NewtonSettings, Nonlinear};

const N: usize = 3;
const MASS: f64 = 1.0e5; // kg, every floor
const STIFFNESS: f64 = 1.0e8; // N/m, every storey
const YIELD: [f64; N] = [6.0e5, 5.0e5, 3.5e5]; // N, ground storey first
const XI: f64 = 0.02; // Rayleigh damping ratio in modes 1 and 2
const STOREY_HEIGHT: f64 = 3.0; // m
const COLLAPSE_RATIO: f64 = 0.04; // peak drift ratio taken as collapse
const PGA: [f64; 8] = [0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.8]; // g, the stripes

const M_K: (Rows<N>, Rows<N>) = models::shear_building([MASS; N], [STIFFNESS; N]);
const W: [f64; N] = aemstep::unwrap_const!(models::natural_frequencies(&M_K.0, &M_K.1));
const AB: (f64, f64) = models::rayleigh_coefficients(W[0], W[1], XI);
const C: Rows<N> = models::rayleigh(&M_K.0, &M_K.1, AB.0, AB.1);

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let default = concat!(env!("CARGO_MANIFEST_DIR"), "/data/elcentro-ns-1940.AT2");
    let path = std::env::args().nth(1).unwrap_or_else(|| default.into());
    let recorded = Record::read_at2(&path)?; // g, every dt
    let reversed = Record {
        title: "the same, reversed in time".into(),
        dt: recorded.dt,
        samples: recorded.samples.iter().rev().copied().collect(),
    };
    let suite = [recorded, reversed];

    let laws = YIELD.map(|fy| Bilinear::new(STIFFNESS, fy, 0.05));
    let building = ShearBuilding::<f64, _, N>::new([MASS; N], [laws[0]?, laws[1]?, laws[2]?], &C)?;

    // One analysis: the record scaled to a peak ground acceleration of `pga` g, stepped at
    // h = dt/2 (the record linear between its samples); its EDP the peak drift ratio.
    let analysis = |r: &Record, pga: f64| -> Result<f64, Error> {
        let peak = r.samples.iter().fold(0.0f64, |p, a| p.max(a.abs()));
        let scale = pga / peak * records::G; // m/s² per sample unit
        let a = |j: usize| scale * r.samples.get(j).copied().unwrap_or(0.0);
        let ground = |n: usize| {
            let i = n / 2;
            if n % 2 == 1 {
                0.5 * (a(i) + a(i + 1))
            } else {
                a(i)
            }
        };
        let stepper = Nonlinear::<f64, N>::new(r.dt / 2.0, NewtonSettings::up_to(30, 1e-10))?;
        let zero = SVector::<f64, N>::zeros();
        let (mut s, mut hist) = stepper.start_with_history(
            &building,
            &zero,
            &zero,
            &building.ground_load(ground(0)),
            &building.initial_history(),
        )?;
        let mut drift = 0.0f64;
        for n in 1..2 * r.samples.len() - 1 {
            stepper.try_step_with_history(
                &building,
                &mut s,
                &mut hist,
                &building.ground_load(ground(n)),
            )?;
            drift = models::drifts(s.u())
                .iter()
                .fold(drift, |d, x| d.max(x.abs()));
        }
        Ok(drift / STOREY_HEIGHT)
    };
    let collapse = Collapse {
        edp: COLLAPSE_RATIO,
        on_failure: OnFailure::Collapse,
    };
    let curves = ida::stripes(&suite, &PGA, &collapse, 2, analysis, None)?;

    println!(
        "IDA of the yielding 3-storey building (T1 = {:.3} s) under {} and its time reversal; \
         intensity: peak ground acceleration (g); EDP: peak storey drift ratio (%); \
         collapse at {:.0} % or a failed Newton step",
        2.0 * core::f64::consts::PI / W[0],
        std::path::Path::new(&path)
            .file_name()
            .map_or(path.as_str().into(), |f| f.to_string_lossy()),
        100.0 * COLLAPSE_RATIO
    );
    println!(
        "{:>8} {:>30} {:>30}",
        "PGA (g)", "drift ratio (%): El Centro", "reversed"
    );
    for (j, pga) in PGA.iter().enumerate() {
        let cell = |c: &ida::Curve| {
            let p = &c.points[j];
            if p.collapsed {
                "collapse".to_string()
            } else {
                format!("{:.3}", 100.0 * p.edp)
            }
        };
        println!(
            "{:>8.2} {:>30} {:>30}",
            pga,
            cell(&curves[0]),
            cell(&curves[1])
        );
    }
    for (r, c) in ["El Centro", "reversed"].iter().zip(&curves) {
        match c.collapse {
            Some([lo, hi]) => println!("{r}: collapse between PGA {lo:.2} g and {hi:.2} g"),
            None => println!("{r}: no collapse up to PGA {:.2} g", PGA[PGA.len() - 1]),
        }
    }
    Ok(())
}
