"""Measurability floor: vibration too small for any accelerometer chain to vouch for.

Why: a model has no sensor, so a noise-free simulation shows vibration no
measurement could: the healthy model's balls enter the load zone with impacts
of about 0.2 mg rms at BPFO, which a noise-free analysis reads as an
outer-race fault.  A real measurement sees such a signal under the sensor's
own noise.  General-purpose IEPE accelerometers (100 mV/g) have a broadband
residual noise of about 0.1-0.5 mg rms over 1 Hz-10 kHz, and the chain
(signal conditioner, 16-bit or 24-bit acquisition on a +-5 V range) adds its own;
vibration of a machine in service stands well above 1 mg.  Below
``FLOOR_MS2`` (1 mg = 0.00980665 m s-2 rms) in the demodulation band, a fault
family is not evidence of a fault: the verdict is "no fault evidence".

The floor is converted to the signal's unit; for a unit that is not an
acceleration (or not known) no floor applies, and the result says so.
"""
from __future__ import annotations

import numpy as np

from ..errors import BearingLabError
from ..units import lookup_unit

__all__ = ["FLOOR_MS2", "floor_in_units", "band_rms"]

#: Measurability floor of an acceleration, m s-2 rms (1 mg).
FLOOR_MS2 = 0.00980665


def floor_in_units(units):
    """The 1 mg floor in ``units`` (e.g. 0.00980665 for m s-2, 0.001 for g), or None when
    ``units`` is not a known acceleration unit."""
    try:
        u = lookup_unit(units)
    except BearingLabError:
        return None
    if u.quantity != "acceleration" or not u.factor:
        return None
    return FLOOR_MS2 / float(u.factor)


def band_rms(x, fs, band):
    """rms of x in the band (low, high) Hz (Parseval on the one-sided DFT); whole signal
    (mean removed) when band is None."""
    x = np.asarray(x, float)
    X = np.fft.rfft(x - x.mean())
    f = np.fft.rfftfreq(x.size, 1.0 / fs)
    w = np.ones(f.size) * 2.0
    w[0] = 1.0
    if x.size % 2 == 0:
        w[-1] = 1.0
    if band is not None:
        w = np.where((f >= band[0]) & (f <= band[1]), w, 0.0)
    return float(np.sqrt(np.sum(w * np.abs(X) ** 2)) / x.size)
