//! Fuzz target `modal` (`fuzz_targets/modal.rs`): checks Modal::new, with_modes, from_rows_f32/_f64,
//! from_rows_with_modes_f32/_f64, every Damping form, f32 and f64; N = 2 (R = 1, 2) and N = 3
//! (R = 2).
//!
//! The decoder and the checks every target shares are in `common.rs`.

use std::fmt::Debug;

use aemstep::nalgebra::{SMatrix, SVector};
use aemstep::{Damping, Error, Linear, Modal, Real};

use super::common::*;

const MOD: &str = "modal";

/// Target `modal`.
pub fn modal(data: &[u8]) {
    let mut b = Bytes::new(data);
    match b.pick(3) {
        0 => modal_n::<2, 1>(&mut b),
        1 => modal_n::<2, 2>(&mut b),
        _ => modal_n::<3, 2>(&mut b),
    }
    count(MOD, "inputs");
    count(MOD, b.category());
}

fn modal_n<const N: usize, const R: usize>(b: &mut Bytes) {
    let s = b.system::<N>();
    let damp = damping(b, &s);
    let bm: SMatrix<f64, N, 2> = b.matrix();
    let y: SMatrix<f64, 2, N> = b.matrix();
    let modes: [usize; R] = if b.flag() {
        core::array::from_fn(|r| r)
    } else {
        core::array::from_fn(|_| usize::from(b.pick(N as u8 + 1)))
    };
    let u0 = if b.flag() {
        b.small_vector::<N>()
    } else {
        b.vector()
    };
    let v0 = if b.flag() {
        b.small_vector::<N>()
    } else {
        b.vector()
    };
    let (p, q) = (b.vector::<2>(), b.vector::<2>());
    let data = ModalData {
        s,
        damp,
        b: bm,
        y,
        modes,
        u0,
        v0,
        p,
        q,
    };
    set_context(format!(
        "N = {N}, R = {R}, M = {:?}, K = {:?}, h = {:e}, damping = {:?}, B = {:?}, Y = {:?}, modes = {:?}, u0 = {:?}, v0 = {:?}, p = {:?}, q = {:?}",
        data.s.m.as_slice(),
        data.s.k.as_slice(),
        data.s.h,
        data.damp,
        data.b.as_slice(),
        data.y.as_slice(),
        data.modes,
        data.u0.as_slice(),
        data.v0.as_slice(),
        data.p.as_slice(),
        data.q.as_slice()
    ));
    let r64 = modal_typed::<f64, N, R>(&data);
    let r32 = modal_typed::<f32, N, R>(&data);
    twins(MOD, data.s.h, "Modal", r64, r32);
}

struct ModalData<const N: usize, const R: usize> {
    s: System<N>,
    damp: Damping<N>,
    b: SMatrix<f64, N, 2>,
    y: SMatrix<f64, 2, N>,
    modes: [usize; R],
    u0: SVector<f64, N>,
    v0: SVector<f64, N>,
    p: SVector<f64, 2>,
    q: SVector<f64, 2>,
}

