"""Pythonic data: typed IDA results, the time axis of histories, pandas/xarray output,
spectra of a DataFrame of records, IDA driven by an intensity measure (Sa(T1), PGA)
checked against a numpy exact-exponential oscillator written here, and the plot helpers
(matplotlib, Agg backend)."""

import pickle
import sys

import numpy as np
import pytest

import aemstep
from conftest import rayleigh, shear_matrices
from test_ida import building, suite


# ---------------------------------------------------------------------------------------
# A reference written here from the equations, independent of the library: the damped
# oscillator u'' + 2ζω u' + ω² u = −a_g(t), a_g linear between samples, stepped exactly
# (state-transition matrix from numpy's eigen-decomposition); Sa = ω² max|u| over the
# samples (the library's `sd` is the peak at the samples).


def _transition(w, zeta, tau):
    """Φ(τ), Γ0(τ), Γ1(τ) for x' = A x + B f, f(s) = f0 + s·slope on [0, τ]:
    x(τ) = Φ x0 + Γ0 f0 + Γ1 slope (Γ1 = (A⁻²(Φ − I) − τ A⁻¹) B)."""
    a = np.array([[0.0, 1.0], [-w * w, -2 * zeta * w]])
    b = np.array([0.0, 1.0])
    lam, vec = np.linalg.eig(a)
    phi = np.real(vec @ np.diag(np.exp(lam * tau)) @ np.linalg.inv(vec))
    ainv = np.linalg.inv(a)
    g0 = ainv @ (phi - np.eye(2)) @ b
    g1 = (ainv @ ainv @ (phi - np.eye(2)) - tau * ainv) @ b
    return phi, g0, g1


def numpy_sa(record, h, period, zeta):
    """ω² max|u| over the record and one period (⌈T/h⌉ samples) of free vibration, the
    ground acceleration back to zero over the first of them."""
    w = 2 * np.pi / period
    tail = int(np.ceil(period / h))
    f = -np.concatenate([np.asarray(record, float), np.zeros(tail)])
    phi, g0, g1 = _transition(w, zeta, h)
    x = np.zeros(2)
    peak = 0.0
    for i in range(f.shape[0] - 1):
        x = phi @ x + g0 * f[i] + g1 * (f[i + 1] - f[i]) / h
        peak = max(peak, abs(x[0]))
    return w * w * peak


#: Relative agreement with the numpy oscillator: two exact schemes differing in rounding
#: only (≈700 steps of a contracting recursion, ~1e-16 each, and the eigenvector
#: transition matrix's own rounding); measured 1.0e-14 at most (T = 0.2, 0.5, 1 s).
SA_TOL = 1e-12


def test_spectral_acceleration_equals_the_numpy_exact_oscillator(elcentro):
    ag, dt = elcentro
    rec = ag[:600]
    worst = 0.0
    for period in (0.2, 0.5, 1.0):
        ref = numpy_sa(rec, dt, period, 0.05)
        got = aemstep.spectral_acceleration(rec, dt, period, 0.05)
        worst = max(worst, abs(got - ref) / ref)
    print(f"spectral_acceleration vs numpy exact oscillator: {worst:.1e} relative")
    assert worst < SA_TOL, worst
    with pytest.raises(aemstep.NonFiniteInput):
        aemstep.spectral_acceleration(np.r_[rec[:10], np.nan], dt, 0.5, 0.05)
    with pytest.raises(aemstep.InvalidPeriod):
        aemstep.spectral_acceleration(rec, dt, -1.0, 0.05)


def test_ida_on_sa_scales_each_record_to_the_measure(elcentro):
    recs, dt = suite(elcentro)
    t1, levels = 0.6, [2.0, 5.0, 9.0]  # s; m/s² of Sa(T1, 5 %)
    curves = aemstep.ida_stripes(recs, dt, levels, collapse_drift=0.02, intensity="sa",
                                 period=t1, damping=0.05, **building())
    b = building()
    for rec, cur in zip(recs, curves):
        assert isinstance(cur, aemstep.IdaCurve) and cur.measure == "sa"
        ref = numpy_sa(rec, dt, t1, 0.05)
        assert abs(cur.record_intensity - ref) / ref < SA_TOL
        np.testing.assert_allclose(cur.scale, np.array(levels) / ref, rtol=SA_TOL)
        # The run at level x is the record scaled to Sa(T1) = x: the numpy oscillator
        # under the run's record gives back x.
        unit = rec / cur.record_intensity
        assert abs(numpy_sa(levels[1] * unit, dt, t1, 0.05) - levels[1]) / levels[1] < SA_TOL
        # and each drift is the direct shear_building run of that record, bit for bit
        for x, d in zip(levels, cur.drift):
            if np.isfinite(d):
                r = aemstep.shear_building(b["masses"], b["c"], dt, x * unit, k=1e8,
                                           fy=[6e5, 5e5, 3.5e5], alpha=0.05, energy=False)
                assert r.peak_drift == d
    # PGA: the record's own peak, and hunt-and-fill in m/s²
    hf = aemstep.ida_hunt_fill(recs, dt, collapse_drift=0.02, runs=6, intensity="pga",
                               first=1.0, step=2.0, step_increment=1.0, resolution=0.5,
                               **building())
    for rec, cur in zip(recs, hf):
        assert cur.measure == "pga" and cur.record_intensity == np.abs(rec).max()
    with pytest.raises(ValueError, match="period"):
        aemstep.ida_stripes(recs, dt, [1.0], intensity="sa", **building())
    with pytest.raises(ValueError, match="intensity"):
        aemstep.ida_stripes(recs, dt, [1.0], intensity="pgv", **building())


