"""aemstep from Python: structural time stepping by the analog equation method.

numpy arrays in (anything ``numpy.asarray`` takes; copied to contiguous ``float64``) and
out; the GIL is released while a record runs. Units are SI: m, s, kg, N; ground
accelerations in m/s² (``G`` converts from g).

- ``linear_response``: a linear model ``M u'' + C u' + K u = p`` over a load history or a
  ground-acceleration record, by the AEM (``"aem"``), modal superposition (``"modal"``),
  Newmark, generalized-α, HHT-α or the exact (matrix exponential) scheme.
- ``shear_building``: a yielding shear building (bilinear, Bouc–Wen, or bilinear with a
  friction damper in every storey) over a record, with its energy account.
- ``spectrum``, ``spectra``, ``rotd``: elastic response spectra of one record, of many
  records on threads, RotD50/RotD100 of two components.
- ``constant_strength``, ``constant_ductility``: inelastic spectra.

  A record with a NaN or infinite sample raises ``NonFiniteInput`` (``.step``: the
  sample's index; ``.record`` too for ``spectra``/``rotd``), as ``linear_response`` and
  ``shear_building`` do; ``nan="skip"`` holds the last finite sample in its place instead
  and the result's ``skipped`` counts them. These calls answer Ctrl-C within a fraction of
  a second (``KeyboardInterrupt``). ``observe`` is different by design: a NaN measurement
  is a missing one, skipped.
- ``observe``: a steady-state (Kalman-gain) observer or a Kalman filter of a building's
  state from measured floor accelerations.
- ``zero_order_hold``, ``lqr``, ``lqg``: the sampled design model of a building, the
  discrete linear–quadratic regulator (with the one-sample computation delay if asked),
  and the observer and regulator gains of an output-feedback controller.
- ``mr_damper_response``, ``mr_building``: the Bouc–Wen MR damper of Dyke et al. (1996)
  driven by a motion, and a building with one MR damper (passive off/on, clipped-optimal).
- ``read_at2``, ``read_column``: PEER NGA ``.AT2`` and one-column records (the library's
  readers).
- ``ida_stripes``, ``ida_hunt_fill``, ``ida_fractiles``: incremental dynamic analysis of
  the yielding shear building over a suite of records, on threads, with a progress bar.
  ``IdaCurve`` results; the intensity a scale factor, the PGA or ``Sa(T₁)``
  (``spectral_acceleration``).
- ``aemstep.distributed``: the batch functions on a Dask cluster (imported on use).
- ``aemstep.frames``: the ``.time`` axis of history results and their optional pandas /
  xarray output (``to_pandas()``, ``to_xarray()``); ``aemstep.plot``: spectra and IDA
  curves with matplotlib (imported on use).

Every ``aemstep::Error`` variant of the Rust library is an exception of the same name
(``aemstep.NotConverged``, ``aemstep.InvalidTimeStep``, …), subclass of ``AemstepError``
(a ``ValueError``); ``ShapeError`` is a wrong array shape (its message names the argument
and the shape expected), ``UnsupportedSize`` a number of degrees of freedom the package is
not compiled for (``SIZES``), ``InvalidArgument`` an argument outside its rule (a negative
count, a file descriptor where a path or text is expected; ``.argument`` names it). An
output too large for the machine's memory raises ``MemoryError`` before anything is
allocated; Ctrl-C stops a long call within about 0.1 s (``KeyboardInterrupt``).

See docs/python.md in the repository.
"""

from __future__ import annotations

import os
from typing import Any, Callable, Dict, List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np

from . import _aemstep, frames
from ._aemstep import (  # noqa: F401  (re-exported)
    CHUNK,
    ERROR_VARIANTS,
    InvalidArgument,
    MAX_CONTROL_INPUTS,
    MAX_DESIGN_STATES,
    MAX_OBSERVE_DOFS,
    MAX_SENSORS,
    MAX_TRUNCATED_MODES,
    ROTD_ANGLES,
    SIZES,
    AemstepError,
    EigenNotConverged,
    InputNotIdentifiable,
    InvalidCovariance,
    InvalidDamping,
    InvalidMaterial,
    InvalidModeSelection,
    InvalidNewtonSettings,
    InvalidParameter,
    InvalidPeriod,
    InvalidTimeStep,
    MalformedRecord,
    MassNotSpd,
    NonClassicalDamping,
    NonFiniteForce,
    NonFiniteInput,
    NonFiniteState,
    NotConverged,
    NotStabilizing,
    OperatorOverflow,
    OperatorUnderflow,
    RiccatiNotConverged,
    ShapeError,
    SingularEffectiveMatrix,
    SingularEffectiveMatrixAtStep,
    SingularJacobian,
    SingularMass,
    StateSizeMismatch,
    StepCountOverflow,
    StiffnessIndefinite,
    StiffnessNotSymmetric,
    UnsupportedSize,
)

__version__ = "0.1.0"

#: Standard gravity (m/s² per g): AT2 records are in g.
G = 9.80665

ArrayLike = Any


def _vec(x: ArrayLike, name: str) -> np.ndarray:
    a = np.asarray(x, dtype=np.float64)
    if a.ndim != 1:
        raise ShapeError(f"{name} must be 1-D, got shape {a.shape}")
    return np.ascontiguousarray(a)


def _mat(x: ArrayLike, name: str) -> np.ndarray:
    a = np.asarray(x, dtype=np.float64)
    if a.ndim != 2:
        raise ShapeError(f"{name} must be 2-D, got shape {a.shape}")
    return np.ascontiguousarray(a)


def _count(x: Any, name: str, high: int = 2**63 - 1) -> int:
    """An integer argument checked in ``0..=high``: ``InvalidArgument`` naming it, not an
    ``OverflowError`` from the native call."""
    try:
        v = int(x)
    except (TypeError, ValueError):
        v = None
    if v is None or v != x or not 0 <= v <= high:
        e = InvalidArgument(f"{name} must be an integer in [0, {high}], got {x!r}")
        e.argument = name
        raise e
    return v


