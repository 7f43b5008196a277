"""Parameter sweeps: many scenes, one labelled Dataset, run in parallel on Dask.

``run_sweep(scene, {"defect.offset_mm": [0, 0.25, 0.5], "speed_rpm": [900, 1800]})``
simulates every combination of the swept values (a full grid) and returns one
:class:`xarray.Dataset` with a dimension per swept key:

- the dimension is named after the key with dots turned into underscores
  (``defect.offset_mm`` -> ``defect_offset_mm``); its coordinate holds the
  values (strings with units such as ``"0.5 mm"`` are converted to the key's
  unit) and a ``units`` attribute taken from the key's suffix (``_mm`` -> mm);
- every variable of :func:`bearing_lab.simulate`'s output, stacked along the
  sweep dimensions (sweep dims first, then ``ball``/``time``); the time axis is
  shared, so a sweep that changes ``output.duration_s`` or
  ``output.sample_rate_hz`` (or the number of balls) is refused;
- per-scene metrics of ``outer_ring_acc_y`` (``rms``, ``peak``,
  ``crest_factor``, Pearson ``kurtosis``; the definitions of
  :mod:`bearing_lab.analysis`), the compute time ``wall_time_s`` per scene,
  ``solver_steps``, ``cached`` (the scene came from the cache) and
  ``scene_hash`` (the cache key); simulation attributes that differ between
  scenes (``shaft_speed_rpm``, the fidelity ``"auto"`` chose, ...) become
  per-scene variables of the same name (``scene_<name>`` if the name is taken);
- attributes ``sweep_params`` (JSON), ``sweep_n_scenes``,
  ``sweep_cache_hits``, ``sweep_computed``, ``sweep_scheduler``,
  ``sweep_wall_time_s``, the base ``scene_toml`` and the per-scene attributes
  that are the same for every scene (bearing, sampling rate, version, ...).

Scheduling (``scheduler=``):

- ``None`` / ``"local"``: a :class:`dask.distributed.LocalCluster` of
  ``n_workers`` (default 2) worker processes with one thread each, closed at
  the end;
- ``"tcp://host:port"``: an existing cluster (``dask.distributed.Client(address)``);
  its workers need bearing_lab installed.  The client writes the cache, since
  remote workers may not share its file system;
- a :class:`dask.distributed.Client`: used as is (not closed);
- ``"serial"``: in this process, no Dask.

Every scene runs through the same function on every path and the results are
placed by index, so a Dask sweep is bit for bit equal to a serial one.

Cache: a finished scene is written to ``cache_dir/<hash>.nc`` (netCDF4,
uncompressed, float64 kept exactly, written atomically) with its checksum in
``<hash>.nc.sha256``; on reading, the file must match its checksum and hold the
scene's variables and shapes with finite values, else it is computed again, the
sweep warns (:class:`CacheWarning`) and says so in ``sweep_cache_rejected`` and
``sweep_cache_rejected_entries``.  The hash is the sha256 of the resolved scene TOML
(:meth:`Scene.to_toml`), the bearing_lab version (with a fingerprint of the
simulator's source, so a development install never reuses results of older
code) and the simulate keywords.  A
sweep that was stopped resumes: cached scenes are read, not recomputed.
``cache_dir`` defaults to ``$BEARING_LAB_CACHE`` or ``~/.cache/bearing_lab/sweeps``;
``cache_dir=False`` turns caching off.
"""
from __future__ import annotations

import hashlib
import itertools
import json
import logging
import math
import os
from pathlib import Path
import time as _time
import tomllib
import uuid

import numpy as np

from .._version import __version__
from ..errors import BearingLabError, SceneError
from ..sim import load_scene, simulate
from ..sim.budget import check_budget
from ..sim.scene import SET_ALIASES as _ALIASES, convert_value as _convert, merge_overrides, parse_value as _parse_value
from .store import (CacheWarning, from_cache as _from_cache, METRIC_SIGNAL as _METRIC_SIGNAL,
                    SWEEP_METRICS as _METRICS, Stack as _Stack, write_cache as _write_cache)

__all__ = ["run_sweep", "scene_hash", "code_fingerprint", "default_cache_dir", "dim_name", "key_units",
           "CacheWarning"]

