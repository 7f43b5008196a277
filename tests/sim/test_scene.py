"""Scenes: built-ins load, overrides apply, bad input is refused with a message naming the key."""
import subprocess
import sys

import pytest

from bearing_lab.errors import SceneError
from bearing_lab.sim import list_scenes, load_scene


def test_builtin_scenes_listed_and_load():
    names = list_scenes()
    for name in ("paper-healthy", "paper-slot"):
        assert name in names and names[name]
        sc = load_scene(name)
        assert sc.bearing.name == "6308"


def test_overrides_and_units():
    sc = load_scene("paper-slot", speed_rpm=900, **{"load.radial_n": "0.48 kN", "defect.length_mm": "3 mm"})
    assert sc.data["speed"]["rpm"] == 900
    assert sc.data["load"]["radial_n"] == pytest.approx(480.0)
    assert sc.defects[0].length == pytest.approx(3e-3)


def test_toml_round_trip(tmp_path):
    sc = load_scene("paper-slot", **{"load.radial_n": 480})
    p = tmp_path / "s.toml"
    p.write_text(sc.to_toml())
    again = load_scene(str(p))
    assert again.data == sc.data


@pytest.mark.parametrize("override,message", [
    ({"load.radail_n": 4}, "unknown key 'load.radail_n'"),
    ({"bogus": 1}, "unknown key 'bogus'"),
    ({"load.radial_n": -5}, "load.radial_n: -5.0 must not be negative"),
    ({"load.radial_n": "150 kg"}, "load.radial_n: unit 'kg' is not a force unit"),
    ({"speed.rpm": "fast"}, "speed.rpm: 'fast' must be a number"),
    ({"mass.ball_kg": -0.01}, "mass.ball_kg: -0.01 must be positive"),
    ({"load.on": "cage"}, "load.on: invalid value 'cage'"),
    ({"fidelity": "exact"}, "fidelity: invalid value 'exact'"),
    ({"defect.contact_model": "hertz"},
     "defect.contact_model: invalid value 'hertz'; allowed values are 'auto', 'profile', 'drop', "
     "'area' and 'halfspace'"),
    ({"bearing_geometry.ball_diameter_mm": 30.0}, "does not fit in the ring gap"),
    ({"bearing_geometry.ball_diameter_mm": 70.0}, "is not smaller than pitch_diameter"),
    ({"defect.length_mm": -1}, "defect.length_mm"),
    ({"defect.offset_mm": 20.0}, "defect"),
    ({"clearance.radial_um": 1000.0}, "clearance.radial_um"),
])
def test_refused_with_message_naming_the_key(override, message):
    with pytest.raises(SceneError, match=message.replace("(", r"\(").replace(")", r"\)")):
        load_scene("paper-slot", **override)


def test_unknown_scene_and_bad_toml(tmp_path):
    with pytest.raises(SceneError, match="unknown scene 'nope'"):
        load_scene("nope")
    p = tmp_path / "bad.toml"
    p.write_text("name = [unclosed")
    with pytest.raises(SceneError, match="not valid TOML"):
        load_scene(str(p))


def test_cli_bad_scene_exits_2_with_one_line(tmp_path):
    r = subprocess.run([sys.executable, "-m", "bearing_lab", "simulate", "paper-slot",
                        "--set", "load.radail_n=4", "-o", str(tmp_path / "x.nc")],
                       capture_output=True, text=True)
    assert r.returncode == 2
    lines = [ln for ln in r.stderr.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and "load.radail_n" in lines[0]
