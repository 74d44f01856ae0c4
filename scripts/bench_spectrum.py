#!/usr/bin/env python3
"""Writes docs/spectrum.md: speed of aemstep's response spectra beside `sdof.spectrum` (PyPI,
C-backed) in one run, batch throughput, Cortex-M4F instructions per sample, and the
accuracy tables and test measurements, every number from a command run here.

    pip install sdof          # the comparator (only this script needs it)
    python3 scripts/bench_spectrum.py [--quick]

Runs, in this order: sdof timed; `cargo bench -p xtask --bench spectrum`; sdof timed
again (so a change of machine load between the two shows); the accuracy tables
(`cargo run --release -p xtask --bin spectrum -- --tables`); the CSV spectra and
the plot (`... --bin spectrum -- --out docs`); the measurements printed by
`cargo test --release --features std --test spectrum`; the firmware under QEMU
(`cargo run -p aemstep-firmware --release --target thumbv7em-none-eabihf --example qemu_spectrum`).

Timings are host wall-clock times on a shared machine: both sides are reported as the
fastest and the median of their repetitions; the ratio uses the fastest (the least
disturbed by other processes).
"""
import glob
import json
import os
import platform
import statistics
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
os.chdir(ROOT)
G = 9.80665
DT = 0.02
REPS = 20 if "--quick" in sys.argv else 200


# The page opens with code a user can paste (compiled and run by scripts/downstream.py).
USE_IT = r"""## Use it

The response spectrum of a ground-acceleration record, one sample at a time (the same code
runs in firmware, in `f32`, with the bank in a `static`):

```rust
use aemstep::spectrum::Bank;

// 4 periods (s), 5 % damping each, samples every dt = 0.02 s; the default exact scheme.
let bank = Bank::<f64, 4>::new([0.2, 0.5, 1.0, 2.0], [0.05; 4], 0.02)?;
let mut r = bank.at_rest();
let record = (0..1500).map(|n| 3.0 * (7.0 * 0.02 * n as f64).sin()); // a_g, m/s²
for a_g in record {
    bank.step(&mut r, a_g); // about 10 multiply-adds per period
}
// Long periods may peak after the record ends: let them ring out.
bank.free_vibration(&mut r, bank.free_vibration_samples());
let (sd, psa) = (r.sd(), bank.psa(r.sd())); // peak |u| (m) and ω² Sd (m/s²), per period
assert!(sd.iter().chain(psa.iter()).all(|x| *x > 0.0));
# Ok::<(), aemstep::Error>(())
```

Many records on the host, in parallel: `spectrum::batch` (feature `std`).

Extreme records: `bank.step` is the bare recurrence (its cost above, unchecked).
`bank.try_step` commits a sample only if the response stays finite, and
`bank.response(&record)` (the record, then one longest period of free vibration) and
`batch::spectra` check the response once at the end: a finite sample that overflows it
(`1.5e308` then `-1.5e308`) is `Error::NonFiniteState`, never a spectrum with `inf` or
`NaN` in it; non-finite samples are still skipped and counted. A free-vibration tail longer
than `spectrum::MAX_FREE_VIBRATION_SAMPLES` (2^20 samples: a step far below the record's) is
`Error::InvalidTimeStep`: resample the record first (`records::resample_into`).
"""

def sh(cmd, **kw):
    print("+", " ".join(cmd), file=sys.stderr, flush=True)
    return subprocess.run(cmd, check=True, text=True, capture_output=True, **kw).stdout


def elcentro():
    with open("data/elcentro-ns-1940.txt") as f:
        return np.array([float(l) for l in f if l.strip() and not l.startswith("#")]) * G


def time_sdof(ag):
    import sdof

    per = np.linspace(0.01, 10.0, 100)
    sdof.spectrum(ag, DT, 0.05, periods=per, threads=1)  # warm up
    ts = []
    for _ in range(REPS):
        t = time.perf_counter()
        sdof.spectrum(ag, DT, 0.05, periods=per, threads=1)
        ts.append(time.perf_counter() - t)
    return min(ts), statistics.median(ts)