def _per_period(x: ArrayLike, count: int, name: str, per: str = "period") -> np.ndarray:
    """A scalar broadcast to every period (or storey: ``per``), or one value per period."""
    a = np.asarray(x, dtype=np.float64)
    if a.ndim == 0:
        return np.full(count, float(a))
    a = np.ascontiguousarray(a)
    if a.shape != (count,):
        raise ShapeError(
            f"{name} must be a scalar or have one value per {per} ({count},), got shape {a.shape}"
        )
    return a


# ---------------------------------------------------------------------------------------
# Linear models.


class _LinearResponse(NamedTuple):
    u: np.ndarray  #: displacements (m; relative to the ground under ground acceleration)
    v: np.ndarray  #: velocities (m/s)
    a: np.ndarray  #: accelerations (m/s²; relative)


class LinearResponse(_LinearResponse, frames.History):
    """Histories of a linear run, each ``steps×n``, row 0 the initial state; ``time``
    (s) the time of each row, ``to_pandas()``/``to_xarray()`` tables (``frames.History``)."""


SCHEMES = ("aem", "modal", "newmark", "generalized_alpha", "hht", "exact")


def linear_response(
    m: ArrayLike,
    c: ArrayLike,
    k: ArrayLike,
    h: float,
    p: Optional[ArrayLike] = None,
    *,
    ground_acceleration: Optional[ArrayLike] = None,
    influence: Optional[ArrayLike] = None,
    scheme: str = "aem",
    u0: Optional[ArrayLike] = None,
    v0: Optional[ArrayLike] = None,
    beta: float = 0.25,
    gamma: float = 0.5,
    rho_inf: float = 1.0,
    alpha: float = 0.0,
    modes: int = 0,
) -> LinearResponse:
    """Step ``M u'' + C u' + K u = p(t)`` over a record; one interface for every scheme.

    ``m``, ``c``, ``k``: ``n×n`` mass (kg), damping (N·s/m), stiffness (N/m) (``n`` in
    ``SIZES``, or any ``n ≥ 1`` with ``scheme="aem"``). ``h``: time
    step (s). Loads either ``p`` (N, ``steps×n``, row ``i`` at ``t = i·h``) or
    ``ground_acceleration`` (m/s², length ``steps``) with ``influence`` ``ι`` (default all
    ones): ``p = −M ι a_g``, ``u`` then relative to the ground. ``u0``, ``v0``: initial
    state (m, m/s; default rest). ``scheme``: ``"aem"`` (the analog equation method;
    identical to Newmark average acceleration for linear systems), ``"modal"`` (the
    ``modes`` lowest modes, 0 for all, else 1 to ``MAX_TRUNCATED_MODES``; ``M`` SPD, ``K``
    symmetric, ``C`` classical), ``"newmark"`` (``beta``, ``gamma``),
    ``"generalized_alpha"`` (``rho_inf`` ∈ [0, 1]), ``"hht"`` (``alpha`` ∈ [−1/3, 0]),
    ``"exact"`` (matrix exponential, load linear between samples).
    """
    m, c, k = _mat(m, "m"), _mat(c, "c"), _mat(k, "k")
    n = m.shape[0]
    if m.shape != (n, n):
        raise ShapeError(f"m must be square (n x n), got shape {m.shape}")
    if (p is None) == (ground_acceleration is None):
        raise ShapeError("give exactly one of p and ground_acceleration")
    if p is None:
        ag = _vec(ground_acceleration, "ground_acceleration")
        iota = np.ones(n) if influence is None else _vec(influence, "influence")
        if iota.shape != (n,):
            raise ShapeError(f"influence must have length {n}")
        p = np.outer(ag, -(m @ iota))
    p = _mat(p, "p")
    u0 = np.zeros(n) if u0 is None else _vec(u0, "u0")
    v0 = np.zeros(n) if v0 is None else _vec(v0, "v0")
    u, v, a = _aemstep.linear_response(
        m, c, k, float(h), p, u0, v0, scheme, beta, gamma, rho_inf, alpha, _count(modes, "modes")
    )
    return frames.timed(LinearResponse(u, v, a), h, u.shape[0])


# ---------------------------------------------------------------------------------------
# The yielding shear building.


class Energy(NamedTuple):
    """The energy account of a building run (J), one value per step:
    ``E0 + input = kinetic + recoverable + viscous + hysteretic + balance_error``."""

    input: np.ndarray  #: work of the loads ∫ p·du
    kinetic: np.ndarray  #: ½ vᵀ M v
    recoverable: np.ndarray  #: strain energy recoverable by elastic unloading
    viscous: np.ndarray  #: dissipated by the damping matrix ∫ (C v)·du
    hysteretic: np.ndarray  #: dissipated by the storey laws
    balance_error: np.ndarray  #: E0 + input − the rest (Newton tolerance and rounding)
    initial: float  #: E0, kinetic plus recoverable at the start


class _BuildingResponse(NamedTuple):
    u: Optional[np.ndarray]  #: floor displacements relative to the ground (m)
    v: Optional[np.ndarray]  #: floor velocities (m/s)
    a: Optional[np.ndarray]  #: floor accelerations relative to the ground (m/s²)
    drifts: Optional[np.ndarray]  #: storey drifts u_i − u_{i−1} (m)
    peak_drifts: np.ndarray  #: max |drift| per storey (m)
    energy: Optional[Energy]  #: the energy account (None with energy=False)
    iterations: Optional[np.ndarray]  #: Newton iterations of each step
    peak_drift: float = float("nan")  #: max of peak_drifts, the peak absolute storey drift (m)
    total_iterations: int = 0  #: Newton iterations over the whole run


class BuildingResponse(_BuildingResponse, frames.History):
    """A yielding building's run. Histories ``steps×n`` (floor ``i``, ground storey first);
    with ``histories=False`` they are ``None`` and only the peaks and counts are kept.
    ``time`` (s): the time of each sample of the record (also without histories)."""


