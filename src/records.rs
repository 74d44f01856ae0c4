//! Ground-motion record readers: PEER NGA **AT2** text and **one-column** text (one value a
//! line), parsed from a `&str` by an iterator or into a caller's `&mut [T]` (`no_std`, no
//! heap), and with the `std` feature into a `Record` (`Vec<f64>`) from text or a file.
//!
//! ```
//! use aemstep::records;
//!
//! let text = "\
//! PEER NGA STRONG MOTION DATABASE RECORD
//! IMPERIAL VALLEY 5/19/40, EL CENTRO ARRAY #9, 180
//! ACCELERATION TIME SERIES IN UNITS OF G
//! NPTS=     5, DT=   .0100 SEC
//!   .1000000E-02  .2000000E-02 -.3000000E-02
//!   .4000000E-02 -.5000000E-02
//! ";
//! let at2 = records::at2(text)?;
//! assert_eq!((at2.npts, at2.dt), (5, 0.01)); // samples, s
//! let mut ag = [0.0f64; 5]; // in g, as in the file
//! let n = at2.read_into(&mut ag)?;
//! assert_eq!(&ag[..n], &[0.001, 0.002, -0.003, 0.004, -0.005]);
//!
//! // One value a line, `#` comments; the time step from a `# dt` header line, if any.
//! let text = "# dt = 0.02 s\n0.5\n-0.25 # a comment\n\n1e-3\n";
//! let mut buf = [0.0f32; 8];
//! let n = records::column_into(text, &mut buf)?;
//! assert_eq!(&buf[..n], &[0.5, -0.25, 1e-3]);
//! assert_eq!(records::column_dt(text)?, Some(0.02)); // s
//!
//! // Bad input is a typed error with the line, never a panic.
//! assert_eq!(
//!     records::at2("t\ne\nu\nNPTS= 2, DT= .01 SEC\n0.1 oops\n")?.read_into(&mut ag),
//!     Err(aemstep::Error::MalformedRecord { line: 5 })
//! );
//! # Ok::<(), aemstep::Error>(())
//! ```
//!
//! **AT2** (the PEER NGA flat-file format; the values are in g for the acceleration files):
//!
//! 1. lines 1–3: free text (title; event, date, station, component; the units line, e.g.
//!    `ACCELERATION TIME SERIES IN UNITS OF G`), kept as [`At2::title`], [`At2::event`],
//!    [`At2::units`] and not interpreted;
//! 2. line 4: the count and the sample interval, in any of the spellings in use: keyword
//!    then value (`NPTS=  4000, DT=   .0050 SEC`, `NPTS = 4000 DT = 0.005`, any case,
//!    `=`/`,`/spaces between, `SEC` optional and possibly glued to the number) or values then
//!    keywords (the older `4000    0.0050    NPTS, DT`);
//! 3. then exactly `NPTS` numbers in free columns (any count a line, separated by white
//!    space): Rust's `f64` syntax, which covers Fortran's `E` formats (`-.6403180E-02`).
//!
//! **One column**: one number a line; blank lines and everything from a `#` to the end of
//! a line are ignored (so a `#` header is allowed); at least one value. The sample
//! interval may be given by a header comment line `# dt = 0.01` ([`column_dt`]: `dt` in
//! any case, then `=`, `:` or blanks, the value in seconds, optionally `s` or `sec`, then
//! optionally a remark after `,` or `;`); a malformed one is [`Error::MalformedRecord`] at
//! its line. Without one, the caller gives the time step.
//!
//! **Bad input** is [`Error::MalformedRecord`] with the 1-based line: a line 4 with no
//! readable `NPTS` (a whole number `> 0`) and `DT` (finite, `> 0`), fewer than 4 lines, a
//! value that is not a finite number (also one that overflows the target type, e.g. `1e39`
//! into `f32`), more or fewer values than `NPTS` (AT2), two values on a line or no value
//! at all (one column). Fortran fields that run together without a space
//! (`-1.0E-03-2.0E-03`) and `D` exponents are not numbers here. A caller's buffer too
//! short for the values is [`Error::InvalidParameter`] (size it with [`At2::npts`], or
//! count [`column()`]'s values first). Nothing here panics, on any bytes (a property test
//! feeds random text).
//!
//! **Resampling** to a stepper's step `h` ([`resample_into`], buffer in, buffer out, no
//! allocation; [`resampled_len`] sizes the buffer; `Record::resampled` with `std`): linear
//! interpolation between samples, and when downsampling (`h > dt`) a Blackman-windowed
//! sinc low-pass first, cutoff [`ANTI_ALIAS_CUTOFF`] `= 0.8` of the new Nyquist frequency,
//! so content the coarser step would alias is removed (about 74 dB down) before it can be.
//!
//! **Cost**: one pass over the text, no allocation (except `Record`'s `Vec`); each value
//! is parsed by `core`'s correctly rounded `f64` parser (`str::parse`), so the values are
//! exactly those of the text, rounded once (to `f32` from that `f64` for `f32` buffers).

