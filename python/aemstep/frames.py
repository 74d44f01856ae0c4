"""Time axes and tables: the ``.time`` axis of every history result, and optional pandas
and xarray output (``to_pandas()``, ``to_xarray()``).

pandas and xarray are not dependencies of ``aemstep``: they are imported when a
``to_pandas``/``to_xarray`` method runs, and a clear ``ImportError`` says what to install
when they are missing. ``records_in`` lets ``spectra`` take a pandas ``DataFrame`` of
records (one column a record, a time index in seconds or timedeltas).
"""

from __future__ import annotations

import math
from typing import Any, List, Optional, Sequence, Tuple, TypeVar

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]


def _pandas() -> Any:
    try:
        import pandas
    except ImportError as e:  # pragma: no cover - exercised without pandas only
        raise ImportError(
            "to_pandas() needs pandas, an optional dependency of aemstep: pip install pandas"
        ) from e
    return pandas


def _xarray() -> Any:
    try:
        import xarray
    except ImportError as e:  # pragma: no cover - exercised without xarray only
        raise ImportError(
            "to_xarray() needs xarray, an optional dependency of aemstep: pip install xarray"
        ) from e
    return xarray


class History:
    """The time axis and tables of a history result (``LinearResponse``,
    ``BuildingResponse``, ``Estimate``, ``DamperResponse``, ``ControlledResponse``).

    ``h`` is the sample interval (s) and ``samples`` the number of samples (rows) the run
    holds, both set by the function that made the result; ``time`` is ``i·h`` for row
    ``i`` (s, row 0 at ``t = 0``), one float64 multiplication a sample. ``NaN`` when the
    result was built by hand without them.
    """

    h: float = math.nan  #: sample interval (s)
    samples: int = 0  #: rows of the histories (row ``i`` at ``t = i·h``)

    @property
    def time(self) -> F64:
        """The time of each row (s): ``np.arange(samples) * h``."""
        return np.arange(self.samples, dtype=np.float64) * self.h

    def _series(self) -> List[Tuple[str, F64]]:
        """``(name, array)`` of every field that is a history: an array whose first axis
        has one entry per sample (nested results such as ``Energy`` as ``energy_<name>``)."""
        out: List[Tuple[str, F64]] = []
        fields: Sequence[str] = getattr(self, "_fields", ())
        for name in fields:
            value = getattr(self, name)
            if hasattr(value, "_fields"):  # a nested NamedTuple (the energy account)
                for sub in value._fields:
                    x = getattr(value, sub)
                    if isinstance(x, np.ndarray) and x.ndim >= 1 and x.shape[0] == self.samples:
                        out.append((f"{name}_{sub}", x))
            elif isinstance(value, np.ndarray) and value.ndim in (1, 2):
                if value.shape[0] == self.samples and self.samples > 0:
                    out.append((name, value))
        return out

    def to_pandas(self) -> Any:
        """The histories as a ``pandas.DataFrame`` indexed by ``time`` (s): one column per
        one-dimensional history, ``(name, dof)`` columns (a two-level ``MultiIndex``, dof
        0-based) for ``samples×n`` ones. Fields that are not histories (gains, peaks) are
        left out. Copies the arrays once."""
        pd = _pandas()
        cols: dict[Tuple[str, Any], F64] = {}
        for name, x in self._series():
            if x.ndim == 1:
                cols[(name, "")] = x
            else:
                for j in range(x.shape[1]):
                    cols[(name, j)] = x[:, j]
        index = pd.Index(self.time, name="time")
        if not cols:
            return pd.DataFrame(index=index)
        return pd.DataFrame(cols, index=index)

    def to_xarray(self) -> Any:
        """The histories as an ``xarray.Dataset``: one variable per history, dimensions
        ``("time",)`` or ``("time", "dof")``, coordinates ``time`` (s) and ``dof``
        (0-based)."""
        xr = _xarray()
        series = self._series()
        data = {name: (("time",) if x.ndim == 1 else ("time", "dof"), x) for name, x in series}
        coords: dict[str, F64] = {"time": self.time}
        dofs = [x.shape[1] for _, x in series if x.ndim == 2]
        if dofs:
            coords["dof"] = np.arange(dofs[0])
        return xr.Dataset(data, coords=coords, attrs={"h": self.h})


H = TypeVar("H", bound=History)


def timed(result: H, h: float, samples: int) -> H:
    """``result`` with its time axis: sample interval ``h`` (s), ``samples`` rows."""
    result.h = float(h)
    result.samples = int(samples)
    return result


