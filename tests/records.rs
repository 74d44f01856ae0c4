//! Record readers (`aemstep::records`): the repository's El Centro AT2 (count, interval,
//! first and last values, every value equal to the one-column `.txt`), the header
//! spellings in use, malformed input as typed errors with the line, `f32` buffers, the
//! `std` conveniences (text and files), and random text never panics (proptest).

use aemstep::records::{self, At2};
use aemstep::{Error, Param};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

const AT2: &str = include_str!("../data/elcentro-ns-1940.AT2");
const TXT: &str = include_str!("../data/elcentro-ns-1940.txt");

fn bad(line: u32) -> Error {
    Error::MalformedRecord { line }
}

/// AT2 text with the given line 4 and values.
fn with_header(line4: &str, values: &str) -> String {
    format!(
        "TITLE\nEVENT, 1/1/00, STATION, 000\nACCELERATION TIME SERIES IN UNITS OF G\n{line4}\n{values}"
    )
}

#[test]
fn el_centro_at2_count_interval_ends_and_equal_to_the_txt() {
    let h = records::at2(AT2).unwrap();
    assert_eq!(h.npts, 3995);
    assert_eq!(h.dt, 0.02);
    assert_eq!(h.units, "ACCELERATION TIME SERIES IN UNITS OF G");
    assert!(
        h.event
            .starts_with("Imperial Valley (El Centro) 1940-05-19, NS")
    );
    let mut ag = vec![0.0f64; 4000];
    assert_eq!(h.read_into(&mut ag).unwrap(), 3995);
    assert_eq!(ag[0], -6.4031800e-3);
    assert_eq!(ag[1], -6.0287100e-3);
    assert_eq!(ag[3994], 1.2536000e-4);
    // The one-column text of the same record: the same 3995 numbers, bit for bit.
    let txt: Vec<f64> = records::column(TXT).collect::<Result<_, _>>().unwrap();
    assert_eq!(txt.len(), 3995);
    assert_eq!(&ag[..3995], &txt[..]);
    // f32 buffers: each value rounded once from its f64.
    let mut ag32 = vec![0.0f32; 3995];
    assert_eq!(records::column_into(TXT, &mut ag32).unwrap(), 3995);
    assert!(ag32.iter().zip(&txt).all(|(&a, &b)| a == b as f32));
}

#[test]
fn header_spellings() {
    let values = " .1000000E-02  .2000000E-02\n -.3000000E-02\n";
    let want = [0.001, 0.002, -0.003];
    for line4 in [
        "NPTS=     3, DT=   .0100 SEC",
        "NPTS=3, DT=.01 SEC,",
        "    3    0.0100    NPTS, DT",
        "3 .01 NPTS, DT, SEC",
        "npts = 3   dt = 0.01",
        "NPTS= 3, DT= 0.01SEC",
        "Npts=3 Dt=1e-2 sec",
    ] {
        let text = with_header(line4, values);
        let h = records::at2(&text).unwrap_or_else(|e| panic!("{line4:?}: {e}"));
        assert_eq!((h.npts, h.dt), (3, 0.01), "{line4:?}");
        let v: Vec<f64> = h.values().collect::<Result<_, _>>().unwrap();
        assert_eq!(v, want, "{line4:?}");
    }
    // CRLF line ends and a byte-order mark.
    let crlf = format!("\u{feff}{}", with_header("NPTS= 3, DT= .01", values)).replace('\n', "\r\n");
    let h = records::at2(&crlf).unwrap();
    assert_eq!(h.title, "TITLE");
    assert_eq!(h.values().collect::<Result<Vec<_>, _>>().unwrap(), want);
}

