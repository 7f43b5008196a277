"""Spectra and envelope analysis on plain numpy arrays.

Why this module exists: bearing diagnostics by envelope analysis (Randall &
Antoni 2011) needs four steps that no established Python package does together
and correctly: an amplitude spectrum on a physical scale, optional cepstral
pre-whitening, a demodulation band chosen by spectral kurtosis (the fast
kurtogram of Antoni 2007), and the squared envelope spectrum (SES).  All are
written here as scipy.signal-style functions: arrays in, tuples out, ``fs`` and
``axis`` keywords, windows passed explicitly (``window="hann"``,
``window="boxcar"`` or an array), never chosen behind the user's back.

Band-pass filtering is done in the frequency domain (an ideal filter on the
DFT of the whole record).  That is exact for the circular record, costs one FFT
pair, and keeps the fast kurtogram a matter of reshaping one spectrum.

Units: spectra of a signal in U are in U (amplitude spectrum), U**2/Hz (PSD) and
U**2 (squared envelope spectrum); pre-whitened signals are dimensionless.
"""
from __future__ import annotations

from functools import cached_property

import numpy as np
from scipy import fft as _fft
from scipy import signal as _sig
from scipy.ndimage import median_filter

from .._docdict import fill_doc
from ..errors import AnalysisError
from ._kurtogram import Kurtogram, KurtogramTree, level_bands
from ._util import check_band, check_fs, check_signal, get_window

__all__ = ["amplitude_spectrum", "welch_psd", "cepstral_prewhitening", "bandpass", "envelope_band",
           "squared_envelope", "squared_envelope_spectrum", "fast_kurtogram", "Kurtogram"]


@fill_doc
def amplitude_spectrum(x, fs, *, window, axis=-1):
    """One-sided amplitude spectrum on a physical (peak) scale.

    A sinusoid ``A*cos(2*pi*f0*t)`` whose frequency falls on a bin reads ``A``
    at ``f0``, whatever the window (the window's coherent gain is divided out).

    Parameters
    ----------
    x : array_like
        Signal, in any unit U.
    %(fs)s
    window : str, tuple or array_like
        Window applied before the DFT (``scipy.signal.get_window`` name or an
        array of length ``x.shape[axis]``).  Required: use ``"boxcar"`` for none.
    axis : int
        Time axis.

    Returns
    -------
    f : ndarray
        Frequencies, Hz (``rfftfreq``).
    amplitude : ndarray
        Peak amplitude, in U; ``f`` replaces ``axis``.

    References
    ----------
    .. [1] Heinzel, Rüdiger & Schilling, "Spectrum and spectral density estimation by
       the DFT", MPI Garching report (2002), section 9.

    Examples
    --------
    >>> import numpy as np
    >>> from bearing_lab.analysis import amplitude_spectrum
    >>> fs = 1000.0; t = np.arange(1000) / fs
    >>> f, a = amplitude_spectrum(3.0 * np.cos(2 * np.pi * 50 * t), fs, window="hann")
    >>> float(f[np.argmax(a)]), round(float(a.max()), 6)
    (50.0, 3.0)
    """
    fs = check_fs(fs, func="amplitude_spectrum")
    x = check_signal(x, func="amplitude_spectrum", min_samples=2, axis=axis)
    x = np.moveaxis(x, axis, -1)
    n = x.shape[-1]
    w = get_window(window, n, func="amplitude_spectrum")
    spec = np.abs(_fft.rfft(x * w, axis=-1)) / w.sum()
    spec[..., 1:] *= 2.0
    if n % 2 == 0:
        spec[..., -1] /= 2.0
    return np.fft.rfftfreq(n, 1.0 / fs), np.moveaxis(spec, -1, axis)