# units of the --set key suffixes (scene.py's _SUFFIX), as CF/UDUNITS strings
_UNIT_STRINGS = {
    "_mm": "mm", "_um": "um", "_m": "m", "_n": "N", "_rpm": "rpm", "_s": "s", "_hz": "Hz",
    "_deg": "degree", "_n_m": "N m-1", "_n_s_m": "N s m-1", "_kg": "kg", "_gpa": "GPa",
    "_kg_m3": "kg m-3", "_m_s2": "m s-2",
}
# simulate()'s keywords and the scene keys they set (the same mapping simulate applies)
_SIM_KW = {"duration": "output.duration_s", "fs": "output.sample_rate_hz", "rtol": "solver.rtol",
           "method": "solver.method", "step": "solver.step_s", "fidelity": "fidelity"}


def default_cache_dir() -> Path:
    """``$BEARING_LAB_CACHE`` or ``~/.cache/bearing_lab/sweeps``."""
    env = os.environ.get("BEARING_LAB_CACHE")
    return Path(env) if env else Path.home() / ".cache" / "bearing_lab" / "sweeps"


def dim_name(key: str) -> str:
    """The Dataset dimension of a swept key: ``defect.offset_mm`` -> ``defect_offset_mm``."""
    return key.replace(".", "_")


def key_units(key: str) -> str | None:
    """The unit a key's suffix names (``speed_rpm`` -> ``"rpm"``), or None."""
    for suf in sorted(_UNIT_STRINGS, key=len, reverse=True):
        if key.endswith(suf):
            return _UNIT_STRINGS[suf]
    return None


def _canonical(key: str) -> str:
    return _ALIASES.get(key, key)


_FINGERPRINT: list = []
_PACKAGE_ROOT = Path(__file__).resolve().parents[1]   # bearing_lab/ (this file is bearing_lab/sweep/__init__.py)


def _simulator_sources() -> list:
    """The files :func:`code_fingerprint` reads: bearings.py and every module under sim/."""
    files = sorted(f for f in [_PACKAGE_ROOT / "bearings.py", *(_PACKAGE_ROOT / "sim").rglob("*.py")]
                   if f.is_file())
    if not files:
        raise BearingLabError(f"sweep: no simulator source under {_PACKAGE_ROOT} to fingerprint the cache key")
    return files


def code_fingerprint() -> str:
    """sha256 of the simulator's source (bearing_lab/sim/**/*.py and bearings.py).

    Part of the scene hash besides the version: in a development (editable) install
    the physics changes while ``__version__`` stays put, and a cache keyed on the
    version alone would hand back results of older code.
    """
    if not _FINGERPRINT:
        root = _PACKAGE_ROOT
        h = hashlib.sha256()
        for f in _simulator_sources():
            h.update(str(f.relative_to(root)).encode() + b"\0" + f.read_bytes() + b"\0")
        _FINGERPRINT.append(h.hexdigest())
    return _FINGERPRINT[0]


def scene_hash(scene_toml: str, simulate_kwargs: dict | None = None) -> str:
    """sha256 of the resolved scene TOML, the bearing_lab version (and simulator source
    fingerprint) and the simulate keywords: the cache key of one scene."""
    h = hashlib.sha256()
    h.update(scene_toml.encode())
    h.update(b"\0bearing_lab " + __version__.encode() + b" " + code_fingerprint().encode())
    h.update(b"\0" + json.dumps(simulate_kwargs or {}, sort_keys=True, default=repr).encode())
    return h.hexdigest()


def _values(key, values) -> list:
    """The swept values of one key as a list (strings with units converted)."""
    if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
        raise SceneError(f"sweep parameter {key!r}: give a list of values, got {values!r}")
    out = []
    for v in values:
        if isinstance(v, np.generic):
            v = v.item()
        if isinstance(v, str):
            v = _parse_value(v)
            v = _convert(v, key.split(".")[-1], f"sweep parameter {key}")
        if isinstance(v, float) and not math.isfinite(v):
            raise SceneError(f"sweep parameter {key!r}: value {v!r} is not finite")
        out.append(v)
    if not out:
        raise SceneError(f"sweep parameter {key!r}: no values")
    if len(set(map(repr, out))) != len(out):
        dup = next(v for i, v in enumerate(out) if repr(v) in map(repr, out[:i]))
        raise SceneError(f"sweep parameter {key!r}: value {dup!r} appears twice")
    kinds = {type(v) for v in out}
    if str in kinds and len(kinds) > 1:
        raise SceneError(f"sweep parameter {key!r}: mixes text and numbers: {out!r}")
    if kinds == {int, float}:  # one numeric type, so 0 and 0.0 resolve to the same scene
        out = [float(v) for v in out]
    if len(set(map(repr, out))) != len(out):
        raise SceneError(f"sweep parameter {key!r}: a value appears twice in {out!r}")
    return out


