"""Speed sources: given, stored, estimated; an estimate that cannot tell the shaft from a fault comb stops."""
import numpy as np
import pytest
import xarray as xr

from bearing_lab.bearings import get_bearing
from bearing_lab.errors import ValidationCaseError
from bearing_lab.validation.speed import estimate_speed, resolve_speed

FS = 20000.0
RPM = 1793.0


def _outer_race_signal(seed=0, n=40000, shaft_line=True):
    """A 6308 outer-race impact train at BPFO (a comb of lines at k BPFO) plus a 1x shaft line."""
    rng = np.random.default_rng(seed)
    fr = RPM / 60.0
    bpfo = get_bearing("6308").fault_frequencies(fr)["bpfo"]
    t = np.arange(n) / FS
    x = rng.normal(0, 0.5, n)
    k = np.arange(100)
    ring = 30.0 * np.exp(-k / 12.0) * np.sin(2 * np.pi * 4300 * k / FS)
    for i in (np.arange(0.003, n / FS - 0.01, 1 / bpfo) * FS).astype(int):
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
    x = _outer_race_signal()
    s = resolve_speed("estimate", _ds(1800.0), x, bearing="6308", case_name="c")
    assert s.resolved and "estimated" in s.source


def test_an_estimator_that_reports_unresolved_is_obeyed(monkeypatch):
    import bearing_lab.analysis as A

    def fake(x, fs, **kw):
        return {"shaft_hz": 92.0, "speed_source": "unresolved", "candidates": [92.0, 29.9]}
    monkeypatch.setattr(A, "shaft_frequency", fake)
    with pytest.raises(ValidationCaseError, match="unresolved"):
        resolve_speed("estimate", _ds(), np.zeros(100), bearing="6308", case_name="c")


def test_an_impact_comb_without_any_shaft_line_is_not_read_as_a_fast_shaft():
    x = _outer_race_signal(shaft_line=False)
    sp = estimate_speed(x, FS, bearing="6308")
    assert not sp.resolved or sp.rpm == pytest.approx(RPM, rel=0.01)
    if not sp.resolved:
        assert any(c == pytest.approx(RPM, rel=0.01) for c in sp.candidates)


def test_a_plain_shaft_family_is_resolved():
    t = np.arange(40000) / FS
    x = sum(np.cos(2 * np.pi * h * 29.88 * t + h) / h for h in range(1, 6))
    x = x + np.random.default_rng(0).normal(0, 0.3, t.size)
    sp = estimate_speed(x, FS, bearing="6308")
    assert sp.resolved and sp.rpm == pytest.approx(29.88 * 60, rel=1e-3)
