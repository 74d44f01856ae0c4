"""Elastic spectra and RotD against numpy loops and a closed form; threads."""

import numpy as np
import pytest

import aemstep

# Periods with T ≥ 20 h at h = 0.02 s: one sub-step per sample (the default rule takes
# ⌈20 h / T⌉), so the peaks are those at the samples, which a numpy loop reproduces.
PERIODS = np.array([0.4, 0.45, 0.5, 0.6, 0.75, 1.0, 1.3, 1.7, 2.0, 2.5, 3.0, 3.5, 4.0, 4.5,
                    5.0, 5.5, 6.0, 7.0])  # 18 periods: two banks of 16, the second padded


def aem_peaks(periods, xi, h, ag, free=0):
    """Average-acceleration oscillators, vectorized over the periods (numpy, here)."""
    w = 2 * np.pi / periods
    c, k = 2 * xi * w, w * w
    u = np.zeros_like(w)
    v = np.zeros_like(w)
    a = -ag[0] - c * v - k * u
    sd = np.zeros_like(w)
    sv = np.zeros_like(w)
    sa = np.zeros_like(w)
    keff = 4 / h**2 + 2 * c / h + k
    rec = np.concatenate([ag, np.zeros(free)])
    for g in rec[1:]:
        rhs = -g + (4 / h**2 * u + 4 / h * v + a) + c * (2 / h * u + v)
        u1 = rhs / keff
        v1 = 2 / h * (u1 - u) - v
        a = 4 / h**2 * (u1 - u) - 4 / h * v - a
        u, v = u1, v1
        sd = np.maximum(sd, np.abs(u))
        sv = np.maximum(sv, np.abs(v))
        sa = np.maximum(sa, np.abs(c * v + k * u))
    return sd, sv, sa


def test_aem_bank_equals_a_numpy_loop(elcentro):
    ag, dt = elcentro
    s = aemstep.spectrum(PERIODS, 0.05, dt, ag, scheme="aem", free_vibration=False)
    sd, sv, sa = aem_peaks(PERIODS, 0.05, dt, ag)
    for got, ref in ((s.sd, sd), (s.sv, sv), (s.sa, sa)):
        err = np.abs(got / ref - 1).max()
        print(f"relative difference {err:.1e}")
        assert err < 1e-11  # rounding over 3995 steps: measured ≤ 9.8e-13
    w = 2 * np.pi / PERIODS
    assert np.allclose(s.psa, w * w * s.sd, rtol=1e-15) and np.allclose(s.psv, w * s.sd, rtol=1e-15)


def test_exact_bank_matches_the_closed_form_of_a_step_load():
    # Undamped, ground acceleration rising linearly from 0 to A over the first h and held:
    # u = −A/(ω²h) (t − sin ωt/ω) on [0, h], then a free oscillation about −A/ω². Its peak
    # |u| is A/ω² + the amplitude about the offset; 5000 samples at incommensurate phases
    # come within (2π/5000)²/2 of it.
    A, h, T = 2.0, 0.02, np.array([0.5137, 0.8123, 1.377])
    ag = np.full(5000, A)
    ag[0] = 0.0
    w = 2 * np.pi / T
    u_h = -A / (w * w * h) * (h - np.sin(w * h) / w)
    v_h = -A / (w * w * h) * (1 - np.cos(w * h))
    amp = np.hypot(u_h + A / w**2, v_h / w)
    peak = A / w**2 + amp
    s = aemstep.spectrum(T, 0.0, h, ag, free_vibration=False)
    err = np.abs(s.sd / peak - 1).max()
    print(f"exact scheme against the closed form: {err:.1e}")
    assert err < 1e-5  # sampling of the peak: measured 1.3e-6


def test_rotd_is_the_median_and_largest_over_rotated_records(elcentro):
    ag, dt = elcentro
    ax, ay = ag[:2000], 0.7 * ag[500:2500]
    r = aemstep.rotd(PERIODS, 0.05, dt, ax, ay, free_vibration=False)
    theta = np.pi * np.arange(aemstep.ROTD_ANGLES) / aemstep.ROTD_ANGLES
    rotated = [np.cos(t) * ax + np.sin(t) * ay for t in theta]
    s = aemstep.spectra(PERIODS, 0.05, dt, rotated, free_vibration=False, threads=2)
    # By linearity the rotated response is the combination of the two: rounding only.
    assert np.allclose(r.rotd100, s.sd.max(axis=0), rtol=1e-12, atol=0)
    assert np.allclose(r.rotd50, np.median(s.sd, axis=0), rtol=1e-12, atol=0)
    assert np.all(r.rotd50 <= r.rotd100)
    assert np.allclose(r.psa100, (2 * np.pi / PERIODS) ** 2 * r.rotd100, rtol=1e-15)


def test_threads_give_the_same_bits(elcentro):
    ag, dt = elcentro
    records = [ag * s for s in (0.5, 1.0, 1.5)] + [ag[::-1], ag[:1000], ag[1000:]]
    periods = np.geomspace(0.05, 4.0, 40)
    one = aemstep.spectra(periods, 0.05, dt, records, threads=1)
    two = aemstep.spectra(periods, 0.05, dt, records, threads=2)
    for a, b in zip(one, two):
        assert np.array_equal(a, b)
    # and each record alone gives the same bits as in the batch
    alone = aemstep.spectrum(periods, 0.05, dt, records[4])
    assert np.array_equal(alone.sd, one.sd[4])


def test_progress_is_reported_between_batches(elcentro):
    ag, dt = elcentro
    seen = []
    s = aemstep.spectra([0.5, 1.0], 0.05, dt, [ag] * 10, threads=1,
                        progress=lambda done, total: seen.append((done, total)))
    assert seen[-1] == (10, 10) and len(seen) >= 2
    assert np.array_equal(s.sd[0], s.sd[9])


def test_bad_periods_and_damping_are_typed_errors(elcentro):
    ag, dt = elcentro
    with pytest.raises(aemstep.InvalidPeriod):
        aemstep.spectrum([1.0, 0.5], 0.05, dt, ag)
    with pytest.raises(aemstep.InvalidPeriod):
        aemstep.spectrum(list(np.linspace(0.1, 2, 20)) + [0.3], 0.05, dt, ag)  # across banks
    with pytest.raises(aemstep.InvalidPeriod):
        aemstep.spectrum([-1.0], 0.05, dt, ag)
    with pytest.raises(aemstep.InvalidDamping):
        aemstep.spectrum([1.0], 1.5, dt, ag)
    with pytest.raises(aemstep.InvalidTimeStep):
        aemstep.spectrum([1.0], 0.05, 0.0, ag)
    with pytest.raises(aemstep.ShapeError):
        aemstep.spectrum([1.0, 2.0], [0.05, 0.05, 0.05], dt, ag)
    with pytest.raises(aemstep.ShapeError):
        aemstep.rotd([1.0], 0.05, dt, ag, ag[:-1])
