"""`bearing-lab scenes` and `bearing-lab simulate`."""
from __future__ import annotations

import sys



def _scenes(args) -> int:
    from ..sim import list_scenes
    scenes = list_scenes()
    width = max(len(n) for n in scenes)
    for name, desc in scenes.items():
        print(f"{name:<{width}}  {desc}")
    return 0


def _simulate(args) -> int:
    from ..sim import simulate
    from ..sim.scene import merge_overrides, parse_set
    overrides = merge_overrides(parse_set(args.set), **{"output.duration_s": args.duration,
                                                        "output.sample_rate_hz": args.fs})
    from ..io_netcdf import check_output_path
    out = check_output_path(args.output)
    ds = simulate(args.scene, progress=not args.quiet, **overrides)
    from ..io_netcdf import write_netcdf
    write_netcdf(ds, out)
    print(f"wrote {out}: {ds.sizes['time']} samples at {ds.attrs['sampling_rate_hz']:g} Hz, "
          f"fidelity {ds.attrs['fidelity']}, defect contact {ds.attrs['defect_contact_models']}, "
          f"{ds.attrs['wall_time_s']:.2f} s compute (+{ds.attrs['table_time_s']:.2f} s defect tables, "
          f"+{ds.attrs['compile_time_s']:.2f} s compile/cache load)",
          file=sys.stderr)
    return 0


def register(sub) -> None:
    p = sub.add_parser("scenes", help="list the built-in scenes")
    p.set_defaults(func=_scenes)
    p = sub.add_parser("simulate", help="simulate a scene and write the Dataset (netCDF)")
    p.add_argument("scene", help="a TOML scene file or a built-in scene name (see `bearing-lab scenes`)")
    p.add_argument("--duration", type=float, default=None, metavar="S", help="recorded duration, s")
    p.add_argument("--fs", type=float, default=None, metavar="HZ", help="output sample rate, Hz")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene key, e.g. load.radial_n=480 or defect.offset_mm=0.5")
    p.add_argument("-o", "--output", required=True, metavar="OUT.nc")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_simulate)
