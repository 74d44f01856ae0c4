"""Models of any size (issue 34): ``linear_response`` with the AEM and ``shear_building``
take any ``n``.

Sizes outside ``aemstep.SIZES`` run on the Rust library's run-time-sized ``DynLinear``,
which shares the const-generic ``Linear``'s build and step code (``tests/runtime_size.rs``
checks the two bit for bit in Rust). Here: sizes 11, 13 and 37 against a numpy
average-acceleration Newmark loop written from the equations, and every compiled size
against the run-time path bit for bit (the compiled model plus decoupled degrees of
freedom: the zero couplings add exact zeros to every sum, so the compiled degrees of
freedom must come out with the same bits).
"""

import numpy as np
import pytest

import aemstep


def chain(n, seed=0):
    """A non-symmetric, well-conditioned model of ``n`` degrees of freedom (kg, N·s/m, N/m)."""
    rng = np.random.default_rng(seed + n)
    m = np.diag(1.0 + 0.3 * (np.arange(n) % 3)) + 0.05 * (np.eye(n, k=1) + np.eye(n, k=-1))
    k = np.diag(2000.0 + 10.0 * np.arange(n)) - 900.0 * (np.eye(n, k=1) + np.eye(n, k=-1))
    k += 5.0 * (rng.random((n, n)) - 0.5)
    skew = 0.01 * (np.arange(n)[:, None] - np.arange(n)[None, :])
    return m, 0.1 * m + 0.002 * k + skew, k


def loads(n, steps, h):
    t = np.arange(steps)[:, None] * h
    j = np.arange(n)[None, :]
    return np.sin(7.3 * t + 0.7 * j) * (1.0 + 0.1 * j) + 0.3


def newmark_average(m, c, k, h, p, u0, v0):
    """β = 1/4, γ = 1/2 from the equations: solve
    ``(M + h/2 C + h²/4 K) a_n = p_n − C (v + h/2 a) − K (u + h v + h²/4 a)`` each step."""
    u, v = u0.copy(), v0.copy()
    a = np.linalg.solve(m, p[0] - c @ v - k @ u)
    eff = m + 0.5 * h * c + 0.25 * h * h * k
    us, vs, as_ = [u], [v], [a]
    for pn in p[1:]:
        vh = v + 0.5 * h * a
        uh = u + h * v + 0.25 * h * h * a
        a = np.linalg.solve(eff, pn - c @ vh - k @ uh)
        u, v = uh + 0.25 * h * h * a, vh + 0.5 * h * a
        us.append(u)
        vs.append(v)
        as_.append(a)
    return np.array(us), np.array(vs), np.array(as_)


@pytest.mark.parametrize("n", [11, 13, 37])
def test_sizes_outside_the_compiled_list_match_a_numpy_newmark_loop(n):
    assert n not in aemstep.SIZES
    h, steps = 0.01, 300
    m, c, k = chain(n)
    p = loads(n, steps, h)
    u0, v0 = 0.001 * np.arange(n), -0.01 + 0.003 * np.arange(n)
    r = aemstep.linear_response(m, c, k, h, p=p, u0=u0, v0=v0)
    assert r.u.shape == (steps, n)
    ref = newmark_average(m, c, k, h, p, u0, v0)
    # The same recurrence in float64 by different operations (precomputed G, GC, GK
    # against a solve per step): rounding, a few n·ε per step, accumulating as a random
    # walk: bound √steps · n · ε (1.4e-13 at n = 37). Measured: 1.1e-14 (u, n = 37),
    # 2.9e-15 (n = 11), 2.1e-15 (n = 13).
    bound = np.sqrt(steps) * n * np.finfo(float).eps
    for got, want in zip((r.u, r.v, r.a), ref):
        err = np.abs(got - want).max() / np.abs(want).max()
        print(f"n = {n}: relative difference {err:.1e} (bound {bound:.1e})")
        assert err < bound


