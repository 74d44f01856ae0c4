"""Type stubs of the native module ``aemstep._aemstep`` (Rust, PyO3, stable ABI).

Arrays are ``float64`` numpy arrays (the wrapper ``aemstep`` converts anything else);
units SI: m, s, kg, N, ground accelerations in m/s². The GIL is released while a record
runs. Library errors are raised as the exception classes below, one per
``aemstep::Error`` variant, message the Rust ``Display``; a failed step sets ``.step``.
"""

from typing import Any, Callable, Dict, List, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]

#: Numbers of degrees of freedom (storeys) compiled in: 1–10, 12, 15, 20.
SIZES: List[int]
#: Oscillators per spectrum bank (periods are stepped in banks of this many, padded).
CHUNK: int
#: Most modes a truncated modal run keeps (``modes=0`` keeps all).
MAX_TRUNCATED_MODES: int
#: Most sensors an observer takes.
MAX_SENSORS: int
MAX_OBSERVE_DOFS: int
#: Rotation angles of RotD (180: 1° apart).
ROTD_ANGLES: int
#: Most states of a design model (``lqr``; with the delay, states + inputs).
MAX_DESIGN_STATES: int
#: Most control inputs of a design model (``zero_order_hold``, ``lqr``).
MAX_CONTROL_INPUTS: int
#: The names of the ``aemstep::Error`` variants, in declaration order.
ERROR_VARIANTS: List[str]

class AemstepError(ValueError):
    """Base of every aemstep error."""

    step: int  # set when a step failed: its index (0: the start)
    record: int  # NonFiniteInput from spectra/rotd: the record's index (rotd: 0 ax, 1 ay)

class ShapeError(AemstepError):
    """An array has the wrong shape or length."""

class UnsupportedSize(ShapeError):
    """A number of degrees of freedom or sensors outside those compiled in."""

class InvalidArgument(AemstepError):
    """An argument outside its rule (a negative count, a file descriptor for a path)."""

    argument: str  # the argument's name

class NonFiniteInput(AemstepError): ...
class InvalidTimeStep(AemstepError): ...
class SingularEffectiveMatrix(AemstepError): ...
class SingularMass(AemstepError): ...
class NonFiniteState(AemstepError): ...
class NotConverged(AemstepError): ...
class SingularJacobian(AemstepError): ...
class NonFiniteForce(AemstepError): ...
class InvalidNewtonSettings(AemstepError): ...
class SingularEffectiveMatrixAtStep(AemstepError): ...
class MassNotSpd(AemstepError): ...
class StiffnessNotSymmetric(AemstepError): ...
class InvalidModeSelection(AemstepError): ...
class NonClassicalDamping(AemstepError): ...
class EigenNotConverged(AemstepError): ...
class OperatorOverflow(AemstepError): ...
class OperatorUnderflow(AemstepError): ...
class InvalidParameter(AemstepError): ...
class InvalidPeriod(AemstepError): ...
class InvalidDamping(AemstepError): ...
class InvalidMaterial(AemstepError): ...
class InvalidCovariance(AemstepError): ...
class RiccatiNotConverged(AemstepError): ...
class StateSizeMismatch(AemstepError): ...
class InputNotIdentifiable(AemstepError): ...

class MalformedRecord(AemstepError):
    """A record's text is malformed (``aemstep::records``)."""

    line: int  # the 1-based line where the problem was found

class StiffnessIndefinite(AemstepError): ...
class StepCountOverflow(AemstepError): ...
class NotStabilizing(AemstepError): ...

def linear_response(
    m: F64,
    c: F64,
    k: F64,
    h: float,
    p: F64,
    u0: F64,
    v0: F64,
    scheme: str = "aem",
    beta: float = 0.25,
    gamma: float = 0.5,
    rho_inf: float = 1.0,
    alpha: float = 0.0,
    modes: int = 0,
) -> Tuple[F64, F64, F64]:
    """Step ``M u'' + C u' + K u = p(t)`` over a load history.

    m, c, k: ``n×n`` mass (kg), damping (N·s/m), stiffness (N/m); h: time step (s);
    p: loads (N), ``steps×n``, row i at t = i·h; u0 (m), v0 (m/s): initial state;
    scheme: ``"aem"``, ``"modal"`` (the ``modes`` lowest modes, 0 for all, else 1 to 3;
    M SPD, K symmetric, C classical),
    ``"newmark"`` (beta, gamma), ``"generalized_alpha"`` (rho_inf in [0, 1]), ``"hht"``
    (alpha in [−1/3, 0]), ``"exact"``.
    Returns (u m, v m/s, a m/s²), each ``steps×n``, row 0 the initial state.
    """

