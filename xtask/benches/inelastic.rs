//! Host benchmark of the inelastic spectra (`aemstep::spectrum::inelastic`): the
//! constant-ductility spectra of El Centro (3 995 samples at 0.02 s) at 40 periods
//! (log-spaced 0.05–3 s, 5 % damping) × `μ = 2, 4, 6` × EPP (`α = 0`) and bilinear
//! (`α = 0.05`): 240 searches with [`Search::DEFAULT`], one thread; and the
//! constant-strength spectra (`R = 4`) of the same bank. Each is timed as repeated whole
//! calls and the fastest is printed as `FASTEST <id> <seconds>` (on a shared machine the
//! fastest call is the least disturbed), with the record passes and oscillator sub-steps.
//!
//! Run: `cargo bench -p xtask --bench inelastic` (about 30 s); `python3
//! scripts/bench_inelastic.py` runs it beside an openseespy loop.

#[path = "../../scenes/modal/elcentro.rs"]
mod elcentro;

use std::hint::black_box;
use std::time::Instant;

use aemstep::spectrum::inelastic::{Search, Yielding};

const P: usize = 40;
const DT: f64 = 0.02;

fn periods() -> [f64; P] {
    core::array::from_fn(|i| 0.05 * 60f64.powf(i as f64 / (P - 1) as f64))
}

fn fastest(id: &str, reps: usize, f: &mut dyn FnMut() -> u64) {
    let mut best = f64::INFINITY;
    let mut work = 0;
    for _ in 0..reps {
        let t = Instant::now();
        work = black_box(f());
        best = best.min(t.elapsed().as_secs_f64());
    }
    println!("FASTEST {id} {best:.6} passes {work}");
}

fn main() {
    let rec: &[f64] = &elcentro::AG_F64;
    let banks =
        [0.0, 0.05].map(|a| Yielding::<f64, P>::new(periods(), [0.05; P], a, DT).expect("bank"));
    println!(
        "# {P} periods 0.05-3 s, El Centro {} samples; sub-steps a sample {}",
        rec.len(),
        banks[0].substeps_per_sample()
    );
    fastest("constant_ductility/40x3x2", 5, &mut || {
        let mut passes = 0;
        for b in &banks {
            for mu in [2.0, 4.0, 6.0] {
                let cd = b
                    .constant_ductility(black_box(rec), mu, &Search::DEFAULT)
                    .expect("cd");
                passes += cd.passes as u64;
            }
        }
        passes
    });
    fastest("constant_strength/40x2", 10, &mut || {
        for b in &banks {
            black_box(b.constant_strength(black_box(rec), &[4.0; P]).expect("cs"));
        }
        4
    });
    fastest("response/40", 20, &mut || {
        black_box(banks[0].response(black_box(rec), &[1.0; P]).expect("r"));
        1
    });
}