def test_every_compiled_size_equals_the_run_time_path_bit_for_bit():
    h, steps = 0.01, 200
    for n in aemstep.SIZES:
        # Pad with decoupled unit oscillators up to a size that is not compiled in.
        big = next(s for s in range(n + 1, 100) if s not in aemstep.SIZES)
        m, c, k = chain(n)
        mb, cb, kb = (np.eye(big) for _ in range(3))
        for a, b in ((mb, m), (cb, c), (kb, k)):
            a[:n, :n] = b
        cb[n:, n:] = 0.1 * np.eye(big - n)
        p = loads(big, steps, h)
        u0, v0 = 0.001 * np.arange(big), -0.01 + 0.003 * np.arange(big)
        compiled = aemstep.linear_response(m, c, k, h, p=p[:, :n], u0=u0[:n], v0=v0[:n])
        run_time = aemstep.linear_response(mb, cb, kb, h, p=p, u0=u0, v0=v0)
        for got, want in ((run_time.u, compiled.u), (run_time.v, compiled.v),
                          (run_time.a, compiled.a)):
            assert np.array_equal(got[:, :n].view(np.uint64), want.view(np.uint64)), n


def test_any_size_keeps_the_errors_of_the_compiled_sizes():
    n = 23
    m, c, k = chain(n)
    p = loads(n, 10, 0.01)
    with pytest.raises(aemstep.InvalidTimeStep):
        aemstep.linear_response(m, c, k, 0.0, p=p)
    with pytest.raises(aemstep.SingularEffectiveMatrix):
        z = np.zeros((n, n))
        aemstep.linear_response(z, z, z, 0.01, p=p)
    bad = p.copy()
    bad[4, 7] = np.nan
    with pytest.raises(aemstep.NonFiniteInput) as e:
        aemstep.linear_response(m, c, k, 0.01, p=bad)
    assert e.value.step == 4
    # The other schemes are compiled for SIZES only.
    with pytest.raises(aemstep.UnsupportedSize, match="aem"):
        aemstep.linear_response(m, c, k, 0.01, p=p, scheme="newmark")


# ---------------------------------------------------------------------------------------
# The yielding shear building at any size: sizes outside ``SIZES`` run the Rust library's
# run-time-sized ``DynShearBuilding`` / ``DynNonlinear``, which share the compiled
# stepper's per-step code (``tests/runtime_size.rs`` checks them bit for bit in Rust).

H_B, STEPS_B = 0.005, 400


def building(n):
    """Floor masses (kg), storey stiffnesses (N/m) and yield forces (N), Rayleigh damping
    ``0.3 M + 0.002 K`` (N·s/m), as in ``tests/runtime_size.rs``."""
    masses = 1e5 * (1.0 + 0.1 * (np.arange(n) % 3))
    ks = 2e8 * (1.0 - 0.5 * np.arange(n) / n)
    fy = 3.0e5 * (n - np.arange(n))
    k = np.diag(ks + np.append(ks[1:], 0.0)) - np.diag(ks[1:], 1) - np.diag(ks[1:], -1)
    return masses, ks, fy, k, 0.3 * np.diag(masses) + 0.002 * k


def ground(steps):
    t = np.arange(steps) * H_B
    return 5.0 * np.sin(9.0 * t) + 2.0 * np.sin(23.0 * t)


