//! Change detection with the load unknown (issue 21): the estimator scene's building
//! (`scenes/estimator/scene.rs`: unknown roof force, 3 accelerometers and the roof
//! displacement) simulated in the estimator's standard form with exactly the noises its
//! gains were solved for (process noise from `Q`, sensor noise from `R`), under a force the
//! estimator is not told; and the same building with storey 1 softened. Shared by
//! `tests/detection_joint.rs` (assertions) and `xtask/src/bin/detection_building.rs`
//! (the page's section).
#![allow(dead_code)] // each includer uses a different subset

use aemstep::estimation::InputModel;
use aemstep::models;
use aemstep::nalgebra::{DMatrix, SMatrix, SVector, SymmetricEigen};
use aemstep::observer::StateSpace;

use super::estimator as scene;
use super::gauss::Gauss;

/// Degrees of freedom of the joint estimator's residual: 4 sensors, 1 unknown force.
pub const DOF: usize = 3;

type V10 = SVector<f64, 10>;
type V4 = SVector<f64, 4>;

/// A square root `L` (`L Lᵀ = Q`) of a symmetric positive semidefinite `Q`, from its
/// eigen-decomposition (negative rounding-level eigenvalues set to zero).
pub fn sqrt_psd<const N: usize>(q: &[[f64; N]; N]) -> SMatrix<f64, N, N> {
    let m = DMatrix::<f64>::from_fn(N, N, |i, j| 0.5 * (q[i][j] + q[j][i]));
    let eig = SymmetricEigen::new(m);
    SMatrix::from_fn(|i, j| eig.eigenvectors[(i, j)] * eig.eigenvalues[j].max(0.0).sqrt())
}

/// The truth in the standard form of `model`: `ξ_n = A ξ_{n−1} + B w_{n−1} + q_n`,
/// `y_n = C ξ_n + D̃ w_n + v_n`, `q ~ N(0, Q)`, `v ~ N(0, R)`, and a force `w` the filter
/// is not told: a first-order low-pass of white noise (30 kN RMS) on a 200 kN static part.
pub struct Truth {
    xi: V10,
    w: f64,
    lq: SMatrix<f64, 10, 10>,
    lr: SMatrix<f64, 4, 4>,
    g: Gauss,
    n: usize,
}

impl Truth {
    pub fn new(seed: u64) -> Self {
        Truth {
            xi: V10::zeros(),
            w: 2e5,
            lq: sqrt_psd(&scene::Q),
            lr: sqrt_psd(&scene::R),
            g: Gauss::new(seed),
            n: 0,
        }
    }

    fn noise<const N: usize>(&mut self, l: &SMatrix<f64, N, N>) -> SVector<f64, N> {
        let z = SVector::<f64, N>::from_fn(|_, _| self.g.next());
        l * z
    }

    /// The next sample of `model` (the model the structure is now).
    pub fn next(&mut self, model: &InputModel<10, 1, 4>) -> V4 {
        let q = self.noise(&self.lq.clone());
        self.xi = model.a_matrix() * self.xi + model.b_matrix() * self.w + q;
        self.w = 2e5 + 0.98 * (self.w - 2e5) + 6e3 * self.g.next();
        self.n += 1;
        let v = self.noise(&self.lr.clone());
        model.c_matrix() * self.xi + model.d_matrix() * SVector::<f64, 1>::new(self.w) + v
    }

    /// Switch to `to` keeping the physical state `x = ξ + Γ₁ w` (the state of the building
    /// does not jump when a storey loses stiffness; `ξ` does, as `Γ₁` changes).
    pub fn switch(&mut self, from: &InputModel<10, 1, 4>, to: &InputModel<10, 1, 4>) {
        let w = SVector::<f64, 1>::new(self.w);
        let x = from.physical_state(&self.xi, &w);
        self.xi = to.xi_of(&x, &w);
    }
}

/// The building with storey-1 stiffness reduced to `factor` of its value, in the scene's
/// standard form (same sensors, same force location).
pub fn damaged(factor: f64) -> InputModel<10, 1, 4> {
    let (m, c, mut k) = models::five_storey_building();
    // Storey 1 connects floor 1 to the ground: k₁ enters only K[0][0].
    let k1 = k[0][0] + k[0][1];
    k[0][0] -= (1.0 - factor) * k1;
    let ss = StateSpace::<5, 10, 1>::from_rows_aem(m, c, k, scene::ROOF, scene::H).unwrap();
    let meas = ss.outputs(&scene::SENSORS).unwrap();
    InputModel::from_parts(&ss, &meas).unwrap()
}
