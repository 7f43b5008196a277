"""Ball faults as smeared 2 BSF hump families (kinematic ratios: 6205 at 29.7 Hz, Harris &
Kotzalas 2007: 2 BSF = 4.714 f_r = 140.0 Hz, FTF = 0.398 f_r = 11.8 Hz)."""
import numpy as np
import pytest

from analysis_synth import bearing_signal
from bearing_lab import get_bearing
from bearing_lab.analysis import analyze
from bearing_lab.analysis import pipeline
from bearing_lab.analysis._hump import hump_score

FR = 29.7
FF = get_bearing("6205").fault_frequencies(FR)
KW = dict(bearing="6205", rpm=60 * FR, rpm_source="file")


def _smeared_ball(seed=1):
    """Ball impacts at 2 BSF with 5 % random slip, modulated at FTF: no line family survives."""
    return bearing_signal(2 * FF["bsf"], slip=0.05, mod_hz=FF["ftf"], mod_depth=0.8, shaft_hz=FR, shaft_amp=0.3,
                          amp=0.5, noise=0.3, seed=seed)


@pytest.mark.parametrize("seed", [1, 2])
def test_smeared_ball_fault_is_diagnosed_from_its_humps(seed):
    x, fs = _smeared_ball(seed)
    r = analyze(x, fs, **KW)
    assert r["verdict"] == "diagnosed" and r["diagnosis"] == "ball", r["evidence"]["reason"]
    assert len(r["evidence"]["decided_by"]) >= 2
    assert "hump" in r["evidence"]["reason"]
    assert r["excitation_period_s"] == pytest.approx(1 / (2 * FF["bsf"]), rel=1e-3)  # kinematic, no line


def test_without_the_hump_detector_the_smeared_ball_is_missed(monkeypatch):
    """What the detector adds: the line families alone see nothing in this record."""
    x, fs = _smeared_ball(1)
    monkeypatch.setattr(pipeline, "apply_humps", lambda v, *a, **k: (v, {}))
    assert analyze(x, fs, **KW)["diagnosis"] != "ball"


@pytest.mark.parametrize("key, mod", [("bpfi", FR), ("bpfo", None)])
def test_smeared_race_faults_are_never_called_ball(key, mod):
    for slip in (0.01, 0.03, 0.05):
        x, fs = bearing_signal(FF[key], slip=slip, mod_hz=mod, shaft_hz=FR, shaft_amp=0.3, amp=0.5, noise=0.3,
                               seed=4)
        assert analyze(x, fs, **KW)["diagnosis"] != "ball"


def test_noise_has_no_hump_family():
    for seed in range(3):
        x = np.random.default_rng(seed).normal(0, 1, 120000)
        r = analyze(x, 12000.0, **KW)
        assert r["verdict"] == "no fault evidence", r["evidence"]["reason"]


def test_hump_score_measures_a_hump_over_its_ring():
    """A flat spectrum scores 0 dB; doubling the spectrum inside every hump window scores
    4 x 3.0 dB (four harmonics, mean over median)."""
    f = np.arange(0, 2000, 0.1)
    s = np.ones_like(f)
    kw = dict(shaft_hz=29.7, ftf_hz=11.8)
    assert hump_score(f, s, 140.0, **kw) == pytest.approx(0.0, abs=1e-9)
    for k in range(1, 5):
        s[np.abs(f - 140.0 * k) <= 1.5 * 11.8 + 0.02 * 140.0 * k] = 2.0
    assert hump_score(f, s, 140.0, **kw) == pytest.approx(4 * 10 * np.log10(2), abs=1e-6)


def test_ring_median_is_numpys_median():
    from bearing_lab.analysis import _hump
    rng = np.random.default_rng(2)
    for v in [rng.exponential(size=n) for n in (1, 2, 3, 6, 7, 1000, 12345)] + [np.array([2.0, 2.0, 1.0, 5.0])]:
        assert _hump._median(v) == float(np.median(v))
    assert np.isnan(_hump._median(np.array([1.0, np.nan, 3.0])))
