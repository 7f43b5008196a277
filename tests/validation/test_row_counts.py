"""One row count everywhere: the terminal line, the index page, the case page and summary.json agree,
also for a case whose healthy-reference rows have a table of their own on the page."""
import json
import re

import pytest

from bearing_lab.cli import main

pytestmark = pytest.mark.xdist_group("row_counts")

CASE = '''name = "rig"
bearing = "6308"
speed = 1793.0
[recording]
file = "rig.uff"
duration_s = 0.5
[reference]
file = "healthy.uff"
speed = 1793.0
tolerances = { shaft_hz = {}, rms_path = {} }
[load]
radial_n = 320.0
[[defect]]
race = "outer"
length_mm = 3.0
width_mm = 1.0
[numerical_error]
enabled = false
[tolerances]
bpfo = {}
excitation_period = {}
rms = {}
kurtosis = {}
'''


def test_terminal_json_index_page_and_summary_count_the_same_rows(tmp_path, capsys):
    from bearing_lab.validation import make_standin_recording
    make_standin_recording(tmp_path / "rig.uff", duration=1.0, overrides={"load.radial_n": 320})
    make_standin_recording(tmp_path / "healthy.uff", scene="paper-healthy", duration=1.0, seed=1)
    (tmp_path / "rig.toml").write_text(CASE)
    out = tmp_path / "out"
    status = main(["validate", str(tmp_path / "rig.toml"), "-o", str(out), "--no-progress"])
    term = re.search(r"rig\s+(PASS|KNOWN LIMITATIONS|FAIL)\s+(\d+)/(\d+) rows pass", capsys.readouterr().out)
    s = json.loads((out / "rig" / "summary.json").read_text())
    assert term.group(1).lower() == s["verdict"] and status == (1 if s["verdict"] == "fail" else 0)
    assert main(["validate", str(tmp_path / "rig.toml"), "-o", str(out), "--json"]) == status
    js = json.loads(capsys.readouterr().out)["cases"][0]
    n_rows, n_pass = len(s["rows"]), sum(bool(r["pass"]) for r in s["rows"])
    assert any(r["quantity"].startswith("healthy:") for r in s["rows"])      # the rows shown in two tables
    assert (int(term.group(2)), int(term.group(3))) == (n_pass, n_rows)
    assert (js["n_pass"], js["n_rows"], js["verdict"]) == (n_pass, n_rows, s["verdict"])
    assert (s["n_pass"], s["n_rows"]) == (n_pass, n_rows)
    page = (out / "rig" / "index.html").read_text()
    assert re.search(rf"\b{n_pass} of {n_rows} rows pass", page)
    # the verdict sentence at the top of the page: its failing counts add up to the rest
    declared = re.search(r"(\d+) fails? as limitations? the case declares", page)
    unexplained = re.search(r"(\d+) fails? unexplained", page)
    assert sum(int(m.group(1)) for m in (declared, unexplained) if m) == n_rows - n_pass
    assert (int(unexplained.group(1)) if unexplained else 0) == s["n_unexplained_failures"]
    index = (out / "index.html").read_text()
    assert f"{n_pass} / {n_rows}" in index
