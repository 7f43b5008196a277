"""Shaft speed checked against the bearing's kinematics: never a fault comb for the shaft.

Kinematic ratios (Harris & Kotzalas 2007): 6308 BPFO = 3.0719 f_r, so BPFO/3 lies
2.4 % above f_r, inside any +-5 % prior window; MFPT BPFO = 3.245 f_r.
"""
import numpy as np
import pytest

from analysis_synth import bearing_signal
from bearing_lab import get_bearing
from bearing_lab.analysis import analyze, shaft_speed
from bearing_lab.analysis import _shaft


def _impacts_only(fr=30.0, bearing="6308", seed=0, duration=5.0):
    """Slip-free outer-race impacts and no shaft line at all (a simulation's signal)."""
    bpfo = get_bearing(bearing).fault_frequencies(fr)["bpfo"]
    return bearing_signal(bpfo, fs=20000.0, duration=duration, slip=0.0, decay=1500.0, noise=0.05, seed=seed)


def test_prior_is_not_refined_onto_bpfo_over_three():
    """The paper-slot trap: a 1800 r/min prior and a BPFO comb whose third sub-harmonic is
    30.72 Hz.  Breaking it: without the sub-multiple rule (_primitive always True) the
    estimate moves to 30.72 Hz."""
    x, fs = _impacts_only()
    sp = shaft_speed(x, fs, bearing="6308", rpm=1800)
    assert sp["status"] == "unconfirmed"
    assert sp["shaft_hz"] == 30.0
    assert any("sub-multiple" in c["note"] for c in sp["candidates"])


def test_blind_impact_comb_is_unresolved_and_read_three_ways():
    x, fs = _impacts_only()
    r = analyze(x, fs, bearing="6308")
    assert r["speed_source"] == "unresolved"
    assert r["diagnosis"] == "uncertain" and r["verdict"] == "uncertain"
    readings = {i["diagnosis"]: i["shaft_hz"] for i in r["evidence"]["interpretations"]}
    assert readings["outer_race"] == pytest.approx(30.0, rel=1e-3)
    assert set(readings) == {"outer_race", "inner_race", "ball"}


def test_blind_speed_from_the_1x_family_confirmed_by_the_fault():
    """Shaft harmonics off the mains grid plus an outer-race fault: the speed is resolved
    within 0.05 % and the fault family at that speed confirms it."""
    fr = 29.37
    bpfo = get_bearing("6205").fault_frequencies(fr)["bpfo"] * 0.995
    x, fs = bearing_signal(bpfo, shaft_hz=fr, shaft_amp=0.3, seed=2)
    sp = shaft_speed(x, fs, bearing="6205")
    assert sp["source"] == "estimated"
    assert sp["shaft_hz"] == pytest.approx(fr, rel=5e-4)
    assert "BPFO" in sp["note"]


def test_blind_fault_comb_stronger_than_the_shaft_points_to_the_shaft():
    """The MFPT trap: the BPFO comb (80 Hz) outscores the 25 Hz shaft family; the comb is
    recognised as BPFO of a shaft that has a 1x family of its own, and the slipping BPFO
    family, which survives pre-whitening, confirms that shaft."""
    fr = 24.8
    bpfo = get_bearing("MFPT").fault_frequencies(fr)["bpfo"]
    x, fs = bearing_signal(bpfo, fs=48828.0, duration=3.0, slip=0.001, decay=2500.0, f_res=9000.0, amp=3.0,
                           shaft_hz=fr, shaft_amp=0.05, noise=0.3, seed=3)
    raw = _shaft.RawLines(x, fs, top_hz=2100)
    assert raw.candidates(5, 100, count=1)[0] == pytest.approx(bpfo, rel=2e-3)  # the trap is real
    sp = shaft_speed(x, fs, bearing="MFPT")
    assert sp["source"] == "estimated"
    assert sp["shaft_hz"] == pytest.approx(fr, rel=1e-3)


def test_chance_combs_in_a_sparse_short_record_do_not_name_a_speed():
    """1 s records (1 Hz bins) with a few dozen random lines: some comb of 5 lines always
    exists somewhere in 5-100 Hz; the chance test refuses it."""
    rng = np.random.default_rng(4)
    fs = 20480.0
    t = np.arange(20480) / fs
    x = rng.normal(0, 1, t.size)
    for f in rng.uniform(20, 400, 12):
        x += 0.3 * np.cos(2 * np.pi * round(f) * t)
    sp = shaft_speed(x, fs, bearing="ZA-2115")
    assert sp["source"] == "unresolved"


def test_stored_speed_contradicted_by_the_signal():
    """A stored 1500 r/min while the shaft turns at 29.37 Hz (1762 r/min) with an outer-race
    fault: the prior is marked contradicted and no fault is named at the wrong speed."""
    fr = 29.37
    bpfo = get_bearing("6205").fault_frequencies(fr)["bpfo"] * 0.995
    x, fs = bearing_signal(bpfo, shaft_hz=fr, shaft_amp=0.3, seed=2)
    r = analyze(x, fs, bearing="6205", rpm=1500, rpm_source="file")
    assert r["speed_source"] == "file" and r["speed"]["status"] == "contradicted"
    assert r["verdict"] != "diagnosed"


