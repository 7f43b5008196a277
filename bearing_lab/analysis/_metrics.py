"""Condition-indicator metrics of a vibration signal.

Why here: the simulator's studies and the recordings are compared through
these numbers, so their definitions are fixed in one place:

- ``rms = sqrt(mean(x**2))`` (about zero, the mean is *not* removed: remove it
  first if the signal has an offset), ``peak = max|x|``,
  ``peak_to_peak = max x - min x``;
- ``crest_factor = peak / rms``; ``impulse_factor = peak / mean|x|``;
  ``clearance_factor = peak / mean(sqrt|x|)**2``; ``shape_factor = rms / mean|x|``;
- ``kurtosis``: Pearson's, ``mean((x - mean)**4) / var**2`` (Gaussian = 3), i.e.
  ``scipy.stats.kurtosis(x, fisher=False)``.

Units: rms, peak and peak_to_peak carry the signal's unit; the others are 1.
Peaks are sampled peaks: the sampled peak of a short pulse can read 10-40 % below the
continuous one, so compare peaks of signals sampled the same way.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import AnalysisError
from ._util import check_signal

__all__ = ["rms", "peak", "peak_to_peak", "crest_factor", "kurtosis", "impulse_factor",
           "clearance_factor", "shape_factor", "metrics", "METRICS", "METRIC_NAMES", "Metric"]
# METRICS, the table of metrics (one entry each), follows the functions below.


def _x(x, func, axis):
    return check_signal(x, func=func, min_samples=2, axis=axis)


def _nonzero(v, func, what):
    if np.any(v == 0):
        raise AnalysisError(f"{func}: {what} is zero (constant or all-zero signal); the ratio is undefined")
    return v


def rms(x, *, axis=-1):
    """Root mean square, in the unit of x.

    Examples
    --------
    >>> import numpy as np
    >>> from bearing_lab.analysis import rms
    >>> round(float(rms(np.sin(2 * np.pi * np.arange(1000) / 100))), 6)
    0.707107
    """
    x = _x(x, "rms", axis)
    return np.sqrt(np.mean(x * x, axis=axis))


def peak(x, *, axis=-1):
    """Largest absolute sample, in the unit of x (a sampled peak).

    Examples
    --------
    >>> from bearing_lab.analysis import peak
    >>> float(peak([1.0, -3.0, 2.0]))
    3.0
    """
    return np.max(np.abs(_x(x, "peak", axis)), axis=axis)


def peak_to_peak(x, *, axis=-1):
    """``max(x) - min(x)``, in the unit of x.

    Examples
    --------
    >>> from bearing_lab.analysis import peak_to_peak
    >>> float(peak_to_peak([1.0, -3.0, 2.0]))
    5.0
    """
    return np.ptp(_x(x, "peak_to_peak", axis), axis=axis)


def crest_factor(x, *, axis=-1):
    """``peak / rms`` (dimensionless); sqrt(2) for a sinusoid.

    Examples
    --------
    >>> import numpy as np
    >>> from bearing_lab.analysis import crest_factor
    >>> round(float(crest_factor(np.sin(2 * np.pi * np.arange(1000) / 100 + 0.5 * np.pi))), 4)
    1.4142
    """
    x = _x(x, "crest_factor", axis)
    return np.max(np.abs(x), axis=axis) / _nonzero(np.sqrt(np.mean(x * x, axis=axis)), "crest_factor", "rms")


def kurtosis(x, *, axis=-1):
    """Pearson kurtosis ``m4 / m2**2`` (Gaussian = 3, sinusoid = 1.5).

    References
    ----------
    .. [1] ``scipy.stats.kurtosis(x, fisher=False, bias=True)``, which this equals.

    Examples
    --------
    >>> import numpy as np
    >>> from bearing_lab.analysis import kurtosis
    >>> round(float(kurtosis(np.random.default_rng(0).normal(size=1_000_000))), 1)
    3.0
    """
    x = _x(x, "kurtosis", axis)
    d = x - x.mean(axis=axis, keepdims=True)
    d2 = d * d
    m2 = np.mean(d2, axis=axis)
    return np.mean(d2 * d2, axis=axis) / _nonzero(m2, "kurtosis", "the variance") ** 2


def impulse_factor(x, *, axis=-1):
    """``peak / mean|x|`` (dimensionless).

    Examples
    --------
    >>> from bearing_lab.analysis import impulse_factor
    >>> float(impulse_factor([1.0, -1.0, 4.0, 2.0]))
    2.0
    """
    x = _x(x, "impulse_factor", axis)
    a = np.abs(x)
    return np.max(a, axis=axis) / _nonzero(np.mean(a, axis=axis), "impulse_factor", "mean |x|")


def clearance_factor(x, *, axis=-1):
    """``peak / mean(sqrt|x|)**2`` (dimensionless).

    Examples
    --------
    >>> from bearing_lab.analysis import clearance_factor
    >>> float(clearance_factor([1.0, 1.0, 4.0, 4.0]))
    1.7777777777777777
    """
    x = _x(x, "clearance_factor", axis)
    a = np.abs(x)
    return np.max(a, axis=axis) / _nonzero(np.mean(np.sqrt(a), axis=axis), "clearance_factor",
                                           "mean sqrt|x|") ** 2


def shape_factor(x, *, axis=-1):
    """``rms / mean|x|`` (dimensionless); pi/(2 sqrt 2) = 1.1107 for a sinusoid.

    Examples
    --------
    >>> import numpy as np
    >>> from bearing_lab.analysis import shape_factor
    >>> round(float(shape_factor(np.sin(2 * np.pi * (np.arange(1000) + 0.5) / 100))), 3)
    1.111
    """
    x = _x(x, "shape_factor", axis)
    a = np.abs(x)
    return np.sqrt(np.mean(x * x, axis=axis)) / _nonzero(np.mean(a, axis=axis), "shape_factor", "mean |x|")


def metrics(x, *, axis=-1, units="1"):
    """All the metrics of :data:`METRICS` at once (one pass over the data).

    Parameters
    ----------
    x : array_like
        Signal.
    axis : int
        Time axis (reduced).
    units : str
        Unit of x; reported for rms, peak and peak_to_peak.

    Returns
    -------
    dict
        ``rms, peak, peak_to_peak, crest_factor, kurtosis, impulse_factor,
        clearance_factor, shape_factor`` (floats for 1-D input, arrays
        otherwise) and ``units``: a dict name -> unit string.

    Examples
    --------
    >>> import numpy as np
    >>> from bearing_lab.analysis import metrics
    >>> m = metrics(np.random.default_rng(0).normal(0, 2.0, 1_000_000), units="m s-2")
    >>> round(float(m["rms"]), 2), round(float(m["kurtosis"]), 1), m["units"]["rms"]
    (2.0, 3.0, 'm s-2')
    """
    x = _x(x, "metrics", axis)
    hi, lo = np.max(x, axis=axis), np.min(x, axis=axis)
    a = np.abs(x)
    d = x - x.mean(axis=axis, keepdims=True)
    d2 = np.multiply(d, d, out=d)  # d**4 as (d*d)**2: numpy's general power costs 50 ms per million samples
    mom = {"rms": np.sqrt(np.mean(x * x, axis=axis)), "peak": np.maximum(hi, -lo),  # max |x|
           "ptp": hi - lo, "mean_abs": np.mean(a, axis=axis)}
    mom["mean_sqrt_abs"] = np.mean(np.sqrt(a, out=a), axis=axis)
    mom["var"] = np.mean(d2, axis=axis)
    mom["m4"] = np.mean(np.multiply(d2, d2, out=d2), axis=axis)
    for k, what in (("rms", "rms"), ("mean_abs", "mean |x|"), ("var", "the variance")):
        _nonzero(mom[k], "metrics", what)
    out = {name: m.from_moments(mom) for name, m in METRICS.items()}
    if x.ndim == 1:
        out = {k: float(v) for k, v in out.items()}
    out["units"] = {k: metric_units(k, units) for k in METRICS}
    return out


def metric_units(name: str, signal_units: str) -> str:
    """The unit of metric ``name`` of a signal in ``signal_units`` ("1" for the ratios)."""
    return "1" if METRICS[name].dimensionless else signal_units


@dataclass(frozen=True)
class Metric:
    """One metric: its function, its value from the one-pass moments of :func:`metrics`
    (keys ``rms``, ``peak``, ``ptp``, ``mean_abs``, ``mean_sqrt_abs``, ``var``, ``m4``: the
    central moments along the time axis), whether it is a ratio (unit 1) and its long name."""

    name: str
    func: Callable
    from_moments: Callable[[dict], np.ndarray]
    dimensionless: bool
    long_name: str


#: name -> Metric, in report order.  Adding a metric: its function above, one entry here, its
#: test in tests/analysis/test_analysis_metrics.py; ``metrics()``, the xarray wrapper, the
#: accessor, ``analyze``'s JSON and sweeps read this table.
METRICS: dict[str, Metric] = {m.name: m for m in [
    Metric("rms", rms, lambda m: m["rms"], False, "RMS"),
    Metric("peak", peak, lambda m: m["peak"], False, "peak (largest |x|)"),
    Metric("peak_to_peak", peak_to_peak, lambda m: m["ptp"], False, "peak to peak"),
    Metric("crest_factor", crest_factor, lambda m: m["peak"] / m["rms"], True, "crest factor (peak / RMS)"),
    Metric("kurtosis", kurtosis, lambda m: m["m4"] / m["var"] ** 2, True, "Pearson kurtosis (Gaussian = 3)"),
    Metric("impulse_factor", impulse_factor, lambda m: m["peak"] / m["mean_abs"], True,
           "impulse factor (peak / mean |x|)"),
    Metric("clearance_factor", clearance_factor, lambda m: m["peak"] / m["mean_sqrt_abs"] ** 2, True,
           "clearance factor (peak / mean(sqrt|x|)^2)"),
    Metric("shape_factor", shape_factor, lambda m: m["rms"] / m["mean_abs"], True, "shape factor (RMS / mean |x|)"),
]}
METRIC_NAMES = tuple(METRICS)
