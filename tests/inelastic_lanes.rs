//! The record-level inelastic spectra step the yielding bank in SIMD lanes (oscillators side
//! by side, `f64 × 2` on SSE2, `× 4` with AVX; a lane with fewer sub-steps a sample frozen)
//! and the constant-ductility search steps only its unfinished trials, packed into lanes.
//! Both must give the bits of the per-oscillator scalar step, [`Yielding::step`]:
//!
//! - `response_is_the_scalar_step_bit_for_bit`: [`Yielding::response`] against a loop of
//!   [`Yielding::step`] and [`Yielding::free_vibration`] (the scalar path, kept for streaming
//!   and the Cortex-M firmware), every field by `to_bits`, at `P = 1, 3, 5, 7, 16`, EPP and
//!   bilinear, finite strengths and `+∞`, El Centro whole and cut, `f64` and `f32`, with
//!   NaN samples under [`NonFinite::Skip`].
//! - `spectra_match_the_pinned_scalar_results` (and its `#[ignore]`d long twin): digests
//!   (FNV-1a over the `to_bits` of every field: strengths, brackets, ductilities,
//!   outcomes, passes, skipped) of `constant_ductility` (`μ = 2, 4, 6`) and
//!   `constant_strength` computed by the scalar build **before** the lane path existed
//!   (commit ee62e96): a regression pin, labelled as such.
//!
//! Run also in the SSE2-only control build
//! (`RUSTFLAGS='--cfg aemstep_control="sse2-only"'`), where the lanes are 2 wide.
#![allow(clippy::needless_range_loop)]

#[path = "../scenes/modal/elcentro.rs"]
mod elcentro;

use aemstep::Real;
use aemstep::spectrum::NonFinite;
use aemstep::spectrum::inelastic::{ConstantDuctility, Outcome, Search, YieldResponse, Yielding};

const DT: f64 = elcentro::DT;

fn periods<const P: usize>(lo: f64, hi: f64) -> [f64; P] {
    if P == 1 {
        return [lo; P];
    }
    core::array::from_fn(|i| lo * (hi / lo).powf(i as f64 / (P - 1) as f64))
}

/// El Centro with a few NaN and ∞ samples (for `NonFinite::Skip`).
fn holed(n: usize) -> Vec<f64> {
    let mut r = elcentro::AG_F64[..n].to_vec();
    for (k, i) in [0usize, 17, 18, n / 2 + 1, n - 1].into_iter().enumerate() {
        r[i] = if k % 2 == 0 { f64::NAN } else { f64::INFINITY };
    }
    r
}

