"""The fast kurtogram's tree of bands, computed once per record and read for several band widths.

Why a module of its own: :func:`~bearing_lab.analysis.analyze` asks for the kurtogram of one record
twice (the speed search, at the band width a candidate speed needs, and the diagnosis at the
speed it settled on); :class:`KurtogramTree` keeps the record's tapered DFT and each level's
spectral kurtosis, so the second kurtogram costs only the levels the first did not reach.
:func:`~bearing_lab.analysis.fast_kurtogram` (in :mod:`._spectral`) is one tree read once.
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np
from scipy import fft as _fft

from ..errors import AnalysisError
from ._util import check_fs, check_signal

__all__ = ["Kurtogram", "KurtogramTree", "level_bands"]

Kurtogram = namedtuple("Kurtogram", ["kurtosis", "levels", "frequency", "band", "level", "kurtosis_max"])
Kurtogram.__doc__ = """Result of :func:`fast_kurtogram`.

Attributes
----------
kurtosis : 2-D array (level, frequency)
    Each cell's spectral kurtosis (excess, 0 for Gaussian noise) repeated over the finest
    frequency grid; NaN where a level was not computed (narrower than ``min_bandwidth``).
levels : 1-D array
    Level numbers 0, 1, 1.6, 2, 2.6, ... (band width fs/2**(level+1)).
frequency : 1-D array
    Centre of each grid column, Hz.
band : (low, high)
    The cell with the largest kurtosis, Hz.
level : float
    Level of that cell.
kurtosis_max : float
    Its spectral kurtosis.
"""


def level_bands(nlevel):
    """(level label, number of bands) of Antoni's 1/3-binary tree: 0, 1, 1.6, 2, 2.6, ..., nlevel.

    Level k has 2**k bands of width fs/2**(k+1); level k + 0.6 has 3 * 2**(k-1).
    """
    layout = [(0.0, 1), (1.0, 2)]
    for k in range(1, nlevel):
        layout.append((k + 0.6, 3 * 2 ** (k - 1)))
        layout.append((float(k + 1), 2 ** (k + 1)))
    return layout



def _tukey_ends(n, alpha):
    """The ramps of ``scipy.signal.windows.tukey(n, alpha)`` (its formula) as ``(slice, values)``."""
    width = int(np.floor(alpha * (n - 1) / 2.0))
    n1 = np.arange(0, width + 1, dtype=np.float64)
    n3 = np.arange(n - width - 1, n, dtype=np.float64)
    w1 = 0.5 * (1 + np.cos(np.pi * (-1 + 2.0 * n1 / alpha / (n - 1))))
    w3 = 0.5 * (1 + np.cos(np.pi * (-2.0 / alpha + 1 + 2.0 * n3 / alpha / (n - 1))))
    return (slice(0, width + 1), w1), (slice(n - width - 1, n), w3)


class KurtogramTree:
    """The record's tapered DFT and the 1/3-binary tree's levels, each level's spectral kurtosis
    computed once when first asked for: :meth:`kurtogram` for several ``min_bandwidth`` (the speed
    search's and the diagnosis's) gives what :func:`fast_kurtogram` gives, from one DFT."""

    def __init__(self, x, fs, *, nlevel=None):
        fs = check_fs(fs, func="fast_kurtogram")
        x = check_signal(x, func="fast_kurtogram", min_samples=256)
        if x.ndim != 1:
            raise AnalysisError(f"fast_kurtogram: x must be 1-D, got shape {x.shape} "
                                "(use bearing_lab.analysis.xr.fast_kurtogram for several channels)")
        n = x.size
        max_level = int(np.floor(np.log2(n))) - 7
        if nlevel is None:
            nlevel = min(max_level, 10)
        nlevel = int(nlevel)
        if not 1 <= nlevel <= max_level:
            raise AnalysisError(f"fast_kurtogram: {nlevel=} must lie between 1 and "
                                f"log2(len(x)) - 7 = {max_level} for a signal of {n} samples")
        self.fs, self.nlevel = fs, nlevel
        # The circular DFT sees the jump between the record's end and start (or a
        # taper's ramps) as an event at the record's edges; next to a strong tone it
        # gives narrow bands a spurious high kurtosis.  So: taper 5 % at each end
        # (Tukey, alpha 0.1) and measure the kurtosis on the middle 80 % only.
        y = x - x.mean()
        for sl, w in _tukey_ends(n, 0.1):  # tukey(n, 0.1) is 1 between its ramps
            y[sl] *= w
        self.X = _fft.rfft(y)
        self.layout = level_bands(nlevel)
        self._rows = {}

    def _row(self, nb):
        """Spectral kurtosis of the ``nb`` bands of one level (None: bands under 8 bins)."""
        if nb not in self._rows:
            X = self.X
            nb_total = X.size - 1  # bins 1..M, DC excluded
            m = nb_total // nb
            if m < 8:
                self._rows[nb] = None
                return None
            if nb_total % nb == 0:  # the bands tile the bins: a view, no gather
                bands = X[1:].reshape(nb, m)
            else:
                starts = 1 + (np.arange(nb) * nb_total) // nb
                bands = X[starts[:, None] + np.arange(m)[None, :]]
            c = _fft.ifft(bands, axis=-1, workers=1)
            c = c[:, int(0.1 * m): m - int(0.1 * m)]
            p = np.multiply(c.real, c.real)  # |c|^2, then |c|^4 in place: no temporaries
            p += c.imag * c.imag
            m2 = p.mean(axis=-1)
            p *= p
            with np.errstate(invalid="ignore", divide="ignore"):
                k = np.where(m2 > 0, p.mean(axis=-1) / np.where(m2 > 0, m2, 1) ** 2 - 2.0, -2.0)
            self._rows[nb] = k
        return self._rows[nb]

    def kurtogram(self, *, min_bandwidth=None, fmin=0.0):
        """:func:`fast_kurtogram` of the record with these ``min_bandwidth`` and ``fmin``."""
        fs = self.fs
        ncol = 3 * 2 ** self.nlevel
        grid = np.full((len(self.layout), ncol), np.nan)
        best = (-np.inf, None, None)
        for row, (lev, nb) in enumerate(self.layout):
            bw = fs / 2 / nb
            if min_bandwidth is not None and bw < float(min_bandwidth) and row > 0:
                continue
            k = self._row(nb)
            if k is None:
                continue
            upper = (np.arange(nb) + 1) * bw
            k = np.where(upper <= fmin, -np.inf, k)
            grid[row] = np.repeat(np.where(np.isfinite(k), k, np.nan), ncol // nb)
            i = int(np.argmax(k))
            if k[i] > best[0]:
                best = (float(k[i]), lev, (i * bw, (i + 1) * bw))
        if best[1] is None:
            raise AnalysisError(f"fast_kurtogram: no band satisfies {min_bandwidth=} Hz and {fmin=} Hz "
                                f"at fs={fs:g} Hz")
        freq = (np.arange(ncol) + 0.5) * fs / 2 / ncol
        return Kurtogram(grid, np.array([lv for lv, _ in self.layout]), freq, best[2], best[1], best[0])