use crate::{Error, Param, Real};

/// Standard gravity (m/s²): multiply a PEER acceleration record (in g) by it for m/s².
pub const G: f64 = 9.80665;

/// The header of a PEER AT2 record and its values (not yet parsed): see the
/// [module](self). Made by [`at2`]; borrows the text.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct At2<'a> {
    /// Line 1, trimmed (the title).
    pub title: &'a str,
    /// Line 2, trimmed (event, date, station, component).
    pub event: &'a str,
    /// Line 3, trimmed (the units line, e.g. `ACCELERATION TIME SERIES IN UNITS OF G`).
    pub units: &'a str,
    /// The number of samples `NPTS` (`> 0`).
    pub npts: usize,
    /// The sample interval `DT` (s, finite, `> 0`).
    pub dt: f64,
    /// The text after line 4.
    body: &'a str,
}

/// The header of a PEER AT2 record (its first four lines; see the [module](self)).
///
/// Errors: [`Error::MalformedRecord`] (`line: 4` for an unreadable count or interval; the
/// line after the last for a text of fewer than 4 lines). Cost: a scan of the header.
pub fn at2(text: &str) -> Result<At2<'_>, Error> {
    let mut rest = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = [""; 4];
    for (i, slot) in lines.iter_mut().enumerate() {
        if rest.is_empty() {
            return Err(Error::MalformedRecord { line: i as u32 + 1 });
        }
        let (line, r) = split_line(rest);
        *slot = line.trim();
        rest = r;
    }
    let (npts, dt) = npts_dt(lines[3]).ok_or(Error::MalformedRecord { line: 4 })?;
    Ok(At2 {
        title: lines[0],
        event: lines[1],
        units: lines[2],
        npts,
        dt,
        body: rest,
    })
}

impl<'a> At2<'a> {
    /// The values, in file order and units (g for an acceleration file): exactly
    /// [`At2::npts`] `Ok` items, or an `Err` ([`Error::MalformedRecord`]) where the text
    /// goes wrong (a value not a finite number, a value past `NPTS`, the end before
    /// `NPTS`), after which the iterator ends. Cost: one pass over the values.
    pub fn values(&self) -> Values<'a> {
        Values {
            rest: self.body,
            line: "",
            line_no: 4,
            expected: Some(self.npts),
            seen: 0,
            one_per_line: false,
            done: false,
        }
    }

    /// The values into `out[..npts]` (rounded once to `T`), checked to be exactly `npts`;
    /// returns `npts`. On an error `out` may be partly written.
    ///
    /// Errors: [`Error::InvalidParameter`] if `out.len() < npts` (nothing written), else as
    /// [`At2::values`]. Cost: one pass over the values.
    pub fn read_into<T: Real>(&self, out: &mut [T]) -> Result<usize, Error> {
        if out.len() < self.npts {
            return Err(Error::InvalidParameter(Param::OutputBuffer));
        }
        fill(self.values(), out)
    }
}

/// The values of a one-column record (see the [module](self)), in file order and units:
/// `Ok` items, or one `Err` ([`Error::MalformedRecord`]) where the text goes wrong (two
/// values on a line, a value not a finite number, no value at all), after which the
/// iterator ends. Cost: one pass over the text.
pub fn column(text: &str) -> Values<'_> {
    Values {
        rest: text.strip_prefix('\u{feff}').unwrap_or(text),
        line: "",
        line_no: 0,
        expected: None,
        seen: 0,
        one_per_line: true,
        done: false,
    }
}

