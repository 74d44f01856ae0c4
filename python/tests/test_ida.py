"""IDA of the yielding shear building from Python (aemstep::ida through ida_stripes,
ida_hunt_fill, ida_fractiles) against direct shear_building runs and numpy."""

import numpy as np
import pytest

import aemstep
from conftest import rayleigh, shear_matrices

MASSES = np.full(3, 1e5)  # kg
K = 1e8  # N/m
FY = np.array([6e5, 5e5, 3.5e5])  # N
ALPHA = 0.05


def building():
    """The three-storey building of test_building.py in ida_* form."""
    m, k = shear_matrices(MASSES, [K] * 3)
    params = np.column_stack([np.full(3, K), FY, np.full(3, ALPHA)])
    return dict(masses=MASSES, law="bilinear", params=params, c=rayleigh(m, k, 0.02))


def suite(elcentro):
    """Three short records (m/s², dt 0.02 s) cut from El Centro: different phases and
    signs, so the curves differ."""
    ag, dt = elcentro
    return [ag[:600].copy(), -ag[150:800].copy(), 1.3 * ag[300:900]], dt


def direct_peak(rec, dt, scale, **newton):
    """The peak absolute storey drift (m) of one shear_building run of `scale × rec`."""
    b = building()
    r = aemstep.shear_building(
        b["masses"], b["c"], dt, scale * rec, k=K, fy=FY, alpha=ALPHA, energy=False, **newton
    )
    return r.peak_drifts.max()


def test_stripes_equal_direct_shear_building_runs_bitwise(elcentro):
    recs, dt = suite(elcentro)
    ims = [2.0, 0.5, 1.0, 4.0]  # any order: each curve comes back sorted
    collapse = 0.02  # m: some runs at 4.0 collapse by drift
    curves = aemstep.ida_stripes(recs, dt, ims, collapse_drift=collapse, **building())
    assert len(curves) == len(recs)
    seen_collapse = False
    for rec, cur in zip(recs, curves):
        assert cur.intensity.tolist() == sorted(ims)
        direct = np.array([direct_peak(rec, dt, s) for s in sorted(ims)])
        # Same start, same steps, same drift rule: equal to the last bit (measured: 0 ulp).
        np.testing.assert_array_equal(cur.drift, direct)
        np.testing.assert_array_equal(cur.collapsed, direct >= collapse)
        assert cur.error == [None] * len(ims)
        if cur.collapsed.any():
            seen_collapse = True
            first = int(np.argmax(cur.collapsed))
            lo = cur.intensity[first - 1] if first > 0 else 0.0
            assert cur.collapse == (lo, cur.intensity[first])
        else:
            assert cur.collapse is None
    assert seen_collapse, "the test should exercise a collapse by drift"


def test_failed_runs_collapse_or_abort(elcentro):
    recs, dt = suite(elcentro)
    newton = dict(max_iterations=1, tolerance=1e-14)  # fails once a storey yields
    b = building()
    cur = aemstep.ida_stripes(recs[:1], dt, [0.01, 3.0], **b, **newton)[0]
    with pytest.raises(aemstep.NotConverged):
        direct_peak(recs[0], dt, 3.0, **newton)
    assert cur.drift[0] == direct_peak(recs[0], dt, 0.01, **newton)
    assert cur.drift[1] == np.inf and cur.collapsed.tolist() == [False, True]
    assert cur.error == [None, "NotConverged"] and cur.collapse == (0.01, 3.0)
    with pytest.raises(aemstep.NotConverged):
        aemstep.ida_stripes(recs[:1], dt, [0.01, 3.0], on_failure="abort", **b, **newton)


def test_hunt_fill_brackets_the_collapse_of_direct_runs(elcentro):
    recs, dt = suite(elcentro)
    collapse, runs, resolution = 0.015, 12, 0.05
    curves = aemstep.ida_hunt_fill(
        recs, dt, collapse_drift=collapse, runs=runs, resolution=resolution, **building()
    )
    for rec, cur in zip(recs, curves):
        im = cur.intensity
        assert 1 <= im.shape[0] <= runs
        assert np.all(np.diff(im) > 0)  # sorted, distinct
        lo, hi = cur.collapse  # every record of the suite collapses below 2.1
        assert 0 <= lo < hi and hi - lo <= resolution
        # The bracket by direct runs: no collapse at lo, collapse at hi.
        assert lo == 0.0 or direct_peak(rec, dt, lo) < collapse
        assert direct_peak(rec, dt, hi) >= collapse
        # The points are the direct runs at their intensities.
        np.testing.assert_array_equal(cur.drift, [direct_peak(rec, dt, s) for s in im])


