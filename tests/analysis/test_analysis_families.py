"""Fault-family evidence: harmonics, sidebands, decoys, rivals, cage combs.

Truths are synthetic impact trains whose rates follow the kinematic formulas
(Harris & Kotzalas 2007): BPFO = Z FTF, BPFI = Z f_r - BPFO, and on the 6203
2 BSF = 3.988 f_r, 1 % from BPFI - f_r.
"""
import numpy as np
import pytest

from analysis_synth import bearing_signal
from bearing_lab import get_bearing
from bearing_lab.analysis import squared_envelope_spectrum
from bearing_lab.analysis import _families as F


def _spectrum(x, fs, band=(2000, 4000), fmax=1500):
    return F.CyclicSpectrum(*squared_envelope_spectrum(x, fs, window="hann", band=band, fmax=fmax))


def _route(x, fs, bearing, fr, **kw):
    ff = get_bearing(bearing).fault_frequencies(fr)
    cs = _spectrum(x, fs, **kw)
    fams = F.search_families(cs, ff, shaft_hz=fr)
    return F.route_verdict(fams, cs.masked(fr), shaft_hz=fr, ftf_hz=ff["ftf"]), fams


def test_decoys_keep_clear_of_every_family_window():
    fac = get_bearing("6205").frequency_factors()
    rho = F.decoy_ratios(fac, tolerance=0.02)
    assert rho.size >= 15
    for r in (fac["bpfo"], fac["bpfi"], 2 * fac["bsf"]):
        for rel in (r - 2, r - 1, r, r + 1, r + 2, r / 2, 2 * r):
            assert np.all(np.abs(rho / rel - 1) > 0.04)
    assert np.all(np.abs(rho - np.round(rho)) > 0.05)


def test_outer_race_family_detected_and_located():
    fr = 29.95
    bpfo = get_bearing("6205").fault_frequencies(fr)["bpfo"] * 0.995
    x, fs = bearing_signal(bpfo, shaft_hz=fr, shaft_amp=0.3)
    v, fams = _route(x, fs, "6205", fr)
    assert v["verdict"] == "outer_race"
    assert fams["bpfo"]["detected"] and fams["bpfo"]["harmonics"] >= 4
    assert fams["bpfo"]["measured_hz"] == pytest.approx(bpfo, rel=2e-3)
    assert fams["bpfo"]["evidence_score"] > fams["bpfo"]["decoy_max_score"]
    assert not fams["bpfi"]["detected"]


def test_noise_never_detects_a_family():
    """Gaussian noise: no family in 20 records (the thresholds are noise statistics)."""
    fr = 29.95
    ff = get_bearing("6205").fault_frequencies(fr)
    hits = 0
    for seed in range(20):
        x = np.random.default_rng(seed).normal(size=60000)
        cs = _spectrum(x, 12000.0)
        fams = F.search_families(cs, ff, shaft_hz=fr)
        hits += any(fams[k]["detected"] for k in ("bpfo", "bpfi", "bsf"))
    assert hits == 0


def _dense_spectrum(seed, fr=29.95, top=1500.0, df=0.1, density=0.5):
    """An SES-like spectrum holding strong lines at random places, `density` per Hz."""
    rng = np.random.default_rng(seed)
    f = np.arange(0, top, df)
    s = rng.rayleigh(1.0, f.size)
    for fl in rng.uniform(5, top - 5, int(density * top)):
        s[int(round(fl / df))] += rng.uniform(5, 30)
    return F.CyclicSpectrum(f, s)


def test_decoys_stop_chance_families_in_a_dense_spectrum():
    """A line every 2 Hz hands the noise rule families at any frequency; the decoys must not.

    Breaking it: without decoys (decoys=False) most of these spectra 'detect' a family."""
    fr = 29.95
    ff = get_bearing("6205").fault_frequencies(fr)
    with_decoys = without = 0
    for seed in range(20):
        cs = _dense_spectrum(seed)
        a = F.search_families(cs, ff, shaft_hz=fr)
        b = F.search_families(cs, ff, shaft_hz=fr, decoys=False)
        with_decoys += any(a[k]["detected"] for k in ("bpfo", "bpfi", "bsf"))
        without += any(b[k]["detected"] for k in ("bpfo", "bpfi", "bsf"))
    assert without >= 10
    assert with_decoys <= 2


