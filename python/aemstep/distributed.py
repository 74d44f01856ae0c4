"""The batch functions of ``aemstep`` on a Dask cluster (``dask.distributed``).

Each function takes a ``dask.distributed.Client`` the caller made (a ``LocalCluster`` on
one machine, a scheduler address, a ``dask_jobqueue`` cluster on a batch system) and runs
one task per record (or per ``chunk`` records): ``client.map`` of the same single-record
call the serial API makes, then ``client.gather`` in input order. Each record's result
depends only on that record and the settings, so the results are bit for bit those of the
serial call on one machine. ``aemstep`` must be installed on every worker (tasks call it
there); dask is imported only here, on use: ``import aemstep`` does not need it.

- ``spectra``: elastic spectra of many records (``aemstep.spectra``);
- ``constant_strength``, ``constant_ductility``: inelastic spectra of many records, one
  result per record (``aemstep.constant_strength`` / ``constant_ductility``);
- ``ida_stripes``, ``ida_hunt_fill``: IDA curves of a suite (``aemstep.ida_stripes`` /
  ``ida_hunt_fill``).

``threads`` is the threads each task uses on its worker (1 by default: Dask already runs
one task per worker thread). See docs/cluster.md in the repository.
"""

from __future__ import annotations

from typing import Any, List, Optional, Sequence, Tuple

import numpy as np

import aemstep
from aemstep import IdaCurve, frames

ArrayLike = Any


def _chunks(records: Sequence[ArrayLike], chunk: int) -> List[List[np.ndarray]]:
    if int(chunk) < 1:
        raise ValueError(f"chunk must be >= 1 record a task, got {chunk}")
    recs = [np.ascontiguousarray(r, dtype=np.float64) for r in records]
    return [recs[i : i + int(chunk)] for i in range(0, len(recs), int(chunk))]


def _map(client: Any, fn: Any, records: Sequence[ArrayLike], chunk: int, **kw: Any) -> List[Any]:
    """``fn(records_of_a_task, **kw)`` on the cluster, one task per chunk; the results in
    input order, flattened (each task returns one item per record)."""
    parts = _chunks(records, chunk)
    if not parts:
        return []
    # The shared settings once to every worker, not once a task; a fresh key each call
    # (hash=False): a content-hashed key repeated right after the last call released it
    # can be lost while the scheduler forgets it ("lost dependencies").
    shared = client.scatter([kw], broadcast=True, hash=False)[0] if kw else None
    futures = client.map(_call, [fn] * len(parts), parts, [shared] * len(parts), pure=False)
    out: List[Any] = []
    parts_out: List[List[Any]] = client.gather(futures)
    for part in parts_out:
        out.extend(part)
    return out


def _call(fn: Any, recs: List[np.ndarray], kw: Any) -> List[Any]:
    out: List[Any] = fn(recs, **(kw or {}))
    return out


# The single-record (or chunk) calls, run on the workers: exactly the serial API.


def _spectra(
    recs: List[np.ndarray], periods: np.ndarray, damping: ArrayLike, h: float, scheme: str,
    free_vibration: bool, threads: int, nan: str = "raise",
) -> List[Tuple[np.ndarray, ...]]:
    s = aemstep.spectra(periods, damping, h, recs, scheme=scheme,
                        free_vibration=free_vibration, threads=threads, nan=nan)
    skipped = np.asarray(s.skipped)
    return [(s.sd[i], s.sv[i], s.sa[i], s.psv[i], s.psa[i], skipped[i]) for i in range(len(recs))]


def _constant_strength(recs: List[np.ndarray], **kw: Any) -> List["aemstep.ConstantStrength"]:
    return [aemstep.constant_strength(ground_acceleration=r, **kw) for r in recs]


def _constant_ductility(recs: List[np.ndarray], **kw: Any) -> List["aemstep.ConstantDuctility"]:
    return [aemstep.constant_ductility(ground_acceleration=r, **kw) for r in recs]


def _ida_stripes(recs: List[np.ndarray], **kw: Any) -> List[IdaCurve]:
    return aemstep.ida_stripes(recs, **kw)


def _ida_hunt_fill(recs: List[np.ndarray], **kw: Any) -> List[IdaCurve]:
    return aemstep.ida_hunt_fill(recs, **kw)


