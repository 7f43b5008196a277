"""Reports that open from disk: one page layer for validation, the studies and the benchmark.

Why self-contained files: a reviewer gets one folder, opens ``index.html`` from a mail
attachment or an archive, and sees every figure without a server or network.  Modelled
on MNE's ``Report``: sections are added one by one and ``save()`` writes HTML, or JSON
that :meth:`Report.load` reads back.  Every page and table is a template file under
``report/templates/``; figures are matplotlib ``Figure`` objects (library code never
switches the plotting backend); provenance and the citation are report methods.

Public API
----------
::

    Report(title, *, subtitle="", verdict=True)           -- one page (verdict=False: no validation verdict)
    Report.add_rows(rows, title, *, show_reference, show_paper, intro) -- the validation table
    Report.add_comparison(result, title, *, figures=True)  -- a ComparisonResult's table (+ figures)
    Report.add_figure(fig, title, *, caption) / add_figures([(fig, caption)], title)
    Report.add_table(rows, title, *, columns, intro)       -- a list of dicts as a table
    Report.add_text(text, title, *, lead, note, preformatted) -- paragraphs (escaped), a bold lead, a <pre> block
    Report.add_html(html, title) / add_notice(heading, body, level=)
    (any add_* with title=None continues the last section: text, a figure and a table under one heading)
    Report.add_provenance(info=None, *, software=True)     -- inputs, checksums, versions, revision, host, date
    Report.add_citation()                                  -- how to cite (software version, the paper)
    Report.save(path) / Report.load(path)                  -- ".html" (self-contained) or ".json"
    write_index(path, entries, *, title, notes)            -- the page listing all cases
    rows_table(rows), table_html(rows), text_html(text), figure_png(fig), fmt(v), esc(text) -- the HTML pieces
"""
from ..utils.figures import figure_png  # noqa: F401
from .html import esc, fmt, rows_table, table_html, text_html  # noqa: F401
from .page import Report, write_index  # noqa: F401

__all__ = ["Report", "write_index", "rows_table", "table_html", "text_html", "figure_png", "fmt", "esc"]
