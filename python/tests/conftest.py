"""Shared fixtures: the El Centro 1940 NS record from the repository's data/ folder."""

from pathlib import Path

import numpy as np
import pytest

import aemstep

#: The repository root (python/tests/ is two levels below it).
ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def elcentro():
    """``(ground acceleration in m/s², dt in s)``: the AT2 record is in g at dt = 0.02 s."""
    acc, dt = aemstep.read_at2(ROOT / "data" / "elcentro-ns-1940.AT2")
    assert dt == 0.02 and acc.shape == (3995,)
    return acc * aemstep.G, dt


def newmark_average(m, c, k, h, p, u0=None, v0=None):
    """A plain numpy Newmark average-acceleration (β = 1/4, γ = 1/2) loop, written here
    independently of the library: the AEM is this rule for linear systems."""
    n = m.shape[0]
    u = np.zeros((p.shape[0], n))
    v = np.zeros_like(u)
    a = np.zeros_like(u)
    u[0] = np.zeros(n) if u0 is None else u0
    v[0] = np.zeros(n) if v0 is None else v0
    a[0] = np.linalg.solve(m, p[0] - c @ v[0] - k @ u[0])
    keff = m * 4 / h**2 + c * 2 / h + k
    for i in range(1, p.shape[0]):
        rhs = p[i] + m @ (4 / h**2 * u[i - 1] + 4 / h * v[i - 1] + a[i - 1]) + c @ (
            2 / h * u[i - 1] + v[i - 1]
        )
        u[i] = np.linalg.solve(keff, rhs)
        v[i] = 2 / h * (u[i] - u[i - 1]) - v[i - 1]
        a[i] = 4 / h**2 * (u[i] - u[i - 1]) - 4 / h * v[i - 1] - a[i - 1]
    return u, v, a


def shear_matrices(masses, stiffness):
    """Mass and stiffness matrices of a shear building (ground storey first)."""
    n = len(masses)
    m = np.diag(np.asarray(masses, dtype=float))
    k = np.zeros((n, n))
    for i, ki in enumerate(stiffness):
        k[i, i] += ki
        if i > 0:
            k[i - 1, i - 1] += ki
            k[i - 1, i] -= ki
            k[i, i - 1] -= ki
    return m, k


def rayleigh(m, k, xi, modes=(0, 1)):
    """Rayleigh damping with ratio ``xi`` in two modes (one mode: stiffness-proportional)."""
    w = np.sqrt(np.sort(np.linalg.eigvals(np.linalg.solve(m, k)).real))
    if len(w) == 1:
        return 2 * xi / w[0] * k
    wi, wj = w[modes[0]], w[modes[1]]
    a0 = 2 * xi * wi * wj / (wi + wj)
    a1 = 2 * xi / (wi + wj)
    return a0 * m + a1 * k
