//! Observers of any size on the host (feature `std`): the AEM state-space model, its
//! steady-state Kalman gain and the fixed-gain observer with the number of degrees of
//! freedom chosen at run time ([`DynStateSpace`], [`DynSteadyState`], [`DynObserver`]).
//!
//! They are the const-generic [`StateSpace`](super::StateSpace),
//! [`SteadyState`](super::SteadyState) and [`Observer`](super::Observer) with heap storage,
//! not second implementations: the Newmark blocks, the outputs, the input noise, the
//! Riccati solve (doubling, verification, Newton refinement) and its checks are the same
//! `const fn` code on flat row-major slices that the const-generic types call with their
//! arrays, and the observer's step is the same per-row arithmetic (`predict_row`,
//! `innovation_row`, `correct_row`). So at every size both serve, the models, gains and
//! estimates are bit-identical (`tests/runtime_size_observer.rs` checks every sample).
//!
//! The number of sensors is run-time too (`1 ≤ O`): unlike the compiled path's short list
//! of sensor counts, nothing here is unrolled for it.
//!
//! The time-varying Kalman filter is here too ([`DynKalman`]): the const-generic
//! [`Kalman`](super::Kalman)'s step on flat column-major slices (`kalman_flat`), so the
//! same numbers bit for bit.
//!
//! Not here yet: the process–measurement cross covariance of
//! [`SteadyState::from_parts_cross`](super::SteadyState::from_parts_cross) and
//! [`Kalman::with_cross`](super::Kalman::with_cross).

use std::vec;
use std::vec::Vec;

use nalgebra::DMatrix;

use super::fixed::{check_parts_flat, next_counts};
use super::flat::{
    LuFlat, OutScratch, RiccatiParts, RiccatiRun, Scratch, Sensors, check_noise, definite_lu_flat,
    identity_into, is_covariance_flat, plain_start,
};
use super::kalman_flat::{KalmanModel, KalmanWork, kalman_step_flat};
use super::state_space::{BlockInputs, blocks_flat, input_noise_flat, outputs_flat};
use crate::kernel::{Buffers, Factored, StartBuffers, Terms, newmark_operators_flat};
use crate::linalg::{all_finite_flat, all_fit};
use crate::{Error, Param, Real};

/// The heap storage of the kernel's flat operator build ([`newmark_operators_flat`]) at
/// `n` degrees of freedom: ten `n×n` matrices, four scale vectors, two permutations.
struct KernelHeap {
    sq: [Vec<f64>; 10],
    scales: [Vec<f64>; 4],
    perms: [Vec<usize>; 2],
}

impl KernelHeap {
    fn new(n: usize) -> Self {
        Self {
            sq: core::array::from_fn(|_| vec![0.0; n * n]),
            scales: core::array::from_fn(|_| vec![0.0; n]),
            perms: core::array::from_fn(|_| vec![0; n]),
        }
    }

    /// The build's view: `M_eff` and its factors, `G`, `GC`, `GK`, and the start-up
    /// factorization of `M` with `M⁻¹`, `M⁻¹C`, `M⁻¹K`.
    fn buffers(&mut self) -> Buffers<'_> {
        let [a, lu, g, gc, gk, ma, mlu, minv, minv_c, minv_k] = &mut self.sq;
        let [scales, pivot_scales, ms, mps] = &mut self.scales;
        let [perm, mperm] = &mut self.perms;
        let eff = Factored {
            a,
            scales,
            lu,
            pivot_scales,
            perm,
        };
        let f = Factored {
            a: ma,
            scales: ms,
            lu: mlu,
            pivot_scales: mps,
            perm: mperm,
        };
        let start = StartBuffers {
            f,
            minv,
            minv_c,
            minv_k,
        };
        Buffers {
            eff,
            g,
            gc,
            gk,
            start,
        }
    }
}

/// Row-major copy of a `nalgebra` matrix.
fn rows(a: &DMatrix<f64>) -> Vec<f64> {
    a.transpose().as_slice().to_vec()
}

/// The discrete AEM state-space model `x_n = Φ x_{n−1} + Γ₀ w_{n−1} + Γ₁ w_n` of
/// [`StateSpace::aem`](super::StateSpace::aem) with `N` degrees of freedom and `I` inputs
/// chosen at run time (feature `std`): `x = [u; v]` (m, m/s for a building), `S = 2N`
/// states, all `f64`, row-major.
///
/// Size: `S² + 2S·I + N·(3S + I)` values of `f64` on the heap. Same numbers as
/// `StateSpace<N, 2N, I>` bit for bit (the same flat build).
#[derive(Clone, Debug, PartialEq)]
pub struct DynStateSpace {
    n: usize,
    inputs: usize,
    /// `Φ` (`S×S`).
    phi: Vec<f64>,
    /// `Γ₀`, `Γ₁` (`S×I`).
    gamma0: Vec<f64>,
    gamma1: Vec<f64>,
    /// `U`, `V`, `A_x` (`N×S`), `A_w` (`N×I`).
    dof_u: Vec<f64>,
    dof_v: Vec<f64>,
    dof_a: Vec<f64>,
    dof_a_input: Vec<f64>,
    time_step: f64,
}

/// The output matrices `y = H x + D w` (`H`: `O×S`, `D`: `O×I`, `f64`, row-major) of a
/// [`DynStateSpace`], as [`Measurement`](super::Measurement).
#[derive(Clone, Debug, PartialEq)]
pub struct DynMeasurement {
    outputs: usize,
    h: Vec<f64>,
    d: Vec<f64>,
}

impl DynMeasurement {
    /// Outputs `O`. Cost: none.
    pub fn outputs(&self) -> usize {
        self.outputs
    }

    /// `H` (`O×S`) as a `nalgebra` matrix. Cost: a copy.
    pub fn h_matrix(&self) -> DMatrix<f64> {
        DMatrix::from_row_slice(self.outputs, self.h.len() / self.outputs.max(1), &self.h)
    }

