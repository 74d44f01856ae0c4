//! The naming rule of the crate docs ("Naming"): every `const fn` constructor that names
//! its scalar builds a typed `static` with no turbofish; the run-time constructors generic
//! over `T: Real` (`Bank::new`/`with`, `RotD::new`) equal the `const` ones bit for bit and
//! fail with the same errors; the inherent `const fn time_step` of a per-scalar stepper is
//! the value generic code reads through `Stepper::time_step`; `State::restore` checks its
//! parts and restores a state the stepper continues from bit for bit; the detection types
//! follow the same rule (`new` generic, `new_f32`/`new_f64` its `const` twins,
//! `from_parts`/`from_rows_*` for `const` builds from parts or rows, `at_rest*` for a
//! state at rest).

use aemstep::detection::{
    BankState, ChiSquareTest, Cusum, CusumState, Detector, ModelBank, Whitener, Window,
};
use aemstep::hybrid::Split;
use aemstep::models::{self, Rows, base_excitation};
use aemstep::nalgebra::{SVector, vector};
use aemstep::observer::{Measurement, Observer, Outputs, Readout, StateSpace};
use aemstep::spectrum::{Bank, RotD, Scheme, Substeps};
use aemstep::{
    CompensatedLinear, Damping, Error, KrAlpha, Linear, LinearInput, Modal, Param, Real, State,
    Stepper,
};

const fn ok<T: Copy>(r: Result<T, Error>) -> T {
    match r {
        Ok(t) => t,
        Err(e) => panic!("{}", e.as_str()),
    }
}

const B: (Rows<5>, Rows<5>, Rows<5>) = models::five_storey_building();
const H: f64 = 0.02;
const ROOF: [[f64; 5]; 1] = [[0.0, 0.0, 0.0, 0.0, 1.0]];

// Typed statics, no turbofish: the scalar is in the constructor's name, the sizes are
// inferred from the annotated type (with one impl per scalar and a shared name, rustc
// stops with `E0034 multiple applicable items`).
static LIN32: Linear<f32, 5> = ok(Linear::from_rows_f32(B.0, B.1, B.2, H));
static LIN64: Linear<f64, 5> = ok(Linear::from_rows_f64(B.0, B.1, B.2, H));
static INPUT32: LinearInput<f32, 5, 1> = ok(LinearInput::from_rows_f32(
    B.0,
    B.1,
    B.2,
    base_excitation(&B.0),
    H,
));
static COMP64: CompensatedLinear<f64, 5> = ok(CompensatedLinear::from_rows_f64(B.0, B.1, B.2, H));
static MODAL32: Modal<f32, 5, 2> = ok(Modal::from_rows_f32(
    B.0,
    B.2,
    Damping::Matrix(B.1),
    base_excitation(&B.0),
    ROOF,
    H,
));
static MODAL64: Modal<f64, 5, 2> = ok(Modal::from_rows_with_modes_f64(
    B.0,
    B.2,
    Damping::Matrix(B.1),
    base_excitation(&B.0),
    ROOF,
    [0, 2],
    H,
));
const SS: StateSpace<5, 10, 1> = ok(StateSpace::from_rows_aem(
    B.0,
    B.1,
    B.2,
    base_excitation(&B.0),
    H,
));
const MEAS: Measurement<10, 1, 1> =
    ok(SS.outputs(&Outputs::displacements(Outputs::<5, 1, 1>::select([4]))));
static OBS32: Observer<f32, 10, 1, 1> = ok(Observer::from_parts_f32(&SS, &MEAS, &[[0.0]; 10]));
static READ64: Readout<f64, 10, 1, 1> = ok(Readout::from_parts_f64(&MEAS));
static BANK32: Bank<f32, 3> = ok(Bank::new_f32([0.1, 0.5, 2.0], [0.05; 3], 0.01));
static BANK64: Bank<f64, 3> = ok(Bank::with_f64(
    [0.1, 0.5, 2.0],
    [0.05; 3],
    0.01,
    Scheme::Aem,
    Substeps::Fixed(4),
));
static ROT32: RotD<f32, 180> = RotD::new_f32();
static KR32: KrAlpha<f32, 5> = ok(KrAlpha::from_rows_f32(B.0, B.1, B.2, H, 0.8));
static CR64: KrAlpha<f64, 5> = ok(KrAlpha::from_rows_chen_ricles_f64(B.0, B.1, B.2, H));
static SPLIT32: Split<f32, 5> = ok(Split::from_rows_f32(B.0, B.1, B.2, B.2, H, 0.8));

