//! Estimating storey drifts from a few accelerometers: the 5-storey benchmark building
//! (`aemstep::models::five_storey_building`) under El Centro, whose "true" ground storey is
//! 10 % softer than the model's. Two accelerometers (floors 2 and 5, absolute acceleration,
//! noise 0.2 m/s² RMS) and the measured ground acceleration feed a fixed-gain observer with
//! the steady-state Kalman gain; its drift estimates are compared with the truth's.
//!
//! Run: `cargo run --release --example observer [RECORD]` (RECORD: one acceleration in g per
//! line, `#` comments, dt = 0.02 s; default `data/elcentro-ns-1940.txt`).

use aemstep::models::{self, base_excitation};
use aemstep::nalgebra::SVector;
use aemstep::observer::{Observer, Outputs, Readout, StateSpace, SteadyState};
use aemstep::{LinearInput, Stepper};

const H: f64 = 0.02; // s, the record's sample interval
const G: f64 = 9.80665; // m/s² per g
const SENSORS: [usize; 2] = [1, 4]; // floors 2 and 5
const SIGMA_Y: f64 = 0.2; // accelerometer noise (m/s², standard deviation)
const SIGMA_F: f64 = 5.0e4; // process noise: unmodelled force on each floor (N)

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let default = concat!(env!("CARGO_MANIFEST_DIR"), "/data/elcentro-ns-1940.txt");
    let path = std::env::args().nth(1).unwrap_or_else(|| default.into());
    let ag: Vec<f64> = std::fs::read_to_string(&path)?
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(|l| l.parse::<f64>().map(|a| a * G))
        .collect::<Result<_, _>>()?;

    // The model, and the truth: the same building with storey 1 10 % softer.
    let (m, c, k) = models::five_storey_building();
    let mut ks = [models::FIVE_STOREY_STIFFNESS; 5];
    ks[0] *= 0.9;
    let (_, k_true) = models::shear_building([models::FIVE_STOREY_MASS; 5], ks);
    let truth = LinearInput::<f64, 5, 1>::from_rows(m, c, k_true, base_excitation(&m), H)?;

    // The observer: the model's discrete state space, the accelerometers, the drift readout
    // and the steady-state Kalman gain (process noise: white forces on every floor).
    let model = StateSpace::aem_from_rows(m, c, k, base_excitation(&m), H)?;
    let meas = model.outputs(&Outputs::absolute_accelerations(
        Outputs::<5, 1, 2>::select(SENSORS),
        0,
    ))?;
    let drifts = model.outputs(&Outputs::displacements(models::storey_drifts::<5>()))?;
    let mut unit_forces = [[0.0; 5]; 5];
    (0..5).for_each(|i| unit_forces[i][i] = 1.0);
    let forces = StateSpace::aem_from_rows(m, c, k, unit_forces, H)?;
    let mut qf = [[0.0; 5]; 5];
    (0..5).for_each(|i| qf[i][i] = SIGMA_F * SIGMA_F);
    let r = [[SIGMA_Y * SIGMA_Y, 0.0], [0.0, SIGMA_Y * SIGMA_Y]];
    let gain = SteadyState::solve(&model, &meas, &forces.input_noise(&qf), &r)?;
    let obs = Observer::<f64, 10, 1, 2>::from_parts(&model, &meas, &gain.gain)?;
    let readout = Readout::<f64, 10, 1, 5>::from_parts(&drifts)?;

    let w = |a: f64| SVector::from([a]);
    let zero = SVector::zeros();
    let mut s = truth.start(&zero, &zero, &w(ag[0]))?;
    let mut e = obs.start_at_rest(&w(ag[0]))?;
    let mut noise = 0x2545_F491_4F6C_DD1Du64; // xorshift64; Irwin–Hall sum of 12 uniforms
    let mut gauss = || {
        (0..12)
            .map(|_| {
                noise ^= noise << 13;
                noise ^= noise >> 7;
                noise ^= noise << 17;
                (noise >> 11) as f64 / (1u64 << 53) as f64
            })
            .sum::<f64>()
            - 6.0
    };
    let (mut sq, mut peak) = ([0.0f64; 5], [0.0f64; 5]);
    for &a in &ag[1..] {
        truth.try_step(&mut s, &w(a))?;
        let y = SVector::from(SENSORS.map(|f| s.a()[f] + a + SIGMA_Y * gauss()));
        obs.try_step(&mut e, &w(a), &y)?;
        let est = readout.read(e.x(), &w(a));
        for i in 0..5 {
            let d = s.u()[i] - if i > 0 { s.u()[i - 1] } else { 0.0 };
            sq[i] += (est[i] - d).powi(2);
            peak[i] = peak[i].max(d.abs());
        }
    }

    let n = (ag.len() - 1) as f64;
    println!("Observer on the 5-storey building, {path}, accelerometers on floors 2 and 5");
    println!("  storey   peak true drift (m)   RMS drift error (m)");
    for i in 0..5 {
        println!(
            "  {:>6}   {:>19.3e}   {:>19.3e}",
            i + 1,
            peak[i],
            (sq[i] / n).sqrt()
        );
    }
    println!(
        "  ({} doubling iterations for the steady-state gain)",
        gain.iterations
    );
    Ok(())
}
