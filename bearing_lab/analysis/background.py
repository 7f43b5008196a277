"""The rig's non-impulsive background: machine tones and broadband noise, measured and re-synthesised.

Why: a bearing model computes what the bearing does; a rig also has a motor, a
coupling, a fan, electrical pick-up and sensor noise.  RMS, crest factor and
kurtosis of a recording describe the sum, so a simulation compared without that
background compares unlike things (a healthy 6308 model gives 0.001 g where every
rig shows about 1 g).  This module measures the background of a recording and
synthesises a signal with the same tones and the same broadband spectrum, to be
added to a simulation as an explicit, documented option.

Measurement:

- *tones*: lines of the Hann amplitude spectrum of the whole record standing more
  than ``tone_snr_db`` (default 15 dB) above the running median over 5 Hz,
  excluding the harmonics of the impact rate(s) and their shaft sidebands given in
  ``exclude_hz`` (those belong to the defect, not the machine), and, when impact times
  are given, every line whose amplitude between the impacts is below half its amplitude
  over the whole record (a machine tone is there between impacts too; a line of the
  impact train is not).  Frequency from the exact two-point ratio of the Hann window
  (Grandke 1983), amplitude and phase by joint least squares over the record; at most
  ``max_tones``, the strongest kept;
- *broadband*: the power spectral density of the record with the tones removed,
  from the quiet part of every period (from 0.45 to 0.85 of a period after each
  impact, where the impact ringing has died out) when impact times are given, else
  from the whole record (Welch, Hann, 50 % overlap).

With a ``model`` (what a model explains of the recording, e.g. the declared scene through
the structural path), the model's power at each tone and its PSD in its own quiet stretches
are removed from the recording's: the background is what the model does not explain.

Synthesis: the tones with their measured amplitude and phase, plus Gaussian noise
shaped to the measured PSD (random phases from a seeded generator: the same seed
gives the same signal).

Public API
----------
Background(fs, tones, frequency, psd, source)  -- .synthesize(n, seed=0), .rms_tones, .rms_noise, .rms,
                                                  .to_dict()
estimate_background(x, fs, *, times=None, period=None, exclude_hz=(), shaft_hz=None, ...) -> Background
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import median_filter
from scipy.signal import welch

from .._docdict import fill_doc
from ..errors import AnalysisError
from .impacts import between_impacts

__all__ = ["Background", "estimate_background"]


@dataclass
class Background:
    """Tones (frequency Hz, amplitude, phase rad) and a one-sided broadband PSD (U**2/Hz)."""

    fs: float
    tones: list
    frequency: np.ndarray
    psd: np.ndarray
    source: str = ""

    @property
    def rms_tones(self) -> float:
        return float(math.sqrt(sum(a * a / 2 for _, a, _ in self.tones)))

    @property
    def rms_noise(self) -> float:
        if self.psd.size < 2:
            return 0.0
        return float(math.sqrt(np.sum(self.psd) * (self.frequency[1] - self.frequency[0])))

    @property
    def rms(self) -> float:
        return float(math.hypot(self.rms_tones, self.rms_noise))

    def synthesize(self, n, *, seed=0, t0=0.0):
        """``n`` samples at :attr:`fs`: the tones plus noise shaped to the PSD."""
        n = int(n)
        t = t0 + np.arange(n) / self.fs
        y = np.zeros(n)
        for f, a, ph in self.tones:
            y += a * np.cos(2 * np.pi * f * t + ph)
        if self.psd.size > 1:
            white = np.random.default_rng(seed).standard_normal(n)
            spec = np.fft.rfft(white)
            fk = np.fft.rfftfreq(n, 1 / self.fs)
            shape = np.sqrt(np.interp(fk, self.frequency, self.psd, left=0.0, right=0.0) * self.fs / 2)
            y += np.fft.irfft(spec * shape, n)
        return y

    def to_dict(self) -> dict:
        return {"source": self.source, "rms_m_s2": self.rms, "rms_tones_m_s2": self.rms_tones,
                "rms_broadband_m_s2": self.rms_noise,
                "tones": [{"frequency_hz": float(f), "amplitude_m_s2": float(a)} for f, a, _ in self.tones]}


def _hann_offset(amp, k):
    """Fractional bin of a Hann-windowed tone from the two largest bins (Grandke)."""
    if not 0 < k < amp.size - 1:
        return 0.0
    if amp[k + 1] >= amp[k - 1]:
        r = amp[k + 1] / max(amp[k], 1e-300)
        return float((2 * r - 1) / (r + 1))
    r = amp[k - 1] / max(amp[k], 1e-300)
    return float(-(2 * r - 1) / (r + 1))


def _excluded(f, df, exclude_hz, shaft_hz, fmax):
    """Mask of spectrum bins at the harmonics of ``exclude_hz`` (and their shaft sidebands)."""
    mask = np.zeros(f.shape, bool)
    sides = (0.0,) if not shaft_hz else (-2 * shaft_hz, -shaft_hz, 0.0, shaft_hz, 2 * shaft_hz)
    for f0 in exclude_hz:
        if not (f0 and np.isfinite(f0) and f0 > 0):
            continue
        for h in np.arange(1, int(fmax / f0) + 1):
            for s in sides:
                c = h * f0 + s
                w = max(2.5 * df, 0.002 * h * f0)
                mask |= np.abs(f - c) <= w
    return mask


def _fit_tones(x, fs, freqs, mask=None):
    """Amplitudes and phases of tones at ``freqs`` by joint least squares (on the samples in ``mask``)."""
    t = np.arange(x.size) / fs
    basis = np.concatenate([np.cos(2 * np.pi * freqs[None, :] * t[:, None]),
                            np.sin(2 * np.pi * freqs[None, :] * t[:, None])], axis=1)
    if mask is not None:
        basis, x = basis[mask], x[mask]
    # normal equations: a (2K x 2K) system instead of an SVD of the (n x 2K) basis
    coef, *_ = np.linalg.lstsq(basis.T @ basis, basis.T @ x, rcond=None)
    c, s = coef[: freqs.size], coef[freqs.size:]
    return np.hypot(c, s), np.arctan2(-s, c)


def _find_tones(x, fs, *, exclude_hz, shaft_hz, snr_db, max_tones, mask=None):
    n = x.size
    w = np.hanning(n)
    amp = np.abs(np.fft.rfft(x * w)) * 2 / w.sum()
    f = np.fft.rfftfreq(n, 1 / fs)
    df = f[1] - f[0]
    floor = median_filter(amp, size=max(21, int(5.0 / df) | 1), mode="nearest")
    lm = (amp[1:-1] > amp[:-2]) & (amp[1:-1] >= amp[2:])
    cand = np.flatnonzero(lm) + 1
    cand = cand[(amp[cand] > floor[cand] * 10 ** (snr_db / 20)) & (f[cand] > 2.0) & (f[cand] < 0.45 * fs)]
    cand = cand[~_excluded(f[cand], df, exclude_hz, shaft_hz, fs / 2)]
    cand = cand[np.argsort(amp[cand])[::-1][:2 * max_tones]]
    freqs = np.array([(k + _hann_offset(amp, k)) * df for k in cand])
    if freqs.size == 0:
        return []
    a_all, _ = _fit_tones(x, fs, freqs)
    if mask is not None and mask.sum() > 4 * freqs.size:
        # a machine tone is there between the impacts too; a line of the impact train is not
        a_gap, _ = _fit_tones(x, fs, freqs, mask)
        freqs = freqs[a_gap >= 0.5 * a_all]
        if freqs.size == 0:
            return []
        a_all, _ = _fit_tones(x, fs, freqs)
    keep = np.argsort(a_all)[::-1][:max_tones]
    freqs = freqs[keep]
    a, ph = _fit_tones(x, fs, freqs)
    return sorted(((float(fr), float(aa), float(p)) for fr, aa, p in zip(freqs, a, ph)), key=lambda v: v[0])


def _runs(mask):
    """(start, stop) of the runs of True in ``mask``."""
    d = np.diff(np.r_[0, mask.astype(np.int8), 0])
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


#: shortest quiet stretch the gated PSD uses, samples; a fast impact train at a low rate (an inner-race
#: defect at 12 kHz: 0.4 of a 6.2 ms period is 30 samples) falls back to the shorter one
_MIN_RUN, _MIN_RUN_SHORT = 32, 16


def _gated_psd(y, fs, mask):
    runs = _runs(mask)
    shortest = _MIN_RUN if any(b - a >= _MIN_RUN for a, b in runs) else _MIN_RUN_SHORT
    runs = [(a, b) for a, b in runs if b - a >= shortest]
    if not runs:
        raise AnalysisError(f"background: no quiet stretch of at least {_MIN_RUN_SHORT} samples between impacts")
    m = min(b - a for a, b in runs)
    w = np.hanning(m)
    segs = np.stack([y[a:a + m] - np.mean(y[a:a + m]) for a, _ in runs])
    p = np.mean(np.abs(np.fft.rfft(segs * w, axis=1)) ** 2, axis=0) * 2 / (fs * np.sum(w ** 2))
    p[0] /= 2
    return np.fft.rfftfreq(m, 1 / fs), p


@fill_doc
def estimate_background(x, fs, *, times=None, period=None, exclude_hz=(), shaft_hz=None, max_tones=20,
                        tone_snr_db=15.0, source="", model=None, model_times=None) -> Background:
    """Measure the non-impulsive background of a recording (module docstring).

    Parameters
    ----------
    x : array_like, 1-D
        Acceleration, m s-2.
    %(fs)s
    times, period : array_like and float, optional
        Impact times (s) and period (s): the broadband part is then measured between impacts.
    exclude_hz : sequence of float
        Impact rates (e.g. the measured BPFO) whose harmonics are not machine tones.
    shaft_hz : float, optional
        Shaft frequency: sidebands at +-1, 2 f_r of the excluded harmonics are excluded too.
    max_tones : int
        Tones kept (the strongest).
    tone_snr_db : float
        Line-to-floor ratio a tone needs, dB.
    source : str
        Description kept with the result (e.g. the recording's file name).
    model, model_times : array_like and array_like, optional
        What a model explains of ``x`` (e.g. the declared scene's simulation through the structural path,
        same rate; it may be shorter) and its own impact times (default ``times``): the model's power at each tone
        and in its own quiet stretches is removed from the recording's (independent powers add), so a
        background measured on a recording the model explains fully is zero, not the model a second time.

    Returns
    -------
    Background

    Examples
    --------
    >>> import numpy as np
    >>> fs = 10000.0; t = np.arange(50000) / fs
    >>> x = 0.5 * np.cos(2 * np.pi * 50 * t) + np.random.default_rng(0).normal(0, 0.1, t.size)
    >>> bg = estimate_background(x, fs)
    >>> round(bg.tones[0][0], 2), round(bg.tones[0][1], 2), round(bg.rms_noise, 2)
    (50.0, 0.5, 0.1)
    """
    x = np.asarray(x, float)
    if x.ndim != 1 or x.size < 1024 or not np.all(np.isfinite(x)):
        raise AnalysisError(f"background: needs a finite 1-D record of at least 1024 samples, got {x.shape}")
    x = x - np.mean(x)
    gated = times is not None and period is not None and len(times) >= 3
    mask = between_impacts(x.size, fs, times, period) if gated else None
    tones = _find_tones(x, fs, exclude_hz=tuple(exclude_hz), shaft_hz=shaft_hz, snr_db=tone_snr_db,
                        max_tones=max_tones, mask=mask)
    t = np.arange(x.size) / fs
    resid = x - sum((a * np.cos(2 * np.pi * f * t + ph) for f, a, ph in tones), np.zeros_like(x))
    if gated:
        freq, psd = _gated_psd(resid, fs, mask)
    else:
        freq, psd = welch(resid, fs, window="hann", nperseg=min(x.size, 2048))
    if model is not None:
        tones, psd = _without_model(model, fs, tones, freq, psd, times=model_times if model_times is not None
                                    else times, period=period if gated else None)
    return Background(float(fs), tones, freq, psd, source)


def _without_model(model, fs, tones, freq, psd, *, times, period):
    """Tones and PSD less the model's power at the same frequencies (in its own quiet stretches)."""
    y = np.asarray(model, float)
    y = y - np.mean(y)
    kept = []
    if tones:
        freqs = np.array([f for f, _, _ in tones])
        a_m, ph_m = _fit_tones(y, fs, freqs)
        t = np.arange(y.size) / fs
        y = y - sum((a * np.cos(2 * np.pi * f * t + ph) for f, a, ph in zip(freqs, a_m, ph_m)), np.zeros_like(y))
        for (f, a, ph), am in zip(tones, a_m):
            left = a * a - am * am
            if left > (0.01 * a) ** 2:       # a tone the model holds (within 1 % of its power) is the model's
                kept.append((f, float(math.sqrt(left)), ph))
    if times is not None and period is not None and len(times) >= 3:
        mask = between_impacts(y.size, fs, times, period)
        f_m, p_m = _gated_psd(y, fs, mask)
    else:
        f_m, p_m = welch(y, fs, window="hann", nperseg=min(y.size, 2048))
    return kept, np.maximum(psd - np.interp(freq, f_m, p_m), 0.0)
