"""Incremental dynamic analysis (IDA) of the yielding shear building: the wrappers of the
native ``ida_stripes``, ``ida_hunt_fill`` and ``ida_fractiles`` (re-exported by
``aemstep``).

An IDA runs every record of a suite scaled by a sequence of intensities (here the record
scale factor: the run's ground acceleration is ``intensity × record``) and keeps each
run's engineering demand parameter, the peak absolute storey drift (m) over the storeys
and the steps. A record's runs are its IDA curve (an ``IdaCurve``); ``ida_fractiles``
summarizes a suite.

**Intensity measure.** ``intensity="scale"`` (the default) takes the intensities as record
scale factors. ``intensity="pga"`` takes them as peak ground accelerations and
``intensity="sa"`` as pseudo-spectral accelerations ``Sa(T₁)`` at ``period`` (s) with
``damping`` (ratio), both in the records' units (m/s²): each record is first divided by its
own measure (``max|a|``, or ``spectral_acceleration(record, h, period, damping)``, which
is linear in the record), so that the run at intensity ``x`` is the record scaled to a
measure of ``x``; the curve keeps that measure as ``record_intensity`` and
``scale = intensity / record_intensity``.
"""

from __future__ import annotations

from typing import Any, Callable, List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import _aemstep
from ._aemstep import ShapeError

ArrayLike = Any
Progress = Union[bool, Callable[[int, int], Any], None]
F64 = npt.NDArray[np.float64]

#: The intensity measures of the IDA calls.
INTENSITY_MEASURES = ("scale", "pga", "sa")


class IdaCurve(NamedTuple):
    """One record's IDA curve: its runs sorted by intensity."""

    intensity: F64  #: the runs' intensity measure (scale factor, or m/s² for pga/sa)
    drift: F64  #: peak absolute storey drift of each run (m; ``inf`` for a failed run)
    collapsed: npt.NDArray[np.bool_]  #: whether each run collapsed
    error: List[Optional[str]]  #: a failed run's error name (e.g. ``"NotConverged"``)
    #: ``(lo, hi)``: the highest non-collapsing intensity below the lowest collapsing one
    #: (0 if none) and that lowest; ``None`` if no run collapsed
    collapse: Optional[Tuple[float, float]]
    measure: str = "scale"  #: ``"scale"``, ``"pga"`` or ``"sa"``
    #: the unscaled record's measure (1 for ``"scale"``; m/s² for pga/sa)
    record_intensity: float = 1.0

    @property
    def scale(self) -> F64:
        """The record scale factor of each run: ``intensity / record_intensity``."""
        return np.asarray(self.intensity / self.record_intensity, dtype=np.float64)

    def to_pandas(self) -> Any:
        """The runs as a ``pandas.DataFrame`` indexed by ``intensity``: columns ``scale``,
        ``drift`` (m), ``collapsed``, ``error`` (pandas imported on use)."""
        from .frames import _pandas

        pd = _pandas()
        return pd.DataFrame(
            {"scale": self.scale, "drift": self.drift, "collapsed": self.collapsed,
             "error": self.error},
            index=pd.Index(self.intensity, name="intensity"),
        )


def spectral_acceleration(record: ArrayLike, h: float, period: float, damping: float = 0.05) -> float:
    """The pseudo-spectral acceleration ``Sa = ω² max|u|`` (the record's units, e.g. m/s²)
    of the oscillator of ``period`` (s) and ``damping`` (ratio) under ``record`` (1-D,
    sampled every ``h`` s), with one period of free vibration after it (exact scheme):
    the library's ``aemstep::ida::spectral_acceleration``, the ``Sa(T₁)`` of the IDA
    calls. Raises ``NonFiniteInput``, ``InvalidPeriod``, ``InvalidDamping``,
    ``InvalidTimeStep``. Cost: one oscillator over the record, the GIL released."""
    rec = _records([record])[0]
    return float(_aemstep.spectral_acceleration(rec, float(h), float(period), float(damping)))


def _measure(
    recs: List[F64], h: float, intensity: str, period: Optional[float], damping: float
) -> List[float]:
    """Each record's own intensity measure (1 for scale factors)."""
    if intensity not in INTENSITY_MEASURES:
        raise ValueError(f"unknown intensity {intensity!r}: one of {INTENSITY_MEASURES}")
    if intensity != "sa" and period is not None:
        raise ValueError(f"period is the Sa(T1) period: give it with intensity='sa', not {intensity!r}")
    if intensity == "scale":
        return [1.0] * len(recs)
    if intensity == "pga":
        out = [float(np.max(np.abs(r))) if r.shape[0] else 0.0 for r in recs]
    else:
        if period is None:
            raise ValueError("intensity='sa' needs period (s), the T1 of Sa(T1)")
        out = [spectral_acceleration(r, h, period, damping) for r in recs]
    for i, x in enumerate(out):
        if not (np.isfinite(x) and x > 0):
            raise ValueError(f"record {i} has {intensity} = {x}: it cannot be scaled to an intensity")
    return out


def _curves(raw: List[Any], measure: str, own: List[float]) -> List[IdaCurve]:
    return [
        IdaCurve(d["intensity"], d["drift"], d["collapsed"], list(d["error"]),
                 None if d["collapse"] is None else (float(d["collapse"][0]), float(d["collapse"][1])),
                 measure, x)
        for d, x in zip(raw, own)
    ]


