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
    # A free-vibration tail longer than aemstep's MAX_FREE_VIBRATION_SAMPLES (2**20; one
    # 3 s period at h = 1e-8 s is 3e8 samples, at 1e-300 s 2**32 - 1) is refused at once
    # with InvalidTimeStep, as the Rust record-level calls do, not stepped for hours.
    rec = [0.1, 0.2, 0.3]
    for h in (1e-8, 1e-300):
        with pytest.raises(aemstep.InvalidTimeStep):
            aemstep.spectrum([3.0], 0.05, h, rec)
        with pytest.raises(aemstep.InvalidTimeStep):
            aemstep.rotd([3.0], 0.05, h, rec, rec)
        # Without the tail, the record alone: three samples.
        assert aemstep.spectrum([3.0], 0.05, h, rec, free_vibration=False).sd.shape == (1,)


# ---------------------------------------------------------------------------------------
# Errors that say which argument and which rule (issue 34).


def test_invalid_parameter_and_material_name_the_rule():
    with pytest.raises(aemstep.InvalidParameter) as info:
        aemstep.linear_response(ONE, ONE, ONE, 0.01, p=np.zeros((3, 1)), scheme="generalized_alpha",
                                rho_inf=2.0)
    assert (info.value.parameter, str(info.value)) == ("RhoInf", "invalid parameter: rho_inf must be in [0, 1]")
    with pytest.raises(aemstep.InvalidMaterial) as info:
        aemstep.shear_building([1e5], [[0.0]], 0.01, np.zeros(10), k=1e8, fy=1e5, alpha=1.5)
    assert info.value.parameter == "PostYieldRatio"
    assert str(info.value) == "invalid material: the post-yield ratio alpha must be in [0, 1)"


@pytest.mark.parametrize(
    "argument, call",
    [
        ("modes", lambda: aemstep.linear_response(ONE, ONE, ONE, 0.01, p=np.zeros((3, 1)),
                                                  scheme="modal", modes=-1)),
        ("max_iterations", lambda: aemstep.shear_building([1e5], [[0.0]], 0.01, np.zeros(10),
                                                          k=1e8, fy=1e5, max_iterations=-3)),
        ("max_iterations", lambda: aemstep.shear_building([1e5], [[0.0]], 0.01, np.zeros(10),
                                                          k=1e8, fy=1e5, max_iterations=2**40)),
        # The Newton budget is capped: a step Ctrl-C cannot split never runs for hours.
        ("max_iterations", lambda: aemstep.shear_building([1e5], [[0.0]], 0.01, np.zeros(10),
                                                          k=1e8, fy=1e5,
                                                          max_iterations=aemstep.MAX_NEWTON_ITERATIONS + 1)),
        ("sensors", lambda: aemstep.observe(ONE, ONE, ONE, 0.01, np.zeros(3), np.zeros((3, 1)), [-1],
                                            sigma_f=1.0, sigma_y=1.0)),
        ("sensors", lambda: aemstep.lqg(np.eye(2), np.eye(2), np.eye(2), [1.0, 0.0], 0.01, [-2],
                                        q=np.eye(4), r=1.0, w=np.eye(4), v=1.0)),
        ("storey", lambda: aemstep.mr_building(ONE, ONE, ONE, np.zeros(5), 0.01, storey=-1)),
        ("modes", lambda: aemstep.linear_response(ONE, ONE, ONE, 0.01, p=np.zeros((3, 1)),
                                                  scheme="modal", modes=1.5)),
    ],
)
def test_negative_or_huge_counts_name_the_argument(argument, call):
    with pytest.raises(aemstep.InvalidArgument) as info:
        call()
    assert info.value.argument == argument
    assert str(info.value).startswith(f"{argument} must be an integer in [0, ")
    assert not isinstance(info.value, OverflowError)


@pytest.mark.parametrize(
    "fragment, call",
    [
        ("m must be square (n x n), got shape (2, 3)",
         lambda: aemstep.linear_response(np.ones((2, 3)), np.eye(2), np.eye(2), 0.01,
                                         ground_acceleration=np.zeros(4))),
        ("influence must have length 2",
         lambda: aemstep.linear_response(np.eye(2), np.eye(2), np.eye(2), 0.01,
                                         ground_acceleration=np.zeros(4), influence=[1.0, 1.0, 1.0])),
        ("fy must be a scalar or have one value per storey (2,), got shape (3,)",
         lambda: aemstep.shear_building([1e5, 1e5], np.zeros((2, 2)), 0.01, np.zeros(4), k=1e8,
                                        fy=[1.0, 2.0, 3.0])),
        ("k must be 2x2, got 3x3",
         lambda: aemstep.observe(np.eye(2), np.eye(2), np.eye(3), 0.01, np.zeros(3), np.zeros((3, 1)), [0],
                                 sigma_f=1.0, sigma_y=1.0)),
        ("measured must be 3 x 1",
         lambda: aemstep.observe(np.eye(2), np.eye(2), np.eye(2), 0.01, np.zeros(3), np.zeros((4, 1)), [0],
                                 sigma_f=1.0, sigma_y=1.0)),
    ],
)
def test_wrong_shapes_are_shape_errors_naming_the_argument(fragment, call):
    with pytest.raises(aemstep.ShapeError) as info:
        call()
    assert fragment in str(info.value)