    /// `D` (`O×I`) as a `nalgebra` matrix. Cost: a copy.
    pub fn d_matrix(&self) -> DMatrix<f64> {
        DMatrix::from_row_slice(self.outputs, self.d.len() / self.outputs.max(1), &self.d)
    }
}

impl DynStateSpace {
    /// The AEM model (Newmark β = 1/4, γ = 1/2) of `M u'' + C u' + K u = B w(t)` with step
    /// `h` (s): [`StateSpace::aem`](super::StateSpace::aem) at a run-time size. `M, C, K`
    /// are `N×N` (kg, N·s/m, N/m), `B` is `N×I` (`N ≥ 1`, `I ≥ 1`).
    ///
    /// Errors: [`Error::StateSizeMismatch`] (a matrix of the wrong shape, or `N = 0`), then
    /// those of [`StateSpace::aem`](super::StateSpace::aem) in its order:
    /// [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`],
    /// [`Error::SingularEffectiveMatrix`], [`Error::OperatorOverflow`],
    /// [`Error::OperatorUnderflow`], [`Error::SingularMass`].
    ///
    /// Cost: about `12N³ + 4N²·I` flops, `O(N²)` `f64` temporaries on the heap.
    pub fn aem(
        m: &DMatrix<f64>,
        c: &DMatrix<f64>,
        k: &DMatrix<f64>,
        b: &DMatrix<f64>,
        h: f64,
    ) -> Result<Self, Error> {
        let (n, ni) = (m.nrows(), b.ncols());
        if n == 0 || ni == 0 || [m, c, k].iter().any(|a| a.shape() != (n, n)) || b.nrows() != n {
            return Err(Error::StateSizeMismatch);
        }
        let (m, c, k, b) = (rows(m), rows(c), rows(k), rows(b));
        let t = Terms {
            m: &m,
            c: &c,
            k: &k,
        };
        // The checks of `input_kernel_operators`: `B` first.
        if !all_finite_flat(&b) {
            return Err(Error::NonFiniteInput);
        }
        let sq = || vec![0.0f64; n * n];
        let mut ident = sq();
        identity_into(&mut ident, n);
        let mut heap = KernelHeap::new(n);
        let mut kb = heap.buffers();
        let built = newmark_operators_flat(&t, &ident, h, 0.25, 0.5, f64::MAX, &mut kb)?;
        let wi = || vec![0.0f64; n * ni];
        let (mut gb, mut aw) = (wi(), wi());
        kb.eff.solve(&b, ni, &mut gb);
        if !built.start {
            return Err(Error::SingularMass);
        }
        kb.start.f.solve(&b, ni, &mut aw);
        let (mut uu, mut uv, mut vu, mut vv, mut au, mut av) = (sq(), sq(), sq(), sq(), sq(), sq());
        let (mut u0, mut v0, mut u1, mut v1) = (wi(), wi(), wi(), wi());
        let (mut t0, mut t1, mut t2, mut t3, mut t4) = (sq(), sq(), sq(), sq(), sq());
        let (mut w0, mut w1, mut w2) = (wi(), wi(), wi());
        blocks_flat(
            &t,
            &BlockInputs {
                minv_k: kb.start.minv_k,
                minv_c: kb.start.minv_c,
                aw: &aw,
                gb: &gb,
                lu: kb.eff.lu,
                perm: kb.eff.perm,
                kin: &built.kin,
                inputs: ni,
            },
            [&mut uu, &mut uv, &mut vu, &mut vv, &mut au, &mut av],
            [&mut u0, &mut v0, &mut u1, &mut v1],
            [&mut t0, &mut t1, &mut t2, &mut t3, &mut t4],
            [&mut w0, &mut w1, &mut w2],
        );
        // Assemble x = [u; v] (`from_uv_blocks`, `full_outputs`).
        let s = 2 * n;
        let mut ss = Self {
            n,
            inputs: ni,
            phi: vec![0.0; s * s],
            gamma0: vec![0.0; s * ni],
            gamma1: vec![0.0; s * ni],
            dof_u: vec![0.0; n * s],
            dof_v: vec![0.0; n * s],
            dof_a: vec![0.0; n * s],
            dof_a_input: aw,
            time_step: h,
        };
        for i in 0..n {
            let (r, q) = (i * n..(i + 1) * n, i * ni..(i + 1) * ni);
            ss.phi[i * s..i * s + n].copy_from_slice(&uu[r.clone()]);
            ss.phi[i * s + n..(i + 1) * s].copy_from_slice(&uv[r.clone()]);
            ss.phi[(n + i) * s..(n + i) * s + n].copy_from_slice(&vu[r.clone()]);
            ss.phi[(n + i) * s + n..(n + i + 1) * s].copy_from_slice(&vv[r.clone()]);
            ss.gamma0[i * ni..(i + 1) * ni].copy_from_slice(&u0[q.clone()]);
            ss.gamma0[(n + i) * ni..(n + i + 1) * ni].copy_from_slice(&v0[q.clone()]);
            ss.gamma1[i * ni..(i + 1) * ni].copy_from_slice(&u1[q.clone()]);
            ss.gamma1[(n + i) * ni..(n + i + 1) * ni].copy_from_slice(&v1[q]);
            ss.dof_u[i * s + i] = 1.0;
            ss.dof_v[i * s + n + i] = 1.0;
            ss.dof_a[i * s..i * s + n].copy_from_slice(&au[r.clone()]);
            ss.dof_a[i * s + n..(i + 1) * s].copy_from_slice(&av[r]);
        }
        let all = [
            &ss.phi,
            &ss.gamma0,
            &ss.gamma1,
            &ss.dof_u,
            &ss.dof_v,
            &ss.dof_a,
            &ss.dof_a_input,
        ];
        if all.iter().all(|a| all_finite_flat(a)) {
            Ok(ss)
        } else {
            Err(Error::OperatorOverflow)
        }
    }

    /// Degrees of freedom `N`. Cost: none.
    pub fn dofs(&self) -> usize {
        self.n
    }

