"""Cyclic spectral coherence and the enhanced envelope spectrum (EES).

Why: the squared envelope spectrum of one band weighs the spectrum by its
power, so a weak modulation spread over many frequencies (ball faults, whose
impacts are irregular and whose transfer paths change as the ball turns) can stay
below the floor.  The spectral *coherence* normalises every spectral frequency
by its own power; averaging its magnitude over the spectral frequencies gives
the enhanced envelope spectrum, a cyclic spectrum in which every band has the
same weight (Antoni, Xin & Hamzaoui 2017; Antoni 2009).

Estimator (the short-time Fourier transform version of Antoni et al. 2017,
"fast spectral correlation"): the record is cut into Hann-windowed frames of
``nw`` samples every ``R`` samples, with ``R <= fs / (2 alpha_max)`` so that the
frame rate resolves every cyclic frequency up to ``alpha_max``, and each
frequency bin is divided by its mean magnitude (whitening: coherence instead of
correlation).  For a shift of ``p`` bins, the product ``X(i, k + p) X*(i, k)``
oscillates over the frames at the cyclic frequency ``alpha`` of any
second-order periodicity with ``alpha`` near ``p fs / nw``; a DFT over the
frames gives it at the record's full resolution ``fs / N``.  Each cyclic
frequency takes the shift nearest to it and is corrected for the window's
response at the remaining offset ``delta = alpha - p fs / nw`` (the magnitude
of the DFT of ``w**2`` at ``delta``).  The EES is the mean over the spectral
bins (DC and Nyquist excluded) of the coherence magnitude.
"""
from __future__ import annotations

import functools

import numpy as np
from scipy import fft as _fft

from .._docdict import fill_doc
from ..errors import AnalysisError
from ._util import check_fs, check_signal

__all__ = ["enhanced_envelope_spectrum"]


@functools.lru_cache(maxsize=8)
def _window_response(nw, oversample=64):
    """|DFT of w**2| / sum(w**2) on a grid of ``nw * oversample`` points (bins of fs/nw/oversample)."""
    w = np.hanning(nw + 1)[:-1]
    w2 = w * w
    g = np.abs(np.fft.fft(w2, nw * oversample)) / w2.sum()
    return g


