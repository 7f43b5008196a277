"""A sweep's store: the checksummed on-disk cache of finished scenes, and the accumulator that
places each scene's variables at its grid index as results arrive (in any order), with the
per-scene metrics, times and attributes."""
from __future__ import annotations

import math
from pathlib import Path
import warnings

import numpy as np

from .._xarray import xr
from ..errors import BearingLabError, SceneError
from ..io.export import checksum_path, to_netcdf
from ..schema import DEFAULT_CHANNEL
from ..utils._files import sha256_file

SWEEP_METRICS = ("rms", "peak", "crest_factor", "kurtosis")   # the analysis METRICS stored per scene
METRIC_SIGNAL = DEFAULT_CHANNEL  # the simulator's accelerometer signal
# variables a cached scene must hold to be used
_REQUIRED = ("outer_ring_acc_y", "outer_ring_acc_x", "outer_ring_disp_y", "outer_ring_disp_x",
             "inner_ring_disp_y", "inner_ring_disp_x")


class CacheWarning(UserWarning):
    """A sweep-cache entry was damaged or incomplete and its scene was computed again."""


# ---------------------------------------------------------------- the cache
def write_cache(ds, path: Path) -> None:
    """Write one scene to the cache: netCDF4, float64 as is, *uncompressed* (zlib costs
    ~0.12 s per 1 s scene, a third of its simulation, to save a third of 3.5 MB), then its
    checksum file ``<hash>.nc.sha256`` (``sha256sum -c`` format).  Both are written
    atomically; an entry without its checksum is incomplete and is never read."""
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        to_netcdf(ds, path, complevel=0, checksum_file=True, error=BearingLabError)
    except BearingLabError as exc:
        raise BearingLabError(f"sweep cache: {exc}") from None


def _cache_problem(ds, digest: str, expect: dict) -> str | None:
    """What is wrong with a cache entry's content, or None (shape, names, finite values)."""
    if ds.attrs.get("sweep_scene_hash") != digest:
        return "it belongs to another scene"
    for name in _REQUIRED:
        if name not in ds.data_vars:
            return f"variable {name} is missing"
    for dim, n in expect.items():
        if ds.sizes.get(dim) != n:
            return f"dimension {dim} has {ds.sizes.get(dim)} entries, the scene needs {n}"
    for name, var in ds.data_vars.items():
        if var.dtype.kind in "fc" and not np.all(np.isfinite(var.values)):
            return f"variable {name} holds NaN/Inf"
    return None


def _read_cache(path: Path, digest: str, expect: dict):
    """Return (Dataset or None, problem or None): None/None when there is no entry.

    The file's bytes are checked against its checksum file before netCDF reads them
    (a damaged file never reaches the C library), then the content is validated.
    """
    if not path.is_file():
        return None, None
    sums = checksum_path(path)
    try:
        recorded = sums.read_text().split()[0] if sums.is_file() else None
    except (OSError, IndexError, UnicodeDecodeError):
        recorded = None
    if recorded is None:
        return None, "no checksum file (an interrupted write)"
    try:
        if sha256_file(path) != recorded:
            return None, "its sha256 does not match the checksum file"
        ds = xr.load_dataset(path, engine="netcdf4")
    except (OSError, ValueError, RuntimeError, KeyError) as exc:
        return None, f"unreadable ({type(exc).__name__}: {exc})"
    return (None, problem) if (problem := _cache_problem(ds, digest, expect)) else (ds, None)


def _drop_entry(path: Path) -> None:
    for p in (path, checksum_path(path)):
        try:
            p.unlink()
        except OSError:
            pass


def from_cache(cdir, scenes, digests, acc):
    """Put every valid cached scene into ``acc``; return (hits, indices to compute, rejected).

    A damaged or incomplete entry is deleted, listed in ``rejected`` and warned about
    (:class:`CacheWarning`): its scene is computed again.
    """
    hits, todo, rejected = 0, [], []
    for i, dg in enumerate(digests):
        ds, problem = (None, None)
        if cdir is not None:
            expect = {"time": int(round(scenes[i].duration * scenes[i].fs_out)),
                      "ball": scenes[i].bearing.n_balls}
            ds, problem = _read_cache(cdir / f"{dg}.nc", dg, expect)
        if problem is not None:
            rejected.append(f"{dg[:12]} ({problem})")
            _drop_entry(cdir / f"{dg}.nc")
        if ds is None:
            todo.append(i)
        else:
            acc.put(i, ds, cached=True)
            hits += 1
    if rejected:
        warnings.warn(f"sweep: {len(rejected)} damaged cache entr{'y' if len(rejected) == 1 else 'ies'} "
                      f"in {cdir} computed again: {'; '.join(rejected)}", CacheWarning, stacklevel=3)
    return hits, todo, rejected


