"""Inelastic spectra against a plain bilinear oscillator loop at a fine step."""

import numpy as np
import pytest

import aemstep


def bilinear_peak(T, xi, alpha, ay, h, ag, sub):
    """Peak |u| of a unit-mass bilinear oscillator (kinematic hardening; ay = f_y/m, m/s²)
    by average acceleration with ``sub`` sub-steps per sample, the record linear between
    samples, then one period of free vibration. Return mapping solved exactly per step
    (the step equation is piecewise linear). Plain Python, independent of the library."""
    w = 2 * np.pi / T
    k, c = w * w, 2 * xi * w
    hs = h / sub
    kap = 4 / hs**2 + 2 * c / hs
    hard = alpha * k / (1 - alpha)
    u = v = up = 0.0
    f = 0.0
    a = -ag[0]
    peak = 0.0
    free = int(np.ceil(T / h))
    rec = np.concatenate([ag, np.zeros(free)])
    for n in range(1, rec.shape[0]):
        for j in range(1, sub + 1):
            g = rec[n - 1] + (rec[n] - rec[n - 1]) * j / sub
            # a1 + c v1 + f1 = −g with a1 = 4/hs² Δu − 4/hs v − a, v1 = 2/hs Δu − v:
            # κ Δu + f1 = b
            b = -g + 4 / hs * v + a + c * v
            # elastic trial
            du = (b - f) / (kap + k)
            ftr = f + k * du
            u1 = u + du
            xi_tr = ftr - hard * up
            if abs(xi_tr) > ay:
                s = np.sign(xi_tr)
                # on the yield surface: f1 = α k u1 + s (1 − α) ay
                du = (b - alpha * k * u - s * (1 - alpha) * ay) / (kap + alpha * k)
                u1 = u + du
                f1 = alpha * k * u1 + s * (1 - alpha) * ay
                up = u1 - f1 / k
            else:
                f1 = ftr
            v1 = 2 / hs * du - v
            a = 4 / hs**2 * du - 4 / hs * v - a
            u, v, f = u1, v1, f1
            peak = max(peak, abs(u))
    return peak


@pytest.mark.parametrize("alpha", [0.0, 0.05])
def test_constant_strength_matches_a_fine_step_loop(elcentro, alpha):
    ag, dt = elcentro
    ag = ag[:1500]  # 30 s of El Centro
    periods, R = np.array([0.3, 1.0]), 4.0
    cs = aemstep.constant_strength(periods, 0.05, dt, ag, R, alpha=alpha, points_per_period=400)
    for p, T in enumerate(periods):
        sub = 40  # 2000 points per period at T = 1 s, 600 at 0.3 s
        u_el = bilinear_peak(T, 0.05, alpha, np.inf, dt, ag, sub)
        ay = (2 * np.pi / T) ** 2 * u_el / R
        mu = bilinear_peak(T, 0.05, alpha, ay, dt, ag, sub) / (ay / (2 * np.pi / T) ** 2)
        err_el = abs(cs.elastic[p] / ((2 * np.pi / T) ** 2 * u_el) - 1)
        err_mu = abs(cs.ductility[p] / mu - 1)
        print(f"T = {T}, α = {alpha}: μ = {cs.ductility[p]:.4f} (loop {mu:.4f}), "
              f"elastic {err_el:.1e}, ductility {err_mu:.1e}")
        # Both are the AEM at different steps: O(h²) errors, (ωh)²/12 per period of
        # elongation at the library's 400 points (2.1e-5 relative) dominating; ductility
        # adds the strength's error. Measured ≤ 3.0e-5 (elastic), ≤ 1.9e-4 (ductility);
        # bound 1e-3.
        assert err_el < 1e-3 and err_mu < 1e-3
    assert np.allclose(cs.yield_acceleration, cs.elastic / R, rtol=1e-15)
    assert np.all(cs.ductility > 1) and np.all(cs.plastic_work > 0)


@pytest.mark.parametrize("alpha", [0.0, 0.1])
def test_constant_ductility_brackets_the_target_to_its_tolerance(elcentro, alpha):
    ag, dt = elcentro
    periods = np.array([0.2, 0.5, 1.0, 2.0])
    cd = aemstep.constant_ductility(periods, 0.05, dt, ag, 4.0, alpha=alpha, tol=1e-6)
    assert cd.outcome == ["converged"] * 4
    lo, hi = cd.bracket[:, 0], cd.bracket[:, 1]
    assert np.all(cd.bracket_ductility[:, 0] >= 4.0) and np.all(cd.bracket_ductility[:, 1] < 4.0)
    assert np.all(hi - lo <= 1e-6 * hi)
    assert np.all((lo <= cd.yield_acceleration) & (cd.yield_acceleration <= hi))
    # The strength it returns gives (nearly) the target through the other function.
    cs = aemstep.constant_strength(periods, 0.05, dt, ag, cd.reduction, alpha=alpha)
    worst = np.abs(cs.ductility / 4.0 - 1).max()
    print(f"α = {alpha}: R = {cd.reduction}, μ at R off by {worst:.1e}, passes {cd.passes}")
    # μ moves by dμ/da_y · 1e-6 a_y across the bracket: measured ≤ 1e-5; bound 1e-3.
    assert worst < 1e-3


def test_threads_and_banks_give_the_same_bits(elcentro):
    ag, dt = elcentro
    periods = np.geomspace(0.1, 3.0, 20)  # two banks
    a = aemstep.constant_ductility(periods, 0.05, dt, ag[:1000], 2.0, threads=1)
    b = aemstep.constant_ductility(periods, 0.05, dt, ag[:1000], 2.0, threads=2)
    assert np.array_equal(a.yield_acceleration, b.yield_acceleration)
    c = aemstep.constant_strength(periods, 0.05, dt, ag[:1000], 3.0, threads=1)
    d = aemstep.constant_strength(periods, 0.05, dt, ag[:1000], 3.0, threads=2)
    assert np.array_equal(c.ductility, d.ductility)


def test_bad_inelastic_input_is_typed(elcentro):
    ag, dt = elcentro
    with pytest.raises(aemstep.InvalidMaterial):
        aemstep.constant_strength([1.0], 0.05, dt, ag, 4.0, alpha=1.0)
    with pytest.raises(aemstep.InvalidParameter):
        aemstep.constant_strength([1.0], 0.05, dt, ag, 0.0)
    with pytest.raises(aemstep.InvalidParameter):
        aemstep.constant_ductility([1.0], 0.05, dt, ag, 0.5)
    with pytest.raises(aemstep.InvalidParameter):
        aemstep.constant_strength([1.0], 0.05, dt, np.zeros(100), 4.0)  # at rest