/// The sample interval of a one-column record from its `# dt` header line (see the
/// [module](self)): `Some(dt)` (s, finite, `> 0`), or `None` if no comment line is a
/// `dt` header.
///
/// A header is a whole-line comment (first non-blank character `#`) whose first word is
/// `dt` (any case), then `=`, `:` or blanks, the value, and optionally the unit `s` or
/// `sec` (any case, separate or glued to the number), then optionally a remark after a
/// comma or semicolon: `# dt = 0.01`, `#DT: 0.005 s`, `# dt 0.02sec`,
/// `# dt = 0.02 s, 3995 samples`. Any other comment is ignored.
///
/// Errors: [`Error::MalformedRecord`] at the header's line if its value is missing, not a
/// finite number `> 0`, or followed by anything but the unit, or if a second header
/// follows. Cost: one pass over the text, no allocation.
///
/// ```
/// use aemstep::{Error, records};
/// assert_eq!(records::column_dt("# dt = 0.01 s\n0.5\n-0.25\n")?, Some(0.01));
/// assert_eq!(records::column_dt("# station 12\n0.5\n")?, None);
/// assert_eq!(
///     records::column_dt("# units: g\n# dt = fast\n0.5\n"),
///     Err(Error::MalformedRecord { line: 2 })
/// );
/// # Ok::<(), Error>(())
/// ```
pub fn column_dt(text: &str) -> Result<Option<f64>, Error> {
    let mut rest = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut line_no = 0u32;
    let mut found = None;
    while !rest.is_empty() {
        let (line, r) = split_line(rest);
        rest = r;
        line_no = line_no.saturating_add(1);
        let Some(comment) = line.trim_start().strip_prefix('#') else {
            continue;
        };
        match dt_header(comment) {
            None => {}
            Some(Some(dt)) if found.is_none() => found = Some(dt),
            Some(_) => return Err(Error::MalformedRecord { line: line_no }),
        }
    }
    Ok(found)
}

/// A comment (after its `#`) as a `dt` header: `None` if it is not one (its first word is
/// not `dt`), `Some(None)` if it is one but malformed, `Some(Some(dt))` if well formed.
fn dt_header(comment: &str) -> Option<Option<f64>> {
    // a remark may follow after a comma or semicolon: `# dt = 0.02 s, 3995 samples`
    let header = comment.split([',', ';']).next().unwrap_or("");
    let mut words = header
        .split(|c: char| c.is_whitespace() || c == '=' || c == ':' || c == '#')
        .filter(|w| !w.is_empty());
    if !words.next()?.eq_ignore_ascii_case("dt") {
        return None;
    }
    let unit = |w: &str| w.eq_ignore_ascii_case("s") || w.eq_ignore_ascii_case("sec");
    let value = |w: &str| -> Option<f64> {
        let v = w.parse::<f64>().ok().or_else(|| {
            // the unit glued to the number: `0.01s`, `0.01sec`
            let cut = w.trim_end_matches(|c: char| c.is_ascii_alphabetic());
            let tail = &w[cut.len()..];
            if unit(tail) { cut.parse().ok() } else { None }
        })?;
        (v.is_finite() && v > 0.0).then_some(v)
    };
    let dt = words.next().and_then(value);
    let tail_ok = match words.next() {
        None => true,
        Some(w) => unit(w) && words.next().is_none(),
    };
    Some(dt.filter(|_| tail_ok))
}

/// The values of a one-column record into `out` (rounded once to `T`); returns how many.
/// On an error `out` may be partly written.
///
/// Errors: as [`column()`]; [`Error::InvalidParameter`] if `out` is too short. Cost: one
/// pass over the text.
pub fn column_into<T: Real>(text: &str, out: &mut [T]) -> Result<usize, Error> {
    fill(column(text), out)
}