LAWS = ("bilinear", "bouc_wen", "bilinear_friction")

#: The largest Newton budget a step may have (``max_iterations``): a larger one could keep
#: one step (which Ctrl-C cannot split) busy for hours.
MAX_NEWTON_ITERATIONS = 10_000


def shear_building(
    masses: ArrayLike,
    c: ArrayLike,
    h: float,
    ground_acceleration: ArrayLike,
    *,
    k: ArrayLike,
    fy: ArrayLike,
    alpha: ArrayLike = 0.0,
    law: str = "bilinear",
    beta: ArrayLike = 0.5,
    gamma: ArrayLike = 0.5,
    n: ArrayLike = 1.0,
    fs: Optional[ArrayLike] = None,
    vr: Optional[ArrayLike] = None,
    max_iterations: int = 20,
    tolerance: float = 1e-10,
    energy: bool = True,
    histories: bool = True,
) -> BuildingResponse:
    """Step a hysteretic shear building over a ground-acceleration record.

    ``masses``: floor masses (kg), ground storey first (``n`` storeys, any ``n ≥ 1``:
    ``SIZES`` compiled, others run-time-sized, bit-identical where both serve). ``c``: damping matrix (N·s/m, ``n×n``; e.g. Rayleigh). ``h``: time step
    (s). ``ground_acceleration``: m/s² at ``t = i·h``. Storey laws (scalars or one value
    per storey): ``k`` elastic stiffness (N/m), ``fy`` yield force (N), ``alpha``
    post-yield ratio; ``law="bouc_wen"`` adds ``beta``, ``gamma``, ``n``;
    ``law="bilinear_friction"`` adds a friction damper with slip force ``fs`` (N) and
    regularization velocity ``vr`` (m/s). Newton: at most ``max_iterations`` a step,
    relative ``tolerance``; a step that does not converge raises ``NotConverged`` (its
    ``.step`` attribute says which); ``max_iterations`` above ``MAX_NEWTON_ITERATIONS``
    raises ``InvalidArgument``. ``energy=False`` skips the energy account (about one
    more law evaluation per storey a step) for the bare stepping speed.

    ``histories=False`` keeps no per-step arrays: ``u``, ``v``, ``a``, ``drifts`` and
    ``iterations`` are ``None``; ``peak_drifts`` (m, per storey), ``peak_drift`` (m, their
    max) and ``total_iterations`` are computed in the loop, bitwise the maxima of the
    histories; ``energy`` (if on) holds the last step only (each field one value). Cost:
    the histories write ``4n + 1`` float64 a step (``8·(4n + 1)`` bytes, 168 for 5 storeys,
    2.7 MB over 16 000 steps) and fresh pages for them; without, a run is the Rust
    stepping loop alone (the IDA and benchmark path).
    """
    masses = _vec(masses, "masses")
    count = masses.shape[0]
    cols = [("k", k), ("fy", fy), ("alpha", alpha)]
    if law == "bouc_wen":
        cols += [("beta", beta), ("gamma", gamma), ("n", n)]
    elif law == "bilinear_friction":
        if fs is None or vr is None:
            raise ShapeError("law='bilinear_friction' needs fs (N) and vr (m/s)")
        cols += [("fs", fs), ("vr", vr)]
    elif law != "bilinear":
        raise ValueError(f"unknown law {law!r}: one of {LAWS}")
    params = np.column_stack([_per_period(x, count, name, "storey") for name, x in cols])
    d = _aemstep.shear_building(
        masses,
        law,
        params,
        _mat(c, "c"),
        float(h),
        _vec(ground_acceleration, "ground_acceleration"),
        _count(max_iterations, "max_iterations", MAX_NEWTON_ITERATIONS),
        float(tolerance),
        bool(energy),
        bool(histories),
    )
    account = None
    if energy:
        e = d["energy"]
        account = Energy(e[:, 0], e[:, 1], e[:, 2], e[:, 3], e[:, 4], e[:, 5], d["initial_energy"])
    return frames.timed(BuildingResponse(
        d.get("u"),
        d.get("v"),
        d.get("a"),
        d.get("drifts"),
        d["peak_drifts"],
        account,
        d.get("iterations"),
        d["peak_drift"],
        d["total_iterations"],
    ), h, len(ground_acceleration))


# ---------------------------------------------------------------------------------------
# Elastic spectra.


class Spectrum(NamedTuple):
    """Elastic spectra; one value per period (``spectrum``) or ``records×periods``
    (``spectra``)."""

    periods: np.ndarray  #: s
    sd: np.ndarray  #: peak relative displacement (m)
    sv: np.ndarray  #: peak relative velocity (m/s)
    sa: np.ndarray  #: peak absolute acceleration (m/s²)
    psv: np.ndarray  #: pseudo-velocity ω·sd (m/s)
    psa: np.ndarray  #: pseudo-acceleration ω²·sd (m/s²)
    #: non-finite samples skipped (``nan="skip"``; 0 otherwise): an int (``spectrum``) or
    #: one per record (``spectra``)
    skipped: Union[int, np.ndarray] = 0

    def to_pandas(self) -> Any:
        """A ``pandas.DataFrame`` indexed by period (``frames.spectrum_to_pandas``)."""
        return frames.spectrum_to_pandas(self)

    def to_xarray(self) -> Any:
        """An ``xarray.Dataset`` on period (``frames.spectrum_to_xarray``)."""
        return frames.spectrum_to_xarray(self)


Progress = Union[bool, Callable[[int, int], Any], None]


