"""Where the structural-path fit (:mod:`.structural_path`) pools each impact, and the background it holds
apart (measured between the impacts).

Public API (of this private module, for :mod:`.structural_path`)
-----------------------------------------------------------------
hilbert_envelope(x)                             -- |analytic signal| of x less its mean
centred_times(x, fs, times, period, env=None)   -- impact times moved to the impact's energy centroid
floor_level(x, fs, times, period, env=None)     -- median envelope between the impacts
background_power(x, fs, times, period, ranges, w2) -- background power per frequency range
ImpactWindows(n, fs, times, period, pre=, post=) -- the impact windows' sample indices, cut once:
                                                   .mean_of(env, shift), .power(x), .peaks(x), .views(...)
frequency_runs(masks)                           -- the runs of frequencies of a spectrum's bins, for .views
signal_of(obj, fs, what)                        -- (samples, fs) of an array or a Dataset, checked
"""
from __future__ import annotations

import numpy as np
from scipy import fft as sfft

from ..errors import AnalysisError
from .impacts import between_impacts

__all__ = ["CENTROID_HALF_S", "hilbert_envelope", "centred_times", "floor_level", "background_power",
           "ImpactWindows", "frequency_runs", "signal_of"]


def hilbert_envelope(x):
    """The Hilbert envelope of ``x`` less its mean: ``abs(scipy.signal.hilbert(x - mean))``, the analytic
    signal built from the real transform (the same values for a real signal, a third less CPU)."""
    x = np.asarray(x, float)
    n = x.size
    spec = sfft.rfft(x - np.mean(x))
    z = np.zeros(n, complex)
    half = (n + 1) // 2             # positive frequencies doubled; DC (and Nyquist, n even) kept once
    z[0] = spec[0]
    z[1:half] = 2 * spec[1:half]
    if n % 2 == 0 and n:
        z[n // 2] = spec[n // 2]
    return np.abs(sfft.ifft(z, overwrite_x=True))


def floor_level(x, fs, times, period, env=None) -> float:
    """The floor of a signal: its median Hilbert envelope between the impacts (0.45 to 0.85 of a period
    after each, :func:`between_impacts`), where the ringing has died out; the whole record's median
    where no such stretch fits.  ``env``: ``x``'s :func:`hilbert_envelope`, when the caller has it."""
    env = hilbert_envelope(x) if env is None else env
    mask = between_impacts(env.size, fs, times, period)
    return float(np.median(env[mask] if mask.sum() >= 8 else env))


#: half-width of the span over which an impact's time is taken as its energy centroid, s
CENTROID_HALF_S = 2e-3


def centred_times(x, fs, times, period, env=None):
    """Impact times moved to the centroid of the impact's envelope power above the background (its mean
    power between the impacts), within :data:`CENTROID_HALF_S` of it (three passes): the same point of
    every impact, in the recording and in the simulation alike.

    An impact time is an envelope maximum; a defect longer than a ball's contact rings at entry and at
    exit, nearly as strongly, and which of the two is the maximum flips from impact to impact with the
    noise and with the path: on a stand-in of paper O2 (3 mm, 600 N, 4300 Hz, 5 %), 6 of 92 impact times
    moved by 0.5 ms between the simulation through the true path and through a path 0.3 % off it, so the
    pooled views compared differently mixed impacts, and the path fit gave 4284 Hz, 5.28 % (4305 Hz,
    5.07 % with the centroids).  The centroid moves continuously with the signal.  ``env``: ``x``'s
    :func:`hilbert_envelope`, when the caller has it."""
    p = (hilbert_envelope(x) if env is None else env) ** 2
    mask = between_impacts(p.size, fs, times, period)
    p = np.maximum(p - (np.mean(p[mask]) if mask.sum() >= 8 else 0.0), 0.0)
    half = max(1, int(round(CENTROID_HALF_S * fs)))
    c = np.asarray(times, float) * fs
    live = np.ones(c.size, bool)            # an impact whose span holds no power keeps its time
    span = np.arange(-half, half + 1)
    for _ in range(3):
        k = np.rint(c).astype(int)
        inner = np.flatnonzero(live & (k - half >= 0) & (k + half + 1 <= p.size))
        rows = k[inner, None] + span
        w = p[rows]
        tot = w.sum(axis=1)
        good = tot > 0
        c[inner[good]] = np.sum(rows * w, axis=1)[good] / tot[good]
        live[inner[~good]] = False
        for j in np.flatnonzero(live & ((k - half < 0) | (k + half + 1 > p.size))):   # spans cut by the ends
            i0, i1 = max(0, k[j] - half), min(p.size, k[j] + half + 1)
            w = p[i0:i1]
            if i1 - i0 < 2 or not w.sum() > 0:
                live[j] = False
            else:
                c[j] = float(np.sum(np.arange(i0, i1) * w) / w.sum())
    return c / fs


def background_power(x, fs, times, period, ranges, w2):
    """Per frequency range: the mean power of ``x`` between its impacts (0.45 to 0.85 of a period after
    each, where the ringing has died out: :func:`between_impacts`), as a Hann-windowed power spectrum
    of a window whose squared window sum is ``w2`` would hold it.  Zeros when no such segment fits."""
    n = int(round(0.4 * period * fs))
    starts = [int(round((t + 0.45 * period) * fs)) for t in times]
    segs = [x[i: i + n] for i in starts if n >= 8 and i + n <= x.size]
    if not segs:
        return np.zeros(len(ranges))
    w = np.hanning(n)
    psd = np.mean(np.abs(np.fft.rfft(np.stack(segs) * w, axis=1)) ** 2, axis=0) / float(np.sum(w * w))
    f = np.fft.rfftfreq(n, 1 / fs)
    out = []
    for lo, hi in ranges:
        sel = (f >= lo) & (f < hi)
        out.append(psd[sel].mean() if sel.any() else np.interp(0.5 * (lo + hi), f, psd))
    return np.asarray(out) * w2


class ImpactWindows:
    """The impact windows at ``times`` in a record of ``n`` samples, their sample indices worked out once
    (the path fit reads the same windows of some 500 signals): the windows from ``pre`` s before to ``post``
    s after each impact, those that fit, as :func:`.impacts.impact_segments` cuts them, and the spans of
    +-20 % of a period around each impact, as :func:`.impacts.impact_peaks` reads them.  Each method gives
    what the function of :mod:`.impacts` named with it gives, from one gather instead of a loop."""

    def __init__(self, n, fs, times, period, *, pre, post):
        self.n, self.fs, self.times = int(n), float(fs), np.asarray(times, float)
        self.i0, self.i1 = int(round(pre * fs)), int(round(post * fs))
        self.hann = np.hanning(self.i0 + self.i1)
        self._rows = {}
        w = max(1, int(0.2 * period * fs))
        idx = (self.times * fs).round().astype(int)
        idx = idx[(idx >= 0) & (idx < self.n)]
        inner = (idx - w >= 0) & (idx + w + 1 <= self.n)
        self._peak_rows = idx[inner, None] + np.arange(-w, w + 1)
        self._peak_spans = [(max(0, i - w), i + w + 1) for i in idx[~inner]]

    def rows(self, shift=0):
        """Sample indices (windows x samples) of the windows moved by ``shift`` samples (None if none fit)."""
        if shift not in self._rows:
            times = self.times + shift / self.fs if shift else self.times
            idx = np.array([int(round(t * self.fs)) for t in times], int)
            idx = idx[(idx - self.i0 >= 0) & (idx + self.i1 < self.n)]
            self._rows[shift] = idx[:, None] + np.arange(-self.i0, self.i1) if idx.size else None
        return self._rows[shift]

    def mean_of(self, env, shift=0):
        """``env`` (a whole record's envelope) averaged over the windows moved by ``shift`` samples (None if
        none fit), as :func:`.impacts.mean_envelope`."""
        rows = self.rows(shift)
        return None if rows is None else env[rows].mean(axis=0)

    def power(self, x):
        """The mean Hann-windowed power spectrum of the windows of ``x`` (its mean removed; None if none fit),
        as :func:`.impacts.segment_spectrum`."""
        rows = self.rows()
        if rows is None:
            return None
        seg = (np.asarray(x, float) - np.mean(x))[rows]
        return np.mean(np.abs(np.fft.rfft(seg * self.hann, axis=1)) ** 2, axis=0)

    def peaks(self, x):
        """The largest ``|x - mean|`` in each impact's span, as :func:`.impacts.impact_peaks` (edge spans last)."""
        a = np.abs(np.asarray(x, float) - np.mean(x))
        inner = a[self._peak_rows].max(axis=1) if self._peak_rows.size else np.zeros(0)
        return np.r_[inner, [a[i:j].max() for i, j in self._peak_spans]]

    def views(self, y, peak_at, runs):
        """What the path fit reads of ``y``, all proportional to its scale: its Hilbert envelope averaged over
        the windows, moved so that its peak falls on sample ``peak_at`` of a window; its mean power spectrum
        (:meth:`power`) averaged over each run of frequencies of ``runs`` (:func:`frequency_runs`); the 90th
        percentile of its impact peaks (:meth:`peaks`).

        The windows are moved (not the averaged envelope rolled): a roll would wrap the rise
        before the peak onto the window's end, where the recording is at its noise level, and
        that wrapped peak pulls the gain down (on a stand-in with a known path, gain 1, 4300 Hz,
        5 %, and 0.05 g sensor noise, model at rtol 1e-6: gain 0.964 with the roll, 0.990 with the
        windows moved).
        """
        env_all = hilbert_envelope(y)
        env = self.mean_of(env_all)
        shift = int(np.argmax(env)) - peak_at
        if shift:
            moved = self.mean_of(env_all, shift)
            env = moved if moved is not None else np.roll(env, -shift)
        starts, sizes = runs
        bins = np.add.reduceat(self.power(y), starts)[::2] / sizes
        return env, bins, float(np.percentile(self.peaks(y), 90))


def frequency_runs(masks):
    """``(starts, sizes)`` of the frequency bins ``masks`` (boolean, each one run of a spectrum's frequencies,
    in increasing order) for :meth:`ImpactWindows.views`: each bin's sum is one segment of ``np.add.reduceat``
    at ``starts`` (start, end, start, end, ... of the runs; the last end dropped where it is the spectrum's)."""
    edges = [(int(np.flatnonzero(m)[0]), int(np.flatnonzero(m)[-1]) + 1) for m in masks]
    starts = [i for e in edges for i in e]
    if edges and edges[-1][1] >= np.size(masks[-1]):
        starts = starts[:-1]
    return np.array(starts, int), np.array([b - a for a, b in edges], float)


def signal_of(obj, fs, what):
    """(x, fs) of an array, or of a Dataset's default channel; ``what`` names it in errors.

    Raises AnalysisError for what the fit cannot read: not 1-D, empty, not finite, all zero, or
    no positive sampling rate.
    """
    if hasattr(obj, "data_vars"):
        ch = obj.attrs.get("default_channel") or next(iter(obj.data_vars), None)
        if ch is None or "sampling_rate_hz" not in obj.attrs:
            raise AnalysisError(f"structural path: the {what} Dataset has no channel or no sampling_rate_hz")
        x, fs = obj[ch].values, obj.attrs["sampling_rate_hz"]
    elif fs is None:
        raise AnalysisError(f"structural path: give fs (Hz) with the {what} as a plain array")
    else:
        x = obj
    x, fs = np.asarray(x, float), float(fs)
    if not (np.isfinite(fs) and fs > 0):
        raise AnalysisError(f"structural path: the {what}'s sampling rate must be positive; got {fs!r} Hz")
    if x.ndim != 1 or x.size == 0:
        raise AnalysisError(f"structural path: the {what} must be one non-empty signal; got shape {x.shape}")
    bad = np.flatnonzero(~np.isfinite(x))
    if bad.size:
        raise AnalysisError(f"structural path: the {what} holds {bad.size} non-finite samples (the first at "
                            f"{bad[0] / fs:.6g} s)")
    if not np.any(x):
        raise AnalysisError(f"structural path: the {what} is zero throughout; it has no impacts to fit on")
    return x, fs
