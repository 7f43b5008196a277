"""`bearing-lab bench` end to end on one scene (short records): the report, the netCDF table and
the auto rules are written, and every row was measured against the converged reference."""
import math
import tomllib

import numpy as np


def test_bench_writes_report_rules_and_rows(tmp_path):
    from bearing_lab.bench import rows_of, run_bench, summary_table
    ds = run_bench(tmp_path, duration=0.05, scenes=["paper-slot"], progress=False, scipy=False)
    for name in ("index.html", "performance.nc", "auto_rules.toml", "work_precision_paper-slot.png"):
        assert (tmp_path / name).stat().st_size > 0
    rows = rows_of(ds)
    assert {r["fidelity"] for r in rows} == {"multibody", "quasi-static", "multibody+dynamic cage"}
    assert {r["contact"] for r in rows} == {"halfspace", "area", "drop", "profile"}
    assert all(r["cost"] > 0 for r in rows)
    assert all(math.isfinite(r["err_peak"]) for r in rows)
    # the tightest adaptive multibody setting sits close to the reference, the cheaper contact
    # models far from it (benchmarks/README.md)
    tight = [r for r in rows if r["setting"] == "dp54 rtol=1e-06" and r["fidelity"] == "multibody"]
    assert tight and tight[0]["err_peak"] < 0.01
    assert min(r["err_peak"] for r in rows if r["contact"] == "profile") > 0.2
    rules = tomllib.loads((tmp_path / "auto_rules.toml").read_text())
    assert rules["defect"]["fidelity"] == "multibody" and rules["defect"]["method"] in ("dp54", "bs32")
    assert "paper-slot" in summary_table(ds)
    assert np.isfinite(ds["cost"].values).all()
