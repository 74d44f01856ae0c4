"""``observe`` at any size (issue 34): the fixed-gain observer and the full Kalman filter
outside the compiled sizes.

Sizes outside ``aemstep.SIZES`` (and sensor counts above the compiled 3) run on the Rust
library's run-time-sized ``DynObserver`` and ``DynKalman``, which share the const-generic
types' build (state-space blocks, outputs, input noise, Riccati solve) and step
(``tests/runtime_size_observer.rs`` checks the two bit for bit in Rust). Here: n = 11 and
37, and 5 sensors on the compiled n = 5, against numpy filters written from the
equations — the average-acceleration (trapezoidal) model; the steady-state gain from the
Riccati recursion iterated to convergence and the fixed-gain loop; the time-varying Kalman
filter (Joseph form) — with a missing sample.
"""

import time

import numpy as np
import pytest

import aemstep

H = 0.02
SIGMA_F, SIGMA_Y = 1.0e4, 0.1


def building(n):
    """A shear building of ``n`` storeys (kg, N/m, N·s/m)."""
    m = np.eye(n) * 1.0e5
    k = 2.0e8 * (2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))
    k[-1, -1] = 2.0e8
    return m, 0.2 * m + 1.0e-3 * k, k


def reference(m, c, k, sensors):
    """The trapezoidal rule on ``x' = F x + G w`` (Newmark β = 1/4, γ = 1/2), ``B = −M ι``;
    absolute accelerations of ``sensors``; process noise ``Q = Γ σ_f² Γᵀ`` of white floor
    forces held over the step (``Γ = Γ₀ + Γ₁`` of the model with ``B = I``)."""
    n = m.shape[0]
    minv = np.linalg.inv(m)
    f = np.block([[np.zeros((n, n)), np.eye(n)], [-minv @ k, -minv @ c]])
    left = np.linalg.inv(np.eye(2 * n) - 0.5 * H * f)
    phi = left @ (np.eye(2 * n) + 0.5 * H * f)
    g_ground = left @ np.concatenate([np.zeros(n), minv @ (-m @ np.ones(n))]) * (0.5 * H)
    g_forces = left @ np.vstack([np.zeros((n, n)), minv]) * H
    e = np.eye(n)[sensors]
    hm = e @ f[n:]
    d = e @ (minv @ (-m @ np.ones(n))) + 1.0
    q = g_forces @ g_forces.T * SIGMA_F**2
    return phi, g_ground, hm, d, q


def steady_gain(phi, hm, q, r, iterations=20000):
    """The Riccati recursion of the a-priori covariance, iterated until it stops moving."""
    p = q.copy()
    for _ in range(iterations):
        s = hm @ p @ hm.T + r
        l = p @ hm.T @ np.linalg.inv(s)
        new = phi @ (p - l @ hm @ p) @ phi.T + q
        new = 0.5 * (new + new.T)
        if np.max(np.abs(new - p)) <= 1e-15 * np.max(np.abs(p)):
            p = new
            break
        p = new
    s = hm @ p @ hm.T + r
    return p @ hm.T @ np.linalg.inv(s)


def record(steps, o):
    t = np.arange(steps) * H
    ag = np.sin(7.0 * t) * np.exp(-0.2 * t) + 0.3 * np.cos(19.0 * t)
    y = 0.5 * np.sin(np.outer(t, 3.0 + np.arange(o)))
    y[7, 0] = np.nan
    return ag, y


def observer_loop(phi, g, hm, d, l, ag, y):
    x = np.zeros(phi.shape[0])
    out = [x]
    for i in range(1, ag.size):
        xp = phi @ x + g * (ag[i - 1] + ag[i])
        x = xp + l @ (y[i] - hm @ xp - d * ag[i]) if np.all(np.isfinite(y[i])) else xp
        out.append(x)
    return np.array(out)