def shear_building(
    masses: F64,
    law: str,
    params: F64,
    c: F64,
    h: float,
    ag: F64,
    max_iterations: int = 20,
    tolerance: float = 1e-10,
    energy: bool = True,
    histories: bool = True,
    compiled: bool = True,
) -> Dict[str, Any]:
    """A hysteretic shear building (Nonlinear AEM stepper, Newton) over a record.

    Any number of storeys: those in ``SIZES`` run compiled, others run-time-sized
    (bit-identical where both serve; compiled=False forces the run-time path).

    masses: floor masses (kg), ground storey first; law: ``"bilinear"`` (params columns
    k N/m, fy N, alpha), ``"bouc_wen"`` (k, fy, alpha, beta, gamma, n) or
    ``"bilinear_friction"`` (k, fy, alpha, fs N, vr m/s); params: one row per storey;
    c: damping (N·s/m, ``n×n``); h: time step (s); ag: ground acceleration (m/s²) at
    t = i·h; Newton at most max_iterations a step to the relative tolerance.
    Returns ``u`` (m), ``v`` (m/s), ``a`` (m/s²) relative to the ground (``steps×n``),
    ``energy`` (``steps×6``: input, kinetic, recoverable, viscous, hysteretic, balance
    error; J) and ``initial_energy`` (J), both only with energy=True (the account costs
    about one law evaluation per storey a step), ``iterations`` (per step), ``drifts``
    (m, ``steps×n``); always ``peak_drifts`` (m, per storey), ``peak_drift`` (m) and
    ``total_iterations``. histories=False keeps no per-step arrays (no ``u``, ``v``,
    ``a``, ``drifts``, ``iterations``; ``energy`` ``1×6``, the last step): the Rust loop's
    speed, no ``8·(4n + 1)`` bytes written a step.
    """

def spectra(
    periods: F64,
    damping: F64,
    h: float,
    records: List[F64],
    scheme: str = "exact",
    free_vibration: bool = True,
    threads: int = 1,
    nan: str = "raise",
) -> Tuple[F64, F64, F64, F64, F64, List[int]]:
    """Elastic spectra of records (m/s², sample interval h s) at periods (s,
    non-decreasing) with damping ratios (one per period), on threads (0: all cores; bit
    for bit the same on any count). Returns (sd m, sv m/s, sa m/s², psv m/s, psa m/s²),
    each ``records×periods``, and the samples skipped per record. nan: "raise"
    (NonFiniteInput with .step and .record) or "skip".
    """

def rotd(
    periods: F64,
    damping: F64,
    h: float,
    ax: F64,
    ay: F64,
    scheme: str = "exact",
    free_vibration: bool = True,
    threads: int = 1,
    nan: str = "raise",
) -> Tuple[F64, F64, F64, F64, Tuple[int, int]]:
    """RotD50/RotD100 of two components (m/s²): (rotd50 m, rotd100 m, psa50 m/s²,
    psa100 m/s²), one value per period, and the samples skipped in (ax, ay)."""

def constant_strength(
    periods: F64,
    damping: F64,
    alpha: float,
    h: float,
    ag: F64,
    reduction: F64,
    points_per_period: int = 40,
    threads: int = 1,
    nan: str = "raise",
) -> Tuple[F64, F64, F64, F64, int]:
    """Constant-strength spectrum of bilinear oscillators (post-yield ratio alpha in
    [0, 1)): strength = elastic / reduction (R per period). Returns (elastic m/s²,
    yield_acceleration m/s², ductility, plastic_work m²/s²) per period and the samples
    skipped."""

def constant_ductility(
    periods: F64,
    damping: F64,
    alpha: float,
    h: float,
    ag: F64,
    target: float,
    points: int = 60,
    lowest: float = 0.01,
    tol: float = 1e-6,
    points_per_period: int = 40,
    threads: int = 1,
    nan: str = "raise",
) -> Dict[str, Any]:
    """Constant-ductility spectrum: the largest yield strength per unit mass (m/s²)
    giving the ductility target (> 1). Returns ``yield_acceleration``, ``elastic``
    (m/s²), ``bracket`` (``periods×2``, m/s²), ``bracket_ductility`` (``periods×2``),
    ``outcome`` (list of str), ``passes`` (int), ``skipped`` (int)."""

def observe(
    m: F64,
    c: F64,
    k: F64,
    h: float,
    ag: F64,
    measured: F64,
    sensors: List[int],
    sigma_f: float,
    sigma_y: float,
    kalman: bool = False,
) -> Tuple[F64, F64, F64]:
    """State of a linear building from measured absolute floor accelerations (m/s²,
    ``steps×sensors``; NaN: missing) and the ground acceleration (m/s²): steady-state
    Kalman-gain observer or full Kalman filter; process noise sigma_f (N, white forces
    on every floor), sensor noise sigma_y (m/s²). Returns (u m, v m/s, gain
    ``2n×sensors``, empty for the Kalman filter). Both take any n up to
    MAX_OBSERVE_DOFS and any number of sensors (outside SIZES or above MAX_SENSORS on the
    run-time-sized DynObserver / DynKalman, same arithmetic)."""

def zero_order_hold(m: F64, c: F64, k: F64, b: F64, h: float) -> Tuple[F64, F64]:
    """Exact sampled model of M u'' + C u' + K u = B f with f held over each step of h s
    (x = [u; v]): (phi ``2n×2n``, gamma ``2n×inputs``, m/N and m/s/N)."""