// Detection: typed statics, no turbofish, the degrees of freedom from the observer's type.
const OBS32C: Observer<f32, 10, 1, 1> = ok(Observer::from_parts_f32(&SS, &MEAS, &[[0.0]; 10]));
const WH32: Whitener<f32, 1> = ok(Whitener::from_rows_f32(&[[4.0e-6]]));
static DET32: Detector<f32, 1, 50> =
    Detector::from_parts(WH32, ok(ChiSquareTest::new_f32(&OBS32C, 1e-3)));
static CUSUM64: Cusum<f64> = ok(Cusum::new_f64(&OBS32C, 2.0, 1e-3));
static MODELS32: ModelBank<f32, 10, 1, 1, 2> = ok(ModelBank::from_parts([OBS32C; 2], [WH32; 2]));
static WINDOW32: Window<f32, 50> = Window::at_rest();
static CUSUM_STATE32: CusumState<f32> = CusumState::at_rest_f32();
static BANK_STATE32: BankState<f32, 10, 1, 2, 50> = BankState::at_rest_f32();
static STATE32: State<f32, 5> = State::at_rest_f32();

// The inherent `const fn time_step` in a `const`.
const H32: f32 = LIN32.time_step();
const H64: f64 = COMP64.time_step();

/// What generic code reads: the trait's `time_step`.
fn trait_time_step<T: Real, const N: usize, S: Stepper<T, N>>(s: &S) -> T {
    s.time_step()
}

#[test]
fn const_time_step_is_the_steppers_time_step() {
    assert_eq!(H32, 0.02f32);
    assert_eq!(H64, 0.02);
    assert_eq!(LIN32.time_step(), trait_time_step(&LIN32));
    assert_eq!(LIN64.time_step(), trait_time_step(&LIN64));
    assert_eq!(INPUT32.time_step(), trait_time_step(&INPUT32));
    assert_eq!(COMP64.time_step(), trait_time_step(&COMP64));
    assert_eq!(MODAL32.time_step(), trait_time_step(&MODAL32));
    assert_eq!(MODAL64.time_step(), trait_time_step(&MODAL64));
    assert_eq!(LIN64.time_step(), H);
    assert_eq!(MODAL32.time_step(), H as f32);
    assert_eq!(KR32.time_step(), trait_time_step(&KR32));
    assert_eq!(CR64.time_step(), trait_time_step(&CR64));
    // The split step's time step is its scheme's.
    assert_eq!(SPLIT32.time_step(), trait_time_step(SPLIT32.scheme()));
    // The observer, the model and the bank: the same name.
    assert_eq!(OBS32.time_step(), H as f32);
    assert_eq!(SS.time_step, H);
    assert_eq!(BANK32.time_step(), 0.01);
    assert_eq!(BANK64.time_step(), 0.01);
}

#[test]
fn typed_statics_are_the_run_time_builds() {
    let sm = |r: &Rows<5>| aemstep::nalgebra::SMatrix::<f64, 5, 5>::from_fn(|i, j| r[i][j]);
    let run = Linear::<f32, 5>::new(&sm(&B.0), &sm(&B.1), &sm(&B.2), H).unwrap();
    assert_eq!(run, LIN32);
    assert_eq!(
        Observer::<f32, 10, 1, 1>::new(&SS, &MEAS, &Default::default()).unwrap(),
        OBS32
    );
    assert_eq!(Readout::<f64, 10, 1, 1>::new(&MEAS).unwrap(), READ64);
    assert_eq!(MODAL64.modes(), &[0, 2]);
}

