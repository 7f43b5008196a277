"""A case's files: the report page (through :mod:`bearing_lab.report`), summary.json, comparison.nc.

Public API
----------
write_case(case, result, out, *, wall) -> status   -- DIR/<case>/{index.html, comparison.nc, summary.json}
                                                      (and structural_path.json when a path was fitted)
summary(case, result, wall) -> dict                -- the summary.json content
verdict_html(rows, author) -> str                  -- a case page's opening: the verdict in words
verdict_legend(entries) -> str                     -- the index page's opening: overall verdict, meanings, exit status
MODEL_ASSUMPTIONS                                  -- the assumptions listed on every page
VERDICT_LEVEL                                      -- the look of each verdict's notice
"""
from __future__ import annotations

import json

import numpy as np

from ..report import Report, esc, fmt, table_html
from ..report.html import fill, list_html
from ..utils._files import atomic_open
from ..utils._json import clean
from .rows import EXIT_STATUS, ROW_KEYS, VERDICTS, case_verdict


__all__ = ["write_case", "summary", "verdict_html", "verdict_legend", "MODEL_ASSUMPTIONS", "VERDICT_LEVEL"]

#: the look of each verdict's notice (the report's "good", "warn" and "bad" blocks)
VERDICT_LEVEL = {"pass": "good", "known limitations": "warn", "fail": "bad"}

#: what every simulated number assumes (docs/validation.md explains each)
MODEL_ASSUMPTIONS = [
    "Planar rolling-bearing model: inner ring (prescribed rotation) and outer ring as rigid bodies on "
    "spring-damper supports; balls spaced by the cage; Hertz point contacts (Harris & Kotzalas 2007) with "
    "the IMPACT damping law; defects as 2-D outlines on the raceway.",
    "Ring support stiffness and damping, groove conformities, clearance and the unbalance are the scene's "
    "documented defaults unless the case sets them; the load path is through the bearing.",
    "No surface roughness, waviness, lubricant film or thermal effects; no shaft bending modes.",
    "The housing and sensor are not simulated: a structural path (one or two resonances and a gain) is "
    "identified once per rig and applied to the outer-ring acceleration.",
    "The rig's machine tones and broadband noise are not simulated: the optional background model adds "
    "what a recording measures between impacts (or on a healthy reference).",
]


def summary(case, result, wall) -> dict:
    rows = [{k: r.get(k) for k in ROW_KEYS} for r in result.rows]
    failing = [r for r in result.rows if not r["pass"]]
    v = case_verdict(result.rows)
    return clean({"case": case.name, "rows": rows, "wall_time_s": wall, "title": case.title,
                  "status": "pass" if result.rows and not failing else "fail",
                  "verdict": v["verdict"], "verdict_text": v["text"], "declared_by": case.author,
                  "n_rows": v["n_rows"], "n_pass": v["n_pass"], "n_declared_limitations": v["n_declared"],
                  "n_unexplained_failures": v["n_unexplained"],
                  "unexplained_failures": [r["quantity"] for r in failing if not r.get("known_limitation")],
                  "known_limitations": [r["quantity"] for r in failing if r.get("known_limitation")],
                  **result.extra})


def _numbers(r) -> str:
    return (f'simulation {fmt(r.get("simulation"))}, experiment {fmt(r.get("experiment"))} '
            f'{esc(r.get("units", ""))}, tolerance {esc(r.get("tolerance", ""))}')


def _label(r) -> str:
    return esc(r.get("label") or r["quantity"])


def verdict_html(rows, author) -> str:
    """The verdict in words, first on a case page: unexplained failures, the limitations the case's
    author declared (with the author's reason), the passes, and what the case expects (the
    ``verdict*.html`` templates of the report layer)."""
    v = case_verdict(rows)
    word = {"pass": "PASS", "known limitations": "KNOWN LIMITATIONS", "fail": "FAIL"}[v["verdict"]]
    out = [fill("verdict.html", level=VERDICT_LEVEL[v["verdict"]], word=esc(word), text=esc(v["text"]),
                meaning=esc(VERDICTS[v["verdict"]]))]
    unexplained = [r for r in rows if not r["pass"] and not r.get("known_limitation")]
    declared = [r for r in rows if not r["pass"] and r.get("known_limitation")]
    passing = [r for r in rows if r["pass"]]
    if unexplained:
        out.append(fill("verdict_unexplained.html", items="".join(
            fill("term.html", term=_label(r), text=": " + _numbers(r),
                 note=fill("term_note.html", note=esc(r["note"])) if r.get("note") else "") for r in unexplained)))
    if declared:
        who = sorted({r.get("declared_by") or author for r in declared})
        out.append(fill("verdict_declared.html", who=esc(", ".join(who)), items="".join(
            fill("term.html", term=_label(r), text=f" ({_numbers(r)}): {esc(r['known_limitation'])}", note="")
            for r in declared)))
    if passing:
        labels = ", ".join(r.get("label") or r["quantity"] for r in passing)
        out.append(fill("verdict_passing.html", labels=esc(labels)))
    out.append(fill("verdict_expected.html", n_declared=sum(bool(r.get("known_limitation")) for r in rows),
                    n_rows=len(rows), author=esc(author)))
    return "\n".join(out)


