"""Plots of spectra and IDA curves with matplotlib, an optional dependency of ``aemstep``:
imported when a function here runs (``import aemstep.plot`` does not need it), with a
clear ``ImportError`` when it is missing. Each function draws on ``ax`` (a matplotlib
``Axes``; a new figure's when ``None``) and returns the ``Axes``.
"""

from __future__ import annotations

from typing import Any, Optional, Sequence

import numpy as np

from . import frames


def _axes(ax: Any) -> Any:
    if ax is not None:
        return ax
    plt = frames.optional("matplotlib.pyplot", "aemstep.plot", "matplotlib")
    _, new = plt.subplots()
    return new


_LABELS = {
    "sd": "Sd (m)",
    "sv": "Sv (m/s)",
    "sa": "Sa (m/s²)",
    "psv": "PSv (m/s)",
    "psa": "PSa (m/s²)",
}


def spectrum(
    s: Any,
    quantity: str = "psa",
    *,
    ax: Any = None,
    labels: Optional[Sequence[str]] = None,
    **line: Any,
) -> Any:
    """A ``Spectrum`` (``aemstep.spectrum``/``spectra``): ``quantity`` (``"sd"``,
    ``"sv"``, ``"sa"``, ``"psv"``, ``"psa"``) against the period (s), one line per record
    (``labels`` for the legend, one per record). ``line``: keyword arguments of
    ``Axes.plot``. Returns the ``Axes``."""
    if quantity not in _LABELS:
        raise ValueError(f"unknown quantity {quantity!r}: one of {tuple(_LABELS)}")
    ax = _axes(ax)
    y = np.atleast_2d(np.asarray(getattr(s, quantity)))
    names = list(labels) if labels is not None else [None] * y.shape[0]
    if len(names) != y.shape[0]:
        raise ValueError(f"labels: {len(names)} given for {y.shape[0]} records")
    for row, name in zip(y, names):
        ax.plot(np.asarray(s.periods), row, label=name, **line)
    ax.set_xlabel("period (s)")
    ax.set_ylabel(_LABELS[quantity])
    if labels is not None:
        ax.legend()
    return ax


def ida(
    curves: Sequence[Any],
    *,
    ax: Any = None,
    fractiles: Optional[Sequence[float]] = None,
    drifts: Any = None,
    **line: Any,
) -> Any:
    """IDA curves (``IdaCurve`` of ``ida_stripes``/``ida_hunt_fill``): the intensity
    against the peak storey drift (m), one grey line per record through its
    non-collapsing runs, a cross at each collapsing run's intensity (drawn at the curve's
    largest finite drift); with ``fractiles`` (quantiles in [0, 1]) and ``drifts`` (m, the
    levels; default 50 up to the largest finite drift), the ``ida_fractiles`` curves on
    top. Returns the ``Axes``."""
    from ._ida import ida_fractiles

    ax = _axes(ax)
    top = 0.0
    for c in curves:
        ok = ~np.asarray(c.collapsed)
        d = np.asarray(c.drift)
        im = np.asarray(c.intensity)
        finite = d[np.isfinite(d)]
        reach = float(finite.max()) if finite.size else 0.0
        top = max(top, reach)
        ax.plot(np.r_[0.0, d[ok]], np.r_[0.0, im[ok]], **{"color": "0.6", "lw": 1, **line})
        if (~ok).any():
            ax.plot(np.full(int((~ok).sum()), reach), im[~ok], "x", color="0.4")
    if fractiles is not None and len(curves):
        levels = np.linspace(0.0, top, 50) if drifts is None else np.asarray(drifts, float)
        f = ida_fractiles(curves, levels, q=list(fractiles))
        for q, row in zip(fractiles, f):
            ax.plot(levels, row, lw=2, label=f"{100 * q:g} %")
        ax.legend()
    measure = curves[0].measure if len(curves) else "scale"
    ax.set_xlabel("peak storey drift (m)")
    ax.set_ylabel({"scale": "scale factor", "pga": "PGA (m/s²)"}.get(measure, "Sa(T1) (m/s²)"))
    return ax
