"""Measurability floor: vibration too small for any accelerometer chain to vouch for.

Why: a model has no sensor, so a noise-free simulation shows vibration no
measurement could: the healthy model's balls enter the load zone with impacts
of about 0.2 mg rms at BPFO, which a noise-free analysis reads as an
outer-race fault.  A real measurement sees such a signal under the sensor's
own noise.  Data sheets of general-purpose IEPE accelerometers (100 mV/g) give a
broadband resolution of the order of 0.1-0.5 mg rms over 1 Hz-10 kHz, a noise
density of the order of 1-5 ug/sqrt(Hz), and the conditioning and acquisition
add their own.  The floor is set a few times above that: **1 mg rms over a
10 kHz band** (``FLOOR_MS2``), i.e. 10 ug/sqrt(Hz), scaled with the square root
of the width of the band considered (white noise): 0.32 mg in a 1 kHz
demodulation band, 1.55 mg over the 24 kHz of a 48 kHz record.  Below it, a
fault family is not evidence of a fault: the verdict is "no fault evidence".

A blind speed's plain 1x family (:mod:`._shaft`) must carry ``FLOOR_MS2`` in its
lines, a chosen threshold: machines in service vibrate more at their shaft
harmonics (ISO 10816-1 calls class I machines good up to 0.71 mm/s rms; even
0.1 mm/s at 30 Hz is 1.9 mg).

The floor is converted to the signal's unit; for a unit that is not an
acceleration (or not known) no floor applies, and the result says so.
"""
from __future__ import annotations

import numpy as np

from ..errors import BearingLabError
from ..units import lookup_unit

__all__ = ["FLOOR_MS2", "REFERENCE_BAND_HZ", "floor_in_units", "band_rms"]

#: Measurability floor of an acceleration over REFERENCE_BAND_HZ, m s-2 rms (1 mg).
FLOOR_MS2 = 0.00980665
#: Width of the band over which the floor is FLOOR_MS2, Hz.
REFERENCE_BAND_HZ = 10000.0


def floor_in_units(units, bandwidth_hz=REFERENCE_BAND_HZ):
    """The floor for a band ``bandwidth_hz`` wide, in ``units`` (1 mg over 10 kHz: 0.00980665 in
    m s-2, 0.001 in g), or None when ``units`` is not a known acceleration unit."""
    try:
        u = lookup_unit(units)
    except BearingLabError:
        return None
    if u.quantity != "acceleration" or not u.factor:
        return None
    return FLOOR_MS2 * float(np.sqrt(bandwidth_hz / REFERENCE_BAND_HZ)) / float(u.factor)


def band_rms(x, fs, band, *, spectrum=None):
    """rms of x in the band (low, high) Hz (Parseval on the one-sided DFT); whole signal
    (mean removed) when band is None.  ``spectrum``: ``rfft(x - x.mean())`` when known."""
    x = np.asarray(x, float)
    X = np.fft.rfft(x - x.mean()) if spectrum is None else spectrum
    f = np.fft.rfftfreq(x.size, 1.0 / fs)
    w = np.ones(f.size) * 2.0
    w[0] = 1.0
    if x.size % 2 == 0:
        w[-1] = 1.0
    if band is not None:
        w = np.where((f >= band[0]) & (f <= band[1]), w, 0.0)
    return float(np.sqrt(np.sum(w * np.abs(X) ** 2)) / x.size)
