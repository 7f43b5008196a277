"""Tachometer pulses: shaft speed, and order tracking when the speed varies.

Why: a once-per-revolution pulse (key phasor, optical tacho) measures the shaft
angle directly, which no spectral estimate can beat; and when the speed varies
during the record, every fault line smears over the speed range unless the
signal is first resampled at constant shaft *angle* (computed order tracking,
Fyfe & Munck 1997; Borghesani et al. 2013 for envelope analysis after it).

- :func:`tacho_pulses`: rising crossings of the mid level between the 1st and
  99th percentiles, with hysteresis (the signal must fall below the lower
  third of the range before the next pulse counts), each crossing interpolated
  linearly between the two samples that straddle it.
- :func:`tacho_speed`: mean shaft frequency ``(pulses - 1) / ppr / span``, the
  per-revolution speeds, and the speed variation read over 8 revolutions.
- :func:`order_track`: the shaft angle is interpolated through the pulse times
  (monotone cubic, PCHIP), the signal is resampled by a cubic spline at equal
  angle steps of ``f_mean / fs`` revolutions, so the result looks like a record
  at the constant mean speed with the original sampling rate.
"""
from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline, PchipInterpolator

from .._docdict import fill_doc
from ..errors import AnalysisError
from ._util import check_fs, check_signal

__all__ = ["tacho_pulses", "tacho_speed", "order_track", "ORDER_TRACK_VARIATION"]

#: Order tracking is applied when the per-revolution speed varies by more than this
#: (peak to peak, relative): the fifth harmonic of a fault line then moves by more than
#: half the +-2 % slip window.
ORDER_TRACK_VARIATION = 0.004
#: Revolutions over which the speed variation is read (pulse-time quantisation averages out).
SMOOTH_REVS = 8


@fill_doc
def tacho_pulses(tacho, fs):
    """Times of the pulses of a tachometer signal, s.

    Parameters
    ----------
    tacho : array_like, 1-D
        Tacho signal (any unit), pulses going up.
    %(fs)s

    Returns
    -------
    ndarray
        Pulse times, s (interpolated rising crossings of the mid level).

    Examples
    --------
    >>> import numpy as np
    >>> from bearing_lab.analysis import tacho_pulses
    >>> fs = 10000.0; t = np.arange(20000) / fs
    >>> pulses = tacho_pulses((np.sin(2 * np.pi * 25 * t) > 0.99).astype(float), fs)
    >>> len(pulses), round(float(np.diff(pulses).mean()), 4)
    (50, 0.04)
    """
    fs = check_fs(fs, func="tacho_pulses")
    t = check_signal(tacho, func="tacho_pulses", name="tacho", min_samples=16)
    if t.ndim != 1:
        raise AnalysisError(f"tacho_pulses: the tacho signal must be 1-D, got shape {t.shape}")
    lo, hi = np.percentile(t, [1, 99])
    if not hi > lo:
        lo, hi = float(t.min()), float(t.max())
    if not hi > lo:
        raise AnalysisError("tacho_pulses: the tacho signal is constant; it holds no pulses")
    mid = 0.5 * (lo + hi)
    low = lo + (hi - lo) / 3
    up = np.flatnonzero((t[:-1] < mid) & (t[1:] >= mid)) + 1
    if up.size == 0:
        return np.array([])
    below = np.flatnonzero(t < low)
    keep, last = [], -1
    for i in up:
        # armed only after the signal fell below the lower third since the last pulse
        j = np.searchsorted(below, i) - 1
        if last < 0 or (j >= 0 and below[j] > last):
            keep.append(i)
            last = i
    i = np.asarray(keep)
    frac = (mid - t[i - 1]) / (t[i] - t[i - 1])
    return (i - 1 + frac) / fs


def tacho_speed(pulse_times, *, pulses_per_rev=1):
    """Mean shaft frequency and per-revolution speeds from pulse times.

    Parameters
    ----------
    pulse_times : array_like
        Pulse times, s (at least ``pulses_per_rev + 2``).
    pulses_per_rev : int
        Pulses per shaft revolution.

    Returns
    -------
    shaft_hz : float
        Mean shaft frequency, Hz.
    per_rev_hz : ndarray
        Speed of each complete revolution, Hz.
    variation : float
        Peak-to-peak variation of the speed read over spans of ``SMOOTH_REVS``
        revolutions, relative to the mean (a sampled pulse edge is uncertain by a
        sample; over one revolution that alone can reach 0.5 %).
    """
    p = np.asarray(pulse_times, float)
    ppr = int(pulses_per_rev)
    if ppr < 1:
        raise AnalysisError(f"tacho: pulses_per_rev={pulses_per_rev!r} must be a positive integer")
    if p.size < ppr + 2:
        raise AnalysisError(f"tacho: {p.size} pulses found, at least {ppr + 2} are needed "
                            f"({pulses_per_rev} a revolution) for a speed")
    if np.any(np.diff(p) <= 0):
        raise AnalysisError("tacho: pulse times must increase")
    shaft = (p.size - 1) / ppr / (p[-1] - p[0])
    per_rev = 1.0 / (p[ppr:] - p[:-ppr])
    # the variation is read over spans of SMOOTH_REVS revolutions: a pulse time's
    # quantisation error enters two neighbouring intervals with opposite signs
    k = min(SMOOTH_REVS * ppr, p.size - 1)
    smooth = k / ppr / (p[k:] - p[:-k])
    return float(shaft), per_rev, float(np.ptp(smooth) / shaft)


@fill_doc
def order_track(x, fs, pulse_times, *, pulses_per_rev=1):
    """Resample a signal at constant shaft angle (computed order tracking).

    Parameters
    ----------
    x : array_like, 1-D
        Signal sampled at ``fs``.
    %(fs)s
    pulse_times : array_like
        Tacho pulse times, s.
    pulses_per_rev : int
        Pulses per revolution.

    Returns
    -------
    xa : ndarray
        The signal between the first and the last pulse, at equal angle steps of
        ``shaft_hz / fs`` revolutions: a record at the constant speed ``shaft_hz``
        sampled at ``fs``.
    shaft_hz : float
        Mean shaft frequency, Hz.

    References
    ----------
    .. [1] Fyfe & Munck, "Analysis of computed order tracking", MSSP 11 (1997) 187-205.
    .. [2] Borghesani, Pennacchi, Randall, Sawalhi & Ricci, MSSP 36 (2013) 370-384.
    """
    fs = check_fs(fs, func="order_track")
    x = check_signal(x, func="order_track", min_samples=16)
    p = np.asarray(pulse_times, float)
    shaft, _, _ = tacho_speed(p, pulses_per_rev=pulses_per_rev)
    revs = np.arange(p.size) / int(pulses_per_rev)
    time_of_angle = PchipInterpolator(revs, p)
    n = int(np.floor((revs[-1] - revs[0]) * fs / shaft))
    angles = revs[0] + np.arange(n) * shaft / fs
    t = time_of_angle(angles)
    t = t[t * fs <= x.size - 1]
    xa = CubicSpline(np.arange(x.size), x)(t * fs)
    return xa, float(shaft)