AT2 = "title\nline 2\nline 3\nNPTS=   3, DT=   .0100 SEC\n  0.1 0.2 0.3\n"


def test_read_at2_takes_a_path_text_or_bytes_never_a_file_descriptor(tmp_path):
    f = tmp_path / "r.AT2"
    f.write_text(AT2)
    for source in (AT2, AT2.encode(), f, str(f)):
        acc, dt = aemstep.read_at2(source)
        assert dt == 0.01 and list(acc) == [0.1, 0.2, 0.3]
    for fd in (0, 5, 3.0, None):
        with pytest.raises(aemstep.InvalidArgument) as info:
            aemstep.read_at2(fd)
        assert info.value.argument == "path_or_text"
        assert "never a file descriptor" in str(info.value)
    with pytest.raises(aemstep.InvalidArgument):
        aemstep.read_column(5, 0.01)


def test_non_utf8_bytes_are_a_malformed_record_at_their_line(tmp_path):
    raw = AT2.encode().replace(b"0.2", b"0.\xff2")
    f = tmp_path / "bad.AT2"
    f.write_bytes(raw)
    for source in (raw, f):
        with pytest.raises(aemstep.MalformedRecord) as info:
            aemstep.read_at2(source)
        assert info.value.line == 5
        assert "not UTF-8" in str(info.value) and "line 5" in str(info.value)
    with pytest.raises(aemstep.MalformedRecord) as info:
        aemstep.read_column(b"0.1\n\xc3\n", 0.01)
    assert info.value.line == 2


# ---------------------------------------------------------------------------------------
# Sizes checked before allocating (issue 34): MemoryError, never an abort.


def machine_memory():
    """MemTotal + SwapTotal (bytes), the limit the native calls check against."""
    try:
        info = dict(line.split(":", 1) for line in open("/proc/meminfo"))
    except OSError:
        pytest.skip("no /proc/meminfo")
    kb = lambda key: int(info.get(key, "0 kB").split()[0])  # noqa: E731
    return (kb("MemTotal") + kb("SwapTotal")) * 1024


def test_a_shear_building_too_large_for_memory_is_a_memory_error():
    # 20 storeys: u, v, a and drifts are 4·20·8 = 640 bytes a step; the record (zeros,
    # pages never touched) is 1/80 of the machine's memory, its histories more than all.
    steps = machine_memory() // 640 + 1
    ag = np.zeros(steps)
    with pytest.raises(MemoryError, match="shear_building: the outputs would take"):
        aemstep.shear_building(np.ones(20), np.zeros((20, 20)), 0.01, ag, k=1e8, fy=1e5)
    # Without histories nothing a step is kept: the same record is no longer too large
    # (stopped at once here by a bad parameter, after the size check).
    with pytest.raises(aemstep.InvalidMaterial):
        aemstep.shear_building(np.ones(20), np.zeros((20, 20)), 0.01, ag, k=1e8, fy=-1.0,
                               histories=False)


def test_linear_and_observer_outputs_too_large_are_memory_errors():
    limit = machine_memory()
    # p (a third of the memory, zero pages never touched) and three histories like it.
    steps = limit // 3 // 8 + 1
    p = np.zeros((steps, 1))
    with pytest.raises(MemoryError, match="linear_response"):
        aemstep.linear_response(ONE, ONE, ONE, 0.01, p=p)
    ag = np.zeros(limit // 32 + 1)
    y = np.zeros((ag.size, 1))
    with pytest.raises(MemoryError, match="observe"):
        aemstep.observe(ONE, ONE, ONE, 0.01, ag, y, [0], sigma_f=1.0, sigma_y=1.0)
    with pytest.raises(MemoryError, match="mr_building"):
        aemstep.mr_building(ONE, ONE, ONE, ag, 0.01)


def test_invalid_argument_pickles_with_its_argument():
    import pickle

    with pytest.raises(aemstep.InvalidArgument) as info:
        aemstep.read_at2(5)
    back = pickle.loads(pickle.dumps(info.value))
    assert type(back) is aemstep.InvalidArgument and back.argument == "path_or_text"
    assert str(back) == str(info.value)
