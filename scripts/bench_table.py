#!/usr/bin/env python3
"""Turn criterion's output of `cargo bench -p xtask --bench steps` into the README's tables.

Reads target/criterion/**/new/{benchmark,estimates}.json (median estimates) and prints
Markdown: time per step against N for every scheme and scalar type, the multiply-add
counts and the fast-form / A-form ratio, and the paper's Example 10 table beside ours.
Also the performance tables of docs/performance.md: multiply-adds per ns, the floor of
each size (the larger of one read of the operator bytes, `floor-read`, and the multiply-
adds at the rate of `floor/compute-<T>`), the share of it reached, and the plain nalgebra
`DMatrix` loop of the same run. Those use the fastest sample of each benchmark (criterion's
sample.json), not the median: on a shared machine the fastest sample is the one least
disturbed by other jobs.
Usage: python3 scripts/bench_table.py [criterion-dir]
"""
import json
import os
import sys

root = sys.argv[1] if len(sys.argv) > 1 else "target/criterion"
res = {}
fast = {}  # fastest sample, ns per iteration
elements = {}  # criterion's throughput: elements (multiply-adds) per iteration
for dirpath, _, files in os.walk(root):
    if os.path.basename(dirpath) == "new" and "estimates.json" in files:
        b = json.load(open(os.path.join(dirpath, "benchmark.json")))
        e = json.load(open(os.path.join(dirpath, "estimates.json")))
        key = (b["group_id"], b["function_id"], b["value_str"])
        res[key] = e["median"]["point_estimate"]
        elements[key] = (b.get("throughput") or {}).get("Elements")
        if "sample.json" in files:
            smp = json.load(open(os.path.join(dirpath, "sample.json")))
            fast[key] = min(t / i for t, i in zip(smp["times"], smp["iters"]))

SCHEMES = [
    ("aem", "AEM `Linear`", lambda n: 3 * n * n + 7 * n),
    ("aem-aform", "AEM `AForm`", lambda n: 12 * n * n),
    ("newmark", "`Newmark`", lambda n: 3 * n * n + 7 * n),
    ("gen-alpha", "`GeneralizedAlpha`", lambda n: 4 * n * n + 10 * n),
    ("exact", "`Exact`", lambda n: 11 * n * n),
]
NS = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 25, 50, 100]


def fmt_ns(x):
    if x is None:
        return "–"
    if x >= 1000:
        return f"{x / 1000:.1f} µs"
    return f"{x:.0f} ns" if x >= 10 else f"{x:.1f} ns"


for ty in ["f64", "f32"]:
    print(f"\nTime per step, `{ty}` (median; multiply-adds per step in brackets):\n")
    print("| N | " + " | ".join(s[1] for s in SCHEMES) + " | `AForm` / `Linear` |")
    print("|---|" + "---|" * (len(SCHEMES) + 1))
    for n in NS:
        cells = []
        for key, _, macs in SCHEMES:
            t = res.get((f"step/{ty}", key, str(n)))
            cells.append(f"{fmt_ns(t)} ({macs(n)})")
        a = res.get((f"step/{ty}", "aem", str(n)))
        b = res.get((f"step/{ty}", "aem-aform", str(n)))
        ratio = f"{b / a:.2f}×" if a and b else "–"
        print(f"| {n} | " + " | ".join(cells) + f" | {ratio} |")

PAPER = {
    25: {20: (0.439, 0.020), 100: (3.667, 0.219), 200: (7.510, 0.652)},
    50: {20: (2.138, 0.039), 100: (14.845, 0.366), 200: (30.667, 1.148)},
    100: {20: (10.786, 0.091), 100: (60.808, 0.623), 200: (121.544, 2.110)},
}
print("\nExample 10 (h = 0.01, whole run, seconds; build = operators from M, C, K):\n")
print("| N | t_tot | paper Newmark | paper AEM | ours `AForm` | ours `Linear` | build `Linear` | build `AForm` |")
print("|---|---|---|---|---|---|---|---|")
for n in [25, 50, 100]:
    g = f"example10/N={n}"
    ba = res.get((g, "build aem", None)) or res.get((g, "build aem", ""))
    bf = res.get((g, "build aem-aform", None)) or res.get((g, "build aem-aform", ""))
    for t in [20, 100, 200]:
        pa = PAPER[n][t]
        a = res.get((g, "run aem", str(t)))
        f = res.get((g, "run aem-aform", str(t)))
        s = lambda x: f"{x * 1e-9:.4f}" if x else "–"
        print(f"| {n} | {t} | {pa[0]} | {pa[1]} | {s(f)} | {s(a)} | {s(ba)} | {s(bf)} |")


# ---------------------------------------------------------------------------------------
# docs/performance.md: the kernel against the machine's floor and the nalgebra loop.
SIZE = {"f64": 8, "f32": 4}
for ty in ["f64", "f32"]:
    peak = fast.get(("floor", f"compute-{ty}", None)) or fast.get(("floor", f"compute-{ty}", ""))
    macs = elements.get(("floor", f"compute-{ty}", None))  # LANES·256 (xtask/benches/steps.rs)
    peak = macs / peak if peak and macs else None  # multiply-adds per ns
    print(f"\n`Linear<{ty}, N>` against the floor (fastest sample; compute peak of this run "
          f"(AVX where the CPU has it) {peak:.1f} multiply-adds per ns; operators {3 * SIZE[ty]}N² bytes):\n" if peak else "")
    print("| N | `Linear` | multiply-adds / ns | floor: read operators | floor: compute | share of floor | "
          "nalgebra `DMatrix` loop | `Linear` speed-up | `AForm` | `AForm` multiply-adds / ns |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for n in NS:
        g = f"step/{ty}"
        t = fast.get((g, "aem", str(n)))
        if t is None:
            continue
        macs = 3 * n * n + 7 * n
        rd = fast.get((g, "floor-read", str(n)))
        comp = 3 * n * n / peak if peak else None
        floor = max(x for x in [rd, comp] if x is not None) if (rd or comp) else None
        nal = fast.get((g, "nalgebra-dmatrix", str(n)))
        af = fast.get((g, "aem-aform", str(n)))
        share = f"{floor / t * 100:.0f} %" if floor else "–"
        sp = f"{nal / t:.2f}×" if nal else "–"
        afr = f"{12 * n * n / af:.2f}" if af else "–"
        print(f"| {n} | {fmt_ns(t)} | {macs / t:.2f} | {fmt_ns(rd)} | {fmt_ns(comp)} | {share} | "
              f"{fmt_ns(nal)} | {sp} | {fmt_ns(af)} | {afr} |")

print("\nPaper Table 1 (MATLAB AEM) against `Linear<f64, N>`, whole runs of t_tot / h steps "
      "(fastest sample):\n")
print("| N | t_tot | steps | paper AEM (s) | ours `Linear` (s) | ratio | ours `AForm` (s) | ratio |")
print("|---:|---:|---:|---:|---:|---:|---:|---:|")
for n in [25, 50, 100]:
    g = f"example10/N={n}"
    for t in [20, 100, 200]:
        a = fast.get((g, "run aem", str(t)))
        f = fast.get((g, "run aem-aform", str(t)))
        pa = PAPER[n][t][1]
        ra = f"{pa / (a * 1e-9):.0f}×" if a else "–"
        rf = f"{pa / (f * 1e-9):.0f}×" if f else "–"
        sa = f"{a * 1e-9:.4f}" if a else "–"
        sf = f"{f * 1e-9:.4f}" if f else "–"
        print(f"| {n} | {t} | {int(round(t / 0.01))} | {pa} | {sa} | {ra} | {sf} | {rf} |")
