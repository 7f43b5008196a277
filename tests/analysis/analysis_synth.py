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


def bearing_signal(rate, *, fs=12000.0, duration=10.0, slip=0.01, mod_hz=None, mod_depth=0.8, f_res=3000.0,
                   decay=900.0, amp=1.0, shaft_hz=None, shaft_amp=0.0, noise=0.3, seed=0):
    """Impacts of a bearing fault with known truth.

    rate: impact rate (BPFO, BPFI or 2 BSF), Hz; slip: relative standard deviation of
    each interval (random slip, 1 % in real bearings); mod_hz: amplitude modulation of
    the impacts (f_r for an inner race, FTF for a ball; depth mod_depth); shaft
    harmonics 1..9 of shaft_hz with amplitude shaft_amp / h; white noise of std noise.
    Returns (x, fs).
    """
    rng = np.random.default_rng(seed)
    n = int(round(duration * fs))
    m = int(duration * rate) + 5
    times = np.cumsum(np.r_[0.002, (1 + slip * rng.standard_normal(m - 1)) / rate])
    times = times[times < duration - 0.02]
    x = np.zeros(n)
    L = int(np.ceil(8.0 / decay * fs))
    for tk in times:
        g = amp * (1 + mod_depth * np.cos(2 * np.pi * mod_hz * tk)) if mod_hz else amp
        i0 = int(np.ceil(tk * fs))
        tau = np.arange(i0, min(n, i0 + L)) / fs - tk
        x[i0:i0 + tau.size] += g * np.exp(-decay * tau) * np.sin(2 * np.pi * f_res * tau)
    t = np.arange(n) / fs
    if shaft_hz:
        x += sum(shaft_amp / h * np.cos(2 * np.pi * h * shaft_hz * t + h) for h in range(1, 10))
    return x + rng.normal(0, noise, n), fs