@fill_doc
def welch_psd(x, fs, *, window, nperseg, noverlap=None, axis=-1):
    """Power spectral density by Welch's method, in U**2/Hz (one-sided).

    A thin, checked wrapper of :func:`scipy.signal.welch` with
    ``scaling="density"`` and linear detrending off (the mean is removed).

    Parameters
    ----------
    x : array_like
        Signal in U.
    %(fs)s
    window : str, tuple or array_like
        Segment window (required).
    nperseg : int
        Segment length, samples.
    noverlap : int, optional
        Overlap, samples (default ``nperseg // 2``).
    axis : int
        Time axis.

    Returns
    -------
    f : ndarray
        Frequencies, Hz.
    psd : ndarray
        PSD in U**2/Hz; integrating it over ``f`` gives the variance.

    References
    ----------
    .. [1] Welch, "The use of fast Fourier transform for the estimation of power
       spectra", IEEE Trans. Audio Electroacoust. 15 (1967) 70-73.

    Examples
    --------
    White noise of variance 4 sampled at 1 kHz has a flat PSD of 4/500 = 0.008 U**2/Hz:

    >>> import numpy as np
    >>> from bearing_lab.analysis import welch_psd
    >>> x = np.random.default_rng(0).normal(0, 2, 200_000)
    >>> f, p = welch_psd(x, 1000.0, window="hann", nperseg=1024)
    >>> bool(abs(np.median(p) / 0.008 - 1) < 0.05)
    True
    """
    fs = check_fs(fs, func="welch_psd")
    x = check_signal(x, func="welch_psd", min_samples=2, axis=axis)
    n = x.shape[axis]
    nperseg = int(nperseg)
    if not 2 <= nperseg <= n:
        raise AnalysisError(f"welch_psd: {nperseg=} must lie between 2 and the signal length {n}")
    if noverlap is not None and not 0 <= int(noverlap) < nperseg:
        raise AnalysisError(f"welch_psd: {noverlap=} must be at least 0 and less than {nperseg=}")
    w = get_window(window, nperseg, func="welch_psd")
    return _sig.welch(x, fs, window=w, nperseg=nperseg, noverlap=noverlap, detrend="constant",
                      scaling="density", axis=axis)


def cepstral_prewhitening(x, *, axis=-1):
    """Cepstral pre-whitening: set the real cepstrum to zero except at zero quefrency.

    Equivalent to dividing the DFT by its magnitude, ``ifft(X / |X|)``: all
    discrete (shaft, gear, mains) lines and the resonance shape are flattened so
    that impulsive content dominates (Sawalhi & Randall; Borghesani et al. 2013).

    Parameters
    ----------
    x : array_like
        Signal in any unit.
    axis : int
        Time axis.

    Returns
    -------
    xw : ndarray
        Whitened signal, dimensionless, same shape; the mean is removed.

    References
    ----------
    .. [1] Borghesani, Pennacchi, Randall, Sawalhi & Ricci, "Application of cepstrum
       pre-whitening for the diagnosis of bearing faults under variable speed
       conditions", MSSP 36 (2013) 370-384.
    .. [2] Randall & Antoni, "Rolling element bearing diagnostics - a tutorial",
       MSSP 25 (2011) 485-520.

    Examples
    --------
    >>> import numpy as np
    >>> from bearing_lab.analysis import cepstral_prewhitening
    >>> x = np.random.default_rng(1).normal(size=4096)
    >>> xw = cepstral_prewhitening(x)
    >>> spec = np.abs(np.fft.rfft(xw))
    >>> bool(np.allclose(spec[1:-1], spec[1]))
    True
    """
    x = check_signal(x, func="cepstral_prewhitening", min_samples=4, axis=axis)
    n = x.shape[axis]
    # x is real: the half spectrum (rfft) and its inverse give what the whole one gives
    return _fft.irfft(whitened_spectrum(_fft.rfft(x - x.mean(axis=axis, keepdims=True), axis=axis), axis=axis),
                      n=n, axis=axis)