def test_results_do_not_depend_on_the_thread_count(elcentro):
    recs, dt = suite(elcentro)
    b = building()
    for f, kw in [
        (aemstep.ida_stripes, dict(intensities=[0.3, 0.9, 1.7, 2.5])),
        (aemstep.ida_hunt_fill, dict(collapse_drift=0.015)),
    ]:
        one = f(recs, dt, threads=1, **kw, **b)
        two = f(recs, dt, threads=2, **kw, **b)
        for a, c in zip(one, two):
            for key in ("intensity", "drift", "collapsed"):
                np.testing.assert_array_equal(getattr(a, key), getattr(c, key))
            assert a.collapse == c.collapse


# Each law the package exposes: its ida_* parameter row (one a storey) and the same
# storeys as shear_building's keywords.
LAWS = {
    "bilinear": ([], {}),
    "bouc_wen": ([0.5, 0.5, 1.0], dict(beta=0.5, gamma=0.5, n=1.0)),
    "bilinear_friction": ([5e4, 1e-3], dict(fs=5e4, vr=1e-3)),
}


def law_building(law, dense=False):
    """building() with `law`'s storeys; `dense`: a damping C coupling storeys 1 and 3 (not
    tridiagonal: the lanes fall back to single steps)."""
    b = dict(building(), law=law)
    extra, _ = LAWS[law]
    b["params"] = np.column_stack([b["params"]] + [np.full(3, x) for x in extra])
    if dense:
        c = b["c"].copy()
        c[0, 2] = c[2, 0] = 0.1 * c[0, 1]
        b["c"] = c
    return b


def direct_run(b, rec, dt, scale, **newton):
    """(peak drift, error name): one shear_building run of `scale × rec` with building `b`
    (`inf` and the error's class name for a run that fails)."""
    _, kw = LAWS[b["law"]]
    try:
        r = aemstep.shear_building(
            b["masses"], b["c"], dt, scale * rec, k=K, fy=FY, alpha=ALPHA, law=b["law"],
            energy=False, histories=False, **kw, **newton
        )
    except aemstep.AemstepError as e:
        return np.inf, type(e).__name__
    return r.peak_drift, None


def lane_suite(elcentro):
    """Five records of different lengths (120 to 1000 samples): more than one batch of
    lanes, the last one partly filled, lanes ending at different steps."""
    ag, dt = elcentro
    return [ag[:600].copy(), -ag[150:800].copy(), 1.3 * ag[300:900], ag[50:170].copy(),
            -0.7 * ag[400:1400]], dt


@pytest.mark.parametrize("law", sorted(LAWS))
def test_lanes_equal_single_runs_bitwise_for_every_law(elcentro, law):
    """The runs go four at a time in SIMD lanes (aemstep::lanes): every curve point is the
    direct shear_building run's peak drift to the last bit, for every law, records of
    different lengths, runs that fail beside runs that do not (the failed ones collapse with
    their error), a dense damping matrix, on 1 and 2 threads, stripes and hunt-and-fill."""
    recs, dt = lane_suite(elcentro)
    cases = [
        (law_building(law), {}, [2.0, 0.5, 4.0]),
        # Newton with one iteration: small runs converge, yielding ones fail (NotConverged),
        # side by side in the same batches.
        (law_building(law), dict(max_iterations=1, tolerance=1e-14), [0.01, 3.0]),
    ]
    if law == "bilinear":
        cases.append((law_building(law, dense=True), {}, [0.5, 3.0]))
    errors = set()
    for b, newton, ims in cases:
        direct = [[direct_run(b, rec, dt, s, **newton) for s in sorted(ims)] for rec in recs]
        errors |= {e for row in direct for _, e in row}
        for threads in (1, 2):
            curves = aemstep.ida_stripes(recs, dt, ims, threads=threads, **b, **newton)
            for cur, want in zip(curves, direct):
                np.testing.assert_array_equal(cur.drift, [d for d, _ in want])
                assert cur.error == [e for _, e in want]
                np.testing.assert_array_equal(cur.collapsed, [e is not None for _, e in want])
    assert errors == {None, "NotConverged"}, "runs should fail beside runs that converge"
    b = law_building(law)
    curves = aemstep.ida_hunt_fill(recs, dt, collapse_drift=0.015, runs=8, threads=2, **b)
    for rec, cur in zip(recs, curves):
        want = [direct_run(b, rec, dt, s)[0] for s in cur.intensity]
        np.testing.assert_array_equal(cur.drift, want)
        np.testing.assert_array_equal(cur.collapsed, np.array(want) >= 0.015)
    assert sum(cur.collapse is not None for cur in curves) >= 3, "traces should collapse"