/// The values of a record ([`At2::values`], [`column()`]): an iterator over the text, no
/// allocation.
#[derive(Clone, Debug)]
pub struct Values<'a> {
    /// The text after the current line.
    rest: &'a str,
    /// What is left of the current line.
    line: &'a str,
    /// The current line (1-based).
    line_no: u32,
    /// AT2: `NPTS`.
    expected: Option<usize>,
    /// Values yielded so far.
    seen: usize,
    /// One column: a second value on a line is an error; `#` starts a comment.
    one_per_line: bool,
    /// An error was yielded, or the text ended.
    done: bool,
}

impl Values<'_> {
    /// The line (1-based) of the value yielded last (`0` before the first). Cost: none.
    pub fn line(&self) -> u32 {
        self.line_no
    }

    fn fail(&mut self, line: u32) -> Option<Result<f64, Error>> {
        self.done = true;
        Some(Err(Error::MalformedRecord { line }))
    }
}

impl Iterator for Values<'_> {
    type Item = Result<f64, Error>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        loop {
            let mut tokens = self.line.split_whitespace();
            if let Some(tok) = tokens.next() {
                if self.one_per_line && tokens.next().is_some() {
                    return self.fail(self.line_no);
                }
                // What is left of the line after this token.
                let at = tok.as_ptr() as usize - self.line.as_ptr() as usize + tok.len();
                self.line = &self.line[at..];
                if self.expected == Some(self.seen) {
                    return self.fail(self.line_no);
                }
                return match tok.parse::<f64>() {
                    Ok(v) if v.is_finite() => {
                        self.seen += 1;
                        Some(Ok(v))
                    }
                    _ => self.fail(self.line_no),
                };
            }
            if self.rest.is_empty() {
                self.done = true;
                let short = match self.expected {
                    Some(n) => self.seen < n,
                    None => self.seen == 0,
                };
                return if short {
                    self.fail(self.line_no.saturating_add(1))
                } else {
                    None
                };
            }
            let (line, rest) = split_line(self.rest);
            self.rest = rest;
            self.line_no = self.line_no.saturating_add(1);
            self.line = if self.one_per_line {
                line.split('#').next().unwrap_or("")
            } else {
                line
            };
        }
    }
}

impl core::iter::FusedIterator for Values<'_> {}

/// `values` into `out`, rounded to `T`, each checked finite after rounding.
fn fill<T: Real>(values: Values<'_>, out: &mut [T]) -> Result<usize, Error> {
    let mut n = 0;
    let mut values = values;
    while let Some(v) = values.next() {
        let v = v?;
        let slot = out
            .get_mut(n)
            .ok_or(Error::InvalidParameter(Param::OutputBuffer))?;
        let t = T::from_f64_rounded(v);
        if !t.as_f64().is_finite() {
            return Err(Error::MalformedRecord {
                line: values.line(),
            });
        }
        *slot = t;
        n += 1;
    }
    Ok(n)
}

/// The first line of `s` (without its `\n` or `\r\n`) and the text after it.
fn split_line(s: &str) -> (&str, &str) {
    let (line, rest) = match s.find('\n') {
        Some(i) => (&s[..i], &s[i + 1..]),
        None => (s, ""),
    };
    (line.strip_suffix('\r').unwrap_or(line), rest)
}

/// `NPTS` and `DT` of an AT2 line 4, in either order of keywords and values.
fn npts_dt(line: &str) -> Option<(usize, f64)> {
    let mut tok = [""; 12];
    let mut n = 0;
    for t in line
        .split(|c: char| c.is_whitespace() || c == ',' || c == '=')
        .filter(|t| !t.is_empty())
    {
        *tok.get_mut(n)? = t;
        n += 1;
    }
    let tok = &tok[..n];
    let key = |k: &str| tok.iter().position(|t| t.eq_ignore_ascii_case(k));
    let (ip, id) = (key("NPTS")?, key("DT")?);
    let count = |t: &str| t.parse::<usize>().ok().filter(|&c| c > 0);
    let step = |t: &str| {
        let t = match t.len().checked_sub(3) {
            Some(i) if t.is_char_boundary(i) && t[i..].eq_ignore_ascii_case("SEC") => &t[..i],
            _ => t,
        };
        t.parse::<f64>().ok().filter(|d| d.is_finite() && *d > 0.0)
    };
    // Keyword then value: `NPTS= 4000, DT= .0050 SEC`.
    if let (Some(c), Some(d)) = (
        tok.get(ip + 1).and_then(|t| count(t)),
        tok.get(id + 1).and_then(|t| step(t)),
    ) {
        return Some((c, d));
    }
    // Values then keywords: `4000  0.0050  NPTS, DT`.
    if ip >= 2 && id > ip {
        return Some((count(tok[0])?, step(tok[1])?));
    }
    None
}

