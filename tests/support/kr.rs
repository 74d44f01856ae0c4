//! The papers' explicit model-based schemes, written independently of the crate (Chen &
//! Ricles 2008; Kolay & Ricles 2014) in plain `nalgebra::DMatrix` arithmetic:
//! `α1 = (M + γhC + βh²K)⁻¹ M`, `α2 = (1/2 + γ) α1`,
//! `α3 = (M + γhC + βh²K)⁻¹ (α_m M + α_f γh C + α_f βh² K)`; `u' = u + h v + h² α2 a`,
//! `v' = v + h α1 a`, and
//! `M [(I − α3) a' + α3 a] + C [(1 − α_f) v' + α_f v] + [(1 − α_f) R(u') + α_f R(u)]
//!  = (1 − α_f) p' + α_f p`, solved for `a'` by LU at every step (`R = K u` for the linear
//! scheme). Shared by `tests/kr_alpha.rs` and `tests/hybrid.rs`.
#![allow(dead_code)]

use nalgebra::{DMatrix, DVector};

/// `(α_m, α_f, β, γ)` of ρ∞ (Chung–Hulbert), or of CR (`None`).
pub fn params(rho: Option<f64>) -> (f64, f64, f64, f64) {
    match rho {
        Some(r) => {
            let am = (2.0 * r - 1.0) / (r + 1.0);
            let af = r / (r + 1.0);
            let d = 1.0 - am + af;
            (am, af, d * d / 4.0, 0.5 - am + af)
        }
        None => (0.0, 0.0, 0.25, 0.5),
    }
}

/// CR and the KR-α members of the tests.
pub fn members() -> [(&'static str, Option<f64>); 4] {
    [
        ("CR", None),
        ("KR-α ρ∞ = 1", Some(1.0)),
        ("KR-α ρ∞ = 0.5", Some(0.5)),
        ("KR-α ρ∞ = 0", Some(0.0)),
    ]
}

/// The scheme's operators for `M, C` and the assumed stiffness `K`.
pub struct Reference {
    pub m: DMatrix<f64>,
    pub c: DMatrix<f64>,
    pub k: DMatrix<f64>,
    pub h: f64,
    pub af: f64,
    pub a1: DMatrix<f64>,
    pub a2: DMatrix<f64>,
    pub a3: DMatrix<f64>,
}

impl Reference {
    pub fn new(
        m: DMatrix<f64>,
        c: DMatrix<f64>,
        k: DMatrix<f64>,
        h: f64,
        rho: Option<f64>,
    ) -> Self {
        let (am, af, beta, gamma) = params(rho);
        let meff = &m + &c * (gamma * h) + &k * (beta * h * h);
        let inv = meff.try_inverse().expect("regular");
        let a1 = &inv * &m;
        let a2 = &a1 * (0.5 + gamma);
        let a3 = &inv * (&m * am + &c * (af * gamma * h) + &k * (af * beta * h * h));
        Self {
            m,
            c,
            k,
            h,
            af,
            a1,
            a2,
            a3,
        }
    }

    /// The explicit displacement and velocity of the next step from `(u, v, a)`.
    pub fn explicit(&self, x: &[DVector<f64>; 3]) -> (DVector<f64>, DVector<f64>) {
        let [u, v, a] = x;
        let h = self.h;
        (u + v * h + &self.a2 * a * (h * h), v + &self.a1 * a * h)
    }

    /// Complete the step: `r0, r1` the restoring forces at `u` and `u'`, `p0, p1` the
    /// loads at `t_n` and `t_{n+1}`.
    pub fn complete(
        &self,
        x: &mut [DVector<f64>; 3],
        r0: &DVector<f64>,
        r1: &DVector<f64>,
        p0: &DVector<f64>,
        p1: &DVector<f64>,
    ) {
        let (u1, v1) = self.explicit(x);
        let [_, v, a] = &*x;
        let af = self.af;
        let vbar = &v1 * (1.0 - af) + v * af;
        let rbar = r1 * (1.0 - af) + r0 * af;
        let pbar = p1 * (1.0 - af) + p0 * af;
        let n = v.len();
        let lhs = &self.m * (DMatrix::identity(n, n) - &self.a3);
        let rhs = pbar - &self.c * vbar - rbar - &self.m * &self.a3 * a;
        let a1 = lhs.lu().solve(&rhs).expect("regular");
        *x = [u1, v1, a1];
    }

    /// The linear step (`R = K u`) from `(u, v, a)` under `p` (at `t_n`) and `p1` (at
    /// `t_{n+1}`).
    pub fn step(&self, x: &mut [DVector<f64>; 3], p: &DVector<f64>, p1: &DVector<f64>) {
        let (u1, _) = self.explicit(x);
        let (r0, r1) = (&self.k * &x[0], &self.k * u1);
        self.complete(x, &r0, &r1, p, p1);
    }
}
