#!/usr/bin/env python3
"""aemstep from Python beside its Python peers, in one run (a benchmark, not a test).

    python3 scripts/bench_python.py [--quick] [--no-install]

The interpreter that runs it must have the peers: openseespy, sdof, pyrotd, eqsig (and
numpy). The aemstep package is built from this checkout: the script makes a virtual
environment `$CARGO_TARGET_DIR/bench-python-venv` with `--system-site-packages` (so it sees
this interpreter's peers), runs `pip install ./python` there (the release build into
`$CARGO_TARGET_DIR`, as scripts/test.sh's Python stage), and re-executes itself in it. The
system interpreter is left as it was. `--no-install`: use the `aemstep` this interpreter
already imports.

Runs, each side by side in the same process:
1. one nonlinear time-history analysis of the yielding 5-storey building
   (scenes/ida/building.rs: El Centro NS ×2 interpolated to h = 0.005 s, 15 975 steps,
   Newton to 1e-12, 50 iterations): `aemstep.shear_building(histories=False, energy=False)`
   against the Rust benchmark (`nonlinear_bench`, run here, alternated with the binding)
   and against openseespy with bench_nonlinear.py's model (imported, not copied); drift
   histories of aemstep (`histories=True`) and OpenSees asserted equal to the Newton
   tolerance;
2. an IDA of 44 records × 20 intensities (880 analyses, whole records, collapse drift
   infinite so both sides run the same steps): `aemstep.ida_stripes(threads=2)` (and
   `threads=1`, for the two-thread speed-up), the same
   as `shear_building(histories=False)` calls on a 2-thread pool, and OpenSees serial
   (model built per analysis as bench_nonlinear.py does, plus an `EnvelopeElement`
   recorder of the storey deformations: the peak drift a user's IDA needs); peak drifts
   asserted equal to the Newton tolerance. `--quick`: 4 records × 5 intensities;
3. elastic spectra of El Centro (5 %, 100 periods 0.05–5 s evenly spaced, as sdof's
   threaded path takes them): `aemstep.spectrum` against sdof, pyrotd and eqsig, one
   thread each, values compared;
4. inelastic spectra: `aemstep.constant_ductility` (μ = 4) and `constant_strength`
   (R = 4) timed alone (their agreement with an independent loop is a test:
   python/tests/test_inelastic.py).

Writes the section between `<!-- python peers: begin -->` and `<!-- python peers: end -->`
of docs/python.md (host timings). Timings: fastest of the repetitions (the least disturbed
by other processes on a shared machine); the load average is recorded before and after.
"""

import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TARGET = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
DOC = os.path.join(ROOT, "docs", "python.md")
BEGIN, END = "<!-- python peers: begin -->", "<!-- python peers: end -->"
QUICK = "--quick" in sys.argv


def ensure_aemstep():
    """Re-execute in a venv with `pip install ./python` unless told not to."""
    if "--no-install" in sys.argv or os.environ.get("AEMSTEP_BENCH_VENV"):
        return
    venv = os.path.join(TARGET, "bench-python-venv")
    py = os.path.join(venv, "bin", "python")
    if not os.path.exists(py):
        subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", venv], check=True)
    env = dict(os.environ, CARGO_TARGET_DIR=TARGET)
    subprocess.run([py, "-m", "pip", "install", "-q", "--no-deps", "--force-reinstall",
                    os.path.join(ROOT, "python")], check=True, env=env)
    env["AEMSTEP_BENCH_VENV"] = venv
    os.execve(py, [py, os.path.abspath(__file__)] + sys.argv[1:], env)


ensure_aemstep()

import json  # noqa: E402
from concurrent.futures import ThreadPoolExecutor  # noqa: E402
from importlib.metadata import version  # noqa: E402

import numpy as np  # noqa: E402
import openseespy.opensees as ops  # noqa: E402

sys.path.insert(0, os.path.join(ROOT, "scripts"))
import bench_nonlinear as bn  # noqa: E402  (the OpenSees model and the record rule)

import aemstep  # noqa: E402

G, DT = bn.G, 0.02
N = 5
NEWTON_ITS = 50  # scenes/ida/building.rs NEWTON_ITERATIONS (bench_nonlinear.build gives OpenSees 50)


def best(f, reps):
    """(fastest, median) seconds of `reps` calls of f, and f's last result."""
    ts, out = [], None
    for _ in range(reps):
        t0 = time.perf_counter()
        out = f()
        ts.append(time.perf_counter() - t0)
    return min(ts), statistics.median(ts), out


