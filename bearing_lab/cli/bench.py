"""`bearing-lab bench`: speed against error (reports/performance/)."""
from __future__ import annotations

from ..errors import check_choice
from ..utils._json import dumps


def json_summary(ds, output) -> dict:
    """What ``bench --json`` prints: every run and, per scene, the fastest setting within tolerance."""
    from ..studies.bench import fastest_within_tolerance, rows_of  # the command's imports load when it runs
    rows = rows_of(ds)
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    return {"output": str(output),
            "units": {"cost": "CPU s per simulated s", "err_peak": "relative", "err_rms": "relative",
                      "err_period": "relative", "err_duration": "relative"},
            "tolerance": {"peak": ds.attrs["tolerance_peak"], "period": ds.attrs["tolerance_period"]},
            "fastest_within_tolerance": {sc: fastest_within_tolerance(rows, sc) for sc in scenes},
            "rows": rows}


def _bench(args) -> int:
    from ..studies.bench import SCENES, run_bench, summary_table  # the command's imports load when it runs
    names = [s[0] for s in SCENES]
    if args.scene:
        for s in args.scene:
            check_choice(s, names, "--scene")
    ds = run_bench(args.output, duration=args.duration, scenes=args.scene,
                   progress=not (args.quiet or args.json),
                   scipy=not args.no_scipy,
                   scipy_duration=args.scipy_duration, rates=not args.no_rates,
                   rate_duration=args.rate_duration)
    if args.json:
        print(dumps(json_summary(ds, args.output), indent=1))
        return 0
    if args.quiet:
        return 0
    print(summary_table(ds))
    if ds.attrs.get("rate_table_md"):
        print("\nAuto-rule study by output rate (auto_rate_study.csv):\n" + ds.attrs["rate_table_md"])
    if ds.attrs.get("equal_accuracy_md"):
        print("\nSpeed at equal accuracy (CPU s per simulated s):\n" + ds.attrs["equal_accuracy_md"])
    print(f"\nwrote {args.output}/index.html, performance.nc, auto_rules.toml, auto_rate_study.csv and "
          "work-precision PNGs")
    return 0


def register(sub) -> None:
    p = sub.add_parser("bench", help="speed against error for every solver setting, fidelity and contact model")
    p.add_argument("-o", "--output", default="reports/performance", metavar="DIR")
    p.add_argument("--duration", type=float, default=0.3, metavar="S", help="simulated seconds per run")
    p.add_argument("--scene", action="append", metavar="NAME", help="only these bench scenes")
    p.add_argument("--scipy-duration", type=float, default=0.1, metavar="S",
                   help="simulated seconds of the equal-accuracy comparison with scipy")
    p.add_argument("--no-scipy", action="store_true", help="skip the equal-accuracy comparison with scipy")
    p.add_argument("--rate-duration", type=float, default=1.0, metavar="S",
                   help="simulated seconds per run of the auto-rule study at 20, 100 and 200 kHz output")
    p.add_argument("--no-rates", action="store_true", help="skip the auto-rule study by output rate")
    p.add_argument("--json", action="store_true",
                   help="print every run (scene, setting, CPU s per simulated s, errors) and each scene's "
                        "fastest setting within tolerance as JSON")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors (the files are written)")
    p.set_defaults(func=_bench)
