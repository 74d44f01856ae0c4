//! `matrix!` and `vector!`: nalgebra's literal syntax, through `aemstep` alone; and the
//! crate-private `const_try!`, `?` for the `const fn` constructors.
//!
//! nalgebra's own `matrix!`/`vector!` (re-exported as `aemstep::nalgebra::{matrix, vector}`)
//! expand to paths that start with `nalgebra::`, so they compile only in a crate that also
//! depends on `nalgebra` itself. These two expand to `$crate::nalgebra::…` paths: a crate
//! whose only dependency is `aemstep` can use them, in `const` and `static` items too.

/// A statically sized matrix from its rows: `matrix![1.0, 2.0; 3.0, 4.0]` is
/// `aemstep::nalgebra::SMatrix<f64, 2, 2>` with first row `[1.0, 2.0]`.
///
/// Same syntax and result as nalgebra's `matrix!` (entries separated by `,`, rows by `;`;
/// row-major, like the text reads), but it needs no `nalgebra` dependency in the calling
/// crate and it is usable in `const` and `static` items. Every row must have the same
/// number of entries (a compile error otherwise), and there must be at least one entry.
/// Cost: a copy of the `R·C` entries (none at run time in a `const`).
///
/// ```
/// use aemstep::matrix;
///
/// const K: aemstep::nalgebra::SMatrix<f64, 2, 3> = matrix![1.0, 2.0, 3.0;
///                                                          4.0, 5.0, 6.0];
/// assert_eq!(K[(0, 2)], 3.0); // row 0, column 2
/// assert_eq!(K[(1, 0)], 4.0);
/// ```
#[macro_export]
macro_rules! matrix {
    ($($($entry:expr),+ $(,)?);+ $(;)?) => {
        $crate::nalgebra::SMatrix::from_array_storage($crate::nalgebra::ArrayStorage(
            $crate::__rows_to_columns([$([$($entry),+]),+]),
        ))
    };
}

/// A statically sized column vector: `vector![1.0, 2.0]` is
/// `aemstep::nalgebra::SVector<f64, 2>`.
///
/// Same syntax and result as nalgebra's `vector!`, but it needs no `nalgebra` dependency in
/// the calling crate and it is usable in `const` and `static` items. At least one entry.
/// Cost: a copy of the entries (none at run time in a `const`).
///
/// ```
/// use aemstep::vector;
///
/// const P: aemstep::nalgebra::SVector<f32, 3> = vector![0.0, 1.0, 2.0];
/// assert_eq!(P[2], 2.0);
/// ```
#[macro_export]
macro_rules! vector {
    ($($entry:expr),+ $(,)?) => {
        $crate::nalgebra::SVector::from_array_storage($crate::nalgebra::ArrayStorage(
            [[$($entry),+]],
        ))
    };
}

/// `?` for a `const fn`: the value of an `Ok`, or `return Err(e)` from the enclosing
/// function (`?` itself calls a trait method, not allowed in a `const fn`). The one
/// spelling of the `match … { Ok(v) => v, Err(e) => return Err(e) }` that the `const`
/// constructors (`_f32`/`_f64` twins) write around every fallible call. Cost: none.
macro_rules! const_try {
    ($result:expr) => {
        match $result {
            Ok(value) => value,
            Err(e) => return Err(e),
        }
    };
}
pub(crate) use const_try;