# ---------------------------------------------------------------------------------------
# The building of scenes/ida/building.rs, through the binding.

def building():
    """(masses, params n×3, C) of the 5-storey bilinear building; C = a0 M + a1 K (the
    Rayleigh coefficients of bench_nonlinear.rayleigh, which OpenSees takes too)."""
    a0, a1 = bn.rayleigh(N)
    k = np.zeros((N, N))
    for i in range(N):
        k[i, i] = 2 * bn.STIFF if i < N - 1 else bn.STIFF
        if i:
            k[i, i - 1] = k[i - 1, i] = -bn.STIFF
    c = a0 * np.eye(N) * bn.MASS + a1 * k
    params = np.column_stack([np.full(N, bn.STIFF), np.full(N, bn.FY), np.full(N, bn.ALPHA)])
    return np.full(N, bn.MASS), params, c


def at_h(rec):
    """A 0.02 s record (m/s²) at h = 0.005 s, bench_nonlinear.ground (scenes/ida/building.rs)
    vectorized with scale 1, values for n = 0 … 4(len − 1) − 1."""
    rec = np.asarray(rec, dtype=float)
    n = np.arange(4 * (len(rec) - 1))
    pos = n * 50
    i, rem = pos // bn.RATE, pos % bn.RATE
    frac = rem / bn.RATE
    out = 1.0 * (rec[i] + frac * (rec[i + 1] - rec[i]))
    # Start from rest with zero acceleration, as nonlinear_bench (`ground_load(0.0)` at the
    # start) and OpenSees (a = 0 at t = 0) do: the first sample only sets a(0) = −a_g(0).
    out[0] = 0.0
    return out


def run(masses, params, c, ag, histories=False):
    return aemstep.shear_building(masses, c, bn.H, ag, k=params[:, 0], fy=params[:, 1],
                                  alpha=params[:, 2], max_iterations=NEWTON_ITS,
                                  tolerance=bn.TOL, energy=False, histories=histories)


def rust_bench(reps, drifts=None):
    args = [os.path.join(TARGET, "release", "nonlinear_bench"), "--reps", str(reps), "--ida", "0"]
    if drifts:
        args += ["--drifts", drifts]
    out = subprocess.run(args, check=True, text=True, capture_output=True).stdout
    rows = [json.loads(x) for x in out.splitlines() if x.startswith("{")]
    return next(r for r in rows if r.get("case") == "bilinear" and r.get("n") == N)


# ---------------------------------------------------------------------------------------
# The 44 records.

def records(el):
    """El Centro NS (m/s², 0.02 s) and 43 deterministic derived or synthetic records of its
    length (so bench_nonlinear.build's fixed step count fits every one), each scaled to El
    Centro's peak: El Centro reversed in time and negated (2), then Gaussian white noise
    (numpy default_rng, seeds 1 … 41) low-passed by a 3-point moving average, under the
    envelope t²·exp(−t/τ) with τ = 2 … 8 s cycling."""
    el = np.asarray(el)
    pga = np.abs(el).max()
    out = [el, el[::-1].copy(), -el]
    t = np.arange(len(el)) * DT
    for seed in range(1, 42):
        w = np.random.default_rng(seed).standard_normal(len(el))
        w = np.convolve(w, np.ones(3) / 3, mode="same")
        tau = 2.0 + (seed % 7)
        env = (t / tau) ** 2 * np.exp(-t / tau)
        x = w * env
        out.append(x * (pga / np.abs(x).max()))
    return out


def opensees_ida(recs, scales, system):
    """Serial: (seconds, peak |storey drift| per (record, scale)); the model built per
    analysis (bench_nonlinear.build), an EnvelopeElement recorder of the 5 zeroLength
    deformations read back after the run."""
    peaks = np.zeros((len(recs), len(scales)))
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "env.txt")
        t0 = time.perf_counter()
        for r, rec in enumerate(recs):
            for j, s in enumerate(scales):
                bn.build(N, list(rec), s, system)
                ops.recorder("EnvelopeElement", "-file", path, "-precision", 17,
                             "-ele", *range(1, N + 1), "deformation")
                assert ops.analyze(bn.STEPS, bn.H) == 0, f"OpenSees failed: record {r}, scale {s}"
                ops.remove("recorders")  # flushes the envelope file
                env = np.loadtxt(path)  # rows: min, max, absmax
                peaks[r, j] = np.abs(env).max()
        return time.perf_counter() - t0, peaks