    /// States `S = 2N`. Cost: none.
    pub fn states(&self) -> usize {
        2 * self.n
    }

    /// Inputs `I`. Cost: none.
    pub fn inputs(&self) -> usize {
        self.inputs
    }

    /// The time step `h` (s). Cost: none.
    pub fn time_step(&self) -> f64 {
        self.time_step
    }

    /// `Φ` (`S×S`) as a `nalgebra` matrix. Cost: a copy.
    pub fn phi_matrix(&self) -> DMatrix<f64> {
        DMatrix::from_row_slice(self.states(), self.states(), &self.phi)
    }

    /// `Γ₀` (`S×I`) as a `nalgebra` matrix. Cost: a copy.
    pub fn gamma0_matrix(&self) -> DMatrix<f64> {
        DMatrix::from_row_slice(self.states(), self.inputs, &self.gamma0)
    }

    /// `Γ₁` (`S×I`) as a `nalgebra` matrix. Cost: a copy.
    pub fn gamma1_matrix(&self) -> DMatrix<f64> {
        DMatrix::from_row_slice(self.states(), self.inputs, &self.gamma1)
    }

    /// The output matrices of `y = Y_u u + Y_v v + Y_a a + Y_w w`
    /// ([`StateSpace::outputs`](super::StateSpace::outputs)): `yu`, `yv`, `ya` are `O×N`,
    /// `yw` is `O×I`.
    ///
    /// Errors: [`Error::StateSizeMismatch`] (shapes), [`Error::NonFiniteInput`] (a
    /// non-finite weight), [`Error::OperatorOverflow`]. Cost: `3O·N·S + O·N·I` flops.
    pub fn outputs(
        &self,
        yu: &DMatrix<f64>,
        yv: &DMatrix<f64>,
        ya: &DMatrix<f64>,
        yw: &DMatrix<f64>,
    ) -> Result<DynMeasurement, Error> {
        let (n, s, ni, o) = (self.n, self.states(), self.inputs, yu.nrows());
        if [yu, yv, ya].iter().any(|y| y.shape() != (o, n)) || yw.shape() != (o, ni) {
            return Err(Error::StateSizeMismatch);
        }
        let (mut h, mut d) = (vec![0.0; o * s], vec![0.0; o * ni]);
        let (mut th, mut td) = (vec![0.0; o * s], vec![0.0; o * ni]);
        outputs_flat(
            [&rows(yu), &rows(yv), &rows(ya), &rows(yw)],
            [&self.dof_u, &self.dof_v, &self.dof_a, &self.dof_a_input],
            [n, s, ni, o],
            [&mut h, &mut d],
            [&mut th, &mut td],
        )?;
        Ok(DynMeasurement { outputs: o, h, d })
    }

    /// The absolute accelerations (m/s²) of the DOFs `dofs` under base excitation, input
    /// `input` the ground acceleration ([`Outputs::absolute_accelerations`](super::Outputs::absolute_accelerations)
    /// of [`Outputs::select`](super::Outputs::select)): `Y_a` the selected rows of the
    /// identity, `Y_w` their sums. A DOF index `≥ N` gives a zero row, an `input ≥ I` no
    /// ground term.
    ///
    /// Errors and cost: as [`DynStateSpace::outputs`].
    pub fn absolute_accelerations(
        &self,
        dofs: &[usize],
        input: usize,
    ) -> Result<DynMeasurement, Error> {
        let (n, o) = (self.n, dofs.len());
        let zero = DMatrix::zeros(o, n);
        let ya = DMatrix::from_fn(o, n, |r, j| if dofs[r] == j { 1.0 } else { 0.0 });
        let yw = DMatrix::from_fn(o, self.inputs, |r, j| {
            // `Y ι`: the row's sum, in the order of the columns.
            if j == input {
                (0..n).fold(0.0, |s, c| s + ya[(r, c)] * 1.0)
            } else {
                0.0
            }
        });
        self.outputs(&zero, &zero, &ya, &yw)
    }

    /// The process-noise covariance `Q = (Γ₀ + Γ₁) Q_w (Γ₀ + Γ₁)ᵀ` (`S×S`) of a white
    /// input noise of covariance `qw` (`I×I`, input units squared) held over each step
    /// ([`StateSpace::input_noise`](super::StateSpace::input_noise)).
    ///
    /// Errors: [`Error::StateSizeMismatch`] (`qw` not `I×I`). Cost: `S²·I + S·I²` flops.
    pub fn input_noise(&self, qw: &DMatrix<f64>) -> Result<DMatrix<f64>, Error> {
        let (s, ni) = (self.states(), self.inputs);
        if qw.shape() != (ni, ni) {
            return Err(Error::StateSizeMismatch);
        }
        let mut q = vec![0.0; s * s];
        let (mut g, mut gq) = (vec![0.0; s * ni], vec![0.0; s * ni]);
        input_noise_flat(
            [&self.gamma0, &self.gamma1],
            &rows(qw),
            [s, ni],
            &mut q,
            [&mut g, &mut gq],
        );
        Ok(DMatrix::from_row_slice(s, s, &q))
    }
}

/// The steady-state Kalman solution of a [`DynStateSpace`] and its [`DynMeasurement`]
/// ([`SteadyState`](super::SteadyState) at a run-time size; feature `std`): the a-priori
/// covariance `P` (units of `x` squared) and the gain `L = P Hᵀ (H P Hᵀ + R)⁻¹` (`S×O`).
/// The same doubling, verification and refinement, bit for bit.
#[derive(Clone, Debug, PartialEq)]
pub struct DynSteadyState {
    states: usize,
    outputs: usize,
    covariance: Vec<f64>,
    gain: Vec<f64>,
    iterations: u32,
}

