"""Incremental dynamic analysis (IDA) of the yielding shear building: the wrappers of the
native ``ida_stripes``, ``ida_hunt_fill`` and ``ida_fractiles`` (re-exported by
``aemstep``).

An IDA runs every record of a suite scaled by a sequence of intensities (here the record
scale factor: the run's ground acceleration is ``intensity × record``) and keeps each
run's engineering demand parameter, the peak absolute storey drift (m) over the storeys
and the steps. A record's runs are its IDA curve; ``ida_fractiles`` summarizes a suite.
"""

from __future__ import annotations

from typing import Any, Callable, Dict, List, Optional, Sequence, Union

import numpy as np

from . import _aemstep

ArrayLike = Any
Progress = Union[bool, Callable[[int, int], Any], None]


def _records(records: Sequence[ArrayLike]) -> List[np.ndarray]:
    from . import ShapeError

    out = []
    for i, r in enumerate(records):
        a = np.ascontiguousarray(r, dtype=np.float64)
        if a.ndim != 1:
            raise ShapeError(f"record {i} must be 1-D, got shape {a.shape}")
        out.append(a)
    return out


def _building(masses: ArrayLike, params: ArrayLike, c: ArrayLike):
    from . import _mat, _vec

    return _vec(masses, "masses"), _mat(params, "params"), _mat(c, "c")


def _callback(progress: Progress, total: int):
    """``(callable for the native code or None, close())``: ``True`` is a tqdm bar if tqdm
    is importable (else nothing), a callable is called as ``progress(done, total)``."""
    if progress is None or progress is False:
        return None, (lambda: None)
    if progress is True:
        try:
            from tqdm import tqdm  # optional
        except ImportError:
            return None, (lambda: None)
        bar = tqdm(total=total, unit="run")

        def update(done: int, total: int) -> None:
            bar.update(done - bar.n)

        return update, bar.close
    if not callable(progress):
        raise TypeError("progress must be None, True or a callable progress(done, total)")
    return progress, (lambda: None)


def ida_stripes(
    records: Sequence[ArrayLike],
    h: float,
    intensities: ArrayLike,
    *,
    masses: ArrayLike,
    law: str,
    params: ArrayLike,
    c: ArrayLike,
    max_iterations: int = 20,
    tolerance: float = 1e-10,
    collapse_drift: float = float("inf"),
    on_failure: str = "collapse",
    threads: int = 0,
    progress: Progress = None,
) -> List[Dict[str, Any]]:
    """IDA curves on fixed stripes: every record at every intensity.

    ``records``: ground accelerations (m/s², each 1-D) sampled every ``h`` s.
    ``intensities``: record scale factors (finite, > 0, any order; each run is the record
    times the factor). ``masses`` (kg, ``n``), ``law``, ``params`` (``n×width``), ``c``
    (N·s/m, ``n×n``), ``max_iterations``, ``tolerance``: the building and Newton settings
    exactly as the native ``shear_building`` takes them (``law`` ``"bilinear"``: k N/m,
    fy N, alpha; ``"bouc_wen"``: k, fy, alpha, beta, gamma, n; ``"bilinear_friction"``:
    k, fy, alpha, fs N, vr m/s). ``collapse_drift``: peak storey drift (m, > 0; ``inf``:
    only failed runs collapse) at or above which a run has collapsed. ``on_failure``:
    ``"collapse"`` (a failed run, e.g. Newton not converging, is a collapse with drift
    ``inf``) or ``"abort"`` (the first failure in (record, intensity) order is raised,
    e.g. ``NotConverged``). ``threads``: 0 for every core; the curves are bit for bit
    those of one thread. ``progress``: ``None``, ``True`` (a tqdm bar if tqdm is
    installed) or ``progress(done, total)``, called from the calling thread about every
    0.1 s (``total = len(records) × len(intensities)``, the last call ``done == total``).
    Ctrl-C stops the runs and raises ``KeyboardInterrupt``.

    Returns one dict per record: ``intensity`` (sorted scale factors), ``drift`` (peak
    absolute storey drift, m; ``inf`` for a failed run), ``collapsed`` (bool),
    ``error`` (name of a failed run's error, or ``None``), ``collapse`` (``(lo, hi)``: the
    highest non-collapsing intensity below the lowest collapsing one (0 if none), and that
    lowest; ``None`` if no run collapsed).
    """
    recs = _records(records)
    ims = np.ascontiguousarray(intensities, dtype=np.float64).reshape(-1)
    m, p, cc = _building(masses, params, c)
    cb, close = _callback(progress, len(recs) * ims.shape[0])
    try:
        return _aemstep.ida_stripes(
            recs, float(h), ims, m, law, p, cc, int(max_iterations), float(tolerance),
            float(collapse_drift), on_failure, int(threads), cb,
        )
    finally:
        close()