#[test]
fn malformed_headers_are_typed_errors() {
    assert_eq!(records::at2(""), Err(bad(1)));
    assert_eq!(records::at2("a\nb\n"), Err(bad(3)));
    assert_eq!(records::at2("a\nb\nc\n"), Err(bad(4)));
    for line4 in [
        "",
        "NPTS= x, DT= .01",
        "NPTS= 0, DT= .01",
        "NPTS= -3, DT= .01",
        "NPTS= 3.5, DT= .01",
        "NPTS= 3, DT= 0",
        "NPTS= 3, DT= -.01",
        "NPTS= 3, DT= nan",
        "NPTS= 3, DT= inf",
        "NPTS= 3",
        "DT= .01",
        "3 .01",
        "NPTS, DT 3 .01",
        "NPTS= 99999999999999999999999, DT= .01",
        "1 2 3 4 5 6 7 8 9 10 11 12 13 NPTS DT",
    ] {
        let text = with_header(line4, "1 2 3\n");
        assert_eq!(records::at2(&text), Err(bad(4)), "{line4:?}");
    }
}

#[test]
fn malformed_values_are_typed_errors_with_the_line() {
    let check = |values: &str, want: Error| {
        let text = with_header("NPTS= 3, DT= .01", values);
        let h = records::at2(&text).unwrap();
        let mut out = [0.0f64; 3];
        assert_eq!(h.read_into(&mut out), Err(want), "{values:?}");
        // The iterator yields one error and ends.
        let mut it = h.values();
        assert!(it.by_ref().any(|v| v.is_err()));
        assert_eq!(it.next(), None);
    };
    check("1 2\n", bad(6)); // two values: the text ends with line 5
    check("1 2", bad(6)); // no final newline
    check("1 2 3 4\n", bad(5)); // one too many
    check("1 2 3\n\n4\n", bad(7));
    check("1 x 3\n", bad(5));
    check("1\n2\nnan\n", bad(7));
    check("1 inf 3\n", bad(5));
    check("1 1e999 3\n", bad(5)); // overflows f64
    check("1 -1.0E-03-2.0E-03\n", bad(5)); // Fortran fields run together
    check("1 1.0D-03 3\n", bad(5));
    // A buffer too short: nothing written.
    let text = with_header("NPTS= 3, DT= .01", "1 2 3\n");
    let mut short = [7.0f64; 2];
    assert_eq!(
        records::at2(&text).unwrap().read_into(&mut short),
        Err(Error::InvalidParameter(Param::OutputBuffer))
    );
    assert_eq!(short, [7.0; 2]);
    // Finite in f64, infinite in f32.
    let text = with_header("NPTS= 3, DT= .01", "1\n2\n1e39\n");
    let mut f32s = [0.0f32; 3];
    assert_eq!(
        records::at2(&text).unwrap().read_into(&mut f32s),
        Err(bad(7))
    );
}

#[test]
fn one_column() {
    let v: Vec<f64> = records::column("# header\n# dt = 0.01\n1.5\n  -2 # note\n\n3e-3\n")
        .collect::<Result<_, _>>()
        .unwrap();
    assert_eq!(v, [1.5, -2.0, 3e-3]);
    let err = |text: &str| records::column(text).find_map(Result::err);
    assert_eq!(err("1\n2 3\n"), Some(bad(2)));
    assert_eq!(err("1\nabc\n"), Some(bad(2)));
    assert_eq!(err("1\nNaN\n"), Some(bad(2)));
    assert_eq!(err(""), Some(bad(1)));
    assert_eq!(err("# only a header\n\n"), Some(bad(3)));
    assert_eq!(err("1,2\n"), Some(bad(1)));
    let mut out = [0.0f64; 2];
    assert_eq!(
        records::column_into("1\n2\n3\n", &mut out),
        Err(Error::InvalidParameter(Param::OutputBuffer))
    );
    assert_eq!(records::column_into("1\n2\n", &mut out), Ok(2));
}