_QUANTITIES = ("sd", "sv", "sa", "psv", "psa")


def spectrum_to_pandas(s: Any) -> Any:
    """A ``Spectrum`` as a ``pandas.DataFrame`` indexed by ``period`` (s): columns ``sd``,
    ``sv``, ``sa``, ``psv``, ``psa`` for one record; ``(quantity, record)`` columns (a
    two-level ``MultiIndex``, records numbered in input order) for ``records×periods``."""
    pd = _pandas()
    index = pd.Index(np.asarray(s.periods), name="period")
    first = np.asarray(s.sd)
    if first.ndim == 1:
        return pd.DataFrame({q: np.asarray(getattr(s, q)) for q in _QUANTITIES}, index=index)
    cols = {
        (q, r): np.asarray(getattr(s, q))[r] for q in _QUANTITIES for r in range(first.shape[0])
    }
    if not cols:
        return pd.DataFrame(index=index)
    return pd.DataFrame(cols, index=index)


def spectrum_to_xarray(s: Any) -> Any:
    """A ``Spectrum`` as an ``xarray.Dataset``: variables ``sd``, ``sv``, ``sa``, ``psv``,
    ``psa`` on dimensions ``("period",)`` or ``("record", "period")``, coordinate
    ``period`` (s)."""
    xr = _xarray()
    dims = ("period",) if np.asarray(s.sd).ndim == 1 else ("record", "period")
    data = {q: (dims, np.asarray(getattr(s, q))) for q in _QUANTITIES}
    return xr.Dataset(data, coords={"period": np.asarray(s.periods)})


def ida_to_pandas(curves: Sequence[Any]) -> Any:
    """IDA curves (``IdaCurve``, e.g. from ``ida_stripes``) as one long
    ``pandas.DataFrame``: a row per run with columns ``record`` (0-based, input order),
    ``intensity`` (the curve's measure), ``scale`` (the record scale factor), ``drift``
    (m), ``collapsed``, ``error``."""
    pd = _pandas()
    rows: dict[str, List[Any]] = {
        k: [] for k in ("record", "intensity", "scale", "drift", "collapsed", "error")
    }
    for r, c in enumerate(curves):
        rows["record"].extend([r] * len(c.intensity))
        rows["intensity"].extend(np.asarray(c.intensity).tolist())
        rows["scale"].extend(np.asarray(c.scale).tolist())
        rows["drift"].extend(np.asarray(c.drift).tolist())
        rows["collapsed"].extend(np.asarray(c.collapsed).tolist())
        rows["error"].extend(c.error)
    return pd.DataFrame(rows)


def _seconds(index: Any) -> F64:
    """A pandas index as seconds: numbers as they are, timedeltas in seconds."""
    a = np.asarray(index)
    if a.dtype.kind == "m":
        return a.astype("timedelta64[ns]").astype(np.int64).astype(np.float64) * 1e-9
    if a.dtype.kind in "iuf":
        return a.astype(np.float64)
    raise TypeError(
        "a DataFrame of records needs a time index in seconds (numbers) or timedeltas, or "
        f"an explicit h; got an index of dtype {a.dtype}"
    )


def records_in(records: Any, h: Optional[float]) -> Tuple[List[Any], float]:
    """``(records, h)`` for ``spectra``: a pandas ``DataFrame`` becomes its columns (one
    record each, float64) and, when ``h`` is ``None``, its index's uniform spacing (s;
    numbers or timedeltas; uniform to 1e-9 relative, else ``ValueError``). Anything else
    passes through, ``h`` required."""
    if hasattr(records, "columns") and hasattr(records, "index") and hasattr(records, "to_numpy"):
        cols = [np.ascontiguousarray(records[c].to_numpy(dtype=np.float64)) for c in records.columns]
        if h is None:
            t = _seconds(records.index)
            if t.shape[0] < 2:
                raise ValueError("a DataFrame of records with fewer than 2 rows needs h")
            steps = np.diff(t)
            dt = (t[-1] - t[0]) / (t.shape[0] - 1)
            if not (dt > 0 and np.all(np.abs(steps - dt) <= 1e-9 * dt)):
                raise ValueError(
                    "the DataFrame's index is not uniformly spaced increasing time (s): "
                    "resample the records or pass h"
                )
            h = float(dt)
        return cols, float(h)
    if records is None:
        raise TypeError("records (the ground accelerations, m/s²) are required")
    if h is None:
        raise TypeError("h (the records' sample interval, s) is required unless records is "
                        "a pandas DataFrame with a time index")
    return list(records), float(h)