def _progress(progress: Progress, total: int) -> Tuple[Callable[[int], None], Callable[[], None]]:
    """``(update(done), close())`` for a callable ``progress(done, total)``, for
    ``True`` (tqdm when installed, else nothing), or nothing."""
    if progress is None or progress is False:
        return (lambda done: None), (lambda: None)
    if progress is True:
        try:
            from tqdm import tqdm  # optional
        except ImportError:
            return (lambda done: None), (lambda: None)
        bar = tqdm(total=total, unit="record")
        state = {"done": 0}

        def update(done: int) -> None:
            bar.update(done - state["done"])
            state["done"] = done

        return update, bar.close
    return (lambda done: progress(done, total)), (lambda: None)


def spectra(
    periods: ArrayLike,
    damping: ArrayLike,
    h: Optional[float] = None,
    records: Union[Sequence[ArrayLike], Any] = None,
    *,
    scheme: str = "exact",
    free_vibration: bool = True,
    threads: int = 0,
    progress: Progress = None,
    nan: str = "raise",
) -> Spectrum:
    """Elastic spectra of many records on ``threads`` threads (0: every core).

    ``periods`` (s, non-decreasing, any count), ``damping`` (ratio: a scalar or one per
    period), ``h`` the records' sample interval (s), ``records`` ground accelerations
    (m/s², each 1-D, any lengths). Results are bit for bit those of one thread.
    ``progress``: a callable ``progress(done, total)`` or ``True`` for a tqdm bar (if tqdm
    is installed); the records then run in batches, the GIL released during each.
    ``records`` may be a pandas ``DataFrame``, one column a record; ``h`` may then be
    ``None``, taken from its uniformly spaced time index (s, or timedeltas).

    ``nan``: a NaN or infinite sample raises ``NonFiniteInput`` (``"raise"``, the default;
    ``.step`` is the sample's index in its record, ``.record`` the record's index), or is
    skipped (``"skip"``: the last finite sample held in its place, ``0`` before any; time
    still advances, so later samples stay on their times), the count per record in
    ``skipped``. Ctrl-C stops the call within a fraction of a second (``KeyboardInterrupt``).
    """
    records, h = frames.records_in(records, h)
    periods = _vec(periods, "periods")
    damping = _per_period(damping, periods.shape[0], "damping")
    recs = [_vec(r, "a record") for r in records]
    threads = int(threads)
    if progress is None or progress is False:
        batches = [recs]
    else:
        size = max(1, 4 * (threads if threads > 0 else (os.cpu_count() or 1)))
        batches = [recs[i : i + size] for i in range(0, len(recs), size)]
    update, close = _progress(progress, len(recs))
    parts = []
    done = 0
    try:
        for b in batches:
            try:
                parts.append(
                    _aemstep.spectra(
                        periods, damping, float(h), b, scheme, free_vibration, threads, nan
                    )
                )
            except NonFiniteInput as e:
                # the record's index in ``records``, not in its batch
                rec = getattr(e, "record", None)
                if rec is not None:
                    setattr(e, "record", rec + done)
                raise
            done += len(b)
            update(done)
    finally:
        close()
    if not parts:
        empty = np.zeros((0, periods.shape[0]))
        return Spectrum(periods, empty, empty, empty, empty, empty, np.zeros(0, dtype=np.int64))
    sd, sv, sa, psv, psa = (np.concatenate([p[q] for p in parts]) for q in range(5))
    skipped = np.concatenate([np.asarray(p[5], dtype=np.int64) for p in parts])
    return Spectrum(periods, sd, sv, sa, psv, psa, skipped)


def spectrum(
    periods: ArrayLike,
    damping: ArrayLike,
    h: float,
    ground_acceleration: ArrayLike,
    *,
    scheme: str = "exact",
    free_vibration: bool = True,
    threads: int = 1,
    nan: str = "raise",
) -> Spectrum:
    """Elastic spectra of one record: as ``spectra`` with one record, one value per period;
    ``skipped`` an int. ``nan="raise"`` (default: ``NonFiniteInput`` with ``.step``) or
    ``"skip"``, as ``spectra``."""
    s = spectra(
        periods,
        damping,
        h,
        [ground_acceleration],
        scheme=scheme,
        free_vibration=free_vibration,
        threads=threads,
        nan=nan,
    )
    return Spectrum(s.periods, s.sd[0], s.sv[0], s.sa[0], s.psv[0], s.psa[0],
                    int(np.asarray(s.skipped)[0]))


class RotDSpectrum(NamedTuple):
    """RotD50/RotD100 of two horizontal components (180 angles, 1° apart)."""

    periods: np.ndarray  #: s
    rotd50: np.ndarray  #: median over the angles of the peak displacement (m)
    rotd100: np.ndarray  #: largest over the angles (m)
    psa50: np.ndarray  #: ω²·rotd50 (m/s²)
    psa100: np.ndarray  #: ω²·rotd100 (m/s²)
    #: non-finite samples skipped in ``(ax, ay)`` (``nan="skip"``; ``(0, 0)`` otherwise)
    skipped: Tuple[int, int] = (0, 0)


def rotd(
    periods: ArrayLike,
    damping: ArrayLike,
    h: float,
    ax: ArrayLike,
    ay: ArrayLike,
    *,
    scheme: str = "exact",
    free_vibration: bool = True,
    threads: int = 0,
    nan: str = "raise",
) -> RotDSpectrum:
    """RotD50 and RotD100 of the components ``ax``, ``ay`` (m/s², same length, sample
    interval ``h`` s); ``periods`` (s), ``damping``, ``nan`` as ``spectra`` (under
    ``"raise"``, ``.record`` is 0 for ``ax``, 1 for ``ay``; under ``"skip"`` each component
    holds its own last finite sample)."""
    periods = _vec(periods, "periods")
    damping = _per_period(damping, periods.shape[0], "damping")
    out = _aemstep.rotd(
        periods,
        damping,
        float(h),
        _vec(ax, "ax"),
        _vec(ay, "ay"),
        scheme,
        free_vibration,
        int(threads),
        nan,
    )
    return RotDSpectrum(periods, *out[:4], (int(out[4][0]), int(out[4][1])))


# ---------------------------------------------------------------------------------------
# Inelastic spectra.