def test_ida_results_are_typed_and_pickle(elcentro):
    recs, dt = suite(elcentro)
    curves = aemstep.ida_stripes(recs[:1], dt, [0.5, 4.0], collapse_drift=0.02, **building())
    cur = curves[0]
    assert isinstance(cur, aemstep.IdaCurve) and cur.measure == "scale"
    assert cur.record_intensity == 1.0 and np.array_equal(cur.scale, cur.intensity)
    back = pickle.loads(pickle.dumps(cur))
    assert np.array_equal(back.drift, cur.drift) and back.collapse == cur.collapse
    f = aemstep.ida_fractiles(curves, [0.001], q=(0.5,))
    assert f.shape == (1, 1)
    with pytest.raises(TypeError, match="IdaCurve"):  # the dicts of earlier versions
        aemstep.ida_fractiles([cur._asdict()], [0.001])


# ---------------------------------------------------------------------------------------
# The time axis.


def test_every_history_has_its_time_axis(elcentro):
    ag, dt = elcentro
    ag = ag[:400]
    m, k = shear_matrices(np.full(3, 1e5), [1e8] * 3)
    c = rayleigh(m, k, 0.02)
    results = {
        "linear_response": aemstep.linear_response(m, c, k, dt, ground_acceleration=ag),
        "shear_building": aemstep.shear_building(np.full(3, 1e5), c, dt, ag, k=1e8, fy=5e5),
        "shear_building(histories=False)": aemstep.shear_building(
            np.full(3, 1e5), c, dt, ag, k=1e8, fy=5e5, histories=False),
        "mr_building": aemstep.mr_building(m, c, k, ag, dt),
        "mr_damper_response": aemstep.mr_damper_response(
            0.01 * np.sin(np.arange(400) * dt), 0.01 * np.cos(np.arange(400) * dt), 1.0, dt),
        "observe": aemstep.observe(m, c, k, dt, ag, np.zeros((400, 1)), [2], sigma_f=1e3,
                                   sigma_y=0.1),
    }
    for name, r in results.items():
        assert r.h == dt, name
        # one time a sample, row i at i·h (one multiplication: exact as written)
        assert r.time.shape == (ag.shape[0],), name
        assert np.array_equal(r.time, np.arange(ag.shape[0]) * dt), name
        first = r[0] if r[0] is not None else None
        if first is not None:
            assert first.shape[0] == r.time.shape[0], name
        back = pickle.loads(pickle.dumps(r))  # the axis survives a process pool
        assert back.h == dt and np.array_equal(back.time, r.time), name
    # tuple unpacking is unchanged
    u, v, a = results["linear_response"]
    assert u.shape == (400, 3)


# ---------------------------------------------------------------------------------------
# pandas and xarray.


def test_to_pandas_and_to_xarray(elcentro):
    pd = pytest.importorskip("pandas")
    xr = pytest.importorskip("xarray")
    ag, dt = elcentro
    m, k = shear_matrices(np.full(2, 1e5), [1e8] * 2)
    r = aemstep.linear_response(m, rayleigh(m, k, 0.02), k, dt, ground_acceleration=ag[:300])
    df = r.to_pandas()
    assert df.index.name == "time" and np.array_equal(df.index.to_numpy(), r.time)
    assert np.array_equal(df[("u", 1)].to_numpy(), r.u[:, 1])
    assert np.array_equal(df[("a", 0)].to_numpy(), r.a[:, 0])
    ds = r.to_xarray()
    assert ds["u"].dims == ("time", "dof") and np.array_equal(ds["v"].values, r.v)
    b = aemstep.shear_building(np.full(2, 1e5), rayleigh(m, k, 0.02), dt, ag[:300], k=1e8,
                               fy=5e5)
    bd = b.to_pandas()
    assert np.array_equal(bd[("energy_hysteretic", "")].to_numpy(), b.energy.hysteretic)
    assert ("peak_drifts", 0) not in bd.columns  # not a history

    periods = np.linspace(0.1, 2.0, 7)
    one = aemstep.spectrum(periods, 0.05, dt, ag[:500])
    t = one.to_pandas()
    assert list(t.columns) == ["sd", "sv", "sa", "psv", "psa"]
    assert np.array_equal(t["psa"].to_numpy(), one.psa) and t.index.name == "period"
    many = aemstep.spectra(periods, 0.05, dt, [ag[:500], ag[500:900]])
    assert np.array_equal(many.to_pandas()[("sd", 1)].to_numpy(), many.sd[1])
    assert many.to_xarray()["psa"].dims == ("record", "period")

    cd = aemstep.constant_ductility(periods, 0.05, dt, ag[:500], 4.0)
    cdt = aemstep.frames.to_pandas(cd)
    assert np.array_equal(cdt[("reduction", "")].to_numpy(), cd.reduction)
    assert np.array_equal(cdt[("bracket", 1)].to_numpy(), cd.bracket[:, 1])
    assert list(cdt[("outcome", "")]) == cd.outcome and ("passes", "") not in cdt.columns
    cdx = aemstep.frames.to_xarray(cd)
    assert cdx["bracket"].dims == ("period", "end")
    rd = aemstep.rotd(periods, 0.05, dt, ag[:500], ag[500:1000])
    assert np.array_equal(aemstep.frames.to_pandas(rd)["psa50"].to_numpy(), rd.psa50)

    recs, rdt = suite(elcentro)
    curves = aemstep.ida_stripes(recs, rdt, [0.5, 1.0], **building())
    assert aemstep.frames.to_pandas(curves).equals(aemstep.frames.ida_to_pandas(curves))
    long = aemstep.frames.ida_to_pandas(curves)
    assert len(long) == 6 and list(long["record"]) == [0, 0, 1, 1, 2, 2]
    assert np.array_equal(long["drift"].to_numpy(), np.concatenate([c.drift for c in curves]))
    assert np.array_equal(curves[0].to_pandas()["drift"].to_numpy(), curves[0].drift)
    assert isinstance(ds, xr.Dataset) and isinstance(df, pd.DataFrame)


