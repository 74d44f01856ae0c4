//! Response spectrum of an accelerogram as CSV: 5 % damping, 50 periods log-spaced from
//! 0.02 s to 10 s; columns period (s), Sd (m), Sv (m/s), Sa (g).
//!
//! Run: `cargo run --release --example spectrum_csv [RECORD [DT]] > spectrum.csv`
//! RECORD: one ground acceleration in g per line, `#` comments (default
//! `data/elcentro-ns-1940.txt`); DT: its sample interval in s (default: from a
//! `# dt = … s` comment line of the record).

use aemstep::spectrum::Bank;

const P: usize = 50;
const G: f64 = 9.80665; // m/s² per g

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let default = concat!(env!("CARGO_MANIFEST_DIR"), "/data/elcentro-ns-1940.txt");
    let path = args.next().unwrap_or_else(|| default.into());
    let text = std::fs::read_to_string(&path)?;
    let dt: f64 = match args.next() {
        Some(dt) => dt.parse()?,
        None => text
            .lines()
            .find_map(|l| {
                l.strip_prefix('#')?
                    .trim()
                    .strip_prefix("dt =")?
                    .split_whitespace()
                    .next()
            })
            .ok_or("no `# dt = … s` line in the record: give DT (s) after the path")?
            .parse()?,
    };

    let periods: [f64; P] = core::array::from_fn(|i| 0.02 * 500f64.powf(i as f64 / (P - 1) as f64));
    let bank = Bank::<f64, P>::new(periods, [0.05; P], dt)?;
    let mut r = bank.at_rest();
    for line in text.lines().map(str::trim) {
        if !line.is_empty() && !line.starts_with('#') {
            bank.step(&mut r, line.parse::<f64>()? * G);
        }
    }
    // The record's end is not the oscillators' end: follow the free vibration to the peaks.
    bank.free_vibration(&mut r, bank.free_vibration_samples());

    println!("period_s,sd_m,sv_m_per_s,sa_g");
    let (sd, sv, sa) = (r.sd(), r.sv(), r.sa());
    for (i, t) in periods.iter().enumerate() {
        println!("{t:.4},{:.6e},{:.6e},{:.6e}", sd[i], sv[i], sa[i] / G);
    }
    Ok(())
}
