"""Validation case files: shipped cases load, bad cases fail with one clear line (exit 2)."""
import os
from pathlib import Path

import pytest

from bearing_lab.cli import main
from bearing_lab.compare import Tolerance
from bearing_lab.errors import ValidationCaseError
from bearing_lab.validation import (CASE_DIR, RECORDING_QUANTITIES, check_case, default_set, list_cases,
                                    load_case)

SHIPPED = ["paper", "cwru-130", "cwru-144", "cwru-234", "cwru-105", "cwru-97"]


def test_shipped_cases_load_with_a_reason_for_every_tolerance():
    cases = list_cases()
    assert set(SHIPPED) <= set(cases)
    assert "paper_reference" not in cases
    for name in SHIPPED:
        c = load_case(name)
        assert c.default, name
        assert c.tolerances, name
        for q, tol in c.tolerances.items():
            assert tol.reason.strip(), (name, q)
    assert load_case("paper").kind == "paper"
    assert load_case("paper").tolerances["excitation_period"].value == 0.5
    for name in ("cwru-130", "cwru-144", "cwru-234"):
        t = load_case(name).tolerances
        assert t["bpfo"].kind == "pct" and t["bpfo"].value == 1.0
        assert t["excitation_period"].value == 1.0
    assert "impulse_strength_ratio" in load_case("cwru-130").tolerances
    assert load_case(str(CASE_DIR / "cwru-130.toml")).name == "cwru-130"


def test_paper_reference_matches_the_kinematics():
    import tomllib
    from bearing_lab.bearings import get_bearing
    ref = tomllib.loads((CASE_DIR / "paper_reference.toml").read_text())
    ff = get_bearing("6308").fault_frequencies(30.0)
    assert ref["kinematic"]["bpfo"] == pytest.approx(ff["bpfo"], rel=1e-4)
    assert ref["kinematic"]["bpfi"] == pytest.approx(ff["bpfi"], rel=1e-4)
    assert ref["slot"]["experiment"]["excitation_period_s"] == 0.01083
    assert ref["slot"]["simulation"]["excitation_period_s"] == 0.01084
    assert ref["healthy"]["experiment"]["amplitude_g"] == 1.0
    assert ref["slot"]["experiment"]["amplitude_g"] == 60.0


def test_tolerance_rules():
    pct = Tolerance("pct", 1.0, "r")
    assert pct.check(100.9, 100.0) and not pct.check(101.1, 100.0)
    assert not pct.check(float("nan"), 100.0)
    fac = Tolerance("factor", 2.0, "r")
    assert fac.check(0.5, 1.0) and fac.check(2.0, 1.0) and not fac.check(2.1, 1.0) and not fac.check(0.49, 1.0)
    assert fac.pct == 100.0
    order = Tolerance("ordering", None, "r")
    assert order.check(3.0, 1.2) and order.check(0.1, 0.8) and not order.check(0.9, 1.1)
    with pytest.raises(ValidationCaseError, match="reason"):
        Tolerance("pct", 1.0, "  ")
    with pytest.raises(ValidationCaseError, match="kind"):
        Tolerance("percent", 1.0, "r")


