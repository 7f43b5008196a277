"""Report: sections, self-contained HTML, JSON round trip, index page."""
import numpy as np
from matplotlib.figure import Figure

from bearing_lab.compare import Tolerance, make_row
from bearing_lab.report import Report, rows_table, write_index


def _rows():
    return [make_row("bpfo", 107.3, 107.6, Tolerance("pct", 1.0, "issue 5")),
            make_row("rms", 1.0, 6.6, Tolerance("factor", 2.0, "uncalibrated"), note="structure as is")]


def test_report_html_is_self_contained_and_round_trips(tmp_path):
    r = Report("Validation: t", subtitle="a <test> case")
    r.add_comparison(_rows(), "Comparison table", figures=False)
    fig = Figure(figsize=(4, 2))
    fig.subplots().plot(np.arange(10))
    r.add_figure(fig, "A figure", caption="ten points")
    r.add_table([{"a": 1.5, "b": "x"}], "A table")
    r.add_provenance({"recording sha256": "ab" * 32, "scene": "name = 'x'\n[speed]\nrpm = 1"})
    html_path = r.save(tmp_path / "r" / "index.html")
    html = html_path.read_text()
    assert html.count("data:image/png;base64,") == 1
    assert "a &lt;test&gt; case" in html and "<link" not in html and "<script" not in html
    assert "1 of 2 rows pass" in html and "FAIL" in html
    assert not r.passed
    back = Report.load(r.save(tmp_path / "r.json"))
    assert back.title == r.title
    assert len(back.rows) == len(r.rows) > 0
    assert back.rows == r.rows or all(
        a["quantity"] == b["quantity"] for a, b in zip(back.rows, r.rows))
    assert [s["title"] for s in back.sections] == [s["title"] for s in r.sections]
    assert back.to_html().count("data:image/png;base64,") == 1


def test_rows_table_and_index(tmp_path):
    t = rows_table(_rows(), show_paper=True)
    assert "paper: experiment" in t and t.count("<tr") == 3
    p = write_index(tmp_path / "index.html", [
        {"case": "paper", "title": "P", "status": "fail", "n_pass": 3, "n_rows": 9, "wall_time_s": 5.0,
         "failing": ["healthy: BPFI"], "link": "paper/index.html"},
        {"case": "cwru-130", "title": "C", "status": "skip", "reason": "recording not found", "link": None}],
        notes=["mirror missing"])
    html = p.read_text()
    assert 'href="paper/index.html"' in html and "skipped" in html and "mirror missing" in html
    assert "recording not found" in html
