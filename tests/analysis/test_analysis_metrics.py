"""Metrics: definitions against scipy and closed forms."""
import numpy as np
import pytest
import scipy.stats

from bearing_lab.analysis import (clearance_factor, crest_factor, impulse_factor, kurtosis, metrics, peak,
                                  peak_to_peak, rms, shape_factor)
from bearing_lab.errors import AnalysisError


def test_kurtosis_is_pearson():
    x = np.random.default_rng(0).standard_t(5, size=50_000)
    assert kurtosis(x) == pytest.approx(scipy.stats.kurtosis(x, fisher=False), rel=1e-12)
    assert kurtosis(np.random.default_rng(1).normal(size=400_000)) == pytest.approx(3.0, abs=0.03)


def test_sinusoid_closed_forms():
    t = (np.arange(100_000) + 0.5) / 100_000
    x = 2.0 * np.sin(2 * np.pi * 10 * t)
    assert rms(x) == pytest.approx(np.sqrt(2), rel=1e-9)
    assert peak(x) == pytest.approx(2.0, rel=1e-6)
    assert peak_to_peak(x) == pytest.approx(4.0, rel=1e-6)
    assert crest_factor(x) == pytest.approx(np.sqrt(2), rel=1e-6)
    assert kurtosis(x) == pytest.approx(1.5, rel=1e-6)
    assert shape_factor(x) == pytest.approx(np.pi / (2 * np.sqrt(2)), rel=1e-6)
    assert impulse_factor(x) == pytest.approx(np.pi / 2, rel=1e-6)
    # mean(sqrt|2 sin|) = sqrt(2) * 2 Gamma(3/4) / (sqrt(pi) Gamma(5/4))
    from math import gamma, pi, sqrt
    msq = sqrt(2) * gamma(0.75) / (sqrt(pi) * gamma(1.25))
    assert clearance_factor(x) == pytest.approx(2.0 / msq ** 2, rel=1e-5)


def test_metrics_dict_matches_single_functions_and_has_units():
    x = np.random.default_rng(2).normal(size=(3, 5000))
    m = metrics(x, units="m s-2")
    for name, fn in [("rms", rms), ("peak", peak), ("peak_to_peak", peak_to_peak),
                     ("crest_factor", crest_factor), ("kurtosis", kurtosis),
                     ("impulse_factor", impulse_factor), ("clearance_factor", clearance_factor),
                     ("shape_factor", shape_factor)]:
        np.testing.assert_allclose(m[name], fn(x), rtol=1e-12)
        assert m[name].shape == (3,)
    assert m["units"]["rms"] == "m s-2" and m["units"]["kurtosis"] == "1"
    m1 = metrics(x[0])
    assert isinstance(m1["kurtosis"], float)


def test_constant_signal_is_refused():
    with pytest.raises(AnalysisError, match="zero"):
        kurtosis(np.ones(100))
    with pytest.raises(AnalysisError, match="NaN"):
        metrics(np.r_[1.0, np.nan, 2.0])


def test_metrics_table_is_read_by_every_consumer(monkeypatch):
    """A metric added to the one table appears in metrics() and the xarray wrapper with its unit
    and long name, and each entry's one-pass value equals its own function."""
    import xarray as xr

    from bearing_lab.analysis import _metrics
    from bearing_lab.analysis import xr as bxr
    x = np.random.default_rng(3).normal(0.5, 2.0, 20_000)
    m = _metrics.metrics(x, units="m s-2")
    for name, spec in _metrics.METRICS.items():
        assert m[name] == pytest.approx(float(spec.func(x)), rel=1e-12), name
    mean_abs = _metrics.Metric("mean_abs", lambda v, axis=-1: np.mean(np.abs(v), axis=axis),
                               lambda mom: mom["mean_abs"], False, "mean |x|")
    monkeypatch.setattr(_metrics, "METRICS", {**_metrics.METRICS, "mean_abs": mean_abs})
    m = _metrics.metrics(x, units="m s-2")
    assert m["mean_abs"] == pytest.approx(np.mean(np.abs(x))) and m["units"]["mean_abs"] == "m s-2"
    ds = bxr.metrics(xr.DataArray(x, dims="time", attrs={"units": "m s-2"}))
    assert float(ds["mean_abs"]) == pytest.approx(np.mean(np.abs(x)))
    assert ds["mean_abs"].attrs == {"units": "m s-2", "long_name": "mean |x|"}
    assert ds["kurtosis"].attrs["units"] == "1"
