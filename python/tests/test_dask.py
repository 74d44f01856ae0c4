"""The batch functions on a Dask LocalCluster of two worker processes equal the serial
run bit for bit (aemstep.distributed)."""

import numpy as np
import pytest

import aemstep

distributed = pytest.importorskip(
    "distributed", reason="dask.distributed is not installed (pip install 'dask[distributed]')"
)
from aemstep import distributed as ad  # noqa: E402

from test_ida import building, suite  # noqa: E402


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
    )
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def test_the_package_imports_without_dask_until_used():
    import subprocess
    import sys

    code = "import sys, aemstep; assert 'distributed' not in sys.modules and 'dask' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True)


def test_spectra_equal_the_serial_run(client, elcentro):
    recs, dt = suite(elcentro)
    periods = np.linspace(0.05, 3.0, 20)
    serial = aemstep.spectra(periods, 0.05, dt, recs, threads=1)
    # Twice in a row with the same inputs: the shared settings' key must not be lost
    # between the calls (a content-hashed scatter failed the second with "lost dependencies").
    for _ in range(2):
        par = ad.spectra(client, periods, 0.05, dt, recs)
        for a, b in zip(serial, par):
            np.testing.assert_array_equal(a, b)


def test_inelastic_spectra_equal_the_serial_run(client, elcentro):
    recs, dt = suite(elcentro)
    periods = np.linspace(0.1, 2.0, 6)
    cs = ad.constant_strength(client, periods, 0.05, dt, recs, 4.0, alpha=0.02, chunk=2)
    cd = ad.constant_ductility(client, periods, 0.05, dt, recs, 4.0)
    for r, a, b in zip(recs, cs, cd):
        s = aemstep.constant_strength(periods, 0.05, dt, r, 4.0, alpha=0.02)
        d = aemstep.constant_ductility(periods, 0.05, dt, r, 4.0)
        for x, y in zip(s, a):
            np.testing.assert_array_equal(x, y)
        np.testing.assert_array_equal(d.yield_acceleration, b.yield_acceleration)
        assert d.outcome == b.outcome and d.passes == b.passes
    assert len(cs) == len(cd) == len(recs)


def test_spectra_of_a_dataframe_equal_the_serial_run(client, elcentro):
    pd = pytest.importorskip("pandas")
    recs, dt = suite(elcentro)
    n = min(r.shape[0] for r in recs)
    df = pd.DataFrame({f"r{i}": r[:n] for i, r in enumerate(recs)}, index=np.arange(n) * dt)
    periods = np.linspace(0.05, 3.0, 8)
    serial = aemstep.spectra(periods, 0.05, dt, [r[:n] for r in recs], threads=1)
    par = ad.spectra(client, periods, 0.05, records=df)  # h from the index
    for x, y in zip(serial, par):
        np.testing.assert_array_equal(x, y)


def test_ida_equals_the_serial_run(client, elcentro):
    recs, dt = suite(elcentro)
    b = building()
    for serial, par in [
        (aemstep.ida_stripes(recs, dt, [0.5, 1.0, 2.0], collapse_drift=0.015, **b),
         ad.ida_stripes(client, recs, dt, [0.5, 1.0, 2.0], collapse_drift=0.015, **b)),
        (aemstep.ida_hunt_fill(recs, dt, collapse_drift=0.015, **b),
         ad.ida_hunt_fill(client, recs, dt, collapse_drift=0.015, chunk=2, **b)),
        # driven by Sa(T1): each record's measure is computed on its worker
        (aemstep.ida_stripes(recs, dt, [3.0, 6.0], collapse_drift=0.015, intensity="sa",
                             period=0.6, **b),
         ad.ida_stripes(client, recs, dt, [3.0, 6.0], collapse_drift=0.015, intensity="sa",
                        period=0.6, **b)),
    ]:
        assert len(serial) == len(par) == len(recs)
        for a, c in zip(serial, par):
            assert isinstance(c, aemstep.IdaCurve)  # typed, through pickle
            for key in ("intensity", "drift", "collapsed"):
                np.testing.assert_array_equal(getattr(a, key), getattr(c, key))
            assert a.collapse == c.collapse and a.error == c.error
            assert a.measure == c.measure and a.record_intensity == c.record_intensity
    assert ad.ida_stripes(client, [], dt, [0.5], **b) == []


def test_the_cluster_page_block_runs(capsys):
    """The first Python block of docs/cluster.md runs as written (it makes its own
    LocalCluster) and prints what it shows."""
    import os
    import re

    from conftest import ROOT

    text = (ROOT / "docs" / "cluster.md").read_text()
    block = re.findall(r"```python\n(.*?)```", text, flags=re.S)[0]
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        exec(compile(block, "docs/cluster.md block 0", "exec"), {"__name__": "__main__"})
    finally:
        os.chdir(cwd)
    assert "equal to the serial run: True" in capsys.readouterr().out