class ConstantStrength(NamedTuple):
    """Constant-strength spectrum, one value per period."""

    periods: np.ndarray  #: initial periods (s)
    elastic: np.ndarray  #: elastic strength per unit mass ω² u_o (m/s²)
    yield_acceleration: np.ndarray  #: f_y/m = elastic/R (m/s²)
    ductility: np.ndarray  #: μ = max|u| / u_y
    plastic_work: np.ndarray  #: hysteretic work per unit mass (m²/s²)
    skipped: int = 0  #: non-finite samples skipped (``nan="skip"``; 0 otherwise)


def constant_strength(
    periods: ArrayLike,
    damping: ArrayLike,
    h: float,
    ground_acceleration: ArrayLike,
    reduction: ArrayLike,
    *,
    alpha: float = 0.0,
    points_per_period: int = 40,
    threads: int = 0,
    nan: str = "raise",
) -> ConstantStrength:
    """Ductility demand of bilinear oscillators (post-yield ratio ``alpha``, 0:
    elastic–perfectly plastic) whose strength is the elastic strength over ``reduction``
    (R, scalar or per period). ``periods`` (s), ``damping`` (ratio), ``h`` (s), record in
    m/s². Sub-steps: at least ``points_per_period`` per initial period. ``nan`` as
    ``spectra``: ``"raise"`` (``NonFiniteInput`` with ``.step``) or ``"skip"``."""
    periods = _vec(periods, "periods")
    count = periods.shape[0]
    out = _aemstep.constant_strength(
        periods,
        _per_period(damping, count, "damping"),
        float(alpha),
        float(h),
        _vec(ground_acceleration, "ground_acceleration"),
        _per_period(reduction, count, "reduction"),
        int(points_per_period),
        int(threads),
        nan,
    )
    return ConstantStrength(periods, *out[:4], int(out[4]))


class ConstantDuctility(NamedTuple):
    """Constant-ductility spectrum, one value per period."""

    periods: np.ndarray  #: initial periods (s)
    yield_acceleration: np.ndarray  #: largest f_y/m giving the target ductility (m/s²)
    elastic: np.ndarray  #: elastic strength per unit mass (m/s²)
    reduction: np.ndarray  #: R_y = elastic / yield_acceleration
    bracket: np.ndarray  #: final bracket [lo, hi] of the strength (m/s², periods×2)
    bracket_ductility: np.ndarray  #: μ at the bracket's ends (periods×2)
    outcome: List[str]  #: "converged", "no_crossing" or "not_converged" per period
    passes: int  #: record passes of the slowest bank
    skipped: int = 0  #: non-finite samples skipped (``nan="skip"``; 0 otherwise)


def constant_ductility(
    periods: ArrayLike,
    damping: ArrayLike,
    h: float,
    ground_acceleration: ArrayLike,
    target: float,
    *,
    alpha: float = 0.0,
    points: int = 60,
    lowest: float = 0.01,
    tol: float = 1e-6,
    points_per_period: int = 40,
    threads: int = 0,
    nan: str = "raise",
) -> ConstantDuctility:
    """The largest yield strength per unit mass (m/s²) giving the ductility ``target``
    (> 1) at each period: a geometric grid of ``points`` strengths from the elastic one
    down to ``lowest`` times it brackets the largest crossing, a safeguarded false
    position refines it to ``tol`` (relative, on the strength). ``nan`` as ``spectra``:
    ``"raise"`` (``NonFiniteInput`` with ``.step``) or ``"skip"``."""
    periods = _vec(periods, "periods")
    d = _aemstep.constant_ductility(
        periods,
        _per_period(damping, periods.shape[0], "damping"),
        float(alpha),
        float(h),
        _vec(ground_acceleration, "ground_acceleration"),
        float(target),
        int(points),
        float(lowest),
        float(tol),
        int(points_per_period),
        int(threads),
        nan,
    )
    ay = d["yield_acceleration"]
    return ConstantDuctility(
        periods,
        ay,
        d["elastic"],
        d["elastic"] / ay,
        d["bracket"],
        d["bracket_ductility"],
        list(d["outcome"]),
        int(d["passes"]),
        int(d["skipped"]),
    )


# ---------------------------------------------------------------------------------------
# Observers.


class _Estimate(NamedTuple):
    u: np.ndarray  #: displacements (m)
    v: np.ndarray  #: velocities (m/s)
    drifts: np.ndarray  #: storey drifts u_i − u_{i−1} (m)
    gain: np.ndarray  #: steady-state gain (2n×sensors; empty for the Kalman filter)


class Estimate(_Estimate, frames.History):
    """State estimates, ``steps×n``, relative to the ground; ``time`` (s) of each row."""


def observe(
    m: ArrayLike,
    c: ArrayLike,
    k: ArrayLike,
    h: float,
    ground_acceleration: ArrayLike,
    measured: ArrayLike,
    sensors: Sequence[int],
    *,
    sigma_f: float,
    sigma_y: float,
    kalman: bool = False,
) -> Estimate:
    """Estimate a building's state from measured absolute floor accelerations.

    ``m``, ``c``, ``k``: the model (kg, N·s/m, N/m; ``n×n``). ``h``: sample interval (s).
    ``ground_acceleration``: the measured ground motion (m/s²), the model's input.
    ``measured``: absolute accelerations (m/s², ``steps×len(sensors)``; NaN for a missing
    sample) of the floors ``sensors`` (0-based). ``sigma_f``: white-force process noise on
    every floor (N, standard deviation); ``sigma_y``: accelerometer noise (m/s²).
    ``kalman``: the full Kalman filter instead of the fixed steady-state gain.
    """
    meas = np.ascontiguousarray(measured, dtype=np.float64)
    if meas.ndim == 1:
        meas = meas[:, None]
    u, v, gain = _aemstep.observe(
        _mat(m, "m"),
        _mat(c, "c"),
        _mat(k, "k"),
        float(h),
        _vec(ground_acceleration, "ground_acceleration"),
        _mat(meas, "measured"),
        [_count(s, "sensors") for s in sensors],
        float(sigma_f),
        float(sigma_y),
        bool(kalman),
    )
    return frames.timed(Estimate(u, v, np.diff(u, axis=1, prepend=0.0), gain), h, u.shape[0])