def aem_ida_pool(recs_h, scales, masses, params, c, threads=2):
    """The IDA as shear_building(histories=False) calls on a thread pool (GIL released)."""
    jobs = [(r, j) for r in range(len(recs_h)) for j in range(len(scales))]
    peaks = np.zeros((len(recs_h), len(scales)))

    def one(job):
        r, j = job
        return run(masses, params, c, recs_h[r] * scales[j]).peak_drift

    with ThreadPoolExecutor(threads) as pool:
        for (r, j), p in zip(jobs, pool.map(one, jobs)):
            peaks[r, j] = p
    return peaks


def aem_ida_stripes(recs_h, scales, masses, params, c, threads=2):
    curves = aemstep.ida_stripes(recs_h, bn.H, scales, masses=masses, law="bilinear",
                                 params=params, c=c, max_iterations=NEWTON_ITS,
                                 tolerance=bn.TOL, collapse_drift=float("inf"), threads=threads)
    peaks = np.zeros((len(recs_h), len(scales)))
    order = np.argsort(scales)
    for r, cur in enumerate(curves):
        assert not np.any(cur.collapsed), "a run failed"
        peaks[r, order] = np.asarray(cur.drift)  # curves come sorted by intensity
    return peaks


# ---------------------------------------------------------------------------------------

