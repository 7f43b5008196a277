"""Tolerances and table rows: every compared number, how close counts as agreement, and why.

Why strict rules: a validation table is evidence only if each row can fail.  So a
row with a missing or NaN value on either side fails (a quantity the model or the
recording does not show is a disagreement to report, not an agreement; only for a
fault line family, which either signal may rightly lack, do both sides lacking it agree), ratios are
compared with a tolerance (never by their ordering alone), and a failing row says
whether it is a known model limitation (with the reason given in the case) or not.

Public API
----------
Tolerance(kind, value, reason, known_limitation="", declared_by="") -- "pct" (|sim - exp| <= value % of |exp|) or
                                                       "factor" (1/value <= sim/exp <= value)
make_row(quantity, simulation, experiment, tolerance, ...) -> dict
row_status(row) -> "pass" | "known limitation" | "fail"
case_verdict(rows) -> dict                          -- a case's verdict in words and its three counts
VERDICTS                                            -- verdict -> what it means (CLI, pages, docs)
EXIT_STATUS                                         -- what `bearing-lab validate` returns, in words (--help, pages)
ROW_KEYS                                            -- the keys every row has (summary.json, netCDF)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ValidationCaseError, check_choice

__all__ = ["Tolerance", "make_row", "row_status", "case_verdict", "VERDICTS", "EXIT_STATUS", "ROW_KEYS",
           "TOLERANCE_KINDS"]

TOLERANCE_KINDS = ("pct", "factor")

#: keys of a row, in table order
ROW_KEYS = ("quantity", "label", "units", "simulation", "experiment", "reference_value", "reference_label",
            "difference", "difference_pct", "tolerance_pct", "tolerance", "rule", "pass", "status", "reason",
            "known_limitation", "declared_by", "note", "simulated_signal", "experiment_span", "independent",
            "paper_simulation")

#: the exit status of ``bearing-lab validate`` (its --help, the index page and docs/validation.md say this)
EXIT_STATUS = ("0: every case ran and no row fails unexplained (each failing row is a limitation its case "
               "declares); 1: a row fails without a declared reason (an unexplained failure) or a case could "
               "not run, and with --strict also when a declared limitation fails; 2: bad input (an unknown "
               "case, an invalid case file, a missing recording of a named case), nothing run")

#: a case's verdict -> what it means (the same words on the terminal, the pages and in summary.json)
VERDICTS = {
    "pass": "every row agrees within its tolerance",
    "known limitations": "rows fail, and each is a limitation the case's author declared, with a reason "
                         "(known_limitation in the case file); no row fails unexplained",
    "fail": "at least one row fails without a declared reason: an unexplained failure, to be treated as a "
            "regression until it is fixed or explained",
    "error": "the case could not run (the reason is given)",
    "skip": "the case needs a recording that is not available",
}


@dataclass(frozen=True)
class Tolerance:
    """A pass rule with its reason, and optionally why a failure is a known model limitation.

    ``kind`` "pct": ``|sim - exp| <= value % of |exp|``; "factor": ``1/value <= sim/exp <= value``
    (both of the same sign).  Any NaN fails.  A tolerance without a reason, a value that is not a
    positive number, or a factor not above 1 raises ``ValidationCaseError``.

    See Also
    --------
    make_row : a table row checked against it.

    Examples
    --------
    >>> tol = Tolerance("factor", 2.0, reason="the rig's load and mount are known to tens of percent")
    >>> tol.check(1.9, 1.0), tol.check(0.4, 1.0), tol.check(float("nan"), 1.0)
    (True, False, False)
    """

    kind: str
    value: float
    reason: str
    known_limitation: str = ""
    declared_by: str = ""     # who declared the limitation: the shipped case (the project) or a case file's author

    def __post_init__(self):
        check_choice(self.kind, TOLERANCE_KINDS, "tolerance kind", ValidationCaseError)
        if not (self.reason or "").strip():
            raise ValidationCaseError("every tolerance needs a reason (key 'reason')")
        try:
            v = float(self.value)
        except (TypeError, ValueError):
            raise ValidationCaseError(f"tolerance {self.kind} = {self.value!r} is not a number") from None
        if not (math.isfinite(v) and v > 0):
            raise ValidationCaseError(f"tolerance {self.kind} = {self.value!r} must be a positive finite number")
        if self.kind == "factor" and v <= 1:
            raise ValidationCaseError(f"tolerance factor = {self.value!r} must be greater than 1")
        object.__setattr__(self, "value", v)

    @property
    def pct(self) -> float:
        """The tolerance as a percentage of the experiment (factor f -> (f - 1) * 100, high side)."""
        return self.value if self.kind == "pct" else (self.value - 1.0) * 100.0

    def text(self) -> str:
        return f"±{self.value:g} %" if self.kind == "pct" else f"factor {self.value:g}"

    def check(self, sim: float, exp: float) -> bool:
        if not (math.isfinite(sim) and math.isfinite(exp)):
            return False
        if self.kind == "pct":
            return abs(sim - exp) <= self.value / 100.0 * abs(exp) * (1 + 1e-12)
        if exp == 0 or sim == 0 or (sim > 0) != (exp > 0):
            return False
        return 1.0 / self.value <= sim / exp <= self.value


def _float_or_nan(v) -> float:
    try:
        return float(v) if v is not None else float("nan")
    except (TypeError, ValueError):
        return float("nan")


def row_status(row: dict) -> str:
    """"pass", "known limitation" (a failure the case explains) or "fail"."""
    if row["pass"]:
        return "pass"
    return "known limitation" if row.get("known_limitation") else "fail"


def case_verdict(rows: list) -> dict:
    """A case's verdict from its rows: ``verdict`` (a key of :data:`VERDICTS`), the counts
    ``n_rows``, ``n_pass``, ``n_declared`` (failing as declared limitations) and ``n_unexplained``,
    the failing row labels of each kind, and ``text`` (one sentence)."""
    unexplained = [r for r in rows if not r["pass"] and not r.get("known_limitation")]
    declared = [r for r in rows if not r["pass"] and r.get("known_limitation")]
    n_pass = len(rows) - len(unexplained) - len(declared)
    verdict = "fail" if unexplained or not rows else "known limitations" if declared else "pass"
    parts = [f"{n_pass} of {len(rows)} rows pass"]
    if declared:
        parts.append(f"{len(declared)} fail{'s' if len(declared) == 1 else ''} as limitation"
                     f"{'s' if len(declared) > 1 else ''} the case declares")
    if unexplained:
        parts.append(f"{len(unexplained)} fail{'s' if len(unexplained) == 1 else ''} unexplained")
    if not rows:
        parts = ["no rows"]
    return {"verdict": verdict, "n_rows": len(rows), "n_pass": n_pass, "n_declared": len(declared),
            "n_unexplained": len(unexplained), "declared": [r.get("label") or r["quantity"] for r in declared],
            "unexplained": [r.get("label") or r["quantity"] for r in unexplained], "text": ", ".join(parts)}


def make_row(quantity: str, simulation, experiment, tolerance: Tolerance, *, label, units, note="",
             reference_value=None, reference_label="", signal="", span="", independent=True,
             paper_simulation=None, untrusted="", absence_agrees=False) -> dict:
    """One table row: simulation, experiment, difference, % difference, tolerance, pass, status.

    ``untrusted`` (a reason) makes the row fail whatever its numbers: used when a number
    depends on a structural-path fit that is degraded.  ``absence_agrees``: the quantity is a
    detection (a fault line family); when *neither* signal shows it the row passes as an agreement
    on its absence (one side showing it and the other not still fails).  A missing value (None,
    NaN) fails the row and the note says which side is missing.

    Returns
    -------
    dict
        ``quantity``, ``label``, ``units``, ``simulation``, ``experiment``, ``difference``,
        ``difference_pct``, ``tolerance``, ``pass``, ``status`` ("pass", "known limitation",
        "fail"), ``reason``, ``known_limitation``, ``note`` and the other arguments.

    See Also
    --------
    Tolerance, bearing_lab.report.rows_table, bearing_lab.report.Report.add_rows

    Examples
    --------
    >>> tol = Tolerance("pct", 1.0, reason="kinematic frequencies hold to 1-2 % under slip")
    >>> row = make_row("bpfo", 91.5, 92.19, tol, label="BPFO", units="Hz")
    >>> row["status"], round(row["difference_pct"], 2)          # (91.5 - 92.19) / 92.19
    ('pass', -0.75)
    >>> make_row("bpfo", None, 92.19, tol, label="BPFO", units="Hz")["note"]
    'missing value (simulation): counts as a failure'
    """
    s, e = _float_or_nan(simulation), _float_or_nan(experiment)
    ok = tolerance.check(s, e)
    notes = [note] if note else []
    both_absent = absence_agrees and not math.isfinite(s) and not math.isfinite(e)
    if both_absent:
        ok = True
        notes.insert(0, "neither signal shows this line family: they agree on its absence")
    elif not (math.isfinite(s) and math.isfinite(e)):
        missing = " and ".join(w for w, v in (("simulation", s), ("experiment", e)) if not math.isfinite(v))
        notes.insert(0, f"missing value ({missing}): counts as a failure")
    if untrusted:
        ok = False
        notes.insert(0, f"not trusted: {untrusted}")
    diff = s - e
    pct = 100.0 * diff / abs(e) if (math.isfinite(diff) and e != 0) else float("nan")
    row = {"quantity": quantity, "label": label, "units": units, "simulation": s, "experiment": e,
           "reference_value": _float_or_nan(reference_value), "reference_label": reference_label,
           "difference": diff, "difference_pct": pct, "tolerance_pct": tolerance.pct,
           "tolerance": tolerance.text(), "rule": tolerance.kind, "pass": bool(ok), "reason": tolerance.reason,
           "known_limitation": tolerance.known_limitation,
           "declared_by": tolerance.declared_by if tolerance.known_limitation else "", "note": "; ".join(notes),
           "simulated_signal": signal, "experiment_span": span, "independent": bool(independent),
           "paper_simulation": _float_or_nan(paper_simulation)}
    row["status"] = row_status(row)
    return row
