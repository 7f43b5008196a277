"""Run cases and write the index: one broken case never loses the others' reports.

Public API
----------
CaseOutcome                                  -- name, title, status (pass/fail/error/skip), rows, wall time
check_case(case, mirror=None)                -- raise ValidationCaseError if a recording the case needs is missing
default_set(mirror=None) -> (cases, skipped) -- the shipped cases marked default (skipped: recordings missing)
run_case(case, out_dir, *, progress, mirror) -> CaseOutcome
run_validation(specs, out_dir, *, strict, progress, mirror) -> (outcomes, exit status)
exit_status(outcomes, strict=False) -> 0 | 1                 -- what `bearing-lab validate` returns
                                                                (its meaning: :data:`.rows.EXIT_STATUS`)
"""
from __future__ import annotations

import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from tqdm.auto import tqdm

from .._docdict import fill_doc
from ..errors import BearingLabError, ValidationCaseError
from ..report import write_index
from .case import DEFAULT_CASE, shipped_cases
from .load import load_case
from .pages import verdict_legend, write_case
from .paper import run_paper_case
from .recording import locate, missing_reason
from .recording_run import run_recording_case
from .rows import case_verdict

__all__ = ["CaseOutcome", "check_case", "default_set", "run_case", "run_validation", "exit_status"]

def exit_status(outcomes, strict=False) -> int:
    """1 when a case errored or has an unexplained failure (with ``strict``: any failing row), else 0."""
    for o in outcomes:
        v = o.verdict
        if v["verdict"] in ("error", "fail") or (strict and v["verdict"] == "known limitations"):
            return 1
    return 0


class _Steps:
    """A tqdm bar over a case's steps (silent when progress is off)."""

    def __init__(self, desc, total, progress, position=1):
        self.bar = None
        if progress:
            self.bar = tqdm(total=total, desc=desc, leave=False, position=position, unit="step")

    def step(self, what):
        if self.bar is not None:
            self.bar.set_postfix_str(what)
            self.bar.update(1)

    def close(self):
        if self.bar is not None:
            self.bar.close()


@dataclass
class CaseOutcome:
    """What :func:`run_case` gives back: the case's status (``pass``, ``fail``, ``error``,
    ``skip``), its rows, its run time (s), its folder, and :attr:`verdict` in words.

    See Also
    --------
    run_case, run_validation
    """

    name: str
    title: str
    status: str                    # pass | fail | error | skip
    rows: list = field(default_factory=list)
    wall_time_s: float = 0.0
    out_dir: Path | None = None
    reason: str = ""
    extra: dict = field(default_factory=dict)

    @property
    def n_pass(self):
        return sum(bool(r["pass"]) for r in self.rows)

    @property
    def verdict(self) -> dict:
        """:func:`~bearing_lab.validation.rows.case_verdict` of the rows ("error"/"skip" when it did not run)."""
        v = case_verdict(self.rows)
        if self.status in ("error", "skip"):
            v.update(verdict=self.status, text=self.reason)
        return v


@fill_doc
def check_case(case, mirror=None) -> None:
    """Raise ValidationCaseError when a recording the case needs is not available.

    Parameters
    ----------
    %(case)s
    %(mirror)s

    Raises
    ------
    ValidationCaseError
        Names the recording and where it was looked for.

    See Also
    --------
    load_case, default_set

    Examples
    --------
    A paper case needs no recording; a recording case needs its file:

    >>> from bearing_lab.validation import load_case
    >>> check_case(load_case("paper"))
    >>> check_case(load_case("cwru-130"), mirror="no-such-folder")
    Traceback (most recent call last):
    ...
    bearing_lab.errors.ValidationCaseError: validation case 'cwru-130': recording 'cwru/...' not found ...
    """
    for spec in case.recording_labels:
        if locate(spec, mirror) is None:
            raise ValidationCaseError(f"validation case {case.name!r}: {missing_reason(spec, mirror)}")


@fill_doc
def default_set(mirror=None):
    """The embedded default set: every shipped case marked ``default = true`` whose recordings are
    available (the paper case first).

    Parameters
    ----------
    %(mirror)s

    Returns
    -------
    cases : list of ValidationCase
    skipped : list of (name, title, reason)

    See Also
    --------
    run_validation : runs this set when it is given no case.

    Examples
    --------
    Without the recordings only the paper case is left:

    >>> cases, skipped = default_set(mirror="no-such-folder")
    >>> [c.name for c in cases], sorted(s[0] for s in skipped)[:2]
    (['paper'], ['cwru-105', 'cwru-130'])
    """
    cases, skipped = [], []
    for name in shipped_cases():
        c = load_case(name)
        if not c.default and name != DEFAULT_CASE:
            continue
        try:
            check_case(c, mirror)
        except ValidationCaseError as exc:
            skipped.append((c.name, c.title, str(exc)))
            continue
        cases.append(c)
    cases.sort(key=lambda c: (c.name != DEFAULT_CASE, c.name))
    return cases, skipped


