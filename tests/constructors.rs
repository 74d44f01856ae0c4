//! Every constructor gives bit-identical operators for the same data, in `f32` and `f64`:
//! the run-time `new` (nalgebra `f64` matrices) and the `const fn` `from_rows_f32`/`_f64` (row
//! arrays) both compute in `f64` and round once. The data are chosen not `f32`-exact
//! (ξ = 0.07, h = 0.01), so a constructor that rounded its inputs before building would
//! fail here.
#![allow(clippy::needless_range_loop)]

use aemstep::models::{Rows, base_excitation, rayleigh, rayleigh_coefficients, shear_building};
use aemstep::nalgebra::SMatrix;
use aemstep::{Damping, Linear, LinearInput, Modal};

/// A 4-storey building, storeys not uniform, Rayleigh damping ξ = 0.07 in modes 1 and 2.
fn building() -> (Rows<4>, Rows<4>, Rows<4>) {
    let (m, k) = shear_building([1.1e5, 0.9e5, 1.0e5, 0.7e5], [1.3e8, 1.1e8, 0.9e8, 0.6e8]);
    let (a0, a1) = rayleigh_coefficients(8.3, 22.9, 0.07);
    (m, rayleigh(&m, &k, a0, a1), k)
}

fn sm<const R: usize, const C: usize>(a: &[[f64; C]; R]) -> SMatrix<f64, R, C> {
    SMatrix::from_fn(|i, j| a[i][j])
}

/// `Debug` prints every float with enough digits to round-trip (and tells −0 from +0), so
/// equal `Debug` strings mean bit-identical operators.
fn bits<T: core::fmt::Debug>(x: &T) -> String {
    format!("{x:?}")
}

const H: f64 = 0.01;

#[test]
fn data_are_not_f32_exact() {
    let (_, c, _) = building();
    assert_ne!(c[0][0] as f32 as f64, c[0][0]);
    assert_ne!(H as f32 as f64, H);
}

#[test]
fn linear_new_equals_from_rows_bit_for_bit() {
    let (m, c, k) = building();
    let a64 = Linear::<f64, 4>::new(&sm(&m), &sm(&c), &sm(&k), H).unwrap();
    let b64 = Linear::<f64, 4>::from_rows_f64(m, c, k, H).unwrap();
    assert_eq!(bits(&a64), bits(&b64));
    let a32 = Linear::<f32, 4>::new(&sm(&m), &sm(&c), &sm(&k), H).unwrap();
    let b32 = Linear::<f32, 4>::from_rows_f32(m, c, k, H).unwrap();
    assert_eq!(bits(&a32), bits(&b32));
    // And the f32 operators are the f64 ones rounded once.
    let g64 = a64.effective_inverse();
    assert_eq!(g64.map(|x| x as f32), a32.effective_inverse());
    assert_eq!(a32.time_step(), H as f32);
}

#[test]
fn linear_input_new_equals_from_rows_bit_for_bit() {
    let (m, c, k) = building();
    let b = base_excitation(&m);
    let a64 = LinearInput::<f64, 4, 1>::new(&sm(&m), &sm(&c), &sm(&k), &sm(&b), H).unwrap();
    let b64 = LinearInput::<f64, 4, 1>::from_rows_f64(m, c, k, b, H).unwrap();
    assert_eq!(bits(&a64), bits(&b64));
    let a32 = LinearInput::<f32, 4, 1>::new(&sm(&m), &sm(&c), &sm(&k), &sm(&b), H).unwrap();
    let b32 = LinearInput::<f32, 4, 1>::from_rows_f32(m, c, k, b, H).unwrap();
    assert_eq!(bits(&a32), bits(&b32));
    assert_eq!(a64.input_operator().map(|x| x as f32), a32.input_operator());
}

