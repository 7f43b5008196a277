"""``bearing-lab identify CASE.toml``: the defect's length, offset and skew identified from the case's recording.

A grid of simulated scenes around the case's declared defect is compared with the recording
through the fixed structural path and background (docs/identification.md); the result is
printed (or ``--json``) and written to ``DIR/<case>/identification.{json,nc,html}``;
``--report`` adds it to the case's validation page ``DIR/<case>/index.html``.
"""
from __future__ import annotations

import json
import sys


#: scenes the refinement typically adds (210 and 244 on the stand-ins), and CPU s per scene of a 1 s record (table
#: cached, skewed table built: the README walkthrough, 37 s and 742 s for 384 scenes);
#: measured in docs/identification.md ("The search")
REFINE_TYPICAL = (100, 250)
SCENE_CPU_S = (0.1, 1.9)


def register(subparsers):
    p = subparsers.add_parser(
        "identify", help="identify the defect's length, offset and skew from a case's recording",
        description=("Search simulated scenes around the case's declared defect (length 0.5-2x, offset 0-B/2, "
                     "skew -60..60 deg by default) for the one whose impact signature after the fixed structural "
                     "path and background matches the recording; report an interval per parameter, or that it "
                     "is not identifiable.  The default grid is 140 scenes; the refinement (a simplex search from the best, "
                     "a roughness probe, profiles minimised over the other parameters, a polish) adds about "
                     f"{REFINE_TYPICAL[0]}-{REFINE_TYPICAL[1]} more.  A scene of a 1 s record at 20 kHz costs about "
                     f"{SCENE_CPU_S[0]:g} s of CPU with its contact table cached, {SCENE_CPU_S[1]:g} s when a skewed "
                     "outline's table has to be built."))
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
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors (the files are written)")
    p.set_defaults(func=run)


def run(args) -> int:
    from ..validation import load_case
    from ..validation.identify import default_grid, identify
    from ..validation.identify_report import write_identification
    from ..errors import ValidationCaseError
    if args.workers < 1:
        raise ValidationCaseError(f"--workers {args.workers}: give 1 (in this process) or more Dask worker processes")
    case = load_case(args.case)
    grid = default_grid(case)
    for key, given in (("defect.length_mm", args.length_mm), ("defect.offset_mm", args.offset_mm),
                       ("defect.skew_deg", args.skew_deg), ("defect.depth_mm", args.depth_mm)):
        if given:
            grid[key] = list(given)
    n = 1
    for v in grid.values():
        n *= len(v)
    if not (args.json or args.quiet):
        lo, hi = (n, n) if args.no_refine else (n + REFINE_TYPICAL[0], n + REFINE_TYPICAL[1])
        sec = float(case.recording.duration_s)
        print(f"identify {case.name}: {n} scenes on the coarse grid"
              + ("" if args.no_refine else f" + about {REFINE_TYPICAL[0]}-{REFINE_TYPICAL[1]} in the refinement")
              + f" of {sec:g} s each: about {SCENE_CPU_S[0] * lo * sec:.0f}-{SCENE_CPU_S[1] * hi * sec:.0f} s of CPU "
                "(cached / new contact tables; measured at 20 kHz)", file=sys.stderr)
    res = identify(case, grid=grid, refine=not args.no_refine, scheduler="serial" if args.workers <= 1 else "local",
                   n_workers=args.workers, progress=not (args.no_progress or args.quiet), level_weight=args.amplitude_weight,
                   mirror=args.mirror, cache_dir=args.cache or False)
    paths = write_identification(res, args.output, report=args.report)
    if args.json:
        from ..utils._json import clean
        print(json.dumps(clean(res.to_dict()), allow_nan=False))
        return 0
    if args.quiet:
        return 0
    for p in res.parameters.values():
        print(p["statement"])
    for note in res.notes:
        print(f"note: {note}")
    print(f"{res.n_scenes} scenes, {res.cpu_time_s:.1f} s CPU here, {res.wall_time_s:.1f} s wall; "
          f"wrote {', '.join(str(p) for p in paths.values())}")
    return 0