def _coord(key, values):
    kinds = {type(v) for v in values}
    if kinds <= {int}:
        arr = np.asarray(values, dtype=np.int64)
    elif kinds <= {int, float}:
        arr = np.asarray(values, dtype=float)
    elif kinds <= {bool}:
        arr = np.asarray(values, dtype=bool)
    else:
        arr = np.asarray([str(v) for v in values], dtype=object)
    attrs = {"long_name": f"swept scene key {key}"}
    u = key_units(key)
    if u is not None:
        attrs["units"] = u
    elif arr.dtype.kind in "if":
        attrs["units"] = "1"
    return arr, attrs


# ---------------------------------------------------------------- one scene (runs on workers)
def _simulate_scene(scene_toml: str, digest: str, cache_path: str | None):
    """Simulate one resolved scene (given as TOML); write the cache file if asked.

    The same function runs in-process (serial) and on Dask workers.
    """
    scene = load_scene(tomllib.loads(scene_toml))
    ds = simulate(scene, progress=False)
    ds.attrs["sweep_scene_hash"] = digest
    if cache_path is not None:
        _write_cache(ds, Path(cache_path))
    return ds


# ---------------------------------------------------------------- the sweep
def _resolve(scene, params: dict, simulate_kwargs: dict):
    """Validate the sweep; return (keys, value lists, base Scene, fixed overrides, scenes in C order)."""
    if not isinstance(params, dict) or not params:
        raise SceneError("sweep: give the swept parameters as a dict {key: [values, ...]}")
    unknown_kw = {"progress"} & set(simulate_kwargs)
    if unknown_kw:
        raise BearingLabError("sweep: 'progress' is the sweep's own progress bar, not a simulate option")
    named = {_SIM_KW[k]: v for k, v in simulate_kwargs.items() if k in _SIM_KW}
    fixed = merge_overrides({k: v for k, v in simulate_kwargs.items()
                             if k not in _SIM_KW and v is not None}, **named)
    keys, values, seen = [], [], {}
    for key, vals in params.items():
        if not isinstance(key, str) or not key:
            raise SceneError(f"sweep: parameter names must be scene keys like 'speed_rpm', got {key!r}")
        canon = _canonical(key)
        if canon in seen:
            raise SceneError(f"sweep parameter {key!r}: the same scene key as {seen[canon]!r}")
        seen[canon] = key
        if canon in {_canonical(k) for k in fixed}:
            raise SceneError(f"sweep parameter {key!r} is also given as a fixed simulate option")
        keys.append(key)
        values.append(_values(key, vals))
    dims = [dim_name(k) for k in keys]
    clash = {d for d in dims if dims.count(d) > 1} | ({"time", "ball"} & set(dims))
    if clash:
        raise SceneError(f"sweep: parameter dimension name {sorted(clash)[0]!r} is taken; rename the key")
    base = load_scene(scene, **fixed)
    # each value on its own first, so an error names the key and value that caused it
    for key, vals in zip(keys, values):
        for v in vals:
            try:
                base.replace(**{key: v})
            except SceneError as exc:
                raise SceneError(f"sweep parameter {key}={v!r}: {exc}") from None
    scenes = []
    for combo in itertools.product(*values):
        ov = dict(zip(keys, combo))
        try:
            scenes.append(base.replace(**ov))
        except SceneError as exc:
            what = ", ".join(f"{k}={v!r}" for k, v in ov.items())
            raise SceneError(f"sweep scene {what}: {exc}") from None
    for combo, sc in zip(itertools.product(*values), scenes):
        try:
            check_budget(sc)  # every scene, before any runs
        except SceneError as exc:
            what = ", ".join(f"{k}={v!r}" for k, v in zip(keys, combo))
            raise SceneError(f"sweep scene {what}: {exc}") from None
    shape = tuple(len(v) for v in values)
    for what, get in (("output.duration_s", lambda s: s.duration),
                      ("output.sample_rate_hz", lambda s: s.fs_out),
                      ("the number of balls", lambda s: s.bearing.n_balls),
                      ("output.ball_loads", lambda s: bool(s.data["output"]["ball_loads"]))):
        arr = np.array([get(s) for s in scenes]).reshape(shape)
        if np.all(arr == arr.flat[0]):
            continue
        culprits = [k for ax, k in enumerate(keys) if np.any(np.diff(arr, axis=ax) != 0)]
        raise SceneError(f"sweep parameter {', '.join(map(repr, culprits))} changes {what}; all scenes "
                         "of a sweep share one time axis and ball set (set duration=/fs= for the whole sweep)")
    return keys, values, base, scenes


