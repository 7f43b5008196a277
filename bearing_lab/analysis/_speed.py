"""Shaft frequency from the vibration signal alone (no tachometer).

Why: the fault frequencies scale with the shaft frequency, and a 1 % speed
error moves BPFI by more than a bin; stored "rpm" values of public recordings
are nominal.  The estimate has two stages:

1. Harmonic family search: on the amplitude spectrum, each candidate ``f0``
   scores the weighted sum over ``h = 1..n_harmonics`` (weights 0.9**(h-1)) of
   the line-to-floor ratio (dB, capped at 20 dB; lines under 10 dB count 0)
   found at ``h * f0``.  With a fixed number of harmonics a sub-harmonic
   ``f0/2`` only collects half of the family, so the true family wins; an
   octave check then prefers ``f0/2`` or ``f0/3`` when their own odd lines are
   present (even harmonics next to mains can otherwise win).  Lines within 1.5 bins of mains
   harmonics (50 and 60 Hz multiples by default) are masked, because ``2 f_r`` sits next to 60 Hz
   at 1797 r/min.
2. Interpolated-DFT refinement of every harmonic that stands clear of the floor
   (Quinn's second estimator on the rectangular-window DFT, or the exact
   two-point ratio of the Hann window), then a weighted least-squares fit of
   ``f_h = h f_r`` (weights: line SNR times h**2, the Cramér-Rao scaling).

A nominal rpm, when given, restricts the search to +-``prior_tolerance``
around it; it is a prior, not the answer.
"""
from __future__ import annotations

import numpy as np
from scipy import fft as _fft
from scipy.ndimage import median_filter

from .._docdict import fill_doc
from ..errors import AnalysisError
from ._util import check_fs, check_signal

__all__ = ["shaft_frequency", "interpolated_peak", "line_floor_db"]

#: Harmonic lines must stand this far above the local floor (dB) to be used in
#: the refinement: for a Rayleigh-distributed floor the chance that a noise bin
#: exceeds the median by 10 dB is exp(-ln2 * 10) ~ 1e-3.
LINE_SNR_DB = 10.0
#: Line SNRs are capped here in the family score so that one huge non-shaft line
#: (bearing-fault or electrical) cannot outweigh a family of shaft harmonics.
SNR_CAP_DB = 20.0


def interpolated_peak(X, k, *, method):
    """Fractional bin offset of a spectral line from the complex DFT around bin ``k``.

    Parameters
    ----------
    X : ndarray, complex
        DFT (one-sided is fine) of the record, last axis = frequency.
    k : int
        Index of the peak bin (``1 <= k < X.shape[-1] - 1``).
    method : {"quinn", "jacobsen", "hann"}
        ``"quinn"``: Quinn's second estimator (rectangular window), unbiased for
        a single tone and near the Cramér-Rao bound.  ``"jacobsen"``: Jacobsen's
        estimator with Candan's bias correction (rectangular window).
        ``"hann"``: exact two-point ratio for a Hann-windowed tone (Grandke).

    Returns
    -------
    delta : float
        Offset in bins; the line is at ``(k + delta) * fs / n``.

    References
    ----------
    .. [1] Quinn, "Estimation of frequency, amplitude, and phase from the DFT of a time
       series", IEEE Trans. Signal Process. 45 (1997) 814-817.
    .. [2] Jacobsen & Kootsookos, "Fast, accurate frequency estimators", IEEE Signal
       Process. Mag. 24 (2007) 123-125; Candan, IEEE SPL 18 (2011) 351-354.
    .. [3] Grandke, "Interpolation algorithms for discrete Fourier transforms of weighted
       signals", IEEE Trans. Instrum. Meas. 32 (1983) 350-355.

    Examples
    --------
    >>> import numpy as np
    >>> from bearing_lab.analysis import interpolated_peak
    >>> n = 1000; x = np.cos(2 * np.pi * 50.3 * np.arange(n) / n)
    >>> X = np.fft.rfft(x); k = int(np.argmax(abs(X)))
    >>> round(k + interpolated_peak(X, k, method="quinn"), 4)
    50.3
    """
    a, b, c = X[k - 1], X[k], X[k + 1]
    if b == 0:
        return 0.0
    if method == "quinn":
        def tau(x):
            return (0.25 * np.log(3 * x * x + 6 * x + 1)
                    - np.sqrt(6) / 24 * np.log((x + 1 - np.sqrt(2 / 3)) / (x + 1 + np.sqrt(2 / 3))))
        ap = (c / b).real
        am = (a / b).real
        dp = -ap / (1 - ap)
        dm = am / (1 - am)
        return float((dp + dm) / 2 + tau(dp * dp) - tau(dm * dm))
    if method == "jacobsen":
        n_half = X.shape[-1]
        den = 2 * b - a - c
        d = ((a - c) / den).real if den != 0 else 0.0
        n = 2 * (n_half - 1)
        return float(np.tan(np.pi / n) / (np.pi / n) * d)
    if method == "hann":
        if abs(c) >= abs(a):
            r = abs(c) / abs(b)
            return float((2 * r - 1) / (r + 1))
        r = abs(a) / abs(b)
        return float(-(2 * r - 1) / (r + 1))
    raise AnalysisError(f"Invalid value for the 'method' parameter. Allowed values are 'quinn', "
                        f"'jacobsen' and 'hann', but got {method!r} instead.")