/// A constructor from the model `M, C, K` (`N×N` matrices in `f64`, the `N` of the
/// surrounding `impl`) and further arguments, returning `Result<Self, Error>`: the one
/// signature of the schemes', the hybrid split's and the state-space models' constructors.
/// The call names the three matrices (so that its body can use them) and gives the further
/// arguments with their types, e.g. `mck_fn! { /// … pub fn new(m, c, k, h: f64) { … } }`;
/// attributes and docs go through unchanged. `SMatrix` and `Error` are those in scope at
/// the call (the module's imports, which its docs' links use too). Cost: none.
macro_rules! mck_fn {
    (
        $(#[$attr:meta])*
        $vis:vis fn $name:ident($m:ident, $c:ident, $k:ident, $($arg:ident: $ty:ty),+ $(,)?)
        $body:block
    ) => {
        $(#[$attr])*
        $vis fn $name(
            $m: &SMatrix<f64, N, N>,
            $c: &SMatrix<f64, N, N>,
            $k: &SMatrix<f64, N, N>,
            $($arg: $ty),+
        ) -> Result<Self, Error> $body
    };
}
pub(crate) use mck_fn;

/// The columns of a matrix given by its rows (`out[j][i] = rows[i][j]`): nalgebra stores
/// matrices column by column. Used by [`matrix!`]; not part of the API.
///
/// Panics (a compile error in a `const`) only when there are no entries (`R = 0` or `C = 0`),
/// which the macro's syntax excludes.
#[doc(hidden)]
pub const fn rows_to_columns<T: Copy, const R: usize, const C: usize>(
    rows: [[T; C]; R],
) -> [[T; R]; C] {
    crate::linalg::transpose_filled(&rows, rows[0][0])
}

#[cfg(test)]
mod tests {
    use nalgebra::{SMatrix, SVector};

    // The reference is nalgebra's own proc-macro (an independent implementation of the
    // same syntax): the same entries must land in the same places.
    #[test]
    fn matrix_matches_nalgebra_on_a_non_square_non_symmetric_matrix() {
        let ours: SMatrix<f64, 2, 3> = crate::matrix![1.0, 2.0, 3.0; 4.0, 5.0, 6.0];
        let theirs = nalgebra::matrix![1.0, 2.0, 3.0; 4.0, 5.0, 6.0];
        assert_eq!(ours, theirs);
        assert_eq!(ours[(0, 1)], 2.0);
        assert_eq!(ours[(1, 0)], 4.0);

        let tall: SMatrix<i32, 3, 2> = crate::matrix![1, 2; 3, 4; 5, 6,];
        assert_eq!(tall, nalgebra::matrix![1, 2; 3, 4; 5, 6]);
        assert_eq!(tall.transpose(), nalgebra::matrix![1, 3, 5; 2, 4, 6]);

        let square = crate::matrix![2.0, -1.0, 0.5; 7.0, 3.0, -4.0; 0.0, 9.0, 1.0;];
        assert_eq!(
            square,
            nalgebra::matrix![2.0, -1.0, 0.5; 7.0, 3.0, -4.0; 0.0, 9.0, 1.0]
        );
        assert_ne!(square, square.transpose());

        let row = crate::matrix![1.0f32, 2.0, 3.0];
        assert_eq!(row, nalgebra::matrix![1.0f32, 2.0, 3.0]);
        let one = crate::matrix![5.0];
        assert_eq!(one, nalgebra::matrix![5.0]);
    }

    #[test]
    fn vector_matches_nalgebra() {
        let ours: SVector<f64, 3> = crate::vector![1.0, -2.0, 3.5];
        assert_eq!(ours, nalgebra::vector![1.0, -2.0, 3.5]);
        assert_eq!(crate::vector![7.0f32], nalgebra::vector![7.0f32]);
        assert_eq!(crate::vector![1, 2,], nalgebra::vector![1, 2]);
    }

    #[test]
    fn both_work_in_const_items() {
        const M: SMatrix<f64, 2, 3> = crate::matrix![1.0, 2.0, 3.0; 4.0, 5.0, 6.0];
        const V: SVector<f32, 2> = crate::vector![0.5, 0.25];
        static S: SMatrix<f32, 1, 2> = crate::matrix![8.0, 9.0];
        assert_eq!(M, nalgebra::matrix![1.0, 2.0, 3.0; 4.0, 5.0, 6.0]);
        assert_eq!(V, nalgebra::vector![0.5, 0.25]);
        assert_eq!(S, nalgebra::matrix![8.0, 9.0]);
    }
}