impl DynSteadyState {
    /// Solve the DARE for the model's `Φ` and the measurement's `H` with process noise `q`
    /// (`S×S`, symmetric positive semidefinite) and measurement noise `r` (`O×O`,
    /// symmetric positive definite): [`SteadyState::new`](super::SteadyState::new) at a
    /// run-time size.
    ///
    /// Errors: [`Error::StateSizeMismatch`] (shapes), then as
    /// [`SteadyState::from_parts`](super::SteadyState::from_parts):
    /// [`Error::InvalidCovariance`], [`Error::NonFiniteInput`],
    /// [`Error::RiccatiNotConverged`], [`Error::OperatorOverflow`].
    ///
    /// Cost: about `10 S³` flops a doubling iteration (typically 10–25), then the
    /// verification (`6 S³` and `3 S³` a squaring of the closed loop); `16 S² + O(S·O)`
    /// `f64` of temporaries on the heap.
    pub fn new(
        model: &DynStateSpace,
        meas: &DynMeasurement,
        q: &DMatrix<f64>,
        r: &DMatrix<f64>,
    ) -> Result<Self, Error> {
        Self::new_with_stop(model, meas, q, r, &mut || false)
    }

    /// [`new`](Self::new), looking at `stop` before each piece of the solve — a doubling
    /// iteration (`10 S³` flops), a verification pass's residual (`4 S³`) or a Stein
    /// squaring (`3 S³`): at `S = 300` (150 storeys) about 0.1 s apart on one core of the
    /// developers' host — and ending with
    /// [`Error::InvalidParameter`]`(`[`Param::Cancelled`]`)` once
    /// it returns `true` (e.g. a Ctrl-C flag; a caller's time budget). The same pieces in
    /// the same order as `new`: the same gain bit for bit when `stop` never fires.
    ///
    /// Errors and cost: as [`new`](Self::new), plus `Cancelled`.
    pub fn new_with_stop(
        model: &DynStateSpace,
        meas: &DynMeasurement,
        q: &DMatrix<f64>,
        r: &DMatrix<f64>,
        stop: &mut dyn FnMut() -> bool,
    ) -> Result<Self, Error> {
        let [n, _, o] = noise_shapes(model, meas, q, r)?;
        let (q, r) = (rows(q), rows(r));
        let sn = Sensors {
            h: &meas.h,
            r: &r,
            cross: None,
            o,
        };
        let sq = || vec![0.0f64; n * n];
        let mut m: [Vec<f64>; 8] = core::array::from_fn(|_| sq());
        let (mut d, mut lu, mut perm, mut sc) = (vec![0.0; n], sq(), vec![0usize; n], vec![0.0; n]);
        let [m0, m1, m2, m3, m4, m5, m6, m7] = &mut m;
        let mut s = Scratch {
            m: [m0, m1, m2, m3, m4, m5, m6, m7],
            d: &mut d,
            lu: LuFlat {
                lu: &mut lu,
                perm: &mut perm,
                scales: &mut sc,
            },
        };
        let (mut on0, mut on1) = (vec![0.0; o * n], vec![0.0; o * n]);
        let (mut oo0, mut oo1, mut oo2) = (vec![0.0; o * o], vec![0.0; o * o], vec![0.0; o * o]);
        let (mut no0, mut no1) = (vec![0.0; n * o], vec![0.0; n * o]);
        let (mut luo, mut permo, mut sco) = (vec![0.0; o * o], vec![0usize; o], vec![0.0; o]);
        let mut t = OutScratch {
            on: [&mut on0, &mut on1],
            oo: [&mut oo0, &mut oo1, &mut oo2],
            no: [&mut no0, &mut no1],
            lu: LuFlat {
                lu: &mut luo,
                perm: &mut permo,
                scales: &mut sco,
            },
        };
        check_noise(&q, n, &sn, &mut s, &mut t)?;
        let (mut a, mut g, mut x) = (sq(), sq(), sq());
        plain_start(&model.phi, &q, n, &sn, [&mut a, &mut g, &mut x], &mut t);
        let (mut covariance, mut gain) = (sq(), vec![0.0; n * o]);
        let (mut res, mut bound, mut delta, mut best) = (sq(), sq(), sq(), vec![0.0; n * o]);
        let mut parts = RiccatiParts {
            phi: &model.phi,
            q: &q,
            n,
            sn: &sn,
            q_cross: false,
            start: [&mut a, &mut g, &mut x],
            out: (&mut covariance, &mut gain),
            work: [&mut res, &mut bound, &mut delta, &mut best],
            s: &mut s,
            t: &mut t,
        };
        let mut run = RiccatiRun::new();
        let iterations = loop {
            if stop() {
                return Err(Error::InvalidParameter(Param::Cancelled));
            }
            if let Some(r) = run.advance(&mut parts) {
                break r?;
            }
        };
        Ok(Self {
            states: n,
            outputs: o,
            covariance,
            gain,
            iterations,
        })
    }

    /// `L` (`S×O`) as a `nalgebra` matrix. Cost: a copy.
    pub fn gain_matrix(&self) -> DMatrix<f64> {
        DMatrix::from_row_slice(self.states, self.outputs, &self.gain)
    }

    /// `P` (`S×S`) as a `nalgebra` matrix. Cost: a copy.
    pub fn covariance_matrix(&self) -> DMatrix<f64> {
        DMatrix::from_row_slice(self.states, self.states, &self.covariance)
    }

    /// `L` (`S×O`), row-major. Cost: none.
    pub fn gain(&self) -> &[f64] {
        &self.gain
    }

    /// Doubling iterations taken (`≤` [`RICCATI_MAX_ITERATIONS`](super::RICCATI_MAX_ITERATIONS)).
    /// Cost: none.
    pub fn iterations(&self) -> u32 {
        self.iterations
    }
}

