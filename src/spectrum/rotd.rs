//! RotD50 and RotD100: the orientation-independent spectra of two horizontal components.

use super::bank::{Bank, Response};
use super::finite;
use super::operators::cos_sin;
use crate::{Error, Real};

/// The rotation angles of a RotD computation: `K` angles `θ_j = jπ/K`, `j = 0 … K−1`
/// (`K = 180` is the usual 1° increment). Build with [`RotD::new`] (run time, generic)
/// or the `const fn` [`RotD::new_f32`] / [`RotD::new_f64`] (in a `static`), bit-identical.
///
/// The response of an oscillator to the two components rotated by `θ` is
/// `u_θ(t) = u_x(t) cos θ + u_y(t) sin θ` (linearity), so one pass over the record with
/// both components gives the peak `max_t |u_θ|` for every angle. RotD100 is the largest
/// of the `K` peaks, RotD50 their median (Boore 2010); both are spectral displacements
/// (m), [`Bank::psa`] turns them into pseudo-accelerations.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RotD<T, const K: usize> {
    cos: [T; K],
    sin: [T; K],
}

/// The running two-component response: each component's [`Response`] and the peak
/// rotated displacement of every oscillator at every angle. Size: `2·(5P + 1) + K·P`
/// values of `T`.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RotDResponse<T, const P: usize, const K: usize> {
    x: Response<T, P>,
    y: Response<T, P>,
    peak: [[T; K]; P],
}

impl<T: Real, const K: usize> RotD<T, K> {
    /// The `K` angles `jπ/K` (run time, either scalar; `K ≥ 1`, cost `40K` flops once):
    /// the `f64` cosines and sines rounded once to `T`, bit-identical to the `const fn`
    /// [`RotD::new_f32`] / [`RotD::new_f64`].
    pub fn new() -> Self {
        let r = RotD::<f64, K>::new_f64();
        RotD {
            cos: r.cos.map(T::from_f64_rounded),
            sin: r.sin.map(T::from_f64_rounded),
        }
    }
}

impl<T: Real, const K: usize> Default for RotD<T, K> {
    fn default() -> Self {
        Self::new()
    }
}

/// The `const fn` constructors of `RotD<f32, K>` and `RotD<f64, K>` (the scalar in the
/// name: a typed `static` needs no turbofish).
macro_rules! rotd_ctor {
    ($t:ident, $new:ident) => {
        impl<const K: usize> RotD<$t, K> {
            /// `const fn` twin of [`RotD::new`]: the `K` angles `jπ/K` (`K ≥ 1`, cost
            /// `40K` flops once).
            pub const fn $new() -> Self {
                let mut r = RotD {
                    cos: [0.0; K],
                    sin: [0.0; K],
                };
                let mut j = 0;
                while j < K {
                    let (c, s) = cos_sin(core::f64::consts::PI * j as f64 / K as f64);
                    r.cos[j] = c as $t;
                    r.sin[j] = s as $t;
                    j += 1;
                }
                r
            }

            /// Both components at rest, before their first samples (cost: zeroing).
            pub const fn at_rest<const P: usize>(
                &self,
                bank: &Bank<$t, P>,
            ) -> RotDResponse<$t, P, K> {
                RotDResponse {
                    x: bank.at_rest(),
                    y: bank.at_rest(),
                    peak: [[0.0; K]; P],
                }
            }
        }
    };
}
rotd_ctor!(f32, new_f32);
rotd_ctor!(f64, new_f64);

#[inline(always)]
fn abs<T: Real>(x: T) -> T {
    if x < T::from_f64_rounded(0.0) { -x } else { x }
}

