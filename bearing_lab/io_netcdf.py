"""Lossless, compressed netCDF4 writing shared by simulations, recordings and reports."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .errors import BearingLabError


def write_netcdf(ds, path, *, complevel: int = 4, error=BearingLabError) -> Path:
    """Write ``ds`` to netCDF4 (zlib + shuffle); reading it back is bit-for-bit equal.

    Floats keep their dtype and get no fill value (a NaN-free Dataset stays NaN-free);
    attributes netCDF cannot store (bools, lists, None) are written as ints / "; "-joined
    strings / "".  A failure raises ``error`` naming the path.
    """
    path = Path(path)
    enc = {}
    for name, var in ds.variables.items():
        if var.dtype.kind in "iufc":
            enc[name] = {"zlib": True, "complevel": int(complevel), "shuffle": True}
            if var.dtype.kind in "fc":
                enc[name]["_FillValue"] = None
    attrs = {}
    for k, v in ds.attrs.items():
        if isinstance(v, (bool, np.bool_)):
            v = int(v)
        elif isinstance(v, (list, tuple)):
            v = "; ".join(map(str, v))
        elif v is None:
            v = ""
        attrs[k] = v
    out = ds.copy()
    out.attrs = attrs
    try:
        out.to_netcdf(path, engine="netcdf4", format="NETCDF4", encoding=enc)
    except (OSError, ValueError, TypeError, RuntimeError) as exc:
        raise error(f"{path}: cannot write netCDF4 ({type(exc).__name__}: {exc})") from exc
    return path


def check_output_path(text: str) -> Path:
    """The CLI's ``-o OUT.nc``: refuse a non-.nc name or a missing directory before any work."""
    out = Path(text)
    if out.suffix not in (".nc", ".nc4"):
        raise BearingLabError(f"-o {text}: the output must be a netCDF file ending in .nc")
    if not out.parent.exists():
        raise BearingLabError(f"-o {text}: directory {out.parent} does not exist")
    return out