def test_6203_inner_race_brings_no_ball_rival():
    """On the 6203, BPFI - f_r lies 1 % from 2 BSF: the inner-race family's shaft sidebands
    form a '2 BSF family' that must be explained away, not reported as a second fault."""
    fr = 29.6
    ff = get_bearing("6203").fault_frequencies(fr)
    assert abs((ff["bpfi"] - fr) / (2 * ff["bsf"]) - 1) < 0.015
    x, fs = bearing_signal(ff["bpfi"] * 0.997, mod_hz=fr, mod_depth=0.9, noise=0.2, seed=3)
    v, fams = _route(x, fs, "6203", fr)
    assert v["verdict"] == "inner_race", v
    assert fams["bpfi"]["sidebands"] >= 4


def test_two_independent_faults_make_the_route_uncertain():
    fr = 29.95
    ff = get_bearing("6205").fault_frequencies(fr)
    a, fs = bearing_signal(ff["bpfo"], noise=0.0, seed=1)
    b, _ = bearing_signal(ff["bpfi"], mod_hz=fr, f_res=3300.0, noise=0.0, seed=2)
    x = a + b + np.random.default_rng(0).normal(0, 0.3, a.size)
    v, _ = _route(x, fs, "6205", fr)
    assert v["verdict"] == "uncertain"
    assert set(v["candidates"]) == {"outer_race", "inner_race"}


@pytest.mark.parametrize("modulated, expected", [(True, "ball"), (False, "uncertain")])
def test_ball_family_needs_cage_modulation(modulated, expected):
    fr = 29.95
    ff = get_bearing("6205").fault_frequencies(fr)
    x, fs = bearing_signal(2 * ff["bsf"], mod_hz=ff["ftf"] if modulated else None, noise=0.2, seed=4)
    v, fams = _route(x, fs, "6205", fr)
    assert v["verdict"] == expected, v
    assert fams["bsf"]["detected"]


def test_cage_comb_does_not_pass_for_a_ball_family():
    """ZA-2115: 2 BSF = 18.94 FTF.  A long cage comb (a cage or a modulation at the cage
    rate) puts lines at 19 FTF, 38 FTF ...; masked as the cage's, they are no ball family."""
    fr = 2000 / 60
    ff = get_bearing("ZA-2115").fault_frequencies(fr)
    cage = ff["ftf"] * 0.995
    assert abs(2 * ff["bsf"] / ff["ftf"] - 19) < 0.1
    x, fs = bearing_signal(cage, fs=20480.0, duration=10.0, decay=300.0, f_res=6000.0, noise=0.05, seed=5)
    v, fams = _route(x, fs, "ZA-2115", fr, band=(4000, 8000), fmax=3500)
    assert fams["ftf"]["detected"]
    assert not fams["bsf"]["detected"]
    assert v["verdict"] in ("uncertain", "none") and v["candidates"] in ([], ["ball"])


def test_measure_names_a_family_frequency_only_where_the_family_is_detected():
    """An outer-race impact train plus one lone envelope line near BPFI (a rig tone): the BPFI slip window
    holds a line, but no family; measure() gives BPFO and no BPFI, and says what it saw instead."""
    from bearing_lab.analysis.measurement import measure
    fr = 29.95
    ff = get_bearing("6205").fault_frequencies(fr)
    x, fs = bearing_signal(ff["bpfo"], shaft_hz=fr, shaft_amp=0.3)
    t = np.arange(x.size) / fs
    x = x + 0.3 * (1 + np.cos(2 * np.pi * 0.997 * ff["bpfi"] * t)) * np.sin(2 * np.pi * 3000 * t)
    m = measure(x, fs, bearing="6205", rpm=60 * fr, shaft_hz=fr)
    assert abs(m["bpfo"] / ff["bpfo"] - 1) < 0.01
    assert np.isnan(m["bpfi"]) and not m["extras"]["families"]["bpfi"]["detected"]
    assert "below the detection rule" in m["extras"]["notes"]["bpfi"]
    assert m["extras"]["families"]["bpfo"]["detected"] and m["extras"]["families"]["bpfo"]["evidence_margin_score"] > 0
