"""Speed sources: given, stored, estimated; an estimate that cannot tell the shaft from a fault comb stops."""
import numpy as np
import pytest
import xarray as xr

from bearing_lab.bearings import get_bearing
from bearing_lab.errors import ValidationCaseError
from bearing_lab.validation.speed import estimate_speed, resolve_speed

FS = 20000.0
RPM = 1793.0


def _outer_race_signal(seed=0, n=40000, shaft_line=True, jitter=0.0):
    """A 6308 outer-race impact train at BPFO (a comb of lines at k BPFO) plus a 1x shaft line;
    ``jitter``: relative random slip of each interval (real bearings: about 1 %)."""
    rng = np.random.default_rng(seed)
    fr = RPM / 60.0
    bpfo = get_bearing("6308").fault_frequencies(fr)["bpfo"]
    t = np.arange(n) / FS
    x = rng.normal(0, 0.5, n)
    k = np.arange(100)
    ring = 30.0 * np.exp(-k / 12.0) * np.sin(2 * np.pi * 4300 * k / FS)
    times = 0.003 + np.cumsum((1 + jitter * rng.standard_normal(int(n / FS * bpfo) + 2)) / bpfo)
    for i in (times[times < n / FS - 0.01] * FS).astype(int):
        x[i:i + 100] += ring
    if shaft_line:
        x += 0.3 * np.cos(2 * np.pi * fr * t)
    return x


def _ds(rpm=None):
    attrs = {"sampling_rate_hz": FS}
    if rpm is not None:
        attrs["shaft_speed_rpm"] = rpm
    return xr.Dataset(attrs=attrs)


def test_given_and_stored_speeds():
    x = _outer_race_signal()
    s = resolve_speed(1793.0, _ds(1800.0), x, bearing="6308", case_name="c")
    assert s.rpm == 1793.0 and "given" in s.source and "1800" in s.source
    s = resolve_speed("file", _ds(1796.0), x, bearing="6308", case_name="c")
    assert s.rpm == 1796.0 and "stored" in s.source
    with pytest.raises(ValidationCaseError, match="stores no shaft speed.*import --rpm"):
        resolve_speed("file", _ds(), x, bearing="6308", case_name="c")


def test_an_estimate_that_takes_the_bpfo_comb_for_the_shaft_stops_with_the_candidates():
    """The analysis layer's estimator, without a prior, reads the 92 Hz BPFO comb as a shaft family
    (5500 r/min); the 6308's own 29.9 Hz line makes that reading ambiguous, so the case must stop."""
    x = _outer_race_signal()
    sp = estimate_speed(x, FS, bearing="6308")
    if sp.resolved:   # a better estimator has landed: it must then have found the true speed
        assert sp.rpm == pytest.approx(RPM, rel=0.01)
        return
    assert any(c == pytest.approx(RPM, rel=0.01) for c in sp.candidates)
    with pytest.raises(ValidationCaseError, match="unresolved.*candidates"):
        resolve_speed("estimate", _ds(), x, bearing="6308", case_name="c")


def test_an_estimate_with_a_stored_prior_is_searched_near_it():
    """One shaft line is no 1x family: the stored speed is used as it is, and the source says so;
    with a shaft family near it, the family refines it."""
    x = _outer_race_signal()
    s = resolve_speed("estimate", _ds(1800.0), x, bearing="6308", case_name="c")
    assert s.resolved and s.rpm == 1800.0 and "not confirmed" in s.source
    t = np.arange(x.size) / FS
    y = x + sum(0.3 / h * np.cos(2 * np.pi * h * RPM / 60 * t + h) for h in range(2, 12))
    s = resolve_speed("estimate", _ds(1800.0), y, bearing="6308", case_name="c")
    assert s.resolved and "estimated" in s.source and s.rpm == pytest.approx(RPM, rel=5e-4)


def test_the_estimate_is_the_analysis_layers_public_estimator(monkeypatch):
    """One estimator, one set of guards: the case obeys bearing_lab.analysis.shaft_speed.
    Breaking it: an estimate_speed with an estimator of its own ignores the spy."""
    import bearing_lab.analysis as A
    calls = []

    def spy(x, fs, **kw):
        calls.append(kw)
        return {"shaft_hz": 92.0, "source": "unresolved", "status": "unresolved", "harmonics": 8,
                "note": "could be a fault comb", "candidates": [{"shaft_hz": 92.0}, {"shaft_hz": 29.9}]}
    monkeypatch.setattr(A, "shaft_speed", spy)
    with pytest.raises(ValidationCaseError, match="unresolved.*5520.0, 1794.0"):
        resolve_speed("estimate", _ds(), np.zeros(100), bearing="6308", case_name="c")
    assert calls and calls[0]["bearing"] == "6308" and calls[0]["rpm"] is None


