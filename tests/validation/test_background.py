"""The background model: tones and noise level measured on a signal whose background is known, the
defect's own harmonics left out, the synthesis reproducing what was measured."""
import doctest
import importlib

import numpy as np
import pytest

from bearing_lab.analysis.background import estimate_background
from bearing_lab.analysis.impacts import impact_times

FS = 20000.0
TONES = [(29.88, 0.3), (50.0, 0.5), (315.0, 0.2)]          # Hz, m s-2 (amplitude)
NOISE = 0.4                                                # m s-2 RMS, white


def _signal(seed=0, impacts=True, n=40000, rate=91.8):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    x = sum(a * np.cos(2 * np.pi * f * t + 1.0) for f, a in TONES) + rng.normal(0, NOISE, n)
    if impacts:
        k = np.arange(200)
        ring = 20.0 * np.exp(-k / 20.0) * np.sin(2 * np.pi * 4300 * k / FS)
        for i in (np.arange(0.002, n / FS - 0.02, 1 / rate) * FS).astype(int):
            x[i:i + 200] += ring
    return x


def test_tones_and_noise_of_a_known_background_between_impacts():
    x = _signal()
    rate = 91.8
    times = impact_times(x, FS, 1 / rate)
    bg = estimate_background(x, FS, times=times, period=1 / rate, exclude_hz=[rate], shaft_hz=29.88)
    found = {round(f): a for f, a, _ in bg.tones}
    for f, a in TONES:
        assert found[round(f)] == pytest.approx(a, rel=0.05), (f, found)
    # the impact train's own harmonics (k x 91.8 Hz, strong in the spectrum) are not machine tones
    assert not any(abs(f / rate - round(f / rate)) * rate < 1.0 for f, _, _ in bg.tones if f > 80)
    assert bg.rms_noise == pytest.approx(NOISE, rel=0.1)
    assert bg.rms == pytest.approx(np.sqrt(NOISE ** 2 + sum(a * a / 2 for _, a in TONES)), rel=0.1)


def test_break_it_without_gating_the_impacts_inflate_the_noise():
    """The gating matters: the same record measured whole puts the impacts' energy into the 'background'."""
    x = _signal()
    whole = estimate_background(x, FS, exclude_hz=[91.8], shaft_hz=29.88)
    assert whole.rms_noise > 2 * NOISE


def test_synthesis_reproduces_the_measured_background_and_is_seeded():
    x = _signal(impacts=False)
    bg = estimate_background(x, FS)
    y = bg.synthesize(x.size, seed=3)
    assert np.std(y) == pytest.approx(np.std(x), rel=0.05)
    np.testing.assert_array_equal(y, bg.synthesize(x.size, seed=3))
    assert not np.array_equal(y, bg.synthesize(x.size, seed=4))
    back = estimate_background(y, FS)
    assert back.rms_noise == pytest.approx(bg.rms_noise, rel=0.1)
    assert bg.to_dict()["tones"][0]["frequency_hz"] == pytest.approx(29.88, abs=0.05)


@pytest.mark.parametrize("name", ["impacts", "measurement", "structural_path", "background"])
def test_docstring_examples(name):
    mod = importlib.import_module(f"bearing_lab.analysis.{name}")
    res = doctest.testmod(mod, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert res.failed == 0 and res.attempted > 0