/// Every value of a bank's response after a record, as bits (a macro: `at_rest` is a
/// `const fn` of each scalar).
macro_rules! response_bits {
    ($b:expr, $t:ty) => {{
        let b = &$b;
        let mut r = b.at_rest();
        for n in 0..400 {
            let t = n as f64 * b.time_step();
            b.step(&mut r, ((7.0 * t).sin() + 0.3 * (23.0 * t).cos()) as $t);
        }
        b.free_vibration(&mut r, b.free_vibration_samples());
        [r.sd(), r.sv(), r.sa()]
            .iter()
            .flat_map(|a| a.iter().map(|x| (*x as f64).to_bits()))
            .collect::<Vec<u64>>()
    }};
}

#[test]
fn generic_bank_equals_the_const_banks() {
    const T3: [f64; 3] = [0.05, 0.5, 2.0];
    const Z3: [f64; 3] = [0.02, 0.05, 0.1];
    let g32 = Bank::<f32, 3>::new(T3, Z3, 0.01).unwrap();
    let g64 = Bank::<f64, 3>::new(T3, Z3, 0.01).unwrap();
    assert_eq!(g32, Bank::new_f32(T3, Z3, 0.01).unwrap());
    assert_eq!(g64, Bank::new_f64(T3, Z3, 0.01).unwrap());
    assert_eq!(
        response_bits!(g32, f32),
        response_bits!(Bank::new_f32(T3, Z3, 0.01).unwrap(), f32)
    );
    assert_eq!(
        response_bits!(g64, f64),
        response_bits!(Bank::new_f64(T3, Z3, 0.01).unwrap(), f64)
    );
    for (scheme, rule) in [
        (Scheme::Aem, Substeps::Fixed(4)),
        (Scheme::Exact, Substeps::PointsPerPeriod(40)),
        (Scheme::Aem, Substeps::AUTO),
    ] {
        let g = Bank::<f32, 3>::with(T3, Z3, 0.01, scheme, rule).unwrap();
        let c = Bank::with_f32(T3, Z3, 0.01, scheme, rule).unwrap();
        assert_eq!(g, c);
        assert_eq!(response_bits!(g, f32), response_bits!(c, f32));
        assert_eq!(g.substeps(), c.substeps());
    }
    // The type is inferred from the use: no turbofish in generic code either.
    let b: Bank<f32, 1> = Bank::new([1.0], [0.05], 0.02).unwrap();
    assert_eq!(b.time_step(), 0.02);
}

#[test]
fn generic_bank_fails_as_the_const_banks() {
    // ω = 2π/T = 2e19 rad/s: ω² = 4e38 overflows f32 (3.4e38), not f64; ω h = 2.
    let t = [core::f64::consts::TAU / 2e19];
    let (z, h) = ([0.05], 1e-19);
    assert_eq!(Bank::<f32, 1>::new(t, z, h), Err(Error::OperatorOverflow));
    assert_eq!(Bank::<f32, 1>::new(t, z, h), Bank::new_f32(t, z, h));
    assert!(Bank::<f64, 1>::new(t, z, h).is_ok());
    // Bad data: the same variant from both.
    type Case = ([f64; 2], [f64; 2], f64, Substeps, Error);
    let cases: [Case; 5] = [
        (
            [0.1, 1.0],
            [0.05; 2],
            0.0,
            Substeps::AUTO,
            Error::InvalidTimeStep,
        ),
        (
            [0.1, 1.0],
            [0.05; 2],
            f64::NAN,
            Substeps::AUTO,
            Error::InvalidTimeStep,
        ),
        (
            [1.0, 0.1],
            [0.05; 2],
            0.01,
            Substeps::AUTO,
            Error::InvalidPeriod,
        ),
        (
            [0.1, 1.0],
            [0.05, 1.0],
            0.01,
            Substeps::AUTO,
            Error::InvalidDamping,
        ),
        (
            [0.1, 1.0],
            [0.05; 2],
            0.01,
            Substeps::Fixed(0),
            Error::InvalidParameter(Param::Substeps),
        ),
    ];
    for (t, z, h, rule, e) in cases {
        assert_eq!(Bank::<f32, 2>::with(t, z, h, Scheme::Exact, rule), Err(e));
        assert_eq!(Bank::with_f32(t, z, h, Scheme::Exact, rule), Err(e));
        assert_eq!(Bank::<f64, 2>::with(t, z, h, Scheme::Exact, rule), Err(e));
        assert_eq!(Bank::with_f64(t, z, h, Scheme::Exact, rule), Err(e));
    }
}

