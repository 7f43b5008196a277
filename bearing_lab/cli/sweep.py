"""`bearing-lab sweep`: a parameter sweep on Dask, written as one netCDF file."""
from __future__ import annotations

import sys
import warnings

from ..errors import BearingLabError, SceneError
from . import check_output_path
from ..utils._json import dumps


def parse_params(items) -> dict:
    """``["speed_rpm=900,1800", "defect.offset_mm=0,0.5"]`` -> ``{key: [values]}``."""
    from ..sim.scene import parse_value  # the command's imports load when it runs
    out = {}
    for item in items or []:
        if "=" not in item:
            raise SceneError(f"--param {item!r}: expected KEY=V1,V2,...")
        key, text = (s.strip() for s in item.split("=", 1))
        if not key:
            raise SceneError(f"--param {item!r}: no key before '='")
        if key in out:
            raise SceneError(f"--param {key}: given twice; list all its values in one --param")
        vals = [v.strip() for v in text.split(",")]
        if not text.strip() or any(v == "" for v in vals):
            raise SceneError(f"--param {key}: empty value in {text!r}; expected {key}=V1,V2,...")
        out[key] = [parse_value(v) for v in vals]
    if not out:
        raise SceneError("sweep: give at least one --param KEY=V1,V2,...")
    return out


def _sweep(args) -> int:
    from ..sweep import run_sweep  # the command's imports load when it runs
    from ..sim.scene import parse_set
    params = parse_params(args.param)
    overrides = parse_set(args.set)
    out = check_output_path(args.output, force=args.force)
    cache = False if args.no_cache else args.cache_dir
    from ..sweep import CacheWarning
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CacheWarning)  # said below, in one line
        ds = run_sweep(args.scene, params, scheduler=args.scheduler, n_workers=args.workers,
                       cache_dir=cache, progress=not (args.quiet or args.json), duration=args.duration, fs=args.fs,
                       **overrides)
    from ..io.export import to_netcdf
    to_netcdf(ds, out, error=BearingLabError)
    dims = " x ".join(f"{d}={ds.sizes[d]}" for d in ds.attrs["sweep_dims"].split())
    if args.json:
        print(dumps({"file": str(out), "dims": {d: ds.sizes[d] for d in ds.attrs["sweep_dims"].split()},
                     **{k: ds.attrs[k] for k in ("sweep_n_scenes", "sweep_computed", "sweep_cache_hits",
                                                 "sweep_wall_time_s", "sweep_scheduler")}}, indent=1))
    elif not args.quiet:
        print(f"wrote {out}: {ds.attrs['sweep_n_scenes']} scenes ({dims}), {ds.attrs['sweep_computed']} computed, "
              f"{ds.attrs['sweep_cache_hits']} from the cache, {ds.attrs['sweep_wall_time_s']:.1f} s; "
              f"scheduler: {ds.attrs['sweep_scheduler']}", file=sys.stderr)
    if ds.attrs.get("sweep_cache_rejected"):
        print(f"warning: {ds.attrs['sweep_cache_rejected']} damaged cache entries were computed "
              f"again: {ds.attrs['sweep_cache_rejected_entries']}", file=sys.stderr)
    return 0


def register(sub) -> None:
    p = sub.add_parser("sweep", help="simulate a grid of scene parameters in parallel (Dask) into one netCDF",
                       description="Simulate every combination of the --param values of a scene on a Dask "
                                   "cluster (local by default) and write one Dataset with a dimension per "
                                   "parameter.  Finished scenes are cached, so a stopped sweep resumes.")
    p.add_argument("scene", help="a TOML scene file or a built-in scene name (see `bearing-lab scenes`)")
    p.add_argument("--param", action="append", default=[], metavar="KEY=V1,V2,...",
                   help="a swept scene key and its values, e.g. defect.offset_mm=0,0.25,0.5 (repeat for a grid)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="a fixed override for every scene, e.g. load.radial_n=480")
    p.add_argument("--duration", type=float, default=None, metavar="S", help="recorded duration of each scene, s")
    p.add_argument("--fs", type=float, default=None, metavar="HZ", help="output sample rate, Hz")
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help="worker processes of the local Dask cluster (default 2)")
    p.add_argument("--scheduler", default=None, metavar="ADDR",
                   help="an existing Dask scheduler (tcp://host:port), or 'serial' to run in this process")
    p.add_argument("--cache-dir", default=None, metavar="DIR",
                   help="scene cache (default $BEARING_LAB_CACHE or ~/.cache/bearing_lab/sweeps)")
    p.add_argument("--no-cache", action="store_true", help="neither read nor write the scene cache")
    p.add_argument("-o", "--output", required=True, metavar="OUT.nc")
    p.add_argument("--force", action="store_true", help="overwrite an existing OUT.nc")
    p.add_argument("--json", action="store_true", help="print what was written as JSON (no progress bar)")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors and warnings")
    p.set_defaults(func=_sweep)
