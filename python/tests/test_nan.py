"""Issue 34: one policy for NaN/inf samples in records. The spectra (``spectrum``,
``spectra``, ``rotd``, ``constant_strength``, ``constant_ductility`` and their
``aemstep.distributed`` twins) raise ``NonFiniteInput`` with ``.step`` by default, as
``linear_response`` and ``shear_building`` do; ``nan="skip"`` holds the last finite sample
in place of each non-finite one (``0`` before any) and counts them in ``skipped``.

The reference for skipping is written here: the record with every non-finite sample
replaced by the last finite one before it (``held``), run under the default policy."""

import numpy as np
import pytest

import aemstep

PERIODS = np.geomspace(0.1, 3.0, 20)  # two banks of 16


def held(rec):
    """Each non-finite sample replaced by the last finite one before it (0 before any)."""
    out = np.array(rec, dtype=float)
    last = 0.0
    for i, a in enumerate(out):
        if np.isfinite(a):
            last = a
        else:
            out[i] = last
    return out


@pytest.fixture
def half_nan(elcentro):
    """El Centro with every other sample NaN from sample 7 on (half the record), an inf
    and a -inf among them; its first non-finite sample is 7."""
    ag, dt = elcentro
    rec = ag[:1500].copy()
    rec[7::2] = np.nan
    rec[101] = np.inf
    rec[203] = -np.inf
    return rec, dt


def nonfinite_count(rec):
    return int(np.count_nonzero(~np.isfinite(rec)))


def test_half_nan_record_raises_by_default_with_the_step(half_nan):
    rec, dt = half_nan
    calls = [
        lambda: aemstep.spectrum(PERIODS, 0.05, dt, rec),
        lambda: aemstep.spectra(PERIODS, 0.05, dt, [rec]),
        lambda: aemstep.rotd(PERIODS, 0.05, dt, rec, rec),
        lambda: aemstep.constant_strength(PERIODS, 0.05, dt, rec, 4.0),
        lambda: aemstep.constant_ductility(PERIODS, 0.05, dt, rec, 4.0),
    ]
    for call in calls:
        with pytest.raises(aemstep.NonFiniteInput) as e:
            call()
        assert e.value.step == 7
        assert isinstance(e.value, aemstep.AemstepError)


def test_spectra_name_the_record_and_the_sample(elcentro):
    ag, dt = elcentro
    bad = ag[:800].copy()
    bad[321] = np.nan
    with pytest.raises(aemstep.NonFiniteInput) as e:
        aemstep.spectra(PERIODS, 0.05, dt, [ag[:800], ag[:500], bad])
    assert (e.value.record, e.value.step) == (2, 321)
    # in batches (with progress), the index is still the record's in ``records``
    with pytest.raises(aemstep.NonFiniteInput) as e:
        aemstep.spectra(PERIODS, 0.05, dt, [ag[:300]] * 9 + [bad], threads=1,
                        progress=lambda done, total: None)
    assert (e.value.record, e.value.step) == (9, 321)
    with pytest.raises(aemstep.NonFiniteInput) as e:
        aemstep.rotd(PERIODS, 0.05, dt, ag[:800], bad)
    assert (e.value.record, e.value.step) == (1, 321)


def test_all_nan_record_raises(elcentro):
    _, dt = elcentro
    rec = np.full(200, np.nan)
    for call in [
        lambda: aemstep.spectrum(PERIODS, 0.05, dt, rec),
        lambda: aemstep.rotd(PERIODS, 0.05, dt, rec, rec),
        lambda: aemstep.constant_strength(PERIODS, 0.05, dt, rec, 4.0),
        lambda: aemstep.constant_ductility(PERIODS, 0.05, dt, rec, 4.0),
    ]:
        with pytest.raises(aemstep.NonFiniteInput) as e:
            call()
        assert e.value.step == 0
    # skipped, it is a record at rest: every sample counted, all zeros
    s = aemstep.spectrum(PERIODS, 0.05, dt, rec, nan="skip")
    assert s.skipped == 200 and not s.sd.any()


