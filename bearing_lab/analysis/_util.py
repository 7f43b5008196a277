"""Input checks shared by the analysis functions.

Every public analysis function validates its input here so that a bad signal
(NaN, too short, no sampling rate) raises :class:`~bearing_lab.errors.AnalysisError`
with a message naming the input and the problem, instead of returning NaN.
"""
from __future__ import annotations

import functools

import numpy as np
from scipy import signal as _sig

from ..errors import AnalysisError


def check_fs(fs, *, func: str) -> float:
    """Return ``fs`` as a positive finite float or raise AnalysisError."""
    if fs is None:
        raise AnalysisError(f"{func}: the sampling rate fs is missing (give fs in Hz)")
    try:
        fs_f = float(fs)
    except (TypeError, ValueError):
        raise AnalysisError(f"{func}: fs={fs!r} is not a number (sampling rate in Hz)") from None
    if not np.isfinite(fs_f) or fs_f <= 0:
        raise AnalysisError(f"{func}: fs={fs!r} must be a positive finite sampling rate in Hz")
    return fs_f


def check_signal(x, *, func: str, name: str = "x", min_samples: int = 16, axis: int = -1) -> np.ndarray:
    """Return ``x`` as a float64 array, or raise AnalysisError naming the problem."""
    try:
        arr = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise AnalysisError(f"{func}: {name} cannot be read as real numbers") from None
    if arr.ndim == 0:
        raise AnalysisError(f"{func}: {name} is a scalar; give a signal (1-D or N-D array)")
    try:
        n = arr.shape[axis]
    except IndexError:
        raise AnalysisError(f"{func}: axis={axis} is out of range for {name} with shape {arr.shape}") from None
    if n < min_samples:
        raise AnalysisError(f"{func}: {name} has {n} samples along axis {axis}; "
                            f"at least {min_samples} are needed")
    if not np.all(np.isfinite(arr)):
        bad = int(np.size(arr) - np.count_nonzero(np.isfinite(arr)))
        raise AnalysisError(f"{func}: {name} holds {bad} NaN or Inf values; "
                            "clean or drop them before analysis")
    return arr


def get_window(window, n: int, *, func: str) -> np.ndarray:
    """scipy.signal.get_window with a helpful error; arrays are checked for length."""
    if window is None:
        raise AnalysisError(f"{func}: window is required (e.g. 'hann' or 'boxcar'); "
                            "windows are always passed explicitly")
    if isinstance(window, (str, tuple)):
        try:
            try:
                return _named_window(window, int(n))
            except TypeError:  # unhashable parameters: made each time
                return _sig.get_window(window, n, fftbins=True).astype(np.float64)
        except ValueError as exc:
            raise AnalysisError(f"{func}: invalid window {window!r}: {exc}") from None
    w = np.asarray(window, dtype=np.float64)
    if w.shape != (n,):
        raise AnalysisError(f"{func}: window array has shape {w.shape}, expected ({n},)")
    return w


@functools.lru_cache(maxsize=2)
def _named_window(window, n):
    """A named window, made once per (name, length): the spectra of one record use the same
    window several times (16 ms each for a minute at 20 kHz).  Read-only, as it is shared."""
    w = _sig.get_window(window, n, fftbins=True).astype(np.float64)
    w.flags.writeable = False
    return w


def check_band(band, fs: float, *, func: str):
    """Return ``band`` as (lo, hi) inside (0, fs/2], or None."""
    if band is None:
        return None
    try:
        lo, hi = (float(band[0]), float(band[1]))
    except (TypeError, ValueError, IndexError):
        raise AnalysisError(f"{func}: band={band!r} must be a pair (low_hz, high_hz)") from None
    if not (0 <= lo < hi) or lo >= fs / 2:
        raise AnalysisError(f"{func}: band={band!r} must satisfy 0 <= low < high with low below "
                            f"fs/2 = {fs / 2:g} Hz")
    return lo, min(hi, fs / 2)
