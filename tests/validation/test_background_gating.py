"""The rig's background is measured between impacts even when no fault was diagnosed on its own.

A recording whose impacts are too weak for the diagnosis still has them: measured over the whole
record, the "background" holds their energy, and every candidate of a comparison would carry a
floor of impact energy the recording does not have between its impacts.  The comparison times the
impacts at the declared defect race's measured fault line; the background is gated on the same
impacts.
"""
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from bearing_lab.validation.rig import _measured_background

FS = 20000.0
PERIOD = 1 / 92.0
NOISE = 0.1


def _recording(seed=3):
    rng = np.random.default_rng(seed)
    n = int(2.0 * FS)
    x = NOISE * rng.standard_normal(n)
    t = np.arange(int(0.004 * FS)) / FS
    burst = 20.0 * np.exp(-t / 0.0005) * np.sin(2 * np.pi * 4000.0 * t)   # a ringing impact, 4 kHz
    # impacts with 1 % random slip (a perfectly periodic train would be a comb of lines, not impacts)
    for k in _TRUE_TIMES:
        i = int(k * FS)
        x[i:i + burst.size] += burst
    return SimpleNamespace(x=x, fs=FS, path=Path("rig.uff"), channel="Acc")


_TRUE_TIMES = np.arange(0.003, 2.0 - 0.02, PERIOD) + 0.01 * PERIOD * np.random.default_rng(7).uniform(-1, 1, 182)


def _measured(diagnosed):
    return {"excitation_period": PERIOD if diagnosed else float("nan"), "bpfo": 1 / PERIOD, "bpfi": float("nan"),
            "extras": {"shaft_hz_used": 30.0,
                       "impact_times": _TRUE_TIMES if diagnosed else np.array([])}}


def _case(race="outer"):
    defects = [{"race": race}] if race else []
    return SimpleNamespace(section=lambda name: {}, data={"defect": defects})


def test_background_is_gated_at_the_declared_fault_line_without_a_diagnosis():
    rec = _recording()
    bg = _measured_background(_case(), rec, _measured(diagnosed=False), None)
    assert "between impacts" in bg.source and "BPFO line" in bg.source, bg.source
    assert abs(bg.rms_noise / NOISE - 1) < 0.15, bg.rms_noise
    # the same as with a diagnosed impact train
    ref = _measured_background(_case(), rec, _measured(diagnosed=True), None)
    assert abs(bg.rms_noise / ref.rms_noise - 1) < 0.1


def test_without_a_declared_race_the_whole_record_is_used_and_said():
    """Break it: with no defect declared there is no line to time the impacts at, so the background is
    the whole record -- impacts included, several times the noise -- and the source says so."""
    bg = _measured_background(_case(race=None), _recording(), _measured(diagnosed=False), None)
    assert "whole record (no impact train)" in bg.source
    assert bg.rms_noise > 3 * NOISE
