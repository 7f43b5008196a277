"""The report layer: sections from templates, self-contained HTML, JSON round trip, provenance and
citation as report methods, the index with known limitations apart, atomic writes."""
import re

import numpy as np
from matplotlib.figure import Figure

from bearing_lab.report import Report, rows_table, write_index
from bearing_lab.validation import Tolerance, make_row


def _rows():
    return [make_row("bpfo", 107.3, 107.6, Tolerance("pct", 1.0, "line search"), label="BPFO", units="Hz"),
            make_row("rms", 1.0, 6.6, Tolerance("factor", 2.0, "amplitude"), label="RMS", units="m s-2",
                     note="structure as is"),
            make_row("ratio", 1295.0, 1.24, Tolerance("factor", 2.0, "ratio", known_limitation="the load zone"),
                     label="ratio", units="1")]


def test_report_html_is_self_contained_and_round_trips(tmp_path):
    r = Report("Validation: t", subtitle="a <test> case")
    r.add_rows(_rows(), "Comparison table")
    fig = Figure(figsize=(4, 2))
    fig.subplots().plot(np.arange(10))
    r.add_figure(fig, "A figure", caption="ten points")
    r.add_table([{"a": 1.5, "b": "x"}], "A table")
    r.add_notice("Look", "a <b> notice", level="bad")
    r.add_provenance({"recording sha256": "ab" * 32, "scene": "name = 'x'\n[speed]\nrpm = 1"})
    r.add_citation()
    html = r.save(tmp_path / "r" / "index.html").read_text()
    assert html.count("data:image/png;base64,") == 1
    assert "a &lt;test&gt; case" in html and "a &lt;b&gt; notice" in html
    assert "<link" not in html and "<script" not in html
    assert "1 of 3 rows pass" in html and "1 failing as limitations the case declares" in html
    assert "FAIL" in html and "known limitation" in html
    # provenance is a report method: the software versions, revision, host and date come with it
    assert "numpy" in r.info["versions"] and r.info["date"] and "host" in r.info
    assert "Liu, Xu, Wang, Xu, Tang" in html and "Eksploatacja" in html and "bearing_lab 0.1.0" in html
    assert not r.passed
    back = Report.load(r.save(tmp_path / "r.json"))
    assert back.title == r.title and len(back.rows) == 3
    assert [s["title"] for s in back.sections] == [s["title"] for s in r.sections]
    assert back.to_html().count("data:image/png;base64,") == 1
    assert not list((tmp_path / "r").glob(".*"))      # no temporary files left by the atomic write


def test_a_page_without_verdict_for_studies_and_bench(tmp_path):
    """verdict=False: the same sections and look, without the validation badge, the rows count and
    the link up to the case index; kept through the JSON round trip."""
    r = Report("Speed against error", verdict=False)
    fig = Figure(figsize=(4, 2))
    fig.subplots().plot(np.arange(10))
    r.add_figure(fig, "A figure")
    r.add_table([{"a": 1.5}], "A table")
    html = r.save(tmp_path / "index.html").read_text()
    assert html.count("data:image/png;base64,") == 1 and 'id="a-table"' in html
    assert "<span class=\"badge" not in html and "rows pass" not in html and "all validation cases" not in html
    assert "Speed against error" in html and "by bearing_lab 0.1.0" in html
    back = Report.load(r.save(tmp_path / "r.json"))
    assert "<span class=\"badge" not in back.to_html()
    assert "<span class=\"badge" in Report("a case").to_html()      # the default page keeps its verdict


def test_rows_table_and_index(tmp_path):
    t = rows_table(_rows(), show_reference=True, show_paper=True)
    assert "reference (not the experiment)" in t and "paper&#x27;s own simulation" in t and t.count("<tr") == 4
    p = write_index(tmp_path / "index.html", [
        {"case": "paper", "title": "P", "status": "fail", "n_pass": 3, "n_rows": 9, "wall_time_s": 5.0,
         "failing": ["healthy: BPFI"], "known": ["slot: peak"], "link": "paper/index.html"},
        {"case": "broken", "title": "B", "status": "error", "reason": "speed unresolved", "link": None},
        {"case": "cwru-130", "title": "C", "status": "skip", "reason": "recording not found", "link": None}],
        notes=["mirror missing"])
    html = p.read_text()
    assert 'href="paper/index.html"' in html and "skipped" in html and "mirror missing" in html
    assert "recording not found" in html and "speed unresolved" in html
    assert "<b>unexplained:</b> healthy: BPFI" in html and "<b>declared limitations</b> (by the case): slot: peak" in html


