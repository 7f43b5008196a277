"""bearing_lab's own netCDF4 output read back (``bearing-lab info OUT.nc``, ``analyze OUT.nc``).

Why: the contract lets every command take a recording *or* a ``.nc`` written by
:func:`bearing_lab.io.to_netcdf` (or by the simulator); this reader loads it
eagerly, unchanged, and checks it:

- netCDF-C runs in a guarded child process (:mod:`._guard`): on some damaged files
  it loops for ever or crashes, and that must not take the caller with it;
- the writer stores floats without a fill value and with HDF5's Fletcher-32 chunk
  checksums, so a damaged chunk fails to read, and a value equal to netCDF's
  default fill value (9.97e36) means a chunk was never written (an interrupted
  writer of another program): such a file is refused, never read as valid;
- non-finite values are refused as in every reader;
- recordings are checked against the recording contract, simulation outputs
  against the common one (``time`` and ``sampling_rate_hz``).
"""
from __future__ import annotations

import os
from pathlib import Path
import tempfile

import numpy as np

from ..errors import BearingLabError, RecordingError
from ._base import ENGINES, MAX_RATE_HZ, MIN_RATE_HZ, RecordingReader, speed_problem

NC_FILL_DOUBLE = 9.969209968386869e36   # netCDF's default _FillValue for doubles
NC_FILL_FLOAT = np.float32(9.96921e36)


def _load(path: str):
    """Read the whole file (runs in the guarded child)."""
    import xarray as xr  # loads when it reads (every reader is imported to sniff)
    try:
        path.encode("utf-8")
    except UnicodeEncodeError:  # a name in another locale's bytes: netCDF-C takes UTF-8 names
        return _load_through_link(path)
    try:
        return xr.load_dataset(path, engine="netcdf4")
    except (OSError, ValueError, RuntimeError, KeyError, IndexError, TypeError, AttributeError,
            UnicodeDecodeError) as exc:
        raise RecordingError(f"{path}: not a readable netCDF4 file ({type(exc).__name__}: "
                             f"{exc})") from None


def _load_through_link(path: str):
    """Read a file whose name is not UTF-8 through a symbolic link with a plain name."""
    with tempfile.TemporaryDirectory(prefix="bearing_lab_nc_") as d:
        link = os.path.join(d, "file.nc")
        os.symlink(os.path.abspath(path), link)
        try:
            return _load(link)
        except RecordingError as exc:
            raise RecordingError(str(exc).replace(link, path)) from None


def _check_values(ds, path):
    for name, var in ds.variables.items():
        if var.dtype.kind != "f":
            continue
        x = np.asarray(var.values)
        fill = NC_FILL_FLOAT if x.dtype == np.float32 else NC_FILL_DOUBLE
        n_fill = int(np.count_nonzero(x == fill))
        if n_fill:
            raise RecordingError(f"{path}: variable {name!r} holds {n_fill} netCDF fill values "
                                 f"({float(fill):.4g}) where data should be: the file was not "
                                 "completely written; write it again")
        bad = ~np.isfinite(x)
        if bad.any():
            raise RecordingError(f"{path}: variable {name!r} holds {int(bad.sum())} NaN/Inf "
                                 "values: damaged or not a bearing_lab file")


def _check_attrs(ds, path):
    """The rate must be a number that matches the time axis, a stored speed a plausible one."""
    if "sampling_rate_hz" in ds.attrs:
        fs = ds.attrs["sampling_rate_hz"]
        if isinstance(fs, (str, bytes)) or np.ndim(fs) != 0 or np.iscomplexobj(fs):
            raise RecordingError(f"{path}: attribute sampling_rate_hz is {fs!r}, not a number of Hz: "
                                 "damaged or not a bearing_lab file")
        fs = float(fs)
        if not MIN_RATE_HZ <= fs <= MAX_RATE_HZ:  # also NaN
            raise RecordingError(f"{path}: attribute sampling_rate_hz = {fs!r} Hz is not a rate of a "
                                 "vibration recording: damaged or not a bearing_lab file")
        if "time" in ds.coords and ds.sizes.get("time", 0) > 1:
            t = np.asarray(ds["time"].values, dtype=np.float64)
            axis = 1.0 / float(np.median(np.diff(t))) if np.all(np.diff(t) > 0) else float("nan")
            if not abs(axis / fs - 1.0) <= 1e-6:
                raise RecordingError(f"{path}: attribute sampling_rate_hz = {fs:.9g} Hz disagrees with "
                                     f"the time coordinate ({axis:.9g} Hz): damaged or edited file")
    if "shaft_speed_rpm" in ds.attrs:
        rpm = ds.attrs["shaft_speed_rpm"]
        problem = "is not a number" if isinstance(rpm, (str, bytes)) or np.ndim(rpm) != 0 \
            else speed_problem(rpm)
        if problem is not None:
            shown = rpm if isinstance(rpm, (str, bytes)) or np.ndim(rpm) != 0 else float(rpm)
            raise RecordingError(f"{path}: attribute shaft_speed_rpm = {shown!r} {problem}: damaged or "
                                 "edited file")


class NetcdfReader(RecordingReader):
    """Read a bearing_lab netCDF4 file (recording or simulation)."""

    name = "netcdf"
    description = "bearing_lab netCDF4 (.nc) written by to_netcdf or the simulator"
    extensions = (".nc",)
    libraries = ("xarray", "netCDF4")

    def guess_can_open(self, path, head):
        return head.startswith(b"\x89HDF\r\n\x1a\n") or head[:3] == b"CDF"

    def open_dataset(self, path, *, channels=None):
        """Load the Dataset; ``channels`` keeps a subset of the variables.

        Returns
        -------
        xarray.Dataset
        """
        from .. import schema  # schema (6 ms) when a Dataset is made: `info` reads plain arrays
        from ._guard import guarded  # the child-process guard: io imports every reader to sniff
        path = Path(path)
        ds = guarded(path, "netCDF-C", _load, str(path))
        _check_values(ds, path)
        _check_attrs(ds, path)
        kind = "recording" if "reader" in ds.attrs else None
        try:
            schema.check_dataset(ds, kind=kind)
        except BearingLabError as exc:
            raise RecordingError(f"{path}: {exc}") from exc
        if channels is not None:
            wanted = [channels] if isinstance(channels, str) else list(channels)
            missing = [c for c in wanted if c not in ds.data_vars]
            if missing:
                raise RecordingError(f"{path}: no channel {missing[0]!r}; it has "
                                     f"{', '.join(ds.data_vars)}")
            ds = ds[wanted]
        return ds


ENGINES["netcdf"] = NetcdfReader
