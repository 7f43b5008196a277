"""`bearing-lab study paper`: the paper's four parametric studies."""
from __future__ import annotations

import sys

from ..errors import BearingLabError, check_choice
from ..units import G
from ..utils._json import dumps


def _study(args) -> int:
    if args.which != "paper":
        raise BearingLabError(f"study {args.which!r}: the only study set is 'paper'")
    from ..studies.paper import STUDIES, run_paper_studies  # the command's imports load when it runs
    names = args.only or list(STUDIES)
    for n in names:
        check_choice(n, STUDIES, "--only")
    table = run_paper_studies(args.output, progress=not (args.quiet or args.json), studies=names)
    if args.json:
        print(dumps({"output": args.output, "rows": table.to_dataframe().reset_index().to_dict("records"),
                     "total_wall_time_s": table.attrs["total_wall_time_s"]}, indent=1))
        return 0
    if args.quiet:
        return 0
    for r in table.to_dataframe().itertuples():
        print(f"{r.study:7s} {r.label:12s} peak disp {r.peak_displacement*1e6:7.4f} µm  "
              f"peak acc {r.peak_acceleration/G:7.2f} g  p-p {r.acceleration_peak_to_peak/G:7.2f} g  "
              f"duration {r.excitation_duration*1e3:6.3f} ms (L/v {r.crossing_time*1e3:6.3f} ms)")
    print(f"wrote {args.output}/index.html, studies.nc and PNG figures "
          f"({table.attrs['total_wall_time_s']:.1f} s)", file=sys.stderr)
    return 0


def register(sub) -> None:
    p = sub.add_parser("study", help="run the paper's parametric studies (size, offset, skew, speed) and the "
                                     "slot's damping sensitivity")
    p.add_argument("which", choices=["paper"], help="the study set")
    p.add_argument("-o", "--output", default="reports/studies", metavar="DIR")
    p.add_argument("--only", action="append", metavar="STUDY", help="size, offset, skew, speed or slot")
    p.add_argument("--json", action="store_true", help="print the study table as JSON")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors (the files are written)")
    p.set_defaults(func=_study)