impl<T: Real, const K: usize> RotD<T, K> {
    /// Feed the next samples of the two horizontal components (`ax`, `ay`, same unit and
    /// same sample interval `h`). Each component behaves as in [`Bank::step`] (unchecked: a
    /// non-finite sample is skipped, counted and held, whatever the bank's
    /// [`NonFinite`](super::NonFinite) policy); each component's own peaks are kept too
    /// ([`RotDResponse::x`], [`RotDResponse::y`]).
    ///
    /// Cost: `Σ_p n_p` sub-steps of both components (16 multiply-adds) plus `K`
    /// multiply-adds, absolute values and comparisons each; no allocation, no panic.
    pub fn step<const P: usize>(
        &self,
        bank: &Bank<T, P>,
        r: &mut RotDResponse<T, P, K>,
        ax: T,
        ay: T,
    ) {
        let first = r.x.samples == 0;
        let (ax1, ay1) = (self.take(&mut r.x, ax), self.take(&mut r.y, ay));
        if !first {
            let (ax0, ay0) = (r.x.last, r.y.last);
            self.advance(bank, r, ax0, ax1, ay0, ay1);
        }
        r.x.last = ax1;
        r.y.last = ay1;
        r.x.samples += 1;
        r.y.samples += 1;
    }

    /// [`RotD::step`], checked: the samples are taken on a copy of `r`, committed only if
    /// both components' states and peaks and every rotated peak are finite
    /// ([`RotDResponse::is_finite`]). A non-finite sample of either component follows the
    /// bank's [`NonFinite`](super::NonFinite) policy: refused (the default), or skipped and
    /// counted in its component (`Ok`); finite samples that make the response overflow are
    /// an error under either policy.
    ///
    /// Errors, each with `r` unchanged: [`Error::NonFiniteInput`] (a non-finite sample,
    /// refused); [`Error::NonFiniteState`]. Cost: two comparisons, one [`RotD::step`], a
    /// copy of `r` and a scan of it.
    pub fn try_step<const P: usize>(
        &self,
        bank: &Bank<T, P>,
        r: &mut RotDResponse<T, P, K>,
        ax: T,
        ay: T,
    ) -> Result<(), Error> {
        super::check_sample(bank.non_finite, ax)?;
        super::check_sample(bank.non_finite, ay)?;
        let mut next = *r;
        self.step(bank, &mut next, ax, ay);
        if next.is_finite() {
            *r = next;
            Ok(())
        } else {
            Err(Error::NonFiniteState)
        }
    }

    /// Continue both components in free vibration for `samples` sample intervals (as
    /// [`Bank::free_vibration`]). Cost: `samples` times that of [`RotD::step`].
    pub fn free_vibration<const P: usize>(
        &self,
        bank: &Bank<T, P>,
        r: &mut RotDResponse<T, P, K>,
        samples: u32,
    ) {
        if r.x.samples == 0 {
            return;
        }
        let z = T::from_f64_rounded(0.0);
        for _ in 0..samples {
            let (ax0, ay0) = (r.x.last, r.y.last);
            r.x.last = z;
            r.y.last = z;
            self.advance(bank, r, ax0, z, ay0, z);
        }
    }

    fn take<const P: usize>(&self, c: &mut Response<T, P>, a: T) -> T {
        if finite(a) {
            a
        } else {
            c.skipped += 1;
            c.last
        }
    }

