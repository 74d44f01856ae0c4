"""Models of any size (issue 34): ``linear_response`` with the AEM takes any ``n``.

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
