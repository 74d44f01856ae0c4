"""The inelastic spectra step their oscillators in SIMD lanes, packed by the search (only
the unfinished trials of a constant-ductility pass are stepped, 4 a group): a period's
result must not depend on which other periods share its bank, its lanes or its passes.
Each period computed alone (one oscillator, the rest of its bank padding) must give the
bits of the same period within 20 others, for both laws, under ``nan="skip"``, on 1 and
2 threads."""

import os

import numpy as np
import pytest

import aemstep

G = 9.80665
H = 0.02


def elcentro(n):
    here = os.path.dirname(os.path.abspath(__file__))
    path = os.path.join(here, "..", "..", "data", "elcentro-ns-1940.txt")
    vals = [float(l) for l in open(path) if l.strip() and not l.startswith("#")]
    return np.array(vals[:n]) * G


PERIODS = 0.05 * 40.0 ** (np.arange(20) / 19.0)


@pytest.mark.parametrize("alpha", [0.0, 0.05])
def test_constant_ductility_does_not_depend_on_the_lanes(alpha):
    ag = elcentro(400)
    ag[[3, 100, 101]] = np.nan
    for mu in (2.0, 4.0):
        together = aemstep.constant_ductility(PERIODS, 0.05, H, ag, mu, alpha=alpha, threads=2, nan="skip")
        assert together.skipped == 3
        for i, t in enumerate(PERIODS[::3]):
            j = 3 * i
            alone = aemstep.constant_ductility([t], 0.05, H, ag, mu, alpha=alpha, threads=1, nan="skip")
            assert alone.yield_acceleration[0].tobytes() == together.yield_acceleration[j].tobytes()
            assert alone.elastic[0].tobytes() == together.elastic[j].tobytes()
            assert alone.bracket[0].tobytes() == together.bracket[j].tobytes()
            assert alone.bracket_ductility[0].tobytes() == together.bracket_ductility[j].tobytes()
            assert alone.outcome[0] == together.outcome[j]


@pytest.mark.parametrize("alpha", [0.0, 0.05])
def test_constant_strength_does_not_depend_on_the_lanes(alpha):
    ag = elcentro(500)
    r = np.linspace(1.5, 6.0, PERIODS.shape[0])
    together = aemstep.constant_strength(PERIODS, 0.05, H, ag, r, alpha=alpha, threads=2)
    for j in range(0, PERIODS.shape[0], 4):
        alone = aemstep.constant_strength([PERIODS[j]], 0.05, H, ag, [r[j]], alpha=alpha, threads=1)
        for field in ("elastic", "yield_acceleration", "ductility", "plastic_work"):
            a, b = getattr(alone, field), getattr(together, field)
            assert a[0].tobytes() == b[j].tobytes(), field
