"""HTML pieces of the report layer: escaping, number formatting, and every table from a template.

Why templates: the page layout, each table and each block live in files under
``report/templates/`` (``string.Template`` syntax: no template engine at run time), so
a page's look changes without touching the code that fills it, and validation, studies
and bench pages share them.
"""
from __future__ import annotations

import html
import itertools
import json
import math
import re
from pathlib import Path
from string import Template

from .._docdict import fill_doc
from ..utils.figures import figure_png

__all__ = ["template", "fill", "css", "esc", "fmt", "figure_html", "text_html", "list_html", "table_html",
           "rows_table", "index_rows", "kv_html", "notice_html"]

_TEMPLATES = Path(__file__).with_name("templates")


def template(name: str) -> Template:
    return Template((_TEMPLATES / name).read_text(encoding="utf-8"))


def fill(name: str, **values) -> str:
    """The template ``name`` filled in with ``values`` (HTML as given: escape text with :func:`esc`),
    without its file's last line break."""
    return template(name).substitute(**values).rstrip("\n")


def css() -> str:
    return (_TEMPLATES / "base.css").read_text(encoding="utf-8")


def esc(text) -> str:
    """``text`` (any object, as ``str``) escaped for HTML, quotes included.

    See Also
    --------
    fmt : a number for a table cell.

    Examples
    --------
    >>> esc('<b>"6308" & 6205</b>')
    '&lt;b&gt;&quot;6308&quot; &amp; 6205&lt;/b&gt;'
    """
    return html.escape(str(text), quote=True)


def fmt(v, digits=5) -> str:
    """A number for a table: NaN / None as an em dash, otherwise ``digits`` significant digits.

    Parameters
    ----------
    v : number, bool, None or other
        A bool gives "yes"/"no"; what is not a number is escaped (:func:`esc`).
    digits : int
        Significant digits.

    See Also
    --------
    table_html, esc

    Examples
    --------
    >>> fmt(92.1875), fmt(float("nan")), fmt(None), fmt(True)
    ('92.188', '—', '—', 'yes')
    """
    if v is None:
        return "—"
    if isinstance(v, bool):
        return "yes" if v else "no"
    try:
        x = float(v)
    except (TypeError, ValueError):
        return esc(v)
    if not math.isfinite(x):
        return "—"
    if x == 0:
        return "0"
    if abs(x) >= 1e5 or abs(x) < 1e-3:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{digits}g}"


def figure_html(fig, alt, caption="", dpi=80) -> str:
    return template("figure.html").substitute(alt=esc(alt), png=figure_png(fig, dpi=dpi), caption=esc(caption))


def text_html(text, *, lead="", note=False, preformatted=False) -> str:
    """Text for a page: each paragraph escaped, through the ``text.html`` template (``pre.html`` when
    ``preformatted``).

    Parameters
    ----------
    text : str or sequence of str
        One paragraph, or several.
    lead : str
        Words shown in bold before the first paragraph.
    note : bool
        Set the paragraphs in the small grey style of the page's notes.
    preformatted : bool
        Keep the text's line breaks and spacing (a Markdown table, a log), in one block.

    See Also
    --------
    Report.add_text : adds it to a page.

    Examples
    --------
    >>> print(text_html(["Cost: CPU s per simulated s.", "Tolerance: 5 % & 0.5 %."], lead="Scored:"))
    <p class=""><b>Scored:</b> Cost: CPU s per simulated s.</p>
    <p class="">Tolerance: 5 % &amp; 0.5 %.</p>
    """
    paragraphs = [text] if isinstance(text, str) else list(text)
    if preformatted:
        return template("pre.html").substitute(text=esc("\n".join(paragraphs))).rstrip("\n")
    lead_html = f"<b>{esc(lead)}</b> " if lead else ""
    return "\n".join(template("text.html").substitute(css_class="note" if note else "", text=esc(p),
                                                      lead=lead_html if i == 0 else "").rstrip("\n")
                     for i, p in enumerate(paragraphs))


def list_html(texts) -> str:
    """A bulleted list of texts (each escaped), through ``list.html`` and ``list_item.html``."""
    return fill("list.html", items="".join(fill("list_item.html", text=esc(t)) for t in texts))


