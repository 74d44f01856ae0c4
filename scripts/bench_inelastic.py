#!/usr/bin/env python3
"""Constant-ductility spectra of El Centro, aemstep beside an openseespy loop, in one run.

    pip install openseespy    # the comparator (only this script needs it)
    python3 scripts/bench_inelastic.py [--reps 3]

aemstep: 40 periods (log-spaced 0.05–3 s, 5 % damping) × μ = 2, 4, 6 × EPP (α = 0) and
bilinear (α = 0.05), 240 searches, `aemstep.constant_ductility` with its defaults (60-point
geometric grid down to 1 % of the elastic strength, Illinois false position safeguarded by
bisection, tol 1e-6 on the strength, 40 points per initial period), on 1 and on 2 threads;
and the elastic batch `aemstep.spectra` (200 records × 100 periods) on 1 and 2 threads.

OpenSees: the same search (the crate's method, ported below: grid bracket then the
safeguarded Illinois refinement, same grid and tolerance) for ONE period, T = 0.2 s, μ = 4,
EPP: each trial strength one openseespy transient analysis of a zero-length SDOF (Steel01,
E0 = ω², b = α, mass 1, mass-proportional damping 2ζω, Newmark average acceleration,
Newton, the record as a Path series linear between samples, sub-step h/4 = the crate's
⌈40 h/T⌉ = 4 sub-steps, one longest period of free vibration appended, peak by an
EnvelopeNode recorder). Its time per analysis step is extrapolated to the 240 searches as
(OpenSees seconds per search at T = 0.2 s) × Σ over the 240 searches of (sub-steps of that
period / 4), i.e. assuming every search takes as many passes as the measured one.

Timings: the fastest of `--reps` repetitions (on a shared machine, the least disturbed);
the load (`uptime`) is printed before and after.
"""
import argparse
import math
import os
import subprocess
import tempfile
import time

import numpy as np

import aemstep

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
H = 0.02
G = 9.80665
ZETA = 0.05


def record():
    vals = []
    with open(os.path.join(ROOT, "data", "elcentro-ns-1940.txt")) as f:
        for line in f:
            line = line.strip()
            if line and not line.startswith("#"):
                vals.append(float(line) * G)
    return np.array(vals)


def periods():
    return 0.05 * 60.0 ** (np.arange(40) / 39.0)


def substeps(t):
    return max(1, math.ceil(40 * H / t))


def aemstep_spectra(ag, threads):
    out = []
    for alpha in (0.0, 0.05):
        for mu in (2.0, 4.0, 6.0):
            out.append(aemstep.constant_ductility(periods(), ZETA, H, ag, mu, alpha=alpha, threads=threads))
    return out


def fastest(f, reps):
    best = math.inf
    for _ in range(reps):
        t = time.perf_counter()
        r = f()
        best = min(best, time.perf_counter() - t)
    return best, r


def opensees_peak(ag, t, alpha, ay, n):
    """Peak |u| of the OpenSees SDOF with strength ay (m/s², None: elastic)."""
    import openseespy.opensees as ops

    w = 2 * math.pi / t
    tail = math.ceil(t / H)
    series = list(ag) + [0.0] * tail
    steps = (len(series) - 1) * n
    with tempfile.NamedTemporaryFile(suffix=".out", delete=False) as fh:
        path = fh.name
    ops.wipe()
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    ops.node(1, 0.0)
    ops.node(2, 0.0)
    ops.fix(1, 1)
    ops.mass(2, 1.0)
    if ay is None:
        ops.uniaxialMaterial("Elastic", 1, w * w)
    else:
        ops.uniaxialMaterial("Steel01", 1, ay, w * w, alpha)
    ops.element("zeroLength", 1, 1, 2, "-mat", 1, "-dir", 1)
    ops.timeSeries("Path", 1, "-dt", H, "-values", *series)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.rayleigh(2 * ZETA * w, 0.0, 0.0, 0.0)
    ops.recorder("EnvelopeNode", "-file", path, "-node", 2, "-dof", 1, "disp")
    ops.constraints("Plain")
    ops.numberer("Plain")
    ops.system("FullGeneral")
    ops.test("NormDispIncr", 1e-12, 25)
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    ops.analyze(steps, H / n)
    ops.wipe()
    with open(path) as f:
        rows = [list(map(float, l.split())) for l in f if l.strip()]
    os.unlink(path)
    return rows[-1][0]  # the envelope file's last row: max |u|


