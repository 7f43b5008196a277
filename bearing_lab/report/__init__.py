"""HTML validation reports that open from disk (figures embedded as base64 PNG).

Why self-contained files: a reviewer gets one folder, opens ``index.html`` from a
mail attachment or an archive, and sees every figure without a server or network.
Modelled on MNE's ``Report``: sections are added one by one (``add_comparison``,
``add_figure``, ``add_table``, ``add_html``) and ``save()`` writes HTML, or JSON data
that :meth:`Report.load` reads back.  The page layout lives in template files under
``report/templates/`` (``string.Template`` syntax, so no template engine is needed at run time).

Public API
----------
Report(title, *, subtitle="")                       -- one case's page
Report.add_comparison(result, title, *, tags=())    -- the table (+ waveform/spectrum/SES figures)
Report.add_figure(fig, title, *, caption="", tags=()) -- a matplotlib figure, embedded as PNG
Report.add_table(rows, title, *, columns=None)      -- a list of dicts as an HTML table
Report.add_html(html, title, *, tags=())            -- raw HTML
Report.save(path)                                   -- ".html" (self-contained) or ".json"
Report.load(path)                                   -- a Report from its ".json"
rows_table(rows)                                    -- the validation table as HTML
write_index(path, entries, *, title, notes)         -- the page listing all cases
figure_png(fig, dpi)                                -- base64 PNG of a figure
"""
from __future__ import annotations

import base64
import datetime as _dt
import html
import io
import json
import math
import re
from pathlib import Path
from string import Template

__all__ = ["Report", "rows_table", "write_index", "figure_png", "fmt"]

_TEMPLATES = Path(__file__).with_name("templates")


def _template(name: str) -> Template:
    return Template((_TEMPLATES / name).read_text(encoding="utf-8"))


def _css() -> str:
    return (_TEMPLATES / "base.css").read_text(encoding="utf-8")


def _now() -> str:
    return _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC")


def _version() -> str:
    from .. import __version__
    return __version__


def esc(text) -> str:
    return html.escape(str(text), quote=True)


def fmt(v, digits=5) -> str:
    """A number for a table: NaN / None as an em dash, otherwise ``digits`` significant digits."""
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


