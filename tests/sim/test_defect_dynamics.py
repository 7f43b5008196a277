"""2-D defects in the time loop: the paper's study trends that geometry and kinematics fix,
inner-race and ball defects at their kinematic frequencies, a defect off the track.

Trends that depend on how the defect's edges meet the contact (amplitude against size and
against skew) are reported by the study, not asserted.
"""
import math

import numpy as np
import pytest

from bearing_lab import get_bearing, simulate
from bearing_lab.studies.paper import PAPER_OFFSET_RATIOS, run_paper_studies


def _ses_peak(x, fs, lo, hi):
    """Frequency of the largest squared-envelope line in [lo, hi] (independent, numpy only)."""
    from scipy.signal import hilbert
    e = np.abs(hilbert(x - x.mean())) ** 2
    e = e - e.mean()
    n = 1 << int(np.ceil(np.log2(len(e) * 8)))
    spec = np.abs(np.fft.rfft(e * np.hanning(len(e)), n))
    f = np.fft.rfftfreq(n, 1 / fs)
    m = (f >= lo) & (f <= hi)
    return f[m][np.argmax(spec[m])], f, spec


@pytest.fixture(scope="module")
def studies(tmp_path_factory):
    out = tmp_path_factory.mktemp("studies")
    table = run_paper_studies(out, progress=False)
    df = table.to_dataframe()
    return out, {(r.study, r.label): r for r in df.itertuples()}


def test_study_outputs_written(studies):
    out, _ = studies
    for name in ("size", "offset", "skew", "speed", "slot", "mechanism"):
        assert (out / f"{name}.png").stat().st_size > 10_000
    assert (out / "studies.nc").is_file()
    html = (out / "index.html").read_text()
    assert "data:image/png;base64" in html and "paper: 1.00, 0.78, 0.54" in html
    assert "exit edge" in html and "No value is picked" in html


def test_slot_amplitude_depends_on_how_the_edge_impact_is_damped(studies):
    """Reported, not tuned: the slot's peak acceleration moves with the damping of the exit-edge
    impact (undamped about a third above the paper's 350 N s/m, which is above 700 N s/m)."""
    _, r = studies
    peaks = {k[1]: x.peak_acceleration for k, x in r.items() if k[0] == "slot"}
    assert len(peaks) == 5
    assert peaks["approach, 0"] > 1.2 * peaks["approach, 350 N s/m"]
    assert peaks["approach, 350 N s/m"] > peaks["approach, 700 N s/m"]


def test_duration_grows_with_size(studies):
    _, r = studies
    t = [r[("size", k)].excitation_duration for k in ("O1 1x1 mm", "O2 1x3 mm", "O3 1x6 mm")]
    assert t[0] < t[1] < t[2], t


def test_duration_falls_with_skew(studies):
    _, r = studies
    t = [r[("skew", k)].excitation_duration for k in ("θ = 0°", "θ = 30°", "θ = 60°")]
    assert t[0] > t[1] > t[2], t


def test_duration_falls_and_amplitude_grows_with_speed(studies):
    _, r = studies
    rows = [r[("speed", k)] for k in ("900 r/min", "1800 r/min", "3600 r/min")]
    t = [x.excitation_duration for x in rows]
    a = [x.peak_acceleration for x in rows]
    assert t[0] > t[1] > t[2], t
    assert a[0] < a[1] < a[2], a


def test_amplitude_falls_with_offset_but_b2_still_responds(studies):
    _, r = studies
    rows = [r[("offset", k)] for k in ("H = 0", "H = B/3", "H = B/2")]
    disp = [x.peak_displacement for x in rows]
    p2p = [x.acceleration_peak_to_peak for x in rows]
    assert disp[0] > disp[1] > disp[2], disp
    assert p2p[0] > p2p[1] > p2p[2], p2p
    healthy = simulate("paper-O1", duration=0.1, fs=100_000.0, progress=False,
                       **{"defect.offset_mm": 8.0, "output.oversample": 4})
    assert rows[2].peak_acceleration > 20 * float(np.abs(healthy.outer_ring_acc_y).max())
    # reported, not asserted: ratios against the paper's 0.78 and 0.54
    ratios = [x.peak_acceleration / rows[0].peak_acceleration for x in rows]
    print("offset acceleration ratios (ours vs paper):",
          [f"{a:.2f} vs {b:.2f}" for a, b in zip(ratios, PAPER_OFFSET_RATIOS)])


