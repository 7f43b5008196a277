"""The structural path's fit under sensor noise: weak impacts through a known housing resonance, in white noise.

At 900 r/min a rig's impacts are weak, and the sensor noise fills every band of the impact windows' spectrum.
A fit that compares the model's impact spectrum with the recording's without holding that background apart
finds a resonance where there is only noise; the fit must recover the resonance the impacts ring at.
"""
import numpy as np
import pytest

from bearing_lab.analysis.impacts import impact_peaks, impact_times
from bearing_lab.analysis.structural_path import Resonance, StructuralPath, fit_structural_path
from bearing_lab.bearings import get_bearing

FS = 20000.0
RPM = 900.0
PERIOD = 1.0 / get_bearing("6308").fault_frequencies(RPM / 60.0)["bpfo"]     # 46 Hz: 21.7 ms
TRUE_HZ, TRUE_ZETA = 4300.0, 0.05
#: white sensor noise RMS over the median impact peak: a 6308 stand-in at 900 r/min, 320 N, with a 3 mm
#: outer-race defect, has median impact peaks of 16.7 m s-2 through its 4.3 kHz resonance, and 0.05 g of
#: sensor noise is 0.49 m s-2 (3 %)
NOISE_OVER_PEAK = 0.03


def _impacts(n, seed):
    """Broadband impacts (a 0.1 ms burst each, flat to beyond 5 kHz) at the BPFO period, 0.5 % timing jitter."""
    rng = np.random.default_rng(seed)
    x = np.zeros(n)
    k = np.arange(40)
    burst = np.exp(-k / 2.0) * np.sin(2 * np.pi * 6000.0 * k / FS)
    t = 0.003
    while t * FS + k.size < n:
        i = int(t * FS)
        x[i:i + k.size] += burst * (1 + 0.1 * rng.standard_normal())
        t += PERIOD * (1 + 0.005 * rng.standard_normal())
    return x


def _recording(noise_over_peak, seed=2):
    clean = StructuralPath((Resonance(TRUE_HZ, TRUE_ZETA),), 1.0).apply(_impacts(int(2.0 * FS), 1), FS)
    peak = float(np.median(impact_peaks(clean, FS, impact_times(clean, FS, PERIOD), PERIOD)))
    return clean + np.random.default_rng(seed).normal(0.0, noise_over_peak * peak, clean.size)


@pytest.mark.parametrize("seed", [2, 3])
def test_the_fit_finds_the_resonance_of_weak_impacts_in_sensor_noise(seed):
    model = _impacts(int(1.0 * FS), 0)
    path = fit_structural_path(_recording(NOISE_OVER_PEAK, seed), model, FS, PERIOD)
    assert len(path.resonances) == 1, path.describe()
    r = path.resonances[0]
    assert r.frequency_hz == pytest.approx(TRUE_HZ, rel=0.03), path.describe()
    assert r.damping_ratio == pytest.approx(TRUE_ZETA, rel=0.20), path.describe()
    assert path.status == "ok", path.problems


def test_without_noise_the_same_impacts_give_the_same_resonance():
    """The control: the noise-free recording, so a failure above is the noise's doing, not the impacts'."""
    path = fit_structural_path(_recording(0.0), _impacts(int(1.0 * FS), 0), FS, PERIOD)
    r = path.resonances[0]
    assert r.frequency_hz == pytest.approx(TRUE_HZ, rel=0.03) and r.damping_ratio == pytest.approx(TRUE_ZETA, rel=0.2)
