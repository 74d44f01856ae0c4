//! The El Centro 1940 NS record (`data/elcentro-ns-1940.txt`, dt = 0.02 s, in g), parsed
//! by the compiler: `static` ground accelerations in m/s², no parsing code in flash.
//!
//! Shared by `examples/firmware/qemu_modal.rs` (firmware) and `tests/firmware_modal.rs` (host),
//! which checks the `const` parser against `str::parse` bit for bit.
#![allow(dead_code)] // each includer uses a different subset

/// The record's text, embedded at build time.
pub const TEXT: &str = include_str!("../../data/elcentro-ns-1940.txt");
/// Samples in the record.
pub const SAMPLES: usize = count(TEXT);
/// Standard gravity (m/s²): the record is in units of g.
pub const G: f64 = 9.80665;
/// Sample interval (s).
pub const DT: f64 = 0.02;
/// Ground acceleration (m/s²), `f64`.
pub static AG_F64: [f64; SAMPLES] = parse(TEXT);
/// Ground acceleration (m/s²), rounded once to `f32`.
pub static AG_F32: [f32; SAMPLES] = to_f32(&parse(TEXT));

/// Data lines: not empty, not starting with `#`.
const fn count(s: &str) -> usize {
    let b = s.as_bytes();
    let (mut i, mut n) = (0, 0);
    while i < b.len() {
        let start = i;
        while i < b.len() && b[i] != b'\n' {
            i += 1;
        }
        if i > start && b[start] != b'#' && b[start] != b'\r' {
            n += 1;
        }
        i += 1;
    }
    n
}

/// `g ·` each data line, where a line is `[-]digits[.digits]`. The decimal value is formed
/// as `mantissa / 10^k` with both exact in `f64` (mantissa < 2⁵³, k ≤ 22), so the
/// quotient is the correctly rounded decimal, as `str::parse` gives.
const fn parse<const M: usize>(s: &str) -> [f64; M] {
    let b = s.as_bytes();
    let mut out = [0.0; M];
    let (mut i, mut n) = (0, 0);
    while i < b.len() {
        let start = i;
        while i < b.len() && b[i] != b'\n' {
            i += 1;
        }
        if i > start && b[start] != b'#' && b[start] != b'\r' {
            let mut j = start;
            let neg = b[j] == b'-';
            if neg || b[j] == b'+' {
                j += 1;
            }
            let (mut mant, mut frac, mut in_frac) = (0u64, 0u32, false);
            while j < i && b[j] != b'\r' {
                let c = b[j];
                if c == b'.' {
                    in_frac = true;
                } else if c >= b'0' && c <= b'9' {
                    mant = mant * 10 + (c - b'0') as u64;
                    if in_frac {
                        frac += 1;
                    }
                } else {
                    panic!("El Centro record: unexpected character");
                }
                j += 1;
            }
            assert!(
                mant < (1u64 << 53) && frac <= 22,
                "El Centro record: too many digits"
            );
            let mut p = 1.0;
            let mut e = 0;
            while e < frac {
                p *= 10.0;
                e += 1;
            }
            let x = mant as f64 / p;
            out[n] = G * if neg { -x } else { x };
            n += 1;
        }
        i += 1;
    }
    out
}

const fn to_f32<const M: usize>(a: &[f64; M]) -> [f32; M] {
    let mut r = [0.0f32; M];
    let mut i = 0;
    while i < M {
        r[i] = a[i] as f32;
        i += 1;
    }
    r
}
