"""Case files: shipped cases load from package data; every key is documented; bad cases fail with one line."""
import os
import re
import tomllib
from pathlib import Path

import pytest

from bearing_lab.cli import main
from bearing_lab.errors import ValidationCaseError
from bearing_lab.validation import QUANTITIES, check_case, default_set, load_case, shipped_cases
from bearing_lab.validation.case import CASE_KEYS

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = ["paper", "cwru-130", "cwru-144", "cwru-234", "cwru-105", "cwru-97"]

GOOD = '''name = "mine"
bearing = "6308"
speed = 1793.0
{top}
[recording]
file = "{rec}"
{rec_extra}
[load]
radial_n = 320.0

[[defect]]
race = "outer"
length_mm = 3.0
width_mm = 1.0
{tail}
[tolerances]
bpfo = {tol}
'''


def _case(tmp_path, name="c.toml", rec="rig.uff", top="", rec_extra="", tail="", tol="{}"):
    p = tmp_path / name
    p.write_text(GOOD.format(rec=rec, top=top, rec_extra=rec_extra, tail=tail, tol=tol))
    return p


def test_shipped_cases_are_package_data_with_reasons():
    cases = shipped_cases()
    assert set(SHIPPED) <= set(cases)
    assert "paper_reference" not in cases
    for name in SHIPPED:
        c = load_case(name)
        assert c.default and c.tolerances, name
        assert all(t.reason.strip() for t in c.tolerances.values()), name
        assert c.source == f"shipped case {name}"
    assert load_case("paper").tolerances["excitation_period"].value == 0.5
    for name in ("cwru-130", "cwru-144", "cwru-234"):
        t = load_case(name).tolerances
        assert t["bpfo"].kind == "pct" and t["bpfo"].value == 1.0 and t["excitation_period"].value == 1.0
    # ratios are compared with a tolerance, never by their ordering
    assert load_case("cwru-130").tolerances["impulse_strength_ratio"].kind == "factor"


def test_no_process_language_in_the_shipped_cases():
    for name, p in shipped_cases().items():
        text = p.read_text()
        assert not re.search(r"issue \d|HOOK|not available yet|reference\.md|paper\.md|contract\.md", text), name
    ref = (ROOT / "bearing_lab" / "validation" / "cases" / "paper_reference.toml").read_text()
    assert "reference.md" not in ref and "paper.md" not in ref


def test_paper_reference_matches_the_kinematics():
    from bearing_lab.bearings import get_bearing
    ref = tomllib.loads((ROOT / "bearing_lab" / "validation" / "cases" / "paper_reference.toml").read_text())
    ff = get_bearing("6308").fault_frequencies(30.0)   # Harris & Kotzalas rolling kinematics
    assert ref["kinematic"]["bpfo"] == pytest.approx(ff["bpfo"], rel=1e-4)
    assert ref["kinematic"]["bpfi"] == pytest.approx(ff["bpfi"], rel=1e-4)
    assert ref["slot"]["experiment"]["excitation_period_s"] == 0.01083
    assert ref["healthy"]["experiment"]["shaft_hz"] == 29.69


def test_every_case_key_is_documented():
    doc = (ROOT / "docs" / "case-format.md").read_text()
    for section, keys in CASE_KEYS.items():
        if section:
            assert f"[{section}]" in doc or f"[[{section}]]" in doc, section
        for k in keys:
            if k.startswith("<"):
                continue
            assert f"`{k}`" in doc, f"{section}.{k} is not in docs/case-format.md"
    vdoc = (ROOT / "docs" / "validation.md").read_text()
    for q in QUANTITIES:
        assert f"`{q}`" in vdoc, f"quantity {q} is not in docs/validation.md"


def test_a_good_case_loads_and_builds_its_scene(tmp_path):
    c = load_case(_case(tmp_path))
    assert c.speed == 1793.0 and c.recording.file == tmp_path / "rig.uff"
    from bearing_lab.validation import simulation
    scene = simulation.build_scene(c, rpm=1793.0, fs=20000.0, duration=0.1)
    assert scene.bearing.name == "6308" and len(scene.defects) == 1
    assert scene.data["load"]["on"] == "inner" and scene.data["load"]["radial_n"] == 320.0
    assert simulation.build_scene(c, rpm=1793.0, fs=20000.0, duration=0.1, healthy=True).defects == ()


@pytest.mark.parametrize("kw, match", [
    (dict(top="colour = 1"), "unknown key 'colour'"),
    (dict(rec_extra="sensitivty = \"9.91 mV/g\""), "unknown key 'sensitivty' in \\[recording\\]"),
    (dict(tail="[structural_pth]\nmethod = \"fit\""), "unknown key 'structural_pth'"),
    (dict(tail="[structural_path]\nfrequency_hz = [500.0, 9000.0]\nmode = 2"), "unknown key 'mode'"),
    (dict(tail="[background]\nsource = \"elsewhere\""), "background.source"),
    (dict(tail="[[run]]\nlabel = \"healthy\"\nscene = \"paper-healthy\""), "'run'.*\\[reference\\]"),
    (dict(tol='{ pct = 1.0 }'), "gives no reason"),
    (dict(tol='{ ordering = true, reason = "r" }'), "unknown key 'ordering'"),
    (dict(tol='{ factor = 0.5, reason = "r" }'), "greater than 1"),
    (dict(top="speed2 = 1"), "unknown key 'speed2'"),
    (dict(tail="[scene]\nset = { \"load.wobble\" = 1.0 }"), "load.wobble"),
    (dict(tail="[structural_path]\nmethod = \"fixed\"\nfrequency_hz = 4300.0"), "needs damping_ratio"),
])
def test_bad_case_files_are_refused_naming_the_problem(tmp_path, kw, match):
    with pytest.raises(ValidationCaseError, match=match):
        load_case(_case(tmp_path, **kw))