/// Issue 31: the one-column reader ignored a `# dt` header (a record whose header says
/// 0.02 s was read at the caller's 0.01 s without a word). Every accepted spelling, and the
/// malformed ones with their line.
#[cfg(feature = "std")]
#[test]
fn one_column_dt_header_is_read_and_checked() {
    for (text, dt) in [
        ("# dt = 0.01\n1\n", 0.01),
        ("#DT=0.005\n1\n", 0.005),
        ("  # dt: 0.02 s\n1\n", 0.02),
        ("# Dt 2e-3 SEC\n1\n", 0.002),
        ("# dt = 0.01s\n1\n", 0.01),
        ("# dt=0.01sec\n1\n", 0.01),
        ("\u{feff}# title\n# dt = 0.01\n1\n", 0.01),
        ("1\n2\n# dt = 0.01\n", 0.01), // anywhere, as a whole-line comment
        ("# dt = 0.02 s, 3995 samples\n1\n", 0.02), // the El Centro file's header
        ("# dt=0.02; from quakeio\n1\n", 0.02),
    ] {
        assert_eq!(records::column_dt(text), Ok(Some(dt)), "{text:?}");
        let mut buf = [0.0f64; 4];
        assert!(records::column_into(text, &mut buf).is_ok(), "{text:?}");
    }
    for text in [
        "1\n",
        "# station 12, 5 % damped\n1\n",
        "1 # dt = 0.01\n", // a trailing comment is not a header
        "# dtx = 0.01\n1\n",
    ] {
        assert_eq!(records::column_dt(text), Ok(None), "{text:?}");
    }
    for (text, line) in [
        ("# dt\n1\n", 1),
        ("# dt = \n1\n", 1),
        ("# x\n# dt = 0\n1\n", 2),
        ("# dt = -0.01\n1\n", 1),
        ("# dt = nan\n1\n", 1),
        ("# dt = inf\n1\n", 1),
        ("# dt = 1e999\n1\n", 1),
        ("# dt = 0.01 ms\n1\n", 1),
        ("# dt = 0.01 s extra\n1\n", 1),
        ("# dt = 0.01 0.02\n1\n", 1),
        ("# dt = 0.01\n1\n# dt = 0.01\n", 3),
    ] {
        assert_eq!(records::column_dt(text), Err(bad(line)), "{text:?}");
    }
    // The std reader: the header's interval, or the caller's if it agrees.
    use aemstep::records::Record;
    let r = Record::from_column_with_header("# dt = 0.02\n0.5\n-0.5\n").unwrap();
    assert_eq!((r.dt, r.samples.as_slice()), (0.02, &[0.5, -0.5][..]));
    assert_eq!(
        Record::from_column("# dt = 0.02\n0.5\n", 0.02).unwrap().dt,
        0.02
    );
    assert_eq!(
        Record::from_column("# dt = 0.02\n0.5\n", 0.01),
        Err(Error::InvalidTimeStep)
    );
    assert_eq!(Record::from_column_with_header("0.5\n"), Err(bad(1)));
    assert_eq!(
        Record::from_column_with_header("# dt = x\n0.5\n"),
        Err(bad(1))
    );
}

