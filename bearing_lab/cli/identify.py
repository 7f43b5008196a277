"""``bearing-lab identify CASE.toml``: the defect's length, offset and skew identified from the case's recording.

A grid of simulated scenes around the case's declared defect is compared with the recording
through the fixed structural path and background (docs/identification.md); the result is
printed (or ``--json``) and written to ``DIR/<case>/identification.{json,nc,html}``;
``--report`` adds it to the case's validation page ``DIR/<case>/index.html``.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

from ..errors import ValidationCaseError
from ..utils._json import clean


def register(subparsers):
    p = subparsers.add_parser(
        "identify", help="identify the defect's length, offset and skew from a case's recording",
        description=("Search simulated scenes around the case's declared defect (length 0.5-2x, offset 0-B/2, "
                     "skew -60..60 deg by default) for the one whose impact signature after the fixed structural "
                     "path and background matches the recording; report an interval per parameter, or that it "
                     "is not identifiable.  The default grid is 45 scenes (lengths 0.5, 1, 2x; offsets 0, B/4, "
                     "B/2; those at offset 0 and a negative skew scored as their mirror images); the refinement "
                     "(a simplex search from the best, a roughness probe, profiles minimised over the other "
                     "parameters, a polish) adds about "
                     "70-100 more.  Before the scenes run, the CPU time they need is estimated from the contact "
                     "tables to build and the scenes to simulate.  Every scored scene is kept in "
                     "DIR/<case>/identification-journal.jsonl: a run stopped by Ctrl-C or a kill resumes there "
                     "when rerun; a stopped run writes the partial result of the scenes done to "
                     "DIR/<case>/identification-partial.{json,nc,html} and exits with status 130."))
    p.add_argument("case", metavar="CASE", help="case TOML file (docs/case-format.md) with one [[defect]]")
    p.add_argument("-o", "--output", default="reports", metavar="DIR", help="output directory (default: reports)")
    p.add_argument("--length-mm", type=float, nargs="+", default=None, help="along-track lengths to search, mm")
    p.add_argument("--offset-mm", type=float, nargs="+", default=None, help="axial offsets H to search, mm")
    p.add_argument("--skew-deg", type=float, nargs="+", default=None, help="skews θ to search, degrees")
    p.add_argument("--depth-mm", type=float, nargs="+", default=None,
                   help="depths to search, mm (default: not searched)")
    p.add_argument("--no-refine", action="store_true",
                   help="the coarse grid alone: no simplex search, roughness probe, minimised profiles or polish")
    p.add_argument("--workers", type=int, default=1,
                   help="Dask worker processes (default 1: in this process, no Dask; measured faster on a "
                        "shared 2-core machine, see docs/identification.md)")
    p.add_argument("--cache", default=None, metavar="DIR",
                   help="keep the simulated scenes in this sweep cache (about 3.6 MB per scene of 1 s at 20 kHz; "
                        "default: not kept; contact tables are always cached)")
    p.add_argument("--amplitude-weight", type=float, default=None,
                   help="weight of the amplitude in the score (default: 1 with an independent path, else 0)")
    p.add_argument("--report", action="store_true", help="add the result to DIR/<case>/index.html (run validate first)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--mirror", default=None, metavar="DIR", help="directory holding public recordings")
    p.add_argument("--restart", action="store_true",
                   help="discard the journal of an earlier run of this case in DIR (default: resume from it)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors (the files are written)")
    p.set_defaults(func=run)


def run(args) -> int:
    from ..validation import load_case  # the command's imports load when it runs
    from ..validation.identify import IdentificationInterrupted, default_grid, identify
    from ..validation.identify_report import write_identification
    if args.workers < 1:
        raise ValidationCaseError(f"--workers {args.workers}: give 1 (in this process) or more Dask worker processes")
    case = load_case(args.case)
    grid = default_grid(case)
    for key, given in (("defect.length_mm", args.length_mm), ("defect.offset_mm", args.offset_mm),
                       ("defect.skew_deg", args.skew_deg), ("defect.depth_mm", args.depth_mm)):
        if given:
            grid[key] = list(given)
    journal = Path(args.output) / case.name / "identification-journal.jsonl"
    if args.restart and journal.is_file():
        journal.unlink()
    say = None if (args.json or args.quiet) else (lambda text: print(f"identify {case.name}: {text}", file=sys.stderr))
    try:
        with _term_stops():
            res = identify(case, grid=grid, refine=not args.no_refine,
                           scheduler="serial" if args.workers <= 1 else "local", n_workers=args.workers,
                           progress=not (args.no_progress or args.quiet), level_weight=args.amplitude_weight,
                           mirror=args.mirror, cache_dir=args.cache or False, journal=journal, notify=say)
    except IdentificationInterrupted as stop:
        return _stopped(stop.result, args, journal)
    paths = write_identification(res, args.output, report=args.report)
    for ext in ("json", "nc", "html"):      # a partial result of an earlier, stopped run is superseded
        (Path(args.output) / case.name / f"identification-partial.{ext}").unlink(missing_ok=True)
    if args.json:
        print(json.dumps(clean(res.to_dict()), allow_nan=False))
        return 0
    if args.quiet:
        return 0
    if res.explains_recording is False:
        print("NOT EXPLAINED: " + next(n for n in res.notes if "does not explain" in n))
    for p in res.parameters.values():
        print(p["statement"])
    for note in res.notes:
        print(f"note: {note}")
    print(f"{res.n_scenes} scenes, {res.cpu_time_s:.1f} s CPU here, {res.wall_time_s:.1f} s wall; "
          f"wrote {', '.join(str(p) for p in paths.values())}")
    return 0


class _term_stops:
    """SIGTERM (a kill) stops the run as Ctrl-C does, so the partial result is written (restored after)."""

    def __enter__(self):
        import signal  # the command's imports load when it runs
        self.old = None
        try:
            self.old = signal.signal(signal.SIGTERM, self._raise)
        except ValueError:          # not the main thread: leave the signal alone
            pass
        return self

    @staticmethod
    def _raise(signum, frame):
        raise KeyboardInterrupt

    def __exit__(self, *exc):
        import signal  # the command's imports load when it runs
        if self.old is not None:
            signal.signal(signal.SIGTERM, self.old)
        return False


def _stopped(res, args, journal) -> int:
    """A stopped run: the partial result of the scenes done (if any) written and printed; exit status 130."""
    from ..validation.identify_report import write_identification  # the command's imports load when it runs
    where = f"the scored scenes are kept in {journal}; rerun the same command to resume"
    if res is None:
        print(f"bearing-lab identify: interrupted before any scene finished; {where}", file=sys.stderr)
        return 130
    paths = write_identification(res, args.output, stem="identification-partial")
    if args.json:
        print(json.dumps(clean(res.to_dict()), allow_nan=False))
    elif not args.quiet:
        print(f"PARTIAL result (interrupted after {res.n_scenes} scenes):")
        for p in res.parameters.values():
            print(p["statement"])
        for note in res.notes:
            print(f"note: {note}")
        print(f"wrote {', '.join(str(p) for p in paths.values())}")
    print(f"bearing-lab identify: interrupted; {where}", file=sys.stderr)
    return 130
