"""``bearing-lab validate [CASE ...] [-o DIR] [--strict] [--json] [-q]``: run validation cases, write reports.

Default (no CASE): the embedded default set - the ``paper`` case, plus the CWRU cases whose
recordings are available (``BEARING_LAB_MIRROR``); missing recordings are listed as skipped in
``DIR/index.html``, never an error.  A CASE named on the command line must be runnable: an
unknown case, an invalid case file, key or scene, or a missing recording is bad input (one line
on stderr, exit status 2) and nothing runs.  A case that fails while running is listed as an
error in the index; the others still run.  The verdicts and the exit status:
:data:`bearing_lab.validation.rows.VERDICTS`, :data:`bearing_lab.validation.rows.EXIT_STATUS`.
The case format: ``docs/case-format.md``.
"""
from __future__ import annotations

import argparse
import os
import sys
import time

from ..utils._json import dumps


def _epilog() -> str:
    from ..validation.rows import VERDICTS  # the command's imports load when it runs
    from ..validation.rows import EXIT_STATUS
    lines = ["verdict of a case:"]
    lines += [f"  {k.upper():18s} {v}" for k, v in VERDICTS.items()]
    lines += ["", "A declared limitation is a row the case's author gives a known_limitation (a reason the model "
              "cannot reproduce it): the shipped cases' by bearing_lab, a case file's by its author.",
              "", "exit status: " + EXIT_STATUS + "."]
    return "\n".join(lines)


def register(subparsers):
    p = subparsers.add_parser(
        "validate", help="run validation cases and write HTML reports",
        formatter_class=argparse.RawDescriptionHelpFormatter, epilog=_epilog(),
        description=("Run validation cases (default: the embedded default set: paper, plus the CWRU cases whose "
                     "recordings are in BEARING_LAB_MIRROR) and write DIR/index.html, DIR/<case>/index.html, "
                     "comparison.nc and summary.json.  A case is a shipped name (--list) or a case TOML file "
                     "(docs/case-format.md; `bearing-lab case new RECORDING` writes a starting one)."))
    p.add_argument("cases", nargs="*", metavar="CASE",
                   help="shipped case name (see --list) or a case TOML file")
    p.add_argument("-o", "--output", default="reports", metavar="DIR", help="report directory (default: reports)")
    p.add_argument("--strict", action="store_true",
                   help="exit status 1 also when a row fails as a declared limitation")
    p.add_argument("--mirror", default=None, metavar="DIR",
                   help="directory holding the public recordings (default: BEARING_LAB_MIRROR)")
    p.add_argument("--list", action="store_true", help="list the shipped cases and exit")
    p.add_argument("--json", action="store_true",
                   help="print the verdicts as JSON (per case: verdict, counts, the failing rows by kind)")
    p.add_argument("-q", "--quiet", action="store_true",
                   help="print nothing but errors (and --json if asked); the exit status tells the verdict")
    p.add_argument("--no-progress", action="store_true", help="no progress bars (the verdict lines stay)")
    p.set_defaults(func=run)


def _line(o) -> str:
    v = o.verdict
    word = v["verdict"].upper()
    if o.status == "error":
        return f"{o.name:10s} {'ERROR':17s}  {o.reason}"
    return f"{o.name:10s} {word:17s}  {o.n_pass}/{len(o.rows)} rows pass" + (
        f", {v['n_declared']} fail as declared limitation(s)" if v["n_declared"] else "") + (
        f", {v['n_unexplained']} fail unexplained" if v["n_unexplained"] else "") + f"  ({o.wall_time_s:.1f} s)"


def _json(outcomes, out_dir, status) -> dict:
    cases = []
    for o in outcomes:
        v = o.verdict
        failing = [r for r in o.rows if not r["pass"]]
        cases.append({"case": o.name, "title": o.title, "verdict": v["verdict"], "text": v["text"],
                      "n_rows": v["n_rows"], "n_pass": v["n_pass"], "n_declared_limitations": v["n_declared"],
                      "n_unexplained_failures": v["n_unexplained"],
                      "unexplained_failures": [r["quantity"] for r in failing if not r.get("known_limitation")],
                      "declared_limitations": [{"quantity": r["quantity"], "declared_by": r.get("declared_by", ""),
                                                "reason": r["known_limitation"]}
                                               for r in failing if r.get("known_limitation")],
                      "wall_time_s": o.wall_time_s, "error": o.reason if o.status == "error" else None,
                      "report": str(o.out_dir / "index.html") if o.out_dir is not None else None})
    return {"cases": cases, "index": os.path.join(out_dir, "index.html"), "exit_status": status}


def run(args) -> int:
    from ..validation import load_case, shipped_cases  # the command's imports load when it runs
    if args.list:
        if args.json:
            print(dumps([{"case": n, "default": load_case(n).default, "title": load_case(n).title}
                         for n in shipped_cases()], indent=1))
            return 0
        for name in shipped_cases():
            c = load_case(name)
            print(f"{name:12s} {'default' if c.default else '       '}  {c.title}")
        return 0
    from ..validation import run_validation  # a run loads the simulator, the analysis and the pages; --list does not
    t0 = time.perf_counter()
    quiet = args.quiet or args.json
    progress = not (args.no_progress or quiet) and os.environ.get("BEARING_LAB_PROGRESS", "1") != "0"
    outcomes, status = run_validation(args.cases or None, args.output, strict=args.strict,
                                      progress=progress, mirror=args.mirror)
    if args.json:
        print(dumps(_json(outcomes, args.output, status), indent=1))
    elif not args.quiet:
        for o in outcomes:
            print(_line(o))
        print(f"reports: {os.path.join(args.output, 'index.html')}  ({time.perf_counter() - t0:.1f} s)")
    if status and not args.quiet:
        bad = [o.name for o in outcomes if o.verdict["verdict"] in ("fail", "error")]
        why = ("unexplained failures or errors in: " + ", ".join(bad)) if bad else \
            "--strict: declared limitations fail in: " + ", ".join(
                o.name for o in outcomes if o.verdict["verdict"] == "known limitations")
        print(f"bearing-lab validate: exit status 1: {why}", file=sys.stderr)
    return status