/// The fixed-gain observer of [`Observer`](super::Observer) with its sizes chosen at run
/// time (feature `std`): `x̂⁻ = Φ x̂ + Γ₀ w_{n−1} + Γ₁ w_n`, `x̂ = x̂⁻ + L (y_n − H x̂⁻ −
/// D w_n)`, `T` = `f32` or `f64` (operators computed in `f64`, rounded once to `T`).
///
/// Same checks and the same per-row arithmetic as `Observer<T, S, I, O>`: bit-identical
/// estimates at every size both serve. A NaN measurement skips the correction (counted);
/// a failed [`DynObserver::try_step`] leaves the estimate unchanged.
///
/// Size: `S² + 2S·I + 2S·O + O·I` values of `T` on the heap. A step costs
/// `S² + 2S·I + 2S·O + O·I` multiply-adds and allocates nothing (the work space lives in
/// the [`DynEstimate`]).
///
/// ```
/// use aemstep::nalgebra::DMatrix;
/// use aemstep::observer::{DynObserver, DynStateSpace, DynSteadyState};
///
/// // A 23-storey shear building (kg, N/m, N·s/m), h = 0.02 s, ground acceleration in,
/// // absolute accelerations of floors 5 and 23 measured.
/// let n = 23;
/// let m = DMatrix::<f64>::identity(n, n) * 1.0e5;
/// let k = DMatrix::from_fn(n, n, |i, j| match (i.abs_diff(j), i + 1 == n && j == i) {
///     (0, true) => 2.0e8,
///     (0, false) => 4.0e8,
///     (1, _) => -2.0e8,
///     _ => 0.0,
/// });
/// let c = &k * 1e-3 + &m * 0.2;
/// let b = DMatrix::from_element(n, 1, -1.0e5);
/// let ss = DynStateSpace::aem(&m, &c, &k, &b, 0.02)?;
/// let meas = ss.absolute_accelerations(&[4, 22], 0)?;
/// let q = ss.input_noise(&DMatrix::from_element(1, 1, 1.0))?
///     + DMatrix::identity(2 * n, 2 * n) * 1e-12;
/// let r = DMatrix::identity(2, 2) * 0.01;
/// let kf = DynSteadyState::new(&ss, &meas, &q, &r)?;
/// let obs = DynObserver::<f64>::new(&ss, &meas, &kf.gain_matrix())?;
/// let mut e = obs.start_at_rest(&[0.0])?;
/// obs.try_step(&mut e, &[0.1], &[0.05, 0.02])?;
/// obs.try_step(&mut e, &[0.1], &[f64::NAN, 0.0])?; // a missing sample
/// assert_eq!((e.steps(), e.missing()), (2, 1));
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct DynObserver<T> {
    states: usize,
    inputs: usize,
    outputs: usize,
    phi: Vec<T>,
    gamma0: Vec<T>,
    gamma1: Vec<T>,
    h: Vec<T>,
    d: Vec<T>,
    gain: Vec<T>,
    time_step: T,
}

/// The estimate of a [`DynObserver`]: `x̂` (`S` values, `[u; v]`), the last input, the
/// step and missing-sample counts, and the step's work space (allocated once, by
/// [`DynObserver::start`]). Two estimates are equal when their `x̂`, inputs and counts are.
#[derive(Clone, Debug)]
pub struct DynEstimate<T> {
    x: Vec<T>,
    w: Vec<T>,
    n: u64,
    missing: u64,
    /// The prediction `x̂⁻` (`S`), the innovation (`O`) and the new estimate (`S`).
    xp: Vec<T>,
    innov: Vec<T>,
    next: Vec<T>,
}

impl<T: PartialEq> PartialEq for DynEstimate<T> {
    fn eq(&self, o: &Self) -> bool {
        (&self.x, &self.w, self.n, self.missing) == (&o.x, &o.w, o.n, o.missing)
    }
}

impl<T: Real> DynEstimate<T> {
    /// The estimate `x̂` (`S` values: `u` (m) then `v` (m/s) for a building). Cost: none.
    pub fn x(&self) -> &[T] {
        &self.x
    }

    /// The last input `w_{n−1}`. Cost: none.
    pub fn last_input(&self) -> &[T] {
        &self.w
    }

    /// Steps taken since the start. Cost: none.
    pub fn steps(&self) -> u64 {
        self.n
    }

    /// Steps whose measurement was missing (a non-finite entry): predicted, not corrected.
    /// Cost: none.
    pub fn missing(&self) -> u64 {
        self.missing
    }

    /// The innovation `ν = y_n − H x̂⁻ − D w_n` of the last step attempted (output units;
    /// non-finite where the measurement was missing; work space, so a refused step may
    /// have written it). Cost: none.
    pub fn innovation(&self) -> &[T] {
        &self.innov
    }
}

impl<T: Real> DynObserver<T> {
    /// The observer of `model` measuring `meas` with gain `gain` (`S×O`, `f64`, e.g.
    /// [`DynSteadyState::gain_matrix`], or zero for the open loop); rounded once to `T`.
    ///
    /// Errors: [`Error::StateSizeMismatch`] (shapes), then as
    /// [`Observer::new`](super::Observer::new): [`Error::NonFiniteInput`],
    /// [`Error::InvalidTimeStep`], [`Error::OperatorOverflow`]. Cost: `O(S²)`.
    pub fn new(
        model: &DynStateSpace,
        meas: &DynMeasurement,
        gain: &DMatrix<f64>,
    ) -> Result<Self, Error> {
        let (s, i, o) = (model.states(), model.inputs, meas.outputs);
        if o == 0 || gain.shape() != (s, o) || meas.h.len() != o * s || meas.d.len() != o * i {
            return Err(Error::StateSizeMismatch);
        }
        let gain = rows(gain);
        let parts = [
            &model.phi,
            &model.gamma0,
            &model.gamma1,
            &meas.h,
            &meas.d,
            &gain,
        ];
        check_parts_flat(parts.map(|a| a.as_slice()), model.time_step, T::MAX)?;
        let round = |a: &Vec<f64>| a.iter().map(|&x| T::from_f64_rounded(x)).collect();
        let [phi, gamma0, gamma1, h, d, gain] = parts.map(round);
        let (states, inputs, outputs) = (s, i, o);
        let time_step = T::from_f64_rounded(model.time_step);
        Ok(Self {
            states,
            inputs,
            outputs,
            phi,
            gamma0,
            gamma1,
            h,
            d,
            gain,
            time_step,
        })
    }