def whitened_spectrum(X, *, axis=-1, mag=None):
    """``X / |X|`` (0 where ``|X|`` is below 1e-12 of its largest value): the DFT of the cepstrum-
    pre-whitened signal, given the DFT ``X`` of the zero-mean signal (full or half spectrum);
    ``mag``: ``|X|`` when the caller has it."""
    mag = np.abs(X) if mag is None else mag
    floor = 1e-12 * np.max(mag, axis=axis, keepdims=True)
    if np.all(floor == 0):
        raise AnalysisError("cepstral_prewhitening: x is constant; nothing to whiten")
    W = X / np.maximum(mag, floor)
    W[~(mag > floor)] = 0.0
    return W


class Prewhitened:
    """A 1-D record's DFT ``X = rfft(x - mean)``, ``mag = |X|``, the whitened DFT ``W`` and ``signal``,
    :func:`cepstral_prewhitening`'s result, transformed back from ``W`` only when first read."""

    def __init__(self, x):
        self.n = x.size
        self.X = _fft.rfft(x - x.mean())
        self.mag = np.abs(self.X)
        self.W = whitened_spectrum(self.X, mag=self.mag)

    @cached_property
    def signal(self):
        return _fft.irfft(self.W, n=self.n)


def record_ses(x, fs, *, window, band=None, fmax=None, spectrum=None, n=None):
    """:func:`squared_envelope_spectrum` of a checked 1-D record, demodulated from ``spectrum``, the
    record's ``rfft`` (its zero-frequency bin unused), when given and the envelope's transform has the
    record's length, else from ``x``: the record or a callable returning it (then ``n`` its length)."""
    n = x.size if n is None else int(n)
    if spectrum is None or _fft.next_fast_len(n, real=True) != n:
        return squared_envelope_spectrum(x() if callable(x) else x, fs, window=window, band=band, fmax=fmax)
    band = check_band(band, fs, func="squared_envelope")
    if window == "hann" and fmax is not None:
        out = _hann_ses_low(spectrum, n, fs, band, float(fmax))
        if out is not None:
            return out
    stand_in = np.broadcast_to(0.0, (n,))  # the band's analytic signal needs only the record's length
    return _ses_of(_analytic_band(stand_in, fs, band, n, X=spectrum), fs, window, fmax)


def _hann_ses_low(X, n, fs, band, fmax):
    """The Hann-windowed SES up to ``fmax`` from a shorter transform (None when it would not be).

    The squared envelope's DFT at lag k is the autocorrelation of the band's bins,
    ``SE[k] = sum_i Z[i + k] conj(Z[i]) / n``: it vanishes beyond the band's ``m`` bins, so the
    DFT of the squared magnitude of the band's complex envelope sampled ``L >= K + m`` times (K the
    highest lag read), times ``L / n``, is ``SE[0..K]`` without aliasing; the periodic Hann window
    is the 3-tap kernel (-1/4, 1/2, -1/4) on that DFT.  A minute at 20 kHz demodulated in a band
    of 833 Hz and read up to 1 kHz: transforms of 120 000 points instead of 1.2 M."""
    f = np.fft.rfftfreq(n, 1.0 / fs)  # increasing: the band's bins and those up to fmax are runs
    lo, hi = (1, f.size) if band is None else (max(1, f.searchsorted(band[0])), f.searchsorted(band[1], "right"))
    f = f[: int(np.searchsorted(f, fmax, side="right"))]
    K = f.size  # lags 0 .. K read (K for the window's kernel at the top bin)
    m = int(max(0, hi - lo))
    if m == 0 or K < 2:
        return None
    L = _fft.next_fast_len(max(K + m + 1, 2 * K + 2), real=True)
    if L >= n:
        return None
    Zb = np.zeros(L, complex)
    np.multiply(X[lo:hi], 2.0, out=Zb[:m])
    if n % 2 == 0 and hi - 1 == n // 2:
        Zb[m - 1] /= 2.0
    c = _fft.ifft(Zb, workers=1, overwrite_x=True)
    se = np.multiply(c.real, c.real)
    se += c.imag * c.imag
    SE = _fft.rfft(se)[: K + 1] * (L / n)
    mean = SE[0].real / n
    SE[0] = 0.0  # the mean removed
    low = np.concatenate([[np.conj(SE[1])], SE[:-2]])  # SE[k - 1], SE[-1] = conj(SE[1])
    spec = np.abs(0.5 * SE[:-1] - 0.25 * (low + SE[1:])) * (4.0 / n)
    spec[0] = mean
    return f, spec