#[test]
fn generic_rotd_equals_the_const_rotd() {
    assert_eq!(RotD::<f32, 180>::new(), ROT32);
    assert_eq!(RotD::<f64, 7>::new(), RotD::<f64, 7>::new_f64());
    assert_eq!(RotD::<f32, 180>::default(), ROT32);
}

#[test]
fn restore_checks_and_continues_bit_for_bit() {
    let p = SVector::<f64, 5>::from_fn(|i, _| 1.0e4 * (i + 1) as f64);
    let mut s = LIN64
        .start(&SVector::repeat(0.01), &SVector::repeat(-0.05), &p)
        .unwrap();
    for _ in 0..25 {
        LIN64.step(&mut s, &p);
    }
    let mut r = State::restore(*s.u(), *s.v(), *s.a(), s.steps()).unwrap();
    assert_eq!(r, s);
    for _ in 0..25 {
        LIN64.step(&mut s, &p);
        LIN64.step(&mut r, &p);
    }
    assert_eq!(r, s);
    assert_eq!(r.steps(), 50);
    // A non-finite entry anywhere: refused.
    let f = vector![1.0, 2.0];
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let b = vector![0.5, bad];
        assert_eq!(State::restore(b, f, f, 3), Err(Error::NonFiniteInput));
        assert_eq!(State::restore(f, b, f, 3), Err(Error::NonFiniteInput));
        assert_eq!(State::restore(f, f, b, 3), Err(Error::NonFiniteInput));
    }
    // f64::MAX is finite: restored as given.
    let m = vector![f64::MAX, -f64::MAX];
    assert_eq!(State::restore(m, m, m, 9).unwrap().u(), &m);
}

#[test]
fn detection_constructors_follow_the_rule() {
    // `new` (run time, generic over `T`) equals its `const` twin `new_<scalar>` bit for bit.
    assert_eq!(
        ChiSquareTest::<f32, 50>::new(&OBS32C, 1e-3).unwrap(),
        DET32.test
    );
    assert_eq!(Cusum::<f64>::new(&OBS32C, 2.0, 1e-3).unwrap(), CUSUM64);
    assert_eq!(Whitener::<f32, 1>::new(&[[4.0e-6]]).unwrap(), WH32);
    // One measurement: 50 degrees of freedom in the window.
    assert_eq!(DET32.test.dof(), 50);
    // `from_parts` is `const` and generic (one impl): the same value at run time.
    assert_eq!(
        ModelBank::from_parts([OBS32C; 2], [WH32; 2]).unwrap(),
        MODELS32
    );
    assert_eq!(Detector::from_parts(WH32, DET32.test), DET32);
    // A state at rest: `at_rest` (holds no `T`) or `at_rest_<scalar>`, equal to `Default`
    // and to the owner's start from rest.
    assert_eq!(WINDOW32, Window::default());
    assert_eq!(CUSUM_STATE32, CusumState::default());
    assert_eq!(BANK_STATE32, BankState::default());
    assert_eq!(
        MODELS32
            .start::<50>(&SVector::zeros(), &SVector::zeros())
            .unwrap(),
        BANK_STATE32
    );
    assert_eq!(STATE32, State::default());
    assert_eq!(
        OBS32.start_at_rest(&SVector::zeros()).unwrap(),
        aemstep::observer::Estimate::at_rest_f32()
    );
}