def _case(tmp_path, text, name="bad.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


GOOD = '''name = "mine"
kind = "recording"
bearing = "6205"
[recording]
path = "{rec}"
channel = "DE"
[scene]
scene = "cwru-or007-6"
speed = "file"
[scene.set]
{set}
[tolerances]
bpfo = {{ pct = 1.0, reason = "{reason}" }}
'''


@pytest.mark.parametrize("fmt, match", [
    (dict(rec="x.mat", set='"load.radial_n" = 150.0', reason="ok", extra="colour = 1"), "unknown key 'colour'"),
    (dict(rec="x.mat", set='"load.radial_n" = 150.0', reason="", extra=""), "no reason"),
    (dict(rec="x.mat", set='"load.wobble" = 1.0', reason="ok", extra=""), "load.wobble"),
    (dict(rec="x.mat", set='"defect.length_mm" = -1.0', reason="ok", extra=""), "defect"),
])
def test_bad_case_files_are_refused(tmp_path, fmt, match):
    extra = fmt.pop("extra")
    p = _case(tmp_path, extra + "\n" + GOOD.format(**fmt))
    with pytest.raises(ValidationCaseError, match=match):
        load_case(p)


def test_unknown_quantity_and_unknown_case(tmp_path):
    p = _case(tmp_path, GOOD.format(rec="x.mat", set="", reason="ok").replace("bpfo =", "bpfx ="))
    with pytest.raises(ValidationCaseError, match="unknown quantity tolerances.bpfx"):
        load_case(p)
    with pytest.raises(ValidationCaseError, match="unknown validation case 'nope'.*paper"):
        load_case("nope")
    assert "impulse_strength_ratio" in RECORDING_QUANTITIES


def test_missing_recording_is_a_case_error(tmp_path):
    p = _case(tmp_path, GOOD.format(rec=str(tmp_path / "missing.mat"), set="", reason="ok"))
    c = load_case(p)
    with pytest.raises(ValidationCaseError, match="missing.mat.*not found"):
        check_case(c)


@pytest.mark.parametrize("args, match", [
    (["validate", "no-such-case"], "unknown validation case 'no-such-case'"),
    (["validate", "{missing}"], "not found"),
    (["validate", "{badscene}"], "load.wobble"),
])
def test_cli_bad_input_exits_2_with_one_line(tmp_path, capsys, args, match):
    missing = _case(tmp_path, GOOD.format(rec=str(tmp_path / "gone.mat"), set="", reason="ok"), "m.toml")
    badscene = _case(tmp_path, GOOD.format(rec="x.mat", set='"load.wobble" = 1', reason="ok"), "s.toml")
    args = [a.format(missing=missing, badscene=badscene) for a in args] + ["-o", str(tmp_path / "out"),
                                                                          "--no-progress"]
    rc = main(args)
    err = capsys.readouterr().err.strip()
    assert rc == 2
    assert len(err.splitlines()) == 1, err
    assert err.startswith("bearing-lab validate: error:")
    assert match in err
    index = (tmp_path / "out" / "index.html").read_text()   # the run still leaves its index
    assert "error" in index


@pytest.mark.parametrize("scale", ["0.0", "nan", "-1e6", "1e300", "inf", '"2"'])
def test_calibration_scale_refused(tmp_path, scale):
    """recording.scale 0, NaN, -1e6 and 1e300 were accepted (0 and NaN ended as ERROR, exit 0)."""
    text = GOOD.format(rec="x.mat", set="", reason="ok").replace('channel = "DE"',
                                                                 f'channel = "DE"\nscale = {scale}')
    with pytest.raises(ValidationCaseError, match=r"recording.scale = .*between 1e-06 and 1e\+06"):
        load_case(_case(tmp_path, text))


def test_calibration_bounds_checked(tmp_path):
    text = GOOD.format(rec="x.mat", set="", reason="ok") + "[calibration]\nfrequency_hz = [5400.0, 1000.0]\n"
    with pytest.raises(ValidationCaseError, match=r"calibration.frequency_hz = \[5400.0, 1000.0\]"):
        load_case(_case(tmp_path, text))


def test_one_bad_case_does_not_stop_the_others(tmp_path, monkeypatch, capsys):
    """A bad case among several aborted the whole run, with no index: now it is listed, the
    others run, and the exit status says bad input."""
    from bearing_lab import validation
    ran = []

    def fake_run(case, out_dir, **kw):
        ran.append(case.name)
        return validation.CaseOutcome(case.name, case.title, "pass", rows=[{"pass": True}])

    monkeypatch.setattr(validation, "run_case", fake_run)
    monkeypatch.setattr(validation, "check_case", lambda c, mirror=None: None)
    good = _case(tmp_path, GOOD.format(rec="x.mat", set="", reason="ok"), "good.toml")
    rc = main(["validate", "no-such-case", str(good), "-o", str(tmp_path / "out"), "--no-progress"])
    assert rc == 2 and ran == ["mine"]
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "unknown validation case 'no-such-case'" in err[0]
    index = (tmp_path / "out" / "index.html").read_text()
    assert "no-such-case" in index and "mine" in index


def test_default_set_without_mirror_skips_the_recordings(tmp_path, monkeypatch):
    monkeypatch.setenv("BEARING_LAB_MIRROR", str(tmp_path / "empty"))
    monkeypatch.setenv("BEARING_LAB_DATA", str(tmp_path / "empty"))
    cases, skipped = default_set()
    assert [c.name for c in cases] == ["paper"]
    names = {s[0] for s in skipped}
    assert {"cwru-130", "cwru-144", "cwru-234", "cwru-105", "cwru-97"} <= names
    assert all("not found" in s[2] for s in skipped)


def test_default_set_with_mirror(mirror, monkeypatch):
    if mirror is None or not (Path(mirror) / "cwru" / "130_OR007@6_0.mat").is_file():
        if os.environ.get("CI", "").lower() in ("1", "true", "yes"):
            pytest.fail("BEARING_LAB_MIRROR with the CWRU records is required in CI")
        pytest.skip("no BEARING_LAB_MIRROR with the CWRU records")
    monkeypatch.setenv("BEARING_LAB_MIRROR", str(mirror))
    cases, skipped = default_set()
    assert [c.name for c in cases][0] == "paper"
    assert {"cwru-130", "cwru-144", "cwru-234", "cwru-105", "cwru-97"} <= {c.name for c in cases}