/// Modal in `T`: the data rule, from_rows bit-identical, Ok ⇒ finite operators, the
/// checked-step contract, the energy check; returns the error of `with_modes`.
fn modal_typed<T: Real, const N: usize, const R: usize>(d: &ModalData<N, R>) -> Option<Error>
where
    Modal<T, N, R, 2, 2>: Debug,
{
    let s = &d.s;
    let lowest = core::array::from_fn::<usize, R, _>(|r| r);
    let valid_modes = {
        let mut v = d.modes.to_vec();
        v.sort_unstable();
        v.dedup();
        v.len() == R && d.modes.iter().all(|&i| i < N)
    };
    let new = Modal::<T, N, R, 2, 2>::new(&s.m, &s.k, &d.damp, &d.b, &d.y, s.h);
    let with = Modal::<T, N, R, 2, 2>::with_modes(&s.m, &s.k, &d.damp, &d.b, &d.y, d.modes, s.h);
    outcome(MOD, &new);
    outcome(MOD, &with);
    if d.modes == lowest {
        check!(
            bits(&new) == bits(&with),
            "{MOD}: with_modes(lowest) differs from new"
        );
    }
    let (mr, kr, br, yr) = (rows(&s.m), rows(&s.k), rows(&d.b), rows(&d.y));
    let fr = from_rows_modal::<T, N, R>(mr, kr, d.damp, br, yr, s.h, None);
    let frm = from_rows_modal::<T, N, R>(mr, kr, d.damp, br, yr, s.h, Some(d.modes));
    check!(
        fr == bits(&new) && frm == bits(&with),
        "{MOD}: from_rows differs from new / with_modes"
    );
    // The data rule (with valid modes): a non-finite M, K, B or Y entry first, then h; a
    // non-finite damping parameter is NonFiniteInput too.
    let dd = damping_data(&d.damp);
    let want = data_error_as::<T>(
        &[
            s.m.as_slice(),
            s.k.as_slice(),
            d.b.as_slice(),
            d.y.as_slice(),
            &dd,
        ],
        s.h,
    );
    expect_data(MOD, "Modal::new", &new, want);
    if valid_modes {
        expect_data(MOD, "Modal::with_modes", &with, want);
    } else {
        check!(
            with.as_ref().err() == Some(&Error::InvalidModeSelection),
            "{MOD}: modes {:?} gave {:?}",
            d.modes,
            with.as_ref().err()
        );
    }
    for (name, r) in [("Modal::new", &new), ("Modal::with_modes", &with)] {
        let Ok(sys) = r else { continue };
        check!(
            sys.frequencies().iter().all(|x| x.is_finite())
                && finite(&sys.mode_shapes())
                && finite(&sys.participation()),
            "{MOD}: {name}: Ok with non-finite operators"
        );
        let st = sys.start_at_rest(&to_t(&d.p));
        check!(
            st.as_ref().map_or(true, |x| x.is_finite()),
            "{MOD}: {name}: start_at_rest gave a non-finite state"
        );
        let (u0, v0) = (to_t::<T, N, 1>(&d.u0), to_t::<T, N, 1>(&d.v0));
        drive::<T, N, 2, _>(MOD, name, sys, &u0, &v0, &loads::<T, 2>(&d.p, &d.q));
        if R == N && matches!(d.damp, Damping::None) {
            energy_holds::<T, N, 2, _>(MOD, name, sys, s, &d.u0, &d.v0);
        }
    }
    // The same data to the full-order AEM with C = 0: the same verdict on the data.
    if valid_modes && all_finite(d.b.as_slice()) && all_finite(d.y.as_slice()) && all_finite(&dd) {
        let lin = Linear::<T, N>::new(&s.m, &SMatrix::zeros(), &s.k, s.h);
        let e = lin.as_ref().err().copied();
        if matches!(e, Some(Error::NonFiniteInput | Error::InvalidTimeStep)) {
            same_outcome(MOD, "Modal vs Linear on bad data", &with, &lin);
        }
    }
    with.err()
}

fn from_rows_modal<T: Real, const N: usize, const R: usize>(
    m: [[f64; N]; N],
    k: [[f64; N]; N],
    damp: Damping<N>,
    b: [[f64; 2]; N],
    y: [[f64; N]; 2],
    h: f64,
    modes: Option<[usize; R]>,
) -> String {
    if eps::<T>() > 1e-10 {
        match modes {
            None => bits(&Modal::<f32, N, R, 2, 2>::from_rows_f32(
                m, k, damp, b, y, h,
            )),
            Some(md) => bits(&Modal::<f32, N, R, 2, 2>::from_rows_with_modes_f32(
                m, k, damp, b, y, md, h,
            )),
        }
    } else {
        match modes {
            None => bits(&Modal::<f64, N, R, 2, 2>::from_rows_f64(
                m, k, damp, b, y, h,
            )),
            Some(md) => bits(&Modal::<f64, N, R, 2, 2>::from_rows_with_modes_f64(
                m, k, damp, b, y, md, h,
            )),
        }
    }
}
