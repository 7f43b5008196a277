"""Rows can fail: NaN is a failure, ratios need a tolerance, known limitations are told apart; the table of
quantities decides signal and span."""
import math

import pytest

from bearing_lab.analysis.structural_path import StructuralPath
from bearing_lab.errors import ValidationCaseError
from bearing_lab.validation import QUANTITIES, Tolerance, make_row
from bearing_lab.validation.quantities import SIGNALS, SPANS
from bearing_lab.validation.evaluate import evaluate_rows

NAN = float("nan")


def _row(s, e, tol=None, **kw):
    return make_row("q", s, e, tol or Tolerance("pct", 1.0, "r"), label="q", units="1", **kw)


def test_tolerance_rules():
    pct = Tolerance("pct", 1.0, "r")
    assert pct.check(100.9, 100.0) and not pct.check(101.1, 100.0) and not pct.check(NAN, 100.0)
    fac = Tolerance("factor", 2.0, "r")
    assert fac.check(0.5, 1.0) and fac.check(2.0, 1.0) and not fac.check(2.1, 1.0) and not fac.check(0.49, 1.0)
    assert not fac.check(-1.0, 1.0) and fac.pct == 100.0
    for bad in (("pct", 1.0, "  "), ("ordering", 1.0, "r"), ("factor", 0.9, "r"), ("pct", NAN, "r"),
                ("pct", -1.0, "r")):
        with pytest.raises(ValidationCaseError):
            Tolerance(*bad)


def test_a_missing_value_is_a_failure_on_either_side_or_both():
    for s, e in ((NAN, NAN), (NAN, 161.7), (162.0, NAN), (None, 1.0)):
        r = _row(s, e)
        assert not r["pass"] and r["status"] == "fail" and "missing value" in r["note"]
    assert _row(100.5, 100.0)["pass"]


def test_a_line_family_absent_from_both_signals_agrees_and_absent_from_one_fails():
    tol = QUANTITIES["bpfi"].tolerance
    both = make_row("bpfi", NAN, NAN, tol, label="BPFI", units="Hz", absence_agrees=True)
    assert both["pass"] and "absence" in both["note"]
    for s, e in ((NAN, 161.7), (162.0, NAN)):
        r = make_row("bpfi", s, e, tol, label="BPFI", units="Hz", absence_agrees=True)
        assert not r["pass"] and "missing value" in r["note"]
    assert not make_row("bpfi", 158.0, 161.7, tol, label="BPFI", units="Hz", absence_agrees=True)["pass"]


def test_a_ratio_of_1295_against_1_24_fails():
    """The impulse-strength ratio the old ordering rule let pass (both on the same side of 1)."""
    tol = QUANTITIES["impulse_strength_ratio"].tolerance
    assert tol.kind == "factor"
    r = make_row("impulse_strength_ratio", 1295.0, 1.24, tol, label="ratio", units="1")
    assert not r["pass"]
    assert make_row("impulse_strength_ratio", 1.5, 1.24, tol, label="ratio", units="1")["pass"]


def test_known_limitation_and_untrusted_rows():
    known = Tolerance("factor", 2.0, "r", known_limitation="the load zone")
    r = _row(10.0, 1.0, known)
    assert not r["pass"] and r["status"] == "known limitation"
    assert _row(1.0, 1.0, known)["status"] == "pass"
    u = _row(1.0, 1.0, untrusted="the structural-path fit is degraded")
    assert not u["pass"] and "not trusted" in u["note"]


def test_every_quantity_has_a_signal_a_span_and_a_reasoned_tolerance():
    for key, q in QUANTITIES.items():
        assert q.signal in SIGNALS and q.span in SPANS, key
        assert q.tolerance.reason.strip() and "issue" not in q.tolerance.reason, key
    assert QUANTITIES["bpfo"].span == "record" and QUANTITIES["rms"].span == "segment"
    assert QUANTITIES["rms"].signal == "path+background" and QUANTITIES["rms_model"].signal == "model"


def _measured(**values):
    return {**values, "extras": {"notes": {}}}


def test_rows_take_signal_and_span_from_the_table():
    """Break it: the experiment's record and segment differ, so a wrong span shows in the number."""
    exp = {"record": _measured(bpfo=107.6, rms=1.0), "segment": _measured(bpfo=99.0, rms=6.6)}
    sim = {"model": _measured(bpfo=107.3, rms=0.01), "path": _measured(bpfo=1.0, rms=3.0),
           "path+background": _measured(bpfo=2.0, rms=6.0)}
    ctx = {"path": StructuralPath.identity(), "span_text": {"record": "whole", "segment": "segment"}}
    tol = {k: QUANTITIES[k].tolerance for k in ("bpfo", "rms", "rms_model", "rms_path")}
    rows = {r["quantity"]: r for r in evaluate_rows(tol, exp, sim, context=ctx)}
    assert (rows["bpfo"]["simulation"], rows["bpfo"]["experiment"]) == (107.3, 107.6) and rows["bpfo"]["pass"]
    assert (rows["rms"]["simulation"], rows["rms"]["experiment"]) == (6.0, 6.6) and rows["rms"]["pass"]
    assert rows["rms_model"]["simulation"] == 0.01 and not rows["rms_model"]["pass"]
    assert rows["rms_path"]["simulation"] == 3.0
    assert all(r["independent"] for r in rows.values())


def test_rows_after_a_degraded_path_fail_and_fitted_rows_are_marked():
    exp = {"record": _measured(bpfo=107.6), "segment": _measured(rms=6.6, peak=30.0)}
    sim = {"model": _measured(bpfo=107.3), "path": _measured(), "path+background": _measured(rms=6.5, peak=31.0)}
    path = StructuralPath((), 1.0, "fit", fit={"problems": ["the fit ended at a bound: gain at its upper bound"]})
    ctx = {"path": path, "path_fitted_here": True, "span_text": {"record": "w", "segment": "s"}}
    tol = {k: QUANTITIES[k].tolerance for k in ("bpfo", "rms", "peak")}
    rows = {r["quantity"]: r for r in evaluate_rows(tol, exp, sim, context=ctx)}
    assert rows["bpfo"]["pass"]                                   # the model's lines do not go through the path
    assert not rows["rms"]["pass"] and "not trusted" in rows["rms"]["note"]
    assert not rows["peak"]["independent"]
    assert math.isfinite(rows["peak"]["simulation"])