def _client_for(scheduler, n_workers):
    """(client, cluster-or-None, own_client, description)."""
    try:
        from dask.distributed import Client, LocalCluster  # dask once a sweep uses it (_xarray reads sys.modules)
    except ImportError:  # pragma: no cover
        raise BearingLabError("sweep: Dask is not installed; `pip install bearing_lab[sweep]` "
                              "or use scheduler='serial'") from None
    if isinstance(scheduler, Client):
        if n_workers is not None:
            raise BearingLabError("sweep: n_workers applies to the local cluster, not to a given Client")
        return scheduler, None, False, f"client {scheduler.scheduler.address}"
    if scheduler in (None, "local"):
        n = 2 if n_workers is None else int(n_workers)
        if n < 1:
            raise BearingLabError(f"sweep: n_workers={n_workers!r} must be at least 1")
        import dask  # dask once a sweep uses it (_xarray reads sys.modules)
        # the workers' statistical profiler samples the running task every 10 ms: ~5 % of a scene
        try:
            with dask.config.set({"distributed.worker.profile.enabled": False}):
                cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=logging.ERROR)
            return Client(cluster), cluster, True, f"local cluster, {n} worker processes x 1 thread"
        except Exception as exc:  # noqa: BLE001 - Dask raises RuntimeError, OSError, TimeoutError...
            raise BearingLabError(f"sweep: the local Dask cluster of {n} worker(s) did not start "
                                  f"({type(exc).__name__}: {exc}); run in this process with "
                                  "scheduler='serial' (CLI --scheduler serial)") from None
    if isinstance(scheduler, str):
        if n_workers is not None:
            raise BearingLabError(f"sweep: n_workers applies to the local cluster; the cluster at "
                                  f"{scheduler} has its own workers")
        try:
            client = Client(scheduler, timeout="10s")
        except Exception as exc:  # noqa: BLE001 - OSError, TimeoutError, ValueError, RuntimeError
            raise BearingLabError(f"sweep: cannot connect to the Dask scheduler {scheduler!r}: {exc}") from None
        return client, None, True, f"scheduler {scheduler}"
    raise BearingLabError(f"sweep: scheduler={scheduler!r}: use None (local cluster), 'serial', "
                          "a 'tcp://host:port' address or a dask.distributed.Client")


def _open_cache_dir(cache_dir) -> Path | None:
    if cache_dir is False:
        return None
    cdir = Path(cache_dir).expanduser() if cache_dir not in (None, True) else default_cache_dir()
    try:
        cdir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise BearingLabError(f"sweep: cannot create the cache directory {cdir}: {exc}") from None
    return cdir


class _Jobs:
    """The sweep's scenes as jobs: scene i's resolved TOML, its cache key and where its cache file goes."""

    def __init__(self, scene_tomls, digests, cache_dir):
        self.scene_tomls, self.digests, self.cache_dir = scene_tomls, digests, cache_dir

    def cache_path(self, i):
        return self.cache_dir / f"{self.digests[i]}.nc" if self.cache_dir is not None else None


