"""The yielding shear building against an independent bilinear oscillator loop, and its
energy account."""

import numpy as np
import pytest

import aemstep
from conftest import rayleigh, shear_matrices


def bilinear_sdof(m, c, k, fy, alpha, h, ag, tol=1e-13):
    """A plain Python AEM (average acceleration) step with Newton on the displacement and a
    bilinear kinematic-hardening return mapping, written here independently."""
    hard = alpha * k / (1 - alpha)
    u = v = up = 0.0
    a = -ag[0]  # m a0 = p0 − c v0 − f0 with everything at rest
    out = np.zeros(ag.shape[0])
    for i in range(1, ag.shape[0]):
        p = -m * ag[i]
        u1 = u
        for _ in range(50):
            ftr = k * (u1 - up)
            xi = ftr - hard * up
            if abs(xi) <= fy:
                f, kt, up1 = ftr, k, up
            else:
                s = np.sign(xi)
                dg = (abs(xi) - fy) / (k + hard)
                up1 = up + s * dg
                f, kt = ftr - k * s * dg, alpha * k
            v1 = 2 / h * (u1 - u) - v
            a1 = 4 / h**2 * (u1 - u) - 4 / h * v - a
            r = m * a1 + c * v1 + f - p
            du = -r / (4 * m / h**2 + 2 * c / h + kt)
            u1 += du
            if abs(du) <= tol * max(abs(u1), 1e-12):
                break
        ftr = k * (u1 - up)
        xi = ftr - hard * up
        if abs(xi) > fy:
            up += np.sign(xi) * (abs(xi) - fy) / (k + hard)
        v1 = 2 / h * (u1 - u) - v
        a = 4 / h**2 * (u1 - u) - 4 / h * v - a
        u, v = u1, v1
        out[i] = u
    return out


def test_one_storey_bilinear_matches_an_independent_loop(elcentro):
    ag, dt = elcentro
    ag = ag[:1500]
    m, k, fy, alpha = 1e5, 4e7, 1.5e5, 0.05
    c = 2 * 0.05 * np.sqrt(k * m)
    r = aemstep.shear_building([m], [[c]], dt, ag, k=k, fy=fy, alpha=alpha)
    ref = bilinear_sdof(m, c, k, fy, alpha, dt, ag)
    err = np.abs(r.u[:, 0] - ref).max() / np.abs(ref).max()
    print(f"peak drift {r.peak_drifts[0]:.4f} m (yield {fy / k:.4f} m), relative difference {err:.1e}")
    assert r.peak_drifts[0] > 3 * fy / k  # it yielded well past the yield drift
    # Both solve the same implicit step, each Newton to its tolerance (1e-10 relative
    # residual in the library, 1e-13 on the increment here); the bilinear law is piecewise
    # linear, so both land on the exact root: measured 5.1e-15; bound 1e-10.
    assert err < 1e-10


def three_storey():
    masses = [1e5] * 3
    m, k = shear_matrices(masses, [1e8] * 3)
    return masses, m, k, rayleigh(m, k, 0.02)


def record_at(ag, dt, h):
    """The record linear between its samples, at step h."""
    t = np.arange(0, (ag.shape[0] - 1) * dt + 1e-12, h)
    return np.interp(t, np.arange(ag.shape[0]) * dt, ag)


def test_energy_account_balances_and_the_building_dissipates(elcentro):
    ag, dt = elcentro
    masses, m, k, c = three_storey()
    h = dt / 2
    r = aemstep.shear_building(
        masses, c, h, record_at(ag, dt, h), k=1e8, fy=[6e5, 5e5, 3.5e5], alpha=0.05
    )
    e = r.energy
    assert r.u.shape == (2 * ag.shape[0] - 1, 3)
    assert np.allclose(r.drifts[:, 0], r.u[:, 0]) and np.allclose(r.drifts[:, 2], r.u[:, 2] - r.u[:, 1])
    assert np.array_equal(r.peak_drifts, np.abs(r.drifts).max(axis=0))
    total = e.initial + e.input - (e.kinetic + e.recoverable + e.viscous + e.hysteretic)
    assert np.allclose(total, e.balance_error, rtol=0, atol=1e-9 * np.abs(e.input).max())
    # The AEM's discrete balance is exact: what is left is the Newton tolerance (1e-10)
    # and rounding; measured 3.9e-15 of the input; bound 1e-8 (the tolerance, 1e-10 a step).
    worst = np.abs(e.balance_error).max() / np.abs(e.input).max()
    print(f"hysteretic {e.hysteretic[-1]:.0f} J of input {e.input[-1]:.0f} J; balance {worst:.1e}")
    assert worst < 1e-8
    assert e.hysteretic[-1] > 0.1 * e.input[-1]  # the yielding storeys dissipate
    assert np.all(np.diff(e.viscous) >= -1e-9)  # viscous dissipation only grows