def main():
    import eqsig
    import pyrotd
    import sdof

    cpu = next((x.split(":", 1)[1].strip() for x in open("/proc/cpuinfo") if x.startswith("model name")),
               platform.processor())
    subprocess.run(["cargo", "build", "--release", "-p", "xtask", "--bin", "nonlinear_bench"],
                   cwd=ROOT, check=True)
    load0 = os.getloadavg()
    el = np.array(bn.record())
    ag = at_h(el) * bn.SCALE  # bn.ground(el, n, 2.0) for n = 0 … STEPS
    assert len(ag) == bn.STEPS + 1
    assert all(ag[n] == bn.ground(el, n, bn.SCALE) for n in range(1, bn.STEPS + 1, 97))
    masses, params, c = building()

    # 1. One analysis: the binding alternated with the Rust benchmark.
    reps = 5 if QUICK else 20
    rust, py_bare, py_hist = [], [], []
    for _ in range(2 if QUICK else 3):
        rust.append(rust_bench(3 if QUICK else 5))
        py_bare.append(best(lambda: run(masses, params, c, ag), reps)[0])
        py_hist.append(best(lambda: run(masses, params, c, ag, histories=True), reps)[0])
    rust_ns = min(r["ns_fast"] for r in rust)
    bare_ns = min(py_bare) / bn.STEPS * 1e9
    hist_ns = min(py_hist) / bn.STEPS * 1e9
    ratio = bare_ns / rust_ns
    full = run(masses, params, c, ag, histories=True)
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "drifts.txt")
        rust_bench(1, path)
        rust_drifts = np.loadtxt(path)
    same_as_rust = np.array_equal(full.drifts[1:], rust_drifts)
    systems = {}
    for s in ["BandGeneral", "FullGeneral", "ProfileSPD", "BandSPD"]:
        try:
            systems[s] = bn.time_opensees(N, list(el), 3, s)[0]
        except Exception as e:  # noqa: BLE001 (an unavailable solver)
            print(f"system {s}: {e}", file=sys.stderr)
    system = min(systems, key=systems.get)
    os_us = bn.time_opensees(N, list(el), 3 if QUICK else 5, system)[0]
    os_drifts, _ = bn.opensees_drifts(list(el))
    diff = np.abs(full.drifts[1:] - os_drifts).max()
    drift_rel = diff / np.abs(os_drifts).max()
    bound = bn.TOL * np.sqrt(bn.STEPS) * 10  # bench_nonlinear.py's bound, argued there
    assert drift_rel <= bound, f"drifts differ by {drift_rel:.2e} of the peak (> {bound:.1e})"
    print(f"one analysis: Rust {rust_ns:.0f} ns/step, binding {bare_ns:.0f} (histories {hist_ns:.0f}), "
          f"ratio {ratio:.3f}; OpenSees {os_us:.2f} µs/step; drifts {drift_rel:.1e}", file=sys.stderr)

    # 2. The IDA.
    recs = records(el)
    scales = np.linspace(0.1, 2.0, 20)
    if QUICK:
        recs, scales = recs[:4], scales[[0, 4, 9, 14, 19]]
    recs_h = [at_h(r) for r in recs]
    count = len(recs) * len(scales)
    t_pool, _, pool_peaks = best(lambda: aem_ida_pool(recs_h, scales, masses, params, c), 3)
    have_stripes = hasattr(aemstep, "ida_stripes")
    if have_stripes:
        t_str, _, str_peaks = best(lambda: aem_ida_stripes(recs_h, scales, masses, params, c), 3)
        # One thread, for the two-thread speed-up (issue 35: ≥ 1.8× on a quiet machine).
        t_str1 = best(lambda: aem_ida_stripes(recs_h, scales, masses, params, c, threads=1), 3)[0]
        str_rel = np.abs(str_peaks - pool_peaks).max() / np.abs(pool_peaks).max()
    t_os, os_peaks = opensees_ida(recs, scales, system)
    ida_rel = np.abs(pool_peaks - os_peaks).max() / np.abs(os_peaks).max()
    assert ida_rel <= bound, f"IDA peak drifts differ by {ida_rel:.2e} (> {bound:.1e})"
    if have_stripes:
        assert str_rel <= bound, f"ida_stripes and shear_building differ by {str_rel:.2e}"
    print(f"IDA {count}: pool {t_pool:.2f} s, stripes {t_str if have_stripes else float('nan'):.2f} s, "
          f"OpenSees {t_os:.1f} s; peaks {ida_rel:.1e}", file=sys.stderr)

    # 3. Elastic spectra, El Centro at 0.02 s, one thread each. sdof's threaded path takes
    # (first, last, count) and steps the periods first + i·(last − first)/count (measured:
    # its results are those periods', to rounding, though it labels them linspace): that
    # grid for every side, 0.05 … 4.95 s.
    per = 0.05 + np.arange(100) * (5.0 - 0.05) / 100
    sreps = 10 if QUICK else 100
    spec_exact = lambda: aemstep.spectrum(per, 0.05, DT, el, free_vibration=False)  # noqa: E731
    spec_aem = lambda: aemstep.spectrum(per, 0.05, DT, el, scheme="aem", free_vibration=False)  # noqa: E731
    t_exact, _, s_exact = best(spec_exact, sreps)
    t_aem, _, s_aem = best(spec_aem, sreps)
    t_sdof, _, s_sdof = best(lambda: np.asarray(sdof.spectrum(el, DT, 0.05, periods=np.linspace(0.05, 5.0, 100),
                                                              threads=1)), sreps)
    t_rotd, _, s_rotd = best(lambda: pyrotd.calc_spec_accels(DT, el, 1.0 / per, 0.05), max(2, sreps // 4))
    t_eqsig, _, s_eqsig = best(lambda: eqsig.sdof.pseudo_response_spectra(el, DT, per, 0.05), max(2, sreps // 4))

    def rel(x, y, band=slice(None)):
        return float(np.max(np.abs(np.asarray(x)[band] - y[band]) / y[band]))

    # sdof: Newmark average acceleration at the record's step, the AEM's scheme. The binding's
    # banks sub-step periods shorter than 20·dt (Substeps::AUTO, 20 points a period), so from
    # T = 0.4 s on the two are the same scheme: equal to rounding (asserted 1e-12); below,
    # the differences are the sub-steps' (sdof keeps the record's step).
    long_ = per >= 20 * DT
    d_sdof = (rel(s_sdof[0][1], s_aem.sd, long_), rel(s_sdof[2][1], s_aem.sa, long_),
              rel(s_sdof[0][1], s_aem.sd), rel(s_sdof[2][1], s_aem.sa))
    # eqsig: Nigam–Jennings, exact for a record linear between samples, as "exact": Sd equal
    # to its recurrence coefficients' rounding (1e-7) at all but a few periods (measured: 4
    # of 100 below 0.4 s, by up to 1.3 %, aemstep's larger: its sub-steps there also catch
    # peaks between samples, eqsig looks at the samples only; asserted: at most 5). Its PSA is ω²·Sd, but the
    # record's peak below T = 6·dt (its convention), so PSA is compared from 0.12 s on.
    sd_rel = np.abs(s_eqsig[0] - s_exact.sd) / s_exact.sd
    off = per[sd_rel > 1e-7]
    agree = sd_rel <= 1e-7
    psa_band = agree & (per >= 6 * DT)
    d_eqsig = (float(sd_rel[agree].max()), rel(s_eqsig[2], s_exact.psa, psa_band), float(sd_rel.max()))
    # pyrotd: the frequency domain (FFT of the zero-padded record): its own discretization,
    # a few per cent; a sanity bound only (0.1).
    d_rotd = rel(np.asarray(s_rotd.spec_accel), s_exact.psa)
    print(f"spectra: sdof {d_sdof}, eqsig {d_eqsig}, pyrotd {d_rotd:.1e}", file=sys.stderr)
    assert max(d_sdof[:2]) <= 1e-12, "sdof and the AEM bank disagree"
    assert len(off) <= 5 and d_eqsig[1] <= 1e-7, "eqsig and the exact bank disagree"
    assert d_rotd <= 0.1, "pyrotd and the exact bank disagree"

    # 4. Inelastic spectra (timed alone).
    t_cd, _, _ = best(lambda: aemstep.constant_ductility(per, 0.05, DT, el, 4.0, threads=1), 3)
    t_cs, _, _ = best(lambda: aemstep.constant_strength(per, 0.05, DT, el, 4.0, threads=1), 3)

    # Re-run the headline pair at the end (the load may have changed).
    rust_end = rust_bench(3 if QUICK else 5)["ns_fast"]
    bare_end = best(lambda: run(masses, params, c, ag), reps)[0] / bn.STEPS * 1e9
    rust_ns, bare_ns = min(rust_ns, rust_end), min(bare_ns, bare_end)
    ratio = bare_ns / rust_ns
    load1 = os.getloadavg()

    def la(x):
        return " / ".join(f"{v:.2f}" for v in x)

    lines = [
        BEGIN, "<!-- host timings: begin -->", "",
        "### Beside the Python peers (host timings)", "",
        f"**Host timings and host measurements**, {cpu}, 2 cores; load average (1 / 5 / 15 min) "
        f"{la(load0)} before, {la(load1)} after; generated by "
        f"`python3 scripts/bench_python.py{' --quick' if QUICK else ''}` with numpy {np.__version__}, "
        f"openseespy {version('openseespy')}, sdof {version('sdof')}, pyrotd {version('pyrotd')}, "
        f"eqsig {version('eqsig')}; fastest of the repetitions.", "",
        "| run | aemstep host time | peer host time | ratio (peer / aemstep) | agreement |",
        "|---|---|---|---|---|",
        f"| one analysis, 5-storey bilinear, {bn.STEPS} steps: `shear_building(histories=False, energy=False)` "
        f"against the Rust `nonlinear_bench` | {bare_ns:.0f} ns/step | Rust {rust_ns:.0f} ns/step "
        f"| binding / Rust {ratio:.3f} ({'within' if ratio <= 1.10 else 'NOT within'} 1.10) "
        f"| drifts bitwise those of Rust: {'yes' if same_as_rust else 'no'} |",
        f"| the same, `histories=True` (u, v, a, drifts, iterations kept) | {hist_ns:.0f} ns/step | Rust "
        f"{rust_ns:.0f} ns/step | binding / Rust {hist_ns / rust_ns:.3f} | — |",
        f"| one analysis against openseespy (`system {system}`) | {bare_ns:.0f} ns/step | {os_us:.2f} µs/step "
        f"| {os_us * 1e3 / bare_ns:.1f}× | drift histories {drift_rel:.1e} of the peak (asserted ≤ {bound:.1e}) |",
    ]
    ida_what = f"{len(recs)} records × {len(scales)} intensities = {count} analyses"
    if have_stripes:
        lines.append(f"| IDA, {ida_what}: `ida_stripes(threads=2)` against openseespy serial "
                     f"| {t_str:.2f} s | {t_os:.1f} s | {t_os / t_str:.0f}× | peak drifts {ida_rel:.1e} of "
                     f"the largest (asserted ≤ {bound:.1e}); `ida_stripes` against the pool {str_rel:.1e}; "
                     f"1 thread {t_str1:.2f} s ({t_str1 / t_str:.2f}× on 2) |")
    else:
        lines.append(f"| IDA, {ida_what}: `ida_stripes(threads=2)` | not in this build (`aemstep.ida_stripes` "
                     "absent: the IDA binding is on another branch) | — | — | — |")
    lines.append(f"| IDA, {ida_what}: `shear_building(histories=False)` on a 2-thread pool against "
                 f"openseespy serial | {t_pool:.2f} s | {t_os:.1f} s | {t_os / t_pool:.0f}× | peak drifts "
                 f"{ida_rel:.1e} of the largest |")
    lines += [
        f"| spectrum of El Centro, 100 periods 0.05 … 4.95 s, 5 %, `scheme=\"aem\"`, against sdof (Newmark "
        f"1/4, 1/2) | {t_aem * 1e3:.2f} ms | {t_sdof * 1e3:.1f} ms | {t_sdof / t_aem:.1f}× | T ≥ 0.4 s: Sd "
        f"{d_sdof[0]:.0e}, Sa {d_sdof[1]:.0e} (asserted ≤ 1e-12); all periods: Sd {d_sdof[2]:.1e}, Sa "
        f"{d_sdof[3]:.1e} |",
        f"| the same, `scheme=\"exact\"`, against eqsig (Nigam–Jennings) | {t_exact * 1e3:.2f} ms "
        f"| {t_eqsig * 1e3:.1f} ms | {t_eqsig / t_exact:.0f}× | Sd {d_eqsig[0]:.0e} at {100 - len(off)} of 100 "
        f"periods (asserted ≤ 1e-7 at ≥ 95), up to {d_eqsig[2]:.1e} at T = "
        + ", ".join(f"{x:.4g}" for x in off) + f" s; PSA (T ≥ 0.12 s) {d_eqsig[1]:.0e} |",
        f"| the same, `scheme=\"exact\"`, against pyrotd (frequency domain) | {t_exact * 1e3:.2f} ms "
        f"| {t_rotd * 1e3:.1f} ms | {t_rotd / t_exact:.0f}× | PSA {d_rotd:.1e} (asserted ≤ 0.1) |",
        f"| inelastic: `constant_ductility` (μ = 4) and `constant_strength` (R = 4), 100 periods, one thread "
        f"| {t_cd * 1e3:.0f} ms and {t_cs * 1e3:.1f} ms | — | — | a test (python/tests/test_inelastic.py) |",
        "",
        "Case of the one analysis: scenes/ida/building.rs (El Centro NS ×2, h = 0.005 s, Newton to 1e-12, "
        "at most 50 iterations; storeys m = 1e5 kg, k = 1e8 N/m, f_y = 3e6 N, α = 0.05; Rayleigh 5 % in "
        "modes 1–2); the binding and `nonlinear_bench` alternated three times and once more at the end, "
        "the binding's time including its argument checks and copies in. OpenSees: the model of "
        "scripts/bench_nonlinear.py (imported from it). IDA: whole records at scales 0.1, 0.2, …, 2.0, "
        "collapse drift infinite (no early stop, both sides run every step); El Centro NS, El Centro "
        "reversed in time, El Centro negated, and 41 synthetic records (seeded Gaussian white noise, 3-point "
        "moving average, envelope t²·exp(−t/τ), τ = 2 … 8 s) scaled to El Centro's peak, all at El "
        "Centro's length and interpolated to h = 0.005 s by its rule. OpenSees' IDA builds each model "
        "afresh and reads the peak drift from an `EnvelopeElement` recorder. Spectra: one thread each, "
        "no free vibration after the record (none of the peers has it); the periods 0.05 + 0.0495·i s, "
        "i = 0 … 99, the grid sdof's threaded path steps when given 0.05, 5.0 and 100 (its results are "
        "those periods', to rounding). Relative differences are max over periods of |peer − aemstep| / "
        "aemstep. Below 0.4 s (20·dt) aemstep's banks sub-step (`Substeps::AUTO`, 20 points a period, "
        "which sdof and eqsig do not: it costs time and moves the peaks there, aemstep also catching "
        "peaks between samples, which explains the few periods where eqsig's Sd is about 1 % lower); "
        "eqsig's PSA is the record's peak below 6·dt (its convention); pyrotd's PSA differs "
        "by its frequency-domain discretization of the record.",
        "",
        "<!-- host timings: end -->", END,
    ]
    if QUICK:
        lines[-3:-3] = ["", "Run with `--quick`: the IDA is the subset stated in its rows (records 1–4, "
                            "scales 0.1, 0.5, 1.0, 1.5, 2.0), not extrapolated."]
    section = "\n".join(lines)
    doc = open(DOC).read()
    if BEGIN in doc:
        doc = re.sub(re.escape(BEGIN) + ".*?" + re.escape(END), lambda _: section, doc, flags=re.S)
    else:
        doc = doc.rstrip("\n") + "\n\n" + section + "\n"
    open(DOC, "w").write(doc)
    print(section)
    if ratio > 1.10:
        print(f"NOT MET: binding / Rust = {ratio:.3f} > 1.10", file=sys.stderr)


if __name__ == "__main__":
    main()