def _simulate_missing(missing, jobs, results, *, scheduler, n_workers, bar, failure) -> str:
    """Simulate the scenes whose indices are ``missing`` (serially or on Dask) into ``results``.

    ``jobs``: each scene's TOML, cache key and cache file (:class:`_Jobs`); ``failure(i, exc)`` makes
    the error naming scene i's values.  Returns the scheduler used, described."""
    if not missing:
        return "serial (in process)"
    if scheduler == "serial":
        for i in missing:
            path = jobs.cache_path(i)
            try:
                ds = _simulate_scene(jobs.scene_tomls[i], jobs.digests[i], None if path is None else str(path))
            except Exception as exc:  # noqa: BLE001 - re-raised with the scene's values
                raise failure(i, exc) from exc
            results.put(i, ds, cached=False)
            if bar is not None:
                bar.update(1)
        return "serial (in process)"
    client, cluster, own, desc = _client_for(scheduler, n_workers)
    remote = cluster is None  # an existing cluster's workers may not share our disk
    try:
        from dask.distributed import as_completed  # dask once a sweep uses it (_xarray reads sys.modules)
        futures = {}
        for i in missing:
            # workers of a local cluster share our disk and write the cache themselves
            path = jobs.cache_path(i) if not remote else None
            fut = client.submit(_simulate_scene, jobs.scene_tomls[i], jobs.digests[i],
                                None if path is None else str(path),
                                key=f"bearing_lab-scene-{jobs.digests[i][:16]}-{uuid.uuid4().hex[:8]}",
                                pure=False)
            futures[fut] = i
        for fut in as_completed(list(futures)):
            i = futures.pop(fut)
            try:
                ds = fut.result()
            except Exception as exc:  # noqa: BLE001
                for other in futures:
                    other.cancel()
                raise failure(i, exc) from exc
            del fut
            if remote and jobs.cache_dir is not None:
                _write_cache(ds, jobs.cache_path(i))
            results.put(i, ds, cached=False)
            if bar is not None:
                bar.update(1)
    finally:
        if own:
            client.close()
        if cluster is not None:
            cluster.close()
    return desc


def _assemble(acc, keys, values, shape, digests, metrics):
    """The sweep Dataset: the stacked scenes on the swept dimensions, per-scene metrics,
    times, cache flags and the attributes that differ between scenes."""
    coords = {}
    for key, vals in zip(keys, values):
        arr, attrs = _coord(key, vals)
        coords[dim_name(key)] = (dim_name(key), arr, attrs)
    sdims = tuple(dim_name(k) for k in keys)
    out = acc.dataset(sdims, coords)
    if metrics:
        units = out[_METRIC_SIGNAL].attrs.get("units", "") if _METRIC_SIGNAL in out else ""
        from ..analysis import METRICS, metric_units  # read at call time (run-time metrics)
        for name in _METRICS:
            out[name] = (sdims, acc.metrics[name].reshape(shape),
                         {"units": metric_units(name, units),
                          "long_name": f"{METRICS[name].long_name} of {_METRIC_SIGNAL}", "signal": _METRIC_SIGNAL})
    out["wall_time_s"] = (sdims, acc.wall.reshape(shape),
                          {"units": "s", "long_name": "compute time of the scene (simulate's wall_time_s, "
                                                      "without compilation; from the run that filled the cache)"})
    out["solver_steps"] = (sdims, acc.steps.reshape(shape), {"units": "1",
                                                             "long_name": "accepted solver steps"})
    out["cached"] = (sdims, acc.cached.reshape(shape).astype(np.int8),
                     {"units": "1", "long_name": "1: the scene was read from the sweep cache",
                      "flag_values": "0 1"})
    out["scene_hash"] = (sdims, np.asarray(digests, dtype=object).reshape(shape),
                         {"units": "1", "long_name": "sha256 of the resolved scene TOML, version and "
                                                     "simulate options (the cache file name)"})
    out.attrs.update(acc.common_attrs)
    # attributes that differ between scenes (e.g. the fidelity "auto" picked) become variables
    for name, vals in acc.scene_attrs.items():
        if name in acc.common_attrs or any(v is None for v in vals):
            continue
        var = name if name not in out.variables else f"scene_{name}"
        kinds = {type(v) for v in vals}
        arr = (np.asarray(vals, dtype=float) if kinds <= {int, float} and kinds != {int}
               else np.asarray(vals, dtype=np.int64) if kinds == {int}
               else np.asarray([str(v) for v in vals], dtype=object))
        out[var] = (sdims, arr.reshape(shape), {"units": key_units(name) or "1",
                                                "long_name": f"simulation attribute {name!r} of each "
                                                             "scene (it differs across the sweep)"})
    return out


