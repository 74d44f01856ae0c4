"""Linear schemes against a numpy Newmark loop and closed forms."""

import numpy as np
import pytest

import aemstep
from conftest import newmark_average, rayleigh, shear_matrices


def building(n=3):
    m, k = shear_matrices([1e5] * n, [1e8] * n)
    return m, rayleigh(m, k, 0.05), k


def test_aem_equals_a_numpy_newmark_loop_under_el_centro(elcentro):
    ag, dt = elcentro
    m, c, k = building(3)
    r = aemstep.linear_response(m, c, k, dt, ground_acceleration=ag)
    p = np.outer(ag, -m.sum(axis=1))
    u, v, a = newmark_average(m, c, k, dt, p)
    # The same recurrence, operators formed differently: rounding only. Measured 5.7e-15 to
    # 1.4e-14 of the peak over 3995 steps; bound 1e-12.
    for got, ref in ((r.u, u), (r.v, v), (r.a, a)):
        err = np.abs(got - ref).max() / np.abs(ref).max()
        print(f"relative difference {err:.1e}")
        assert err < 1e-12
    assert r.u.shape == (ag.shape[0], 3)


def test_undamped_free_vibration_is_the_closed_form_of_the_trapezoidal_rule():
    # u'' + ω² u = 0, u(0) = 1: average acceleration keeps the amplitude and turns the
    # phase by θ = 2 atan(ωh/2) a step, so u_n = cos(nθ) exactly (up to rounding).
    w, h, steps = 5.0, 0.01, 2000
    r = aemstep.linear_response([[1.0]], [[0.0]], [[w * w]], h, p=np.zeros((steps, 1)), u0=[1.0])
    theta = 2 * np.arctan(w * h / 2)
    ref = np.cos(theta * np.arange(steps))
    err = np.abs(r.u[:, 0] - ref).max()
    print(f"max |u − cos(nθ)| = {err:.1e}")
    assert err < 1e-12  # measured 8.1e-15 after 2000 steps
    # and against the exact solution, the O(h²) phase error ω³h²t/12 (t = 20 s: 0.21 rad).
    exact = np.cos(w * h * np.arange(steps))
    assert np.abs(r.u[:, 0] - exact).max() < (w**3 * h**2 * steps * h / 12) * 1.05


def test_exact_scheme_matches_damped_free_vibration():
    w, xi, h, steps = 4.0, 0.05, 0.05, 400
    r = aemstep.linear_response(
        [[1.0]], [[2 * xi * w]], [[w * w]], h, p=np.zeros((steps, 1)), u0=[0.3], v0=[-0.2],
        scheme="exact",
    )
    t = h * np.arange(steps)
    wd = w * np.sqrt(1 - xi**2)
    ref = np.exp(-xi * w * t) * (0.3 * np.cos(wd * t) + (-0.2 + xi * w * 0.3) / wd * np.sin(wd * t))
    err = np.abs(r.u[:, 0] - ref).max()
    print(f"exact scheme: max error {err:.1e}")
    assert err < 1e-14  # rounding: measured 4.4e-16


@pytest.mark.parametrize(
    "scheme, kw",
    [
        ("newmark", {}),
        ("generalized_alpha", {"rho_inf": 1.0}),
        ("hht", {"alpha": 0.0}),
        ("modal", {}),
    ],
)
def test_schemes_that_are_the_aem_give_its_history(elcentro, scheme, kw):
    ag, dt = elcentro
    m, c, k = building(4)
    aem = aemstep.linear_response(m, c, k, dt, ground_acceleration=ag[:1000])
    r = aemstep.linear_response(m, c, k, dt, ground_acceleration=ag[:1000], scheme=scheme, **kw)
    err = np.abs(r.u - aem.u).max() / np.abs(aem.u).max()
    print(f"{scheme}: relative difference from the AEM {err:.1e}")
    assert err < 1e-12  # rounding through different operators: measured ≤ 2.8e-15


