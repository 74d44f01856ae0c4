//! Issue 31, "state that cannot live in a `static`" and "soft double in an f32 interrupt".
//!
//! Every step state has a `const` at-rest constructor (per scalar, `at_rest_f32` /
//! `at_rest_f64`, where it holds values of `T`; `at_rest` where it does not), so firmware
//! can put it in a `static` (a `static Mutex<RefCell<…>>` as it does heapless and idsp
//! types: here `static`s of the values, and `std::sync::Mutex<RefCell<…>>` for the
//! critical-section mutex); `Default` is the same value; and the at-rest state is the one the stepper's own
//! start gives from rest. An `f32` detector (whitener, window, χ² test, CUSUM) takes and
//! gives `f32` only: checked at the type level.

use core::cell::RefCell;
use std::sync::Mutex;

use aemstep::detection::{
    BankState, ChiSquareTest, Cusum, CusumState, Detector, Dof, Whitener, Window,
};
use aemstep::estimation::JointEstimate;
use aemstep::hybrid::{
    Actuator, ActuatorState, Compensator, CompensatorState, Polynomial, Split, SplitState,
};
use aemstep::hysteresis::{Bilinear, BilinearHistory, BoucWen, BoucWenHistory, Law};
use aemstep::models;
use aemstep::nalgebra::SVector;
use aemstep::observer::Estimate;
use aemstep::{Error, KrAlpha, Linear, State, Stepper};

#[path = "../scenes/estimator/scene.rs"]
mod scene;

const fn ok<T: Copy>(r: Result<T, Error>) -> T {
    match r {
        Ok(t) => t,
        Err(e) => panic!("{}", e.as_str()),
    }
}

/// The firmware's `static Mutex<RefCell<…>>`, with the host's mutex (`const fn new` as
/// `cortex_m::interrupt::Mutex`'s is): the value inside must be `const`-constructible,
/// which is what is tested.
type Shared<X> = Mutex<RefCell<X>>;

const fn shared<X>(x: X) -> Shared<X> {
    Mutex::new(RefCell::new(x))
}

static STATE32: Shared<State<f32, 4>> = shared(State::at_rest_f32());
static STATE64: State<f64, 4> = State::at_rest_f64();
static ESTIMATE32: Estimate<f32, 10, 1> = Estimate::at_rest_f32();
static ESTIMATE64: Estimate<f64, 10, 1> = Estimate::at_rest_f64();
static JOINT32: Shared<JointEstimate<f32, 10, 1>> = shared(JointEstimate::at_rest_f32());
static JOINT64: JointEstimate<f64, 10, 1> = JointEstimate::at_rest_f64();
static SPLIT32: SplitState<f32, 5> = SplitState::at_rest_f32();
static SPLIT64: SplitState<f64, 5> = SplitState::at_rest_f64();
static ACT32: ActuatorState<f32, 8> = ActuatorState::at_rest_f32();
static ACT64: ActuatorState<f64, 8> = ActuatorState::at_rest_f64();
static COMP32: CompensatorState<f32> = CompensatorState::at_rest_f32();
static COMP64: CompensatorState<f64> = CompensatorState::at_rest_f64();
static WIN32: Shared<Window<f32, 50>> = shared(Window::at_rest());
/// The window a handler steps (`a_static_state_is_stepped_in_place`).
static WIN_STEPPED: Shared<Window<f32, 50>> = shared(Window::at_rest());
static WIN64: Window<f64, 50> = Window::at_rest();
static CUSUM32: CusumState<f32> = CusumState::at_rest_f32();
static CUSUM64: CusumState<f64> = CusumState::at_rest_f64();
static BANK32: BankState<f32, 10, 1, 3, 50> = BankState::at_rest_f32();
static BANK64: BankState<f64, 10, 1, 3, 50> = BankState::at_rest_f64();
static BILINEAR32: [BilinearHistory<f32>; 5] = [BilinearHistory::at_rest_f32(); 5];
static BILINEAR64: BilinearHistory<f64> = BilinearHistory::at_rest_f64();
static BOUC_WEN32: BoucWenHistory<f32> = BoucWenHistory::at_rest_f32();
static BOUC_WEN64: [BoucWenHistory<f64>; 3] = [BoucWenHistory::at_rest_f64(); 3];