def _analytic_band(x, fs, band, nfft, X=None):
    """Analytic signal of ``x`` band-passed to ``band`` (ideal filter), last axis; ``X``: its rfft
    of length ``nfft`` when known."""
    if X is None:
        X = _fft.rfft(x, n=nfft, axis=-1)
    f = np.fft.rfftfreq(nfft, 1.0 / fs)
    keep = np.ones(f.shape, bool) if band is None else (f >= band[0]) & (f <= band[1])
    keep[0] = False  # the analytic signal of the zero-mean part
    Z = np.zeros(x.shape[:-1] + (nfft,), dtype=complex)
    Z[..., : f.size] = np.where(keep, 2.0 * X, 0.0)
    if nfft % 2 == 0:
        Z[..., f.size - 1] /= 2.0
    return _fft.ifft(Z, axis=-1, workers=1)[..., : x.shape[-1]]


@fill_doc
def bandpass(x, fs, *, band, axis=-1):
    """Ideal (brick-wall) band-pass filter applied to the DFT of the whole record.

    Parameters
    ----------
    x : array_like
        Signal in U.
    %(fs)s
    band : (float, float)
        Pass band (low, high) in Hz, inclusive.
    axis : int
        Time axis.

    Returns
    -------
    y : ndarray
        Band-passed signal in U (zero mean).

    Examples
    --------
    >>> import numpy as np
    >>> from bearing_lab.analysis import bandpass
    >>> t = np.arange(1000) / 1000.0
    >>> y = bandpass(np.sin(2*np.pi*50*t) + np.sin(2*np.pi*200*t), 1000.0, band=(100, 300))
    >>> bool(np.allclose(y, np.sin(2*np.pi*200*t)))
    True
    """
    fs = check_fs(fs, func="bandpass")
    x = check_signal(x, func="bandpass", min_samples=4, axis=axis)
    band = check_band(band, fs, func="bandpass")
    xm = np.moveaxis(x, axis, -1)
    return np.moveaxis(_analytic_band(xm, fs, band, xm.shape[-1]).real, -1, axis)


@fill_doc
def squared_envelope(x, fs, *, band=None, prewhiten=False, axis=-1):
    """Squared envelope ``|x_a(t)|**2`` of the (band-passed) analytic signal, in U**2.

    Parameters
    ----------
    x : array_like
        Signal in U.
    %(fs)s
    band : (float, float), optional
        Demodulation band in Hz (ideal filter); None keeps (0, fs/2].
    prewhiten : bool
        Apply :func:`cepstral_prewhitening` first (the result is then dimensionless).
    axis : int
        Time axis.

    Returns
    -------
    se : ndarray
        Squared envelope, same shape as ``x``.

    Examples
    --------
    An AM carrier ``(1 + 0.5 cos(2 pi 10 t)) cos(2 pi 200 t)`` has squared envelope
    ``(1 + 0.5 cos(2 pi 10 t))**2``:

    >>> import numpy as np
    >>> from bearing_lab.analysis import squared_envelope
    >>> t = np.arange(2000) / 2000.0; m = 1 + 0.5*np.cos(2*np.pi*10*t)
    >>> se = squared_envelope(m*np.cos(2*np.pi*200*t), 2000.0, band=(100, 300))
    >>> bool(np.allclose(se, m**2))
    True
    """
    fs = check_fs(fs, func="squared_envelope")
    x = check_signal(x, func="squared_envelope", min_samples=16, axis=axis)
    band = check_band(band, fs, func="squared_envelope")
    xm = np.moveaxis(x, axis, -1)
    if prewhiten:
        xm = cepstral_prewhitening(xm, axis=-1)
    z = _analytic_band(xm, fs, band, _fft.next_fast_len(xm.shape[-1], real=True))
    return np.moveaxis(z.real ** 2 + z.imag ** 2, -1, axis)


