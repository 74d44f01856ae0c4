//! Host twin of the nonlinear firmware example (`examples/qemu_nonlinear.rs`): paper
//! Example 5, the Duffing oscillator `u'' + 0.2 u' + u + u³ = p(t)`, u0 = 0, v0 = 1, with
//! `p(t)` chosen so that the exact solution is `u = e^{−0.1t} sin t`; h = 0.01 s,
//! 0 < t ≤ 20 s (2000 steps), `f32`, exactly 2 Newton iterations a step.
//!
//! The run itself (`trajectory`, Newton tolerance `TOL`, exact solution and load) is
//! `tests/support/duffing.rs`, which `xtask/src/bin/verification.rs` prints from.
//!
//! This test is where the firmware's bound comes from: it measures the same f32 error and
//! asserts the same bound (`FIRMWARE_BOUND`, copied into the firmware as `BOUND`), and
//! checks the Newton report of every step as the firmware does.
//!
//! Measured (`cargo test --release --test firmware_duffing -- --nocapture`): f64 max
//! error 1.588e-5, 3.970e-6, 9.925e-7 at h, h/2, h/4 (ratios 4.000: second order);
//! f32 max error 1.622e-5; max |u_f32 − u_f64| 1.139e-6; every report converged in 2.

#[path = "support/duffing.rs"]
mod duffing;
mod support;

use duffing::{max_error, trajectory};

const H: f64 = 0.01;
const STEPS: u32 = 2000;
/// The bound the firmware checks every step against, max |u_n − u(t_n)| in f32: the
/// method's error at h (≤ 1.05 × 16 × its value at h/4, by the O(h²) order verified
/// below: 1.667e-5) plus the f32 rounding part (≤ 2e-6), i.e. 1.867e-5, rounded down.
const FIRMWARE_BOUND: f64 = 1.85e-5;

#[test]
fn f64_error_is_second_order() {
    let e: Vec<f64> = [1u32, 2, 4]
        .iter()
        .map(|&k| {
            let (u, bad) = trajectory::<f64>(H / k as f64, STEPS * k);
            assert_eq!(
                bad, 0,
                "h/{k}: every step converges in exactly 2 iterations"
            );
            max_error(&u, H / k as f64)
        })
        .collect();
    println!(
        "f64 max error at h, h/2, h/4: {:.4e} {:.4e} {:.4e}",
        e[0], e[1], e[2]
    );
    for w in e.windows(2) {
        let ratio = w[0] / w[1];
        // O(h²): halving h divides the error by 4; 2.5% covers the next-order term.
        assert!((3.9..=4.1).contains(&ratio), "ratio {ratio}");
    }
}

/// The method's error bound at h from its value at h/4 and the verified order.
fn method_bound() -> f64 {
    let (u, _) = trajectory::<f64>(H / 4.0, STEPS * 4);
    1.05 * 16.0 * max_error(&u, H / 4.0)
}

#[test]
fn f32_error_within_the_firmware_bound_and_every_report_good() {
    let (u64_, _) = trajectory::<f64>(H, STEPS);
    let (u32_, bad) = trajectory::<f32>(H, STEPS);
    assert_eq!(bad, 0, "every f32 step converges in exactly 2 iterations");
    // The f32 rounding part alone: both runs follow the same recurrence. Measured 1.139e-6
    // (≈ 20 f32 ulps of |u| ≈ 0.8: the increments h·v added to u each step, accumulated over
    // the damped response); 2e-6 leaves room for another valid summation order.
    let rounding = support::max_diff(&u64_, &u32_);
    let e32 = max_error(&u32_, H);
    println!("f32 max error {e32:.4e} (bound {FIRMWARE_BOUND:e}), rounding part {rounding:.4e}");
    assert!(rounding <= 2e-6, "{rounding:e}");
    assert!(FIRMWARE_BOUND <= method_bound() + 2e-6);
    assert!(e32 <= FIRMWARE_BOUND, "{e32:e}");
}
