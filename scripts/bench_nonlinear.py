#!/usr/bin/env python3
"""The yielding shear-building step beside OpenSees, in one run.

    python3 scripts/bench_nonlinear.py [--quick]

Builds xtask's `nonlinear_bench` (release), times OpenSees (openseespy) on the same model,
then aemstep, then OpenSees again (the spread shows the machine's load), checks that the two
drift histories agree to the Newton tolerance, and writes the section between
`<!-- nonlinear peers: begin -->` and `<!-- nonlinear peers: end -->` of docs/performance.md.
Not a test: the tests never need openseespy.

The OpenSees model (the choices, each checked by the drift comparison):
- `model basic -ndm 1 -ndf 1`, nodes 0..N at x = 0, node 0 fixed, floor masses;
- each storey a `zeroLength` element with `Steel01(Fy = 3e6, E0 = 1e8, b = 0.05)` in dir 1:
  Steel01 without its isotropic-hardening options is the bilinear kinematic-hardening law of
  `aemstep::hysteresis::Bilinear`, and a zeroLength element's deformation is u_j − u_i, the
  storey drift (a unit-length element would be the same); created with `-doRayleigh 1`, else
  it takes no stiffness-proportional damping;
- `rayleigh a0 0 a1 0` (betaKinit = a1): C = a0 M + a1 K_initial, constant, as in aemstep;
- `UniformExcitation` (load −M ι a_g) of a `Path` time series holding a_g at every step,
  interpolated to h = 0.005 in Python by the same integer rule as scenes/ida/building.rs;
- `integrator Newmark 0.5 0.25`, `algorithm Newton`, `numberer Plain`, `constraints Plain`,
  the fastest `system` of those tried; `test NormUnbalance` (the residual, as aemstep's
  test) at 1e-12 × the storey yield force (aemstep's is relative to the force scale);
- timed: one `analyze(STEPS, h)` call, the way a user runs a record.
"""

import json
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time

from importlib.metadata import version

import numpy as np
import openseespy.opensees as ops

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TARGET = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
DOC = os.path.join(ROOT, "docs", "performance.md")
BEGIN, END = "<!-- nonlinear peers: begin -->", "<!-- nonlinear peers: end -->"

# scenes/ida/building.rs
MASS, STIFF, FY, ALPHA, XI, SCALE, RATE, STEPS, TOL = 1e5, 1e8, 3.0e6, 0.05, 0.05, 2.0, 200, 15975, 1e-12
G = 9.80665  # scenes/modal/elcentro.rs `G`
H = 1.0 / RATE


def record():
    with open(os.path.join(ROOT, "data", "elcentro-ns-1940.txt")) as f:
        return [float(x) * G for x in f if x.strip() and not x.startswith("#")]


def ground(ag, n, scale):
    """scenes/ida/building.rs `ground`, operation for operation."""
    pos = n * 50
    i, rem = pos // RATE, pos % RATE
    if i + 1 >= len(ag):
        return 0.0
    frac = rem / RATE
    return scale * (ag[i] + frac * (ag[i + 1] - ag[i]))


def rayleigh(n):
    """(a0, a1): 5 % in modes 1-2; N = 5 exactly as models::five_storey_building."""
    if n == 5:
        root = 31.622776601683793
        w1, w2 = 2.0 * root * 0.1423148382732851, 2.0 * root * 0.4154150130018864
    else:
        k = np.zeros((n, n))
        for i in range(n):
            k[i, i] = 2 * STIFF if i < n - 1 else STIFF
            if i:
                k[i, i - 1] = k[i - 1, i] = -STIFF
        w1, w2 = np.sqrt(np.sort(np.linalg.eigvalsh(k / MASS))[:2])
    a1 = 2.0 * XI / (w1 + w2)
    return a1 * w1 * w2, a1


def build(n, ag, scale, system="BandGeneral"):
    ops.wipe()
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    for i in range(n + 1):
        ops.node(i, 0.0)
    ops.fix(0, 1)
    for i in range(1, n + 1):
        ops.mass(i, MASS)
        ops.uniaxialMaterial("Steel01", i, FY, STIFF, ALPHA)
        ops.element("zeroLength", i, i - 1, i, "-mat", i, "-dir", 1, "-doRayleigh", 1)
    a0, a1 = rayleigh(n)
    ops.rayleigh(a0, 0.0, a1, 0.0)
    values = [ground(ag, k, scale) for k in range(STEPS + 1)]
    ops.timeSeries("Path", 1, "-dt", H, "-values", *values)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.constraints("Plain")
    ops.numberer("Plain")
    ops.system(system)
    ops.test("NormUnbalance", TOL * FY, 50)
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")


def time_opensees(n, ag, reps, system):
    t = []
    for _ in range(reps):
        build(n, ag, SCALE, system)
        t0 = time.perf_counter()
        ok = ops.analyze(STEPS, H)
        t.append(time.perf_counter() - t0)
        assert ok == 0, f"OpenSees failed (N = {n}, {system})"
    return min(t) / STEPS * 1e6, statistics.median(t) / STEPS * 1e6


