"""Reports: the paper case end to end (files, summary.json schema, --strict) and a real browser render."""
import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from bearing_lab.validation import CASE_DIR

IN_CI = os.environ.get("CI", "").lower() in ("1", "true", "yes")
pytestmark = pytest.mark.xdist_group("validation_paper")


@pytest.fixture(scope="module")
def paper_reports(tmp_path_factory):
    """Run the paper case once (section-5 studies hook off: it has its own tests) into a temp dir."""
    import matplotlib
    matplotlib.use("Agg")
    from bearing_lab.validation import run_validation
    d = tmp_path_factory.mktemp("cases")
    shutil.copy(CASE_DIR / "paper_reference.toml", d / "paper_reference.toml")
    text = (CASE_DIR / "paper.toml").read_text().replace("enabled = true", "enabled = false")
    (d / "paper.toml").write_text(text)
    out = tmp_path_factory.mktemp("reports")
    outcomes, status = run_validation([str(d / "paper.toml")], out, strict=True, progress=False)
    return out, outcomes, status


def test_paper_case_writes_the_contract_files(paper_reports):
    out, outcomes, status = paper_reports
    assert (out / "index.html").is_file()
    for f in ("index.html", "comparison.nc", "summary.json"):
        assert (out / "paper" / f).is_file(), f
    s = json.loads((out / "paper" / "summary.json").read_text())
    assert s["case"] == "paper" and s["wall_time_s"] > 0
    for r in s["rows"]:
        assert {"quantity", "simulation", "experiment", "difference_pct", "tolerance_pct", "pass"} <= set(r)
        assert isinstance(r["pass"], bool)
        assert r["reason"]
    rows = {r["quantity"]: r for r in s["rows"]}
    # the acceptance rows: period within 0.5 % of 0.01083 s; BPFO within 1 % of the kinematic value
    per = rows["slot: excitation_period"]
    assert per["experiment"] == 0.01083 and per["tolerance_pct"] == 0.5 and per["pass"]
    assert per["paper_simulation"] == 0.01084
    for g in ("healthy", "slot"):
        assert rows[f"{g}: bpfo"]["pass"] and abs(rows[f"{g}: bpfo"]["experiment"] - 92.158) < 1e-6
        assert f"{g}: bpfi" in rows and f"{g}: shaft_hz" in rows
        amp = rows[f"{g}: peak"]  # amplitudes: compared and shown with their numbers, pass or not
        assert amp["simulation"] is not None and amp["experiment"] in (1.0, 60.0)
    assert rows["slot: bpfo"]["paper_experiment"] == 92.19
    # a failing row makes --strict exit non-zero; rows are never dropped to pass
    assert status == (0 if all(r["pass"] for r in s["rows"]) else 1)
    assert "error" not in {o.status for o in outcomes}
    html = (out / "paper" / "index.html").read_text()
    assert "data:image/png;base64," in html and "src=\"http" not in html
    assert "sha256" in html and "Estimated numerical error" in html and "Compute time" in html
    index = (out / "index.html").read_text()
    assert 'href="paper/index.html"' in index


def test_comparison_netcdf_loads(paper_reports):
    from bearing_lab.compare import ComparisonResult
    out, _, _ = paper_reports
    res = ComparisonResult.load(out / "paper" / "comparison.nc")
    ds = res.dataset
    assert set(ds["signal"].values) == {"simulation_healthy", "simulation_slot"}
    assert {"waveform", "spectrum", "ses", "simulation", "experiment", "difference", "difference_pct",
            "tolerance_pct", "pass"} <= set(ds.data_vars)
    assert ds["pass"].dtype == bool
    assert json.loads(ds.attrs["provenance"])["versions"]["numpy"]


def _chromium():
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        p = shutil.which(name)
        if p:
            return p
    return None


def test_report_renders_in_headless_chromium(paper_reports, tmp_path):
    exe = _chromium()
    if exe is None:
        if IN_CI:
            pytest.fail("chromium is not installed in CI (.ci/run installs Debian's chromium package)")
        pytest.skip("chromium not installed (apt-get install chromium): the browser-render check needs it")
    out, _, _ = paper_reports
    page = out / "paper" / "index.html"
    png = tmp_path / "shot.png"
    cmd = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
           "--disable-background-networking", "--disable-component-update", "--disable-sync",
           f"--user-data-dir={tmp_path / 'profile'}", f"--screenshot={png}", "--window-size=1200,2000",
           page.resolve().as_uri()]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert png.is_file() and png.stat().st_size > 10_000, (r.returncode, r.stderr[-2000:])
    import matplotlib.image as mpimg
    img = mpimg.imread(png)
    assert img.shape[0] >= 1000 and img.shape[1] >= 1000
    rgb = img[..., :3]
    # non-blank: many distinct colours and a good share of non-white pixels (text, tables, figures)
    nonwhite = np.mean(np.any(rgb < 0.95, axis=-1))
    assert nonwhite > 0.03, nonwhite
    assert len(np.unique((rgb[::4, ::4] * 255).astype(np.uint8).reshape(-1, 3), axis=0)) > 50
    # the pass/fail colours of the table are on screen (the table rendered, not just text)
    red = np.any((rgb[..., 0] > 0.9) & (rgb[..., 1] < 0.9) & (rgb[..., 2] < 0.9))
    assert red