def _cell(v) -> str:
    if isinstance(v, bool):
        return f'<td class="l">{"yes" if v else "no"}</td>'
    numeric = isinstance(v, (int, float)) and not isinstance(v, bool)
    return f'<td class="{"" if numeric else "l"}">{fmt(v) if numeric else esc("" if v is None else v)}</td>'


def table_html(rows: list, *, columns=None, intro="", row_class=None) -> str:
    """A list of dicts as a table (numbers right-aligned with 5 significant digits).

    Parameters
    ----------
    rows : list of dict
        One dict per row; missing keys give empty cells.
    columns : list of str, optional
        Column keys in order (default: the first row's keys).
    intro : str
        A paragraph above the table (escaped).
    row_class : callable, optional
        ``row -> CSS class`` of the row.

    Returns
    -------
    str
        HTML (the ``table.html`` template).

    See Also
    --------
    rows_table : the validation table.
    Report.add_table : adds one to a page.

    Examples
    --------
    >>> html = table_html([{"quantity": "BPFO", "value": 92.1875}])
    >>> '<th class="l">quantity</th>' in html, "92.188" in html
    (True, True)
    """
    if not rows:
        return (f"<p>{esc(intro)}</p>" if intro else "") + "<p>(no rows)</p>"
    columns = columns or list(rows[0])
    body = "\n".join(template("table_row.html").substitute(
        css_class=(row_class(r) if row_class else ""), cells="".join(_cell(r.get(c)) for c in columns))
        for r in rows)
    return template("table.html").substitute(intro=f"<p>{esc(intro)}</p>\n" if intro else "",
                                             head="".join(f'<th class="l">{esc(c)}</th>' for c in columns),
                                             rows=body)


_LONG_REASON = 240          # characters of reason, limitation and note kept in the table cell
_REASON_IDS = itertools.count(1)


def _shorten(text, n=120) -> str:
    text = str(text)
    return text if len(text) <= n else text[:n].rsplit(" ", 1)[0] + " …"


_STATUS = {"pass": ("pass", "pass"), "known limitation": ("known", "known limitation"), "fail": ("fail", "FAIL")}


@fill_doc
def rows_table(rows: list, *, show_reference=False, show_paper=False, intro="") -> str:
    """The validation table: quantity, simulation, experiment, difference, tolerance, status, reason.

    Parameters
    ----------
    %(rows)s
    show_reference : bool
        Add the column of a reference value (not the experiment).
    show_paper : bool
        Add the column of the paper's own simulation.
    intro : str
        A paragraph above the table (escaped).

    Returns
    -------
    str
        HTML; a failing row is marked FAIL, a failing declared limitation "known limitation".

    See Also
    --------
    bearing_lab.validation.make_row, Report.add_rows, table_html

    Examples
    --------
    >>> from bearing_lab.validation import Tolerance, make_row
    >>> tol = Tolerance("pct", 1.0, reason="kinematic frequencies hold to 1-2 % under slip")
    >>> html = rows_table([make_row("bpfo", 95.0, 92.19, tol, label="BPFO", units="Hz")])
    >>> "FAIL" in html                      # 3 % off against a 1 % tolerance
    True
    """
    head = ["quantity", "units", "simulation", "experiment"]
    if show_reference:
        head.append("reference (not the experiment)")
    if show_paper:
        head.append("paper's own simulation")
    head += ["difference %", "tolerance", "status", "signal / span", "reason, limitation, note"]
    lines, below = [], []
    for r in rows:
        status = r.get("status") or ("pass" if r.get("pass") else "fail")
        cls, label = _STATUS[status]
        mark = "" if r.get("independent", True) else " &#8224;"
        cells = [f'<td class="l">{esc(r.get("label") or r["quantity"])}{mark}</td>',
                 f"<td>{esc(r.get('units', ''))}</td>",
                 f"<td>{fmt(r.get('simulation'))}</td>", f"<td>{fmt(r.get('experiment'))}</td>"]
        if show_reference:
            cells.append(f"<td>{fmt(r.get('reference_value'))}<br><span class='note'>"
                         f"{esc(r.get('reference_label', ''))}</span></td>")
        if show_paper:
            cells.append(f"<td>{fmt(r.get('paper_simulation'))}</td>")
        text = esc(r.get("reason", ""))
        if r.get("known_limitation") and not r.get("pass"):
            who = f" (declared by {esc(r['declared_by'])})" if r.get("declared_by") else ""
            text += f"<br><b>known limitation{who}:</b> {esc(r['known_limitation'])}"
        if r.get("note"):
            text += f"<br><em>{esc(r['note'])}</em>"
        plain = len(html.unescape(re.sub(r"<[^>]+>", "", text)))
        if plain > _LONG_REASON:      # long reasons below the table, linked: rows stay a few lines tall
            anchor = f"reason-{next(_REASON_IDS)}"
            below.append(f'<li id="{anchor}"><b>{esc(r.get("label") or r["quantity"])}</b>: {text}</li>')
            text = (esc(_shorten(r.get("reason", ""))) + f' <a href="#{anchor}">(full reason, limitation and note '
                    f'below the table)</a>')
        cells += [f"<td>{fmt(r.get('difference_pct'), 3)}</td>", f"<td>{esc(r.get('tolerance', ''))}</td>",
                  f'<td class="status">{label}</td>',
                  f'<td class="l note">{esc(r.get("simulated_signal", ""))}<br>'
                  f'{esc(r.get("experiment_span", ""))}</td>',
                  f'<td class="reason">{text}</td>']
        lines.append(template("table_row.html").substitute(css_class=cls, cells="".join(cells)))
    return template("rows_table.html").substitute(
        intro=f"<p>{esc(intro)}</p>\n" if intro else "",
        head="".join(f'<th class="{"l" if h.startswith(("quantity", "reason")) else ""}">{esc(h)}</th>' for h in head),
        rows="\n".join(lines)) + (f'<ol class="reasons note">{"".join(below)}</ol>' if below else "")


