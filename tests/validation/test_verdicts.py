"""Verdicts in words and the exit status: PASS / KNOWN LIMITATIONS / FAIL, who declared each limitation,
and what `bearing-lab validate` returns for each (also --strict), as --help and the pages say it."""
import json

import pytest

from bearing_lab.cli import main
from bearing_lab.validation.rows import Tolerance, case_verdict, make_row
from bearing_lab.validation.runner import CaseOutcome, exit_status


def _rows(*kinds):
    """One row per kind: "pass", "declared" (fails, known_limitation given) or "fail" (fails, no reason)."""
    out = []
    for i, k in enumerate(kinds):
        tol = Tolerance("pct", 1.0, "a reason", known_limitation="the author's reason" if k == "declared" else "",
                        declared_by="the author of x.toml")
        out.append(make_row(f"q{i}", 1.0 if k == "pass" else 2.0, 1.0, tol, label=f"row {i}", units="Hz"))
    return out


@pytest.mark.parametrize("kinds, verdict, status, strict", [
    (("pass", "pass"), "pass", 0, 0),
    (("pass", "declared"), "known limitations", 0, 1),
    (("pass", "declared", "fail"), "fail", 1, 1),
    (("fail",), "fail", 1, 1),
])
def test_verdict_and_exit_status(kinds, verdict, status, strict):
    rows = _rows(*kinds)
    v = case_verdict(rows)
    assert v["verdict"] == verdict
    assert (v["n_pass"], v["n_declared"], v["n_unexplained"]) == (
        kinds.count("pass"), kinds.count("declared"), kinds.count("fail"))
    o = CaseOutcome("c", "t", "pass" if verdict == "pass" else "fail", rows)
    assert exit_status([o]) == status and exit_status([o], strict=True) == strict
    # a declared limitation says who declared it; a row with no limitation declares nothing
    for r, k in zip(rows, kinds):
        assert r["declared_by"] == ("the author of x.toml" if k == "declared" else "")


def test_an_error_exits_1_and_an_empty_case_is_no_pass():
    assert exit_status([CaseOutcome("c", "t", "error", reason="boom")]) == 1
    assert case_verdict([])["verdict"] == "fail"


def test_who_declared_a_limitation(tmp_path):
    from bearing_lab.validation import load_case
    shipped = load_case("cwru-130")
    assert shipped.tolerances["impulse_strength_ratio"].declared_by == "bearing_lab (shipped case cwru-130)"
    assert not shipped.tolerances["rms"].declared_by
    text = shipped.text.replace('name = "cwru-130"', 'name = "mine"')
    (tmp_path / "mine.toml").write_text(text)
    mine = load_case(tmp_path / "mine.toml")
    assert mine.tolerances["impulse_strength_ratio"].declared_by == f"the author of {tmp_path / 'mine.toml'}"


def test_pages_open_with_the_verdict_in_words_and_the_authors_reason(tmp_path):
    from bearing_lab.report import write_index
    from bearing_lab.validation.pages import verdict_html, verdict_legend
    from bearing_lab.validation.runner import _index_entry
    rows = _rows("pass", "declared", "fail")
    html = verdict_html(rows, "the author of x.toml")
    assert "<b>FAIL</b>: 1 of 3 rows pass, 1 fails as limitation the case declares, 1 fails unexplained" in html
    assert "Unexplained failures" in html and "Limitations declared by the author of x.toml" in html
    assert "the author&#x27;s reason" in html and "Expected result" in html
    assert "<b>KNOWN LIMITATIONS</b>" in verdict_html(_rows("pass", "declared"), "a")
    assert "<b>PASS</b>" in verdict_html(_rows("pass"), "a")
    entries = [_index_entry(CaseOutcome("c", "t", "fail", rows))]
    write_index(tmp_path / "index.html", entries, opening=verdict_legend(entries))
    index = (tmp_path / "index.html").read_text()
    assert "<b>FAIL</b>: 1 row(s) fail without a declared reason" in index
    assert "declared limitations</b> (by the author of x.toml): row 1" in index
    assert "<b>unexplained:</b> row 2" in index and "Exit status of" in index


def test_validate_help_says_what_verdicts_and_exit_status_mean(capsys):
    with pytest.raises(SystemExit):
        main(["validate", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for part in ("KNOWN LIMITATIONS", "exit status: 0: every case ran and no row fails unexplained",
                 "with --strict also when a declared limitation fails", "2: bad input"):
        assert part in text, part


def test_validate_list_json(capsys):
    assert main(["validate", "--list", "--json"]) == 0
    got = json.loads(capsys.readouterr().out)
    assert {"case": "paper", "default": True} .items() <= got[[c["case"] for c in got].index("paper")].items()
