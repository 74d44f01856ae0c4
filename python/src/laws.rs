//! The storey laws of a shear building from their parameter rows, shared by
//! `shear_building` and the IDA functions (`ida.rs`): one place that maps a law name and a
//! `storeys × width` parameter table to `[L; N]`.

use aemstep::Error;
use aemstep::hysteresis::{Bilinear, BoucWen, Friction, Parallel};
use aemstep::lanes::LaneLaw;

use crate::{Fail, Res};

/// The parameter columns of each law name: `(name, width)`.
pub(crate) const LAW_WIDTHS: [(&str, usize); 3] =
    [("bilinear", 3), ("bouc_wen", 6), ("bilinear_friction", 5)];

/// The number of parameter columns of `law`; a `ValueError` naming the laws for a name
/// `shear_building` does not know.
pub(crate) fn known_law(law: &str) -> pyo3::PyResult<usize> {
    law_width(law).ok_or_else(|| {
        pyo3::exceptions::PyValueError::new_err(format!(
            "unknown law {law:?}: one of bilinear, bouc_wen, bilinear_friction"
        ))
    })
}

/// The number of parameter columns of `law`, or `None` for an unknown name.
pub(crate) fn law_width(law: &str) -> Option<usize> {
    LAW_WIDTHS.iter().find(|(n, _)| *n == law).map(|&(_, w)| w)
}

/// What to do with the `N` storey laws once built (a generic callback over the law type).
pub(crate) trait WithLaws<const N: usize> {
    type Out;
    fn run<L: LaneLaw<f64> + Send + Sync>(self, laws: [L; N]) -> Res<Self::Out>;
}

/// What to do with storey laws of a run-time count once built.
pub(crate) trait WithLawVec {
    type Out;
    fn run<L: LaneLaw<f64> + Send + Sync>(self, laws: Vec<L>) -> Res<Self::Out>;
}

/// `n` laws, the `i`-th from `f(i)`.
fn build<L>(n: usize, f: impl Fn(usize) -> Result<L, Error>) -> Result<Vec<L>, Error> {
    (0..n).map(f).collect()
}

/// Builds the `N` laws named `law` from `params` (row-major, `N × width`, one row a storey,
/// the columns of `shear_building`'s docstring) and hands them to `v`.
///
/// Errors: the laws' `InvalidMaterial`; an unknown name or a table of the wrong size is a
/// `ShapeError` (callers check both first).
pub(crate) fn with_laws<const N: usize, V: WithLaws<N>>(
    law: &str,
    params: &[f64],
    width: usize,
    v: V,
) -> Res<V::Out> {
    /// The laws as an array of `N`.
    struct Array<V, const N: usize>(V);
    impl<V: WithLaws<N>, const N: usize> WithLawVec for Array<V, N> {
        type Out = V::Out;
        fn run<L: LaneLaw<f64> + Send + Sync>(self, laws: Vec<L>) -> Res<V::Out> {
            match <[L; N]>::try_from(laws) {
                Ok(laws) => self.0.run(laws),
                Err(_) => unreachable!("N laws built"),
            }
        }
    }
    with_law_vec(law, params, width, N, Array::<V, N>(v))
}

/// [`with_laws`] for `n` storeys chosen at run time: the laws in a `Vec`.
///
/// Errors: as [`with_laws`].
pub(crate) fn with_law_vec<V: WithLawVec>(
    law: &str,
    params: &[f64],
    width: usize,
    n: usize,
    v: V,
) -> Res<V::Out> {
    if law_width(law) != Some(width) || params.len() != n * width {
        return Err(Fail::Shape(format!(
            "law {law:?} with a {n}x{width} parameter table of {} values",
            params.len()
        )));
    }
    let row = |i: usize| &params[i * width..(i + 1) * width];
    match law {
        "bilinear" => v.run(build(n, |i| {
            let r = row(i);
            Bilinear::<f64>::new(r[0], r[1], r[2])
        })?),
        "bouc_wen" => v.run(build(n, |i| {
            let r = row(i);
            BoucWen::<f64>::new(r[0], r[1], r[2], r[3], r[4], r[5])
        })?),
        _ => v.run(build(n, |i| {
            let r = row(i);
            Ok(Parallel(
                Bilinear::<f64>::new(r[0], r[1], r[2])?,
                Friction::<f64>::new(r[3], r[4])?,
            ))
        })?),
    }
}