@fill_doc
def squared_envelope_spectrum(x, fs, *, window, band=None, prewhiten=False, fmax=None, axis=-1):
    """Squared envelope spectrum (SES): amplitude spectrum of the squared envelope.

    The signal is (optionally) cepstrum pre-whitened, band-passed to ``band``
    with an ideal filter, demodulated by the analytic signal, squared, and the
    squared envelope's amplitude spectrum is taken with ``window``.  A bearing
    fault shows as lines at its fault frequency and harmonics (Randall & Antoni
    2011, section 3).  Line ``k > 0`` reads the peak amplitude of that component
    of the squared envelope; ``ses[0]`` is its mean (the band's power times 2).

    Parameters
    ----------
    x : array_like
        Signal in U.
    %(fs)s
    window : str, tuple or array_like
        Window for the squared envelope's DFT (required; ``"boxcar"`` for none,
        which is what interpolated line estimates expect).
    band : (float, float), optional
        Demodulation band, Hz.  None: the whole band (the "raw" SES).
    prewhiten : bool
        Cepstral pre-whitening first (then the SES is dimensionless).
    fmax : float, optional
        Crop the output to ``f <= fmax``.
    axis : int
        Time axis.

    Returns
    -------
    f : ndarray
        Cyclic (envelope) frequencies, Hz.
    ses : ndarray
        SES in U**2 (or 1 with ``prewhiten=True``); ``f`` replaces ``axis``.

    References
    ----------
    .. [1] Randall & Antoni, "Rolling element bearing diagnostics - a tutorial",
       MSSP 25 (2011) 485-520.
    .. [2] Smith & Randall, "Rolling element bearing diagnostics using the Case Western
       Reserve University data: a benchmark study", MSSP 64-65 (2015) 100-131.

    Examples
    --------
    A 3 kHz resonance struck every 10 ms gives SES lines at 100 Hz and harmonics:

    >>> import numpy as np
    >>> from bearing_lab.analysis import squared_envelope_spectrum
    >>> fs = 20000.0; t = np.arange(20000) / fs
    >>> x = np.exp(-800 * (t % 0.01)) * np.sin(2 * np.pi * 3000 * t)
    >>> f, ses = squared_envelope_spectrum(x, fs, window="hann", band=(2000, 4000), fmax=500)
    >>> float(f[1:][np.argmax(ses[1:])])
    100.0
    """
    fs = check_fs(fs, func="squared_envelope_spectrum")
    x = check_signal(x, func="squared_envelope_spectrum", min_samples=16, axis=axis)
    se = np.moveaxis(squared_envelope(x, fs, band=band, prewhiten=prewhiten, axis=axis), axis, -1)
    w = get_window(window, se.shape[-1], func="squared_envelope_spectrum")
    f, spec = _ses_spectrum(se, fs, w, fmax)
    return f, np.moveaxis(spec, -1, axis)


def _ses_of(z, fs, window, fmax):
    """SES of the analytic signal ``z`` (1-D), as :func:`squared_envelope_spectrum`."""
    se = z.real ** 2 + z.imag ** 2
    return _ses_spectrum(se, fs, get_window(window, se.size, func="squared_envelope_spectrum"), fmax)


def _ses_spectrum(se, fs, w, fmax):
    n = se.shape[-1]
    mean = se.mean(axis=-1, keepdims=True)
    spec = np.abs(_fft.rfft((se - mean) * w, axis=-1)) * (2.0 / w.sum())
    spec[..., 0] = mean[..., 0]
    f = np.fft.rfftfreq(n, 1.0 / fs)
    if fmax is not None:
        keep = f <= float(fmax)
        f, spec = f[keep], spec[..., keep]
    return f, spec


