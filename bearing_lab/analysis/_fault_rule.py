"""The fault-line rule's thresholds and its shaft-harmonic mask, shared by the one-line search
(:mod:`._faults`, where the reasons for each threshold are written) and the family search
(:mod:`._families`); they sit below both so that neither imports the other's module for them."""
from __future__ import annotations

import numpy as np

__all__ = ["FUNDAMENTAL_SNR_DB", "HARMONIC_SNR_DB", "MIN_HARMONICS", "shaft_mask"]

FUNDAMENTAL_SNR_DB = 12.0
HARMONIC_SNR_DB = 10.0
MIN_HARMONICS = 3


def shaft_mask(f, shaft_hz, df):
    """True on the bins of ``f`` within ``max(1.5 df, 0.1 %)`` of an integer multiple of ``shaft_hz``
    (none when ``shaft_hz`` is None or 0): shaft lines are not bearing-fault evidence."""
    if not shaft_hz:
        return np.zeros(f.shape, bool)
    h = np.rint(f / shaft_hz)
    tol = np.maximum(1.5 * df, 1e-3 * f)
    return (h >= 1) & (np.abs(f - h * shaft_hz) <= tol)
