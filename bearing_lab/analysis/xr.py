"""xarray wrappers of the analysis functions (same names, one ``apply_ufunc`` each).

Why: a simulation sweep or a multi-channel recording is a DataArray with extra
dimensions (channel, speed, defect size, ...).  Each wrapper maps the numpy
function over every dimension except ``dim`` (default ``"time"``), works on
dask arrays (``dask="parallelized"``; the time dimension is gathered into one
chunk), and returns DataArrays with ``units`` attributes.

The sampling rate is taken from ``da.attrs["sampling_rate_hz"]`` when present,
otherwise from the spacing of the ``dim`` coordinate (a DataArray taken from a
Dataset does not carry the Dataset's global attributes); ``fs=`` overrides both.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from ..errors import AnalysisError
from . import _impulse, _metrics, _spectral, _speed

__all__ = ["amplitude_spectrum", "welch_psd", "bandpass", "squared_envelope", "squared_envelope_spectrum",
           "envelope_spectrum",
           "cepstral_prewhitening", "kurtogram_band", "shaft_frequency", "excitation_period",
           "excitation_duration", "metrics", "sampling_rate"]


def sampling_rate(da, *, dim="time", fs=None):
    """Sampling rate of ``da`` along ``dim``, Hz (attrs, then coordinate spacing)."""
    if fs is not None:
        return float(fs)
    if "sampling_rate_hz" in da.attrs:
        return float(da.attrs["sampling_rate_hz"])
    if dim in da.coords and da.sizes[dim] > 1:
        t = np.asarray(da[dim].values, dtype=float)
        dt = (t[-1] - t[0]) / (t.size - 1)
        if dt > 0:
            # 9 significant digits: t = arange(n) / fs gives back fs exactly
            return float(f"{1.0 / dt:.9g}")
    name = da.name or "the DataArray"
    raise AnalysisError(f"{name}: no sampling rate (no attrs['sampling_rate_hz'] and no uniform "
                        f"{dim!r} coordinate); pass fs=")


def _units(da):
    return da.attrs.get("units", "1")


def _kw(out_sizes=None):
    kw = {"allow_rechunk": True}
    if out_sizes:
        kw["output_sizes"] = out_sizes
    return kw


def amplitude_spectrum(da, *, window="boxcar", dim="time", fs=None):
    """:func:`bearing_lab.analysis.amplitude_spectrum` over ``dim``; new dim ``frequency`` (Hz).

    ``window`` defaults to ``"boxcar"`` (no window), as :func:`scipy.signal.periodogram` does."""
    fs = sampling_rate(da, dim=dim, fs=fs)
    n = da.sizes[dim]
    f = np.fft.rfftfreq(n, 1 / fs)
    out = xr.apply_ufunc(lambda x: _spectral.amplitude_spectrum(x, fs, window=window)[1], da,
                         input_core_dims=[[dim]], output_core_dims=[["frequency"]], dask="parallelized",
                         output_dtypes=[float], dask_gufunc_kwargs=_kw({"frequency": f.size}))
    out = out.assign_coords(frequency=("frequency", f, {"units": "Hz"}))
    out.attrs = {"units": _units(da), "long_name": "amplitude spectrum (peak)", "window": str(window)}
    return out


def welch_psd(da, *, window="hann", nperseg=None, noverlap=None, dim="time", fs=None):
    """:func:`bearing_lab.analysis.welch_psd` over ``dim``; units (U)^2 Hz-1.

    Defaults as :func:`scipy.signal.welch`: ``window="hann"``, ``nperseg`` 256 samples (the record
    when shorter), ``noverlap`` half a segment."""
    fs = sampling_rate(da, dim=dim, fs=fs)
    nperseg = min(256, da.sizes[dim]) if nperseg is None else nperseg
    f = np.fft.rfftfreq(int(nperseg), 1 / fs)
    out = xr.apply_ufunc(lambda x: _spectral.welch_psd(x, fs, window=window, nperseg=nperseg,
                                                       noverlap=noverlap)[1], da,
                         input_core_dims=[[dim]], output_core_dims=[["frequency"]], dask="parallelized",
                         output_dtypes=[float], dask_gufunc_kwargs=_kw({"frequency": f.size}))
    out = out.assign_coords(frequency=("frequency", f, {"units": "Hz"}))
    out.attrs = {"units": f"({_units(da)})2 Hz-1", "long_name": "power spectral density (Welch)"}
    return out


def bandpass(da, *, band, dim="time", fs=None):
    """:func:`bearing_lab.analysis.bandpass` over ``dim`` (same units)."""
    fs = sampling_rate(da, dim=dim, fs=fs)
    out = xr.apply_ufunc(lambda x: _spectral.bandpass(x, fs, band=band), da, input_core_dims=[[dim]],
                         output_core_dims=[[dim]], dask="parallelized", output_dtypes=[float],
                         dask_gufunc_kwargs=_kw())
    out.attrs = {"units": _units(da), "long_name": f"band-passed {band[0]:g}-{band[1]:g} Hz"}
    return out


def squared_envelope(da, *, band=None, prewhiten=False, dim="time", fs=None):
    """:func:`bearing_lab.analysis.squared_envelope` over ``dim``; units (U)2."""
    fs = sampling_rate(da, dim=dim, fs=fs)
    out = xr.apply_ufunc(lambda x: _spectral.squared_envelope(x, fs, band=band, prewhiten=prewhiten), da,
                         input_core_dims=[[dim]], output_core_dims=[[dim]], dask="parallelized",
                         output_dtypes=[float], dask_gufunc_kwargs=_kw())
    out.attrs = {"units": "1" if prewhiten else f"({_units(da)})2", "long_name": "squared envelope"}
    return out


def cepstral_prewhitening(da, *, dim="time"):
    """:func:`bearing_lab.analysis.cepstral_prewhitening` over ``dim`` (dimensionless result)."""
    out = xr.apply_ufunc(_spectral.cepstral_prewhitening, da, input_core_dims=[[dim]],
                         output_core_dims=[[dim]], dask="parallelized", output_dtypes=[float],
                         dask_gufunc_kwargs=_kw())
    out.attrs = {"units": "1", "long_name": "cepstrum pre-whitened signal"}
    return out


def squared_envelope_spectrum(da, *, window, band=None, prewhiten=False, fmax=None, dim="time", fs=None):
    """:func:`bearing_lab.analysis.squared_envelope_spectrum` over ``dim``; dim ``frequency``."""
    fs = sampling_rate(da, dim=dim, fs=fs)
    f = np.fft.rfftfreq(da.sizes[dim], 1 / fs)
    if fmax is not None:
        f = f[f <= float(fmax)]
    out = xr.apply_ufunc(lambda x: _spectral.squared_envelope_spectrum(
        x, fs, window=window, band=band, prewhiten=prewhiten, fmax=fmax)[1], da,
        input_core_dims=[[dim]], output_core_dims=[["frequency"]], dask="parallelized",
        output_dtypes=[float], dask_gufunc_kwargs=_kw({"frequency": f.size}))
    out = out.assign_coords(frequency=("frequency", f, {"units": "Hz",
                                                        "long_name": "cyclic frequency"}))
    out.attrs = {"units": "1" if prewhiten else f"({_units(da)})2",
                 "long_name": "squared envelope spectrum",
                 "band_hz": "full" if band is None else f"{band[0]:g}-{band[1]:g}"}
    return out


envelope_spectrum = squared_envelope_spectrum


def kurtogram_band(da, *, dim="time", fs=None, nlevel=None, min_bandwidth=None):
    """Best band of :func:`bearing_lab.analysis.fast_kurtogram` per signal.

    Returns a DataArray with a ``bound`` dimension (``low``, ``high``; Hz).
    """
    fs = sampling_rate(da, dim=dim, fs=fs)
    out = xr.apply_ufunc(lambda x: np.asarray(_spectral.fast_kurtogram(
        x, fs, nlevel=nlevel, min_bandwidth=min_bandwidth).band), da,
        input_core_dims=[[dim]], output_core_dims=[["bound"]], vectorize=True, dask="parallelized",
        output_dtypes=[float], dask_gufunc_kwargs=_kw({"bound": 2}))
    out = out.assign_coords(bound=["low", "high"])
    out.attrs = {"units": "Hz", "long_name": "demodulation band of largest spectral kurtosis"}
    return out


def shaft_frequency(da, *, window="hann", rpm=None, dim="time", fs=None, **kwargs):
    """:func:`bearing_lab.analysis.shaft_frequency` per signal (Hz); ``window`` defaults to ``"hann"``, the
    window :func:`bearing_lab.analysis.analyze` searches the shaft line with (it leaks less next to mains
    lines)."""
    fs = sampling_rate(da, dim=dim, fs=fs)
    out = xr.apply_ufunc(lambda x: _speed.shaft_frequency(x, fs, window=window, rpm=rpm, **kwargs)[0],
                         da, input_core_dims=[[dim]], vectorize=True, dask="parallelized",
                         output_dtypes=[float], dask_gufunc_kwargs=_kw())
    out.attrs = {"units": "Hz", "long_name": "shaft frequency"}
    return out


def excitation_period(da, *, frequency_range, band=None, method="ses", dim="time", fs=None):
    """:func:`bearing_lab.analysis.excitation_period` per signal (s)."""
    fs = sampling_rate(da, dim=dim, fs=fs)
    out = xr.apply_ufunc(lambda x: _impulse.excitation_period(
        x, fs, frequency_range=frequency_range, band=band, method=method)[0], da,
        input_core_dims=[[dim]], vectorize=True, dask="parallelized", output_dtypes=[float],
        dask_gufunc_kwargs=_kw())
    out.attrs = {"units": "s", "long_name": "excitation period"}
    return out


def excitation_duration(da, *, level=0.1, baseline="median", dim="time", fs=None):
    """:func:`bearing_lab.analysis.excitation_duration` per signal: Dataset of duration, entry, exit (s)."""
    fs = sampling_rate(da, dim=dim, fs=fs)
    d, t0, t1 = xr.apply_ufunc(lambda x: _impulse.excitation_duration(x, fs, level=level, baseline=baseline), da,
                               input_core_dims=[[dim]], output_core_dims=[[], [], []],
                               dask="parallelized", output_dtypes=[float, float, float],
                               dask_gufunc_kwargs=_kw())
    ds = xr.Dataset({"duration": d, "entry": t0, "exit": t1})
    for k in ds.data_vars:
        ds[k].attrs = {"units": "s"}
    ds.attrs["level"] = level
    return ds


def metrics(da, *, dim="time"):
    """The :func:`bearing_lab.analysis.metrics` as a Dataset (units and long names in attrs)."""
    names = tuple(_metrics.METRICS)
    res = xr.apply_ufunc(lambda x: (lambda m: tuple(np.asarray(m[k]) for k in names))(_metrics.metrics(x)), da,
                         input_core_dims=[[dim]], output_core_dims=[[] for _ in names],
                         dask="parallelized", output_dtypes=[float] * len(names),
                         dask_gufunc_kwargs=_kw())
    ds = xr.Dataset(dict(zip(names, res)))
    for k in names:
        ds[k].attrs.update(units=_metrics.metric_units(k, _units(da)), long_name=_metrics.METRICS[k].long_name)
    return ds