/// Resampling a record to a step `h` ([`resample_into`]): the anti-alias filter's cutoff,
/// as a fraction of the new Nyquist frequency `1/(2h)`.
pub const ANTI_ALIAS_CUTOFF: f64 = 0.8;

/// The number of samples [`resample_into`] writes for `n` samples at interval `dt` resampled
/// to `h`: the times `k·h` from `0` to the record's end `(n − 1)·dt` (the end included to
/// `1e-12` relative), `⌊(n − 1)·dt/h⌋ + 1`; `0` for `n = 0`. Saturates at `usize::MAX`.
///
/// Errors: [`Error::InvalidTimeStep`] if `dt` or `h` is not finite and `> 0`. Cost: O(1).
pub fn resampled_len(n: usize, dt: f64, h: f64) -> Result<usize, Error> {
    if !(dt.is_finite() && dt > 0.0 && h.is_finite() && h > 0.0) {
        return Err(Error::InvalidTimeStep);
    }
    if n == 0 {
        return Ok(0);
    }
    let d = (n - 1) as f64 * dt / h * (1.0 + 1e-12);
    Ok((d as usize).saturating_add(1)) // saturating cast
}

/// The anti-alias filter of a resampling from `dt` to `h > dt`: a Blackman-windowed sinc
/// on the input grid, `g_m ∝ 2f sinc(2f m) w(m/M)`, `|m| ≤ M`, `f = ANTI_ALIAS_CUTOFF ·
/// dt/(2h)` (cycles a sample), its sum scaled to 1 (unit gain at 0 Hz).
struct AntiAlias {
    /// Half-length `M` (taps `2M + 1`).
    half: usize,
    /// Cutoff `f` (cycles a sample).
    f: f64,
    /// `1/Σ g_m`.
    norm: f64,
}

impl AntiAlias {
    fn new(dt: f64, h: f64) -> Self {
        // The Blackman window's transition band is about 5.5/(2M + 1) cycles a sample
        // wide, centred on f: with 2M + 1 ≥ 27.5 h/dt it spans f ± 0.1·dt/h, so the stop
        // band (≥ 74 dB down) starts at (0.8 + 0.2)·dt/(2h), the new Nyquist frequency.
        let x = 13.75 * h / dt;
        let half = x as usize; // saturating cast; then rounded up (`ceil` is not in `core`)
        let half = if (half as f64) < x {
            half.saturating_add(1)
        } else {
            half
        };
        let f = ANTI_ALIAS_CUTOFF * dt / (2.0 * h);
        let mut a = AntiAlias { half, f, norm: 1.0 };
        let sum: f64 = (0..=2 * half).map(|i| a.tap(i as f64 - half as f64)).sum();
        a.norm = 1.0 / sum;
        a
    }

    /// The unscaled tap `g_m` at offset `m` (samples).
    fn tap(&self, m: f64) -> f64 {
        use core::f64::consts::PI;
        use nalgebra::ComplexField;
        let x = 2.0 * PI * self.f * m;
        let sinc = if m == 0.0 {
            2.0 * self.f
        } else {
            <f64 as ComplexField>::sin(x) / (PI * m)
        };
        let r = PI * m / self.half as f64;
        let w =
            0.42 + 0.5 * <f64 as ComplexField>::cos(r) + 0.08 * <f64 as ComplexField>::cos(2.0 * r);
        sinc * w
    }

    /// The filtered input at sample `j` (zero outside the record: it starts and ends at
    /// rest).
    fn at<T: Real>(&self, x: &[T], j: usize) -> f64 {
        let lo = j.saturating_sub(self.half);
        let hi = (j + self.half).min(x.len() - 1);
        let mut acc = 0.0;
        for (i, xi) in x.iter().enumerate().take(hi + 1).skip(lo) {
            acc += xi.as_f64() * self.tap(j as f64 - i as f64);
        }
        acc * self.norm
    }
}