    /// States `S`. Cost: none.
    pub fn states(&self) -> usize {
        self.states
    }

    /// The time step `h` (s). Cost: none.
    pub fn time_step(&self) -> T {
        self.time_step
    }

    /// The estimate at `t = 0`: `x̂_0 = x0` (`S` values), input `w0` (`I` values).
    ///
    /// Errors: [`Error::StateSizeMismatch`] (lengths), [`Error::NonFiniteInput`].
    /// Cost: allocates the estimate and its work space (`3S + O + I` values).
    pub fn start(&self, x0: &[T], w0: &[T]) -> Result<DynEstimate<T>, Error> {
        if x0.len() != self.states || w0.len() != self.inputs {
            return Err(Error::StateSizeMismatch);
        }
        if !x0.iter().chain(w0).all(|v| v.is_finite()) {
            return Err(Error::NonFiniteInput);
        }
        Ok(DynEstimate {
            x: x0.to_vec(),
            w: w0.to_vec(),
            n: 0,
            missing: 0,
            xp: vec![T::zero(); self.states],
            innov: vec![T::zero(); self.outputs],
            next: vec![T::zero(); self.states],
        })
    }

    /// [`DynObserver::start`] at rest, `x̂_0 = 0`. Errors: as [`DynObserver::start`].
    pub fn start_at_rest(&self, w0: &[T]) -> Result<DynEstimate<T>, Error> {
        self.start(&vec![T::zero(); self.states], w0)
    }

    /// One checked step ([`Observer::try_step`](super::Observer::try_step)): predict with
    /// the input `w` (`w_n`, `I` values), correct with the measurement `y` (`O` values;
    /// any non-finite entry — NaN, a missing sample — skips the correction and is
    /// counted). The input must be finite and the new estimate finite, else `e` is left
    /// unchanged.
    ///
    /// Errors: [`Error::StateSizeMismatch`] (lengths, or an estimate of another observer),
    /// [`Error::NonFiniteInput`], [`Error::StepCountOverflow`], [`Error::NonFiniteState`].
    /// Cost: `S² + 2S·I + 2S·O + O·I` multiply-adds and a scan; no allocation.
    pub fn try_step(&self, e: &mut DynEstimate<T>, w: &[T], y: &[T]) -> Result<(), Error> {
        let (s, ni, o) = (self.states, self.inputs, self.outputs);
        if w.len() != ni || y.len() != o || e.x.len() != s || e.xp.len() != s {
            return Err(Error::StateSizeMismatch);
        }
        if e.w.len() != ni || e.innov.len() != o || e.next.len() != s {
            return Err(Error::StateSizeMismatch);
        }
        if !w.iter().all(|v| v.is_finite()) {
            return Err(Error::NonFiniteInput);
        }
        let measured = y.iter().all(|v| v.is_finite());
        let Some((n, missing)) = next_counts(e.n, e.missing, measured) else {
            return Err(Error::StepCountOverflow);
        };
        for (((xp, phi), g0), g1) in
            e.xp.iter_mut()
                .zip(self.phi.chunks_exact(s))
                .zip(self.gamma0.chunks_exact(ni))
                .zip(self.gamma1.chunks_exact(ni))
        {
            *xp = predict_row(phi, g0, g1, &e.x, &e.w, w);
        }
        for (((v, yo), d), h) in e
            .innov
            .iter_mut()
            .zip(y)
            .zip(self.d.chunks_exact(ni))
            .zip(self.h.chunks_exact(s))
        {
            *v = innovation_row(*yo, d, h, w, &e.xp);
        }
        if measured {
            for ((x, xp), l) in e.next.iter_mut().zip(&e.xp).zip(self.gain.chunks_exact(o)) {
                *x = correct_row(*xp, l, &e.innov);
            }
        } else {
            e.next.copy_from_slice(&e.xp);
        }
        if !e.next.iter().all(|v| v.is_finite()) {
            return Err(Error::NonFiniteState);
        }
        core::mem::swap(&mut e.x, &mut e.next);
        e.w.copy_from_slice(w);
        e.n = n;
        e.missing = missing;
        Ok(())
    }
}

/// `[S, I, O]` of a filter of `model` measuring `meas` with noises `q` (`S×S`) and `r`
/// (`O×O`). Errors: [`Error::StateSizeMismatch`] (no sensor, or a shape that differs).
fn noise_shapes(
    model: &DynStateSpace,
    meas: &DynMeasurement,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
) -> Result<[usize; 3], Error> {
    let (n, o) = (model.states(), meas.outputs);
    if q.shape() != (n, n) || r.shape() != (o, o) || meas.h.len() != o * n || o == 0 {
        return Err(Error::StateSizeMismatch);
    }
    Ok([n, model.inputs, o])
}

/// A row-major `rows×cols` `f64` slice as a column-major `T` vector, each entry rounded
/// once (as [`matrix_t`](crate::linalg::matrix_t) stores the const-generic filters).
fn column_major<T: Real>(a: &[f64], rows: usize, cols: usize) -> Vec<T> {
    (0..rows * cols)
        .map(|k| T::from_f64_rounded(a[(k % rows) * cols + k / rows]))
        .collect()
}