def test_missing_optional_packages_raise_a_clear_import_error(monkeypatch, elcentro):
    ag, dt = elcentro
    s = aemstep.spectrum([0.5, 1.0], 0.05, dt, ag[:200])
    for mod, call, hint in (
        ("pandas", s.to_pandas, "pip install pandas"),
        ("xarray", s.to_xarray, "pip install xarray"),
        ("matplotlib.pyplot", lambda: aemstep.plot.spectrum(s), "pip install matplotlib"),
    ):
        with monkeypatch.context() as mp:
            mp.setitem(sys.modules, mod, None)  # import of it raises ImportError
            with pytest.raises(ImportError, match=hint):
                call()


def test_spectra_of_a_dataframe_of_records(elcentro):
    pd = pytest.importorskip("pandas")
    ag, dt = elcentro
    a, b = ag[:800], -ag[400:1200]
    periods = np.linspace(0.05, 2.0, 9)
    ref = aemstep.spectra(periods, 0.05, dt, [a, b], threads=1)
    seconds = pd.DataFrame({"ns": a, "ew": b}, index=np.arange(800) * dt)
    deltas = pd.DataFrame({"ns": a, "ew": b},
                          index=pd.to_timedelta(np.arange(800) * 20, unit="ms"))
    for df in (seconds, deltas):
        got = aemstep.spectra(periods, 0.05, records=df, threads=1)
        for q in ("sd", "sv", "sa", "psv", "psa"):
            assert np.array_equal(getattr(got, q), getattr(ref, q)), q  # bit for bit
    # an explicit h overrides the index; a ragged index is refused
    same = aemstep.spectra(periods, 0.05, dt, pd.DataFrame({"x": a}), threads=1)
    assert np.array_equal(same.psa[0], ref.psa[0])
    ragged = pd.DataFrame({"x": a[:5]}, index=[0.0, 0.02, 0.04, 0.07, 0.08])
    with pytest.raises(ValueError, match="uniformly"):
        aemstep.spectra(periods, 0.05, records=ragged)
    with pytest.raises(TypeError, match="h"):
        aemstep.spectra(periods, 0.05, None, [a])


# ---------------------------------------------------------------------------------------
# Plots (headless).


def test_plot_helpers_draw_spectra_and_ida_curves(elcentro):
    mpl = pytest.importorskip("matplotlib")
    mpl.use("Agg")
    import matplotlib.pyplot as plt

    ag, dt = elcentro
    periods = np.linspace(0.1, 2.0, 12)
    s = aemstep.spectra(periods, 0.05, dt, [ag[:600], ag[600:1200]])
    ax = aemstep.plot.spectrum(s, "psa", labels=["a", "b"])
    lines = ax.get_lines()
    assert len(lines) == 2 and np.array_equal(lines[1].get_ydata(), s.psa[1])
    assert ax.get_xlabel() == "period (s)" and "PSa" in ax.get_ylabel()
    recs, rdt = suite(elcentro)
    curves = aemstep.ida_stripes(recs, rdt, [0.25, 0.5, 1.0, 4.0], collapse_drift=0.02,
                                 **building())
    fig, ax2 = plt.subplots()
    out = aemstep.plot.ida(curves, ax=ax2, fractiles=(0.5,), drifts=[0.0, 0.005, 0.01])
    assert out is ax2 and ax2.get_ylabel() == "scale factor"
    med = ax2.get_lines()[-1]
    expected = aemstep.ida_fractiles(curves, [0.0, 0.005, 0.01], q=(0.5,))[0]
    np.testing.assert_array_equal(med.get_ydata(), expected)
    plt.close("all")
    with pytest.raises(ValueError, match="quantity"):
        aemstep.plot.spectrum(s, "pgd")
