#!/usr/bin/env python3
"""The numpy comparator for `AForm`: a plain numpy loop of the paper's literal A-form,
U_n = A U_{n-1} + b p_n (U = (q, v, u), A is 3N x 3N, b is 3N x N: 12N^2 multiply-adds a
step), on the same random systems as `xtask/benches/steps.rs` (same generator and seed), h = 0.01.

Not part of the test command (numpy comes from PyPI: `pip install numpy`). Run it beside
`cargo bench -p xtask --bench steps -- 'step/f64/aem-aform'` and compare (docs/performance.md):

    python3 scripts/bench_numpy_aform.py [N ...]

Prints the time per step (fastest of 7 runs of at least 0.2 s each: the machine may be
shared) and multiply-adds per ns, one Markdown row per N.
"""
import sys
import time

import numpy as np


def rng(seed):
    """The xorshift generator of xtask/benches/steps.rs, values in [-1, 1)."""
    s = seed & 0xFFFFFFFFFFFFFFFF
    while True:
        s ^= (s << 13) & 0xFFFFFFFFFFFFFFFF
        s ^= s >> 7
        s ^= (s << 17) & 0xFFFFFFFFFFFFFFFF
        yield (s >> 11) / float(1 << 52) - 1.0


def system(n):
    r = rng(0x9E3779B97F4A7C15 ^ n)

    def spd(diag):
        a = np.zeros((n, n))
        for i in range(n):
            for j in range(i + 1):
                x = next(r)
                a[i, j] = x
                a[j, i] = x
            a[i, i] = diag + n
        return a

    m = spd(10.0)
    k = spd(1000.0) * 10.0
    c = m * 0.01 + k * 0.001
    return m, c, k


def a_form(m, c, k, h):
    """A and b of U_n = A U_{n-1} + b p_n for the AEM (Newmark average acceleration)."""
    n = m.shape[0]
    g = np.linalg.inv(m + (h / 2) * c + (h * h / 4) * k)
    gc, gk = g @ c, g @ k
    i = np.eye(n)
    aqq = -(h / 2) * gc - (h * h / 4) * gk
    aqv = -gc - h * gk
    aqu = -gk
    a = np.block([
        [aqq, aqv, aqu],
        [(h / 2) * (i + aqq), i + (h / 2) * aqv, (h / 2) * aqu],
        [(h * h / 4) * (i + aqq), h * i + (h * h / 4) * aqv, i + (h * h / 4) * aqu],
    ])
    b = np.vstack([g, (h / 2) * g, (h * h / 4) * g])
    return np.ascontiguousarray(a), np.ascontiguousarray(b)


def per_step(n, h=0.01):
    a, b = a_form(*system(n), h)
    p = np.ones(n)
    u = np.zeros(3 * n)
    steps = 1
    while True:  # calibrate: at least 0.2 s a run
        t = time.perf_counter()
        for _ in range(steps):
            u = a @ u + b @ p
        if time.perf_counter() - t > 0.2:
            break
        steps *= 2
    best = float("inf")
    for _ in range(7):
        t = time.perf_counter()
        for _ in range(steps):
            u = a @ u + b @ p
        best = min(best, (time.perf_counter() - t) / steps)
    assert np.all(np.isfinite(u))
    return best


def main():
    ns = [int(x) for x in sys.argv[1:]] or [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 25, 50, 100]
    print(f"numpy {np.__version__}; time per step of `U = A @ U + b @ p` (12N² multiply-adds)\n")
    print("| N | numpy A-form | multiply-adds per ns |")
    print("|---:|---:|---:|")
    for n in ns:
        t = per_step(n)
        print(f"| {n} | {t * 1e9:.0f} ns | {12 * n * n / (t * 1e9):.2f} |", flush=True)


if __name__ == "__main__":
    main()
