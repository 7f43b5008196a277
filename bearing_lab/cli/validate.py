"""``bearing-lab validate [CASE ...] [-o DIR] [--strict]``: run validation cases, write reports.

Default (no CASE): the embedded default set - the ``paper`` case, plus the CWRU cases whose
recordings are available (``BEARING_LAB_MIRROR``); missing recordings are listed as skipped in
``DIR/index.html``, never an error.  A CASE named on the command line must be runnable: an
unknown case, an invalid case file or scene key, or a missing recording is bad input (one line
on stderr, exit status 2).  ``--strict`` turns failed tolerances into exit status 1.
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
                     "comparison.nc and summary.json."))
    p.add_argument("cases", nargs="*", metavar="CASE",
                   help="shipped case name (see --list) or a case TOML file")
    p.add_argument("-o", "--output", default="reports", metavar="DIR", help="report directory (default: reports)")
    p.add_argument("--strict", action="store_true", help="exit status 1 when any tolerance fails")
    p.add_argument("--mirror", default=None, metavar="DIR",
                   help="directory holding the public recordings (default: BEARING_LAB_MIRROR)")
    p.add_argument("--list", action="store_true", help="list the shipped cases and exit")
    p.add_argument("--no-progress", action="store_true", help="no progress bars")
    p.set_defaults(func=run)


def run(args) -> int:
    import matplotlib
    matplotlib.use("Agg")
    from ..validation import list_cases, load_case, run_validation
    if args.list:
        for name in list_cases():
            c = load_case(name)
            print(f"{name:12s} {'default' if c.default else '       '}  {c.title}")
        return 0
    t0 = time.perf_counter()
    progress = not args.no_progress and os.environ.get("BEARING_LAB_PROGRESS", "1") != "0"
    outcomes, status = run_validation(args.cases or None, args.output, strict=args.strict,
                                      progress=progress, mirror=args.mirror)
    for o in outcomes:
        line = f"{o.name:10s} {o.status.upper():5s} {o.n_pass}/{len(o.rows)} rows pass  ({o.wall_time_s:.1f} s)"
        if o.status == "error":
            line += f"  {o.reason}"
        print(line)
    print(f"reports: {os.path.join(args.output, 'index.html')}  ({time.perf_counter() - t0:.1f} s)")
    if status == 2:  # bad input: one line per case that could not run (the others did)
        for o in outcomes:
            if o.extra.get("bad_input"):
                print(f"bearing-lab validate: error: {o.reason}", file=sys.stderr)
        return 2
    if status:
        failed = [o.name for o in outcomes if o.status in ("fail", "error")]
        print(f"bearing-lab validate: --strict: failing cases: {', '.join(failed)}", file=sys.stderr)
    return status