# ---------------------------------------------------------------------------------------
# Vibration control.


def zero_order_hold(m: ArrayLike, c: ArrayLike, k: ArrayLike, b: ArrayLike, h: float) -> Tuple[np.ndarray, np.ndarray]:
    """The exact sampled model ``x_{k+1} = Φ x_k + Γ f_k`` of ``M u'' + C u' + K u = B f``
    with the force held over each step of ``h`` s (zero-order hold), ``x = [u; v]``.

    ``m``, ``c``, ``k``: kg, N·s/m, N/m (``n×n``, ``n`` in ``SIZES``). ``b``: the force
    distribution (``n`` or ``n×inputs``, 1 to ``MAX_CONTROL_INPUTS`` columns). Returns
    ``(phi, gamma)``: ``2n×2n`` and ``2n×inputs`` (m/N, m/s/N)."""
    bb = np.asarray(b, dtype=np.float64)
    if bb.ndim == 1:
        bb = bb[:, None]
    return _aemstep.zero_order_hold(_mat(m, "m"), _mat(c, "c"), _mat(k, "k"), _mat(bb, "b"), float(h))


class Regulator(NamedTuple):
    """A discrete LQR design (``lqr``)."""

    gain: np.ndarray  #: K (inputs×states; inputs×(states+inputs) with the delay): u = −K x
    cost: np.ndarray  #: P, the stabilizing Riccati solution (cost-to-go x₀ᵀ P x₀)
    closed_loop: np.ndarray  #: Φ − Γ K (of the delayed model with the delay)
    radius_bound: float  #: certified upper bound on the closed loop's spectral radius (< 1)
    iterations: int  #: doubling iterations of the Riccati solver


def lqr(
    phi: ArrayLike,
    gamma: ArrayLike,
    q: ArrayLike,
    r: ArrayLike,
    s: Optional[ArrayLike] = None,
    delay: bool = False,
    decision: Optional[ArrayLike] = None,
) -> Regulator:
    """The discrete linear–quadratic regulator of ``x_{k+1} = Φ x_k + Γ u_k`` for the cost
    ``Σ xᵀQx + 2xᵀSu + uᵀRu``: ``u = −K x`` (``aemstep::control::Lqr``, certified
    stabilizing).

    ``phi`` (``S×S``, ``S`` ≤ ``MAX_DESIGN_STATES``), ``gamma`` (``S`` or ``S×I``, ``I`` ≤
    ``MAX_CONTROL_INPUTS``), ``q`` (``S×S``, symmetric positive semidefinite), ``r``
    (``I×I`` or a scalar, symmetric positive definite), ``s`` (``S×I`` cross weight,
    default zero). ``delay=True`` designs on the model with the one-sample computation
    delay ``z = [x; u_{k−1}]`` (the force computed from sample ``k`` acts from ``k+1``):
    ``K`` is then ``I×(S+I)``, and ``decision`` (default ``1e-3·R``) weighs the command as
    computed. Raises ``InvalidParameter`` (``.parameter == "Weight"``),
    ``RiccatiNotConverged``, ``NotStabilizing``, ``UnsupportedSize``, …"""
    g = np.asarray(gamma, dtype=np.float64)
    if g.ndim == 1:
        g = g[:, None]
    rr = np.asarray(r, dtype=np.float64)
    if rr.ndim == 0:
        rr = rr.reshape(1, 1)
    ss = np.zeros(g.shape) if s is None else np.asarray(s, dtype=np.float64)
    if ss.ndim == 1:
        ss = ss[:, None]
    dec = None
    if delay:
        dec = 1e-3 * rr if decision is None else np.asarray(decision, dtype=np.float64)
        if dec.ndim == 0:
            dec = dec.reshape(1, 1)
        dec = _mat(dec, "decision")
    elif decision is not None:
        raise ShapeError("decision weighs the delayed design: pass delay=True with it")
    k, p, cl, radius, iterations = _aemstep.lqr(
        _mat(phi, "phi"), _mat(g, "gamma"), _mat(q, "q"), _mat(rr, "r"), _mat(ss, "s"), dec
    )
    return Regulator(k, p, cl, float(radius), int(iterations))


class OutputFeedback(NamedTuple):
    """The gains of an LQG controller (``lqg``)."""

    observer_gain: np.ndarray  #: L = P Hᵀ (H P Hᵀ + V)⁻¹ (2n×sensors)
    gain: np.ndarray  #: K (1×2n): u = −K x̂
    filter_covariance: np.ndarray  #: the a-priori error covariance P (2n×2n)
    cost: np.ndarray  #: the regulator's Riccati solution (2n×2n)
    radius_bound: float  #: certified bound on the spectral radius of Φ − Γ K (< 1)


SENSED = ("displacements", "velocities", "accelerations")