def line_floor_db(amp, *, width):
    """Line-to-floor ratio in dB: ``20 log10(amp / running median over width bins)``."""
    width = max(3, int(width) | 1)
    floor = median_filter(amp, size=width, mode="nearest")
    floor = np.maximum(floor, np.max(amp) * 1e-12 + 1e-300)
    return 20 * np.log10(np.maximum(amp, 1e-300) / floor)


def grid_near_lines(values, df, lo, step, count, h):
    """Indices of the candidates ``c = lo + i step`` (i < count) one of whose harmonics ``h c``
    rounds to a bin (of width ``df``) where ``values`` is nonzero, two candidates to spare each side
    (a superset: the others read only zeros); None when that is not much fewer than all of them."""
    nz = np.flatnonzero(values > 0)
    if nz.size * len(h) > count:
        return None
    hh = np.asarray(h, float)[:, None]
    a = np.floor(((nz - 0.5) * df / hh - lo) / step).astype(np.int64) - 2
    b = np.ceil(((nz + 0.5) * df / hh - lo) / step).astype(np.int64) + 2
    a[:, nz <= 1] = 0  # positions are clipped to bins 1 .. size-2
    b[:, nz >= values.size - 2] = count - 1
    np.clip(a, 0, count, out=a)
    np.clip(b, -1, count - 1, out=b)
    ok = a <= b
    mark = np.bincount(a[ok], minlength=count + 1) - np.bincount(b[ok] + 1, minlength=count + 1)
    idx = np.flatnonzero(np.cumsum(mark[:-1]) > 0)
    return None if 2 * idx.size > count else idx


class SpectrumFloors:
    """:func:`line_floor_db` of slices of one amplitude spectrum ``|spectrum|``, the running median
    of the whole spectrum computed once for the wide slices (the discrete-comb tests of several
    combs read nearly the same half million bins).  Inside a slice the median's window lies in
    the slice, so the whole spectrum's median is the slice's; the ``width // 2`` bins at each end,
    where the slice's own median repeats its end values, are filtered from the slice's ends
    alone: the same numbers as ``line_floor_db(abs(spectrum[a:b]), width=width)``."""

    def __init__(self, spectrum, *, amp=None):
        self.spectrum = spectrum
        self.amp = np.abs(spectrum) if amp is None else amp  # ``amp``: |spectrum|, when known
        self._median = {}

    def snr(self, a, b, *, width):
        amp = self.amp[a:b]
        w = max(3, int(width) | 1)
        h = w // 2
        if 2 * amp.size < self.amp.size or amp.size < 3 * h + 1:  # narrow: filtered on its own
            return line_floor_db(amp, width=width)
        if w not in self._median:
            self._median[w] = median_filter(self.amp, size=w, mode="nearest")
        floor = self._median[w][a:b].copy()
        floor[:h] = median_filter(amp[: 3 * h + 1], size=w, mode="nearest")[:h]
        floor[-h:] = median_filter(amp[-(3 * h + 1):], size=w, mode="nearest")[-h:]
        floor = np.maximum(floor, np.max(amp) * 1e-12 + 1e-300)
        return 20 * np.log10(np.maximum(amp, 1e-300) / floor)