def ida_hunt_fill(
    records: Sequence[ArrayLike],
    h: float,
    *,
    masses: ArrayLike,
    law: str,
    params: ArrayLike,
    c: ArrayLike,
    max_iterations: int = 20,
    tolerance: float = 1e-10,
    first: float = 0.1,
    step: float = 0.2,
    step_increment: float = 0.1,
    resolution: float = 0.05,
    runs: int = 12,
    collapse_drift: float = float("inf"),
    on_failure: str = "collapse",
    threads: int = 0,
    progress: Progress = None,
) -> List[Dict[str, Any]]:
    """IDA curves traced by hunt-and-fill (Vamvatsikos & Cornell 2002), at most ``runs``
    analyses a record.

    Per record: *hunt up* at scale factors ``first``, ``first + step``, … the step growing
    by ``step_increment`` a run (0.1, 0.3, 0.6, 1.0, 1.5, … by default) until a run
    collapses; *bracket* the collapse by bisection down to ``resolution``; *fill* the
    largest gaps below it with what is left of the budget. Arguments otherwise as
    ``ida_stripes`` (``total = len(records) × runs`` for ``progress``; a record that ends
    early counts its unused runs at once). Raises ``InvalidParameter`` for settings out of
    range (``first``, ``step``, ``resolution`` > 0, ``step_increment`` ≥ 0, ``runs`` in
    1..10 000, ``collapse_drift`` > 0) before any run.

    Returns the dicts of ``ida_stripes``: at most ``runs`` points each, sorted; when the
    record collapsed, ``collapse = (lo, hi)`` brackets its collapse intensity.
    """
    recs = _records(records)
    m, p, cc = _building(masses, params, c)
    cb, close = _callback(progress, len(recs) * max(int(runs), 0))
    try:
        return _aemstep.ida_hunt_fill(
            recs, float(h), m, law, p, cc, int(max_iterations), float(tolerance),
            float(first), float(step), float(step_increment), float(resolution), int(runs),
            float(collapse_drift), on_failure, int(threads), cb,
        )
    finally:
        close()


def ida_fractiles(
    curves: Sequence[Dict[str, Any]],
    drifts: ArrayLike,
    q: Sequence[float] = (0.16, 0.5, 0.84),
) -> np.ndarray:
    """Fractile IDA curves, *intensity given drift*: for each quantile ``q[k]`` (in
    [0, 1]) and drift level ``drifts[j]`` (m, finite, ≥ 0), the ``q[k]`` quantile over the
    curves (dicts of ``ida_stripes`` / ``ida_hunt_fill``) of the intensity at which each
    first reaches ``drifts[j]``: its non-collapsing points below its collapse joined by
    straight lines from the origin, flat past its last point when it collapsed; numpy's
    default (linear) quantile. ``NaN`` where the quantile depends on curves that never
    collapsed nor reached the level (censored). Returns ``len(q) × len(drifts)``.
    """
    levels = np.ascontiguousarray(drifts, dtype=np.float64).reshape(-1)
    qs = np.ascontiguousarray(q, dtype=np.float64).reshape(-1)
    out = _aemstep.ida_fractiles(
        [np.ascontiguousarray(c["intensity"], dtype=np.float64) for c in curves],
        [np.ascontiguousarray(c["drift"], dtype=np.float64) for c in curves],
        [np.ascontiguousarray(c["collapsed"], dtype=np.bool_) for c in curves],
        levels,
        qs,
    )
    return out.reshape(qs.shape[0], levels.shape[0])
