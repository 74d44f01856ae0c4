#!/usr/bin/env python3
"""Turn criterion's output of `cargo bench --bench steps` into the README's tables.

Reads target/criterion/**/new/{benchmark,estimates}.json (median estimates) and prints
Markdown: time per step against N for every scheme and scalar type, the multiply-add
counts and the fast-form / A-form ratio, and the paper's Example 10 table beside ours.
Usage: python3 scripts/bench_table.py [criterion-dir]
"""
import json
import os
import sys

root = sys.argv[1] if len(sys.argv) > 1 else "target/criterion"
res = {}
for dirpath, _, files in os.walk(root):
    if os.path.basename(dirpath) == "new" and "estimates.json" in files:
        b = json.load(open(os.path.join(dirpath, "benchmark.json")))
        e = json.load(open(os.path.join(dirpath, "estimates.json")))
        res[(b["group_id"], b["function_id"], b["value_str"])] = e["median"]["point_estimate"]

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
