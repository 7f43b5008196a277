"""The shared-transform paths of ``analyze`` against the separate computations they replace.

``analyze`` transforms the record once and demodulates its envelope spectra from that DFT (the
band's SES from a shorter transform of its complex envelope), and reads its two kurtograms from one
tree of levels.  Each must give what the public functions give on their own, to rounding.
"""
import numpy as np
import pytest
from scipy import fft

from bearing_lab.analysis import cepstral_prewhitening, fast_kurtogram, squared_envelope_spectrum
from bearing_lab.analysis._kurtogram import KurtogramTree
from bearing_lab.analysis._spectral import Prewhitened, record_ses


def _impacts(n, fs, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    tau = t % (1 / 92.16)
    x = np.exp(-1500 * tau) * np.sin(2 * np.pi * 3000 * tau)
    return x + 0.2 * np.cos(2 * np.pi * 30 * t) + rng.normal(0, 0.5, n)


@pytest.mark.parametrize("n", [120000, 2 ** 17, 121991])  # even, a power of two, a length that pads
@pytest.mark.parametrize("band,fmax", [((2500.0, 3333.0), 1000.0),  # fmax beyond the band's width
                                       ((2500.0, 5000.0), 1000.0), (None, 900.0),
                                       ((9000.0, 10000.0), 1200.0),  # up to the Nyquist bin
                                       ((0.0, 10000.0), 500.0), ((2000.0, 4000.0), None)])
def test_record_ses_from_the_record_dft_equals_the_separate_ses(n, band, fmax):
    fs = 20000.0
    x = _impacts(n, fs)
    X = fft.rfft(x - x.mean())
    f0, s0 = squared_envelope_spectrum(x, fs, window="hann", band=band, fmax=fmax)
    f1, s1 = record_ses(x, fs, window="hann", band=band, fmax=fmax, spectrum=X)
    np.testing.assert_array_equal(f1, f0)
    # rounding only: far below every line and floor the searches read
    np.testing.assert_allclose(s1, s0, rtol=0, atol=1e-12 * s0[1:].max())
    assert s1[0] == pytest.approx(s0[0], rel=1e-12)


def test_record_ses_reads_the_known_modulation_line():
    # (1 + 0.5 cos(2 pi 10 t)) cos(2 pi 200 t): squared envelope 1.125 + cos(2 pi 10 t) + 0.125 cos(2 pi 20 t)
    fs, n = 2000.0, 20000
    t = np.arange(n) / fs
    x = (1 + 0.5 * np.cos(2 * np.pi * 10 * t)) * np.cos(2 * np.pi * 200 * t)
    f, s = record_ses(x, fs, window="hann", band=(100, 300), fmax=50, spectrum=fft.rfft(x - x.mean()))
    assert s[np.argmin(abs(f - 10))] == pytest.approx(1.0, rel=1e-9)
    assert s[np.argmin(abs(f - 20))] == pytest.approx(0.125, rel=1e-9)
    assert s[0] == pytest.approx(1.125, rel=1e-9)


def test_prewhitened_gives_the_prewhitened_signal_and_its_spectra():
    x = _impacts(50000, 20000.0)
    pw = Prewhitened(x)
    X, W, xw = pw.X, pw.W, pw.signal
    np.testing.assert_allclose(xw, cepstral_prewhitening(x), rtol=0, atol=1e-12)
    np.testing.assert_allclose(X, fft.rfft(x - x.mean()), rtol=0, atol=1e-9)
    np.testing.assert_array_equal(pw.mag, np.abs(X))
    np.testing.assert_allclose(np.abs(W[1:-1]), 1.0, rtol=1e-12)
    np.testing.assert_allclose(fft.rfft(xw)[1:], W[1:], rtol=0, atol=1e-9)


@pytest.mark.parametrize("n,read", [(120000, False), (121991, True)])  # a fast length, one that pads
def test_record_ses_reads_a_deferred_record_only_when_its_dft_cannot_serve(n, read):
    fs = 20000.0
    x = _impacts(n, fs)
    asked = []

    def record():
        asked.append(1)
        return x

    f0, s0 = squared_envelope_spectrum(x, fs, window="hann", fmax=900.0)
    f1, s1 = record_ses(record, fs, window="hann", fmax=900.0, spectrum=fft.rfft(x - x.mean()), n=n)
    assert bool(asked) == read
    np.testing.assert_array_equal(f1, f0)
    np.testing.assert_allclose(s1, s0, rtol=0, atol=1e-12 * s0[1:].max())


def test_kurtogram_tree_read_twice_equals_two_kurtograms():
    fs = 20000.0
    x = _impacts(2 ** 16, fs)
    tree = KurtogramTree(x, fs)
    for mb in (2500.0, 800.0, 5000.0, None):  # deeper, then shallower levels than already computed
        a, b = tree.kurtogram(min_bandwidth=mb), fast_kurtogram(x, fs, min_bandwidth=mb)
        np.testing.assert_array_equal(a.kurtosis, b.kurtosis)
        assert (a.band, a.level, a.kurtosis_max) == (b.band, b.level, b.kurtosis_max)
    assert tree.kurtogram(min_bandwidth=800.0, fmin=4000.0).band[1] > 4000.0


def test_spectrum_floors_of_slices_equal_the_slices_own_floors():
    from bearing_lab.analysis._speed import SpectrumFloors, line_floor_db
    X = fft.rfft(_impacts(200000, 20000.0, seed=3))
    floors = SpectrumFloors(X)
    n = X.size
    for a, b, w in ((1, n, 601), (200, n - 150, 600), (0, n // 2 + 10, 31), (5000, n - 1, 600), (10, 3000, 601)):
        np.testing.assert_array_equal(floors.snr(a, b, width=w), line_floor_db(np.abs(X[a:b]), width=w))


def test_enhanced_envelope_spectrum_equals_the_coherence_computed_whole():
    from bearing_lab.analysis import enhanced_envelope_spectrum
    fs, nw = 20000.0, 64
    x = _impacts(60000, fs)
    alpha_max = 805.0
    a, e = enhanced_envelope_spectrum(x, fs, alpha_max=alpha_max)
    # the estimator of the module docstring, every product at once
    hop = int(fs / (2 * alpha_max))
    frames = np.lib.stride_tricks.sliding_window_view(x - x.mean(), nw)[::hop]
    X = fft.rfft(frames * np.hanning(nw + 1)[:-1], axis=1)
    Xt = X / np.sqrt(np.mean(np.abs(X) ** 2, axis=0))
    n_fft = fft.next_fast_len(len(frames))
    alpha = np.arange(n_fft) * (fs / hop) / n_fft
    np.testing.assert_array_equal(a, alpha[alpha <= alpha_max])
    ref = np.zeros(a.size)
    for p in range(4):
        sel = np.flatnonzero(np.rint(a * nw / fs) == p)
        prod = Xt[:, 1 + p: nw // 2] * np.conj(Xt[:, 1: nw // 2 - p])
        Q = np.abs(fft.fft(prod, n=n_fft, axis=0))[sel]
        # the window's response |DFT of w**2| at the offset from p bins, read on a grid 64 times finer
        w2 = np.hanning(nw + 1)[:-1] ** 2
        q = np.rint(np.abs(a[sel] - p * fs / nw) / (fs / nw / 64))
        gain = np.abs(np.exp(-2j * np.pi * np.outer(q, np.arange(nw)) / (64 * nw)) @ w2) / w2.sum()
        ref[sel] = Q.mean(axis=1) / len(frames) / gain
    np.testing.assert_allclose(e, ref, rtol=1e-11)


def test_window_maxima_give_the_strongest_peak_near_each_centre():
    from bearing_lab.analysis._families import CyclicSpectrum
    rng = np.random.default_rng(4)
    f = np.arange(20000) * 0.05
    cs = CyclicSpectrum(f, rng.exponential(size=f.size) * (1 + 30 * (rng.random(f.size) < 0.01))).masked(7.3)
    centres = rng.uniform(0, f[-1], 3000)
    k0 = np.rint(centres / cs.df).astype(int)
    for h in (1, 2, 3, 4):
        direct = [max([cs.peak_snr[j] for j in range(k - h, k + h + 1) if 1 <= j < f.size - 1], default=0.0)
                  for k in k0]
        np.testing.assert_array_equal(cs.window_max(h)[k0], direct)
        np.testing.assert_array_equal(cs.window_max(h)[k0], cs.best(centres, h)[1])


@pytest.mark.parametrize("lines", [4, 400])  # sparse lines (few candidates scored), dense lines
def test_shaft_line_scan_scores_every_candidate_as_the_whole_grid_does(lines):
    from bearing_lab.analysis._shaft import RawLines
    fs, n = 5000.0, 100000
    rng = np.random.default_rng(lines)
    t = np.arange(n) / fs
    x = rng.normal(0, 1.0, n) + sum(np.cos(2 * np.pi * rng.uniform(5, 2000) * t) for _ in range(lines))
    x += sum(0.5 / h * np.cos(2 * np.pi * 24.7 * h * t) for h in range(1, 12))
    raw = RawLines(x, fs, top_hz=2100.0)
    for lo, hi in ((5.0, 100.0), (23.0, 26.0)):
        cand, score = raw.scan(lo, hi)
        nh = raw.n_harmonics(hi)
        h = np.arange(1, nh + 1)
        pos = np.clip(np.rint(cand[:, None] * h / raw.df).astype(int), 1, raw.clear.size - 2)
        np.testing.assert_array_equal(score, (raw.clear3[pos] * 0.9 ** (h - 1)).sum(axis=1))
        assert abs(cand[np.argmax(score)] - 24.7) < 2 * raw.df