def opensees_search(ag, t, alpha, mu_t, points=60, lowest=0.01, tol=1e-6):
    """The crate's constant-ductility search (Yielding::constant_ductility) driving OpenSees."""
    n = substeps(t)
    w2 = (2 * math.pi / t) ** 2
    a0 = w2 * opensees_peak(ag, t, alpha, None, n)
    passes = 1

    def mu_of(ay):
        return opensees_peak(ag, t, alpha, ay, n) / (ay / w2)

    ratio = lowest ** (1.0 / (points - 1))
    x, k = a0 * ratio, 1
    lo = hi = a0
    flo = fhi = mlo = mhi = 1.0 - mu_t
    kept, w1, wprev = 0, math.inf, math.inf
    while True:
        f = mu_of(x) - mu_t
        passes += 1
        if k is not None:
            if f >= 0:
                lo, flo, mlo, mhi, k = x, f, f, fhi, None
            else:
                hi, fhi = x, f
                if k + 1 >= points:
                    return x, passes
                x, k = a0 * ratio ** (k + 1), k + 1
                continue
        elif f >= 0:
            lo, flo, mlo = x, f, f
            if kept == 1:
                mhi *= 0.5
            kept = 1
        else:
            hi, fhi, mhi = x, f, f
            if kept == -1:
                mlo *= 0.5
            kept = -1
        w = hi - lo
        if w <= tol * hi:
            break
        xn = lo + w * (mlo / (mlo - mhi))
        if not (lo < xn < hi) or w > 0.5 * wprev:
            xn = lo + 0.5 * w
        wprev, w1 = w1, w
        x = xn
    return lo + (hi - lo) * (flo / (flo - fhi)), passes


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=3)
    args = ap.parse_args()
    ag = record()
    print("load before:", subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip())
    aemstep_spectra(ag, 1)  # warm up
    t1, res = fastest(lambda: aemstep_spectra(ag, 1), args.reps)
    t2, _ = fastest(lambda: aemstep_spectra(ag, 2), args.reps)
    passes = sum(r.passes for r in res)
    print(f"aemstep 240 searches (40 periods x mu 2,4,6 x EPP, bilinear): 1 thread {t1:.3f} s, "
          f"2 threads {t2:.3f} s (x{t1 / t2:.2f}); record passes {passes} (slowest bank of each call)")
    tp, mu_t, alpha = 0.2, 4.0, 0.0
    to, (ay_os, passes_os) = fastest(lambda: opensees_search(ag, tp, alpha, mu_t), 1)
    mine = aemstep.constant_ductility([tp], ZETA, H, ag, mu_t, alpha=alpha, threads=1)
    print(f"OpenSees one search T = {tp} s, mu = {mu_t}, EPP: {to:.3f} s, {passes_os} passes, "
          f"a_y = {ay_os:.5g} m/s^2 (aemstep: {mine.yield_acceleration[0]:.5g} m/s^2, "
          f"{mine.passes} passes)")
    weight = sum(substeps(t) for t in periods()) / substeps(tp)
    extrap = to * weight * 6
    print(f"OpenSees extrapolated to the 240 searches: {extrap:.1f} s "
          f"(x {weight:.2f} = the 40 periods' sub-steps over T = {tp} s's, x 6 targets and laws)")
    print(f"RATIO OpenSees / aemstep (1 thread): {extrap / t1:.0f}x; (2 threads): {extrap / t2:.0f}x")
    # The host batch: 200 elastic spectra (100 periods, El Centro) on 1 and 2 threads.
    recs = [ag * (1.0 + 0.001 * i) for i in range(200)]
    per = 0.01 * 1000.0 ** (np.arange(100) / 99.0)
    e1, _ = fastest(lambda: aemstep.spectra(per, 0.05, H, recs, threads=1), args.reps)
    e2, _ = fastest(lambda: aemstep.spectra(per, 0.05, H, recs, threads=2), args.reps)
    print(f"spectra, 200 records x 100 periods: 1 thread {e1:.3f} s, 2 threads {e2:.3f} s "
          f"(x{e1 / e2:.2f}); cores {os.cpu_count()}")
    print("load after:", subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip())


if __name__ == "__main__":
    main()