#[test]
fn modal_new_equals_from_rows_bit_for_bit() {
    let (m, c, k) = building();
    let b = base_excitation(&m);
    let y = [[0.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 0.0]];
    let d = Damping::Matrix(c);
    let a64 = Modal::<f64, 4, 2, 1, 2>::new(&sm(&m), &sm(&k), &d, &sm(&b), &sm(&y), H).unwrap();
    let b64 = Modal::<f64, 4, 2, 1, 2>::from_rows_f64(m, k, d, b, y, H).unwrap();
    assert_eq!(bits(&a64), bits(&b64));
    let a32 = Modal::<f32, 4, 2, 1, 2>::new(&sm(&m), &sm(&k), &d, &sm(&b), &sm(&y), H).unwrap();
    let b32 = Modal::<f32, 4, 2, 1, 2>::from_rows_f32(m, k, d, b, y, H).unwrap();
    assert_eq!(bits(&a32), bits(&b32));
    let ratios = Damping::Ratios([0.07; 4]);
    let a = Modal::<f32, 4, 2, 1, 2>::with_modes(
        &sm(&m),
        &sm(&k),
        &ratios,
        &sm(&b),
        &sm(&y),
        [3, 1],
        H,
    )
    .unwrap();
    let b =
        Modal::<f32, 4, 2, 1, 2>::from_rows_with_modes_f32(m, k, ratios, b, y, [3, 1], H).unwrap();
    assert_eq!(bits(&a), bits(&b));
}

/// The largest sizes the `const fn` constructors are documented to compile in a `static`
/// with the default `long_running_const_eval` lint (rustc 1.95): `Linear<f32, 63>` and
/// `Modal<f32, 49, 2>`. One size more stops the build (measured: `Linear` at 64, `Modal`
/// at 50); the rustdoc of `from_rows_f32`/`_f64` says so and names the lint to allow.
mod largest_const_sizes {
    use super::*;

    const fn chain<const N: usize>(d: f64, o: f64) -> Rows<N> {
        let mut a = [[0.0; N]; N];
        let mut i = 0;
        while i < N {
            a[i][i] = d;
            if i > 0 {
                a[i][i - 1] = o;
                a[i - 1][i] = o;
            }
            i += 1;
        }
        a
    }

    static LINEAR_63: Linear<f32, 63> =
        match Linear::from_rows_f32(chain(1.0, 0.0), chain(0.0, 0.0), chain(2.0, -1.0), H) {
            Ok(s) => s,
            Err(e) => panic!("{}", e.as_str()),
        };

    static MODAL_49: Modal<f32, 49, 2> = match Modal::from_rows_f32(
        chain(1.0, 0.0),
        chain(2.0, -1.0),
        Damping::None,
        [[1.0]; 49],
        [[1.0; 49]],
        H,
    ) {
        Ok(s) => s,
        Err(e) => panic!("{}", e.as_str()),
    };

    /// Run-time builds at these sizes put a few dozen `N×N` `f64` temporaries on the stack
    /// in a debug build: run them on a thread with room.
    #[test]
    fn compile_time_operators_equal_run_time_ones() {
        std::thread::Builder::new()
            .stack_size(256 << 20)
            .spawn(compare)
            .unwrap()
            .join()
            .unwrap();
    }

    fn compare() {
        let (m, c, k) = (
            chain::<63>(1.0, 0.0),
            chain::<63>(0.0, 0.0),
            chain::<63>(2.0, -1.0),
        );
        let rt = Linear::<f32, 63>::new(&sm(&m), &sm(&c), &sm(&k), H).unwrap();
        assert_eq!(bits(&rt), bits(&LINEAR_63));
        let (m, k) = (chain::<49>(1.0, 0.0), chain::<49>(2.0, -1.0));
        let rt = Modal::<f32, 49, 2>::new(
            &sm(&m),
            &sm(&k),
            &Damping::None,
            &SMatrix::repeat(1.0),
            &SMatrix::repeat(1.0),
            H,
        )
        .unwrap();
        assert_eq!(bits(&rt), bits(&MODAL_49));
        // The lowest frequency of the chain: ω₁ = 2 sin(π / (2(N + 1))).
        let w1 = 2.0 * (core::f64::consts::PI / 100.0).sin();
        assert!((MODAL_49.frequencies()[0] as f64 - w1).abs() < 1e-6 * w1);
    }
}
