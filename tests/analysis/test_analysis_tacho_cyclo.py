"""Tacho pulses, order tracking, and the enhanced envelope spectrum against brute force."""
import numpy as np
import pytest

from bearing_lab import get_bearing
from bearing_lab.analysis import (amplitude_spectrum, analyze, enhanced_envelope_spectrum, order_track,
                                  tacho_pulses, tacho_speed)
from bearing_lab.analysis._tacho import ORDER_TRACK_VARIATION
from bearing_lab.errors import AnalysisError
from tests.naive import resample_at_angle, spectral_coherence_at


def _run_up(fs=20000.0, duration=8.0, f0=25.0, f1=35.0, seed=0):
    """A run-up f0 -> f1 Hz: angle-locked outer-race impacts of a 6308, a once-per-rev tacho."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(fs * duration)) / fs
    revs = f0 * t + 0.5 * (f1 - f0) / duration * t ** 2          # shaft angle, revolutions
    ratio = get_bearing("6308").frequency_factors()["bpfo"]
    imp_revs = np.arange(0.01, revs[-1] * ratio) / ratio          # an impact every 1/BPFO revolution
    imp_t = np.interp(imp_revs, revs, t)
    x = np.zeros(t.size)
    for tk in imp_t[imp_t < duration - 0.01]:
        i0 = int(np.ceil(tk * fs))
        tau = np.arange(i0, min(t.size, i0 + 120)) / fs - tk
        x[i0:i0 + tau.size] += np.exp(-1500 * tau) * np.sin(2 * np.pi * 3000 * tau)
    tacho = ((revs % 1.0) < 0.05).astype(float) * 5.0 + rng.normal(0, 0.05, t.size)
    return x + rng.normal(0, 0.2, t.size), tacho, fs


def test_tacho_pulses_and_speed_of_a_steady_shaft():
    fs = 10000.0
    t = np.arange(50000) / fs
    tacho = (np.sin(2 * np.pi * 24.7 * t) > 0.95).astype(float)  # TTL pulses, edges on samples
    p = tacho_pulses(tacho, fs)
    fr, per_rev, var = tacho_speed(p)
    assert fr == pytest.approx(24.7, rel=1e-4)
    assert per_rev.size == p.size - 1
    assert var < 0.25 * ORDER_TRACK_VARIATION  # steady: no order tracking


def test_tacho_refuses_a_flat_channel():
    with pytest.raises(AnalysisError, match="constant"):
        tacho_pulses(np.ones(1000), 1000.0)
    with pytest.raises(AnalysisError, match="pulses"):
        tacho_speed([0.1, 0.2])


def _angle_locked(fs=20000.0, duration=2.0, orders=(3.0, 7.0)):
    t = np.arange(int(fs * duration)) / fs
    revs = 25.0 * t + 0.5 * 10.0 / duration * t ** 2
    x = sum(np.sin(2 * np.pi * k * revs) for k in orders)
    tacho = ((revs % 1.0) < 0.05).astype(float)
    return x, tacho, fs


def test_order_tracking_turns_angle_locked_orders_into_lines():
    """Orders 3 and 7 during a 25 -> 35 Hz run-up: after tracking, lines at 3 and 7 times the
    mean speed hold nearly all the energy (they smear over 10 Hz before)."""
    x, tacho, fs = _angle_locked()
    xa, fr = order_track(x, fs, tacho_pulses(tacho, fs))
    f, a = amplitude_spectrum(xa, fs, window="hann")
    for k in (3, 7):
        i = int(np.argmin(np.abs(f - k * fr)))
        assert a[i - 2: i + 3].max() == pytest.approx(1.0, abs=0.03)
    f0, a0 = amplitude_spectrum(x, fs, window="hann")
    assert a0.max() < 0.4


def test_order_track_matches_brute_force():
    """Slowly varying orders, where linear interpolation is exact enough: the fast
    (PCHIP angle, cubic resampling) and the brute-force (linear) tracking agree."""
    x, tacho, fs = _angle_locked(orders=(1.0, 2.0))
    p = tacho_pulses(tacho, fs)
    fast, fr = order_track(x, fs, p)
    slow, fr_slow = resample_at_angle(x, fs, p)
    n = min(fast.size, slow.size)
    assert fr == pytest.approx(fr_slow, rel=1e-9)
    assert np.sqrt(np.mean((fast[:n] - slow[:n]) ** 2)) < 0.01 * np.std(slow[:n])


def test_run_up_diagnosed_only_after_order_tracking():
    """25 -> 35 Hz in 8 s: the BPFO lines smear over 40 %.  With the tacho the signal is
    order-tracked and the fault named; with only a mean speed it is not.  Breaking it:
    with order tracking disabled (ORDER_TRACK_VARIATION = inf) the first assertion fails."""
    x, tacho, fs = _run_up()
    r = analyze(x, fs, bearing="6308", tacho=tacho)
    assert r["speed_source"] == "tacho" and r["speed"]["status"] == "order-tracked"
    assert r["speed"]["min_rpm"] < 1560 and r["speed"]["max_rpm"] > 2040
    assert r["diagnosis"] == "outer_race" and r["verdict"] == "diagnosed"
    smeared = analyze(x, fs, bearing="6308", rpm=60 * r["shaft_hz"])
    assert smeared["verdict"] != "diagnosed"


@pytest.mark.parametrize("alpha", [13.0, 62.5, 180.0])
def test_ees_matches_closed_form_and_brute_force(alpha):
    """White noise amplitude-modulated at alpha with depth m has a spectral coherence of
    m / (1 + m**2 / 2) at every frequency (Antoni 2009).  The fast EES gives it within 2 %
    and equals the textbook estimate (Welch cross-spectrum of x and its frequency-shifted
    copy) within 1 %, also half a bin from the frame grid (62.5 and 180 Hz with 125 Hz bins).
    Breaking it: without the window-response correction the EES reads 9 % low there."""
    fs, m = 4000.0, 0.8
    t = np.arange(80000) / fs
    x = (1 + m * np.cos(2 * np.pi * alpha * t)) * np.random.default_rng(0).normal(size=t.size)
    a, e = enhanced_envelope_spectrum(x, fs, alpha_max=200.0, nw=32)
    k = int(np.argmin(np.abs(a - alpha)))
    assert e[k] == pytest.approx(m / (1 + m ** 2 / 2), rel=0.02)
    assert e[k] == pytest.approx(spectral_coherence_at(x, fs, a[k], 32), rel=0.01)
    assert e[k] > 4 * spectral_coherence_at(x, fs, alpha * 0.77, 32)


def test_ees_refuses_bad_arguments():
    x = np.random.default_rng(0).normal(size=4096)
    with pytest.raises(AnalysisError, match="alpha_max"):
        enhanced_envelope_spectrum(x, 1000.0, alpha_max=400.0)
    with pytest.raises(AnalysisError, match="nw"):
        enhanced_envelope_spectrum(x, 1000.0, alpha_max=100.0, nw=8)