    fn advance<const P: usize>(
        &self,
        b: &Bank<T, P>,
        r: &mut RotDResponse<T, P, K>,
        ax0: T,
        ax1: T,
        ay0: T,
        ay1: T,
    ) {
        let (x, y) = (&mut r.x, &mut r.y);
        for p in 0..P {
            let (Some(&n), Some(&inv)) = (b.n.get(p), b.inv_n.get(p)) else {
                return;
            };
            let (dx, dy) = ((ax1 - ax0) * inv, (ay1 - ay0) * inv);
            let (mut gx, mut gy) = (ax0, ay0);
            let (uu, uv, ug, ud) = (b.uu[p], b.uv[p], b.ug[p], b.ud[p]);
            let (vu, vv, vg, vd) = (b.vu[p], b.vv[p], b.vg[p], b.vd[p]);
            let (w2, c2) = (b.w2[p], b.c2[p]);
            let (mut ux, mut vx, mut uy, mut vy) = (x.u[p], x.v[p], y.u[p], y.v[p]);
            let peak = &mut r.peak[p];
            for _ in 0..n {
                let ux1 = uu * ux + uv * vx + ug * gx + ud * dx;
                vx = vu * ux + vv * vx + vg * gx + vd * dx;
                ux = ux1;
                let uy1 = uu * uy + uv * vy + ug * gy + ud * dy;
                vy = vu * uy + vv * vy + vg * gy + vd * dy;
                uy = uy1;
                gx += dx;
                gy += dy;
                for (pk, (c, s)) in peak.iter_mut().zip(self.cos.iter().zip(self.sin.iter())) {
                    let a = abs(ux * *c + uy * *s);
                    if a > *pk {
                        *pk = a;
                    }
                }
                for (resp, uq, vq) in [(&mut *x, ux, vx), (&mut *y, uy, vy)] {
                    let acc = abs(w2 * uq + c2 * vq);
                    let (au, av) = (abs(uq), abs(vq));
                    if au > resp.sd[p] {
                        resp.sd[p] = au;
                    }
                    if av > resp.sv[p] {
                        resp.sv[p] = av;
                    }
                    if acc > resp.sa[p] {
                        resp.sa[p] = acc;
                    }
                }
            }
            x.u[p] = ux;
            x.v[p] = vx;
            y.u[p] = uy;
            y.v[p] = vy;
        }
    }
}

impl<T: Real, const P: usize, const K: usize> RotDResponse<T, P, K> {
    /// Both components' states and peaks ([`Response::is_finite`]) and every rotated peak
    /// are finite. A non-finite value never turns finite again under the linear maps, so
    /// this at the end of a record (after [`RotD::free_vibration`]) also tells whether any
    /// step overflowed. Cost: a scan of `10P + K·P` values.
    pub fn is_finite(&self) -> bool {
        let mut ok = self.x.is_finite() & self.y.is_finite();
        for pk in &self.peak {
            ok &= super::all_finite(pk);
        }
        ok
    }
    /// The first component's own response (its `Sd`, `Sv`, `Sa`). Cost: none.
    pub fn x(&self) -> &Response<T, P> {
        &self.x
    }
    /// The second component's own response. Cost: none.
    pub fn y(&self) -> &Response<T, P> {
        &self.y
    }
    /// Peak rotated relative displacement `max_t |u_θ|` (m), `[p][j]` for angle `jπ/K`.
    /// Cost: none.
    pub fn peaks(&self) -> &[[T; K]; P] {
        &self.peak
    }
    /// RotD100: the largest peak over the `K` angles, per oscillator (m). Cost: `K·P`
    /// comparisons.
    pub fn rotd100(&self) -> [T; P] {
        let mut out = [T::from_f64_rounded(0.0); P];
        for (o, pk) in out.iter_mut().zip(self.peak.iter()) {
            for &a in pk {
                if a > *o {
                    *o = a;
                }
            }
        }
        out
    }
    /// RotD50: the median of the `K` peaks, per oscillator (m); for even `K` the mean of
    /// the two middle values. Cost: a sort of `K` values per oscillator (`O(P·K log K)`).
    pub fn rotd50(&self) -> [T; P] {
        let mut out = [T::from_f64_rounded(0.0); P];
        if K == 0 {
            return out;
        }
        for (o, pk) in out.iter_mut().zip(self.peak.iter()) {
            let mut s = *pk;
            s.sort_unstable_by(|a, b| a.partial_cmp(b).unwrap_or(core::cmp::Ordering::Equal));
            *o = if K % 2 == 1 {
                s[K / 2]
            } else {
                (s[K / 2 - 1] + s[K / 2]) * T::from_f64_rounded(0.5)
            };
        }
        out
    }
}