def hand_intensity_at(cur, level):
    """The intensity where a curve first reaches `level` (numpy, for the fractile test):
    its non-collapsing points below its lowest collapse, from the origin, linear."""
    if level <= 0:
        return 0.0
    im, e, col = cur.intensity, cur.drift, cur.collapsed
    cap = im[col].min() if col.any() else np.inf
    keep = ~col & (im < cap)
    x = np.concatenate([[0.0], im[keep]])
    y = np.concatenate([[0.0], e[keep]])
    above = np.nonzero(y >= level)[0]
    if above.size:
        j = above[0]  # y[j-1] < level <= y[j]
        return x[j - 1] + (level - y[j - 1]) / (y[j] - y[j - 1]) * (x[j] - x[j - 1])
    return x[-1]  # past its last point: the flatline of a collapsed curve


def curve(intensity, drift, collapsed):
    """A hand-made IdaCurve (no run errors; collapse left to ida_fractiles)."""
    return aemstep.IdaCurve(intensity, drift, collapsed, [None] * len(intensity), None)


def test_fractiles_equal_a_numpy_hand_computation():
    curves = [
        curve(intensity=np.array([0.2, 0.4, 0.6, 0.8]), drift=np.array([0.004, 0.009, 0.02, np.inf]),
             collapsed=np.array([False, False, False, True])),
        curve(intensity=np.array([0.1, 0.3, 0.5]), drift=np.array([0.003, 0.011, 0.03]),
             collapsed=np.array([False, False, True])),
        curve(intensity=np.array([0.25, 0.5, 1.0, 1.2]), drift=np.array([0.002, 0.006, 0.015, 0.05]),
             collapsed=np.array([False, False, False, False])),
        curve(intensity=np.array([0.3, 0.6, 0.9]), drift=np.array([0.005, 0.012, np.inf]),
             collapsed=np.array([False, False, True])),
    ]
    levels = np.array([0.0, 0.001, 0.005, 0.01, 0.02, 0.04])
    q = (0.16, 0.5, 0.84)
    got = aemstep.ida_fractiles(curves, levels, q)
    assert got.shape == (3, levels.shape[0])
    hand = np.array([[np.quantile([hand_intensity_at(c, lv) for c in curves], qk) for lv in levels]
                     for qk in q])
    # The same formulas, but numpy's quantile interpolates as b − (b − a)(1 − t) for
    # t ≥ 0.5 where the library uses a + t (b − a): a few ulp may differ. Intensities here
    # are ≤ 1.2 (ulp 2.2e-16), so 1e-15 is about 4 ulp. Measured: 0 (bitwise equal).
    np.testing.assert_allclose(got, hand, rtol=0, atol=1e-15)


def test_fractiles_nan_where_censored_curves_decide():
    never = curve(intensity=np.array([0.5, 1.0]), drift=np.array([0.001, 0.002]),
                  collapsed=np.array([False, False]))
    reached = curve(intensity=np.array([0.5, 1.0]), drift=np.array([0.01, 0.02]),
                    collapsed=np.array([False, False]))
    f = aemstep.ida_fractiles([never, reached], [0.015], q=(0.0, 1.0))
    # q=0: the reached curve's 0.75 is below the censored one's "> 1.0": known. q=1: not.
    assert f[0, 0] == 0.75 and np.isnan(f[1, 0])


def test_progress_callable_ends_at_total_and_bar_runs(elcentro):
    recs, dt = suite(elcentro)
    calls = []
    aemstep.ida_stripes(recs, dt, [0.5, 1.0], progress=lambda d, t: calls.append((d, t)),
                        **building())
    assert calls and calls[-1] == (6, 6)
    assert all(a[0] <= b[0] for a, b in zip(calls, calls[1:]))
    calls.clear()
    aemstep.ida_hunt_fill(recs, dt, collapse_drift=0.015, runs=8,
                          progress=lambda d, t: calls.append((d, t)), **building())
    assert calls[-1] == (3 * 8, 3 * 8)
    # True: a tqdm bar when tqdm is importable, else nothing; no error either way.
    aemstep.ida_stripes(recs[:1], dt, [0.5], progress=True, **building())


