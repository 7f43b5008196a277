"""The README's 'Validate your own recording' walkthrough, executed line by line from a fresh directory,
then broken: a wrong speed and a wrong defect geometry must fail rows that the true ones pass."""
import json
import re
import shlex
from pathlib import Path

import numpy as np
import pytest

from bearing_lab.cli import main

README = Path(__file__).resolve().parents[2] / "README.md"
pytestmark = pytest.mark.xdist_group("walkthrough")


def _blocks():
    text = README.read_text()
    sec = text[text.index("## Validate your own recording"):]
    sec = sec[: sec.index("\n## ", 5)] if "\n## " in sec[5:] else sec
    return re.findall(r"```(\w+)\n(.*?)```", sec, flags=re.S)


def _run(line):
    args = shlex.split(line)
    assert args[0].endswith("bearing-lab"), line
    return main(args[1:] + (["--no-progress"] if args[1] == "validate" else []))


@pytest.fixture(scope="module")
def walked(tmp_path_factory):
    """Run every block of the walkthrough in a fresh directory, in order."""
    import os
    d = tmp_path_factory.mktemp("walkthrough")
    old = os.getcwd()
    os.chdir(d)
    try:
        blocks = _blocks()
        assert [k for k, _ in blocks] == ["sh", "toml", "sh", "python"], [k for k, _ in blocks]
        for kind, body in blocks:
            if kind == "sh":
                for line in body.strip().splitlines():
                    assert _run(line) == 0, line
            elif kind == "toml":
                with open("rig.toml", "a", encoding="utf-8") as fh:
                    fh.write("\n" + body)
            else:
                exec(compile(body, "README walkthrough", "exec"), {})
    finally:
        os.chdir(old)
    return d


def test_the_walkthrough_runs_and_finds_what_was_hidden(walked):
    d = walked
    for f in ("rig.uff", "rig.mat", "rig.toml", "reports/index.html", "reports/rig/index.html",
              "reports/rig/comparison.nc", "reports/rig/summary.json", "reports/rig/structural_path.json"):
        assert (d / f).is_file(), f
    s = json.loads((d / "reports/rig/summary.json").read_text())
    rows = {r["quantity"]: r for r in s["rows"]}
    # kinematics at the given speed: the recording's jittered BPFO and impact period within 1 %
    assert rows["bpfo"]["pass"] and rows["excitation_period"]["pass"], rows["bpfo"]
    assert "given" in s["speed"]["source"]
    # the structural path is identified: the hidden 4.3 kHz, zeta 0.05, gain 1 housing resonance
    sp = s["structural_path"]
    assert sp["status"] == "ok" and sp["fit"]["residual_db"] < sp["fit"]["initial_db"]
    assert sp["resonances"][0]["frequency_hz"] == pytest.approx(4300.0, rel=0.03)
    assert sp["resonances"][0]["damping_ratio"] == pytest.approx(0.05, rel=0.3)
    assert sp["gain"] == pytest.approx(1.0, rel=0.3)
    # the background model finds the machine tones the stand-in added (50 Hz at 0.03 g, 315 Hz at 0.02 g)
    tones = {round(t["frequency_hz"]): t["amplitude_m_s2"] / 9.80665 for t in s["background"]["tones"]}
    assert tones[50] == pytest.approx(0.03, rel=0.1) and tones[315] == pytest.approx(0.02, rel=0.1)
    html = (d / "reports/rig/index.html").read_text()
    for part in ("Structural path", "Background model", "Model assumptions", "How to cite", "Provenance",
                 "What the bearing contributes"):
        assert part in html, part
    assert "Liu, Xu, Wang, Xu, Tang" in html and "bearing_lab 0.1.0" in html
    # the Testlab-style export reads back as the same signal
    import bearing_lab as bl
    a, b = bl.open_recording(d / "rig.mat"), bl.open_recording(d / "rig.uff")
    assert a.attrs["reader"] == "testlab_mat" and a["Acc"].attrs["original_units"] == "g"
    np.testing.assert_allclose(a["Acc"].values, b["Acc"].values, rtol=1e-12)


def test_break_it_a_wrong_speed_fails_the_kinematic_rows(walked):
    case = walked / "rig.toml"
    wrong = walked / "wrong_speed.toml"
    wrong.write_text(case.read_text().replace("speed = 1793.0", "speed = 1700.0").replace('name = "rig"',
                                                                                          'name = "wrong_speed"'))
    # unexplained failures: exit status 1
    assert main(["validate", str(wrong), "-o", str(walked / "reports"), "--no-progress"]) == 1
    s = json.loads((walked / "reports/wrong_speed/summary.json").read_text())
    rows = {r["quantity"]: r for r in s["rows"]}
    assert not rows["bpfo"]["pass"] and not rows["excitation_period"]["pass"]
    assert rows["bpfo"]["status"] == "fail"


def test_break_it_a_wrong_geometry_fails_through_the_fixed_path_but_passes_with_a_refit(walked):
    """The issue the fixed path solves: a path re-fitted to each geometry absorbs the geometry's effect."""
    from bearing_lab.validation import load_case
    from bearing_lab.validation.evaluate import compare_candidates
    from bearing_lab.validation.recording_case import prepare
    from bearing_lab.validation.rig import background_for, path_for
    case = load_case(walked / "rig.toml")
    prep = prepare(case)
    path = path_for(case, prep)
    bg = background_for(case, prep.recording, prep.measured["record"])
    got = compare_candidates(prep, path, bg, {"true": {}, "wrong skew": {"defect.skew_deg": 0.0}})
    amp = ("rms", "peak", "impulse_strength")
    ok = {k: {r["quantity"]: r["pass"] for r in rows} for k, rows in got.items()}
    assert all(ok["true"][q] for q in amp)
    assert not any(ok["wrong skew"][q] for q in amp)
    # the old way: fit the path again on the wrong geometry's simulation -> its amplitudes "agree"
    from bearing_lab.analysis.structural_path import fit_structural_path
    from bearing_lab.validation import simulation
    scene = simulation.build_scene(case, rpm=prep.speed.rpm, fs=prep.fs, duration=prep.n / prep.fs,
                                   overrides={"sensor.enabled": False, "defect.skew_deg": 0.0})
    x_wrong = simulation.signal(simulation.run(scene))[: prep.n]
    m = prep.measured["record"]
    refit = fit_structural_path(prep.recording.x, x_wrong, prep.fs, m["excitation_period"], band=m["extras"]["band"],
                                frequency_bounds=(500.0, 9000.0))
    again = compare_candidates(prep, refit, bg, {"wrong skew, re-fitted path": {"defect.skew_deg": 0.0}})
    rows = {r["quantity"]: r for r in again["wrong skew, re-fitted path"]}
    for q in ("rms", "peak", "kurtosis"):        # the numbers now "agree" within a factor 2 ...
        assert 0.5 <= rows[q]["simulation"] / rows[q]["experiment"] <= 2.0, q