def opensees_drifts(ag):
    """Untimed: the 5-storey drift history, step by step; and Newton iterations a step."""
    build(5, ag, SCALE)
    out, its = [], 0
    for _ in range(STEPS):
        assert ops.analyze(1, H) == 0
        its += ops.testIter()
        u = [0.0] + [ops.nodeDisp(i, 1) for i in range(1, 6)]
        out.append([u[i] - u[i - 1] for i in range(1, 6)])
    return np.array(out), its / STEPS


def opensees_ida(ag, k, system):
    """(whole, analyze only) seconds of k analyses, each model built afresh (as a user's
    IDA script does; the build includes the 15 976-value Path series)."""
    t0, solve = time.perf_counter(), 0.0
    for j in range(1, k + 1):
        build(5, ag, 2.0 * j / k, system)
        t1 = time.perf_counter()
        assert ops.analyze(STEPS, H) == 0
        solve += time.perf_counter() - t1
    return time.perf_counter() - t0, solve


def main():
    quick = "--quick" in sys.argv
    reps, ida_k = (1, 10) if quick else (3, 100)
    subprocess.run(["cargo", "build", "--release", "-p", "xtask", "--bin", "nonlinear_bench"],
                   cwd=ROOT, check=True)
    ag = record()
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")),
               platform.processor())

    # Which linear solver: the fastest correct one for this size.
    systems = {}
    for s in ["BandGeneral", "FullGeneral", "ProfileSPD", "BandSPD", "UmfPack"]:
        try:
            systems[s] = time_opensees(5, ag, 3, s)[0]  # fastest of 3: the machine may be loaded
        except Exception as e:  # noqa: BLE001 (an unavailable solver)
            print(f"system {s}: {e}", file=sys.stderr)
    system = min(systems, key=systems.get)
    print("systems (µs/step):", systems, "->", system, file=sys.stderr)

    load0 = os.getloadavg()[0]
    ns = [5, 3, 10, 20]
    first = {n: time_opensees(n, ag, reps, system) for n in ns}
    ida1 = opensees_ida(ag, ida_k, system)

    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "drifts.txt")
        out = subprocess.run([os.path.join(TARGET, "release", "nonlinear_bench"), "--reps", str(reps),
                              "--ida", str(ida_k), "--drifts", path],
                             check=True, text=True, capture_output=True).stdout
        aem_drifts = np.loadtxt(path)
    rows = [json.loads(l) for l in out.splitlines() if l.startswith("{")]
    peak, chain = rows[0]["peak_flops"], rows[0]["solve_chain_ns"]
    cases = {(r["case"], r.get("n")): r for r in rows[1:]}

    second = {n: time_opensees(n, ag, reps, system) for n in ns}
    ida2 = opensees_ida(ag, ida_k, system)
    load1 = os.getloadavg()[0]

    # The check: the same discrete scheme to the Newton tolerance.
    os_drifts, os_its = opensees_drifts(ag)
    diff = np.abs(aem_drifts - os_drifts).max()
    scale = np.abs(os_drifts).max()
    rel = diff / scale
    print(f"drift agreement: max |Δ| = {diff:.3e} m, max |drift| = {scale:.4f} m, ratio {rel:.2e}",
          file=sys.stderr)
    # Each step's state is the solution of its equation to a relative residual of 1e-12
    # (aemstep) and an absolute 1e-12·f_y (OpenSees); the difference of two such solutions
    # is that residual through the step's (well-conditioned) Jacobian, and it is carried
    # forward by the scheme, which is stable: over the record the errors of 16 000 steps
    # add at most linearly, and in practice as a random walk. The bound: 1e-12 per step ×
    # √steps × 10 (conditioning of the yielding storeys), ≈ 1.3e-9 relative.
    bound = TOL * np.sqrt(STEPS) * 10
    assert rel <= bound, f"drifts differ by {rel:.2e} of the peak (> {bound:.1e}): a model mismatch"

    def os_pair(n):
        a, b = first[n], second[n]
        return min(a[0], b[0]), a[1], b[1]

    lines = [BEGIN, "", "### Yielding shear building beside OpenSees (host timings)", "",
             f"**Host timings**, {cpu}, one thread; load average {load0:.2f} before, {load1:.2f} after; "
             f"generated by `python3 scripts/bench_nonlinear.py{' --quick' if quick else ''}` "
             f"(openseespy {version('openseespy')}, fastest of {reps} whole runs and median; "
             "OpenSees timed before and after aemstep, both medians shown). "
             f"Case: El Centro NS ×2, h = 0.005 s, {STEPS} steps, Newton to 1e-12; storeys m = 1e5 kg, "
             "k = 1e8 N/m, f_y = 3e6 N, α = 0.05; Rayleigh 5 % in modes 1–2.", "",
             "| case | OpenSees µs/step (fastest; median before / after) | aemstep ns/step (fastest; median) "
             "| ratio (fastest) | Newton iterations/step | ns/iteration | flops/step | share of floor |",
             "|---|---|---|---|---|---|---|---|"]
    for (name, n), r in cases.items():
        if name == "ida":
            continue
        if name == "bilinear" and n in first:
            f, m1, m2 = os_pair(n)
            osc, ratio = f"{f:.2f}; {m1:.2f} / {m2:.2f}", f"{f * 1e3 / r['ns_fast']:.1f}×"
        else:
            osc, ratio = "—", "—"
        lines.append(f"| {name}, N = {n} | {osc} | {r['ns_fast']:.0f}; {r['ns_median']:.0f} | {ratio} "
                     f"| {r['iterations']:.3f} | {r['ns_per_iteration']:.0f} | {r['flops_step']:.0f} "
                     f"| {100 * r['floor_share']:.1f} % |")
    ida = cases[("ida", None)]
    lines += ["", f"Serial IDA, {ida_k} analyses of the 5-storey bilinear building (scales 0.02 … 2.0), "
              f"whole record each: OpenSees {min(ida1, ida2)[0]:.2f} s (runs {ida1[0]:.2f} / {ida2[0]:.2f} s with the "
              f"model built each time; `analyze` alone {min(ida1, ida2)[1]:.2f} s), aemstep {ida['s_fast']:.3f} s "
              f"(median {ida['s_median']:.3f} s): {min(ida1, ida2)[0] / ida['s_fast']:.0f}× "
              f"({min(ida1, ida2)[1] / ida['s_fast']:.0f}× against `analyze` alone).", "",
              f"Drift agreement (5-storey bilinear): max over steps and storeys |δ_aemstep − δ_OpenSees| = "
              f"{diff:.2e} m against max |δ| = {scale:.4f} m, {rel:.1e} relative (asserted ≤ {bound:.1e}: "
              "1e-12 a step × √steps × 10). "
              f"Newton iterations a step: OpenSees {os_its:.3f}, aemstep {cases[('bilinear', 5)]['iterations']:.3f} "
              "(aemstep starts from q_{n−1} and checks the residual before solving; OpenSees' count includes "
              "its convergence check).", "",
              f"OpenSees: `zeroLength` + `Steel01` storeys with `-doRayleigh 1`, `rayleigh a0 0 a1 0` "
              f"(C = a0 M + a1 K_init), `Newmark 0.5 0.25`, `Newton`, `system {system}` (fastest of "
              + ", ".join(f"{s} {t:.2f}" for s, t in systems.items())
              + " µs/step at N = 5), `test NormUnbalance 3e-6 50` (1e-12 × f_y: the residual, in force, as "
              "aemstep's relative residual), one `analyze(15975, 0.005)` call. "
              "Bouc–Wen not run in OpenSees: its `BoucWen` uniaxialMaterial (Baber–Noori, with degradation "
              "parameters and its own local Newton) is not integrated as `aemstep::hysteresis::BoucWen`, so the "
              "histories would not be the same scheme. Friction storeys have no Steel01-like peer (OpenSees' "
              "friction models are bearing elements) and are aemstep only.", "",
              "**The latency floor of one analysis.** A step that corrects its predictor evaluates the "
              "storeys, solves `J δ = r`, updates `q` and evaluates them again, each part waiting for the last. "
              f"The solve alone — the `L D Lᵀ` factor-and-solve of the 5×5 tridiagonal `J`, five divisions and two "
              f"substitutions in one dependency chain — takes {chain:.1f} ns when chained as Newton chains it "
              "(`solve_chain_ns` in `nonlinear_bench`, fastest of 20). 100× OpenSees' fastest step here is "
              f"{min(os_pair(5)[0], 1e9) * 1e3 / 100:.1f} ns: the solve's chain is "
              f"{100 * chain / (min(os_pair(5)[0], 1e9) * 10):.0f} % of it before either evaluation, the residual's "
              f"norms or the state's checks, and the {cases[('bilinear', 5)]['flops_step']:.0f} flops of the step at "
              f"the SSE2 rate below take {cases[('bilinear', 5)]['flops_step'] / peak * 1e9:.0f} ns. So one analysis "
              "cannot step 100× faster than OpenSees on this machine; many analyses at once (a batch, an IDA) share "
              "the cores instead.", "",
              f"Flops: `flops_per_step` in xtask/src/bin/nonlinear_bench.rs, counted from the code (the tridiagonal "
              f"path: k + 1 trials with their tangents, k solves of J on three diagonals by L D Lᵀ); the floor is that count at the "
              f"host's measured f64 multiply-add rate without AVX, {peak / 1e9:.1f} Gflop/s (24 independent "
              "chains of `a = a·m + k`, as xtask/benches/steps.rs `floor_compute` without AVX; the compiler "
              "packs the chains two to an SSE2 register, so it is the SSE2 rate, 2× the one-lane scalar "
              "rate). A core shared with other jobs shows as a gap between the two OpenSees medians.", "", END]
    section = "\n".join(lines)
    doc = open(DOC).read()
    if BEGIN in doc:
        doc = re.sub(re.escape(BEGIN) + ".*?" + re.escape(END), lambda _: section, doc, flags=re.S)
    else:
        anchor = "### SSE2 only"
        assert anchor in doc
        doc = doc.replace(anchor, section + "\n\n" + anchor, 1)
    open(DOC, "w").write(doc)
    print(section)


if __name__ == "__main__":
    main()
