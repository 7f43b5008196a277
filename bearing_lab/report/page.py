"""The report page: ordered sections saved as one self-contained HTML file (or reloadable JSON)."""
from __future__ import annotations

import datetime as _dt
import json
import re
from pathlib import Path

from .._version import __version__
from ..errors import check_choice
from ..utils._files import atomic_open
from ..utils.figures import new_figure
from .html import (css, esc, figure_html, kv_html, notice_html, rows_table, table_html, template,
                   index_rows, text_html)
from .provenance import citation, environment

__all__ = ["Report", "write_index"]


def _now() -> str:
    return _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC")


def _head(title: str) -> str:
    """The document head every page shares (``head.html``: title, the inline stylesheet)."""
    return template("head.html").substitute(title=esc(title), css=css())


def _anchor(title: str, used: set) -> str:
    a = re.sub(r"[^a-z0-9]+", "-", title.lower()).strip("-") or "section"
    base, i = a, 1
    while a in used:
        i += 1
        a = f"{base}-{i}"
    used.add(a)
    return a


class Report:
    """One page: sections added in order (MNE's ``Report`` style), saved as self-contained HTML.

    Figures are matplotlib :class:`~matplotlib.figure.Figure` objects (no backend is switched),
    embedded as PNG.  ``rows`` collects the validation rows added with :meth:`add_rows`.  Every
    ``add_*`` method returns the report, so calls chain; one given ``title=None`` adds to the last
    section instead of starting one (text, a figure and a table under one heading).
    ``verdict=False`` makes a page without the validation verdict (badge, rows passing, link to the
    case index): the studies' and the benchmark's pages.

    Parameters
    ----------
    title : str
        The page's heading.
    subtitle : str
        A line under it.
    verdict : bool
        Show the validation verdict (default); False for pages that hold no validation.

    See Also
    --------
    write_index : the page listing several reports.
    bearing_lab.validation.run_case : writes one per case.

    Examples
    --------
    >>> from bearing_lab.validation import Tolerance, make_row
    >>> tol = Tolerance("pct", 1.0, reason="kinematic frequencies hold to 1-2 % under slip")
    >>> report = Report("Rig 3, outer race").add_rows([make_row("bpfo", 91.5, 92.19, tol, label="BPFO",
    ...                                                          units="Hz")])
    >>> report.status()
    ('pass', 'PASS: every row agrees')
    >>> path = report.save("rig3.html")
    >>> Report.load(report.save("rig3.json")).rows[0]["label"]
    'BPFO'
    """

    def __init__(self, title: str, *, subtitle: str = "", verdict: bool = True):
        self.title = title
        self.subtitle = subtitle
        self.verdict = verdict
        self.sections: list[dict] = []
        self.rows: list[dict] = []
        self.info: dict = {}

    # ---- adding content
    def add_html(self, html_text: str, title: str | None):
        """HTML as it is, in a section of its own (``title``) or, with ``title=None``, after the last
        section's content (in a "Notes" section on an empty page)."""
        if title is None and self.sections:
            self.sections[-1]["html"] += "\n" + html_text
        else:
            self.sections.append({"title": "Notes" if title is None else title, "html": html_text})
        return self

    def add_text(self, text, title: str | None, *, lead="", note=False, preformatted=False):
        """Paragraphs of text (escaped; see :func:`~bearing_lab.report.html.text_html` for ``lead``,
        ``note`` and ``preformatted``)."""
        return self.add_html(text_html(text, lead=lead, note=note, preformatted=preformatted), title)

    def add_figure(self, fig, title: str | None, *, caption: str = "", alt=None, dpi=80):
        """A figure; ``alt`` describes it to screen readers (default: ``title``, else ``caption``, else the
        section's title)."""
        if alt is None:
            alt = title if title is not None else (caption or (self.sections[-1]["title"] if self.sections else ""))
        return self.add_html(figure_html(fig, alt, caption, dpi=dpi), title)

    def add_figures(self, figs, title: str, *, dpi=80, intro=""):
        """Several ``(figure, caption)`` pairs in one section."""
        body = "\n".join(figure_html(f, title, c, dpi=dpi) for f, c in figs)
        return self.add_html((f"<p>{esc(intro)}</p>" if intro else "") + body, title)

    def add_table(self, rows: list, title: str | None, *, columns=None, intro=""):
        return self.add_html(table_html(rows, columns=columns, intro=intro), title)

    def add_rows(self, rows: list, title: str = "Comparison table", *, show_reference=False, show_paper=False,
                 intro=""):
        """Validation rows (see :func:`bearing_lab.validation.rows.make_row`) as the status table."""
        self.rows.extend(rows)
        return self.add_html(rows_table(rows, show_reference=show_reference, show_paper=show_paper, intro=intro),
                             title)

    def add_comparison(self, result, title: str = "Comparison", *, figures=True, intro=""):
        """A :class:`~bearing_lab.compare.ComparisonResult`: its table, and its figures."""
        self.add_rows(result.rows, title, intro=intro)
        if figures:
            fig = new_figure(figsize=(10, 9), layout="constrained")
            axes = fig.subplots(3, 1)
            result.plot_waveforms(ax=axes[0], window_s=(0, 0.1))
            result.plot_spectra(ax=axes[1])
            result.plot_envelope(ax=axes[2], fmax=600)
            self.add_figure(fig, f"{title}: figures")
        return self

    def add_notice(self, heading: str, body: str, *, level="warn", title=None):
        """A highlighted block ("warn", "bad", "good"): in its own section when ``title`` is given,
        else appended to the last section (or a "Notes" section)."""
        block = notice_html(heading, body, level=level)
        if title is not None or not self.sections:
            return self.add_html(block, title or "Notes")
        self.sections[-1]["html"] += "\n" + block
        return self

    def add_provenance(self, info: dict | None = None, title="Provenance", *, software=True):
        """Where the results came from: ``info`` (inputs, checksums) and, with ``software``, the
        package versions, source revision, host and date."""
        merged = dict(info or {})
        if software:
            merged.update(environment())
        self.info.update(merged)
        return self.add_html(kv_html(merged), title)

    def add_citation(self, title="How to cite", *, note=""):
        c = citation()
        body = template("cite.html").substitute(software=esc(c["software"]), paper=esc(c["paper"]), note=esc(note))
        return self.add_html(body, title)

    # ---- output
    @property
    def passed(self) -> bool:
        return all(r.get("pass") for r in self.rows)

    def status(self) -> tuple:
        """(css class, text) of the page's result badge: the verdict in words."""
        if not self.rows:
            return "skip", "no rows"
        failing = [r for r in self.rows if not r.get("pass")]
        if not failing:
            return "pass", "PASS: every row agrees"
        if all(r.get("known_limitation") for r in failing):
            return "known", "KNOWN LIMITATIONS: every failing row is a limitation the case declares"
        return "fail", "FAIL: rows fail without a declared reason"

    def to_html(self) -> str:
        used: set = set()
        secs, toc = [], []
        for s in self.sections:
            a = _anchor(s["title"], used)
            toc.append(f'<a href="#{a}">{esc(s["title"])}</a>')
            secs.append(template("section.html").substitute(anchor=a, title=esc(s["title"]), body=s["html"]))
        if not self.verdict:
            return template("page.html").substitute(
                head=_head(self.title), title=esc(self.title), subtitle=esc(self.subtitle), toc=" ".join(toc),
                sections="\n".join(secs), date=_now(), version=__version__)
        n_pass = sum(bool(r.get("pass")) for r in self.rows)
        n_known = sum(bool(r.get("known_limitation")) and not r.get("pass") for r in self.rows)
        cls, text = self.status()
        return template("case.html").substitute(
            head=_head(self.title), title=esc(self.title), subtitle=esc(self.subtitle), toc=" ".join(toc),
            sections="\n".join(secs), n_pass=n_pass, n_rows=len(self.rows), status_class=cls, status_text=text,
            known=f" ({n_known} failing as limitations the case declares)" if n_known else "", date=_now(),
            version=__version__)

    def save(self, path, *, overwrite=True):
        """Write ``.html`` (self-contained page) or ``.json`` (sections, rows, info: reloadable), atomically."""
        path = Path(path)
        if path.exists() and not overwrite:
            raise FileExistsError(f"{path} exists (pass overwrite=True)")
        if path.suffix == ".json":
            text = json.dumps({"title": self.title, "subtitle": self.subtitle, "verdict": self.verdict,
                               "sections": self.sections,
                               "rows": self.rows, "info": self.info}, default=str, allow_nan=True)
        elif path.suffix in (".html", ".htm"):
            text = self.to_html()
        else:
            check_choice(path.suffix, (".html", ".htm", ".json"), f"{path}: suffix", ValueError)
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_open(path, "w", encoding="utf-8") as fh:
            fh.write(text)
        return path

    @classmethod
    def load(cls, path) -> "Report":
        d = json.loads(Path(path).read_text(encoding="utf-8"))
        r = cls(d["title"], subtitle=d.get("subtitle", ""), verdict=d.get("verdict", True))
        r.sections, r.rows, r.info = d["sections"], d["rows"], d.get("info", {})
        return r


