"""Lossless, compressed netCDF4 writing shared by simulations, recordings and reports."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .errors import BearingLabError


def write_netcdf(ds, path) -> Path:
    """Write ``ds`` to netCDF4 with zlib compression (lossless: float64 kept as float64)."""
    path = Path(path)
    enc = {}
    for name, var in ds.variables.items():
        if var.dtype.kind in "fiu" and var.ndim >= 1:
            enc[name] = {"zlib": True, "complevel": 4}
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
    except (OSError, ValueError, RuntimeError) as exc:
        raise BearingLabError(f"cannot write {path}: {exc}") from None
    return path
