"""Shaft frequency: interpolated DFT on a pure tone, harmonic families, priors."""
import numpy as np
import pytest

from bearing_lab.analysis import interpolated_peak, shaft_frequency
from bearing_lab.errors import AnalysisError

FS = 20000.0
T = np.arange(200_000) / FS  # 10 s at 20 kHz: 0.1 Hz bins


@pytest.mark.parametrize("method", ["quinn", "jacobsen"])
def test_interpolated_peak_exact_for_noise_free_tone(method):
    n = 4096
    for f0 in (100.0, 100.25, 100.5, 100.77):
        x = np.cos(2 * np.pi * f0 * np.arange(n) / n + 0.3)
        X = np.fft.rfft(x)
        k = int(np.argmax(abs(X)))
        assert k + interpolated_peak(X, k, method=method) == pytest.approx(f0, abs=2e-3)


def test_interpolated_peak_hann():
    n = 4096
    x = np.cos(2 * np.pi * 100.3 * np.arange(n) / n) * np.hanning(n + 1)[:-1]
    X = np.fft.rfft(x)
    k = int(np.argmax(abs(X)))
    assert k + interpolated_peak(X, k, method="hann") == pytest.approx(100.3, abs=1e-3)


def test_pure_tone_within_2_mHz_over_10_s_at_minus_20_dB():
    """Quinn (1997) reaches ~1 mHz at -20 dB per-sample SNR; the Cramer-Rao bound is 1.2 mHz."""
    errs = []
    for seed in range(10):
        rng = np.random.default_rng(seed)
        f0 = 29.9 + rng.uniform(0, 0.1)
        x = np.sqrt(2) * np.cos(2 * np.pi * f0 * T + rng.uniform(0, 2 * np.pi))
        x = x + rng.normal(0, 10.0, T.size)  # signal power 1, noise power 100
        f, n = shaft_frequency(x, FS, window="boxcar", n_harmonics=1)
        errs.append(f - f0)
    rms = float(np.sqrt(np.mean(np.square(errs))))
    assert rms < 2e-3, errs
    assert max(abs(e) for e in errs) < 5e-3


def test_pure_tone_without_noise_is_exact():
    x = np.cos(2 * np.pi * 29.9537 * T)
    f, _ = shaft_frequency(x, FS, window="boxcar", n_harmonics=1)
    # residual bias from the tone's negative-frequency image, ~40 uHz
    assert f == pytest.approx(29.9537, abs=1e-4)


def test_harmonic_family_beats_its_octave_and_mains():
    """Weak fundamental, strong even harmonics and 60 Hz mains family: the answer is f_r."""
    rng = np.random.default_rng(1)
    fr = 29.93
    x = 0.02 * np.cos(2 * np.pi * fr * T)
    for h in range(2, 16):
        x += (0.3 if h % 2 == 0 else 0.05) / np.sqrt(h) * np.cos(2 * np.pi * h * fr * T + h)
    for h in range(1, 6):
        x += 0.5 * np.cos(2 * np.pi * 60 * h * T)
    x += rng.normal(0, 1.0, T.size)
    f, n = shaft_frequency(x, FS, window="boxcar")
    assert f == pytest.approx(fr, abs=2e-3)
    assert n >= 5


def test_prior_restricts_search():
    rng = np.random.default_rng(2)
    x = sum(np.cos(2 * np.pi * h * 24.8 * T) / h for h in range(1, 8))
    x = x + 2.0 * np.cos(2 * np.pi * 80.1 * T) + rng.normal(0, 1, T.size)
    f, _ = shaft_frequency(x, FS, window="hann", rpm=1500)
    assert f == pytest.approx(24.8, abs=5e-3)


def test_too_short_record_is_refused():
    with pytest.raises(AnalysisError, match="too short|cannot resolve|record at least"):
        shaft_frequency(np.random.default_rng(0).normal(size=2000), FS, window="boxcar")
    with pytest.raises(AnalysisError, match="window"):
        shaft_frequency(np.ones(200_000), FS, window="flattop")
