//! The bilinear law where `k (d − d_p)` overflows but the force fits (found by the seeded
//! fuzz stage, input kept in `fuzz/regressions/hysteresis/`): the trial is taken at half
//! scale and gives the force of the law's definition, checked here against that definition
//! evaluated by hand; the lane trial keeps every lane's bits.

use aemstep::hysteresis::{Bilinear, BilinearHistory, Law};
use aemstep::lanes::LaneLaw;

/// Elastic–perfectly plastic, `k = 1e9` N/m, `f_y = 2.989215087890626e307` N: a plastic
/// offset of `−1.74e299` m, then a reversal to `d = 2.2268e298` m. The elastic trial force
/// `k (d − d_p) ≈ 1.96e308` overflows; the law's force is `f_y` (the trial is plastic:
/// `|k (d − d_p)| > f_y`), the new offset `d − f_y / k`.
#[test]
fn reversal_from_a_huge_plastic_offset_gives_the_yield_force() {
    let (k, fy) = (1e9, 2.989215087890626e307);
    let law = Bilinear::<f64>::new(k, fy, 0.0).unwrap();
    let dp = -1.74e299;
    let d = 2.226768197491766e298;
    let committed = BilinearHistory { plastic: dp };
    let t = law.trial(&committed, d, 0.0);
    assert!(t.inelastic);
    // Definition: f = sign(ξ) f_y with ξ = k (d − d_p) > 0 (α = 0), d_p' = d − f / k.
    // Rounding: the half-scale trial rounds each of its 5 operations once (relative 2⁻⁵³
    // each), the force's `f_tr − excess` cancels to f_y with the excess's error amplified
    // by |f_tr| / f_y ≈ 6.6: 6.6 · 3 ε bounds it.
    let tol = 6.6 * 3.0 * f64::EPSILON;
    assert!(((t.force - fy) / fy).abs() <= tol, "{:e}", t.force);
    let dp_new = d - fy / k;
    assert!(
        ((t.history.plastic - dp_new) / dp_new).abs() <= 1e-6,
        "{:e}",
        t.history.plastic
    );
    assert_eq!(t.stiffness, 0.0);

    // Lanes: one lane overflowing beside ordinary ones, each lane the scalar trial's bits.
    let committed = [
        BilinearHistory { plastic: dp },
        BilinearHistory { plastic: 0.0 },
        BilinearHistory { plastic: 1e-3 },
        BilinearHistory { plastic: -2e298 },
    ];
    let ds = [d, 1e-4, 1e299, -1e298];
    let lanes = law.trial_lanes(&committed, &ds, &[0.0; 4]);
    for l in 0..4 {
        let s = law.trial(&committed[l], ds[l], 0.0);
        assert_eq!(lanes.force[l].to_bits(), s.force.to_bits(), "lane {l}");
        assert_eq!(
            lanes.stiffness[l].to_bits(),
            s.stiffness.to_bits(),
            "lane {l}"
        );
        assert_eq!(
            lanes.history[l].plastic.to_bits(),
            s.history.plastic.to_bits(),
            "lane {l}"
        );
        assert_eq!(lanes.inelastic[l], s.inelastic, "lane {l}");
    }
}