@pytest.fixture(scope="module")
def paper_slot():
    from bearing_lab import simulate
    ds = simulate("paper-slot", duration=1.0, progress=False)
    return ds["outer_ring_acc_y"].values.astype(float), float(ds.attrs["sampling_rate_hz"]), ds


def test_paper_slot_simulation_is_never_estimated_at_its_bpfo(paper_slot):
    """The project's own simulation (6308, 1800 r/min, BPFO = 3.07 f_r, no shaft lines): the
    estimate is 1800 r/min or unresolved, never the 5530 r/min of the BPFO comb; a case with
    speed = "estimate" stops rather than simulating at a fault-family speed."""
    x, fs, ds = paper_slot
    assert float(ds.attrs["shaft_speed_rpm"]) == 1800.0
    sp = estimate_speed(x, fs, bearing="6308")
    assert (not sp.resolved) or abs(sp.rpm / 1800.0 - 1) < 0.005, sp
    assert not (sp.resolved and abs(sp.rpm / 5530.0 - 1) < 0.05)
    bare = xr.Dataset(attrs={"sampling_rate_hz": fs})
    if not sp.resolved:
        assert any(abs(c / 5530.0 - 1) < 0.01 for c in sp.candidates)  # the comb is named as a candidate
        with pytest.raises(ValidationCaseError, match="unresolved"):
            resolve_speed("estimate", bare, x, bearing="6308", case_name="c")


def test_paper_slot_with_shaft_lines_is_estimated_within_half_a_percent():
    """The paper's slot at 1660 r/min (27.67 Hz: its even harmonics stay off the 60 Hz mains
    grid that exactly 1800 r/min shares) plus a shaft family (1x..12x) and a sensor floor:
    the estimate must be the shaft, within 0.5 %, not the BPFO comb (85 Hz)."""
    from bearing_lab import simulate
    ds = simulate("paper-slot", duration=1.0, progress=False, **{"speed.rpm": 1660.0})
    x, fs = ds["outer_ring_acc_y"].values.astype(float), float(ds.attrs["sampling_rate_hz"])
    t = np.arange(x.size) / fs
    rms = float(np.std(x))
    y = x + sum(0.3 * rms / np.sqrt(h) * np.cos(2 * np.pi * 1660.0 / 60 * h * t + h) for h in range(1, 13))
    y = y + np.random.default_rng(1).normal(0, 0.1 * rms, x.size)
    sp = estimate_speed(y, fs, bearing="6308")
    assert sp.resolved, sp
    assert abs(sp.rpm / 1660.0 - 1) < 0.005, sp


def test_a_stored_prior_the_signal_contradicts_stops_the_case():
    """A stored 1500 r/min while the signal's own 1x family (confirmed by its BPFO family) is at
    1793 r/min: the case stops with both speeds as candidates."""
    fr = RPM / 60.0
    t = np.arange(200000) / FS
    x = _outer_race_signal(n=200000, jitter=0.01) + sum(0.3 / h * np.cos(2 * np.pi * h * fr * t + h)
                                                          for h in range(1, 12))
    with pytest.raises(ValidationCaseError, match="unresolved.*1500"):
        resolve_speed("estimate", _ds(1500.0), x, bearing="6308", case_name="c")


def test_an_impact_comb_without_any_shaft_line_is_not_read_as_a_fast_shaft():
    x = _outer_race_signal(shaft_line=False)
    sp = estimate_speed(x, FS, bearing="6308")
    assert not sp.resolved or sp.rpm == pytest.approx(RPM, rel=0.01)
    if not sp.resolved:
        assert any(c == pytest.approx(RPM, rel=0.01) for c in sp.candidates)


def test_a_plain_shaft_family_is_resolved():
    """Harmonics 1x..8x of 24.37 Hz (off the 50 and 60 Hz mains grids) and no impacts: a plain
    1x family, resolved within 0.1 %."""
    t = np.arange(40000) / FS
    x = sum(np.cos(2 * np.pi * h * 24.37 * t + h) / h for h in range(1, 9))
    x = x + np.random.default_rng(0).normal(0, 0.3, t.size)
    sp = estimate_speed(x, FS, bearing="6308")
    assert sp.resolved and sp.rpm == pytest.approx(24.37 * 60, rel=1e-3)