def figure_png(fig, dpi=80) -> str:
    """Base64 PNG of a matplotlib figure (the figure is closed)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    if getattr(fig.canvas, "manager", None) is not None:  # a pyplot figure: release it
        import matplotlib.pyplot as plt
        plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def rows_table(rows: list[dict], *, show_paper=False) -> str:
    """HTML table of validation rows (quantity, simulation, experiment, difference, tolerance, pass)."""
    head = ["quantity", "units", "simulation", "experiment", "reference"]
    if show_paper:
        head += ["paper: experiment", "paper: simulation"]
    head += ["difference", "difference %", "tolerance", "pass", "reason / note"]
    out = ["<table>", "<tr>" + "".join(f'<th class="{"l" if h in ("quantity", "reference", "reason / note") else ""}">'
                                       f"{esc(h)}</th>" for h in head) + "</tr>"]
    for r in rows:
        ok = bool(r.get("pass"))
        cells = [f'<td class="l">{esc(r.get("label") or r["quantity"])}</td>', f"<td>{esc(r.get('units', ''))}</td>",
                 f"<td>{fmt(r.get('simulation'))}</td>", f"<td>{fmt(r.get('experiment'))}</td>",
                 f'<td class="l">{esc(r.get("reference", ""))}</td>']
        if show_paper:
            cells += [f"<td>{fmt(r.get('paper_experiment'))}</td>", f"<td>{fmt(r.get('paper_simulation'))}</td>"]
        note = esc(r.get("reason", ""))
        if r.get("note"):
            note += f"<br><em>{esc(r['note'])}</em>"
        cells += [f"<td>{fmt(r.get('difference'))}</td>", f"<td>{fmt(r.get('difference_pct'), 3)}</td>",
                  f"<td>{esc(r.get('tolerance', fmt(r.get('tolerance_pct'))))}</td>",
                  f'<td class="status">{"pass" if ok else "FAIL"}</td>', f'<td class="reason">{note}</td>']
        out.append(f'<tr class="{"pass" if ok else "fail"}">' + "".join(cells) + "</tr>")
    out.append("</table>")
    return "\n".join(out)


def _anchor(title: str, used: set) -> str:
    a = re.sub(r"[^a-z0-9]+", "-", title.lower()).strip("-") or "section"
    base, i = a, 1
    while a in used:
        i += 1
        a = f"{base}-{i}"
    used.add(a)
    return a


class Report:
    """A validation report: ordered sections, saved as one self-contained HTML page."""

    def __init__(self, title: str, *, subtitle: str = ""):
        self.title = title
        self.subtitle = subtitle
        self.sections: list[dict] = []   # {"title", "html", "tags"}
        self.rows: list[dict] = []
        self.info: dict = {}

    # ---- adding content
    def add_html(self, html_text: str, title: str, *, tags=()):
        self.sections.append({"title": title, "html": html_text, "tags": list(tags)})
        return self

    def add_figure(self, fig, title: str, *, caption: str = "", tags=(), dpi=80):
        png = figure_png(fig, dpi=dpi)
        body = _template("figure.html").substitute(alt=esc(title), png=png, caption=esc(caption))
        return self.add_html(body, title, tags=tags)

    def add_figures(self, figs, title: str, *, tags=(), dpi=80):
        """Several (fig, caption) pairs in one section."""
        body = "\n".join(_template("figure.html").substitute(alt=esc(title), png=figure_png(f, dpi=dpi),
                                                            caption=esc(c)) for f, c in figs)
        return self.add_html(body, title, tags=tags)

    def add_table(self, rows: list[dict], title: str, *, columns=None, tags=(), intro=""):
        if not rows:
            return self.add_html(f"<p>{esc(intro)}</p><p>(no rows)</p>", title, tags=tags)
        columns = columns or list(rows[0])
        out = [f"<p>{esc(intro)}</p>" if intro else "", "<table>",
               "<tr>" + "".join(f'<th class="l">{esc(c)}</th>' for c in columns) + "</tr>"]
        for r in rows:
            out.append("<tr>" + "".join(
                f'<td class="{"" if isinstance(r.get(c), (int, float)) and not isinstance(r.get(c), bool) else "l"}">'
                f"{fmt(r.get(c)) if isinstance(r.get(c), (int, float)) else esc(r.get(c, ''))}</td>"
                for c in columns) + "</tr>")
        out.append("</table>")
        return self.add_html("\n".join(out), title, tags=tags)

    def add_comparison(self, result, title: str = "Comparison", *, tags=(), figures=True, show_paper=False,
                       intro=""):
        """The comparison table; with ``figures`` also its waveform, spectrum and SES plots."""
        rows = result.rows if hasattr(result, "rows") else list(result)
        self.rows.extend(rows)
        body = (f"<p>{esc(intro)}</p>" if intro else "") + rows_table(rows, show_paper=show_paper)
        self.add_html(body, title, tags=tags)
        if figures and hasattr(result, "plot_waveforms"):
            from matplotlib.figure import Figure
            fig = Figure(figsize=(10, 9), layout="constrained")
            axes = fig.subplots(3, 1)
            result.plot_waveforms(ax=axes[0], window_s=(0, 0.1))
            result.plot_spectra(ax=axes[1])
            result.plot_envelope(ax=axes[2], fmax=600)
            self.add_figure(fig, f"{title}: figures", tags=tags)
        return self

    def add_provenance(self, info: dict, title="Provenance", *, tags=()):
        self.info.update(info)
        items = []
        for k, v in info.items():
            if isinstance(v, str) and ("\n" in v or len(v) > 160):
                items.append(f"<dt>{esc(k)}</dt><dd><pre>{esc(v)}</pre></dd>")
            else:
                items.append(f"<dt>{esc(k)}</dt><dd>{esc(v if isinstance(v, str) else json.dumps(v, default=str))}</dd>")
        return self.add_html('<dl class="kv">' + "\n".join(items) + "</dl>", title, tags=tags)

    # ---- output
    @property
    def passed(self) -> bool:
        return all(r.get("pass") for r in self.rows)

    def to_html(self) -> str:
        used: set = set()
        secs, toc = [], []
        for s in self.sections:
            a = _anchor(s["title"], used)
            toc.append(f'<a href="#{a}">{esc(s["title"])}</a>')
            secs.append(_template("section.html").substitute(anchor=a, title=esc(s["title"]), body=s["html"]))
        n_pass = sum(bool(r.get("pass")) for r in self.rows)
        status = "pass" if self.rows and n_pass == len(self.rows) else ("fail" if self.rows else "skip")
        return _template("case.html").substitute(
            title=esc(self.title), subtitle=esc(self.subtitle), css=_css(), toc=" ".join(toc),
            sections="\n".join(secs), n_pass=n_pass, n_rows=len(self.rows), status_class=status,
            status_text={"pass": "all rows pass", "fail": "some rows fail", "skip": "no rows"}[status],
            date=_now(), version=_version())

    def save(self, path, *, overwrite=True):
        """Write ``.html`` (self-contained page) or ``.json`` (sections, rows, info: reloadable)."""
        path = Path(path)
        if path.exists() and not overwrite:
            raise FileExistsError(f"{path} exists (pass overwrite=True)")
        path.parent.mkdir(parents=True, exist_ok=True)
        from .._files import write_text
        if path.suffix == ".json":
            write_text(path, json.dumps({"title": self.title, "subtitle": self.subtitle, "sections": self.sections,
                                         "rows": self.rows, "info": self.info}, default=str, allow_nan=True))
        elif path.suffix in (".html", ".htm"):
            write_text(path, self.to_html())
        else:
            raise ValueError(f"Invalid value for the report path suffix: allowed are '.html' and '.json', "
                             f"but got {path.suffix!r} instead.")
        return path

    @classmethod
    def load(cls, path) -> "Report":
        d = json.loads(Path(path).read_text(encoding="utf-8"))
        r = cls(d["title"], subtitle=d.get("subtitle", ""))
        r.sections, r.rows, r.info = d["sections"], d["rows"], d.get("info", {})
        return r


def write_index(path, entries: list[dict], *, title="bearing_lab validation", notes=()):
    """The page listing all cases.

    ``entries``: dicts with ``case``, ``title``, ``status`` ("pass", "fail", "skip", "error"),
    ``n_pass``, ``n_rows``, ``wall_time_s``, ``failing`` (labels), ``link`` (relative, or None),
    ``reason`` (for skipped / errored cases).
    """
    rows = []
    for e in entries:
        st = e["status"]
        link = f'<a href="{esc(e["link"])}">{esc(e["case"])}</a>' if e.get("link") else esc(e["case"])
        what = esc(e.get("title", ""))
        if e.get("reason"):
            what += f'<br><span class="note">{esc(e["reason"])}</span>'
        failing = ", ".join(esc(f) for f in e.get("failing", []))
        wt = fmt(e.get("wall_time_s"), 3) if e.get("wall_time_s") is not None else "—"
        counts = f"{e.get('n_pass', 0)} / {e.get('n_rows', 0)}" if st in ("pass", "fail") else "—"
        label = {"pass": "pass", "fail": "FAIL", "skip": "skipped", "error": "error"}[st]
        rows.append(f'<tr class="{st}"><td class="l">{link}</td><td class="l">{what}</td>'
                    f'<td class="status">{label}</td><td>{counts}</td><td>{wt}</td>'
                    f'<td class="l reason">{failing}</td></tr>')
    notes_html = "".join(f'<p class="note">{esc(n)}</p>' for n in notes)
    page = _template("index.html").substitute(title=esc(title), css=_css(), date=_now(), version=_version(),
                                              rows="\n".join(rows), notes=notes_html)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    from .._files import write_text
    return write_text(path, page)
