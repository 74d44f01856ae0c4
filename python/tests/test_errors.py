"""Every library error a Python exception of its variant's name, message its Display."""

import re

import numpy as np
import pytest

import aemstep
from conftest import ROOT


def rust_variants():
    """The variant names of `enum Error` read from the library's source."""
    src = (ROOT / "src" / "error.rs").read_text()
    body = src[src.index("pub enum Error {"):src.index("\n}\n", src.index("pub enum Error {"))]
    return re.findall(r"^    ([A-Z][A-Za-z]+)\b", body, flags=re.M)


def test_every_variant_is_an_exception_class():
    names = rust_variants()
    assert len(names) >= 25
    assert list(aemstep.ERROR_VARIANTS) == names
    for name in names:
        cls = getattr(aemstep, name)
        assert issubclass(cls, aemstep.AemstepError) and issubclass(cls, ValueError)
        assert cls.__name__ == name
    assert issubclass(aemstep.UnsupportedSize, aemstep.ShapeError)
    assert issubclass(aemstep.ShapeError, aemstep.AemstepError)


ONE = np.array([[1.0]])


@pytest.mark.parametrize(
    "exc, message, call",
    [
        (aemstep.InvalidTimeStep, "the time step h must be finite and > 0",
         lambda: aemstep.linear_response(ONE, ONE, ONE, -0.01, p=np.zeros((3, 1)))),
        (aemstep.NonFiniteInput, "an input has a NaN or infinite entry",
         lambda: aemstep.linear_response([[np.nan]], ONE, ONE, 0.01, p=np.zeros((3, 1)))),
        (aemstep.SingularEffectiveMatrix, "the effective matrix M + (h/2)C + (h^2/4)K is singular",
         lambda: aemstep.linear_response(0 * ONE, 0 * ONE, 0 * ONE, 0.01, p=np.zeros((3, 1)))),
        (aemstep.SingularMass, "the mass matrix M is singular: start with a known initial acceleration",
         lambda: aemstep.linear_response(0 * ONE, ONE, ONE, 0.01, p=np.zeros((3, 1)))),
        (aemstep.MassNotSpd, "the mass matrix M is not symmetric positive definite",
         lambda: aemstep.linear_response(-ONE, ONE, ONE, 0.01, p=np.zeros((3, 1)), scheme="modal")),
        (aemstep.StiffnessNotSymmetric, "the stiffness matrix K is not symmetric",
         lambda: aemstep.linear_response(np.eye(2), np.zeros((2, 2)), [[2.0, -1.0], [0.0, 1.0]], 0.01,
                                         p=np.zeros((3, 2)), scheme="modal")),
        (aemstep.NonClassicalDamping,
         "the damping is not classical (it couples the modes): use the full stepper",
         lambda: aemstep.linear_response(np.eye(2), [[1.0, 0.0], [0.0, 0.0]], [[2.0, -1.0], [-1.0, 1.0]],
                                         0.01, p=np.zeros((3, 2)), scheme="modal")),
        (aemstep.InvalidParameter, "invalid parameter: HHT alpha must be in [-1/3, 0]",
         lambda: aemstep.linear_response(ONE, ONE, ONE, 0.01, p=np.zeros((3, 1)), scheme="hht", alpha=0.5)),
        (aemstep.NonFiniteState, "the step would make the state NaN or infinite; state unchanged",
         lambda: aemstep.linear_response(1e-3 * ONE, ONE, ONE, 0.01, p=np.array([[0.0], [1e308], [1e308]]))),
        (aemstep.InvalidCovariance, "a covariance is not finite, symmetric and positive (semi)definite",
         lambda: aemstep.observe(ONE, ONE, ONE, 0.01, np.zeros(3), np.zeros((3, 1)), [0],
                                 sigma_f=1.0, sigma_y=0.0)),
    ],
)
def test_variants_raised_with_their_display(exc, message, call):
    with pytest.raises(exc) as info:
        call()
    assert str(info.value) == message
    assert type(info.value).__name__ == exc.__name__