def _method_for(window):
    if window == "boxcar" or window == "rectangular":
        return "quinn"
    if window == "hann":
        return "hann"
    raise AnalysisError(f"Invalid value for the 'window' parameter. Allowed values are 'boxcar' "
                        f"(Quinn's estimator) and 'hann', but got {window!r} instead.")


@fill_doc
def shaft_frequency(x, fs, *, window, rpm=None, prior_tolerance=0.05, fmin=5.0, fmax=100.0,
                    n_harmonics=20, mains_hz=(50.0, 60.0)):
    """Shaft (rotation) frequency from a vibration signal, without a tachometer.

    Parameters
    ----------
    x : array_like, 1-D
        Vibration signal (any unit), ideally several seconds long.
    %(fs)s
    window : {"boxcar", "hann"}
        Window of the DFT used for the search and the interpolation
        (``"boxcar"``: Quinn's estimator, best for an isolated line;
        ``"hann"``: leaks less next to strong neighbours such as mains lines).
    rpm : float, optional
        Nominal speed, r/min: a prior restricting the search to
        ``rpm/60 * (1 +- prior_tolerance)``.
    prior_tolerance : float
        Relative half-width of the prior window (default 0.05: induction-motor
        slip stays within a few per cent).
    fmin, fmax : float
        Search range without a prior, Hz (default 5-100 Hz, i.e. 300-6000 r/min).
    n_harmonics : int
        Number of harmonics in the family score (default 20).  Use 1 for a
        single tone: a family search over many harmonics of noise can then
        outscore one capped line.
    mains_hz : sequence of float
        Mains frequencies whose harmonics are masked (within 1.5 bins).  Pass
        ``()`` to disable.

    Returns
    -------
    shaft_hz : float
        Estimated shaft frequency, Hz.
    n_lines : int
        Number of harmonics that entered the refinement (0 means the family
        score alone gave the answer; treat it as weak evidence).

    References
    ----------
    .. [1] Quinn, IEEE Trans. Signal Process. 45 (1997) 814-817.
    .. [2] Hermes, "Measurement of pitch by subharmonic summation", JASA 83 (1988) 257-264.

    Examples
    --------
    A 29.95 Hz shaft with a few harmonics in noise, 10 s at 12 kHz:

    >>> import numpy as np
    >>> from bearing_lab.analysis import shaft_frequency
    >>> fs = 12000.0; t = np.arange(120000) / fs
    >>> x = sum(np.cos(2*np.pi*h*29.95*t + h) / h for h in range(1, 6))
    >>> x = x + np.random.default_rng(0).normal(0, 1, t.size)
    >>> f, n = shaft_frequency(x, fs, window="boxcar")
    >>> bool(abs(f - 29.95) < 0.005)
    True
    """
    fs = check_fs(fs, func="shaft_frequency")
    x = check_signal(x, func="shaft_frequency", min_samples=64)
    if x.ndim != 1:
        raise AnalysisError(f"shaft_frequency: x must be 1-D, got shape {x.shape}")
    method = _method_for(window)
    n = x.size
    df = fs / n
    if rpm is not None:
        if not (np.isfinite(rpm) and rpm > 0):
            raise AnalysisError(f"shaft_frequency: rpm={rpm!r} must be a positive speed in r/min")
        lo, hi = rpm / 60 * (1 - prior_tolerance), rpm / 60 * (1 + prior_tolerance)
    else:
        lo, hi = float(fmin), float(fmax)
    if not 0 < lo < hi:
        raise AnalysisError(f"shaft_frequency: empty search range ({lo:g}, {hi:g}) Hz")
    if hi * 2 >= fs / 2:
        raise AnalysisError(f"shaft_frequency: search range up to {hi:g} Hz needs fs above "
                            f"{4 * hi:g} Hz, got {fs=}")
    if lo < 4 * df:
        raise AnalysisError(f"shaft_frequency: x lasts {n / fs:.3g} s; its 1/T = {df:.3g} Hz "
                            f"bins cannot resolve a shaft line at {lo:.3g} Hz (record at least "
                            f"{4 / lo:.3g} s)")
    return harmonic_family(x, fs, lo, hi, n_harmonics=n_harmonics, method=method,
                            mains_hz=mains_hz, rpm_given=rpm is not None, fmin=fmin)