def lqr(
    phi: F64,
    gamma: F64,
    q: F64,
    r: F64,
    s: F64,
    decision: Optional[F64] = None,
) -> Tuple[F64, F64, F64, float, int]:
    """Discrete LQR of x' = phi x + gamma u for the cost Σ xᵀqx + 2xᵀsu + uᵀru, u = −K x;
    with ``decision`` (``I×I``) on the model with the one-sample computation delay.
    Returns (K, P, phi − gamma K, certified spectral-radius bound, doubling iterations)."""

def lqg(
    m: F64,
    c: F64,
    k: F64,
    b: F64,
    h: float,
    sensors: List[int],
    sensed: str,
    q: F64,
    r: float,
    w: F64,
    v: F64,
) -> Tuple[F64, F64, F64, F64, float]:
    """Gains of an LQG controller of a building with one control force b (``n``) sampled
    at h s: the steady-state Kalman gain of its zero-order-hold model measuring ``sensed``
    ("displacements", "velocities", "accelerations") at ``sensors``, noise covariances w
    (``2n×2n``) and v, and the LQR gain for weights q (``2n×2n``), r. Returns (L
    ``2n×sensors``, K ``1×2n``, filter covariance, regulator cost, radius bound)."""

def mr_damper_response(
    x: F64,
    xdot: F64,
    voltage: F64,
    h: float,
    params: List[float],
) -> Tuple[F64, F64, F64]:
    """Bouc–Wen MR damper (Dyke et al. 1996) driven by x (m), xdot (m/s) and a command
    voltage (V, held over the following step), params (c0a, c0b, alpha_a, alpha_b, gamma,
    beta, a, n, eta, v_max) in SI. Returns (force N, z m, filtered voltage V) per sample."""

def mr_building(
    m: F64,
    c: F64,
    k: F64,
    ag: F64,
    h: float,
    storey: int,
    params: List[float],
    law: str,
    gain: Optional[F64] = None,
) -> Tuple[F64, F64, F64, F64]:
    """Linear building with one MR damper in ``storey`` under ag (m/s²): law "off", "on"
    or "clipped" (clipped-optimal on f_c = −gain·[u; v], gain ``1×2n``). Returns (u m,
    v m/s, damper force N, command V held from each sample)."""

def parse_at2(text: str) -> Tuple[str, float, F64]:
    """PEER NGA AT2 text parsed by ``aemstep::records``: (title, dt s, the NPTS values in
    the file's units, g for acceleration). Raises ``MalformedRecord`` (``.line``)."""

def parse_column(text: str, dt: float) -> F64:
    """One-column text (one number a line, ``#`` comments) sampled every dt s (> 0):
    the values. Raises ``InvalidTimeStep``, ``MalformedRecord`` (``.line``)."""

def ida_stripes(
    records: List[F64],
    h: float,
    intensities: F64,
    masses: F64,
    law: str,
    params: F64,
    c: F64,
    max_iterations: int = 20,
    tolerance: float = 1e-10,
    collapse_drift: Optional[float] = None,
    on_failure: str = "collapse",
    threads: int = 0,
    progress: Optional[Callable[[int, int], Any]] = None,
) -> List[Dict[str, Any]]:
    """IDA on fixed stripes: every record (m/s², sampled every h s) times every scale
    factor, the yielding shear building of ``shear_building``; per record a dict of
    ``intensity``, ``drift`` (peak storey drift, m; inf for a failed run), ``collapsed``,
    ``error``, ``collapse`` ((lo, hi) or None). The GIL released; progress(done, total)
    called from the calling thread about every 0.1 s."""

def ida_hunt_fill(
    records: List[F64],
    h: float,
    masses: F64,
    law: str,
    params: F64,
    c: F64,
    max_iterations: int = 20,
    tolerance: float = 1e-10,
    first: float = 0.1,
    step: float = 0.2,
    step_increment: float = 0.1,
    resolution: float = 0.05,
    runs: int = 12,
    collapse_drift: Optional[float] = None,
    on_failure: str = "collapse",
    threads: int = 0,
    progress: Optional[Callable[[int, int], Any]] = None,
) -> List[Dict[str, Any]]:
    """IDA traced by hunt-and-fill (Vamvatsikos & Cornell 2002), at most ``runs``
    analyses a record; the dicts of ``ida_stripes``."""

def ida_fractiles(
    intensity: List[F64],
    drift: List[F64],
    collapsed: List[npt.NDArray[np.bool_]],
    drifts: F64,
    q: F64,
) -> npt.NDArray[np.float64]:
    """Fractile IDA curves, intensity given drift: ``len(q) × len(drifts)``; NaN where
    censored curves decide the quantile."""

def spectral_acceleration(record: F64, h: float, period: float, damping: float) -> float:
    """The pseudo-spectral acceleration ``Sa = ω² max|u|`` (the record's units) of the
    oscillator of ``period`` (s) and ``damping`` (ratio) under ``record`` (sampled every
    h s), one period of free vibration after it: ``aemstep::ida::spectral_acceleration``.
    Raises ``NonFiniteInput``, ``InvalidPeriod``, ``InvalidDamping``, ``InvalidTimeStep``,
    ``NonFiniteState``, ``OperatorOverflow``. The GIL released."""