def test_an_elastic_building_is_the_linear_aem(elcentro):
    ag, dt = elcentro
    masses, m, k, c = three_storey()
    r = aemstep.shear_building(masses, c, dt, ag[:800], k=1e8, fy=1e12, alpha=0.0)
    lin = aemstep.linear_response(m, c, k, dt, ground_acceleration=ag[:800])
    err = np.abs(r.u - lin.u).max() / np.abs(lin.u).max()
    assert err < 1e-8  # Newton to 1e-10 relative residual: measured 1e-15 (linear: 1 iteration)
    assert np.abs(r.energy.hysteretic).max() <= 1e-9 * np.abs(r.energy.input).max()


@pytest.mark.parametrize(
    "law, extra",
    [("bouc_wen", {"beta": 0.5, "gamma": 0.5, "n": 1.0}), ("bilinear_friction", {"fs": 5e4, "vr": 1e-3})],
)
def test_bouc_wen_and_friction_storeys_dissipate_and_balance(elcentro, law, extra):
    ag, dt = elcentro
    masses, m, k, c = three_storey()
    h = dt / 4
    r = aemstep.shear_building(
        masses, c, h, record_at(ag[:1000], dt, h), law=law, k=1e8, fy=[6e5, 5e5, 3.5e5],
        alpha=0.05, max_iterations=30, **extra,
    )
    e = r.energy
    worst = np.abs(e.balance_error).max() / np.abs(e.input).max()
    print(f"{law}: peak drifts {r.peak_drifts}, hysteretic {e.hysteretic[-1]:.0f} J, balance {worst:.1e}")
    assert e.hysteretic[-1] > 0 and worst < 1e-9  # measured 1.2e-12 and 2.0e-13


def test_newton_failure_and_bad_laws_are_typed_errors(elcentro):
    ag, dt = elcentro
    masses, m, k, c = three_storey()
    with pytest.raises(aemstep.NotConverged) as info:
        aemstep.shear_building(
            masses, c, dt, 3 * ag, k=1e8, fy=[6e5, 5e5, 3.5e5], alpha=0.05,
            max_iterations=1, tolerance=1e-14,
        )
    assert info.value.step >= 1
    assert str(info.value) == "Newton did not converge within its budget; state unchanged"
    with pytest.raises(aemstep.InvalidMaterial):
        aemstep.shear_building(masses, c, dt, ag, k=1e8, fy=-1.0)
    with pytest.raises(aemstep.InvalidNewtonSettings):
        aemstep.shear_building(masses, c, dt, ag, k=1e8, fy=1e5, max_iterations=0)
    with pytest.raises(aemstep.MassNotSpd):
        aemstep.shear_building([1e5, -1.0, 1e5], c, dt, ag, k=1e8, fy=1e5)
    with pytest.raises(aemstep.ShapeError):
        aemstep.shear_building(masses, c, dt, ag, k=[1e8, 1e8], fy=1e5)
    with pytest.raises(aemstep.NonFiniteInput):
        bad = ag.copy()
        bad[10] = np.nan
        aemstep.shear_building(masses, c, dt, bad, k=1e8, fy=1e5)


def test_without_the_energy_account_the_run_is_the_same(elcentro):
    ag, dt = elcentro
    masses, m, k, c = three_storey()
    kw = dict(k=1e8, fy=[6e5, 5e5, 3.5e5], alpha=0.05)
    a = aemstep.shear_building(masses, c, dt, ag, **kw)
    b = aemstep.shear_building(masses, c, dt, ag, energy=False, **kw)
    assert b.energy is None and a.energy is not None
    assert np.array_equal(a.u, b.u) and np.array_equal(a.iterations, b.iterations)


@pytest.mark.parametrize("energy", [False, True])
def test_without_histories_the_peaks_are_those_of_the_histories(elcentro, energy):
    """histories=False keeps no per-step arrays; its peaks and iteration count are
    bitwise those computed from the full run's histories (drifts as np.diff forms them)."""
    ag, dt = elcentro
    masses, m, k, c = three_storey()
    kw = dict(k=1e8, fy=[6e5, 5e5, 3.5e5], alpha=0.05, energy=energy)
    full = aemstep.shear_building(masses, c, dt, ag, **kw)
    bare = aemstep.shear_building(masses, c, dt, ag, histories=False, **kw)
    assert bare.u is None and bare.v is None and bare.a is None
    assert bare.drifts is None and bare.iterations is None
    drifts = np.diff(full.u, axis=1, prepend=0.0)
    assert np.array_equal(full.drifts, drifts)
    peaks = np.abs(drifts).max(axis=0)
    assert np.array_equal(bare.peak_drifts, peaks) and np.array_equal(full.peak_drifts, peaks)
    assert bare.peak_drift == full.peak_drift == peaks.max()
    assert bare.total_iterations == full.total_iterations == int(full.iterations.sum())
    assert (peaks > np.array([6e5, 5e5, 3.5e5]) / 1e8).any()  # a storey yields
    if energy:
        for name in ("input", "kinetic", "recoverable", "viscous", "hysteretic", "balance_error"):
            assert getattr(bare.energy, name).shape == (1,)
            assert getattr(bare.energy, name)[0] == getattr(full.energy, name)[-1]
        assert bare.energy.initial == full.energy.initial
    else:
        assert bare.energy is None
