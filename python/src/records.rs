//! Ground-motion records read by the library's readers (`aemstep::records`): PEER AT2 and
//! one-column text. One implementation: the Python `read_at2` / `read_column` pass the
//! text here.

use aemstep::records::Record;
use numpy::PyArray1;
use pyo3::prelude::*;

use crate::{Fail, out1};

/// Parse PEER NGA AT2 text (`aemstep::records::Record::from_at2`).
///
/// Arguments: `text` — the whole file. Returns `(title, dt, samples)`: line 1 of the file,
/// the sample interval `DT` (s) and the `NPTS` values in the file's units (g for an
/// acceleration record). Raises `MalformedRecord` (its `.line` the 1-based line) for a
/// header without a readable `NPTS`/`DT`, a value that is not a finite number, or more or
/// fewer values than `NPTS`. The GIL is released while parsing.
#[pyfunction]
fn parse_at2<'py>(
    py: Python<'py>,
    text: &str,
) -> PyResult<(String, f64, Bound<'py, PyArray1<f64>>)> {
    let r = py
        .detach(|| Record::from_at2(text))
        .map_err(|e| Fail::from(e).raise(py))?;
    Ok((r.title, r.dt, out1(py, r.samples)))
}

/// Parse one-column text, one number a line, `#` comments and blank lines ignored
/// (`aemstep::records::Record::from_column`).
///
/// Arguments: `text`; `dt` — the sample interval (s, finite, `> 0`; it is not in the
/// file). Returns the values in file order and units. Raises `InvalidTimeStep` for a bad
/// `dt`, `MalformedRecord` (with `.line`) for a line with a value that is not a number or
/// with more than one value, or a text with no value.
#[pyfunction]
fn parse_column<'py>(py: Python<'py>, text: &str, dt: f64) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let r = py
        .detach(|| Record::from_column(text, dt))
        .map_err(|e| Fail::from(e).raise(py))?;
    Ok(out1(py, r.samples))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(parse_at2, m)?)?;
    m.add_function(wrap_pyfunction!(parse_column, m)?)?;
    Ok(())
}