#[cfg(feature = "std")]
#[test]
fn std_records_from_text_and_files() {
    let r = records::Record::from_at2(AT2).unwrap();
    assert_eq!((r.samples.len(), r.dt), (3995, 0.02));
    assert!(r.title.starts_with("PEER-format"));
    let c = records::Record::from_column(TXT, 0.02).unwrap();
    assert_eq!(c.samples, r.samples);
    assert_eq!(records::column_dt(TXT), Ok(Some(0.02)));
    assert_eq!(records::Record::from_column_with_header(TXT).unwrap(), c);
    assert_eq!(r.scaled(records::G).unwrap()[0], -6.4031800e-3 * 9.80665);
    for dt in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert_eq!(
            records::Record::from_column(TXT, dt),
            Err(Error::InvalidTimeStep)
        );
    }
    assert_eq!(
        records::Record::from_at2("a\nb\nc\nNPTS= 2, DT= .01\n1\n"),
        Err(bad(6))
    );

    let dir = std::env::temp_dir().join(format!("aemstep-records-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = dir.join("elcentro.AT2");
    std::fs::write(&good, AT2).unwrap();
    assert_eq!(records::Record::read_at2(&good).unwrap(), r);
    let col = dir.join("elcentro.txt");
    std::fs::write(&col, TXT).unwrap();
    let c = records::Record::read_column(&col, 0.02).unwrap();
    assert_eq!((c.title.as_str(), c.samples.len()), ("elcentro.txt", 3995));
    let broken = dir.join("broken.AT2");
    std::fs::write(&broken, "a\nb\nc\nNPTS= 2, DT= .01\n1 x\n").unwrap();
    let e = records::Record::read_at2(&broken).unwrap_err();
    assert_eq!(e.kind(), std::io::ErrorKind::InvalidData);
    let inner = e.get_ref().and_then(|e| e.downcast_ref::<Error>());
    assert_eq!(inner, Some(&bad(5)));
    let missing = records::Record::read_at2(dir.join("none.AT2")).unwrap_err();
    assert_eq!(missing.kind(), std::io::ErrorKind::NotFound);
    std::fs::write(&broken, [0xffu8, 0xfe, b'\n']).unwrap();
    assert_eq!(
        records::Record::read_at2(&broken).unwrap_err().kind(),
        std::io::ErrorKind::InvalidData
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Parses `text` both ways; whatever it is, no panic, and a success is consistent: exactly
/// `npts` finite values.
fn parse_anything(text: &str) {
    if let Ok(h) = records::at2(text) {
        check_at2(&h);
    }
    let mut buf = [0.0f64; 64];
    let n = records::column_into(text, &mut buf);
    if let Ok(n) = n {
        assert!(n >= 1 && buf[..n].iter().all(|v| v.is_finite()));
    }
    let _ = records::column(text).count();
    let _ = records::column_dt(text);
}

fn check_at2(h: &At2<'_>) {
    let mut n = 0;
    let mut failed = false;
    for v in h.values() {
        match v {
            Ok(x) => {
                assert!(x.is_finite());
                n += 1;
            }
            Err(Error::MalformedRecord { line }) => {
                assert!(line >= 5);
                failed = true;
            }
            Err(e) => panic!("unexpected {e:?}"),
        }
    }
    assert!(failed || n == h.npts, "{n} values for NPTS {}", h.npts);
    assert!(n <= h.npts);
}

/// Text near the format: a header line either well formed (both spellings) or of random
/// keywords, numbers and separators, then tokens mostly numbers, some junk — so the parser
/// often gets past the header and sometimes reads a whole record.
fn near_at2() -> impl Strategy<Value = String> {
    let tok = prop_oneof![
        Just("NPTS".to_string()),
        Just("DT".to_string()),
        Just("SEC".to_string()),
        Just("=".to_string()),
        Just(",".to_string()),
        (0u32..6).prop_map(|n| n.to_string()),
        (-1e3f64..1e3).prop_map(|x| format!("{x:e}")),
        "[ -~]{0,4}",
    ];
    let header = prop_oneof![
        (1usize..6, 1u32..100)
            .prop_map(|(n, d)| format!("NPTS= {n}, DT= {:.4} SEC", d as f64 * 1e-3)),
        (1usize..6, 1u32..100).prop_map(|(n, d)| format!("{n} {:.4} NPTS, DT", d as f64 * 1e-3)),
        prop::collection::vec(tok, 0..8).prop_map(|t| t.join(" ")),
    ];
    let value = prop_oneof![
        12 => (-1.0f64..1.0).prop_map(|x| format!("{x:.7E}")),
        2 => Just("\n".to_string()),
        1 => Just("nan".to_string()),
        1 => Just("1e999".to_string()),
        1 => "[ -~\n]{0,3}",
    ];
    (header, prop::collection::vec(value, 0..8))
        .prop_map(|(h, v)| format!("t\ne\nu\n{h}\n{}", v.join(" ")))
}

#[test]
fn random_text_never_panics() {
    // A fixed seed (reproducible); AEMSTEP_PROP_CASES sets the cases (default 2000).
    let cases = std::env::var("AEMSTEP_PROP_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2000);
    let config = Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    };
    let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &[24; 32]);
    let mut runner = TestRunner::new_with_rng(config.clone(), rng);
    runner
        .run(&prop::collection::vec(any::<u8>(), 0..300), |bytes| {
            parse_anything(&String::from_utf8_lossy(&bytes));
            Ok(())
        })
        .unwrap();
    let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &[25; 32]);
    let mut runner = TestRunner::new_with_rng(config, rng);
    let (headers, complete) = (std::cell::Cell::new(0u32), std::cell::Cell::new(0u32));
    runner
        .run(&near_at2(), |text| {
            parse_anything(&text);
            if let Ok(h) = records::at2(&text) {
                headers.set(headers.get() + 1);
                complete.set(complete.get() + h.values().all(|v| v.is_ok()) as u32);
            }
            Ok(())
        })
        .unwrap();
    // The generator reaches the values, and some records parse whole.
    let (headers, complete) = (headers.get(), complete.get());
    println!("near-AT2 text: {headers} of {cases} headers read, {complete} records whole");
    assert!(
        headers > cases / 50 && complete > 0,
        "{headers} headers, {complete} complete"
    );
}

/// `sin(2π f t)` at `t = k·dt`, `k = 0..n`.
fn sine_at(f: f64, dt: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| (std::f64::consts::TAU * f * k as f64 * dt).sin())
        .collect()
}