def _metrics(x: np.ndarray) -> dict:
    """The sweep's metrics (the analysis table's functions; NaN where undefined)."""
    from ..analysis import METRICS  # read at call time (run-time metrics)
    out = {}
    for name in SWEEP_METRICS:
        try:
            out[name] = float(METRICS[name].func(x))
        except BearingLabError:
            out[name] = math.nan
    return out


# attributes that differ per scene or are replaced by the sweep's own
_PER_SCENE_ATTRS = {"title", "scene_toml", "wall_time_s", "table_time_s", "compile_time_s", "solver_steps",
                    "solver_rejected_steps", "sweep_scene_hash", "scene_name"}


class Stack:
    """Places each scene's variables at its grid index as results arrive (any order)."""

    def __init__(self, shape, n):
        self.shape, self.n = shape, n
        self.arrays = None
        self.template = None
        self.metrics = {m: np.full(n, np.nan) for m in SWEEP_METRICS}
        self.wall = np.full(n, np.nan)
        self.steps = np.zeros(n, dtype=np.int64)
        self.cached = np.zeros(n, dtype=bool)
        self.common_attrs = None
        self.scene_attrs = {}  # scalar per-scene attributes, name -> values by scene index
        self.on_put = None     # on_put(i, ds, cached): called as each scene is placed

    def put(self, i, ds, *, cached):
        if self.arrays is None:
            self.template = ds
            self.arrays = {name: np.empty((self.n, *var.shape), dtype=var.dtype)
                           for name, var in ds.data_vars.items()}
            self.common_attrs = {k: v for k, v in ds.attrs.items() if k not in _PER_SCENE_ATTRS}
        else:
            t0 = self.template
            if set(ds.data_vars) != set(self.arrays):
                raise BearingLabError("sweep: scenes returned different variables "
                                      f"({sorted(ds.data_vars)} vs {sorted(self.arrays)})")
            if not np.array_equal(ds["time"].values, t0["time"].values):
                raise SceneError("sweep: scenes have different time axes; all scenes of a sweep "
                                 "must share output.duration_s and output.sample_rate_hz")
            for k in list(self.common_attrs):
                if not _same(ds.attrs.get(k), self.common_attrs[k]):
                    del self.common_attrs[k]
        for name, arr in self.arrays.items():
            v = ds[name].transpose(*self.template[name].dims).values
            if v.shape != arr.shape[1:]:
                raise BearingLabError(f"sweep: variable {name} has shape {v.shape} in one scene "
                                      f"and {arr.shape[1:]} in another")
            arr[i] = v
        if METRIC_SIGNAL in ds:
            for k, val in _metrics(np.asarray(ds[METRIC_SIGNAL].values)).items():
                self.metrics[k][i] = val
        for k, v in ds.attrs.items():
            if k not in _PER_SCENE_ATTRS and isinstance(v, (str, int, float, np.number)):
                self.scene_attrs.setdefault(k, [None] * self.n)[i] = v.item() if isinstance(v, np.generic) else v
        self.wall[i] = float(ds.attrs.get("wall_time_s", np.nan))
        self.steps[i] = int(ds.attrs.get("solver_steps", 0))
        self.cached[i] = cached
        if self.on_put is not None:
            self.on_put(i, ds, cached)

    def dataset(self, sdims, coords):
        t = self.template
        data_vars = {}
        for name, arr in self.arrays.items():
            var = t[name]
            data_vars[name] = ((*sdims, *var.dims), arr.reshape(*self.shape, *var.shape), dict(var.attrs))
        all_coords = dict(coords)
        for cname, c in t.coords.items():
            all_coords[cname] = (c.dims, c.values, dict(c.attrs))
        self.arrays = None  # hand the memory to the Dataset
        return xr.Dataset(data_vars, coords=all_coords)


def _same(a, b) -> bool:
    try:
        return bool(np.array_equal(np.asarray(a), np.asarray(b)))
    except Exception:  # noqa: BLE001 - incomparable attributes are simply not common
        return False
