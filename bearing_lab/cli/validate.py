"""``bearing-lab validate [CASE ...] [-o DIR] [--strict]``: run validation cases, write reports.

Default (no CASE): the embedded default set - the ``paper`` case, plus the CWRU cases whose
recordings are available (``BEARING_LAB_MIRROR``); missing recordings are listed as skipped in
``DIR/index.html``, never an error.  A CASE named on the command line must be runnable: an
unknown case, an invalid case file, key or scene, or a missing recording is bad input (one line
on stderr, exit status 2) and nothing runs.  A case that fails while running is listed as an
error in the index; the others still run.  ``--strict`` turns failing rows into exit status 1.
The case format: ``docs/case-format.md``.
"""
from __future__ import annotations

import os
import sys
import time


def register(subparsers):
    p = subparsers.add_parser(
        "validate", help="run validation cases and write HTML reports",
        description=("Run validation cases (default: the embedded default set: paper, plus the CWRU cases whose "
                     "recordings are in BEARING_LAB_MIRROR) and write DIR/index.html, DIR/<case>/index.html, "
                     "comparison.nc and summary.json.  A case is a shipped name (--list) or a case TOML file "
                     "(docs/case-format.md; `bearing-lab case new RECORDING` writes a starting one)."))
    p.add_argument("cases", nargs="*", metavar="CASE",
                   help="shipped case name (see --list) or a case TOML file")
    p.add_argument("-o", "--output", default="reports", metavar="DIR", help="report directory (default: reports)")
    p.add_argument("--strict", action="store_true", help="exit status 1 when any row fails or a case errors")
    p.add_argument("--mirror", default=None, metavar="DIR",
                   help="directory holding the public recordings (default: BEARING_LAB_MIRROR)")
    p.add_argument("--list", action="store_true", help="list the shipped cases and exit")
    p.add_argument("--no-progress", action="store_true", help="no progress bars")
    p.set_defaults(func=run)


def run(args) -> int:
    from ..validation import load_case, run_validation, shipped_cases
    if args.list:
        for name in shipped_cases():
            c = load_case(name)
            print(f"{name:12s} {'default' if c.default else '       '}  {c.title}")
        return 0
    t0 = time.perf_counter()
    progress = not args.no_progress and os.environ.get("BEARING_LAB_PROGRESS", "1") != "0"
    outcomes, status = run_validation(args.cases or None, args.output, strict=args.strict,
                                      progress=progress, mirror=args.mirror)
    for o in outcomes:
        known = sum(1 for r in o.rows if not r["pass"] and r.get("known_limitation"))
        line = (f"{o.name:10s} {o.status.upper():5s} {o.n_pass}/{len(o.rows)} rows pass"
                + (f", {known} known limitation(s)" if known else "") + f"  ({o.wall_time_s:.1f} s)")
        if o.status == "error":
            line += f"  {o.reason}"
        print(line)
    print(f"reports: {os.path.join(args.output, 'index.html')}  ({time.perf_counter() - t0:.1f} s)")
    if status:
        failed = [o.name for o in outcomes if o.status in ("fail", "error")]
        print(f"bearing-lab validate: --strict: failing cases: {', '.join(failed)}", file=sys.stderr)
    return status