def test_defect_off_the_track_gives_the_healthy_response():
    """An outline whose every point lies 7.5-8.5 mm off the centre line (the 300 N contact
    ellipse reaches 0.9 mm) changes nothing."""
    kw = dict(duration=0.05, progress=False)
    off = simulate("paper-O1", **{"defect.offset_mm": 8.0}, **kw)
    hit = simulate("paper-O1", **kw)
    import copy
    from bearing_lab.sim import load_scene
    raw = copy.deepcopy(load_scene("paper-O1").data)
    raw["defect"] = []
    healthy = simulate(raw, **kw)
    diff = np.max(np.abs(off.outer_ring_acc_y.values - healthy.outer_ring_acc_y.values))
    assert diff < 1e-4 * np.max(np.abs(hit.outer_ring_acc_y.values))


def test_inner_race_defect_at_bpfi_with_shaft_sidebands():
    ds = simulate("cwru-ir007", duration=1.0, progress=False)
    fs = ds.attrs["sampling_rate_hz"]
    fr = 1797 / 60
    f = get_bearing("6205").fault_frequencies(fr)
    peak, freqs, spec = _ses_peak(ds.outer_ring_acc_y.values, fs, 120, 200)
    assert peak == pytest.approx(f["bpfi"], rel=5e-3)
    # modulation by the shaft turning the defect through the load zone: lines at BPFI ± f_r
    # stand well above the floor between them
    def line(fc):
        m = (freqs > fc - 1.0) & (freqs < fc + 1.0)
        return spec[m].max()
    floor = np.median(spec[(freqs > 120) & (freqs < 200)])
    assert line(f["bpfi"] - fr) > 10 * floor and line(f["bpfi"] + fr) > 10 * floor


def test_ball_defect_at_twice_bsf():
    ds = simulate("cwru-ir007", duration=1.0, progress=False, **{"defect.race": "ball"})
    fs = ds.attrs["sampling_rate_hz"]
    bsf = get_bearing("6205").fault_frequencies(1797 / 60)["bsf"]
    peak, _, _ = _ses_peak(ds.outer_ring_acc_y.values, fs, 100, 180)
    assert peak == pytest.approx(2 * bsf, rel=5e-3)


def test_two_defects_in_one_scene_double_the_impacts():
    from bearing_lab.sim import load_scene
    raw = dict(load_scene("paper-O1").data)
    d0 = dict(raw["defect"][0])
    raw["defect"] = [dict(d0, angle_deg=-20.0), dict(d0, angle_deg=20.0)]
    ds = simulate(raw, duration=0.2, progress=False)
    peak, _, _ = _ses_peak(ds.outer_ring_acc_y.values, ds.attrs["sampling_rate_hz"], 50, 120)
    assert peak == pytest.approx(92.158, rel=5e-3)  # the family still sits at BPFO
    from tests.naive import impulse_times
    # a ball meets the second defect (45 - 40) deg of cage travel after its neighbour met the
    # first, 1.2 ms, while the rings still ring from that passage: its peak depends on the
    # ringing's phase (1.8 g against 6.5 g with the half-space contact), so count impacts
    # above 20 % of the largest
    lag = math.radians(45.0 - 40.0) / (2 * math.pi * 92.158 / 8)
    t = impulse_times(ds.outer_ring_acc_y.values, ds.attrs["sampling_rate_hz"], 0.2, dead_time=0.9 * lag)
    assert abs(len(t) - 2 * 92.158 * 0.2) <= 3
    short = np.diff(t)[np.diff(t) < 0.5 / 92.158]
    assert short.size >= 15 and np.median(short) == pytest.approx(lag, rel=0.1)


def test_offset_under_axial_load_follows_the_contact_track(studies):
    """Beyond the paper: an axial force on the outer ring moves the outer contact f_o D_b sin(alpha) off the
    groove bottom (Harris: alpha = 8.22 deg at 300 N on the 6308, 1.143 mm; 6.25 deg at 100 N, 0.870 mm, for
    massless balls at rest; within 3 % here at speed under the radial load too). A centred defect is then
    missed and one at H = -B/2 struck."""
    _, r = studies
    row = {k[1]: x for k, x in r.items() if k[0] == "offset_axial"}
    assert len(row) == 9
    assert row["H = 0, 0 N axial"].outer_contact_track == 0.0
    assert row["H = 0, 300 N axial"].outer_contact_track == pytest.approx(-1.143e-3, rel=0.03)
    assert row["H = 0, 100 N axial"].outer_contact_track == pytest.approx(-0.870e-3, rel=0.05)
    base = row["H = 0, 0 N axial"].peak_acceleration
    assert row["H = 0, 300 N axial"].peak_acceleration < 0.3 * base
    assert row["H = -B/2, 300 N axial"].peak_acceleration > 2 * row["H = 0, 300 N axial"].peak_acceleration
    assert row["H = -B/2, 100 N axial"].peak_acceleration > 0.8 * base
