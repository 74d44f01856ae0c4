//! Checks the tests make the same way in several files: a state's bits, a refused step,
//! and the firmware reference files that host tests generate. Unlike `support/mod.rs`,
//! this drives or inspects the code under test.
#![allow(dead_code)]

use core::fmt::Debug;

use aemstep::{Error, Real, State, StepState, Stepper};

/// Bit patterns of a state and its step count, so "unchanged" means bit-identical
/// (NaN-safe).
pub fn bits<T: Real, const N: usize>(s: &State<T, N>) -> Vec<u64> {
    s.u()
        .iter()
        .chain(s.v().iter())
        .chain(s.a().iter())
        .map(|x| x.as_f64().to_bits())
        .chain([s.steps()])
        .collect()
}

/// From the started state `s`: a step under `first`; then a step under the non-finite
/// `bad` is refused as input and leaves the state as it was; then a step under `good`
/// goes on, the second in all. Returns the state after it.
pub fn refuses_non_finite_input<T: Real, const N: usize, S: Stepper<T, N>>(
    sys: &S,
    mut s: S::State,
    first: &S::Input,
    bad: &S::Input,
    good: &S::Input,
) -> S::State
where
    S::State: PartialEq + Debug,
{
    sys.step(&mut s, first);
    let before = s;
    assert_eq!(sys.try_step(&mut s, bad), Err(Error::NonFiniteInput));
    assert_eq!(s, before);
    sys.try_step(&mut s, good).unwrap();
    assert_eq!(s.steps(), 2);
    s
}

/// A generated firmware reference file (`path` from the crate root) is current: with
/// `AEMSTEP_WRITE_REFERENCE` set it is first rewritten with `text`; then the committed
/// file must equal `text`.
pub fn reference_is_current(path: &str, text: &str) {
    let full = format!("{}/{path}", env!("CARGO_MANIFEST_DIR"));
    if std::env::var_os("AEMSTEP_WRITE_REFERENCE").is_some() {
        std::fs::write(&full, text).unwrap();
    }
    assert_eq!(
        std::fs::read_to_string(&full).unwrap(),
        text,
        "{path} is stale: rewrite it with AEMSTEP_WRITE_REFERENCE=1 cargo test --release --test {}",
        env!("CARGO_CRATE_NAME")
    );
}

/// `/// {doc}` and `pub static {name}: [{ty}; len] = [ … ];` with one value a line: the
/// layout rustfmt keeps (the generated files are formatted with the crate).
pub fn static_array<X: Debug>(doc: &str, name: &str, ty: &str, xs: &[X]) -> String {
    let mut s = format!("/// {doc}\npub static {name}: [{ty}; {}] = [\n", xs.len());
    for x in xs {
        s.push_str(&format!("    {x:?},\n"));
    }
    s.push_str("];\n");
    s
}