def newton_newmark_bilinear(masses, ks, fy, alpha, c, ag):
    """The average-acceleration Newmark step (β = 1/4, γ = 1/2) with Newton on the
    acceleration and bilinear storeys with kinematic hardening by the return mapping
    (Simo & Hughes 1998, §1.4: ``H = α k/(1 − α)``, trial ``f = k (δ − δ_p)``,
    ``ξ = f − H δ_p``; if ``|ξ| > f_y``: ``δ_p += (|ξ| − f_y)/(k + H) sgn ξ``, tangent
    ``α k``), written from the equations. Newton until the correction is below 1e-15 of
    the acceleration. Returns ``u`` at every sample."""
    n = masses.size
    m = np.diag(masses)
    hard = alpha * ks / (1.0 - alpha)

    def storeys(u, dp):
        drift = np.diff(u, prepend=0.0)
        trial = ks * (drift - dp)
        xi = trial - hard * dp
        over = np.abs(xi) > fy
        dp_new = np.where(over, dp + (np.abs(xi) - fy) / (ks + hard) * np.sign(xi), dp)
        f = ks * (drift - dp_new)
        kt = np.where(over, ks * hard / (ks + hard), ks)
        fs = f - np.append(f[1:], 0.0)
        k = np.diag(kt + np.append(kt[1:], 0.0)) - np.diag(kt[1:], 1) - np.diag(kt[1:], -1)
        return fs, k, dp_new

    u, v, dp = np.zeros(n), np.zeros(n), np.zeros(n)
    a = np.linalg.solve(m, -masses * ag[0])
    out = [u]
    for g in ag[1:]:
        p = -masses * g
        vh, uh = v + 0.5 * H_B * a, u + H_B * v + 0.25 * H_B * H_B * a
        q = a.copy()
        for _ in range(50):
            fs, k, _ = storeys(uh + 0.25 * H_B * H_B * q, dp)
            r = m @ q + c @ (vh + 0.5 * H_B * q) + fs - p
            delta = np.linalg.solve(m + 0.5 * H_B * c + 0.25 * H_B * H_B * k, r)
            q = q - delta
            if np.abs(delta).max() <= 1e-15 * np.abs(q).max():
                break
        u, v, a = uh + 0.25 * H_B * H_B * q, vh + 0.5 * H_B * q, q
        dp = storeys(u, dp)[2]
        out.append(u)
    return np.array(out)


@pytest.mark.parametrize("n", [11, 13, 37])
@pytest.mark.parametrize("case", ["elastic", "yielding"])
def test_shear_building_outside_the_compiled_sizes_matches_numpy(n, case):
    assert n not in aemstep.SIZES
    masses, ks, fy, k, c = building(n)
    ag = ground(STEPS_B)
    if case == "elastic":
        # A yield force no record reaches: the linear building, whose reference is the
        # plain average-acceleration Newmark loop above (``newmark_average``).
        fy = np.full(n, 1e15)
        p = -np.outer(ag, masses)
        want = newmark_average(np.diag(masses), c, k, H_B, p, np.zeros(n), np.zeros(n))[0]
    else:
        want = newton_newmark_bilinear(masses, ks, fy, 0.05, c, ag)
    r = aemstep.shear_building(masses, c, H_B, ag, k=ks, fy=fy, alpha=0.05)
    assert r.u.shape == (STEPS_B, n)
    # Storeys linear (elastic) or piecewise linear with the exact tangent (bilinear): a
    # Newton iterate on the solution's branches solves the step up to rounding, and the
    # library stops there (its tolerance 1e-10 is far above that floor). So both loops
    # compute the same recurrence by different operations (banded L D Lᵀ against dense
    # LU): rounding, a few n·ε a step, accumulating as a random walk: bound
    # √steps · n · ε (1.6e-13 at n = 37). Measured: printed.
    bound = np.sqrt(STEPS_B) * n * np.finfo(float).eps
    err = np.abs(r.u - want).max() / np.abs(want).max()
    print(f"n = {n}, {case}: relative difference {err:.1e} (bound {bound:.1e})")
    assert err < bound
    if case == "yielding":
        assert r.energy.hysteretic[-1] > 0.0  # it yielded
    # The energy account runs on the run-time path too, its balance at the Newton
    # tolerance's scale.
    assert np.abs(r.energy.balance_error).max() <= 1e-6 * np.abs(r.energy.input).max()


PARAMS = {
    "bilinear": lambda ks, fy: np.column_stack([ks, fy, np.full(ks.size, 0.05)]),
    "bouc_wen": lambda ks, fy: np.column_stack(
        [ks, fy, np.full(ks.size, 0.05), np.full(ks.size, 0.5), np.full(ks.size, 0.5),
         np.full(ks.size, 2.0)]),
    "bilinear_friction": lambda ks, fy: np.column_stack(
        [ks, fy, np.full(ks.size, 0.05), 0.1 * fy, np.full(ks.size, 0.01)]),
}