def write_index(path, entries: list, *, title="bearing_lab validation", notes=(), opening=""):
    """The page listing all cases, written atomically; returns its path.

    Parameters
    ----------
    path : str or path
        The ``.html`` file to write (its folder is created).
    entries : list of dict
        ``case``, ``title``, ``status`` ("pass", "fail", "skip", "error"), ``n_pass``, ``n_rows``,
        ``wall_time_s``, ``failing`` and ``known`` (row labels), ``link`` (relative, or None),
        ``reason`` (for skipped or errored cases); optionally ``verdict``, ``verdict_text`` and
        ``declared_by``.
    title : str
        The page's heading.
    notes : sequence of str
        Paragraphs under the table (escaped).
    opening : str
        HTML shown above the table.

    See Also
    --------
    Report, bearing_lab.validation.run_validation

    Examples
    --------
    >>> p = write_index("reports/index.html", [
    ...     {"case": "rig3", "title": "Rig 3, outer race", "status": "pass", "n_pass": 1, "n_rows": 1,
    ...      "wall_time_s": 12.0, "failing": [], "known": [], "link": "rig3/index.html"}])
    >>> 'href="rig3/index.html"' in p.read_text(encoding="utf-8")
    True
    """
    notes_html = "".join(f'<p class="note">{esc(n)}</p>' for n in notes)
    page = template("index.html").substitute(head=_head(title), title=esc(title), date=_now(), version=__version__,
                                              rows=index_rows(entries), notes=notes_html,
                                              verdicts=opening)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_open(path, "w", encoding="utf-8") as fh:
        fh.write(page)
    return path