def criterion():
    """{full_id: (min, median)} of seconds per iteration, from criterion's raw samples."""
    out = {}
    target = os.environ.get("CARGO_TARGET_DIR", "target")  # where criterion writes its samples
    for path in glob.glob(os.path.join(target, "criterion/**/new/sample.json"), recursive=True):
        bench = json.load(open(os.path.join(os.path.dirname(path), "benchmark.json")))
        s = json.load(open(path))
        per = [t / i * 1e-9 for t, i in zip(s["times"], s["iters"])]
        out[bench["full_id"]] = (min(per), statistics.median(per))
    return out


def ms(x):
    return f"{x * 1e3:.3f}"


def main():
    import sdof

    ag = elcentro()
    load0 = os.getloadavg()
    sdof_before = time_sdof(ag)
    bench_args = ["cargo", "bench", "-p", "xtask", "--bench", "spectrum"]
    if "--quick" in sys.argv:
        bench_args += ["--", "--quick"]
    bench_out = sh(bench_args)
    single = {l.split()[1]: float(l.split()[2]) for l in bench_out.splitlines() if l.startswith("FASTEST ")}
    sdof_after = time_sdof(ag)
    load1 = os.getloadavg()
    res = criterion()
    tables = sh(["cargo", "run", "-q", "--release", "-p", "xtask", "--bin", "spectrum", "--", "--tables"])
    files = sh(["cargo", "run", "-q", "--release", "-p", "xtask", "--bin", "spectrum", "--", "--out", "docs"])
    tests = sh(["cargo", "test", "-q", "--release", "--features", "std", "--test", "spectrum", "--",
                "--nocapture", "--test-threads", "1"])
    lin = [np.array([float(x) for x in l.split()]) for l in sh(
        ["cargo", "run", "-q", "--release", "-p", "xtask", "--bin", "spectrum", "--", "--linear-sd"]
    ).split("\n") if l.strip()]
    sd_sdof = sdof.spectrum(ag, DT, 0.05, periods=np.linspace(0.01, 10.0, 100), threads=1)[0][1]
    d_aem = np.abs(sd_sdof - lin[0]) / lin[0]
    d_exact = np.abs(sd_sdof - lin[1]) / lin[1]
    fw = sh(["cargo", "run", "-q", "-p", "aemstep-firmware", "--release", "--target", "thumbv7em-none-eabihf",
             "--example", "qemu_spectrum"])
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    sdof_min = min(sdof_before[0], sdof_after[0])

    L = []
    w = L.append
    w("# Response spectra (`aemstep::spectrum`): speed, accuracy, firmware cost\n")
    w("Generated by `python3 scripts/bench_spectrum.py` — do not edit by hand. Every number below comes from")
    w("a command that script runs (named in each section).\n")
    w(USE_IT)
    w("## Host speed beside `sdof` (host timings)\n")
    w(f"Host: {cpu}, {os.cpu_count()} cores shared with other work (load average {load0[0]:.1f} at the start, <!-- host timing -->")
    w(f"{load1[0]:.1f} at the end), Python `{platform.python_version()}`, `sdof` {getattr(sdof, '__version__', '(no version attribute)')}. <!-- host timing -->")
    w("Record: El Centro NS 1940, 3 995 samples at `dt = 0.02 s`; 5 % damping; 100 periods.")
    w("`sdof.spectrum(ag, dt, 0.05, periods, threads=1)` (its C path, one thread; it takes the periods as a linear range, so the")
    w("comparison uses 100 periods spaced linearly from `0.01 s` to `10 s` for both) was timed "
      f"{REPS} times before and {REPS} times after")
    w("`cargo bench -p xtask --bench spectrum` in the same run; the benchmark times each spectrum by criterion")
    w("(20 samples; the median of its per-sample means is shown) and then as 200 single calls (`sdof`: the median")
    w("of its calls). Times are wall-clock on a shared machine; the ratio compares the fastest single call of each side (the same estimator on both, the")
    w("least disturbed by the other processes). On a CPU with AVX the bank's per-sample step runs on 256-bit registers")
    w("(4 `f64` or 8 `f32` oscillators a packed operation, chosen at run time, the same bits as the SSE2 loop:")
    w("`cargo test --lib --features std wide_path_is_bit_identical`).\n")
    w("| computation | periods | host: fastest single call (ms) | host: median (ms) | host ratio: sdof fastest / this |")
    w("|---|---|---:|---:|---:|")
    w(f"| `sdof.spectrum`, threads=1, before the benchmark | linear | {ms(sdof_before[0])} | {ms(sdof_before[1])} | |")
    w(f"| `sdof.spectrum`, threads=1, after the benchmark | linear | {ms(sdof_after[0])} | {ms(sdof_after[1])} | |")
    names = {
        "exact-auto": "exact scheme, default sub-step rule",
        "exact-1": "exact scheme, no sub-steps",
        "aem-1": "AEM, no sub-steps",
    }
    for pk, pname in [("lin", "linear"), ("log", "`log 0.01–10 s`")]:
        for ty in ["f64", "f32"]:
            for sk, sname in names.items():
                key = f"spectrum/{ty}/{pk}/{sk}"
                if key not in res:
                    continue
                mn = single[key]
                md = res[key][1]
                ratio = f"{sdof_min / mn:.1f}×" if pk == "lin" else ""
                w(f"| `Bank<{ty}, 100>`, {sname} | {pname} | {ms(mn)} | {ms(md)} | {ratio} |")
    w("")
    w("`sdof` is given Newmark's average acceleration (its defaults β = 1/4, γ = 1/2: the AEM's scheme). Its Sd")
    w(f"differs from the bank's \"AEM, no sub-steps\" by {100 * d_aem.max():.1f} % at most (median {100 * np.median(d_aem):.1f} %), <!-- peer run -->")
    w(f"from the exact scheme with the default rule by {100 * d_exact.max():.1f} % at most (median {100 * np.median(d_exact):.1f} %; <!-- peer run -->")
    w("`cargo run --release -p xtask --bin spectrum -- --linear-sd` against `sdof.spectrum`). The like-for-like")
    w("comparison is therefore the \"no sub-steps\" rows; the default rule also searches the peaks between samples")
    w("(accuracy below).\n")
    w("### Batch throughput (host timings)\n")
    w("`spectrum::batch::spectra`: 32 records (El Centro scaled), `Bank<f64, 100>` (log periods, exact,")
    w("default rule), from `cargo bench -p xtask --bench spectrum` (group `batch32`).\n")
    w("| threads | host: fastest (ms) for 32 records | host: records / s |")
    w("|---:|---:|---:|")
    for key in sorted(k for k in res if k.startswith("batch32/")):
        mn, _ = res[key]
        w(f"| {key.split('threads')[-1]} | {ms(mn)} | {32 / mn:.0f} |")
    w("")
    w("## Cortex-M4F: instructions per incoming sample\n")
    w("`cargo run -p aemstep-firmware --release --target thumbv7em-none-eabihf --example qemu_spectrum` (QEMU")
    w("`mps2-an386`, `-icount shift=0`): `Bank<f32, P>`, 5 %, exact scheme, default rule, El Centro, averaged")
    w("over the record (sub-step walks included); multiply-adds: the whole-interval steps, 10P.\n")
    w("| bank | instructions / sample | multiply-adds / sample |")
    w("|---|---:|---:|")
    for line in fw.splitlines():
        if line.startswith("COST spectrum"):
            _, what, instr, madds = line.split()
            w(f"| `{what}` | {instr} | {madds} |")
    w("")
    w("The same rows are in [cortex-m4-cost.md](cortex-m4-cost.md), written by `bash scripts/qemu.sh`; the")
    w("firmware checks its spectrum against the host's `f64` one within a bound measured on the host, and its")
    w("bits against the host's `f32` run.\n")
    w("## Accuracy\n")
    w("The tables (peak error against the sub-step count, the sub-step rule, free vibration after the")
    w("record, schemes and precision) are in [spectrum_tables.md](spectrum_tables.md), generated by")
    w("`cargo run --release -p xtask --bin spectrum -- --tables` and re-checked by the test command.")
    w("`tests/spectrum.rs` checks the bank against closed forms (step and harmonic ground motion, every period)")
    w("and independent computations (Nigam–Jennings steps and a small-step RK4 on El Centro), each against a")
    w("bound derived in the test; `cargo test --release --features std --test spectrum -- --nocapture` prints")
    w("the measured ratios.\n")
    w("## Files\n")
    w("`cargo run --release -p xtask --bin spectrum -- --out docs` read `data/` (the one-column")
    w("El Centro file and its `.AT2` re-formatting) and wrote:\n")
    for line in files.splitlines():
        w(f"- `{line}`")
    w("\n![PSA](spectrum.svg)\n")
    open("docs/spectrum.md", "w").write("\n".join(L))
    print("wrote docs/spectrum.md")


if __name__ == "__main__":
    main()