def verdict_legend(entries: list) -> str:
    """The index's opening: the overall verdict in words, then what each verdict and the exit status mean."""
    n_unexp = sum(len(e.get("failing") or []) for e in entries)
    n_decl = sum(len(e.get("known") or []) for e in entries)
    errors = [e["case"] for e in entries if e.get("status") == "error"]
    if n_unexp or errors:
        verdict = "fail"
        text = (f"{n_unexp} row(s) fail without a declared reason"
                + (f"; case(s) that could not run: {', '.join(errors)}" if errors else "") + ".")
    elif n_decl:
        verdict, text = "known limitations", f"no unexplained failure; {n_decl} row(s) fail as declared limitations."
    else:
        verdict, text = "pass", "every row of every case that ran agrees."
    items = "".join(fill("term.html", term=esc(k), text=": " + esc(v), note="") for k, v in VERDICTS.items())
    return fill("legend.html", level=VERDICT_LEVEL[verdict], word=esc(verdict.upper()), text=esc(text), items=items,
                exit_status=esc(EXIT_STATUS))


def _overview(report, rows, author):
    report.add_html(verdict_html(rows, author), "Verdict")


def _render_sections(report, sections):
    last = None
    for kind, title, payload in sections:
        start = len(report.sections)
        if kind == "rows":
            report.add_rows(payload["rows"], title, show_reference=payload.get("show_reference", False),
                            show_paper=payload.get("show_paper", False), intro=payload.get("intro", ""))
        elif kind == "table":
            report.add_table(payload["rows"], title, intro=payload.get("intro", ""))
        elif kind == "figures":
            report.add_figures(payload, title)
        elif kind == "notice":
            report.add_notice(title, payload[0], level=payload[1], title=title)
        if title == last and len(report.sections) == start + 1 and start > 0:
            merged = report.sections.pop()
            report.sections[-1]["html"] += "\n" + merged["html"]
        last = title


def _compute_tables(report, result, wall):
    ne = result.extra.get("numerical_error") or {}
    items = ne.items() if ne and all(isinstance(v, dict) for v in ne.values()) else [("simulation", ne)]
    rows = [{"run": k, "solver rtol": v["rtol"], "check rtol": v["rtol_check"], "checked over (s)": v["duration_s"],
             "peak difference (m s-2)": v["peak_difference_m_s2"],
             "peak difference (% of peak)": v["peak_difference_pct_of_peak"]} for k, v in items if v]
    comp = result.extra.get("compute") or {}
    crow = ([{"run": k, **v} for k, v in comp.items()] if comp and all(isinstance(v, dict) for v in comp.values())
            else [{"run": "declared scene", **comp}])
    report.add_table(crow + [{"run": "whole case (simulations, analysis, fits, figures)", "wall_time_s": wall}],
                     "Compute time", intro="Simulation wall time excludes numba compilation (compile_time_s).")
    report.add_table(rows, "Estimated numerical error", intro=(
        "Each simulation is rerun with the solver tolerance divided by 10 over its first seconds; the peak "
        "difference of the accelerometer signal estimates the integration error."))


def build_report(case, result, wall) -> Report:
    report = Report(f"Validation: {case.name}", subtitle=case.title)
    _overview(report, result.rows, case.author)
    _render_sections(report, result.sections)
    # the page counts the case's rows, as summary.json, the index and the terminal do (a rows table shown
    # twice, e.g. the healthy rows in their own section, is not counted twice)
    report.rows = list(result.rows)
    model = result.extra.get("model") or {}
    runs = model if model and all(isinstance(v, dict) for v in model.values()) else {"simulation": model}
    report.add_html(list_html(MODEL_ASSUMPTIONS)
                    + table_html([{"run": k, **v} for k, v in runs.items() if v],
                                 intro="The simulations as they ran:"), "Model assumptions")
    _compute_tables(report, result, wall)
    report.add_provenance({"case": case.name, "case source": case.source, "case TOML": case.text,
                           **result.provenance})
    report.add_citation(note="Tolerances, quantities and the background model: docs/validation.md; the case "
                             "format: docs/case-format.md.")
    with_path = result.path is not None and result.path.resonances
    report.add_html(fill("case_files.html", path=fill("case_files_path.html") if with_path else ""), "Files")
    return report


def write_case(case, result, out, *, wall) -> str:
    """Write the case's files into ``out`` (atomically); returns "pass" or "fail"."""
    out.mkdir(parents=True, exist_ok=True)
    report = build_report(case, result, wall)
    info = {k: v for k, v in report.info.items() if k != "case TOML"}
    result.comparison.dataset.attrs["provenance"] = json.dumps(clean(info), default=str)
    result.comparison.to_netcdf(out / "comparison.nc")
    if result.path is not None and result.path.resonances:
        result.path.save(out / "structural_path.json")
    report.save(out / "index.html")
    report.save(out / "report.json")      # reloadable: `bearing-lab identify --report` adds its sections
    s = summary(case, result, wall)
    with atomic_open(out / "summary.json", "w", encoding="utf-8") as fh:
        json.dump(s, fh, indent=1, default=str)
    return s["status"]
