"""The notebooks run top to bottom (nbclient) against the public recordings (~15 s each; a
cell that runs for 120 s is an error), in the kernel's own matplotlib backend
(inline), as a user runs them: every figure shows once as an image, progress bars render as
widgets."""
import os
from pathlib import Path

import pytest

from tests.helpers import require

NB_DIR = Path(__file__).resolve().parents[2] / "notebooks"
IN_CI = os.environ.get("CI", "").lower() in ("1", "true", "yes")


# figures each notebook shows, and whether it shows a progress bar
NOTEBOOKS = {"01_open_analyse_plot.ipynb": (1, False), "02_offset_skew_study.ipynb": (1, True)}


@pytest.mark.parametrize("name", sorted(NOTEBOOKS))
def test_notebook_runs(name, mirror, monkeypatch):
    nbformat = require("nbformat")
    nbclient = require("nbclient")
    if mirror is None or not (Path(mirror) / "cwru" / "130_OR007@6_0.mat").is_file():
        if IN_CI:
            pytest.fail("BEARING_LAB_MIRROR with cwru/130_OR007@6_0.mat is required in CI")
        pytest.skip("no BEARING_LAB_MIRROR with cwru/130_OR007@6_0.mat")
    monkeypatch.setenv("BEARING_LAB_MIRROR", str(mirror))
    monkeypatch.delenv("MPLBACKEND", raising=False)   # the kernel picks its inline backend
    nb = nbformat.read(NB_DIR / name, as_version=4)
    nbclient.NotebookClient(nb, timeout=120, kernel_name="python3",
                            resources={"metadata": {"path": str(NB_DIR)}}).execute()
    errors = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
              if o.get("output_type") == "error"]
    assert not errors
    n_fig, has_bar = NOTEBOOKS[name]
    outputs = [[o for o in c.get("outputs", []) if o.get("output_type") in ("execute_result", "display_data")]
               for c in nb.cells if c.cell_type == "code"]
    pngs = [sum("image/png" in o.get("data", {}) for o in cell) for cell in outputs]
    assert sum(pngs) == n_fig and max(pngs) <= 1, f"image outputs per cell: {pngs}"
    bars = [o for cell in outputs for o in cell
            if "application/vnd.jupyter.widget-view+json" in o.get("data", {})]
    assert bool(bars) == has_bar, f"{len(bars)} progress-bar widgets"
