"""Figures for the plotting API: created through pyplot, then detached from it.

:func:`new_figure` returns a ``matplotlib.figure.Figure`` that pyplot no longer tracks
(``plt.close`` right after creation).  So

- a script or the command line never accumulates open figures, and library code never
  switches the backend (``savefig`` works headless, whatever backend the user chose);
- in Jupyter the figure keeps the session's canvas, so returning it as a cell's value shows
  it inline (a bare ``Figure()`` built without pyplot shows only its text form there), and it
  is not shown a second time when the cell ends.
"""
from __future__ import annotations

import base64
import io

__all__ = ["new_figure", "figure_png"]


def new_figure(figsize=None, *, layout=None, **kwargs):
    """A new detached ``matplotlib.figure.Figure`` (``figsize`` in inches).

    Examples
    --------
    >>> fig = new_figure(figsize=(4, 3), layout="constrained")
    >>> ax = fig.subplots()
    >>> import matplotlib.pyplot as plt
    >>> fig in map(plt.figure, plt.get_fignums())   # not tracked by pyplot
    False
    """
    import matplotlib.pyplot as plt  # lazy.load would import matplotlib itself (0.075 s) with this module
    fig = plt.figure(figsize=figsize, layout=layout, **kwargs)
    plt.close(fig)
    return fig


def figure_png(fig, dpi=80) -> str:
    """Base64 PNG of a matplotlib figure (a pyplot figure is closed afterwards), for an ``<img>``
    in a self-contained page.

    See Also
    --------
    new_figure, bearing_lab.report.Report.add_figure

    Examples
    --------
    >>> import base64
    >>> fig = new_figure(figsize=(2, 1))
    >>> base64.b64decode(figure_png(fig, dpi=50))[1:4]      # the PNG signature
    b'PNG'
    """
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    if getattr(fig.canvas, "manager", None) is not None:
        import matplotlib.pyplot as plt  # lazy.load would import matplotlib itself (0.075 s) with this module
        plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode("ascii")
