"""``da.bearing.<name>(...)``: the analysis functions where a Jupyter user looks.

Registered as soon as a recording or a simulation can exist (``open_recording``,
:mod:`bearing_lab.sim` and :mod:`bearing_lab.analysis` import this module), so
``bl.open_recording(path).DE.bearing...`` works without importing the analysis package
first.  Registration is cheap: every method imports :mod:`bearing_lab.analysis.xr` when
called and only forwards to it (xarray's docs advise accessors over subclassing); see there
for parameters and units.

Examples
--------
>>> import numpy as np, xarray as xr
>>> import bearing_lab.sim  # registers the accessor (as do open_recording and bearing_lab.analysis)
>>> t = np.arange(2000) / 1000.0
>>> da = xr.DataArray(np.cos(2 * np.pi * 50 * t), dims="time", coords={"time": t},
...                   attrs={"units": "m s-2"})
>>> float(da.bearing.metrics()["rms"].round(4))
0.7071
"""
from __future__ import annotations

from ._xarray import xr  # xarray, dask imported only once the process uses dask

_FORWARDED = {  # accessor method -> function of bearing_lab.analysis.xr
    "amplitude_spectrum": "amplitude_spectrum", "welch_psd": "welch_psd", "bandpass": "bandpass",
    "squared_envelope": "squared_envelope", "cepstral_prewhitening": "cepstral_prewhitening",
    "squared_envelope_spectrum": "squared_envelope_spectrum",
    "envelope_spectrum": "squared_envelope_spectrum", "kurtogram_band": "kurtogram_band",
    "shaft_frequency": "shaft_frequency", "excitation_period": "excitation_period",
    "excitation_duration": "excitation_duration", "metrics": "metrics",
}


def _forward(name: str, target: str):
    def method(self, **kw):
        from .analysis import xr as _x  # analysis (scipy) loads at first use: sim and io import this module
        return getattr(_x, target)(self._da, **kw)
    method.__name__ = method.__qualname__ = name
    method.__doc__ = f":func:`bearing_lab.analysis.xr.{target}` of this DataArray (keywords as there)."
    return method


@xr.register_dataarray_accessor("bearing")
class BearingAccessor:
    """Bearing-analysis methods on a DataArray with a time dimension."""

    def __init__(self, da):
        self._da = da

    def analyze(self, *, bearing, dim="time", fs=None, **kw):
        """:func:`bearing_lab.analysis.analyze` of a 1-D DataArray (dict, see docs/analysis.md)."""
        from .analysis import xr as _x  # analysis (scipy) loads at first use: sim and io import this module
        from .analysis.pipeline import analyze  # analysis (scipy) loads at first use: sim and io import this module
        fs = _x.sampling_rate(self._da, dim=dim, fs=fs)
        return analyze(self._da.transpose(dim).values, fs, bearing=bearing,
                       channel=str(self._da.name or ""), units=self._da.attrs.get("units", "1"), **kw)


for _name, _target in _FORWARDED.items():
    setattr(BearingAccessor, _name, _forward(_name, _target))
