"""The notebooks run top to bottom (nbclient) against the public recordings (~15 s each; the
assertion allows 60 s for a loaded 2-core CI machine)."""
import os
import time
from pathlib import Path

import pytest

from tests.helpers import require

NB_DIR = Path(__file__).resolve().parents[2] / "notebooks"
IN_CI = os.environ.get("CI", "").lower() in ("1", "true", "yes")


@pytest.mark.parametrize("name", ["01_open_analyse_plot.ipynb", "02_offset_skew_study.ipynb"])
def test_notebook_runs(name, mirror, monkeypatch):
    nbformat = require("nbformat")
    nbclient = require("nbclient")
    if mirror is None or not (Path(mirror) / "cwru" / "130_OR007@6_0.mat").is_file():
        if IN_CI:
            pytest.fail("BEARING_LAB_MIRROR with cwru/130_OR007@6_0.mat is required in CI")
        pytest.skip("no BEARING_LAB_MIRROR with cwru/130_OR007@6_0.mat")
    monkeypatch.setenv("BEARING_LAB_MIRROR", str(mirror))
    monkeypatch.setenv("MPLBACKEND", "Agg")
    nb = nbformat.read(NB_DIR / name, as_version=4)
    t0 = time.perf_counter()
    nbclient.NotebookClient(nb, timeout=120, kernel_name="python3",
                            resources={"metadata": {"path": str(NB_DIR)}}).execute()
    took = time.perf_counter() - t0
    errors = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
              if o.get("output_type") == "error"]
    assert not errors
    assert took < 60, f"{name} took {took:.0f} s (budget 60 s on a loaded 2-core machine)"
