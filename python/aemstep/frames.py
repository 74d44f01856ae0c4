"""Time axes and tables: the ``.time`` axis of every history result, and optional pandas
and xarray output (``to_pandas()``, ``to_xarray()`` methods, and ``to_pandas(result)`` /
``to_xarray(result)`` for every result of the package, the inelastic spectra and RotD
included).

pandas and xarray are not dependencies of ``aemstep``: they are imported when a
``to_pandas``/``to_xarray`` method runs, and a clear ``ImportError`` says what to install
when they are missing. ``records_in`` lets ``spectra`` take a pandas ``DataFrame`` of
records (one column a record, a time index in seconds or timedeltas).
"""

from __future__ import annotations

import importlib
import math
from typing import Any, List, Optional, Sequence, Tuple, TypeVar

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]


def optional(module: str, user: str, package: str) -> Any:
    """``module`` imported on first use, or an ``ImportError`` saying that ``user`` needs the
    optional dependency ``package`` and how to install it."""
    try:
        return importlib.import_module(module)
    except ImportError as e:  # pragma: no cover - exercised without the package only
        raise ImportError(
            f"{user} needs {package}, an optional dependency of aemstep: pip install {package}"
        ) from e


def _pandas() -> Any:
    return optional("pandas", "to_pandas()", "pandas")


def _xarray() -> Any:
    return optional("xarray", "to_xarray()", "xarray")


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


def _per_period(result: Any) -> Tuple[Any, List[Tuple[str, Any, Any]]]:
    """``(periods, [(name, key, column)])`` of a result with a ``periods`` field: every
    field with one value per period (arrays ``periods``, lists of that length), a
    ``records×periods`` array as one column per record (key the record), a
    ``periods×k`` array as one column per ``k`` (key ``k``); scalars left out."""
    periods = np.asarray(result.periods)
    count = periods.shape[0]
    cols: List[Tuple[str, Any, Any]] = []
    for name in result._fields:
        if name == "periods":
            continue
        x = getattr(result, name)
        if isinstance(x, list) and len(x) == count:
            cols.append((name, "", x))
        elif isinstance(x, np.ndarray) and x.ndim == 1 and x.shape[0] == count:
            cols.append((name, "", x))
        elif isinstance(x, np.ndarray) and x.ndim == 2 and x.shape[1] == count:
            cols.extend((name, r, x[r]) for r in range(x.shape[0]))
        elif isinstance(x, np.ndarray) and x.ndim == 2 and x.shape[0] == count:
            cols.extend((name, j, x[:, j]) for j in range(x.shape[1]))
    return periods, cols


def spectrum_to_pandas(s: Any) -> Any:
    """A spectrum result (``Spectrum``, ``RotDSpectrum``, ``ConstantStrength``,
    ``ConstantDuctility``) as a ``pandas.DataFrame`` indexed by ``period`` (s): one column
    per quantity (``sd``, ``sv``, … for one record), ``(quantity, record)`` columns (a
    two-level ``MultiIndex``, records numbered in input order) for ``records×periods``
    arrays, ``(quantity, end)`` for ``periods×2`` brackets; scalar fields left out."""
    pd = _pandas()
    periods, cols = _per_period(s)
    index = pd.Index(periods, name="period")
    if not cols:
        return pd.DataFrame(index=index)
    if all(key == "" for _, key, _ in cols):
        return pd.DataFrame({name: x for name, _, x in cols}, index=index)
    return pd.DataFrame({(name, key): x for name, key, x in cols}, index=index)


def spectrum_to_xarray(s: Any) -> Any:
    """A spectrum result as an ``xarray.Dataset``: one variable per quantity on
    ``("period",)``, ``("record", "period")`` or ``("period", "end")``, coordinate
    ``period`` (s)."""
    xr = _xarray()
    periods = np.asarray(s.periods)
    count = periods.shape[0]
    data: dict[str, Tuple[Tuple[str, ...], Any]] = {}
    for name in s._fields:
        x = getattr(s, name)
        if name == "periods" or not isinstance(x, (np.ndarray, list)):
            continue
        a = np.asarray(x)
        if a.ndim == 1 and a.shape[0] == count:
            data[name] = (("period",), a)
        elif a.ndim == 2 and a.shape[1] == count:
            data[name] = (("record", "period"), a)
        elif a.ndim == 2 and a.shape[0] == count:
            data[name] = (("period", "end"), a)
    return xr.Dataset(data, coords={"period": periods})


def to_pandas(result: Any) -> Any:
    """Any result of the package as a ``pandas.DataFrame``: a history's
    ``to_pandas()``, a spectrum result's ``spectrum_to_pandas``, an ``IdaCurve``'s
    ``to_pandas()``, a list of ``IdaCurve`` as ``ida_to_pandas``."""
    if isinstance(result, list) and result and all(hasattr(c, "record_intensity") for c in result):
        return ida_to_pandas(result)
    if hasattr(result, "to_pandas"):
        return result.to_pandas()
    if hasattr(result, "periods"):
        return spectrum_to_pandas(result)
    raise TypeError(f"no table for a {type(result).__name__}")


def to_xarray(result: Any) -> Any:
    """Any history or spectrum result as an ``xarray.Dataset`` (``History.to_xarray``,
    ``spectrum_to_xarray``)."""
    if hasattr(result, "to_xarray"):
        return result.to_xarray()
    if hasattr(result, "periods"):
        return spectrum_to_xarray(result)
    raise TypeError(f"no Dataset for a {type(result).__name__}")


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
