"""Spectra, pre-whitening, SES and the fast kurtogram on signals with a known answer."""
import numpy as np
import pytest
import scipy.signal

from bearing_lab.analysis import (amplitude_spectrum, bandpass, cepstral_prewhitening, envelope_band,
                                  fast_kurtogram, squared_envelope, squared_envelope_spectrum, welch_psd)
from bearing_lab.errors import AnalysisError


def test_amplitude_spectrum_reads_peak_amplitude_for_any_window():
    fs = 2000.0
    t = np.arange(4000) / fs
    x = 2.5 * np.cos(2 * np.pi * 100 * t) + 0.5
    for window in ("hann", "boxcar", "flattop"):
        f, a = amplitude_spectrum(x, fs, window=window)
        assert a[np.argmin(abs(f - 100))] == pytest.approx(2.5, rel=1e-9)
        assert a[0] == pytest.approx(0.5, rel=1e-6)


def test_amplitude_spectrum_vectorised_over_axis():
    fs = 1000.0
    t = np.arange(1000) / fs
    x = np.stack([np.cos(2 * np.pi * 50 * t), 3 * np.cos(2 * np.pi * 50 * t)])
    f, a = amplitude_spectrum(x.T, fs, window="hann", axis=0)
    assert a.shape == (f.size, 2)
    np.testing.assert_allclose(a[50], [1.0, 3.0])


def test_welch_psd_integrates_to_variance():
    x = np.random.default_rng(0).normal(0, 3.0, 100_000)
    f, p = welch_psd(x, 1000.0, window="hann", nperseg=1024)
    assert np.trapezoid(p, f) == pytest.approx(9.0, rel=0.03)


def test_prewhitening_flattens_the_spectrum_and_keeps_impulses():
    fs = 12000.0
    t = np.arange(2 ** 15) / fs
    x = 5 * np.sin(2 * np.pi * 60 * t) + np.exp(-800 * (t % 0.01)) * np.sin(2 * np.pi * 3000 * t)
    xw = cepstral_prewhitening(x)
    mag = np.abs(np.fft.rfft(xw))[1:-1]
    np.testing.assert_allclose(mag, mag[0], rtol=1e-9)
    assert xw.shape == x.shape


def test_ses_of_am_signal_has_line_at_modulation_frequency():
    fs = 10000.0
    t = np.arange(20000) / fs
    m = 1 + 0.5 * np.cos(2 * np.pi * 37 * t)
    x = m * np.cos(2 * np.pi * 2000 * t)
    se = squared_envelope(x, fs, band=(1500, 2500))
    np.testing.assert_allclose(se, m ** 2, atol=1e-9)
    f, ses = squared_envelope_spectrum(x, fs, window="boxcar", band=(1500, 2500), fmax=200)
    # (1 + 0.5 cos)^2 = 1.125 + cos + 0.125 cos(2.)
    assert ses[np.argmin(abs(f - 37))] == pytest.approx(1.0, rel=1e-6)
    assert ses[np.argmin(abs(f - 74))] == pytest.approx(0.125, rel=1e-6)
    assert ses[0] == pytest.approx(1.125, rel=1e-6)


def test_bandpass_matches_scipy_on_separated_tones():
    fs = 1000.0
    t = np.arange(1000) / fs
    y = bandpass(np.sin(2 * np.pi * 50 * t) + np.sin(2 * np.pi * 200 * t), fs, band=(100, 300))
    np.testing.assert_allclose(y, np.sin(2 * np.pi * 200 * t), atol=1e-9)
    assert np.allclose(np.abs(scipy.signal.hilbert(y)), 1.0, atol=1e-9)


def _kurtogram_signal(seed=0):
    """Impacts every 9.3 ms ringing a 4.3 kHz mode (Q ~ 20), a strong 1.2 kHz tone, white noise."""
    rng = np.random.default_rng(seed)
    fs = 24000.0
    n = 2 ** 17
    t = np.arange(n) / fs
    x = np.zeros(n)
    for tk in np.arange(0.002, t[-1] - 0.01, 0.0093):
        i0 = int(np.ceil(tk * fs))
        tau = np.arange(i0, min(n, i0 + 400)) / fs - tk
        x[i0:i0 + tau.size] += np.exp(-700 * tau) * np.sin(2 * np.pi * 4300 * tau)
    x += 3.0 * np.sin(2 * np.pi * 1200 * t) + rng.normal(0, 0.25, n)
    return x, fs


def test_fast_kurtogram_finds_the_known_best_band():
    x, fs = _kurtogram_signal()
    kg = fast_kurtogram(x, fs)
    lo, hi = kg.band
    assert lo < 4300 < hi, kg.band
    assert not (lo < 1200 < hi)
    assert hi - lo <= 3000  # a band around the resonance, not the whole spectrum
    assert kg.kurtosis_max > 1.0
    assert kg.kurtosis.shape == (kg.levels.size, kg.frequency.size)
    # the top row is the whole band, whose kurtosis is diluted by the tone and noise
    assert np.nanmax(kg.kurtosis[0]) < kg.kurtosis_max
    np.testing.assert_allclose(kg.levels[:5], [0, 1, 1.6, 2, 2.6])


def test_fast_kurtogram_of_gaussian_noise_is_near_zero():
    x = np.random.default_rng(3).normal(size=2 ** 16)
    kg = fast_kurtogram(x, 20000.0, nlevel=5)
    assert abs(kg.kurtosis_max) < 0.3


def test_fast_kurtogram_min_bandwidth_limits_levels():
    x, fs = _kurtogram_signal()
    kg = fast_kurtogram(x, fs, min_bandwidth=1000.0)
    assert kg.band[1] - kg.band[0] >= 1000.0
    assert kg.band[0] < 4300 < kg.band[1]


def test_envelope_band_finds_resonance_where_kurtosis_cannot():
    import analysis_synth
    x, fs, _ = analysis_synth.impulse_train(snr_db=-20, seed=3, duration=5.0)
    band, score = envelope_band(x, fs, frequency_range=(50, 150))
    assert band[0] <= 3000 <= band[1]
    assert score > 30


@pytest.mark.parametrize("bad, match", [
    (np.r_[np.ones(100), np.nan], "NaN"),
    (np.ones(5), "at least"),
])
def test_bad_signals_raise_analysis_error(bad, match):
    with pytest.raises(AnalysisError, match=match):
        squared_envelope_spectrum(bad, 1000.0, window="hann")


def test_missing_fs_and_window_are_named():
    with pytest.raises(AnalysisError, match="fs"):
        amplitude_spectrum(np.ones(100), None, window="hann")
    with pytest.raises(AnalysisError, match="window"):
        amplitude_spectrum(np.ones(100), 100.0, window=None)
    with pytest.raises(AnalysisError, match="invalid window"):
        amplitude_spectrum(np.ones(100), 100.0, window="hanning-ish")
    with pytest.raises(AnalysisError, match="band"):
        squared_envelope_spectrum(np.ones(100), 100.0, window="hann", band=(60, 40))
    with pytest.raises(AnalysisError, match="noverlap"):
        welch_psd(np.ones(100), 100.0, window="hann", nperseg=32, noverlap=40)