@fill_doc
def run_case(case, out_dir, *, progress=True, mirror=None, position=1) -> CaseOutcome:
    """Run one case and write ``out_dir/<case>/{index.html, comparison.nc, summary.json}``.

    Parameters
    ----------
    %(case)s
    %(out_dir)s
    %(progress)s
    %(mirror)s
    position : int
        Line of the case's progress bar (under the bar of :func:`run_validation`).

    Returns
    -------
    CaseOutcome

    See Also
    --------
    run_validation : several cases and the index page.
    load_case, check_case

    Examples
    --------
    A run simulates the compared record (1 s by default) and analyses both signals, tens of seconds
    of CPU, so this example is not run in the tests:

    >>> from bearing_lab.validation import load_case
    >>> outcome = run_case(load_case("paper"), "reports", progress=False)   # doctest: +SKIP
    >>> outcome.verdict["text"]                                             # doctest: +SKIP
    '... rows pass, ...'
    """
    t0 = time.perf_counter()
    out = Path(out_dir) / case.name
    out.mkdir(parents=True, exist_ok=True)
    steps = _Steps(case.name, 3 if case.kind == "paper" else 4, progress, position=position)
    try:
        if case.kind == "paper":
            result = run_paper_case(case, out, steps=steps)
        else:
            result = run_recording_case(case, steps=steps, mirror=mirror)
    finally:
        steps.close()
    wall = time.perf_counter() - t0
    status = write_case(case, result, out, wall=wall)
    return CaseOutcome(case.name, case.title, status, result.rows, wall, out, extra=result.extra)


def _load_named(specs, mirror):
    cases = [load_case(s) for s in specs]
    for c in cases:
        check_case(c, mirror)
    return cases


def _index_entry(oc) -> dict:
    failing = [r for r in oc.rows if not r["pass"]]
    v = oc.verdict
    return {"case": oc.name, "title": oc.title, "status": oc.status, "n_pass": oc.n_pass, "n_rows": len(oc.rows),
            "verdict": v["verdict"], "verdict_text": v["text"],
            "declared_by": sorted({r.get("declared_by", "") for r in failing if r.get("known_limitation")} - {""}),
            "wall_time_s": oc.wall_time_s, "failing": [r["label"] for r in failing if not r.get("known_limitation")],
            "known": [r["label"] for r in failing if r.get("known_limitation")],
            "link": f"{oc.name}/index.html" if oc.status in ("pass", "fail") else None, "reason": oc.reason}


def _outcome(case, out_dir, progress, mirror):
    """The case run, or its failure to run as an \"error\" outcome (the other cases go on)."""
    try:
        return run_case(case, out_dir, progress=progress, mirror=mirror)
    except Exception as exc:  # one broken case must not lose the others' reports: listed as "error"
        msg = f"{exc}" if isinstance(exc, BearingLabError) else f"{type(exc).__name__}: {exc}"
        msg = msg.splitlines()[0] if msg else type(exc).__name__
        print(f"bearing-lab validate: case {case.name!r} failed to run: {msg}", file=sys.stderr)
        return CaseOutcome(case.name, case.title, "error", reason=msg)


@fill_doc
def run_validation(specs=None, out_dir="reports", *, strict=False, progress=True, mirror=None):
    """Run cases (default: the embedded default set) and write ``out_dir/index.html``.

    Bad input (an unknown case, an invalid file, a missing recording of a named case) raises
    ValidationCaseError before anything runs.  A case that fails while running is listed as an
    error in the index and the others still run.

    Parameters
    ----------
    specs : list of str or path, optional
        Shipped case names or case files (default: :func:`default_set`).
    %(out_dir)s
    strict : bool
        Exit status 1 also when a limitation the case declares fails.
    %(progress)s
    %(mirror)s

    Returns
    -------
    outcomes : list of CaseOutcome
    status : int
        :func:`exit_status`: 1 when a row fails unexplained or a case errors, else 0.

    See Also
    --------
    run_case, default_set, bearing_lab.report.write_index

    Examples
    --------
    ``bearing-lab validate``; a run takes minutes (each case simulates and analyses its record),
    so this example is not run in the tests:

    >>> outcomes, status = run_validation(["paper"], "reports", progress=False)   # doctest: +SKIP
    """
    out_dir = Path(out_dir)
    notes, skipped = [], []
    if specs:
        cases = _load_named(specs, mirror)
    else:
        cases, skipped = default_set(mirror)
        if skipped:
            m = mirror or os.environ.get("BEARING_LAB_MIRROR")
            notes.append("Recording cases skipped: " + ", ".join(s[0] for s in skipped) + ". "
                         + (f"They need the public recordings in the mirror {m}." if m else
                            "BEARING_LAB_MIRROR is not set: set it to a directory holding the public recordings "
                            "to add the CWRU cases."))
    out_dir.mkdir(parents=True, exist_ok=True)
    outcomes = []
    bar = None
    if progress:
        bar = tqdm(total=len(cases), desc="validate", unit="case", position=0)
    for c in cases:
        if bar is not None:
            bar.set_postfix_str(c.name)
        outcomes.append(_outcome(c, out_dir, progress, mirror))
        if bar is not None:
            bar.update(1)
    if bar is not None:
        bar.close()
    entries = [_index_entry(o) for o in outcomes]
    entries += [{"case": n, "title": t, "status": "skip", "reason": r, "link": None} for n, t, r in skipped]
    write_index(out_dir / "index.html", entries, notes=notes, opening=verdict_legend(entries))
    return outcomes, exit_status(outcomes, strict)