@pytest.mark.parametrize("law", sorted(PARAMS))
def test_compiled_sizes_equal_the_run_time_path_bit_for_bit(law):
    native = aemstep._aemstep.shear_building
    ag = ground(STEPS_B)
    for n, full in [(1, False), (2, False), (3, False), (4, False), (5, False), (12, False),
                    (20, False), (5, True)]:
        masses, ks, fy, _, c = building(n)
        if full:  # a damping matrix that is not tridiagonal: the dense Newton path
            c = c + 1e3 / (1.0 + np.abs(np.subtract.outer(np.arange(n), np.arange(n))))
        args = (masses, law, PARAMS[law](ks, fy), c, H_B, ag)
        compiled = native(*args)
        run_time = native(*args, compiled=False)
        assert compiled["total_iterations"] == run_time["total_iterations"]
        for key in ("u", "v", "a", "drifts", "iterations", "peak_drifts"):
            assert np.array_equal(compiled[key].view(np.uint64),
                                  run_time[key].view(np.uint64)), (law, n, key)
        # The energy account, bit for bit too (the run-time account sums n = 2, 3, 4 in
        # nalgebra's fixed-size order, as the compiled one does).
        assert np.array_equal(compiled["energy"].view(np.uint64),
                              run_time["energy"].view(np.uint64)), (law, n)
        peaks = native(*args, energy=False, histories=False, compiled=False)
        assert np.array_equal(peaks["peak_drifts"], compiled["peak_drifts"])


def test_shear_building_any_size_keeps_the_errors_of_the_compiled_sizes():
    n = 37
    masses, ks, fy, _, c = building(n)
    ag = ground(200)
    with pytest.raises(aemstep.InvalidTimeStep):
        aemstep.shear_building(masses, c, 0.0, ag, k=ks, fy=fy)
    with pytest.raises(aemstep.InvalidMaterial):
        aemstep.shear_building(masses, c, H_B, ag, k=ks, fy=-fy)
    with pytest.raises(aemstep.MassNotSpd):
        aemstep.shear_building(-masses, c, H_B, ag, k=ks, fy=fy)
    bad = ag.copy()
    bad[17] = np.nan
    with pytest.raises(aemstep.NonFiniteInput) as e:
        aemstep.shear_building(masses, c, H_B, bad, k=ks, fy=fy)
    assert e.value.step == 17
    # One Newton iteration a step: refused at the first step on which a storey yields,
    # the same step at a compiled size and the run-time path (``compiled=False``).
    native = aemstep._aemstep.shear_building
    with pytest.raises(aemstep.NotConverged) as e:
        native(masses, "bilinear", PARAMS["bilinear"](ks, fy), c, H_B, 3.0 * ground(400),
               max_iterations=1)
    assert e.value.step > 1
    m5, k5, f5, _, c5 = building(5)
    steps = []
    for compiled in (True, False):
        with pytest.raises(aemstep.NotConverged) as e:
            native(m5, "bilinear", PARAMS["bilinear"](k5, f5), c5, H_B, 3.0 * ground(400),
                   max_iterations=1, compiled=compiled)
        steps.append(e.value.step)
    assert steps[0] == steps[1]


def test_a_run_time_sized_building_too_large_for_memory_is_a_memory_error():
    try:
        info = dict(line.split(":", 1) for line in open("/proc/meminfo"))
    except OSError:
        pytest.skip("no /proc/meminfo")
    kb = lambda key: int(info.get(key, "0 kB").split()[0])  # noqa: E731
    limit = (kb("MemTotal") + kb("SwapTotal")) * 1024
    n = 37  # u, v, a and drifts: 4·37·8 bytes a step; the record's pages never touched
    ag = np.zeros(limit // (4 * n * 8) + 1)
    with pytest.raises(MemoryError, match="shear_building: the outputs would take"):
        aemstep.shear_building(np.ones(n), np.zeros((n, n)), 0.01, ag, k=1e8, fy=1e5)