/// The full Kalman filter ([`Kalman`](super::Kalman)) at a run-time size (feature
/// `std`): the estimate and its covariance propagated every step, Joseph form,
///
/// ```text
/// x̂⁻ = Φ x̂ + Γ₀ w_{n−1} + Γ₁ w_n           P⁻ = Φ P Φᵀ + Q
/// K = P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹                 x̂ = x̂⁻ + K (y − H x̂⁻ − D w)
/// P = (I − K H) P⁻ (I − K H)ᵀ + K R Kᵀ
/// ```
///
/// The step is the const-generic filter's own code (`observer::kalman_flat`, called by
/// [`Kalman`](super::Kalman) with its arrays): at every size both serve, estimates and
/// covariances are bit-identical (`tests/runtime_size_observer.rs`). Any number of sensors
/// `O ≥ 1`. Not here: the cross covariance of [`Kalman::with_cross`](super::Kalman::with_cross).
///
/// Cost of a step: about `3S³ + 3S²·O + 2S·O² + O³/6` multiply-adds, no allocation (the
/// work space lives in the [`DynKalmanState`]). Size: `S² + 2S·I + O·(S + I) + O²` values
/// of `T` on the heap.
///
/// ```
/// use aemstep::nalgebra::DMatrix;
/// use aemstep::observer::{DynKalman, DynStateSpace};
/// let (m, k) = (DMatrix::identity(2, 2), DMatrix::from_row_slice(2, 2, &[2.0, -1.0, -1.0, 1.0]));
/// let ss = DynStateSpace::aem(&m, &(&k * 0.01), &k, &DMatrix::from_element(2, 1, -1.0), 0.02)?;
/// let meas = ss.absolute_accelerations(&[1], 0)?;
/// let q = DMatrix::identity(4, 4) * 1e-6;
/// let kf = DynKalman::<f64>::new(&ss, &meas, &q, &DMatrix::identity(1, 1))?;
/// let mut s = kf.start(&[0.0; 4], &DMatrix::zeros(4, 4), &[0.0])?;
/// kf.try_step(&mut s, &[0.1], &[0.05])?;
/// kf.try_step(&mut s, &[0.1], &[f64::NAN])?; // a missing sample
/// assert_eq!((s.estimate().steps(), s.estimate().missing()), (2, 1));
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct DynKalman<T> {
    dims: [usize; 3],
    /// Column-major `Φ`, `Γ₀`, `Γ₁`, `H`, `D`, `Q`, `R`.
    parts: [Vec<T>; 7],
}

/// The state of a [`DynKalman`]: the [`DynEstimate`] (`x̂`, the last input, the step and
/// missing-sample counts, the innovation), its a-posteriori error covariance `P` (`S×S`),
/// and the step's work space (allocated once, by [`DynKalman::start`]).
#[derive(Clone, Debug)]
pub struct DynKalmanState<T> {
    estimate: DynEstimate<T>,
    p: Vec<T>,
    /// The new `P`, then the flat step's work space (`KalmanWork`'s `S×S`, `S×O`, `O×S`,
    /// `O×O` and vector parts not in the estimate).
    p_next: Vec<T>,
    work: [Vec<T>; 9],
}

impl<T: Real> DynKalmanState<T> {
    /// The estimate: `x̂` (`S` values: `u` (m) then `v` (m/s) for a building), the last
    /// input, the counts and the last innovation. Cost: none.
    pub fn estimate(&self) -> &DynEstimate<T> {
        &self.estimate
    }

    /// The a-posteriori error covariance `P` (`S×S`, units of `x` squared). Cost: a copy.
    pub fn covariance_matrix(&self) -> DMatrix<T> {
        let s = self.estimate.x.len();
        DMatrix::from_column_slice(s, s, &self.p)
    }
}

impl<T: Real> DynKalman<T> {
    /// The filter of `model` measuring `meas`, process noise `q` (`S×S`, symmetric
    /// positive semidefinite), measurement noise `r` (`O×O`, symmetric positive
    /// definite), in `f64`, rounded once to `T`: [`Kalman::new`](super::Kalman::new) at a
    /// run-time size.
    ///
    /// Errors: [`Error::StateSizeMismatch`] (shapes), then as `Kalman::new`:
    /// [`Error::InvalidCovariance`], [`Error::NonFiniteInput`],
    /// [`Error::OperatorOverflow`]. Cost: `O(S³)` (the covariance checks).
    pub fn new(
        model: &DynStateSpace,
        meas: &DynMeasurement,
        q: &DMatrix<f64>,
        r: &DMatrix<f64>,
    ) -> Result<DynKalman<T>, Error> {
        let [s, ni, o] = noise_shapes(model, meas, q, r)?;
        if meas.d.len() != o * ni {
            return Err(Error::StateSizeMismatch);
        }
        let (q, r) = (rows(q), rows(r));
        let sq = |n: usize| vec![0.0f64; n * n];
        let (mut b, mut l) = (sq(s), sq(s));
        let (mut lo, mut luo, mut permo, mut sco) = (sq(o), sq(o), vec![0usize; o], vec![0.0; o]);
        let mut lu = LuFlat {
            lu: &mut luo,
            perm: &mut permo,
            scales: &mut sco,
        };
        if !(is_covariance_flat(&q, s, &mut b, &mut l) && definite_lu_flat(&r, o, &mut lo, &mut lu))
        {
            return Err(Error::InvalidCovariance);
        }
        if !(all_finite_flat(&meas.h) && all_finite_flat(&meas.d)) {
            return Err(Error::NonFiniteInput);
        }
        let parts = [
            (&model.phi, s, s),
            (&model.gamma0, s, ni),
            (&model.gamma1, s, ni),
            (&meas.h, o, s),
            (&meas.d, o, ni),
            (&q, s, s),
            (&r, o, o),
        ];
        if !parts.iter().all(|(a, ..)| all_fit(a, T::MAX)) {
            return Err(Error::OperatorOverflow);
        }
        Ok(Self {
            dims: [s, ni, o],
            parts: parts.map(|(a, rows, cols)| column_major(a, rows, cols)),
        })
    }

    /// States `S`. Cost: none.
    pub fn states(&self) -> usize {
        self.dims[0]
    }