/// The detector of a firmware handler, every part built by the compiler.
static DETECTOR32: Detector<f32, 2, 50> = Detector::from_parts(
    ok(Whitener::from_rows_f32(&[[2.0, 0.3], [0.3, 0.5]])),
    ok(ChiSquareTest::new_f32(&Dof::<2>, 1e-3)),
);
static CUSUM_TEST32: Cusum<f32> = ok(Cusum::new_f32(&Dof::<2>, 2.0, 1e-3));

#[test]
fn each_state_lives_in_a_static_and_equals_its_default() {
    assert_eq!(*STATE32.lock().unwrap().borrow(), State::default());
    assert_eq!(STATE64, State::default());
    assert_eq!(ESTIMATE32, Estimate::default());
    assert_eq!(ESTIMATE64, Estimate::default());
    assert_eq!(*JOINT32.lock().unwrap().borrow(), JointEstimate::default());
    assert_eq!(JOINT64, JointEstimate::default());
    assert_eq!(SPLIT32, SplitState::default());
    assert_eq!(SPLIT64, SplitState::default());
    assert_eq!(ACT32, ActuatorState::default());
    assert_eq!(ACT64, ActuatorState::default());
    assert_eq!(COMP32, CompensatorState::default());
    assert_eq!(COMP64, CompensatorState::default());
    assert_eq!(*WIN32.lock().unwrap().borrow(), Window::default());
    assert_eq!(WIN64, Window::default());
    assert_eq!(CUSUM32, CusumState::default());
    assert_eq!(CUSUM64, CusumState::default());
    assert_eq!(BANK32, BankState::default());
    assert_eq!(BANK64, BankState::default());
    assert_eq!(BILINEAR32, [BilinearHistory::default(); 5]);
    assert_eq!(BILINEAR64, BilinearHistory::default());
    assert_eq!(BOUC_WEN32, BoucWenHistory::default());
    assert_eq!(BOUC_WEN64, [BoucWenHistory::default(); 3]);
    // Bit for bit too (`PartialEq` takes −0 for 0): every at-rest value is +0.
    assert_eq!(
        format!("{:?}", *STATE32.lock().unwrap().borrow()),
        format!("{:?}", State::<f32, 4>::default())
    );
    assert_eq!(
        format!("{BANK64:?}"),
        format!("{:?}", BankState::<f64, 10, 1, 3, 50>::default())
    );
}

#[test]
fn the_at_rest_state_is_the_steppers_start_from_rest() {
    let (m, c, k) = models::five_storey_building();
    let sm = |r: &models::Rows<5>| aemstep::nalgebra::SMatrix::<f64, 5, 5>::from_fn(|i, j| r[i][j]);
    // A linear stepper from rest with no load.
    let lin = Linear::<f32, 5>::new(&sm(&m), &sm(&c), &sm(&k), 0.02).unwrap();
    let z = SVector::<f32, 5>::zeros();
    assert_eq!(lin.start(&z, &z, &z).unwrap(), State::at_rest_f32());
    let z = SVector::<f64, 5>::zeros();
    // The split (hybrid) step from rest, no restoring force, no load.
    let split = Split::<f64, 5>::from_rows_f64(m, c, k, k, 0.02, 0.8).unwrap();
    assert_eq!(split.start(&z, &z, &z, &z).unwrap(), SPLIT64);
    let _ = KrAlpha::<f64, 5>::from_rows_f64(m, c, k, 0.02, 0.8).unwrap();
    // The actuator and the polynomial compensator at rest at 0.
    let act = Actuator::<f32, 8>::new(0.01, 0.025, 0.0).unwrap();
    assert_eq!(act.rest(0.0), ACT32);
    let poly = Polynomial::<f64>::new(2, 0.01, 0.02).unwrap();
    assert_eq!(poly.rest(0.0), COMP64);
    // The laws' virgin histories.
    let b = Bilinear::<f32>::new(1e3, 10.0, 0.05).unwrap();
    assert_eq!(b.initial_history(), BILINEAR32[0]);
    let bw = BoucWen::<f64>::new(1e3, 10.0, 0.05, 0.5, 0.5, 1.0).unwrap();
    assert_eq!(bw.initial_history(), BOUC_WEN64[0]);
    // The joint estimator's and the observer's start at rest.
    let f =
        aemstep::estimation::InputStateObserver::<f32, 10, 1, 4>::new(&scene::MODEL, &scene::GAINS)
            .unwrap();
    assert_eq!(f.start_at_rest(), *JOINT32.lock().unwrap().borrow());
}

