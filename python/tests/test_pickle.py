"""Every aemstep exception survives pickle with its class and attributes, so an error raised
in a worker process (concurrent.futures, Dask) reaches the caller as itself: the caller's
``except aemstep.AemstepError`` catches it, ``.step``/``.line``/``.parameter`` say where."""

import pickle
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

import aemstep

ONE = np.ones((1, 1))

#: Every exception class the package raises: the base, the shape errors, one per variant.
CLASSES = ["AemstepError", "ShapeError", "UnsupportedSize", "InvalidArgument", *aemstep.ERROR_VARIANTS]


def record(bad_at=None, steps=10):
    """A load record on one degree of freedom (N), NaN at step ``bad_at`` if given."""
    p = np.zeros((steps, 1))
    p[1] = 1.0
    if bad_at is not None:
        p[bad_at] = np.nan
    return p


def roundtrip(e):
    return pickle.loads(pickle.dumps(e, protocol=pickle.HIGHEST_PROTOCOL))


@pytest.mark.parametrize("name", CLASSES)
def test_every_class_round_trips_with_its_attributes(name):
    cls = getattr(aemstep, name)
    # Importable as aemstep.<name>: the name pickle stores.
    assert cls.__module__ == "aemstep" and cls.__qualname__ == name
    e = cls(f"{name}: a message")
    e.step, e.line, e.parameter = 6, 12, "RhoInf"
    back = roundtrip(e)
    assert type(back) is cls
    assert back.args == e.args and str(back) == str(e)
    assert (back.step, back.line, back.parameter) == (6, 12, "RhoInf")
    assert isinstance(back, aemstep.AemstepError) and isinstance(back, ValueError)


def raised(call):
    with pytest.raises(aemstep.AemstepError) as info:
        call()
    return info.value


def test_errors_the_library_raises_round_trip():
    step = raised(lambda: aemstep.linear_response(ONE, ONE, ONE, 0.01, p=record(bad_at=6)))
    line = raised(lambda: aemstep.read_column("0.1\nx\n", 0.01))
    param = raised(lambda: aemstep.linear_response(
        ONE, ONE, ONE, 0.01, p=record(), scheme="hht", alpha=0.5))
    shape = raised(lambda: aemstep.linear_response(np.eye(2), np.eye(3), np.eye(2), 0.01,
                                                   p=np.zeros((3, 2))))
    for e, attr, value in [(step, "step", 6), (line, "line", 2), (param, "parameter", "HhtAlpha")]:
        back = roundtrip(e)
        assert type(back) is type(e) and str(back) == str(e)
        assert getattr(back, attr) == value
    assert type(roundtrip(shape)) is aemstep.ShapeError
    assert type(step) is aemstep.NonFiniteInput and type(line) is aemstep.MalformedRecord
    assert type(param) is aemstep.InvalidParameter


def test_a_process_pool_reports_the_bad_record_and_stays_usable():
    records = [record(), record(bad_at=4), record()]
    with ProcessPoolExecutor(max_workers=1) as pool:
        futures = [pool.submit(aemstep.linear_response, ONE, ONE, ONE, 0.01, p=p)
                   for p in records]
        caught = []
        for f in futures:
            try:
                f.result()
            except aemstep.AemstepError as e:
                caught.append(e)
        assert len(caught) == 1
        assert type(caught[0]) is aemstep.NonFiniteInput and caught[0].step == 4
        # The pool is not broken: the next task runs and equals the run in this process.
        u, _, _ = pool.submit(aemstep.linear_response, ONE, ONE, ONE, 0.01, p=records[0]).result()
    assert np.array_equal(u, aemstep.linear_response(ONE, ONE, ONE, 0.01, p=records[0])[0])


def test_a_dask_worker_process_error_is_caught_as_aemstep_error():
    distributed = pytest.importorskip(
        "distributed", reason="dask.distributed is not installed (pip install 'dask[distributed]')"
    )
    # One worker process: the error crosses a process boundary, so only pickle carries it.
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=":0") as cluster, \
            distributed.Client(cluster) as client:
        bad = client.submit(aemstep.linear_response, ONE, ONE, ONE, 0.01, p=record(bad_at=7))
        good = client.submit(aemstep.linear_response, ONE, ONE, ONE, 0.01, p=record())
        with pytest.raises(aemstep.AemstepError) as info:
            bad.result()
        assert type(info.value) is aemstep.NonFiniteInput and info.value.step == 7
        assert good.result()[0].shape == (10, 1)
        line = client.submit(aemstep.read_column, "0.1\n0.2\nx\n", 0.01)
        with pytest.raises(aemstep.MalformedRecord) as info:
            line.result()
        assert info.value.line == 3
