"""On-disk cache of contact tables: one ``.npz`` file per table, checked on every read.

Why: a half-space table costs a few tenths of a second, and the same defect comes back
in every run of a sweep, a validation case or a study, in every process and session.
The key is a sha256 of everything the table depends on: the outline and depth (not the
defect's angle around the ring), the bearing geometry, the clearance, the material, the
model and grid arguments, and the source of the code that builds tables (this package's
``sim/defects`` modules), so editing that code invalidates old entries by itself.

An entry is ``<cache_dir("tables")>/<model>-<key[:40]>.npz`` holding the table's arrays,
the key, and a sha256 of the arrays.  Reading checks the key, the shapes, that every
value is finite and the checksum; an entry that fails is reported (a
:class:`TableCacheWarning` naming the file and the reason), rebuilt and replaced, never
used.  Writes go to a temporary file that is renamed into place
(:func:`bearing_lab.utils._files.atomic_path`), so concurrent processes see either no entry or
a complete one; two processes building the same table write identical content.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
from pathlib import Path
import warnings

import numpy as np

from bearing_lab.utils._files import atomic_path, cache_dir, sha256_bytes

from .halfspace import (ABOVE_NODE_STEP, COARSE_STEP, DIRECT_UPDATE_CELLS, ENTER_SCALE, HALFSPACE_NODES,
                        REFINE_TOL, REFRESH_EVERY, SOLVE_TOL, TABLE_CELLS)
from .halfspace_skewed import INTACT_LATTICE

FORMAT = 1
_ARRAYS = ("psi", "delta", "G", "drop", "intact_fraction")
_SOURCE: list = []


class TableCacheWarning(UserWarning):
    """A contact-table cache entry was unreadable or inconsistent and has been rebuilt."""


def code_fingerprint() -> str:
    """sha256 of the modules that build contact tables (``sim/defects/*.py``)."""
    if not _SOURCE:
        h = hashlib.sha256()
        for f in sorted(Path(__file__).resolve().parent.glob("*.py")):
            h.update(f.name.encode() + b"\0" + f.read_bytes() + b"\0")
        _SOURCE.append(h.hexdigest())
    return _SOURCE[0]


def _plain(x):
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return {f.name: _plain(getattr(x, f.name)) for f in dataclasses.fields(x)}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, dict):
        return {str(k): _plain(v) for k, v in x.items()}
    if isinstance(x, np.generic):
        return _plain(x.item())
    return x


#: the bearing's fields a table depends on (the groove geometry)
BEARING_FIELDS = ("ball_diameter", "pitch_diameter", "inner_conformity", "outer_conformity")


def table_key(defect, bearing, *, halfspace_nodes=HALFSPACE_NODES, above_node_step=ABOVE_NODE_STEP,
              **args) -> str:
    """sha256 (hex) of everything a table depends on (JSON floats round-trip exactly).

    ``defect`` must have angle 0: where the defect sits around the ring does not enter
    the table.  The half-space nodes are the table builder's (:mod:`.contact` hands in the
    values it builds with)."""
    payload = {"format": FORMAT, "code": code_fingerprint(), "defect": _plain(defect),
               "bearing": {f: _plain(getattr(bearing, f)) for f in BEARING_FIELDS},
               "args": _plain(args),
               "halfspace": _plain([halfspace_nodes, above_node_step, TABLE_CELLS, SOLVE_TOL,
                                    REFINE_TOL, COARSE_STEP, INTACT_LATTICE, DIRECT_UPDATE_CELLS,
                                    REFRESH_EVERY, ENTER_SCALE])}
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()


def entry_path(key: str, model: str) -> Path:
    return cache_dir("tables") / f"{model}-{key[:40]}.npz"


def _checksum(arrays: dict) -> str:
    h = b"".join(np.ascontiguousarray(arrays[n], dtype=np.float64).tobytes()
                 + repr(np.shape(arrays[n])).encode() for n in _ARRAYS)
    return sha256_bytes(h)


def _split_info(info: dict):
    """Info entries that are arrays (stored as arrays) and the rest (stored as JSON)."""
    arrays, plain = {}, {}
    for k, v in info.items():
        if isinstance(v, np.ndarray):
            arrays[f"info__{k}"] = v
        elif isinstance(v, tuple) and any(isinstance(e, np.ndarray) for e in v):
            for i, e in enumerate(v):
                arrays[f"info__{k}__{i}"] = np.asarray(e)
        else:
            plain[k] = _plain(v)
    return arrays, plain


def store(key: str, table) -> None:
    """Write ``table`` under ``key`` (atomically; failures to write only warn)."""
    arrays = {n: np.asarray(getattr(table, n), dtype=np.float64) for n in _ARRAYS}
    info_arrays, info_plain = _split_info(table.info)
    meta = {"key": key, "checksum": _checksum(arrays), "model": table.model, "race": table.race,
            "psi_min": repr(table.psi_min), "psi_max": repr(table.psi_max),
            "track_radius": repr(table.track_radius), "info": info_plain}
    path = entry_path(key, table.model)
    try:
        with atomic_path(path) as tmp:
            with open(tmp, "wb") as fh:
                np.savez(fh, meta=np.array(json.dumps(meta)), **arrays, **info_arrays)
    except OSError as exc:
        warnings.warn(f"contact-table cache: cannot write {path} ({exc}); the table is used "
                      "without being cached", TableCacheWarning, stacklevel=3)


def _problem(meta: dict, arrays: dict, key: str) -> str | None:
    """Why an entry cannot be used, or None."""
    if meta.get("key") != key:
        return "its key does not match the file name"
    n_psi, n_delta = arrays["psi"].shape[0], arrays["delta"].shape[0]
    if arrays["psi"].ndim != 1 or arrays["delta"].ndim != 1 or n_psi < 2 or n_delta < 2:
        return "its psi/delta axes are malformed"
    if arrays["G"].shape != (n_psi, n_delta) or arrays["intact_fraction"].shape != (n_psi, n_delta):
        return f"G has shape {arrays['G'].shape}, expected {(n_psi, n_delta)}"
    if arrays["drop"].shape != (n_psi,):
        return "its drop profile has the wrong length"
    for n in _ARRAYS:
        if not np.all(np.isfinite(arrays[n])):
            return f"{n} holds NaN or Inf"
    if _checksum(arrays) != meta.get("checksum"):
        return "its checksum does not match its content"
    return None


def load(key: str, model: str | None = None):
    """The cached table's fields for ``key`` (keyword arguments of :class:`.contact.ContactTable`), or None
    (missing, or damaged: then warned)."""
    if model is None:
        candidates = sorted(cache_dir("tables").glob(f"*-{key[:40]}.npz"))
        if not candidates:
            return None
        path = candidates[0]
    else:
        path = entry_path(key, model)
        if not path.is_file():
            return None
    try:
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"]))
            arrays = {n: z[n] for n in _ARRAYS}
            extra = {k[6:]: z[k] for k in z.files if k.startswith("info__")}
        reason = _problem(meta, arrays, key)
    except Exception as exc:        # any unreadable file is a damaged entry
        reason = f"it cannot be read ({type(exc).__name__}: {exc})"
    if reason is not None:
        warnings.warn(f"contact-table cache entry {path} is damaged ({reason}); rebuilding it",
                      TableCacheWarning, stacklevel=3)
        return None
    info = dict(meta["info"])
    tuples: dict = {}
    for k, v in extra.items():
        if "__" in k:
            name, i = k.rsplit("__", 1)
            tuples.setdefault(name, {})[int(i)] = v
        else:
            info[k] = v
    for name, parts in tuples.items():
        info[name] = tuple(parts[i] for i in sorted(parts))
    info["source"] = "disk"
    return dict(psi=arrays["psi"], delta=arrays["delta"], G=arrays["G"], drop=arrays["drop"],
                intact_fraction=arrays["intact_fraction"], model=meta["model"], race=meta["race"],
                psi_min=float(meta["psi_min"]), psi_max=float(meta["psi_max"]),
                track_radius=float(meta["track_radius"]), info=info)