@pytest.mark.parametrize("scale", ["0.0", "-2.0", "nan", "1e300", "inf", "\"two\""])
def test_calibration_scales_that_are_not_a_sensor_are_refused(tmp_path, scale):
    p = _case(tmp_path, rec_extra=f"scale = {scale}")
    with pytest.raises(ValidationCaseError, match=r"recording\.scale = .*calibration factor|recording\.scale"):
        load_case(p)


def test_a_case_never_names_code_to_run(tmp_path):
    paper = Path(str(shipped_cases()["paper"]))
    text = paper.read_text().replace("[studies]\nenabled = true", "[studies]\nenabled = true\nmodule = \"os\"")
    (tmp_path / "paper_reference.toml").write_text((paper.parent / "paper_reference.toml").read_text())
    (tmp_path / "p.toml").write_text(text)
    with pytest.raises(ValidationCaseError, match="unknown key 'module' in \\[studies\\]"):
        load_case(tmp_path / "p.toml")


def test_speed_values(tmp_path):
    for bad in ("\"fast\"", "-1.0", "0"):
        p = tmp_path / "s.toml"
        p.write_text(_case(tmp_path).read_text().replace("speed = 1793.0", f"speed = {bad}"))
        with pytest.raises(ValidationCaseError, match="speed"):
            load_case(p)
    p.write_text(_case(tmp_path).read_text().replace("speed = 1793.0", "speed = \"estimate\""))
    assert load_case(p).speed == "estimate"


def test_unknown_quantity_case_and_missing_recording(tmp_path):
    p = _case(tmp_path, tol="{}")
    p.write_text(p.read_text().replace("bpfo = {}", "bpfx = {}"))
    with pytest.raises(ValidationCaseError, match="unknown quantity tolerances.bpfx"):
        load_case(p)
    with pytest.raises(ValidationCaseError, match="unknown validation case 'nope'.*paper"):
        load_case("nope")
    c = load_case(_case(tmp_path, rec=str(tmp_path / "missing.uff")))
    with pytest.raises(ValidationCaseError, match="missing.uff.*not found"):
        check_case(c)


@pytest.mark.parametrize("args, match", [
    (["validate", "no-such-case"], "unknown validation case 'no-such-case'"),
    (["validate", "{missing}"], "not found"),
    (["validate", "{badscale}"], "recording.scale = 0"),
    (["validate", "{badkey}"], "unknown key 'colour'"),
])
def test_cli_bad_input_exits_2_with_one_line_and_runs_nothing(tmp_path, capsys, args, match):
    names = {"missing": _case(tmp_path, "m.toml", rec=str(tmp_path / "gone.uff")),
             "badscale": _case(tmp_path, "s.toml", rec_extra="scale = 0.0"),
             "badkey": _case(tmp_path, "k.toml", top="colour = 1")}
    args = [a.format(**names) for a in args] + ["-o", str(tmp_path / "out"), "--no-progress"]
    rc = main(args)
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1, err
    assert err.startswith("bearing-lab validate: error:") and match in err
    assert not (tmp_path / "out" / "index.html").exists()


def test_default_set_without_mirror_is_the_paper_case(tmp_path, monkeypatch):
    monkeypatch.setenv("BEARING_LAB_MIRROR", str(tmp_path / "empty"))
    monkeypatch.setenv("BEARING_LAB_DATA", str(tmp_path / "empty"))
    cases, skipped = default_set()
    assert [c.name for c in cases] == ["paper"]
    assert {"cwru-130", "cwru-144", "cwru-234", "cwru-105", "cwru-97"} <= {s[0] for s in skipped}
    assert all("not found" in s[2] for s in skipped)


def test_default_set_with_mirror(mirror, monkeypatch):
    if mirror is None or not (Path(mirror) / "cwru" / "130_OR007@6_0.mat").is_file():
        if os.environ.get("CI", "").lower() in ("1", "true", "yes"):
            pytest.fail("BEARING_LAB_MIRROR with the CWRU records is required in CI")
        pytest.skip("no BEARING_LAB_MIRROR with the CWRU records")
    monkeypatch.setenv("BEARING_LAB_MIRROR", str(mirror))
    cases, _ = default_set()
    assert cases[0].name == "paper"
    assert {"cwru-130", "cwru-144", "cwru-234", "cwru-105", "cwru-97"} <= {c.name for c in cases}


def test_validate_list_and_help_speak_for_themselves(capsys):
    assert main(["validate", "--list"]) == 0
    out = capsys.readouterr().out
    assert "paper" in out and "cwru-130" in out
    for cmd in (["validate", "--help"], ["case", "new", "--help"], ["case", "standin", "--help"]):
        with pytest.raises(SystemExit):
            main(cmd)
        text = capsys.readouterr().out
        assert not re.search(r"issue \d|HOOK|not available yet|reference\.md|paper\.md|contract\.md", text)
