"""Slow, obvious reference implementations that the fast code is tested against.

Nothing here imports bearing_lab's kernels: each function is written from the
textbook formula so that a sign or factor error in the package cannot hide.
"""
from __future__ import annotations

import math

import numpy as np


def hertz_stiffness_harris(sum_rho_per_mm: float, delta_star: float) -> float:
    """Harris & Kotzalas steel constant: K = 2.15e5 Σρ^-1/2 δ*^-3/2 (N/mm^1.5) -> N/m^1.5."""
    k_mm = 2.15e5 * sum_rho_per_mm ** -0.5 * delta_star ** -1.5
    return k_mm * 1e3 ** 1.5


def static_ball_loads(force, angles, k_eff, clearance=0.0, iters=100):
    """Quasi-static ball loads under a radial force (2-vector, N) on the inner ring.

    Newton's method on the inner-ring displacement e with an analytic Jacobian:
    sum_j K (e.u_j - Pd/2)_+^1.5 u_j = F.
    """
    u = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    f = np.asarray(force, float)
    w = np.linalg.norm(f)
    e = f / w * (clearance / 2 + (5 * w / (len(angles) * k_eff)) ** (2 / 3))
    for _ in range(iters):
        d = u @ e - clearance / 2
        dp = np.maximum(d, 0.0)
        q = k_eff * dp ** 1.5
        r = u.T @ q - f
        J = (u * (1.5 * k_eff * np.sqrt(dp))[:, None]).T @ u
        step = np.linalg.solve(J + 1e-3 * np.eye(2) * np.trace(J) * 1e-9, r)
        e = e - step
        if np.linalg.norm(step) < 1e-16:
            break
    d = u @ e - clearance / 2
    return k_eff * np.maximum(d, 0.0) ** 1.5, e


def impulse_times(x, fs, threshold_frac=0.5, dead_time=None):
    """Times of impulses: first upward crossing of threshold_frac * max|x| after a dead time,
    refined by linear interpolation between samples."""
    a = np.abs(np.asarray(x, float))
    thr = threshold_frac * a.max()
    dead = int(round((dead_time or 0.0) * fs))
    times = []
    i = 1
    n = len(a)
    while i < n:
        if a[i] >= thr and a[i - 1] < thr:
            frac = (thr - a[i - 1]) / (a[i] - a[i - 1])
            times.append((i - 1 + frac) / fs)
            i += max(dead, 1)
        else:
            i += 1
    return np.array(times)


def interpolated_peak_frequency(x, fs, f_lo, f_hi, pad=8):
    """Frequency of the largest spectral line in [f_lo, f_hi]: Hann window, zero padding,
    parabolic interpolation of the log magnitude (Gaussian peak fit)."""
    x = np.asarray(x, float) - np.mean(x)
    n = len(x)
    w = np.hanning(n)
    nfft = pad * n
    spec = np.abs(np.fft.rfft(x * w, nfft))
    f = np.fft.rfftfreq(nfft, 1 / fs)
    m = (f >= f_lo) & (f <= f_hi)
    i = np.flatnonzero(m)[np.argmax(spec[m])]
    a, b, c = np.log(spec[i - 1:i + 2])
    p = 0.5 * (a - c) / (a - 2 * b + c)
    return f[i] + p * (f[1] - f[0])


def spectral_coherence_at(x, fs, alpha, nw):
    """Cyclic spectral coherence magnitude at one cyclic frequency, averaged over f (brute force).

    Welch cross-spectrum of x(t) and x(t) exp(-2j pi alpha t) with Hann frames of nw
    samples and half overlap, normalised by the two power spectra (the textbook
    definition, Antoni 2009), magnitude averaged over the interior bins.
    """
    x = np.asarray(x, float) - np.mean(x)
    t = np.arange(x.size) / fs
    y = x * np.exp(-2j * np.pi * alpha * t)
    w = np.hanning(nw + 1)[:-1]
    sxy = np.zeros(nw, complex)
    sxx = np.zeros(nw)
    syy = np.zeros(nw)
    for start in range(0, x.size - nw + 1, nw // 2):
        X = np.fft.fft(w * x[start:start + nw])
        Y = np.fft.fft(w * y[start:start + nw])
        sxy += X * np.conj(Y)
        sxx += np.abs(X) ** 2
        syy += np.abs(Y) ** 2
    coh = np.abs(sxy) / np.sqrt(sxx * syy)
    return float(np.mean(coh[1:nw // 2]))


def resample_at_angle(x, fs, pulse_times, pulses_per_rev=1):
    """Order tracking the slow way: shaft angle by linear interpolation between pulses,
    then linear interpolation of x at each equal-angle instant."""
    p = np.asarray(pulse_times, float)
    revs = np.arange(p.size) / pulses_per_rev
    shaft = revs[-1] / (p[-1] - p[0])
    out = []
    a = revs[0]
    while a <= revs[-1]:
        t = np.interp(a, revs, p)
        if t * fs > x.size - 1:
            break
        out.append(np.interp(t * fs, np.arange(x.size), x))
        a += shaft / fs
    return np.array(out), float(shaft)