@pytest.mark.parametrize("n,sensors", [(11, [3, 10]), (37, [5, 20, 36]), (5, [0, 1, 2, 3, 4])])
def test_run_time_sizes_match_a_numpy_kalman_filter(n, sensors):
    assert n not in aemstep.SIZES or len(sensors) > 3
    m, c, k = building(n)
    ag, y = record(400, len(sensors))
    out = aemstep.observe(m, c, k, H, ag, y, sensors, sigma_f=SIGMA_F, sigma_y=SIGMA_Y)
    u, v, gain = out.u, out.v, out.gain
    assert u.shape == v.shape == (ag.size, n) and gain.shape == (2 * n, len(sensors))
    phi, g, hm, d, q = reference(m, c, k, sensors)
    r = np.eye(len(sensors)) * SIGMA_Y**2
    l = steady_gain(phi, hm, q, r)
    gain_err = np.max(np.abs(gain - l)) / np.max(np.abs(l))
    x = observer_loop(phi, g, hm, d, l, ag, y)
    est = np.hstack([u, v])
    est_err = np.max(np.abs(est - x)) / np.max(np.abs(x))
    print(f"n = {n}, {len(sensors)} sensors: gain {gain_err:.1e}, estimates {est_err:.1e}")
    # The gain: the recursion's fixed point to ~1e-15 against the doubling's; rounding of
    # the 2n×2n products (measured ≤ 4.6e-12 at n = 37). The estimates carry it (≤ 8.4e-12).
    assert gain_err < 2e-11
    assert est_err < 2e-11
    # The missing sample was predicted, not corrected: the loop agrees there too.
    assert np.all(np.isfinite(est))


def kalman_loop(phi, g, hm, d, q, r, ag, y):
    """The Kalman filter from the equations, started at rest with zero covariance:
    ``P⁻ = Φ P Φᵀ + Q``, ``K = P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹``, Joseph form; predict only where a
    sample is missing."""
    s = phi.shape[0]
    x, p = np.zeros(s), np.zeros((s, s))
    out = [x]
    for i in range(1, ag.size):
        xp = phi @ x + g * (ag[i - 1] + ag[i])
        pm = phi @ p @ phi.T + q
        if np.all(np.isfinite(y[i])):
            gain = pm @ hm.T @ np.linalg.inv(hm @ pm @ hm.T + r)
            ikh = np.eye(s) - gain @ hm
            x = xp + gain @ (y[i] - hm @ xp - d * ag[i])
            p = ikh @ pm @ ikh.T + gain @ r @ gain.T
        else:
            x, p = xp, pm
        out.append(x)
    return np.array(out)


@pytest.mark.parametrize("n,sensors", [(11, [3, 10]), (37, [5, 20, 36]), (5, [0, 1, 2, 3, 4])])
def test_the_kalman_filter_at_run_time_sizes_matches_numpy(n, sensors):
    assert n not in aemstep.SIZES or len(sensors) > 3
    m, c, k = building(n)
    ag, y = record(300, len(sensors))
    out = aemstep.observe(
        m, c, k, H, ag, y, sensors, sigma_f=SIGMA_F, sigma_y=SIGMA_Y, kalman=True
    )
    assert out.u.shape == out.v.shape == (ag.size, n) and out.gain.size == 0
    phi, g, hm, d, q = reference(m, c, k, sensors)
    r = np.eye(len(sensors)) * SIGMA_Y**2
    x = kalman_loop(phi, g, hm, d, q, r, ag, y)
    est = np.hstack([out.u, out.v])
    err = np.max(np.abs(est - x)) / np.max(np.abs(x))
    print(f"kalman=True, n = {n}, {len(sensors)} sensors: estimates {err:.1e}")
    # Rounding of the two models and of the 2n×2n covariance products, carried by the
    # stable recursion (measured 2.6e-14, 2.0e-13, 2.2e-15).
    assert err < 2e-12
    assert np.all(np.isfinite(est))


def test_bad_noise_raises_the_compiled_paths_error_at_any_size():
    for n in (5, 11):
        m, c, k = building(n)
        ag, y = record(50, 1)
        with pytest.raises(aemstep.InvalidCovariance):
            aemstep.observe(m, c, k, H, ag, y, [n - 1], sigma_f=SIGMA_F, sigma_y=0.0)
        with pytest.raises(aemstep.NonFiniteInput) as err:
            bad = ag.copy()
            bad[20] = np.inf
            aemstep.observe(m, c, k, H, bad, y, [n - 1], sigma_f=SIGMA_F, sigma_y=SIGMA_Y)
        assert err.value.step == 20


def test_a_model_above_the_observe_bound_raises_before_any_work():
    # MAX_OBSERVE_DOFS + 1 storeys: refused at once (the gain solve would take minutes).
    # (The bound itself is taken: test_interrupt.py runs and stops its gain solve.)
    n = aemstep.MAX_OBSERVE_DOFS + 1
    m, c, k = building(n)
    ag, y = record(50, 1)
    t = time.perf_counter()
    with pytest.raises(aemstep.ShapeError, match="MAX_OBSERVE_DOFS"):
        aemstep.observe(m, c, k, H, ag, y, [n - 1], sigma_f=SIGMA_F, sigma_y=SIGMA_Y)
    assert time.perf_counter() - t < 0.5