def test_an_exception_in_progress_stops_and_propagates(elcentro):
    recs, dt = suite(elcentro)

    def stop(done, total):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        aemstep.ida_stripes(recs, dt, [0.5, 1.0], progress=stop, **building())


def test_bad_settings_are_typed_errors(elcentro):
    recs, dt = suite(elcentro)
    b = building()
    with pytest.raises(aemstep.InvalidParameter):
        aemstep.ida_stripes(recs, dt, [0.5, -1.0], **b)
    with pytest.raises(aemstep.InvalidParameter):
        aemstep.ida_stripes(recs, dt, [0.5], collapse_drift=0.0, **b)
    for bad in [dict(runs=0), dict(runs=-3), dict(first=0.0), dict(resolution=np.nan),
                dict(step_increment=-0.1)]:
        with pytest.raises(aemstep.InvalidParameter):
            aemstep.ida_hunt_fill(recs, dt, **bad, **b)
    with pytest.raises(aemstep.InvalidTimeStep):
        aemstep.ida_stripes(recs, -dt, [0.5], **b)
    with pytest.raises(aemstep.InvalidNewtonSettings):
        aemstep.ida_stripes(recs, dt, [0.5], max_iterations=0, **b)
    with pytest.raises(aemstep.InvalidMaterial):
        aemstep.ida_stripes(recs, dt, [0.5], **{**b, "params": -b["params"]})
    with pytest.raises(aemstep.ShapeError):
        aemstep.ida_stripes(recs, dt, [0.5], **{**b, "params": b["params"][:, :2]})
    with pytest.raises(aemstep.ShapeError):
        aemstep.ida_stripes([recs[0], np.zeros(0)], dt, [0.5], **b)
    with pytest.raises(aemstep.UnsupportedSize):
        aemstep.ida_stripes(recs, dt, [0.5], masses=np.full(11, 1e5), law="bilinear",
                            params=np.tile(b["params"][:1], (11, 1)), c=np.eye(11))
    with pytest.raises(ValueError, match="unknown law"):
        aemstep.ida_stripes(recs, dt, [0.5], **{**b, "law": "elastic"})
    with pytest.raises(ValueError, match="on_failure"):
        aemstep.ida_stripes(recs, dt, [0.5], on_failure="ignore", **b)
    with pytest.raises(TypeError):
        aemstep.ida_stripes(recs, dt, [0.5], progress=3, **b)
    with pytest.raises(aemstep.InvalidParameter):
        aemstep.ida_fractiles([], [0.01])
    cur = aemstep.ida_stripes(recs[:1], dt, [0.5], **b)
    with pytest.raises(aemstep.InvalidParameter):
        aemstep.ida_fractiles(cur, [0.01], q=(1.5,))
    assert aemstep.ida_stripes([], dt, [0.5], **b) == []


def test_ctrl_c_stops_a_long_batch(elcentro):
    """SIGINT while the runs go: KeyboardInterrupt, raised at the next poll (0.1 s), the
    rest of the batch cancelled (progress never reached the total)."""
    import os
    import signal
    import threading
    import time

    ag, dt = elcentro
    recs = [ag, -ag, np.roll(ag, 500), -np.roll(ag, 500)]  # 3995 steps each
    ims = np.linspace(0.01, 1.0, 700)  # 2 800 runs, 11 M steps: over a second
    seen = []
    timer = threading.Timer(0.05, lambda: os.kill(os.getpid(), signal.SIGINT))
    t = time.perf_counter()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        aemstep.ida_stripes(recs, dt, ims, threads=1, progress=lambda d, n: seen.append(d),
                            **building())
    elapsed = time.perf_counter() - t
    timer.join()
    total = len(recs) * len(ims)
    # The whole batch's time, estimated from 1/70 of it (40 of the 2 800 runs).
    t = time.perf_counter()
    aemstep.ida_stripes(recs, dt, ims[::70], threads=1, **building())
    full = 70 * (time.perf_counter() - t)
    print(f"interrupted after {elapsed:.2f} s of about {full:.2f} s, "
          f"{seen[-1] if seen else 0} of {total} runs reported")
    assert elapsed < 0.5 * full
    assert not seen or seen[-1] < total
