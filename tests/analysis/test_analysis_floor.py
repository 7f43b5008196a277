"""The measurability floor (1 mg over 10 kHz): a noise-free healthy model is no fault evidence."""
import numpy as np
import pytest

from bearing_lab.analysis import analyze
from bearing_lab.analysis._floor import FLOOR_MS2, band_rms, floor_in_units


@pytest.fixture(scope="module")
def healthy():
    from bearing_lab import simulate
    ds = simulate("paper-healthy", duration=1.0, progress=False)
    return ds["outer_ring_acc_y"].values.astype(float), float(ds.attrs["sampling_rate_hz"]), ds


def test_floor_in_units():
    """1 mg over 10 kHz (10 ug per root hertz), white: 0.316 mg in a 1 kHz band."""
    assert floor_in_units("m s-2") == pytest.approx(0.00980665)
    assert floor_in_units("g") == pytest.approx(0.001)
    assert floor_in_units("g", 1000.0) == pytest.approx(0.001 / np.sqrt(10))
    assert floor_in_units("m") is None and floor_in_units("no such unit") is None


def test_band_rms_is_parseval():
    fs = 1000.0
    t = np.arange(10000) / fs
    x = np.sin(2 * np.pi * 100 * t) + 0.5 * np.sin(2 * np.pi * 300 * t)
    assert band_rms(x, fs, None) == pytest.approx(np.sqrt(0.5 + 0.125), rel=1e-9)
    assert band_rms(x, fs, (200, 400)) == pytest.approx(0.5 / np.sqrt(2), rel=1e-9)


def test_noise_free_healthy_simulation_is_no_fault_evidence(healthy):
    """The healthy model's ball-entry impacts (about 0.2 mg) at BPFO: with the stored speed and
    blind, 'no fault evidence'.  Breaking it: without a floor (a unit that is not an
    acceleration) the same signal reads as an outer-race fault."""
    x, fs, ds = healthy
    assert np.std(x) < FLOOR_MS2  # the premise: the model's vibration is below 1 mg
    kw = dict(bearing=ds.attrs["bearing"])
    for rpm in (float(ds.attrs["shaft_speed_rpm"]), None):
        r = analyze(x, fs, rpm=rpm, rpm_source="file", **kw)
        assert r["verdict"] == "no fault evidence" and r["diagnosis"] == "none", r["evidence"]["reason"]
        assert "measurability floor" in r["evidence"]["reason"]
    unfloored = analyze(x, fs, rpm=float(ds.attrs["shaft_speed_rpm"]), rpm_source="file", units="V", **kw)
    assert unfloored["diagnosis"] in ("outer_race", "uncertain")  # what the floor protects against


def test_the_floor_is_an_amplitude_gate_in_the_signals_unit(healthy):
    """The floor is converted to the unit (1 mg = 0.001 g) and gates on amplitude only: the
    same record 100 times larger is measurable and the routes speak again."""
    x, fs, ds = healthy
    kw = dict(bearing=ds.attrs["bearing"], rpm=float(ds.attrs["shaft_speed_rpm"]), rpm_source="file")
    r = analyze(x / 9.80665, fs, units="g", **kw)
    b = r["evidence"]["band"]
    assert b["floor_rms"] == pytest.approx(0.001 * np.sqrt((b["high_hz"] - b["low_hz"]) / 10000.0))
    assert r["verdict"] == "no fault evidence"
    loud = analyze(100 * x, fs, **kw)
    assert loud["evidence"]["band"]["rms"] > FLOOR_MS2
    assert "measurability floor" not in loud["evidence"]["reason"]