def _records(records: Sequence[ArrayLike]) -> List[F64]:
    out = []
    for i, r in enumerate(records):
        a = np.ascontiguousarray(r, dtype=np.float64)
        if a.ndim != 1:
            raise ShapeError(f"record {i} must be 1-D, got shape {a.shape}")
        out.append(a)
    return out


def _building(masses: ArrayLike, params: ArrayLike, c: ArrayLike) -> Tuple[F64, F64, F64]:
    from . import _mat, _vec

    return _vec(masses, "masses"), _mat(params, "params"), _mat(c, "c")


def _callback(
    progress: Progress, total: int
) -> Tuple[Optional[Callable[[int, int], Any]], Callable[[], None]]:
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

        def close() -> None:
            bar.close()

        return update, close
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
    intensity: str = "scale",
    period: Optional[float] = None,
    damping: float = 0.05,
) -> List[IdaCurve]:
    """IDA curves on fixed stripes: every record at every intensity.

    ``records``: ground accelerations (m/s², each 1-D) sampled every ``h`` s.
    ``intensities``: finite, > 0, any order: record scale factors with
    ``intensity="scale"`` (each run is the record times the factor), peak ground
    accelerations (m/s²) with ``intensity="pga"``, or ``Sa(period, damping)`` (m/s²) with
    ``intensity="sa"`` (each record scaled to that measure; see the module). ``masses`` (kg, ``n``), ``law``, ``params`` (``n×width``), ``c``
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

    Returns one ``IdaCurve`` per record: ``intensity`` (sorted, in the measure),
    ``drift`` (peak absolute storey drift, m; ``inf`` for a failed run), ``collapsed``
    (bool), ``error`` (name of a failed run's error, or ``None``), ``collapse`` (``(lo,
    hi)``: the highest non-collapsing intensity below the lowest collapsing one (0 if
    none), and that lowest; ``None`` if no run collapsed), ``measure``,
    ``record_intensity``.
    """
    recs = _records(records)
    own = _measure(recs, float(h), intensity, period, float(damping))
    if intensity != "scale":
        recs = [r / x for r, x in zip(recs, own)]
    ims = np.ascontiguousarray(intensities, dtype=np.float64).reshape(-1)
    m, p, cc = _building(masses, params, c)
    cb, close = _callback(progress, len(recs) * ims.shape[0])
    try:
        raw = _aemstep.ida_stripes(
            recs, float(h), ims, m, law, p, cc, int(max_iterations), float(tolerance),
            float(collapse_drift), on_failure, int(threads), cb,
        )
    finally:
        close()
    return _curves(raw, intensity, own)


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
    intensity: str = "scale",
    period: Optional[float] = None,
    damping: float = 0.05,
) -> List[IdaCurve]:
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

    ``intensity``, ``period``, ``damping``: the measure, as ``ida_stripes``; ``first``,
    ``step``, ``step_increment`` and ``resolution`` are then in its units (m/s² for
    ``"pga"``/``"sa"``: the defaults suit scale factors, not accelerations).

    Returns the ``IdaCurve`` of ``ida_stripes``: at most ``runs`` points each, sorted;
    when the record collapsed, ``collapse = (lo, hi)`` brackets its collapse intensity.
    """
    recs = _records(records)
    own = _measure(recs, float(h), intensity, period, float(damping))
    if intensity != "scale":
        recs = [r / x for r, x in zip(recs, own)]
    m, p, cc = _building(masses, params, c)
    cb, close = _callback(progress, len(recs) * max(int(runs), 0))
    try:
        raw = _aemstep.ida_hunt_fill(
            recs, float(h), m, law, p, cc, int(max_iterations), float(tolerance),
            float(first), float(step), float(step_increment), float(resolution), int(runs),
            float(collapse_drift), on_failure, int(threads), cb,
        )
    finally:
        close()
    return _curves(raw, intensity, own)


def ida_fractiles(
    curves: Sequence[IdaCurve],
    drifts: ArrayLike,
    q: Sequence[float] = (0.16, 0.5, 0.84),
) -> F64:
    """Fractile IDA curves, *intensity given drift*: for each quantile ``q[k]`` (in
    [0, 1]) and drift level ``drifts[j]`` (m, finite, ≥ 0), the ``q[k]`` quantile over the
    curves (``IdaCurve`` of ``ida_stripes`` / ``ida_hunt_fill``, in their measure) of the intensity at which each
    first reaches ``drifts[j]``: its non-collapsing points below its collapse joined by
    straight lines from the origin, flat past its last point when it collapsed; numpy's
    default (linear) quantile. ``NaN`` where the quantile depends on curves that never
    collapsed nor reached the level (censored). Returns ``len(q) × len(drifts)``.
    """
    for i, c in enumerate(curves):
        if not all(hasattr(c, f) for f in ("intensity", "drift", "collapsed")):
            raise TypeError(
                f"curve {i}: ida_fractiles takes the IdaCurve results of ida_stripes / "
                f"ida_hunt_fill (fields intensity, drift, collapsed), got {type(c).__name__}"
            )
    levels = np.ascontiguousarray(drifts, dtype=np.float64).reshape(-1)
    qs = np.ascontiguousarray(q, dtype=np.float64).reshape(-1)
    out = _aemstep.ida_fractiles(
        [np.ascontiguousarray(c.intensity, dtype=np.float64) for c in curves],
        [np.ascontiguousarray(c.drift, dtype=np.float64) for c in curves],
        [np.ascontiguousarray(c.collapsed, dtype=np.bool_) for c in curves],
        levels,
        qs,
    )
    return np.asarray(out.reshape(qs.shape[0], levels.shape[0]), dtype=np.float64)
