"""Each shipped case's row verdicts against the committed table (benchmarks/verdicts.csv).

A changed verdict fails here with the row's numbers and note, its cause; when the change is
intended, `make verdicts` rewrites the table and the diff shows it in review."""
import importlib.util
import math
from pathlib import Path

import pytest

pytestmark = [pytest.mark.data, pytest.mark.xdist_group("validation_cwru")]

ROOT = Path(__file__).resolve().parents[2]


def _script():
    spec = importlib.util.spec_from_file_location("verdicts", ROOT / "benchmarks" / "verdicts.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_margin_is_the_share_of_the_tolerance_left():
    v = _script()
    assert v.margin({"simulation": 101.0, "experiment": 100.0, "rule": "pct", "tolerance_pct": 1.0}) == \
        pytest.approx(0.0)
    assert v.margin({"simulation": 100.5, "experiment": 100.0, "rule": "pct", "tolerance_pct": 1.0}) == \
        pytest.approx(0.5)
    assert v.margin({"simulation": 4.0, "experiment": 1.0, "rule": "factor", "tolerance_pct": 100.0}) == \
        pytest.approx(-1.0)
    assert math.isnan(v.margin({"simulation": None, "experiment": 1.0, "rule": "pct", "tolerance_pct": 1.0}))


def test_every_shipped_verdict_matches_the_committed_table(default_validation):
    """The rows of the run's validation of the default set (tests/conftest.py), the cases `verdicts.py table`
    runs, read as the script reads them."""
    v = _script()
    names = v.shipped_names()
    now = v.report_rows(default_validation.reports, [(n, "no summary.json (an error)") for n in names])
    committed = v.read(ROOT / "benchmarks" / "verdicts.csv")
    was = {(r["case"], r["quantity"]): r for r in committed}
    is_ = {(r["case"], r["quantity"]): r for r in now}
    diffs = [f"{k}: row {'added' if k not in was else 'removed'}" for k in set(was) ^ set(is_)]
    for k in sorted(set(was) & set(is_)):
        if was[k]["status"] != is_[k]["status"]:
            r = is_[k]
            diffs.append(f"{k}: {was[k]['status']} -> {r['status']} (simulation {r['simulation']}, experiment "
                         f"{r['experiment']}, margin {r.get('margin', float('nan')):.3g}; {r['note']})")
    assert not diffs, "verdicts changed (run `make verdicts` if intended):\n" + "\n".join(diffs)
