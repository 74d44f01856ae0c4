//! Standard normal samples: Box–Muller on xorshift64*. The noise generator of the detection
//! scene (`tests/detection.rs`, `xtask/src/bin/detection_building.rs`, through
//! `scenes/detection/scene.rs`) and of the noisy runs of `tests/observer.rs`: fixed seeds give
//! the same samples on every host.

/// Standard normal samples: Box–Muller on xorshift64*.
pub struct Gauss(u64, Option<f64>);
impl Gauss {
    /// The generator started from `seed` (any value; scrambled, never the zero state).
    pub fn new(seed: u64) -> Self {
        Gauss(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1, None)
    }
    /// Uniform on (0, 1), 53 bits.
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    /// The next standard normal sample.
    pub fn next(&mut self) -> f64 {
        if let Some(z) = self.1.take() {
            return z;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let t = 2.0 * std::f64::consts::PI * u2;
        self.1 = Some(r * t.sin());
        r * t.cos()
    }
}
