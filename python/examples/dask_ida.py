"""An IDA of the 5-storey yielding shear building on a Dask cluster, checked against the
serial run, with both times.

    python3 python/examples/dask_ida.py                       # a LocalCluster (2 workers)
    python3 python/examples/dask_ida.py tcp://SCHEDULER:8786  # a running scheduler

Needs ``pip install ./python 'dask[distributed]'`` (on every worker too, for a real
cluster). The suite: 44 records made from El Centro 1940 NS (shifted in time by 1.8 s
steps and alternately negated: a stand-in for a real suite, the repository holds one
record), each at 20 scale factors 0.1, 0.2, …, 2.0: 880 analyses, FEMA P-695's 44 records
at 20 intensities; the record interpolated to h = 0.005 s (15 977 steps); the building: 5
storeys of 1e5 kg, k = 1e8 N/m, fy = 3e6 N, post-yield ratio 0.05, Rayleigh damping 5 %
in modes 1 and 2 (the repository's IDA scene); collapse at 0.1 m of storey drift. Each
time is the best of 3 runs.
"""

import sys
import time
from pathlib import Path

import numpy as np

import aemstep
from aemstep import distributed as ad

ROOT = Path(__file__).resolve().parents[2]


def five_storey():
    n, mass, k, fy, alpha, xi = 5, 1e5, 1e8, 3e6, 0.05, 0.05
    m = np.diag(np.full(n, mass))
    kk = np.zeros((n, n))
    for i in range(n):
        kk[i, i] += k
        if i > 0:
            kk[i - 1, i - 1] += k
            kk[i - 1, i] -= k
            kk[i, i - 1] -= k
    w = np.sqrt(np.sort(np.linalg.eigvalsh(kk / mass)))[:2]
    a0, a1 = 2 * xi * w[0] * w[1] / (w[0] + w[1]), 2 * xi / (w[0] + w[1])
    params = np.column_stack([np.full(n, k), np.full(n, fy), np.full(n, alpha)])
    return dict(masses=np.full(n, mass), law="bilinear", params=params, c=a0 * m + a1 * kk)


def suite(count=44, h=0.005):
    acc, dt = aemstep.read_at2(ROOT / "data" / "elcentro-ns-1940.AT2")
    t = np.arange(acc.shape[0]) * dt
    ag = np.interp(np.arange(0.0, t[-1] + h / 2, h), t, acc * aemstep.G)
    shift = int(round(1.8 / h))
    return [(-1) ** i * np.roll(ag, i * shift) for i in range(count)], h


def best(f, repeat=3):
    """(the result, the best wall time of `repeat` calls in s)."""
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t)
    return out, min(times)


def main(address=None):
    from dask.distributed import Client, LocalCluster

    records, dt = suite()
    scales = np.arange(1, 21) * 0.1
    kw = dict(collapse_drift=0.1, **five_storey())
    cluster = None
    if address is None:
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                               dashboard_address=":0")
        address = cluster
    with Client(address) as client:
        client.run(lambda: __import__("aemstep").__version__)  # workers up, package there
        workers = len(client.scheduler_info()["workers"])
        serial, t_serial = best(lambda: aemstep.ida_stripes(records, dt, scales, threads=1, **kw))
        threaded, t_threads = best(
            lambda: aemstep.ida_stripes(records, dt, scales, threads=2, **kw))
        par, t_dask = best(lambda: ad.ida_stripes(client, records, dt, scales, **kw))
    if cluster is not None:
        cluster.close()
    same = all(
        np.array_equal(a.drift, b.drift) and np.array_equal(a.drift, c.drift)
        and a.collapse == b.collapse == c.collapse
        for a, b, c in zip(serial, par, threaded)
    )
    runs = len(records) * len(scales)
    print(f"IDA: {len(records)} records x {len(scales)} scale factors = {runs} analyses "
          f"of {records[0].shape[0]} steps")
    print(f"serial, threads=1:              {t_serial:.2f} s")
    print(f"threads=2, one process:         {t_threads:.2f} s")
    print(f"Dask, {workers} workers, {len(records)} tasks:   {t_dask:.2f} s")
    print(f"Dask result equal to the serial run bit for bit: {same}")
    f = aemstep.ida_fractiles(serial, [0.01, 0.02, 0.04])
    print("median scale factor at drifts 0.01, 0.02, 0.04 m:", np.round(f[1], 3))
    if not same:
        sys.exit(1)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
