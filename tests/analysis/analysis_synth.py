"""Synthetic signals with a known truth for the analysis tests."""
from __future__ import annotations

import numpy as np


def impulse_train(*, fs=20000.0, duration=10.0, period=0.0108509, jitter=0.0, f_res=3000.0,
                  decay=1500.0, snr_db=None, seed=0):
    """Impacts ringing one resonance, evaluated at continuous impact times.

    jitter: relative standard deviation of each interval (cumulative random slip).
    snr_db: signal power over white-noise power (None: no noise).
    Returns (x, fs, impact_times).
    """
    rng = np.random.default_rng(seed)
    n = int(round(duration * fs))
    nimp = int(duration / period) + 2
    intervals = period * (1 + jitter * rng.standard_normal(nimp))
    times = 0.003 + np.cumsum(np.r_[0.0, intervals[:-1]])
    times = times[times < duration - 0.01]
    x = np.zeros(n)
    L = int(np.ceil(8.0 / decay * fs))
    for tk in times:
        i0 = int(np.ceil(tk * fs))
        i1 = min(n, i0 + L)
        tau = np.arange(i0, i1) / fs - tk
        x[i0:i1] += np.exp(-decay * tau) * np.sin(2 * np.pi * f_res * tau)
    if snr_db is not None:
        p = np.mean(x ** 2)
        x = x + rng.normal(0.0, np.sqrt(p / 10 ** (snr_db / 10)), n)
    return x, fs, times
