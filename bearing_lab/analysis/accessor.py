"""``da.bearing.<name>(...)``: the analysis functions where a Jupyter user looks.

Registered when :mod:`bearing_lab.analysis` is imported.  Every method only
forwards to :mod:`bearing_lab.analysis.xr` (xarray's docs advise accessors over
subclassing); see there for parameters and units.

Examples
--------
>>> import numpy as np, xarray as xr
>>> import bearing_lab.analysis  # registers the accessor
>>> t = np.arange(2000) / 1000.0
>>> da = xr.DataArray(np.cos(2 * np.pi * 50 * t), dims="time", coords={"time": t},
...                   attrs={"units": "m s-2"})
>>> float(da.bearing.metrics()["rms"].round(4))
0.7071
"""
from __future__ import annotations

import xarray as xr

from . import xr as _x


@xr.register_dataarray_accessor("bearing")
class BearingAccessor:
    """Bearing-analysis methods on a DataArray with a time dimension."""

    def __init__(self, da):
        self._da = da

    def amplitude_spectrum(self, **kw):
        return _x.amplitude_spectrum(self._da, **kw)

    def welch_psd(self, **kw):
        return _x.welch_psd(self._da, **kw)

    def bandpass(self, **kw):
        return _x.bandpass(self._da, **kw)

    def squared_envelope(self, **kw):
        return _x.squared_envelope(self._da, **kw)

    def cepstral_prewhitening(self, **kw):
        return _x.cepstral_prewhitening(self._da, **kw)

    def squared_envelope_spectrum(self, **kw):
        return _x.squared_envelope_spectrum(self._da, **kw)

    def envelope_spectrum(self, **kw):
        return _x.squared_envelope_spectrum(self._da, **kw)

    def kurtogram_band(self, **kw):
        return _x.kurtogram_band(self._da, **kw)

    def shaft_frequency(self, **kw):
        return _x.shaft_frequency(self._da, **kw)

    def excitation_period(self, **kw):
        return _x.excitation_period(self._da, **kw)

    def excitation_duration(self, **kw):
        return _x.excitation_duration(self._da, **kw)

    def metrics(self, **kw):
        return _x.metrics(self._da, **kw)

    def analyze(self, *, bearing, dim="time", fs=None, **kw):
        """:func:`bearing_lab.analysis.analyze` of a 1-D DataArray (dict, see docs/analysis.md)."""
        from .pipeline import analyze
        fs = _x.sampling_rate(self._da, dim=dim, fs=fs)
        return analyze(self._da.transpose(dim).values, fs, bearing=bearing,
                       channel=str(self._da.name or ""), units=self._da.attrs.get("units", "1"), **kw)