@fill_doc
def fast_kurtogram(x, fs, *, nlevel=None, min_bandwidth=None, fmin=0.0):
    """Fast kurtogram: spectral kurtosis over a 1/3-binary tree of frequency bands.

    Each level ``k`` splits (0, fs/2) into ``2**k`` bands (and the 1/3 levels
    ``k + 0.6`` into ``3 * 2**(k-1)``), as in Antoni (2007).  For each band the
    complex envelope ``c`` is obtained by an ideal band-pass on the record's DFT
    and an inverse DFT of the band's bins (which decimates it to the band's
    rate), and its spectral kurtosis is ``mean(|c|**4) / mean(|c|**2)**2 - 2``
    (0 for Gaussian noise, -1 for a pure tone, large for repetitive impulses).
    The band with the largest kurtosis is the one to demodulate for the SES.
    The circular DFT sees the jump between the record's end and start as an
    event at the edges, and narrow bands next to a strong tone would show a
    spurious high kurtosis: the record is tapered (Tukey, 5 % at each end) and
    the kurtosis is measured on the middle 80 % of each band's envelope.

    Parameters
    ----------
    x : array_like, 1-D
        Signal (any unit).
    %(fs)s
    nlevel : int, optional
        Deepest level.  Default ``floor(log2(len(x))) - 7`` (Antoni's rule: the
        narrowest band keeps at least ~64 complex samples), at most 10.
    min_bandwidth : float, optional
        Skip levels whose bands are narrower than this, Hz.  For envelope
        analysis the band must hold the fault's modulation sidebands, so callers
        typically pass a few times the highest fault frequency.
    fmin : float
        Ignore bands whose upper edge is below ``fmin`` Hz (e.g. to keep shaft
        and mains harmonics out).

    Returns
    -------
    Kurtogram
        namedtuple ``(kurtosis, levels, frequency, band, level, kurtosis_max)``.

    References
    ----------
    .. [1] Antoni, "Fast computation of the kurtogram for the detection of transient
       faults", MSSP 21 (2007) 108-124.
    .. [2] Antoni & Randall, "The spectral kurtosis: application to the vibratory
       surveillance and diagnostics of rotating machines", MSSP 20 (2006) 308-331.

    Examples
    --------
    Impulses ringing a 6 kHz resonance, buried in white noise: the best band
    contains 6 kHz.

    >>> import numpy as np
    >>> from bearing_lab.analysis import fast_kurtogram
    >>> fs = 20000.0; t = np.arange(2**16) / fs
    >>> x = np.exp(-1000 * (t % 0.0125)) * np.sin(2 * np.pi * 6000 * t)
    >>> x = x + np.random.default_rng(0).normal(0, 0.3, t.size)
    >>> kg = fast_kurtogram(x, fs)
    >>> bool(kg.band[0] < 6000 < kg.band[1])
    True
    """
    return KurtogramTree(x, fs, nlevel=nlevel).kurtogram(min_bandwidth=min_bandwidth, fmin=fmin)


