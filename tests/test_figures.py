"""Library figures: built as objects, detached from pyplot, no backend switching."""
import re
from pathlib import Path

import matplotlib.pyplot as plt

from bearing_lab.utils.figures import new_figure

PKG = Path(__file__).resolve().parents[1] / "bearing_lab"


def test_new_figure_is_detached_and_drawable(tmp_path):
    before = plt.get_fignums()
    fig = new_figure(figsize=(3, 2), layout="constrained")
    fig.subplots().plot([0, 1], [1, 0])
    assert plt.get_fignums() == before            # pyplot does not hold it open
    assert tuple(fig.get_size_inches()) == (3, 2)
    fig.savefig(tmp_path / "f.png")
    assert (tmp_path / "f.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_no_backend_switch_and_no_pyplot_figures_in_library_code():
    switch = re.compile(r"matplotlib\.use\(|plt\.switch_backend|pyplot\.switch_backend")
    creates = re.compile(r"plt\.(subplots|figure)\(")
    bad = []
    for p in PKG.rglob("*.py"):
        text = p.read_text()
        if switch.search(text):
            bad.append(f"{p.name}: switches the backend")
        # compare.py: plot methods that return an Axes keep pyplot's figure, as pandas and
        # xarray do, so that Jupyter shows it when the cell ends
        if creates.search(text) and p.name not in ("figures.py", "compare.py"):
            bad.append(f"{p.name}: creates a pyplot figure (use bearing_lab.utils.figures.new_figure)")
    assert not bad, bad