def test_dissipative_schemes_stay_within_second_order_error():
    # HHT α = −0.1 and generalized-α ρ∞ = 0.8 damp high frequencies but are second order:
    # on a slow free vibration (ωh = 0.05) they are within a few (ωh)² of the exact.
    w, h, steps = 1.0, 0.05, 200
    exact = np.cos(w * h * np.arange(steps))
    for scheme, kw in (("hht", {"alpha": -0.1}), ("generalized_alpha", {"rho_inf": 0.8})):
        r = aemstep.linear_response(
            [[1.0]], [[0.0]], [[w * w]], h, p=np.zeros((steps, 1)), u0=[1.0], scheme=scheme, **kw
        )
        err = np.abs(r.u[:, 0] - exact).max()
        print(f"{scheme}: {err:.1e}")
        assert 1e-6 < err < 10 * (w * h) ** 2 * (w * h * steps)  # measured 2.1e-3, 1.7e-3


def test_ground_acceleration_is_the_load_minus_m_iota_ag():
    m, c, k = building(2)
    ag = np.sin(np.arange(300) * 0.1)
    a = aemstep.linear_response(m, c, k, 0.01, ground_acceleration=ag)
    b = aemstep.linear_response(m, c, k, 0.01, p=np.outer(ag, -m @ np.ones(2)))
    assert np.array_equal(a.u, b.u)


def test_inputs_need_not_be_contiguous_float64():
    m, c, k = building(2)
    p = np.asfortranarray(np.ones((50, 2)) * 1e3)[:, ::1]
    wide = np.ones((50, 4)) * 1e3  # a strided view
    r1 = aemstep.linear_response(m.tolist(), c, k.astype(np.float32).astype(float), 0.01, p=p)
    r2 = aemstep.linear_response(m, c, k, 0.01, p=wide[:, ::2])
    assert np.array_equal(r1.u, r2.u)
    ints = aemstep.linear_response(np.eye(2, dtype=int), np.zeros((2, 2), dtype=int),
                                   np.eye(2, dtype=int) * 4, 0.01, p=np.ones((10, 2), dtype=int))
    assert ints.u.dtype == np.float64


def test_every_compiled_size_runs_and_others_are_refused():
    for n in aemstep.SIZES:
        m, c, k = building(n)
        r = aemstep.linear_response(m, c, k, 0.01, ground_acceleration=np.ones(5))
        assert r.u.shape == (5, n)
    for n in (11, 21):
        m, c, k = building(n)
        # The AEM takes any n (test_any_size.py); the other schemes only SIZES.
        assert aemstep.linear_response(m, c, k, 0.01, ground_acceleration=np.ones(5)).u.shape == (5, n)
        with pytest.raises(aemstep.UnsupportedSize, match="degrees of freedom"):
            aemstep.linear_response(m, c, k, 0.01, ground_acceleration=np.ones(5), scheme="newmark")


def test_truncated_modal_runs():
    m, c, k = building(5)
    # A load shaped as M φ1 excites mode 1 alone: one mode gives the full response.
    w2, phi = np.linalg.eig(np.linalg.solve(m, k))
    phi1 = phi[:, np.argmin(w2.real)].real
    p = np.outer(np.sin(np.arange(800) * 0.05), m @ phi1) * 1e3
    full = aemstep.linear_response(m, c, k, 0.01, p=p)
    one = aemstep.linear_response(m, c, k, 0.01, p=p, scheme="modal", modes=1)
    err = np.abs(one.u - full.u).max() / np.abs(full.u).max()
    print(f"one mode against the full model under a first-mode load: {err:.1e}")
    assert err < 1e-12  # rounding (the other modes' loads are zero to rounding): measured 5.9e-15
    # Under ground motion the truncation error falls as modes are added.
    ag = np.sin(np.arange(800) * 0.2) * 3.0
    full = aemstep.linear_response(m, c, k, 0.01, ground_acceleration=ag)
    errs = [np.abs(aemstep.linear_response(m, c, k, 0.01, ground_acceleration=ag,
                                           scheme="modal", modes=r).u - full.u).max()
            for r in (1, 2, 3)]
    print("truncation errors (m), 1 to 3 modes: " + ", ".join(f"{e:.1e}" for e in errs))
    assert errs[0] > errs[1] > errs[2] > 0
    assert errs[0] < 0.2 * np.abs(full.u).max()
    with pytest.raises(aemstep.InvalidModeSelection):
        aemstep.linear_response(m[:2, :2], c[:2, :2], k[:2, :2], 0.01, p=p[:, :2], scheme="modal",
                                modes=3)
    with pytest.raises(aemstep.UnsupportedSize):
        aemstep.linear_response(m, c, k, 0.01, p=p, scheme="modal", modes=4)