/// Resampled with the library, the length checked against `resampled_len`.
fn resampled(x: &[f64], dt: f64, h: f64) -> Vec<f64> {
    let n = records::resampled_len(x.len(), dt, h).unwrap();
    let mut y = vec![f64::NAN; n + 3];
    assert_eq!(records::resample_into(x, dt, h, &mut y), Ok(n));
    assert!(y[n..].iter().all(|v| v.is_nan()), "wrote past its length");
    y.truncate(n);
    y
}

/// Upsampling is linear interpolation: exact (to rounding) against the interpolant written
/// here, at a ratio that is not a power of two; and the output length covers the record.
#[test]
fn resample_upsampling_is_linear_interpolation() {
    let dt = 0.02;
    let x: Vec<f64> = (0..50).map(|k| ((k * 37) % 11) as f64 - 5.0).collect();
    let h = dt / 3.0;
    let y = resampled(&x, dt, h);
    assert_eq!(y.len(), 49 * 3 + 1); // t from 0 to the end, 0.98 s
    let mut worst = 0.0f64;
    for (k, &yk) in y.iter().enumerate() {
        let t = k as f64 * h;
        let j = ((t / dt).floor() as usize).min(x.len() - 2);
        let th = t / dt - j as f64;
        let exact = x[j] + th * (x[j + 1] - x[j]);
        worst = worst.max((yk - exact).abs());
    }
    // Both sides round the position t/dt = k·h/dt (two roundings each, ≤ 4ε·49 apart at
    // the end) and the slope is at most 10: ≤ 4·49ε·10 + a few ulps of 5 (measured 5.0e-14).
    println!("upsampling vs the linear interpolant: {worst:.1e}");
    assert!(
        worst <= (4.0 * 49.0 * 10.0 + 8.0 * 5.0) * f64::EPSILON,
        "{worst:e}"
    );
    // A sine: linear interpolation's error ≤ ω² dt²/8 (amplitude 1).
    let (f, dt) = (1.3, 0.01);
    let x = sine_at(f, dt, 400);
    let h = 0.0037;
    let y = resampled(&x, dt, h);
    let w = std::f64::consts::TAU * f;
    let err = y
        .iter()
        .enumerate()
        .map(|(k, v)| (v - (w * k as f64 * h).sin()).abs())
        .fold(0.0, f64::max);
    let bound = w * w * dt * dt / 8.0;
    println!("upsampled 1.3 Hz sine: error {err:.3e}, bound ω²dt²/8 = {bound:.3e}");
    assert!(err <= bound && err >= 0.5 * bound, "{err:e} vs {bound:e}");
    // h = dt: a copy.
    assert_eq!(resampled(&x, dt, dt), x);
}