def lqg(
    m: ArrayLike,
    c: ArrayLike,
    k: ArrayLike,
    b: ArrayLike,
    h: float,
    sensors: Sequence[int],
    *,
    q: ArrayLike,
    r: float,
    w: ArrayLike,
    v: ArrayLike,
    sensed: str = "velocities",
) -> OutputFeedback:
    """The two gains of an output-feedback (LQG) controller of a building with one control
    force ``b`` (``n`` values): the steady-state Kalman gain of its zero-order-hold model
    at sample interval ``h`` (s), measuring ``sensed`` (``SENSED``: relative displacements,
    velocities or accelerations) of the DOFs ``sensors``, with process noise covariance
    ``w`` (``2n×2n``, on ``x = [u; v]``) and measurement noise covariance ``v``
    (``sensors×sensors``, or a scalar for ``σ² I``); and the LQR gain for the weights ``q``
    (``2n×2n``) and ``r`` (scalar, on the force). The Rust ``Controller`` combines them.
    Raises ``InvalidCovariance``, ``InvalidParameter`` (``.parameter == "Weight"``),
    ``RiccatiNotConverged``, ``NotStabilizing``, ``UnsupportedSize``, …"""
    if sensed not in SENSED:
        raise ValueError(f"unknown sensed {sensed!r}: one of {SENSED}")
    sensors = [_count(s, "sensors") for s in sensors]
    vv = np.asarray(v, dtype=np.float64)
    if vv.ndim == 0:
        vv = float(vv) * np.eye(len(sensors))
    ell, kk, pf, pr, radius = _aemstep.lqg(
        _mat(m, "m"),
        _mat(c, "c"),
        _mat(k, "k"),
        _vec(b, "b"),
        float(h),
        sensors,
        sensed,
        _mat(q, "q"),
        float(r),
        _mat(w, "w"),
        _mat(vv, "v"),
    )
    return OutputFeedback(ell, kk, pf, pr, float(radius))


#: The Bouc–Wen MR damper parameters of Dyke, Spencer, Sain & Carlson (1996), "Modeling
#: and control of magnetorheological dampers for seismic response reduction", Smart Mater.
#: Struct. 5, in SI units — as quoted by the literature citing the paper (its table was not
#: read here): the 3-kN prototype of the benchmark. ``gamma``, ``beta`` in m⁻ⁿ (``n = 1``).
DYKE_1996 = {
    "c0a": 4.40,  # N·s/m
    "c0b": 44.0,  # N·s/(m·V)
    "alpha_a": 1.0872e5,  # N/m
    "alpha_b": 4.9616e5,  # N/(m·V)
    "gamma": 300.0,  # m⁻¹
    "beta": 300.0,  # m⁻¹
    "a": 1.2,
    "n": 1.0,
    "eta": 50.0,  # 1/s
    "v_max": 2.25,  # V
}

#: The order of the damper's parameters in the native calls.
MR_PARAMETERS = ("c0a", "c0b", "alpha_a", "alpha_b", "gamma", "beta", "a", "n", "eta", "v_max")


def _mr_params(params: Optional[Dict[str, float]]) -> List[float]:
    p = dict(DYKE_1996)
    if params is not None:
        unknown = set(params) - set(MR_PARAMETERS)
        if unknown:
            raise ValueError(f"unknown MR damper parameters {sorted(unknown)}: known are {MR_PARAMETERS}")
        p.update(params)
    return [float(p[name]) for name in MR_PARAMETERS]


class _DamperResponse(NamedTuple):
    force: np.ndarray  #: the damper force (N)
    z: np.ndarray  #: the Bouc–Wen variable (m)
    voltage: np.ndarray  #: the filtered voltage u (V)


class DamperResponse(_DamperResponse, frames.History):
    """An MR damper driven by a motion (``mr_damper_response``), one value per sample;
    ``time`` (s) of each sample."""


def mr_damper_response(
    x: ArrayLike,
    xdot: ArrayLike,
    voltage: Union[float, ArrayLike],
    h: float,
    params: Optional[Dict[str, float]] = None,
) -> DamperResponse:
    """The force of the Bouc–Wen MR damper of Dyke et al. (1996) (``aemstep::control::MrDamper``)
    driven by a displacement ``x`` (m) and velocity ``xdot`` (m/s) history sampled every
    ``h`` s, and a command ``voltage`` (V; a scalar, or one value per sample, each held
    over the step that follows, clipped into ``[0, V_max]``).

    ``params``: a dict overriding ``DYKE_1996`` (keys ``MR_PARAMETERS``, SI units). The
    damper starts at rest at ``x[0]`` (row 0: force 0). Raises ``InvalidMaterial``
    (``.parameter == "Device"``), ``InvalidParameter`` (``"Saturation"``),
    ``NonFiniteInput`` (``.step``), ``InvalidTimeStep``."""
    xs = _vec(x, "x")
    v = np.asarray(voltage, dtype=np.float64)
    if v.ndim == 0:
        v = np.full(xs.shape[0], float(v))
    f, z, u = _aemstep.mr_damper_response(xs, _vec(xdot, "xdot"), _vec(v, "voltage"), float(h), _mr_params(params))
    return frames.timed(DamperResponse(f, z, u), h, f.shape[0])


class _ControlledResponse(NamedTuple):
    u: np.ndarray  #: displacements relative to the ground (m), steps×n
    v: np.ndarray  #: velocities (m/s), steps×n
    force: np.ndarray  #: the damper force (N), one value per sample
    command: np.ndarray  #: the voltage held from each sample on (V)


class ControlledResponse(_ControlledResponse, frames.History):
    """A building with one MR damper (``mr_building``); ``time`` (s) of each row."""


MR_LAWS = ("off", "on", "clipped")


