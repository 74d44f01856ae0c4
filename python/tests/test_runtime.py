"""The GIL is released while a record runs; memory stays flat over 10 000 runs."""

import os
import threading
import time

import numpy as np

import aemstep
from conftest import rayleigh, shear_matrices


def test_python_runs_while_a_record_is_stepped(elcentro):
    """A pure-Python counter advances while another thread is inside one long native call.

    Were the GIL held for the call, the counter could only run in the switch interval
    before the call took it (5 ms by default); here it must get at least 100 ms of Python
    time during a call of at least 0.5 s. Robust on a loaded machine: only a share of a
    core is needed, and the call's own length is measured, not assumed."""
    ag, dt = elcentro
    periods = np.geomspace(0.02, 5.0, 120)  # short periods: many sub-steps
    # Enough records for a call of about 1.5 s on this machine and build.
    t0 = time.perf_counter()
    aemstep.spectra(periods, 0.05, dt, [ag] * 2, threads=1)
    per_record = (time.perf_counter() - t0) / 2
    records = [ag] * max(2, min(2000, int(1.5 / per_record)))
    inside = threading.Event()
    done = threading.Event()
    span = {}

    def work():
        inside.set()
        t0 = time.perf_counter()
        aemstep.spectra(periods, 0.05, dt, records, threads=1)
        span["call"] = time.perf_counter() - t0
        done.set()

    # The counter's speed alone, to turn counts into seconds of Python time.
    t0, count = time.perf_counter(), 0
    while time.perf_counter() - t0 < 0.2:
        count += 1
    rate = count / (time.perf_counter() - t0)

    thread = threading.Thread(target=work)
    thread.start()
    inside.wait()
    during = 0
    while not done.is_set():
        during += 1
        time.perf_counter()
    thread.join()
    python_seconds = during / rate
    print(f"call {span['call']:.2f} s; Python ran {python_seconds:.2f} s of it in the other thread")
    assert span["call"] > 0.5, "the job is too short to tell; lengthen it"
    assert python_seconds > 0.1


def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def test_no_memory_growth_over_10000_runs(elcentro):
    ag, dt = elcentro
    ag = ag[:200]
    m, k = shear_matrices([1e5] * 3, [1e8] * 3)
    c = rayleigh(m, k, 0.05)
    periods = np.array([0.2, 0.5, 1.0])

    def one(i):
        aemstep.linear_response(m, c, k, dt, ground_acceleration=ag)
        aemstep.shear_building([1e5] * 3, c, dt, ag, k=1e8, fy=2e5, alpha=0.05)
        aemstep.spectrum(periods, 0.05, dt, ag, threads=1)
        if i % 10 == 0:  # the error path too
            try:
                aemstep.linear_response(m, c, k, -1.0, ground_acceleration=ag)
            except aemstep.InvalidTimeStep:
                pass

    for i in range(500):  # warm up: allocator pools, numpy caches
        one(i)
    before = rss_bytes()
    for i in range(10_000):
        one(i)
    growth = rss_bytes() - before
    print(f"RSS growth over 10 000 runs: {growth / 1024:.0f} KiB")
    # Each run allocates about 40 KiB of results; a leak of any one of them per run would
    # be 400 MB. Bound: 4 MiB (allocator noise; measured 0 to a few hundred KiB).
    assert growth < 4 * 1024 * 1024