struct Fnv(u64);
impl Fnv {
    fn new() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
    fn u64(&mut self, x: u64) {
        for b in x.to_le_bytes() {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
    fn reals<T: Real>(&mut self, xs: &[T]) {
        for &x in xs {
            self.u64(x.as_f64().to_bits());
        }
    }
}

fn digest_cd<T: Real, const P: usize>(h: &mut Fnv, cd: &ConstantDuctility<T, P>) {
    h.reals(&cd.yield_acceleration);
    h.reals(&cd.elastic);
    h.reals(cd.bracket.as_flattened());
    h.reals(cd.ductility.as_flattened());
    for o in cd.outcome {
        h.u64(match o {
            Outcome::Converged => 1,
            Outcome::NoCrossing => 2,
            Outcome::NotConverged => 3,
        });
    }
    h.u64(cd.passes as u64);
    h.u64(cd.skipped);
}

fn digest_response<T: Real, const P: usize>(h: &mut Fnv, r: &YieldResponse<T, P>) {
    h.reals(r.sd());
    h.reals(&r.ductility());
    h.reals(r.displacement());
    h.reals(r.velocity());
    h.reals(r.force());
    h.reals(r.yield_acceleration());
    h.reals(r.plastic_work());
    h.reals(r.plastic_deformation());
    h.reals(r.yield_displacement());
    for &c in r.yielding_substeps() {
        h.u64(c as u64);
    }
    h.u64(r.samples());
    h.u64(r.skipped());
}

/// Every field of two responses, bit for bit.
fn same<T: Real, const P: usize>(a: &YieldResponse<T, P>, b: &YieldResponse<T, P>, what: &str) {
    let (mut x, mut y) = (Fnv::new(), Fnv::new());
    digest_response(&mut x, a);
    digest_response(&mut y, b);
    assert_eq!(x.0, y.0, "{what}: {a:?}\n!=\n{b:?}");
}

/// The scalar path: `step` every sample, then the free vibration `response` appends.
fn scalar<T: Real, const P: usize>(
    y: &Yielding<T, P>,
    rec: &[T],
    ay: &[T; P],
) -> YieldResponse<T, P> {
    let mut r = y.at_rest(ay).unwrap();
    for &a in rec {
        y.step(&mut r, a);
    }
    y.free_vibration(&mut r, y.free_vibration_samples());
    r
}

fn check_response<const P: usize>(lo: f64, hi: f64, n: usize) {
    for alpha in [0.0, 0.05] {
        let y = Yielding::<f64, P>::new(periods(lo, hi), [0.05; P], alpha, DT)
            .unwrap()
            .with_non_finite(NonFinite::Skip);
        let y32 = Yielding::<f32, P>::new(periods(lo, hi), [0.05; P], alpha, DT)
            .unwrap()
            .with_non_finite(NonFinite::Skip);
        let clean = &elcentro::AG_F64[..n];
        let holes = holed(n);
        let clean32 = &elcentro::AG_F32[..n];
        let strengths: [[f64; P]; 3] = [
            core::array::from_fn(|p| 0.5 + 0.4 * p as f64),
            core::array::from_fn(|p| if p % 2 == 0 { f64::INFINITY } else { 1.5 }),
            [f64::INFINITY; P],
        ];
        for ay in &strengths {
            let what = format!("P = {P}, α = {alpha}, N = {n}, a_y = {ay:?}");
            same(
                &y.response(clean, ay).unwrap(),
                &scalar(&y, clean, ay),
                &what,
            );
            same(
                &y.response(&holes, ay).unwrap(),
                &scalar(&y, &holes, ay),
                &what,
            );
            let ay32 = ay.map(|a| a as f32);
            same(
                &y32.response(clean32, &ay32).unwrap(),
                &scalar(&y32, clean32, &ay32),
                &what,
            );
        }
    }
}

#[test]
fn response_is_the_scalar_step_bit_for_bit() {
    check_response::<1>(0.3, 0.3, 400);
    check_response::<3>(0.05, 1.0, 333);
    check_response::<5>(0.1, 3.0, 401);
    check_response::<7>(0.04, 0.5, 250);
    check_response::<16>(0.05, 3.0, 150);
}

/// Digest of the spectra of a `P`-bank on `rec` (μ = 2, 4, 6; EPP and bilinear).
fn spectra_digest<const P: usize>(lo: f64, hi: f64, rec: &[f64], policy: NonFinite) -> u64 {
    let mut h = Fnv::new();
    for alpha in [0.0, 0.05] {
        let y = Yielding::<f64, P>::new(periods(lo, hi), [0.05; P], alpha, DT)
            .unwrap()
            .with_non_finite(policy);
        for mu in [2.0, 4.0, 6.0] {
            digest_cd(
                &mut h,
                &y.constant_ductility(rec, mu, &Search::DEFAULT).unwrap(),
            );
        }
        let cs = y.constant_strength(rec, &[4.0; P]).unwrap();
        h.reals(&cs.elastic);
        h.reals(&cs.yield_acceleration);
        h.reals(&cs.ductility);
        h.reals(&cs.plastic_work);
        digest_response(&mut h, &cs.response);
    }
    h.0
}

/// `f32` twin of [`spectra_digest`] (μ = 4, EPP and bilinear).
fn spectra_digest_f32<const P: usize>(lo: f64, hi: f64, rec: &[f32]) -> u64 {
    let mut h = Fnv::new();
    for alpha in [0.0, 0.05] {
        let y = Yielding::<f32, P>::new(periods(lo, hi), [0.05; P], alpha, DT).unwrap();
        let s = Search {
            tol: 1e-5,
            ..Search::DEFAULT
        };
        digest_cd(&mut h, &y.constant_ductility(rec, 4.0, &s).unwrap());
    }
    h.0
}

/// Regression pin: digests computed by the scalar per-oscillator build (commit ee62e96),
/// before the lane path.
#[test]
fn spectra_match_the_pinned_scalar_results() {
    let short = &elcentro::AG_F64[..300];
    let got = [
        spectra_digest::<1>(0.5, 0.5, short, NonFinite::Refuse),
        spectra_digest::<3>(0.05, 1.0, short, NonFinite::Refuse),
        spectra_digest::<5>(0.2, 2.0, &holed(200), NonFinite::Skip),
    ];
    println!("{got:#x?}");
    assert_eq!(got, PINNED_SHORT);
}

/// Regression pin (long): the whole of El Centro at `P = 16` and `P = 7` (`f64`), and
/// `P = 5` in `f32`; scalar digests as above.
#[test]
#[ignore = "long: about 1 s in release, a minute in debug"]
fn spectra_match_the_pinned_scalar_results_long() {
    let got = [
        spectra_digest::<16>(0.05, 3.0, &elcentro::AG_F64, NonFinite::Refuse),
        spectra_digest::<7>(0.1, 2.0, &holed(elcentro::SAMPLES - 500), NonFinite::Skip),
        spectra_digest_f32::<5>(0.1, 3.0, &elcentro::AG_F32),
    ];
    println!("{got:#x?}");
    assert_eq!(got, PINNED_LONG);
}

const PINNED_SHORT: [u64; 3] = [
    0x368f_6757_41c9_5a81,
    0xd6b8_6942_65b5_1504,
    0x720e_4af5_7b45_f344,
];
const PINNED_LONG: [u64; 3] = [
    0x9c16_5d57_30bd_f58f,
    0x975e_84cc_316b_eba9,
    0x14f9_f104_59d2_03ed,
];