def spectra(
    client: Any,
    periods: ArrayLike,
    damping: ArrayLike,
    h: Optional[float] = None,
    records: Any = None,
    *,
    scheme: str = "exact",
    free_vibration: bool = True,
    chunk: int = 1,
    threads: int = 1,
    nan: str = "raise",
) -> "aemstep.Spectrum":
    """``aemstep.spectra`` of ``records`` (m/s², sampled every ``h`` s) on the cluster:
    ``sd`` (m), ``sv`` (m/s), ``sa``, ``psa`` (m/s²), ``psv`` (m/s), each
    ``records×periods``, and ``skipped`` per record, bit for bit the serial result.
    ``records`` may be a pandas ``DataFrame`` (one column a record; ``h`` then from its
    time index if ``None``). ``nan`` as ``aemstep.spectra`` (``NonFiniteInput`` raised
    from the worker)."""
    records, h = frames.records_in(records, h)
    periods = np.ascontiguousarray(periods, dtype=np.float64)
    rows = _map(client, _spectra, records, chunk, periods=periods, damping=damping,
                h=float(h), scheme=scheme, free_vibration=bool(free_vibration),
                threads=int(threads), nan=nan)
    if not rows:
        empty = np.zeros((0, periods.shape[0]))
        return aemstep.Spectrum(periods, empty, empty, empty, empty, empty,
                                np.zeros(0, dtype=np.int64))
    sd, sv, sa, psv, psa = (np.stack([r[q] for r in rows]) for q in range(5))
    return aemstep.Spectrum(periods, sd, sv, sa, psv, psa,
                            np.array([r[5] for r in rows], dtype=np.int64))


def constant_strength(
    client: Any,
    periods: ArrayLike,
    damping: ArrayLike,
    h: float,
    records: Sequence[ArrayLike],
    reduction: ArrayLike,
    *,
    alpha: float = 0.0,
    points_per_period: int = 40,
    chunk: int = 1,
    threads: int = 1,
    nan: str = "raise",
) -> List["aemstep.ConstantStrength"]:
    """``aemstep.constant_strength`` of every record (m/s²) on the cluster: one
    ``ConstantStrength`` per record (ductility for the reduction factors ``R``)."""
    return _map(client, _constant_strength, records, chunk, periods=periods,
                damping=damping, h=float(h), reduction=reduction, alpha=float(alpha),
                points_per_period=int(points_per_period), threads=int(threads), nan=nan)


def constant_ductility(
    client: Any,
    periods: ArrayLike,
    damping: ArrayLike,
    h: float,
    records: Sequence[ArrayLike],
    target: float,
    *,
    alpha: float = 0.0,
    points: int = 60,
    lowest: float = 0.01,
    tol: float = 1e-6,
    points_per_period: int = 40,
    chunk: int = 1,
    threads: int = 1,
    nan: str = "raise",
) -> List["aemstep.ConstantDuctility"]:
    """``aemstep.constant_ductility`` of every record (m/s²) on the cluster: one
    ``ConstantDuctility`` per record (yield strength per unit mass, m/s², for the target
    ductility)."""
    return _map(client, _constant_ductility, records, chunk, periods=periods,
                damping=damping, h=float(h), target=float(target), alpha=float(alpha),
                points=int(points), lowest=float(lowest), tol=float(tol),
                points_per_period=int(points_per_period), threads=int(threads), nan=nan)


def ida_stripes(
    client: Any,
    records: Sequence[ArrayLike],
    h: float,
    intensities: ArrayLike,
    *,
    chunk: int = 1,
    threads: int = 1,
    **building: Any,
) -> List[IdaCurve]:
    """``aemstep.ida_stripes`` on the cluster, one task per record (or ``chunk``):
    ``building`` is its keyword arguments (``masses``, ``law``, ``params``, ``c``,
    ``collapse_drift``, ``intensity``, ``period``, ``damping``, …; not ``progress``). The
    ``IdaCurve`` list is the serial one, bit for bit."""
    building.pop("progress", None)
    return _map(client, _ida_stripes, records, chunk, h=float(h),
                intensities=np.ascontiguousarray(intensities, dtype=np.float64),
                threads=int(threads), **building)


def ida_hunt_fill(
    client: Any,
    records: Sequence[ArrayLike],
    h: float,
    *,
    chunk: int = 1,
    threads: int = 1,
    **settings: Any,
) -> List[IdaCurve]:
    """``aemstep.ida_hunt_fill`` on the cluster, one task per record (or ``chunk``):
    ``settings`` is its keyword arguments (building, hunt-and-fill, collapse; not
    ``progress``; ``intensity``, ``period``, ``damping`` as ``ida_stripes``). Each record's
    trace (and measure) is independent: the serial ``IdaCurve`` list, bit for bit."""
    settings.pop("progress", None)
    return _map(client, _ida_hunt_fill, records, chunk, h=float(h), threads=int(threads),
                **settings)