def test_report_cosmetics_booleans_long_reasons_and_trace_colours():
    """A True/False cell reads yes/no; a long reason goes below the table, linked; no compared signal
    is drawn in a fault marker's colour (BPFO red, BPFI green)."""
    from bearing_lab.compare import SIGNAL_COLORS
    from bearing_lab.report import rows_table, table_html
    from bearing_lab.validation.rows import Tolerance, make_row
    html = table_html([{"study": "size", "agrees": True}, {"study": "skew", "agrees": False}])
    assert ">yes<" in html and ">no<" in html and "True" not in html and "False" not in html
    long = "the impacts ring on between them " * 30
    rows = [make_row("kurtosis", 15.0, 7.0, Tolerance("factor", 2.0, "short reason", known_limitation=long,
                                                      declared_by="bearing_lab (shipped case x)"),
                     label="kurtosis", units="1"),
            make_row("rms", 1.0, 1.0, Tolerance("factor", 2.0, "a short one"), label="rms", units="m s-2")]
    t = rows_table(rows)
    table, below = t.split("</table>")
    assert long.strip()[:60] not in table and "(full reason, limitation and note below the table)" in table
    assert long.strip()[:60] in below and "declared by bearing_lab (shipped case x)" in below
    anchor = re.search(r'href="#(reason-\d+)"', table).group(1)
    assert f'id="{anchor}"' in below and "a short one" in table
    assert not {SIGNAL_COLORS[k] for k in ("model", "path", "path+background")} & {"tab:red", "tab:green"}


def test_text_a_figure_and_a_table_under_one_heading(tmp_path):
    """``title=None`` continues the last section; text is escaped, its lead in bold, preformatted text kept."""
    r = Report("Speed against error", verdict=False)
    r.add_text(["a < b", "c & d"], "Scene 1", lead="Fastest:")
    fig = Figure(figsize=(4, 2))
    fig.subplots().plot(np.arange(10))
    r.add_figure(fig, None, alt="work-precision")
    r.add_table([{"a": 1.5}], None)
    r.add_text("| x |\n|---|", "Markdown", preformatted=True)
    assert [s["title"] for s in r.sections] == ["Scene 1", "Markdown"]
    html = r.save(tmp_path / "index.html").read_text()
    first = html.split('id="scene-1"')[1].split("</section>")[0]
    assert "<p class=\"\"><b>Fastest:</b> a &lt; b</p>" in first and "c &amp; d" in first
    assert 'alt="work-precision"' in first and "<table" in first
    assert "<pre>| x |\n|---|</pre>" in html
    assert Report("t").add_text("alone", None).sections[0]["title"] == "Notes"


def test_the_pages_build_no_html_outside_the_report_layer():
    """The studies', the benchmark's and the validation pages say what they show through the report
    layer (its methods and templates): no HTML markup in the strings of studies/ and validation/."""
    import ast
    import re
    from pathlib import Path
    tag = re.compile(r"</?(p|b|i|em|pre|div|span|ul|ol|li|h[1-6]|table|tr|td|th|br|code|a|figure|img)\b[^>]*>")
    pkg = Path(__file__).resolve().parents[2] / "bearing_lab"
    modules = sorted(pkg.glob("studies/*.py")) + sorted(pkg.glob("validation/*.py"))
    found = [f"{p.relative_to(pkg)}:{n.lineno}" for p in modules
             for n in ast.walk(ast.parse(p.read_text())) if isinstance(n, ast.Constant) and isinstance(n.value, str)
             and tag.search(n.value)]
    assert not found, found
    assert tag.search("<p class=\"note\">x</p>") and not tag.search("``work_precision_<scene>.png``")