#[test]
fn a_static_state_is_stepped_in_place() {
    // A handler borrows the static's state and steps it (here the window of the static
    // detector): the value is the one a run-time state gets.
    let nu = SVector::<f32, 2>::new(0.4, -0.2);
    let mut local = Window::<f32, 50>::at_rest();
    for _ in 0..60 {
        DETECTOR32.update(&mut WIN_STEPPED.lock().unwrap().borrow_mut(), &nu);
        DETECTOR32.update(&mut local, &nu);
    }
    assert_eq!(*WIN_STEPPED.lock().unwrap().borrow(), local);
    assert!(local.is_full());
}

/// The value's type, named: a use below compiles only if the type is `f32`.
fn is_f32(_: f32) {}

#[test]
fn an_f32_detector_gives_f32_end_to_end() {
    // Issue 31, "soft double in an f32 interrupt": `Window::sum`, `Window::push`,
    // `ChiSquareTest::threshold` and `Whitener::log_det` took or gave `f64`. Each is `f32`
    // in an `f32` detector (this does not compile otherwise).
    let mut win = Window::<f32, 50>::at_rest();
    win.push(1.5f32);
    is_f32(win.sum());
    is_f32(DETECTOR32.test.threshold());
    is_f32(DETECTOR32.test.false_alarm());
    is_f32(DETECTOR32.whitener.log_det());
    is_f32(DETECTOR32.whitener.nis(&SVector::<f32, 2>::new(0.1, 0.2)));
    let mut g = CusumState::<f32>::at_rest_f32();
    CUSUM_TEST32.update(&mut g, 3.0f32);
    is_f32(g.statistic());
    is_f32(CUSUM_TEST32.threshold());
    // Their values: the f64 computations rounded once (the sum: the fixed-point integer
    // rounded once to f32, scaled by 2⁻²⁴ exactly).
    assert_eq!(win.sum(), win.sum_fixed() as f32 / (1u32 << 24) as f32);
    assert_eq!(win.sum(), 1.5);
    let t64 = ChiSquareTest::<f64, 50>::new(&Dof::<2>, 1e-3).unwrap();
    assert_eq!(DETECTOR32.test.threshold(), t64.threshold() as f32);
    assert_eq!(DETECTOR32.test.threshold_fixed(), t64.threshold_fixed());
    let w64 = Whitener::<f64, 2>::new(&[[2.0, 0.3], [0.3, 0.5]]).unwrap();
    assert_eq!(DETECTOR32.whitener.log_det(), w64.log_det() as f32);
    // ln det S = ln(1 − 0.09) for S = [[2, .3], [.3, .5]]: within the f32 rounding.
    assert!(
        (DETECTOR32.whitener.log_det() as f64 - 0.91f64.ln()).abs() <= 0.1 * f32::EPSILON as f64
    );
}
