"""The perfect-model check: a recording the model itself made, given to `case new` with the scene's own
load and defect, validates with every row passing; the same recording with a wrong defect race or a wrong
speed fails rows.  And a record too short to resolve a fault line from a shaft harmonic is said so."""
import json
import math
import tomllib
from pathlib import Path

import pytest

from bearing_lab.cli import main

pytestmark = pytest.mark.xdist_group("perfect_model")


def _table(name, d, array=False):
    return "\n".join([f"[[{name}]]" if array else f"[{name}]"] + [f"{k} = {json.dumps(v)}" for k, v in d.items()])


def _record(d: Path, scene, duration, sets=()):
    nc = d / f"{scene}_{duration:g}.nc"
    if not nc.exists():
        args = ["simulate", scene, "--duration", str(duration), "-o", str(nc), "-q"]
        for s in sets:
            args += ["--set", s]
        assert main(args) == 0
    return nc


def _case(d: Path, nc: Path, name, *, load, defects, bearing, speed=None):
    """`case new` as a user runs it, then the load and defect tables added as docs/case-format.md shows."""
    case = d / "cases" / f"{name}.toml"               # another folder: the recording is named relative to it
    case.parent.mkdir(exist_ok=True)
    args = ["case", "new", str(nc), "--bearing", bearing, "--name", name, "-o", str(case), "--force"]
    assert main(args + (["--speed", str(speed)] if speed else [])) == 0
    text = case.read_text()
    tables = _table("load", load) + "\n\n" + "\n\n".join(_table("defect", df, True) for df in defects)
    text = text.replace("[structural_path]", tables + "\n\n[structural_path]", 1)
    if defects[0]["race"] == "inner":
        text = text.replace("bpfo = {}", "bpfi = {}", 1)
    case.write_text(text)
    return case


def _validate(d: Path, case: Path) -> dict:
    main(["validate", str(case), "-o", str(d / "reports"), "--no-progress"])
    return json.loads((d / "reports" / case.stem / "summary.json").read_text())


def _declared(scene, sets=()):
    """The scene's own bearing, load and defect (what the user made), with the --set keys applied."""
    from bearing_lab.sim import load_scene
    raw = load_scene(scene).data
    defect = dict(raw["defect"][0])
    for s in sets:
        k, v = s.split("=")
        defect[k.split(".", 1)[1]] = float(v)
    load = {k: raw["load"][k] for k in ("radial_n", "on", "direction_deg")}
    return raw["bearing"], load, defect


@pytest.fixture(scope="module")
def work(tmp_path_factory):
    return tmp_path_factory.mktemp("perfect")


@pytest.mark.parametrize("scene, sets, duration", [
    ("paper-O2", ("defect.skew_deg=30",), 1.0),     # outer race, skewed, load on the shaft
    ("cwru-ir007", (), 0.5),                         # inner race, another bearing, a short record
])
def test_a_recording_the_model_made_validates_with_every_row_passing(work, scene, sets, duration):
    nc = _record(work, scene, duration, sets)
    bearing, load, defect = _declared(scene, sets)
    case = _case(work, nc, f"{scene}-perfect", load=load, defects=[defect], bearing=bearing)
    spec = tomllib.loads(case.read_text())
    assert spec["recording"]["file"] == f"../{nc.name}"              # relative to the case file
    assert spec["recording"]["duration_s"] == pytest.approx(duration)  # the whole record is compared
    s = _validate(work, case)
    failed = [(r["quantity"], r["note"]) for r in s["rows"] if not r["pass"]]
    assert len(s["rows"]) == 9 and not failed
    # the frequencies are measured alike: the same line on both sides
    for r in s["rows"]:
        if r["quantity"] in ("shaft_hz", "bpfo", "bpfi", "excitation_period"):
            assert r["simulation"] == pytest.approx(r["experiment"], rel=1e-4)
    # no housing resonance in the recording: the path is the gain alone, about 1, and says so
    path = s["structural_path"]
    assert path["status"] == "ok" and path["resonances"] == []
    assert path["gain"] == pytest.approx(1.0, abs=0.02)
    assert any("no resonance" in n for n in path["fit"]["notes"])
    # the background measured on the recording holds nothing the model does not explain
    assert s["background"]["rms_m_s2"] < 0.05 * next(r["experiment"] for r in s["rows"] if r["quantity"] == "rms")


def test_a_wrong_defect_race_or_speed_fails_rows(work):
    sets = ("defect.skew_deg=30",)
    nc = _record(work, "paper-O2", 1.0, sets)
    bearing, load, defect = _declared("paper-O2", sets)
    inner = _validate(work, _case(work, nc, "o2-as-inner", load=load, defects=[{**defect, "race": "inner"}],
                                  bearing=bearing))
    failed = {r["quantity"] for r in inner["rows"] if not r["pass"]}
    assert {"bpfi", "excitation_period"} <= failed        # the recording has no BPFI line; the period is BPFO's
    fast = _validate(work, _case(work, nc, "o2-fast", load=load, defects=[defect], bearing=bearing,
                                 speed=1.03 * 1800.0))
    failed = {r["quantity"] for r in fast["rows"] if not r["pass"]}
    assert {"shaft_hz", "bpfo", "excitation_period"} <= failed      # 3 % off, against a 1 % tolerance


def test_case_new_says_when_the_record_cannot_resolve_a_fault_line(work):
    # 6308 at 1800 r/min: BPFO = Z/2 (1 - D_b/d_m) f_r (Harris & Kotzalas), 2.16 Hz from 3 f_r
    fr = 30.0
    bpfo = 8 / 2 * (1 - 15.081 / 65.0) * fr
    need = 2.0 / abs(bpfo - 3 * fr)                   # two bins of 1/T between the lines
    from bearing_lab.validation.newcase import resolution_limits
    short = {lim["family"]: lim for lim in resolution_limits("6308", 1800.0, 0.5)}
    assert short["bpfo"]["min_duration_s"] == pytest.approx(need, rel=1e-3)
    assert not [lim for lim in resolution_limits("6308", 1800.0, 1.0) if lim["family"] == "bpfo"]
    nc = _record(work, "cwru-ir007", 0.5)            # any 0.5 s recording: case new does not simulate
    case = _case(work, nc, "short", load={"radial_n": 480.0}, defects=[{"race": "outer"}], bearing="6308",
                 speed=1800.0)
    text = case.read_text()
    assert "cannot resolve BPFO" in text and f"at least {need:.2g} s" in text
    assert math.isfinite(need) and need > 0.5