def test_skip_equals_the_held_record_and_counts(half_nan):
    rec, dt = half_nan
    ref = held(rec)
    n = nonfinite_count(rec)
    assert n == (1500 - 7 + 1) // 2

    s = aemstep.spectrum(PERIODS, 0.05, dt, rec, nan="skip")
    r = aemstep.spectrum(PERIODS, 0.05, dt, ref)
    assert s.skipped == n and r.skipped == 0
    for a, b in zip(s[:6], r[:6]):
        np.testing.assert_array_equal(a, b)

    many = aemstep.spectra(PERIODS, 0.05, dt, [ref, rec, rec[:100]], nan="skip", threads=2)
    np.testing.assert_array_equal(many.skipped, [0, n, nonfinite_count(rec[:100])])
    np.testing.assert_array_equal(many.sd[1], r.sd)

    rd = aemstep.rotd(PERIODS, 0.05, dt, rec, ref, nan="skip")
    rd_ref = aemstep.rotd(PERIODS, 0.05, dt, ref, ref)
    assert rd.skipped == (n, 0) and rd_ref.skipped == (0, 0)
    np.testing.assert_array_equal(rd.rotd50, rd_ref.rotd50)
    np.testing.assert_array_equal(rd.psa100, rd_ref.psa100)

    cs = aemstep.constant_strength(PERIODS, 0.05, dt, rec, 4.0, nan="skip")
    cs_ref = aemstep.constant_strength(PERIODS, 0.05, dt, ref, 4.0)
    assert (cs.skipped, cs_ref.skipped) == (n, 0)
    np.testing.assert_array_equal(cs.ductility, cs_ref.ductility)

    cd = aemstep.constant_ductility(PERIODS, 0.05, dt, rec, 2.0, nan="skip", tol=1e-4)
    cd_ref = aemstep.constant_ductility(PERIODS, 0.05, dt, ref, 2.0, tol=1e-4)
    assert (cd.skipped, cd_ref.skipped) == (n, 0)
    np.testing.assert_array_equal(cd.yield_acceleration, cd_ref.yield_acceleration)


def test_unknown_policy_is_a_value_error(elcentro):
    ag, dt = elcentro
    with pytest.raises(ValueError, match="raise.*skip"):
        aemstep.spectrum(PERIODS, 0.05, dt, ag, nan="ignore")


def test_finite_records_are_unchanged_by_the_policy(elcentro):
    ag, dt = elcentro
    a = aemstep.spectrum(PERIODS, 0.05, dt, ag)
    b = aemstep.spectrum(PERIODS, 0.05, dt, ag, nan="skip")
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)
    assert a.skipped == b.skipped == 0


def test_distributed_twins_pass_the_policy(half_nan):
    pytest.importorskip("distributed")
    from distributed import Client, LocalCluster

    import aemstep.distributed as ad

    rec, dt = half_nan
    ref = held(rec)
    n = nonfinite_count(rec)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False) as cluster, Client(
        cluster
    ) as client:
        with pytest.raises(aemstep.NonFiniteInput) as e:
            ad.spectra(client, PERIODS, 0.05, dt, [ref, rec])
        assert e.value.step == 7
        s = ad.spectra(client, PERIODS, 0.05, dt, [ref, rec], nan="skip")
        np.testing.assert_array_equal(s.skipped, [0, n])
        np.testing.assert_array_equal(s.sd[0], s.sd[1])
        with pytest.raises(aemstep.NonFiniteInput):
            ad.constant_strength(client, PERIODS, 0.05, dt, [rec], 4.0)
        (cs,) = ad.constant_strength(client, PERIODS, 0.05, dt, [rec], 4.0, nan="skip")
        assert cs.skipped == n
        (cd,) = ad.constant_ductility(client, PERIODS, 0.05, dt, [rec], 2.0, nan="skip",
                                      tol=1e-3)
        assert cd.skipped == n
