"""xarray wrappers and the da.bearing accessor: vectorised over extra dims, dask-friendly, units."""
import numpy as np
import pytest
import xarray as xr

import bearing_lab.analysis as ba
from bearing_lab.analysis import xr as bxr


@pytest.fixture(scope="module")
def da():
    fs = 12000.0
    t = np.arange(60000) / fs
    fr = np.array([25.0, 30.0])
    x = np.stack([sum(np.cos(2 * np.pi * h * f * t) / h for h in range(1, 8)) for f in fr])
    x = x + np.random.default_rng(0).normal(0, 0.5, x.shape)
    return xr.DataArray(x, dims=("channel", "time"),
                        coords={"channel": ["a", "b"], "time": ("time", t, {"units": "s"})},
                        attrs={"units": "m s-2"}, name="acc")


def test_sampling_rate_from_coordinate(da):
    assert bxr.sampling_rate(da) == pytest.approx(12000.0)


def test_spectra_match_numpy_and_carry_units(da):
    a = bxr.amplitude_spectrum(da, window="hann")
    f, ref = ba.amplitude_spectrum(da.values, 12000.0, window="hann")
    np.testing.assert_allclose(a.values, ref)
    assert a.dims == ("channel", "frequency") and a.attrs["units"] == "m s-2"
    assert a.frequency.attrs["units"] == "Hz"
    ses = bxr.squared_envelope_spectrum(da, window="hann", band=(100, 1000), fmax=500)
    assert ses.attrs["units"] == "(m s-2)2" and float(ses.frequency.max()) <= 500
    p = bxr.welch_psd(da, window="hann", nperseg=4096)
    assert p.attrs["units"] == "(m s-2)2 Hz-1"


def test_shaft_frequency_vectorised_and_dask(da):
    f = bxr.shaft_frequency(da, window="boxcar")
    np.testing.assert_allclose(f.values, [25.0, 30.0], atol=2e-3)
    assert f.attrs["units"] == "Hz"
    lazy = bxr.shaft_frequency(da.chunk({"channel": 1, "time": 20000}), window="boxcar")
    assert lazy.chunks is not None
    np.testing.assert_allclose(lazy.compute().values, f.values)


def test_metrics_dataset_and_accessor(da):
    m = da.bearing.metrics()
    assert set(m.data_vars) >= {"rms", "kurtosis", "crest_factor"}
    assert m["rms"].attrs["units"] == "m s-2" and m["kurtosis"].attrs["units"] == "1"
    np.testing.assert_allclose(m["kurtosis"].values, ba.kurtosis(da.values))
    es = da.bearing.envelope_spectrum(window="hann", fmax=300)
    assert es.sizes["channel"] == 2
    band = da.isel(channel=0).bearing.kurtogram_band()
    assert band.attrs["units"] == "Hz" and band.sizes["bound"] == 2


def test_sweep_dimension_period_and_duration():
    fs = 20000.0
    t = np.arange(40000) / fs
    periods = np.array([0.01, 0.0125])
    x = np.stack([np.exp(-1500 * (t % T)) * np.sin(2 * np.pi * 3000 * (t % T)) for T in periods])
    da = xr.DataArray(x, dims=("defect", "time"), coords={"time": t}, attrs={"units": "m s-2"})
    T = da.bearing.excitation_period(frequency_range=(50, 150))
    np.testing.assert_allclose(T.values, periods, rtol=1e-5)
    assert T.attrs["units"] == "s"
    d = da.isel(time=slice(0, 200)).bearing.excitation_duration()
    assert d["duration"].attrs["units"] == "s" and d["duration"].shape == (2,)


def test_accessor_analyze_returns_contract_dict():
    fs = 12000.0
    t = np.arange(120000) / fs
    fr = 29.95
    tau = t % (1 / (3.5848 * fr))
    x = np.exp(-900 * tau) * np.sin(2 * np.pi * 3000 * tau) + np.random.default_rng(0).normal(0, 0.3, t.size)
    da = xr.DataArray(x, dims="time", coords={"time": t}, attrs={"units": "m s-2"}, name="DE")
    r = da.bearing.analyze(bearing="6205", shaft_hz=fr)
    assert r["diagnosis"] == "outer_race" and r["channel"] == "DE"


def test_envelope_wrappers(da):
    se = bxr.squared_envelope(da, band=(100, 2000))
    assert se.dims == da.dims and se.attrs["units"] == "(m s-2)2"
    bp = da.bearing.bandpass(band=(100, 2000))
    np.testing.assert_allclose(bp.values, ba.bandpass(da.values, 12000.0, band=(100, 2000)))


def test_accessor_defaults_are_scipys(da):
    import scipy.signal as ss
    x = da.sel(channel="b")
    f, ref = ss.welch(x.values, 12000.0)                # scipy's defaults: Hann, 256 samples, half overlap
    p = x.bearing.welch_psd()
    np.testing.assert_allclose(p.frequency.values, f)
    np.testing.assert_allclose(p.values, ref, rtol=1e-6, atol=1e-12 * ref.max())
    a = x.bearing.amplitude_spectrum()                  # periodogram's default: no window
    line = float(a.sel(frequency=30.0))
    assert line == pytest.approx(1.0, abs=0.02)         # the fundamental's amplitude, 1 m s-2
    assert float(x.bearing.shaft_frequency()) == pytest.approx(30.0, abs=2e-3)