    /// The filter at `t = 0`: estimate `x0` (`S` values), its covariance `p0` (`S×S`,
    /// symmetric positive semidefinite), input `w0` (`I` values).
    ///
    /// Errors: [`Error::StateSizeMismatch`] (lengths), [`Error::NonFiniteInput`],
    /// [`Error::InvalidCovariance`]. Cost: `O(S³)`; allocates the state and its work space
    /// (`5S² + 2S·O + 2O² + 5S + 2O + I` values).
    pub fn start(&self, x0: &[T], p0: &DMatrix<T>, w0: &[T]) -> Result<DynKalmanState<T>, Error> {
        let [s, ni, o] = self.dims;
        if x0.len() != s || w0.len() != ni || p0.shape() != (s, s) {
            return Err(Error::StateSizeMismatch);
        }
        if !x0.iter().chain(w0).all(|v| v.is_finite()) {
            return Err(Error::NonFiniteInput);
        }
        let pr: Vec<f64> = p0.transpose().iter().map(|v| v.as_f64()).collect();
        let (mut b, mut l) = (vec![0.0; s * s], vec![0.0; s * s]);
        if !is_covariance_flat(&pr, s, &mut b, &mut l) {
            return Err(Error::InvalidCovariance);
        }
        let z = |n: usize| vec![T::zero(); n];
        Ok(DynKalmanState {
            estimate: DynEstimate {
                x: x0.to_vec(),
                w: w0.to_vec(),
                n: 0,
                missing: 0,
                xp: z(s),
                innov: z(o),
                next: z(s),
            },
            p: p0.as_slice().to_vec(),
            p_next: z(s * s),
            work: [
                z(s * s),
                z(s * s),
                z(s * s),
                z(s * o),
                z(o * s),
                z(o * o),
                z(o * o),
                z(s),
                z(o),
            ],
        })
    }

    /// One filter step ([`Kalman::try_step`](super::Kalman::try_step)) with input `w`
    /// (`w_n`, `I` values) and measurement `y` (`O` values; a non-finite entry: missing,
    /// predict only, counted).
    ///
    /// Errors, `st` unchanged (but its work space): [`Error::StateSizeMismatch`] (lengths,
    /// or a state of another filter), [`Error::NonFiniteInput`] (`w`),
    /// [`Error::InvalidCovariance`] (`H P⁻ Hᵀ + R` not positive definite to working
    /// precision), [`Error::StepCountOverflow`], [`Error::NonFiniteState`]. No allocation;
    /// cost in the type docs.
    pub fn try_step(&self, st: &mut DynKalmanState<T>, w: &[T], y: &[T]) -> Result<(), Error> {
        let [s, ni, o] = self.dims;
        let sizes = [s * s, s * s, s * s, s * o, o * s, o * o, o * o, s, o];
        let e = &mut st.estimate;
        let fits = st.work.iter().zip(sizes).all(|(v, n)| v.len() == n)
            && (e.x.len(), e.xp.len(), e.next.len(), e.w.len()) == (s, s, s, ni)
            && (e.innov.len(), st.p.len(), st.p_next.len()) == (o, s * s, s * s);
        if !fits || w.len() != ni || y.len() != o {
            return Err(Error::StateSizeMismatch);
        }
        if !w.iter().all(|v| v.is_finite()) {
            return Err(Error::NonFiniteInput);
        }
        let [phi, gamma0, gamma1, h, d, q, r] = &self.parts;
        let model = KalmanModel {
            phi,
            gamma: [gamma0, gamma1],
            h,
            d,
            q,
            r,
            cross: None,
            dims: self.dims,
        };
        let [pm, ikh, ss, so, xt, si, oo, vs, vo] = &mut st.work;
        let mut wk = KalmanWork {
            pm,
            ikh,
            ss,
            so,
            xt,
            si,
            oo,
            xp: &mut e.xp,
            vs,
            innov: &mut e.innov,
            vo,
        };
        let (xn, pn) = (&mut e.next, &mut st.p_next);
        let present = kalman_step_flat(&model, &mut wk, (&e.x, &st.p, &e.w), (w, y), (xn, pn))?;
        let (n, missing) = next_counts(e.n, e.missing, present).ok_or(Error::StepCountOverflow)?;
        if !xn.iter().chain(pn.iter()).all(|v| v.is_finite()) {
            return Err(Error::NonFiniteState);
        }
        core::mem::swap(&mut e.x, xn);
        core::mem::swap(&mut st.p, pn);
        e.w.copy_from_slice(w);
        (e.n, e.missing) = (n, missing);
        Ok(())
    }
}

/// Row `i` of the fixed-gain observer's prediction, `Σ_j Γ₀[i][j] w_{n−1}[j] + Γ₁[i][j]
/// w_n[j]` then `+ Σ_j Φ[i][j] x[j]`, summed from `−0` (`−0 + x = x` exactly, so the
/// compiler drops the add): the one row of [`DynObserver`], the same sums in the
/// same order as [`Observer`](super::Observer)'s step on its arrays. Cost: `S + 2I` multiply-adds.
#[inline(always)]
pub(crate) fn predict_row<T: Real>(
    phi: &[T],
    gamma0: &[T],
    gamma1: &[T],
    x: &[T],
    w_prev: &[T],
    w: &[T],
) -> T {
    let mut s = -T::zero();
    for ((g0, g1), (wp, wn)) in gamma0.iter().zip(gamma1).zip(w_prev.iter().zip(w)) {
        s += *g0 * *wp;
        s += *g1 * *wn;
    }
    for (p, xj) in phi.iter().zip(x) {
        s += *p * *xj;
    }
    s
}

/// Innovation `o`: `y_o − Σ_j D[o][j] w[j] − Σ_j H[o][j] x̂⁻[j]` (the observers' one row).
/// Cost: `I + S` multiply-adds.
#[inline(always)]
pub(crate) fn innovation_row<T: Real>(y: T, d: &[T], h: &[T], w: &[T], xp: &[T]) -> T {
    let mut s = y;
    for (dj, wj) in d.iter().zip(w) {
        s -= *dj * *wj;
    }
    for (hj, xj) in h.iter().zip(xp) {
        s -= *hj * *xj;
    }
    s
}

/// Corrected state `i`: `x̂⁻[i] + Σ_o L[i][o] ν[o]` (the observers' one row). Cost: `O`
/// multiply-adds.
#[inline(always)]
pub(crate) fn correct_row<T: Real>(xp: T, gain: &[T], innov: &[T]) -> T {
    let mut s = xp;
    for (l, v) in gain.iter().zip(innov) {
        s += *l * *v;
    }
    s
}
