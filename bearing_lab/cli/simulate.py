"""`bearing-lab scenes` and `bearing-lab simulate`."""
from __future__ import annotations

import sys
import math

from . import check_output_path, imports_loaded
from ..errors import BearingLabError, SceneError
from ..utils._json import dumps


def _scenes(args) -> int:
    from ..sim import list_scenes  # the command's imports load when it runs
    scenes = list_scenes()
    if args.json:
        print(dumps(scenes, indent=1))
        return 0
    if args.quiet:
        return 0
    width = max(len(n) for n in scenes)
    for name, desc in scenes.items():
        print(f"{name:<{width}}  {desc}")
    return 0


def _simulate(args) -> int:
    from ..sim import simulate  # the command's imports load when it runs
    from ..sim.noise import add_measurement_noise
    from ..sim.scene import merge_overrides, parse_set
    from ..io.export import to_netcdf
    imports_loaded()
    overrides = merge_overrides(parse_set(args.set), **{"output.duration_s": args.duration,
                                                        "output.sample_rate_hz": args.fs})
    out = check_output_path(args.output, force=args.force)
    if args.noise_g is not None and not (math.isfinite(args.noise_g) and args.noise_g >= 0):
        raise SceneError(f"--noise-g {args.noise_g:g}: give the noise RMS as a number of g, 0 or more")
    ds = simulate(args.scene, progress=not (args.quiet or args.json), **overrides)
    if args.noise_g:
        ds = add_measurement_noise(ds, args.noise_g, seed=args.seed, color=args.noise_color)
    to_netcdf(ds, out, error=BearingLabError)
    info = {"file": str(out), "samples": int(ds.sizes["time"]), "sampling_rate_hz": float(ds.attrs["sampling_rate_hz"]),
            "fidelity": ds.attrs["fidelity"], "defect_contact_models": ds.attrs["defect_contact_models"],
            "wall_time_s": float(ds.attrs["wall_time_s"]), "table_time_s": float(ds.attrs["table_time_s"]),
            "compile_time_s": float(ds.attrs["compile_time_s"]),
            "noise": ({"rms_g": args.noise_g, "color": args.noise_color, "seed": args.seed,
                       "channel": ds.attrs["measurement_noise_channel"]} if args.noise_g else None)}
    if args.json:
        print(dumps(info, indent=1))
    elif not args.quiet:
        noise = (f", {args.noise_color} noise {args.noise_g:g} g rms on {ds.attrs['measurement_noise_channel']} "
                 f"(seed {args.seed})" if args.noise_g else "")
        print(f"wrote {out}: {info['samples']} samples at {info['sampling_rate_hz']:g} Hz, "
              f"fidelity {info['fidelity']}, defect contact {info['defect_contact_models']}{noise}, "
              f"{info['wall_time_s']:.2f} s compute (+{info['table_time_s']:.2f} s defect tables, "
              f"+{info['compile_time_s']:.2f} s compile/cache load)", file=sys.stderr)
    return 0


def register(sub) -> None:
    p = sub.add_parser("scenes", help="list the built-in scenes")
    p.add_argument("--json", action="store_true", help="print {name: description} as JSON")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing (exit status 0: the scenes load)")
    p.set_defaults(func=_scenes)
    p = sub.add_parser("simulate", help="simulate a scene and write the Dataset (netCDF)")
    p.add_argument("scene", help="a TOML scene file or a built-in scene name (see `bearing-lab scenes`)")
    p.add_argument("--duration", type=float, default=None, metavar="S", help="recorded duration, s")
    p.add_argument("--fs", type=float, default=None, metavar="HZ", help="output sample rate, Hz")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene key, e.g. load.radial_n=480 or defect.offset_mm=0.5")
    p.add_argument("--noise-g", type=float, default=None, metavar="G",
                   help="measurement noise added to the accelerometer channel (outer_ring_acc_y), RMS in g; "
                        "recorded in the attributes (measurement_noise_*)")
    p.add_argument("--noise-color", default="white", choices=["white", "pink", "brown"],
                   help="noise spectrum: white (flat), pink (1/f), brown (1/f^2); default white")
    p.add_argument("--seed", type=int, default=0, help="seed of the noise (default 0): same seed, same samples")
    p.add_argument("-o", "--output", required=True, metavar="OUT.nc")
    p.add_argument("--force", action="store_true", help="overwrite an existing OUT.nc")
    p.add_argument("--json", action="store_true", help="print what was written as JSON (no progress bar)")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing (no progress bar, no summary)")
    p.set_defaults(func=_simulate)