def run_sweep(scene, params: dict, *, scheduler=None, n_workers: int | None = None, cache_dir=None,
              progress: bool = True, metrics: bool = True, on_scene=None, **simulate_kwargs):
    """Simulate every combination of swept scene keys; return one labelled Dataset.

    Parameters
    ----------
    scene : built-in name, TOML path, dict or Scene (the base of every scene).
    params : ``{key: [values, ...]}`` with ``--set`` keys (``speed_rpm``,
        ``load.radial_n``, ``defect.offset_mm``, ``fidelity`` ...).  The grid is the
        Cartesian product, in the order the keys are given.
    scheduler : None/"local" (LocalCluster), "serial", "tcp://host:port" or a Client.
    n_workers : worker processes of the local cluster (default 2).
    cache_dir : where finished scenes are kept (default ``$BEARING_LAB_CACHE`` or
        ``~/.cache/bearing_lab/sweeps``); False: no cache.
    progress : tqdm bar over the scenes as they finish.
    metrics : add rms, peak, crest_factor, kurtosis of outer_ring_acc_y.
    on_scene : ``on_scene(index, ds, cached)``, called in this process as each scene is read from
        the cache or finishes (``index`` in C order over the grid); an exception it raises (a
        KeyboardInterrupt) stops the sweep, the scenes cached so far kept.
    **simulate_kwargs : fixed for every scene: ``duration``, ``fs``, ``rtol``,
        ``method``, ``step``, ``fidelity`` or ``--set`` keys.

    Returns
    -------
    xarray.Dataset (see the module docstring).

    Raises
    ------
    SceneError : a bad key or value (the message names it), or a sweep that
        changes the time axis.
    BearingLabError : scheduler problems; errors of a scene's solve are re-raised
        with the scene's swept values in the message.
    """
    t_start = _time.perf_counter()
    keys, values, base, scenes = _resolve(scene, params, simulate_kwargs)
    kw_for_hash = {k: v for k, v in simulate_kwargs.items() if v is not None}
    tomls = [s.to_toml() for s in scenes]
    digests = [scene_hash(t, kw_for_hash) for t in tomls]
    cdir = _open_cache_dir(cache_dir)
    shape = tuple(len(v) for v in values)
    n = len(scenes)

    acc = _Stack(shape, n)
    acc.on_put = on_scene
    hits, todo, rejected = _from_cache(cdir, scenes, digests, acc)

    bar = None
    if progress:
        from tqdm.auto import tqdm  # tqdm only when the bar is shown
        bar = tqdm(total=n, initial=hits, unit="scene", desc=f"sweep {base.name}", leave=False)

    def label(i):
        idx = np.unravel_index(i, shape)
        return ", ".join(f"{k}={values[a][j]!r}" for a, (k, j) in enumerate(zip(keys, idx)))

    def failed(i, exc):
        if isinstance(exc, BearingLabError):
            return type(exc)(f"sweep scene {label(i)}: {exc}")
        return BearingLabError(f"sweep scene {label(i)}: {type(exc).__name__}: {exc}")

    try:
        desc = _simulate_missing(todo, _Jobs(tomls, digests, cdir), acc, scheduler=scheduler, n_workers=n_workers,
                                 bar=bar, failure=failed)
    finally:
        if bar is not None:
            bar.close()

    out = _assemble(acc, keys, values, shape, digests, metrics)
    out.attrs.update({
        "title": f"bearing_lab sweep of scene {base.name!r}",
        "scene_name": base.name,
        "scene_toml": base.to_toml(),
        "bearing_lab_version": __version__,
        "sweep_params": json.dumps({k: v for k, v in zip(keys, values)}),
        "sweep_dims": " ".join(dim_name(k) for k in keys),
        "sweep_n_scenes": int(n),
        "sweep_cache_hits": int(hits),
        "sweep_cache_rejected": int(len(rejected)),
        "sweep_cache_rejected_entries": "; ".join(rejected),
        "sweep_computed": int(n - hits),
        "sweep_cache_dir": str(cdir) if cdir is not None else "",
        "sweep_scheduler": desc if todo else "none (all scenes cached)",
        "sweep_wall_time_s": float(_time.perf_counter() - t_start),
        "sweep_simulate_kwargs": json.dumps(kw_for_hash, sort_keys=True, default=repr),
    })
    out.attrs.setdefault("Conventions", "CF-1.8")
    return out