def mr_building(
    m: ArrayLike,
    c: ArrayLike,
    k: ArrayLike,
    ground_acceleration: ArrayLike,
    h: float,
    *,
    storey: int = 0,
    law: str = "off",
    gain: Optional[ArrayLike] = None,
    params: Optional[Dict[str, float]] = None,
) -> ControlledResponse:
    """A linear building (``m``, ``c``, ``k``: kg, N·s/m, N/m, ``n×n``) with one MR damper
    (Dyke et al. 1996; ``params`` as in ``mr_damper_response``) in storey ``storey`` (0:
    ground to floor 0; ``j``: floor ``j−1`` to ``j``) under ``ground_acceleration`` (m/s²,
    one value per step of ``h`` s).

    ``law``: ``"off"`` (0 V), ``"on"`` (``V_max``), or ``"clipped"``: the clipped-optimal
    law on the desired force ``f_c = −K x`` of the state ``x = [u; v]`` (``gain`` ``K``,
    ``2n`` values, internal-force sign: a positive ``f_c`` resists a positive storey
    drift; e.g. ``lqr(*zero_order_hold(m, c, k, -b, h), q, r).gain`` with ``b`` the
    damper's unit drift vector), the measured force the damper's own; the command is held
    from the next step. Raises ``NotConverged``, ``InvalidMaterial``, … (``.step``)."""
    if law not in MR_LAWS:
        raise ValueError(f"unknown law {law!r}: one of {MR_LAWS}")
    kk = None
    if law == "clipped":
        if gain is None:
            raise ValueError("law='clipped' needs the state-feedback gain")
        kk = _mat(np.asarray(gain, dtype=np.float64).reshape(1, -1), "gain")
    elif gain is not None:
        raise ValueError(f"law={law!r} takes no gain")
    u, v, f, cmd = _aemstep.mr_building(
        _mat(m, "m"),
        _mat(c, "c"),
        _mat(k, "k"),
        _vec(ground_acceleration, "ground_acceleration"),
        float(h),
        _count(storey, "storey"),
        _mr_params(params),
        law,
        kk,
    )
    return frames.timed(ControlledResponse(u, v, f, cmd), h, u.shape[0])


# ---------------------------------------------------------------------------------------
# Records.


def _text(path_or_text: Union[str, bytes, "os.PathLike[str]"]) -> str:
    """One rule for what a record reader takes: a ``str`` with a line break is the text
    itself; ``bytes`` are the file's content (UTF-8); any other ``str`` or ``os.PathLike``
    is a path, read as UTF-8. Anything else (an ``int`` file descriptor above all) raises
    ``InvalidArgument``; bytes that are not UTF-8 raise ``MalformedRecord`` with the
    ``.line`` (1-based) of the first bad byte."""
    if isinstance(path_or_text, str) and "\n" in path_or_text:
        return path_or_text
    if isinstance(path_or_text, (bytes, bytearray)):
        raw = bytes(path_or_text)
    elif isinstance(path_or_text, (str, os.PathLike)):
        with open(path_or_text, "rb") as f:
            raw = f.read()
    else:
        e = InvalidArgument(
            "path_or_text must be a path (str or os.PathLike), the record's text (a str with a"
            f" line break) or its bytes, never a file descriptor; got {type(path_or_text).__name__}"
        )
        e.argument = "path_or_text"
        raise e
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as u:
        line = raw.count(b"\n", 0, u.start) + 1
        e = MalformedRecord(
            f"malformed record: the bytes are not UTF-8 (byte {u.start}, line {line})"
        )
        e.line = line
        raise e from None


def read_at2(path_or_text: Union[str, bytes, "os.PathLike[str]"]) -> Tuple[np.ndarray, float]:
    """A PEER NGA ``.AT2`` record (a path, or the text itself: a ``str`` with a line
    break, or the file's ``bytes``; never a file descriptor: ``InvalidArgument``):
    ``(accelerations in the file's units (g), dt in s)``. Multiply by ``G`` for
    m/s². Parsed by the library's reader (``aemstep::records``): a header without a
    readable ``NPTS``/``DT``, a value that is not a number, or more or fewer values than
    ``NPTS`` raise ``MalformedRecord`` (its ``.line`` is the 1-based line)."""
    _title, dt, values = _aemstep.parse_at2(_text(path_or_text))
    return values, dt


def read_column(path_or_text: Union[str, bytes, "os.PathLike[str]"], dt: float) -> Tuple[np.ndarray, float]:
    """A one-column record (one number a line; blank lines and ``#`` comments ignored), a
    path or the text itself (a ``str`` with a line break), sampled every ``dt`` s (not in
    the file): ``(values in the file's units, dt)``. Raises ``InvalidTimeStep`` for a
    ``dt`` not finite and > 0, ``MalformedRecord`` (with ``.line``) for a line that is not
    one number, or no value at all."""
    values = _aemstep.parse_column(_text(path_or_text), float(dt))
    return values, float(dt)


from ._ida import (  # noqa: E402  (re-exported: `name as name` for mypy --strict)
    INTENSITY_MEASURES as INTENSITY_MEASURES,
    IdaCurve as IdaCurve,
    ida_fractiles as ida_fractiles,
    ida_hunt_fill as ida_hunt_fill,
    ida_stripes as ida_stripes,
    spectral_acceleration as spectral_acceleration,
)
from . import plot as plot  # noqa: E402  (matplotlib imported on use)

__all__ = [
    "G",
    "SIZES",
    "CHUNK",
    "MAX_OBSERVE_DOFS",
    "MAX_SENSORS",
    "MAX_TRUNCATED_MODES",
    "ROTD_ANGLES",
    "SCHEMES",
    "LAWS",
    "MAX_NEWTON_ITERATIONS",
    "ERROR_VARIANTS",
    "AemstepError",
    "ShapeError",
    "UnsupportedSize",
    "InvalidArgument",
    "LinearResponse",
    "linear_response",
    "Energy",
    "BuildingResponse",
    "shear_building",
    "Spectrum",
    "spectra",
    "spectrum",
    "RotDSpectrum",
    "rotd",
    "ConstantStrength",
    "constant_strength",
    "ConstantDuctility",
    "constant_ductility",
    "Estimate",
    "observe",
    "MAX_DESIGN_STATES",
    "MAX_CONTROL_INPUTS",
    "zero_order_hold",
    "Regulator",
    "lqr",
    "SENSED",
    "OutputFeedback",
    "lqg",
    "DYKE_1996",
    "MR_PARAMETERS",
    "DamperResponse",
    "mr_damper_response",
    "MR_LAWS",
    "ControlledResponse",
    "mr_building",
    "read_at2",
    "read_column",
    "ida_stripes",
    "ida_hunt_fill",
    "ida_fractiles",
    "IdaCurve",
    "INTENSITY_MEASURES",
    "spectral_acceleration",
    "frames",
    "plot",
] + list(ERROR_VARIANTS)