def test_an_invalid_parameter_names_it():
    with pytest.raises(aemstep.InvalidParameter) as info:
        aemstep.linear_response(ONE, ONE, ONE, 0.01, p=np.zeros((3, 1)), scheme="hht", alpha=0.5)
    assert info.value.parameter == "HhtAlpha"
    with pytest.raises(aemstep.InvalidMaterial) as info:
        aemstep.shear_building([1e5], [[0.0]], 0.01, np.zeros(10), k=1e8, fy=-1.0)
    assert info.value.parameter == "YieldForce"


def test_a_failed_step_says_which():
    p = np.zeros((10, 1))
    p[6] = np.nan
    with pytest.raises(aemstep.NonFiniteInput) as info:
        aemstep.linear_response(ONE, ONE, ONE, 0.01, p=p)
    assert info.value.step == 6


def test_shapes_are_checked_before_anything_runs():
    with pytest.raises(aemstep.ShapeError, match="c must be 2x2"):
        aemstep.linear_response(np.eye(2), np.eye(3), np.eye(2), 0.01, p=np.zeros((3, 2)))
    with pytest.raises(aemstep.ShapeError, match="p must be steps x 2"):
        aemstep.linear_response(np.eye(2), np.eye(2), np.eye(2), 0.01, p=np.zeros((3, 3)))
    with pytest.raises(aemstep.ShapeError):
        aemstep.linear_response(np.eye(2), np.eye(2), np.eye(2), 0.01, p=np.zeros((0, 2)))
    with pytest.raises(aemstep.ShapeError):
        aemstep.linear_response(np.eye(2), np.eye(2), np.eye(2), 0.01)
    with pytest.raises(ValueError, match="unknown scheme"):
        aemstep.linear_response(ONE, ONE, ONE, 0.01, p=np.zeros((3, 1)), scheme="rk4")
    with pytest.raises(aemstep.UnsupportedSize):
        aemstep.observe(np.eye(5), np.eye(5), np.eye(5), 0.01, np.zeros(3), np.zeros((3, 4)),
                        [0, 1, 2, 3], sigma_f=1.0, sigma_y=1.0)


def test_empty_and_degenerate_inputs_raise_typed_errors_never_crash():
    ag = np.sin(np.arange(100) * 0.3)
    with pytest.raises(aemstep.ShapeError):
        aemstep.spectrum([], 0.05, 0.02, ag)
    with pytest.raises(aemstep.ShapeError):
        aemstep.constant_strength([], 0.05, 0.02, ag, [])
    with pytest.raises(aemstep.ShapeError):
        aemstep.shear_building([1e5], [[0.0]], 0.01, [], k=1e8, fy=1e5)
    with pytest.raises(aemstep.ShapeError):
        aemstep.shear_building([], np.zeros((0, 0)), 0.01, ag, k=1e8, fy=1e5)
    with pytest.raises(aemstep.InvalidParameter):
        aemstep.constant_strength([1.0], 0.05, 0.02, [], 4.0)  # no record: at rest
    with pytest.raises(aemstep.InvalidParameter):
        aemstep.constant_strength([1.0], 0.05, 0.02, ag, 4.0, points_per_period=0)
    with pytest.raises(aemstep.ShapeError):
        aemstep.observe(ONE, ONE, ONE, 0.01, [], np.zeros((0, 1)), [0], sigma_f=1.0, sigma_y=1.0)
    with pytest.raises(aemstep.UnsupportedSize):
        aemstep.linear_response(np.zeros((0, 0)), np.zeros((0, 0)), np.zeros((0, 0)), 0.01,
                                p=np.zeros((3, 0)))
    # An empty record gives zero spectra, an empty list of records empty arrays.
    assert np.all(aemstep.spectrum([1.0], 0.05, 0.02, []).sd == 0)
    assert aemstep.spectra([1.0], 0.05, 0.02, []).sd.shape == (0, 1)
    # NaN samples raise NonFiniteInput with .step in spectra too (issue 34); skipped
    # (held at the last finite one) only with nan="skip" (python/tests/test_nan.py).
    bad = ag.copy()
    bad[5] = np.nan
    with pytest.raises(aemstep.NonFiniteInput) as e:
        aemstep.spectrum([0.5, 1.0], 0.05, 0.02, bad)
    assert e.value.step == 5
    assert np.all(np.isfinite(aemstep.spectrum([0.5, 1.0], 0.05, 0.02, bad, nan="skip").sd))