/// Downsampling filters first: a sine above the new Nyquist frequency (which plain
/// decimation would alias, at full amplitude, onto a lower frequency) comes out attenuated
/// by the Blackman window's stop band (about 74 dB: ≤ 2e-4 of the amplitude); one in the
/// pass band (below 0.6 of the new Nyquist frequency) comes out as itself.
#[test]
fn resample_downsampling_filters_before_it_decimates() {
    let (dt, h) = (0.002, 0.01); // 500 Hz to 100 Hz: new Nyquist 50 Hz
    let n = 2500; // 5 s
    // the filter's half-length M = ⌈13.75 h/dt⌉ = 69 input samples: skip its edges
    let edge = (70.0f64 * dt / h).ceil() as usize + 1;
    let interior = |y: &[f64]| edge..y.len() - edge;
    let mut worst_stop = 0.0f64;
    for f in [50.0, 55.0, 60.0, 80.0, 120.0, 249.0] {
        let x = sine_at(f, dt, n);
        // plain decimation aliases it at (nearly) full amplitude
        let alias = (0..n / 5).map(|k| x[5 * k].abs()).fold(0.0, f64::max);
        let y = resampled(&x, dt, h);
        let peak = y[interior(&y)].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        println!("{f} Hz: decimated {alias:.3}, resampled peak {peak:.2e}");
        worst_stop = worst_stop.max(peak);
        if f != 50.0 {
            assert!(alias > 0.5, "{f} Hz aliases (test premise)");
        }
    }
    // Blackman: about −74 dB (2e-4); measured 1.56e-4 at 55 Hz, 1.1 of the new Nyquist.
    assert!(worst_stop <= 2e-4, "stop band {worst_stop:e}");
    // Pass band at an integer ratio (outputs on input samples, no interpolation): the
    // filter's own gain error, up to 0.6 of the new Nyquist frequency (where the
    // transition band, 0.6 to 1.0 of it, begins).
    let mut ripple = 0.0f64;
    for f in [0.5, 5.0, 15.0, 25.0, 30.0] {
        let x = sine_at(f, dt, n);
        let y = resampled(&x, dt, h);
        let w = std::f64::consts::TAU * f;
        let err = interior(&y)
            .map(|k| (y[k] - (w * k as f64 * h).sin()).abs())
            .fold(0.0, f64::max);
        println!("{f} Hz pass band, ratio 5: error {err:.2e}");
        ripple = ripple.max(err);
    }
    // the window's ripple, of the order of its stop band (measured 1.85e-4 at 25 Hz)
    assert!(ripple <= 2e-4, "pass band {ripple:e}");
    // At a ratio 2.5 (outputs between input samples): that ripple plus linear
    // interpolation's ω² dt²/8.
    let (dt, h) = (0.004, 0.01);
    for f in [0.5, 2.0, 10.0, 25.0] {
        let x = sine_at(f, dt, 1250);
        let y = resampled(&x, dt, h);
        let w = std::f64::consts::TAU * f;
        let err = interior(&y)
            .map(|k| (y[k] - (w * k as f64 * h).sin()).abs())
            .fold(0.0, f64::max);
        let bound = 2e-4 + w * w * dt * dt / 8.0;
        println!("{f} Hz pass band: error {err:.2e} (bound {bound:.2e})");
        assert!(err <= bound, "{f} Hz: {err:e}");
    }
}

#[test]
fn resample_bad_input_is_typed() {
    let mut out = [0.0f64; 8];
    let x = [0.0, 1.0, 2.0];
    for (dt, h) in [
        (0.0, 0.01),
        (0.01, -1.0),
        (f64::NAN, 0.01),
        (0.01, f64::INFINITY),
    ] {
        assert_eq!(
            records::resample_into(&x, dt, h, &mut out),
            Err(Error::InvalidTimeStep)
        );
    }
    assert_eq!(
        records::resample_into(&[0.0, f64::NAN], 0.01, 0.02, &mut out),
        Err(Error::NonFiniteInput)
    );
    assert_eq!(
        records::resample_into(&x, 0.01, 0.001, &mut out),
        Err(Error::InvalidParameter(Param::OutputBuffer))
    );
    assert_eq!(
        records::resample_into::<f64>(&[], 0.01, 0.02, &mut out),
        Ok(0)
    );
    // f32 out of an f64 computation: rounded once; an overflow is typed
    let mut o32 = [0.0f32; 8];
    assert_eq!(
        records::resample_into(&[1.0f32, 3.0], 0.02, 0.01, &mut o32),
        Ok(3)
    );
    assert_eq!(&o32[..3], &[1.0, 2.0, 3.0]);
    let big = [f32::MAX, f32::MAX];
    assert!(records::resample_into(&big, 0.01, 0.0101, &mut o32).is_ok());
    #[cfg(feature = "std")]
    {
        let r = aemstep::records::Record::from_column("1\n2\n", 0.01).unwrap();
        assert_eq!(r.resampled(0.0).map(|_| ()), Err(Error::InvalidTimeStep));
    }
}
