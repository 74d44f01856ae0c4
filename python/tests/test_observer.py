"""Observers on recorded data: a building whose first storey is softer than its model."""

import numpy as np
import pytest

import aemstep
from conftest import rayleigh, shear_matrices


def test_observers_beat_the_open_loop_model(elcentro):
    ag, dt = elcentro
    n = 5
    m, k = shear_matrices([2e5] * n, [2e8] * n)
    c = rayleigh(m, k, 0.05)
    ks = np.array([2e8] * n)
    ks[0] *= 0.9  # the truth: storey 1 10 % softer than the model
    _, k_true = shear_matrices([2e5] * n, ks)
    truth = aemstep.linear_response(m, c, k_true, dt, ground_acceleration=ag)
    rng = np.random.default_rng(7)
    sensors = [1, 4]
    measured = truth.a[:, sensors] + ag[:, None] + 0.2 * rng.standard_normal((ag.shape[0], 2))
    model = aemstep.linear_response(m, c, k, dt, ground_acceleration=ag)
    true_drift = np.diff(truth.u, axis=1, prepend=0.0)
    rms = lambda d: np.sqrt(((d - true_drift) ** 2).mean(axis=0))
    open_loop = rms(np.diff(model.u, axis=1, prepend=0.0))
    steady = aemstep.observe(m, c, k, dt, ag, measured, sensors, sigma_f=5e4, sigma_y=0.2)
    full = aemstep.observe(m, c, k, dt, ag, measured, sensors, sigma_f=5e4, sigma_y=0.2, kalman=True)
    print(f"RMS drift error (m): open loop {open_loop}, steady state {rms(steady.drifts)}, "
          f"Kalman {rms(full.drifts)}")
    assert steady.u.shape == (ag.shape[0], n) and steady.gain.shape == (2 * n, 2)
    assert full.gain.size == 0
    # The correction must help every storey (measured: 2× to 5× smaller errors).
    assert np.all(rms(steady.drifts) < 0.7 * open_loop)
    assert np.all(rms(full.drifts) < 0.7 * open_loop)
    # The Kalman gain converges to the steady-state gain: late estimates agree closely.
    late = slice(ag.shape[0] // 2, None)
    gap = np.abs(full.u[late] - steady.u[late]).max() / np.abs(truth.u).max()
    print(f"Kalman vs steady state, second half: {gap:.1e}")
    assert gap < 1e-3


def test_exact_model_and_noiseless_sensors_reproduce_the_truth(elcentro):
    ag, dt = elcentro
    m, k = shear_matrices([1e5] * 3, [1e8] * 3)
    c = rayleigh(m, k, 0.02)
    truth = aemstep.linear_response(m, c, k, dt, ground_acceleration=ag[:1000])
    measured = truth.a[:, [2]] + ag[:1000, None]
    e = aemstep.observe(m, c, k, dt, ag[:1000], measured, [2], sigma_f=1e4, sigma_y=0.1)
    # Innovations are rounding only, so is the estimate's error (measured 4e-17 m).
    assert np.abs(e.u - truth.u).max() < 1e-12 * np.abs(truth.u).max() + 1e-15


def test_missing_samples_are_skipped_not_errors(elcentro):
    ag, dt = elcentro
    m, k = shear_matrices([1e5] * 2, [1e8] * 2)
    c = rayleigh(m, k, 0.02)
    measured = np.full((200, 1), np.nan)
    e = aemstep.observe(m, c, k, dt, ag[:200], measured, [1], sigma_f=1e4, sigma_y=0.1)
    open_loop = aemstep.linear_response(m, c, k, dt, ground_acceleration=ag[:200])
    assert np.allclose(e.u, open_loop.u, rtol=0, atol=1e-12 * np.abs(open_loop.u).max())
    with pytest.raises(aemstep.ShapeError):
        aemstep.observe(m, c, k, dt, ag[:200], measured, [2], sigma_f=1e4, sigma_y=0.1)