@pytest.mark.parametrize("hs, primitive", [([1, 2, 3, 4, 5], True), ([3, 6, 9, 12, 15], False),
                                           ([2, 4, 6, 8, 10, 3], False), ([2, 4, 6, 3, 5, 7], True)])
def test_primitive_family(hs, primitive):
    assert _shaft._primitive(hs) is primitive


def _plain_shaft(fr=29.88, n_lines=20, fs=12000.0, duration=5.0, noise=0.3, seed=5):
    """Unbalance and misalignment: shaft harmonics 1..n_lines (no impacts), white noise."""
    t = np.arange(int(duration * fs)) / fs
    rng = np.random.default_rng(seed)
    x = sum((1.0 / np.sqrt(h)) * np.cos(2 * np.pi * h * fr * t + rng.uniform(0, 2 * np.pi))
            for h in range(1, n_lines + 1))
    return x + rng.normal(0, noise, t.size), fs


def test_blind_plain_1x_family_resolves_the_speed_within_half_a_percent():
    """No fault anywhere: a rich shaft family that no envelope spectrum holds as a comb names the
    speed.  Breaking it: without the plain-family rule the speed stays unresolved."""
    x, fs = _plain_shaft()
    sp = shaft_speed(x, fs, bearing="6205")
    assert sp["source"] == "estimated", sp["note"]
    assert abs(sp["shaft_hz"] / 29.88 - 1) < 0.005
    assert "plain 1x family" in sp["note"]
    r = analyze(x, fs, bearing="6205")
    assert r["speed_source"] == "estimated" and r["verdict"] == "no fault evidence"


def test_blind_sparse_line_family_without_fault_confirmation_stays_unresolved():
    """Six weak lines of a 92 Hz comb (a healthy model's ball-pass lines at BPFO of a 30 Hz
    6308 shaft): too few for a plain 1x family, so no 5530 r/min speed is named."""
    fs, fr0 = 20000.0, 92.16
    t = np.arange(int(2 * fs)) / fs
    rng = np.random.default_rng(6)
    x = sum(0.01 * np.cos(2 * np.pi * h * fr0 * t + h) for h in (1, 2, 3, 6, 7, 18))
    x = x + rng.normal(0, 0.0098, t.size)
    sp = shaft_speed(x, fs, bearing="6308")
    assert sp["source"] == "unresolved"
    assert "too few" in sp["note"] or "comb" in sp["note"]


def test_stored_speed_is_not_contradicted_by_its_own_fault_comb(monkeypatch):
    """A blind search that resolves a family at the stored speed's BPFO (the 6308 at 30 Hz:
    92.16 Hz) leaves the stored speed unconfirmed, never contradicted.  Breaking it: without
    the own-comb check the status is 'contradicted'."""
    x, fs = _impacts_only()
    bpfo = get_bearing("6308").fault_frequencies(30.0)["bpfo"]
    fam = {"shaft_hz": bpfo, "harmonics": list(range(1, 11)), "snr_db": [20.0] * 10, "primitive": True,
           "supported": True}
    monkeypatch.setattr(_shaft, "_blind", lambda *a, **k: {"resolved": True, "family": fam, "candidates": [],
                                                           "note": ""})
    sp = shaft_speed(x, fs, bearing="6308", rpm=1800, rpm_source="file")
    assert sp["status"] == "unconfirmed" and sp["shaft_hz"] == 30.0
    assert "BPFO comb of the file speed" in sp["note"]
    assert _shaft._own_comb(get_bearing("6205"), 25.0, 29.37, 0.02) is None


def _ses_with_family(f0, key="bpfo", seed=0, with_family=True):
    """A synthetic envelope spectrum (0.1 Hz bins, exponential noise) with lines at k F (k = 1..5)
    of the 6205's ``key`` family at shaft f0, 30 dB over the floor."""
    from bearing_lab.analysis._families import CyclicSpectrum
    f = np.arange(0, 3000, 0.1)
    s = np.random.default_rng(seed).exponential(1.0, f.size)
    if with_family:
        F = get_bearing("6205").fault_frequencies(f0)[key]
        for k in range(1, 6):
            s[int(round(k * F / 0.1))] = 1000.0
    return CyclicSpectrum(f, s)


def test_only_the_pre_whitened_spectrum_confirms_a_blind_speed():
    """A BPFO family in the kurtogram band's spectrum alone does not confirm f0 (the band may
    hold discrete lines); in the pre-whitened spectrum it does.  Breaking it: letting the
    kurtogram band count confirms the speed from the first pair too."""
    g = get_bearing("6205")
    with_f, without = _ses_with_family(29.9), _ses_with_family(29.9, with_family=False)
    assert _shaft._corroborated(lambda f0: [without, with_f], g, 29.9, 0.02) is None
    assert _shaft._corroborated(lambda f0: [with_f, without], g, 29.9, 0.02) == "bpfo"