@fill_doc
def envelope_band(x, fs, *, frequency_range, min_bandwidth=None, nlevel=None, n_harmonics=3):
    """Demodulation band chosen by the strength of a line family in its SES.

    Spectral kurtosis fails when single impacts are buried in noise (per-sample
    SNR of -20 dB): the kurtosis of every band is then near 0, yet the squared
    envelope spectrum of the right band still shows the impact rate clearly,
    because the SES integrates over all impacts.  This selector visits the
    same 1/3-binary tree as :func:`fast_kurtogram` (bands at least
    ``min_bandwidth`` wide, default ``4 * frequency_range[1]``) and keeps the
    band whose SES has the strongest family: for each band the line SNR (dB
    over a running median, clipped to 0-20 dB) is summed over the first
    ``n_harmonics`` harmonics of the best fundamental in ``frequency_range``.
    The idea follows the "protrugram" (Barszcz & Jabłoński 2011) and SES-based
    band selection (Smith, Borghesani, Ni, Wang & Peng 2017).

    Parameters
    ----------
    x : array_like, 1-D
        Signal.
    %(fs)s
    frequency_range : (float, float)
        Where the fundamental (impact rate) may lie, Hz.
    min_bandwidth : float, optional
        Narrowest band visited, Hz.
    nlevel : int, optional
        Deepest level (default as in :func:`fast_kurtogram`).
    n_harmonics : int
        Harmonics in the family score (default 3).

    Returns
    -------
    band : (float, float)
        Chosen band, Hz.
    score : float
        Its family score, dB summed over harmonics.

    References
    ----------
    .. [1] Barszcz & Jabłoński, "A novel method for the optimal band selection for
       vibration signal demodulation and comparison with the Kurtogram", MSSP 25
       (2011) 431-451.

    Examples
    --------
    >>> import numpy as np
    >>> from bearing_lab.analysis import envelope_band
    >>> fs = 20000.0; t = np.arange(200000) / fs
    >>> x = np.exp(-1500 * (t % 0.0108509)) * np.sin(2 * np.pi * 3000 * (t % 0.0108509))
    >>> x = x + np.random.default_rng(0).normal(0, 1.0, t.size)
    >>> band, score = envelope_band(x, fs, frequency_range=(50, 150))
    >>> bool(band[0] <= 3000 <= band[1])
    True
    """
    fs = check_fs(fs, func="envelope_band")
    x = check_signal(x, func="envelope_band", min_samples=256)
    if x.ndim != 1:
        raise AnalysisError(f"envelope_band: x must be 1-D, got shape {x.shape}")
    lo, hi = float(frequency_range[0]), float(frequency_range[1])
    if not 0 < lo < hi:
        raise AnalysisError(f"envelope_band: frequency_range={frequency_range!r} must be (low, high) Hz")
    min_bw = 4 * hi if min_bandwidth is None else float(min_bandwidth)
    n = x.size
    max_level = int(np.floor(np.log2(n))) - 7
    nlevel = min(max_level, 10) if nlevel is None else int(nlevel)
    X = _fft.rfft(x - x.mean())
    nb_total = X.size - 1
    df = fs / n
    top = int(np.ceil(n_harmonics * hi * 1.01 / df)) + 2
    wfloor = max(21, int(round(10.0 / df))) | 1
    best = (-np.inf, None)
    for lev, nb in level_bands(nlevel):
        bw = fs / 2 / nb
        if bw < min_bw and nb > 1:
            continue
        m = nb_total // nb
        L = _fft.next_fast_len(max(2 * m, 2 * top + 2))
        starts = 1 + (np.arange(nb) * nb_total) // nb
        idx = starts[:, None] + np.arange(m)[None, :]
        c = _fft.ifft(X[idx], n=L, axis=-1)
        se = c.real ** 2 + c.imag ** 2
        S = np.abs(_fft.rfft(se - se.mean(axis=-1, keepdims=True), axis=-1))
        # the padded envelope has L samples over the record: bin spacing is still df
        S = S[:, : min(S.shape[-1], top + wfloor)]
        fl = median_filter(S, size=(1, wfloor), mode="nearest")
        snr = np.clip(20 * np.log10(np.maximum(S, 1e-300) / np.maximum(fl, 1e-300)), 0, 20)
        k_lo, k_hi = int(np.floor(lo / df)), int(np.ceil(hi / df))
        cand = np.arange(max(k_lo, 1), k_hi + 1)
        score = np.zeros((nb, cand.size))
        for h in range(1, n_harmonics + 1):
            pos = np.clip(np.rint(h * cand).astype(int), 1, S.shape[-1] - 2)
            score += np.maximum(np.maximum(snr[:, pos - 1], snr[:, pos]), snr[:, pos + 1])
        i, j = np.unravel_index(int(np.argmax(score)), score.shape)
        if score[i, j] > best[0]:
            s0 = starts[i] * df
            best = (float(score[i, j]), (s0, s0 + m * df))
    if best[1] is None:
        raise AnalysisError(f"envelope_band: no band is at least {min_bw:g} Hz wide at fs={fs:g} Hz")
    return best[1], best[0]