/// A record sampled every `dt` seconds resampled to the step `h` (s), into `out`; returns
/// the number of samples written, [`resampled_len`] (the times `k·h` from `0` to the
/// record's end). `no_std`, no allocation; computed in `f64`, each output rounded once to
/// `T`.
///
/// **Interpolation**: linear between the (filtered) input samples,
/// `y(t) = (1 − θ) z_j + θ z_{j+1}`, `t = (j + θ) dt`: exact for a signal linear between
/// samples (the load model of every stepper and of the spectra), error at most
/// `dt²/8 · max|x''|` for a smooth one.
///
/// **Downsampling** (`h > dt`): the input is first low-pass filtered on its own grid by a
/// Blackman-windowed sinc FIR, `2M + 1 ≥ 27.5 h/dt` taps, cutoff (−6 dB)
/// [`ANTI_ALIAS_CUTOFF`]` = 0.8` of the new Nyquist frequency `1/(2h)`, unit gain at 0 Hz:
/// content above the new Nyquist frequency (which the coarser step would alias onto lower
/// frequencies) is attenuated by about 72 dB (the window's stop band, measured: at most
/// `1.6e-4` of the amplitude), content below `0.6/(2h)` passes within `2e-4` (the
/// transition band is `0.6` to `1.0` of the new Nyquist frequency). The filter sees zeros outside the record (a
/// record starts and ends at rest), so the first and last `M·dt` seconds carry its edge
/// transient. Upsampling (`h < dt`) and `h = dt` are not filtered (nothing can alias).
///
/// Errors: [`Error::InvalidTimeStep`] if `dt` or `h` is not finite and `> 0`;
/// [`Error::NonFiniteInput`] if a sample is not finite (nothing written);
/// [`Error::InvalidParameter`] if `out` is shorter than [`resampled_len`] (nothing
/// written); [`Error::OperatorOverflow`] if an output does not fit `T`. Cost: `n` checks,
/// then per output one or two filtered samples of at most `2M + 1` taps (a sine and two
/// cosines each) when downsampling, else a few flops.
///
/// ```
/// use aemstep::records::{resample_into, resampled_len};
/// // 1 s of a 1 Hz sine at 200 Hz, resampled to 50 Hz (h = 0.02 s).
/// let dt = 0.005;
/// let x: Vec<f64> = (0..=200).map(|n| (std::f64::consts::TAU * n as f64 * dt).sin()).collect();
/// let mut y = vec![0.0; resampled_len(x.len(), dt, 0.02)?];
/// assert_eq!(resample_into(&x, dt, 0.02, &mut y)?, 51);
/// // mid-record (away from the filter's edge transient), the sine itself
/// assert!((y[20] - (std::f64::consts::TAU * 0.4).sin()).abs() < 1e-3);
/// # Ok::<(), aemstep::Error>(())
/// ```
pub fn resample_into<T: Real>(input: &[T], dt: f64, h: f64, out: &mut [T]) -> Result<usize, Error> {
    let n_out = resampled_len(input.len(), dt, h)?;
    if input.iter().any(|x| !x.as_f64().is_finite()) {
        return Err(Error::NonFiniteInput);
    }
    if out.len() < n_out {
        return Err(Error::InvalidParameter(Param::OutputBuffer));
    }
    if n_out == 0 {
        return Ok(0);
    }
    let filter = (h > dt).then(|| AntiAlias::new(dt, h));
    let z = |j: usize| match &filter {
        Some(f) => f.at(input, j),
        None => input[j].as_f64(),
    };
    let last = input.len() - 1;
    // the last pair (j, z_j, z_{j+1}) computed: consecutive outputs often share it
    let mut cache: Option<(usize, f64, f64)> = None;
    // the ratio rounded once: an integer ratio (h = dt, 2dt, …) lands on input samples
    let ratio = h / dt;
    for (k, o) in out.iter_mut().take(n_out).enumerate() {
        let pos = k as f64 * ratio;
        let j = (pos as usize).min(last); // saturating cast; `pos ≤ last` to 1e-12
        let theta = (pos - j as f64).clamp(0.0, 1.0);
        let (z0, z1) = match cache {
            Some((cj, z0, z1)) if cj == j => (z0, z1),
            _ => {
                let z0 = z(j);
                let z1 = if j < last { z(j + 1) } else { z0 };
                cache = Some((j, z0, z1));
                (z0, z1)
            }
        };
        let y = if theta == 0.0 {
            z0
        } else {
            (1.0 - theta) * z0 + theta * z1
        };
        let t = T::from_f64_rounded(y);
        if !t.as_f64().is_finite() {
            return Err(Error::OperatorOverflow);
        }
        *o = t;
    }
    Ok(n_out)
}