def harmonic_family(x, fs, lo, hi, *, n_harmonics, method, mains_hz=(), rpm_given=False, fmin=None,
                     harmonic_weight=2, details=False):
    """Family search in [lo, hi] + interpolated refinement; returns (f0, n_lines[, best_snr_db]).

    ``harmonic_weight``: harmonic h enters the least squares with weight
    SNR_h * h**harmonic_weight (2 for noise-limited lines, the Cramer-Rao
    scaling; 0 where lines broaden with h, as for impacts with random slip).
    """
    df = fs / x.size
    nh = int(max(1, min(n_harmonics, np.floor(fs / 2 * 0.9 / hi))))
    X, amp, snr, masked, score_spec = _family_spectrum(x, fs, method, nh * hi, mains_hz)
    f0 = _family_search(score_spec, df, lo, hi, nh)
    f0 = _octave_check(score_spec, df, f0, lo, nh, rpm_given, fmin)
    fr, n_lines, best = _refine(X, amp, snr, masked, df, f0, nh, method, harmonic_weight)
    return (fr, n_lines, best) if details else (fr, n_lines)


def _family_spectrum(x, fs, method, f_top, mains_hz):
    """The windowed DFT up to a little above ``f_top`` Hz, its amplitude, the line-to-floor ratio
    (dB, capped at SNR_CAP_DB), the bins next to mains harmonics and the score spectrum (clear
    lines only, mains masked)."""
    n = x.size
    df = fs / n
    xw = x - x.mean()
    if method == "hann":
        w = np.hanning(n + 1)[:-1]
        xw = xw * w
    top = min(int(np.ceil(f_top * 1.02 / df)) + 64, n // 2)
    X = _fft.rfft(xw)[: top + 2]
    amp = np.abs(X)
    snr = line_floor_db(amp, width=max(31, int(round(10.0 / df))))
    snr = np.clip(snr, 0.0, SNR_CAP_DB)
    f = np.arange(amp.size) * df
    masked = np.zeros(amp.size, bool)
    for fm in mains_hz or ():
        for m in np.arange(fm, f[-1] + fm, fm):
            masked |= np.abs(f - m) <= 1.5 * df
    # only clear lines count (>= LINE_SNR_DB): noise bins would otherwise add a
    # few dB per harmonic and a long family of noise could outscore one true line
    score_spec = np.where(masked | (snr < LINE_SNR_DB), 0.0, snr)
    return X, amp, snr, masked, score_spec


def _family_search(score_spec, df, lo, hi, nh):
    """The candidate f0 in [lo, hi] whose first ``nh`` harmonics score best."""
    # candidates: step so that the highest harmonic moves by at most half a bin
    step = 0.5 * df / nh
    cand = np.arange(lo, hi + step, step)
    h = np.arange(1, nh + 1)
    pos = np.rint(cand[:, None] * h[None, :] / df).astype(int)
    pos = np.clip(pos, 1, score_spec.size - 2)
    vals = np.maximum(np.maximum(score_spec[pos - 1], score_spec[pos]), score_spec[pos + 1])
    # harmonic weights 0.9**(h-1) (Hermes' compression) break the tie between a
    # lone line and its sub-harmonics in favour of the line itself
    score = (vals * 0.9 ** (h - 1)).sum(axis=1)
    # candidates within a bin of the family tie (the score takes the best of 3
    # bins): take the middle of the plateau that holds the maximum
    i_best = int(np.argmax(score))
    j = i_best
    while j + 1 < score.size and score[j + 1] >= score[i_best]:
        j += 1
    return float(0.5 * (cand[i_best] + cand[j]))


def _octave_check(score_spec, df, f0, lo, nh, rpm_given, fmin):
    """``f0 / 2`` or ``f0 / 3`` when their own odd lines are present, else ``f0``."""
    # a family of even harmonics (2 f_r next to mains, say) also scores well at 2 f_r;
    # prefer f0/d when at least half (and 3) of the first n_harmonics harmonics of f0/d
    # that are not harmonics of f0 are clear lines (a noise bin passes with chance ~3e-3;
    # a true family passes nearly all).
    for d in (2, 3):
        sub = f0 / d
        if sub < lo * (1 - 1e-9) and rpm_given:
            continue
        if sub < min(lo, fmin if fmin is not None else lo) or sub < 4 * df:
            continue
        hh = np.array([j for j in range(1, nh + 1) if j % d])
        kk = np.rint(hh * sub / df).astype(int)
        kk = kk[(kk >= 1) & (kk < score_spec.size - 1)]
        peak = np.maximum(np.maximum(score_spec[kk - 1], score_spec[kk]), score_spec[kk + 1])
        if np.count_nonzero(peak >= LINE_SNR_DB) >= max(3, 0.5 * hh.size):
            return sub
    return f0


def _refine(X, amp, snr, masked, df, f0, nh, method, harmonic_weight):
    """(f_r, lines used, best line SNR dB): every clear harmonic of ``f0`` interpolated, then the
    weighted least squares of ``f_h = h f_r`` (``f0`` and 0 lines when none stands clear)."""
    est, wts, hs, snrs = [], [], [], []
    for hh in range(1, nh + 1):
        k0 = int(round(hh * f0 / df))
        if k0 + 2 >= amp.size or k0 < 2:
            continue
        win = np.arange(max(k0 - 2, 1), min(k0 + 3, amp.size - 1))
        k = int(win[np.argmax(amp[win])])
        if masked[k] or snr[k] < LINE_SNR_DB or amp[k] < amp[k - 1] or amp[k] < amp[k + 1]:
            continue
        d = interpolated_peak(X, k, method=method)
        if abs(d) > 1:
            continue
        est.append((k + d) * df)
        wts.append(10 ** (snr[k] / 10) * float(hh) ** harmonic_weight)
        snrs.append(float(snr[k]))
        hs.append(hh)
    if not est:
        return f0, 0, 0.0
    est, wts, hs = np.array(est), np.array(wts), np.array(hs)
    good = np.ones(est.size, bool)
    for _ in range(3):
        fr = np.sum(wts[good] * est[good] / hs[good]) / np.sum(wts[good])
        new = np.abs(est - hs * fr) <= 0.5 * df
        if not new.any() or np.array_equal(new, good):
            break
        good = new
    # weighted LS of f_h = h f_r with weights SNR_h: the mean of f_h/h weighted by SNR_h h**2
    # (with harmonic_weight=2; see the docstring)
    fr = float(np.sum(wts[good] * est[good] / hs[good]) / np.sum(wts[good]))
    return fr, int(good.sum()), float(max(snrs))