_VERDICT_LABEL = {"pass": "PASS", "known limitations": "KNOWN LIMITATIONS", "fail": "FAIL", "skip": "skipped",
                  "error": "error"}
_VERDICT_CLASS = {"pass": "pass", "known limitations": "known", "fail": "fail", "skip": "skip", "error": "error"}


def index_rows(entries: list) -> str:
    """The index table's rows: per case its verdict in words, counts, and the failing rows by kind."""
    out = []
    for e in entries:
        st = e["status"]
        verdict = e.get("verdict") or ({"pass": "pass"}.get(st) or ("fail" if st == "fail" else st))
        link = f'<a href="{esc(e["link"])}">{esc(e["case"])}</a>' if e.get("link") else esc(e["case"])
        what = esc(e.get("title", ""))
        if e.get("reason"):
            what += f'<br><span class="note">{esc(e["reason"])}</span>'
        parts = []
        if e.get("failing"):
            parts.append("<b>unexplained:</b> " + ", ".join(esc(f) for f in e["failing"]))
        if e.get("known"):
            who = ", ".join(e.get("declared_by") or []) or "the case"
            parts.append(f"<b>declared limitations</b> (by {esc(who)}): " + ", ".join(esc(f) for f in e["known"]))
        failing = "<br>".join(parts)
        wall = fmt(e.get("wall_time_s"), 3) if e.get("wall_time_s") is not None else "—"
        counts = f"{e.get('n_pass', 0)} / {e.get('n_rows', 0)}" if st in ("pass", "fail") else "—"
        label = _VERDICT_LABEL[verdict]
        if e.get("verdict_text") and st in ("pass", "fail"):
            label += f'<br><span class="note">{esc(e["verdict_text"])}</span>'
        out.append(template("index_row.html").substitute(status=_VERDICT_CLASS[verdict], link=link, what=what,
                                                         label=label, counts=counts, wall=wall, failing=failing))
    return "\n".join(out)


def kv_html(info: dict) -> str:
    items = []
    for k, v in info.items():
        if isinstance(v, str) and ("\n" in v or len(v) > 160):
            items.append(f"<dt>{esc(k)}</dt><dd><pre>{esc(v)}</pre></dd>")
        else:
            items.append(f"<dt>{esc(k)}</dt><dd>{esc(v if isinstance(v, str) else json.dumps(v, default=str))}</dd>")
    return template("provenance.html").substitute(items="\n".join(items))


def notice_html(heading: str, body: str, *, level="warn") -> str:
    """A highlighted block (``level`` "warn", "bad" or "good"); ``body`` is escaped."""
    return template("notice.html").substitute(level=level, heading=esc(heading), body=esc(body))