/// A whole record in memory (feature `std`): its samples (in the file's units: g for a
/// PEER acceleration record; times [`G`] for m/s²), sample interval and title.
#[cfg(feature = "std")]
#[cfg_attr(docsrs, doc(cfg(feature = "std")))]
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// The title (AT2: line 1; one column: empty, or the file name from
    /// [`Record::read_column`]).
    pub title: std::string::String,
    /// The sample interval (s, finite, `> 0`).
    pub dt: f64,
    /// The samples, in file order and units.
    pub samples: std::vec::Vec<f64>,
}

#[cfg(feature = "std")]
impl Record {
    /// A record from PEER AT2 text ([`at2`], [`At2::values`]).
    ///
    /// Errors: [`Error::MalformedRecord`] as [`at2`] and [`At2::values`]. Cost: one pass
    /// over the text; allocates `NPTS` values (once the header is read).
    ///
    /// ```
    /// let r = aemstep::records::Record::from_at2("T\nE\nU\n3 0.02 NPTS, DT\n1 2\n3\n")?;
    /// assert_eq!((r.dt, r.samples.as_slice()), (0.02, &[1.0, 2.0, 3.0][..]));
    /// # Ok::<(), aemstep::Error>(())
    /// ```
    pub fn from_at2(text: &str) -> Result<Self, Error> {
        let h = at2(text)?;
        // The count is the header's word: allocate no more than the text could hold
        // (a value takes at least two bytes with its separator).
        let mut samples = std::vec::Vec::with_capacity(h.npts.min(text.len() / 2 + 1));
        for v in h.values() {
            samples.push(v?);
        }
        Ok(Record {
            title: h.title.into(),
            dt: h.dt,
            samples,
        })
    }