@fill_doc
def enhanced_envelope_spectrum(x, fs, *, alpha_max, nw=None):
    """Enhanced envelope spectrum: cyclic spectral coherence averaged over frequency.

    Parameters
    ----------
    x : array_like, 1-D
        Signal (any unit).
    %(fs)s
    alpha_max : float
        Highest cyclic frequency wanted, Hz (below fs / 4).
    nw : int, optional
        Frame length, samples (power of two).  Default: the power of two nearest
        ``fs / 350``, i.e. spectral bins about 350 Hz wide, wide enough to hold a
        structural resonance's modulation and short enough to keep the cost low.

    Returns
    -------
    alpha : ndarray
        Cyclic frequencies from 0 to ``alpha_max``, spacing about ``fs / len(x)``.
    ees : ndarray
        Mean coherence magnitude at each cyclic frequency (dimensionless, 0-1;
        ``ees[0]`` is 1 by construction).

    References
    ----------
    .. [1] Antoni, Xin & Hamzaoui, "Fast computation of the spectral correlation",
       MSSP 92 (2017) 248-277.
    .. [2] Antoni, "Cyclostationarity by examples", MSSP 23 (2009) 987-1036.
    .. [3] Smith, Borghesani, Ni, Wang & Peng, "Optimal demodulation-band selection
       for envelope-based diagnostics", MSSP 134 (2019) 106303.

    Examples
    --------
    White noise amplitude-modulated at 13 Hz: the EES peaks at 13 Hz.

    >>> import numpy as np
    >>> from bearing_lab.analysis import enhanced_envelope_spectrum
    >>> fs = 5000.0; t = np.arange(50000) / fs
    >>> x = (1 + np.cos(2 * np.pi * 13 * t)) * np.random.default_rng(0).normal(size=t.size)
    >>> a, e = enhanced_envelope_spectrum(x, fs, alpha_max=50)
    >>> round(float(a[1:][np.argmax(e[1:])]), 1)
    13.0
    """
    fs = check_fs(fs, func="enhanced_envelope_spectrum")
    x = check_signal(x, func="enhanced_envelope_spectrum", min_samples=256)
    if x.ndim != 1:
        raise AnalysisError(f"enhanced_envelope_spectrum: x must be 1-D, got shape {x.shape}")
    alpha_max = float(alpha_max)
    if not 0 < alpha_max < fs / 4:
        raise AnalysisError(f"enhanced_envelope_spectrum: alpha_max={alpha_max:g} Hz must lie between "
                            f"0 and fs/4 = {fs / 4:g} Hz")
    if nw is None:
        nw = int(2 ** np.round(np.log2(fs / 350.0)))
    nw = int(nw)
    if nw < 16 or nw > x.size // 8:
        raise AnalysisError(f"enhanced_envelope_spectrum: nw={nw} must lie between 16 and len(x)/8 = "
                            f"{x.size // 8}")
    hop = max(1, min(int(fs / (2 * alpha_max)), nw // 4))
    n_frames = (x.size - nw) // hop + 1
    n_fft = _fft.next_fast_len(n_frames)
    X = _stft(x, nw, hop, n_frames, n_fft)
    # each bin's mean power over the frames: the whitening (coherence) of the products below
    power = np.array([np.dot(v, v) for v in X[:, :n_frames].view(np.float64)]) / n_frames
    scale = np.maximum(power, power.max() * 1e-12)[1:-1]
    frame_rate = fs / hop
    alpha = np.arange(n_fft) * frame_rate / n_fft
    keep = int(np.searchsorted(alpha, alpha_max, side="right"))
    alpha = alpha[:keep]
    bin_hz = fs / nw
    shift = np.rint(alpha / bin_hz).astype(int)
    # shift p serves the run of cyclic frequencies [a, b) nearest to p bins (shift grows with alpha)
    runs = [(p, int(sel[0]), int(sel[-1]) + 1) for p in range(min(int(shift.max()) + 1, nw // 2 - 1))
            if (sel := np.flatnonzero(shift == p)).size]
    sums = _shift_sums(X[1:-1], scale, runs)  # bins 1 .. nb-2: DC and Nyquist excluded
    g = _window_response(nw)
    grid_hz = fs / (nw * 64)
    ees = np.zeros(keep)
    for p, a, b in runs:
        delta = np.abs(alpha[a:b] - p * bin_hz)
        gain = g[np.rint(delta / grid_hz).astype(int) % g.size]
        ees[a:b] = sums[p] / (scale.size - p) / n_frames / np.maximum(gain, 1e-3)
    return alpha, ees


def _stft(x, nw, hop, n_frames, n_fft, block=8192):
    """STFT of Hann-windowed frames of ``x - mean`` as columns: bins as rows ``(nw // 2 + 1, n_fft)``,
    zero beyond ``n_frames``; computed a block of frames at a time (no record-sized temporaries)."""
    frames = np.lib.stride_tricks.sliding_window_view(x - x.mean(), nw)[::hop][:n_frames]
    w = np.hanning(nw + 1)[:-1, None]
    X = np.zeros((nw // 2 + 1, n_fft), complex)
    for c in range(0, n_frames, block):
        X[:, c:min(c + block, n_frames)] = _fft.rfft(frames[c:c + block].T * w, axis=0)
    return X


def _shift_sums(X, scale, runs, block=4):
    """For each ``(p, a, b)`` of ``runs``: the sum over bins k of the magnitude of the DFT over the
    frames of the whitened products ``X[k + p] conj(X[k]) / sqrt(scale[k + p] scale[k])``, at DFT
    bins ``a .. b-1``.  The whitening is a positive factor per product, so it scales the
    magnitudes; a few bins at a time, so the products and their transforms stay in cache."""
    nr, n_fft = X.shape
    sums = {p: np.zeros(b - a) for p, a, b in runs}
    conj = np.empty((block, n_fft), complex)
    prod = np.empty((block, n_fft), complex)
    for r in range(0, nr, block):
        q = min(block, nr - r)
        np.conjugate(X[r:r + q], out=conj[:q])
        for p, a, b in runs:
            m = min(q, nr - p - r)
            if m <= 0:
                continue
            if p == 0:  # |X|^2 is real: half the transform
                P = np.abs(X[r:r + m])
                P *= P
                Q = _fft.rfft(P, axis=1, workers=1)
                wts = 1.0 / scale[r:r + m]
            else:
                Q = _fft.fft(np.multiply(X[r + p:r + p + m], conj[:m], out=prod[:m]), axis=1, overwrite_x=True,
                             workers=1)
                wts = 1.0 / np.sqrt(scale[r + p:r + p + m] * scale[r:r + m])
            sums[p] += wts @ np.abs(Q[:, a:b])
    return sums
