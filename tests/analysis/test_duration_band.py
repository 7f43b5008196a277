"""The impulse duration of a comparison is measured in one band for both signals.

A duration depends on the band it is measured in (a ringing outside the band is not seen), so a
simulation compared with a recording is measured in the recording's band.
"""
import numpy as np
import pytest

from bearing_lab.analysis.measurement import measure
from bearing_lab.errors import AnalysisError
from bearing_lab.validation.rows import Tolerance

FS = 12000.0
RPM = 1797.0
BPFO = 3.5848 * RPM / 60.0                  # 6205, drive end


def _train(decay_per_s, seed=0, hz=3000.0):
    """Impacts at BPFO ringing at ``hz`` with an exponential decay, in white noise at 2 % of the peak."""
    t = np.arange(int(2.0 * FS)) / FS
    tau = t % (1 / BPFO)
    x = np.exp(-decay_per_s * tau) * np.sin(2 * np.pi * hz * tau)
    return x + np.random.default_rng(seed).normal(0, 0.02, t.size)


def _duration(x, band):
    m = measure(x, FS, bearing="6205", rpm=RPM, fault="bpfo", duration_band=band)
    return m["impulse_duration"], m["extras"]


FACTOR_2 = Tolerance("factor", 2.0, "the impulse duration's tolerance")


def test_a_signal_against_itself_passes_and_a_longer_decay_fails_in_one_band():
    rec = _train(2500.0)
    d_rec, ex = _duration(rec, "own")
    band = ex["band"]
    assert band is not None and band[0] < 3000.0 < band[1]
    assert ex["duration_band"] == band
    # 10 % level of exp(-a t): ln(10) / a (0.92 ms), within the sampling and the detector's resolution
    assert d_rec == pytest.approx(np.log(10) / 2500.0, rel=0.25)
    d_same, ex_same = _duration(_train(2500.0, seed=1), band)
    assert ex_same["duration_band"] == tuple(band)
    assert FACTOR_2.check(d_same, d_rec)
    # a 2.8 times slower decay: a duration about 2.8 times longer, outside the factor 2
    d_long, _ = _duration(_train(900.0, seed=1), band)
    assert d_long > 2.0 * d_rec and not FACTOR_2.check(d_long, d_rec), (d_long, d_rec)


def test_the_duration_band_is_the_given_one_and_bad_bands_are_named():
    x = _train(2500.0)
    _, ex = _duration(x, (2000.0, 4000.0))
    assert ex["duration_band"] == (2000.0, 4000.0)
    _, ex = _duration(x, None)
    assert ex["duration_band"] is None
    for bad in ((4000.0, 2000.0), (100.0, 7000.0), "kurtogram", (1.0,), (float("nan"), 2000.0)):
        with pytest.raises(AnalysisError, match="duration_band"):
            _duration(x, bad)