    /// A record from one-column text ([`column()`]) sampled every `dt` seconds. A `# dt`
    /// header in the text ([`column_dt`]) must agree with `dt`.
    ///
    /// Errors: [`Error::InvalidTimeStep`] if `dt` is not finite and `> 0`, or differs from
    /// the text's `# dt` header; [`Error::MalformedRecord`] as [`column()`] and
    /// [`column_dt`]. Cost: two passes over the text.
    pub fn from_column(text: &str, dt: f64) -> Result<Self, Error> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::InvalidTimeStep);
        }
        if column_dt(text)?.is_some_and(|h| h != dt) {
            return Err(Error::InvalidTimeStep);
        }
        Ok(Record {
            title: std::string::String::new(),
            dt,
            samples: column(text).collect::<Result<_, _>>()?,
        })
    }

    /// A record from one-column text ([`column()`]) sampled at the interval of its `# dt`
    /// header line ([`column_dt`]).
    ///
    /// Errors: [`Error::MalformedRecord`] as [`column()`] and [`column_dt`], and at line 1
    /// if the text has no `# dt` header. Cost: two passes over the text.
    ///
    /// ```
    /// use aemstep::records::Record;
    /// let r = Record::from_column_with_header("# dt = 0.005 s\n0.1\n-0.2\n")?;
    /// assert_eq!((r.dt, r.samples.as_slice()), (0.005, &[0.1, -0.2][..]));
    /// # Ok::<(), aemstep::Error>(())
    /// ```
    pub fn from_column_with_header(text: &str) -> Result<Self, Error> {
        let dt = column_dt(text)?.ok_or(Error::MalformedRecord { line: 1 })?;
        Self::from_column(text, dt)
    }

    /// The record resampled to the step `h` (s): [`resample_into`] (linear interpolation,
    /// an anti-alias filter first when `h > dt`), its `dt` set to `h`, the title kept.
    ///
    /// Errors: as [`resample_into`]; [`Error::InvalidTimeStep`] also if the result could
    /// not be allocated (an `h` so small the record would need more memory than there is).
    /// Cost: as [`resample_into`]; allocates [`resampled_len`] values.
    ///
    /// ```
    /// use aemstep::records::Record;
    /// let r = Record::from_column("0\n1\n0\n-1\n0\n", 0.02)?;
    /// let fine = r.resampled(0.01)?; // upsampling: linear, no filter
    /// assert_eq!(fine.samples, [0.0, 0.5, 1.0, 0.5, 0.0, -0.5, -1.0, -0.5, 0.0]);
    /// assert_eq!(fine.dt, 0.01);
    /// # Ok::<(), aemstep::Error>(())
    /// ```
    pub fn resampled(&self, h: f64) -> Result<Self, Error> {
        let n = resampled_len(self.samples.len(), self.dt, h)?;
        let mut samples = std::vec::Vec::new();
        samples
            .try_reserve_exact(n)
            .map_err(|_| Error::InvalidTimeStep)?;
        samples.resize(n, 0.0);
        resample_into(&self.samples, self.dt, h, &mut samples)?;
        Ok(Record {
            title: self.title.clone(),
            dt: h,
            samples,
        })
    }

    /// [`Record::from_at2`] of a file.
    ///
    /// Errors: the file's I/O error; a parse error as an [`std::io::Error`] of kind
    /// `InvalidData` whose `get_ref()` downcasts to the crate's [`Error`]. A file that is
    /// not UTF-8 is `InvalidData` from the read. Cost: reads the file once.
    pub fn read_at2(path: impl AsRef<std::path::Path>) -> std::io::Result<Self> {
        let text = std::fs::read_to_string(path)?;
        Self::from_at2(&text).map_err(invalid_data)
    }

    /// [`Record::from_column`] of a file; the title is the file name.
    ///
    /// Errors: as [`Record::read_at2`] (and [`Error::InvalidTimeStep`] for `dt`, as
    /// `InvalidData`). Cost: reads the file once.
    pub fn read_column(path: impl AsRef<std::path::Path>, dt: f64) -> std::io::Result<Self> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path)?;
        let mut r = Self::from_column(&text, dt).map_err(invalid_data)?;
        if let Some(name) = path.file_name() {
            r.title = name.to_string_lossy().into_owned();
        }
        Ok(r)
    }

    /// The samples times `factor` (e.g. [`G`] for a record in g to m/s²), every one
    /// finite.
    ///
    /// Errors: [`Error::NonFiniteInput`] if `factor` or a sample is not finite (a NaN
    /// factor gave a record of NaN); [`Error::OperatorOverflow`] if a product overflows
    /// (e.g. a record times `1e300`). Cost: one pass; allocates the result.
    ///
    /// ```
    /// use aemstep::{Error, records::{G, Record}};
    /// let r = Record::from_column("0.5\n-0.25\n", 0.01)?; // g
    /// assert_eq!(r.scaled(G)?, [0.5 * G, -0.25 * G]); // m/s²
    /// assert_eq!(r.scaled(f64::NAN), Err(Error::NonFiniteInput));
    /// assert_eq!(Record::from_column("3\n", 0.01)?.scaled(1e308), Err(Error::OperatorOverflow));
    /// # Ok::<(), Error>(())
    /// ```
    pub fn scaled(&self, factor: f64) -> Result<std::vec::Vec<f64>, Error> {
        if !factor.is_finite() {
            return Err(Error::NonFiniteInput);
        }
        self.samples
            .iter()
            .map(|&a| match a * factor {
                x if x.is_finite() => Ok(x),
                _ if !a.is_finite() => Err(Error::NonFiniteInput),
                _ => Err(Error::OperatorOverflow),
            })
            .collect()
    }
}

#[cfg(feature = "std")]
fn invalid_data(e: Error) -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::InvalidData, e)
}
