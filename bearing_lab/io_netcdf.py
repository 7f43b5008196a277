"""Lossless, compressed, atomic netCDF4 writing shared by simulations, recordings and reports.

Why one writer: every ``.nc`` bearing_lab writes must survive a failure, a kill or a
second process writing the same name (the file is written beside the target and
renamed over it in one step, :func:`bearing_lab.utils._files.atomic_path`), must carry
checksums (HDF5's Fletcher-32 on every numeric chunk, so a damaged chunk cannot be
read as data), and must read back bit for bit.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from . import _xarray  # noqa: F401  (xarray writes without importing dask)
from .utils._files import atomic_path
from .errors import BearingLabError


def _text(v: str) -> str:
    """A string netCDF can store: undecodable bytes of a file name become U+FFFD."""
    try:
        v.encode("utf-8")
        return v
    except UnicodeEncodeError:
        return v.encode("utf-8", "surrogateescape").decode("utf-8", "replace")


def _attr(v):
    if isinstance(v, (bool, np.bool_)):
        return int(v)
    if isinstance(v, (list, tuple)):
        return _text("; ".join(map(str, v)))
    if v is None:
        return ""
    if isinstance(v, str):
        return _text(v)
    return v


def write_netcdf(ds, path, *, complevel: int = 4, error=BearingLabError) -> Path:
    """Write ``ds`` to netCDF4 (zlib + shuffle + Fletcher-32), atomically.

    Floats keep their dtype and get no fill value (a NaN-free Dataset stays NaN-free);
    attributes netCDF cannot store (bools, lists, None, undecodable file names) are
    written as ints / "; "-joined strings / "" / repaired text.  The target is replaced
    only once the new file is complete and on disk; a failure leaves an existing file
    untouched and raises ``error`` naming the path.
    """
    path = Path(path)
    enc = {}
    for name, var in ds.variables.items():
        if var.dtype.kind in "iufc":
            enc[name] = {"zlib": True, "complevel": int(complevel), "shuffle": True,
                         "fletcher32": True}
            if var.dtype.kind in "fc":
                enc[name]["_FillValue"] = None
    out = ds.copy()
    out.attrs = {k: _attr(v) for k, v in ds.attrs.items()}
    for name in out.variables:
        out[name].attrs = {k: _attr(v) for k, v in out[name].attrs.items()}
    if path.is_dir():
        raise error(f"{path}: is a directory; give a file name ending in .nc")
    try:
        with atomic_path(path) as tmp:
            out.to_netcdf(tmp, engine="netcdf4", format="NETCDF4", encoding=enc)
    except (OSError, ValueError, TypeError, RuntimeError, UnicodeError) as exc:
        raise error(f"{path}: cannot write netCDF4 ({_write_failure(path, exc, out)}); an existing "
                    "file of that name is left as it was") from exc
    return path


def _write_failure(path: Path, exc, ds) -> str:
    """The true cause of a failed write.  netCDF-C/HDF5 report a full disk as "HDF error" or
    as "Permission denied"; the free space and the directory's permissions tell them apart."""
    import errno
    import shutil
    directory = path.parent if str(path.parent) else Path(".")
    needed = sum(int(v.nbytes) for v in ds.variables.values())
    try:
        free = shutil.disk_usage(directory).free
    except OSError:
        free = None
    full = getattr(exc, "errno", None) in (errno.ENOSPC, errno.EDQUOT)
    if full or (free is not None and free < needed):
        return (f"no space left on the device: {free / 1e6:.3g} MB free in {directory}, the data "
                f"take up to {needed / 1e6:.3g} MB" if free is not None else "no space left on the device")
    if isinstance(exc, PermissionError) and not os.access(directory, os.W_OK):
        return f"no permission to write in {directory}"
    return f"{type(exc).__name__}: {exc}"


def check_output_path(text: str, *, force: bool = False, suffixes=(".nc", ".nc4")) -> Path:
    """The CLI's ``-o FILE``: refuse a wrong suffix, a missing directory or (without ``force``) an
    existing file before any work."""
    out = Path(text)
    if out.suffix not in suffixes:
        what = "a netCDF file ending in .nc" if ".nc" in suffixes else "a file ending in " + " or ".join(suffixes)
        raise BearingLabError(f"-o {text}: the output must be {what}")
    if not out.parent.exists():
        raise BearingLabError(f"-o {text}: directory {out.parent} does not exist")
    size = len(os.fsencode(out.name))
    if size > 255:
        raise BearingLabError(f"-o {text}: the file name has {size} bytes; a file name has at most "
                              "255")
    if out.is_dir():
        raise BearingLabError(f"-o {text}: is a directory; give a file name ending in {suffixes[0]}")
    if out.exists() and not force:
        raise BearingLabError(f"-o {text}: exists; pass --force to overwrite it")
    return out
