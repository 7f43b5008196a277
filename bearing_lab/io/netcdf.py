"""bearing_lab's own netCDF4 output read back (``bearing-lab info OUT.nc``, ``analyze OUT.nc``).

Why: the contract lets every command take a recording *or* a ``.nc`` written by
:func:`bearing_lab.io.to_netcdf` (or by the simulator); this reader loads it
eagerly, unchanged, and only checks the contract.
"""
from __future__ import annotations

from pathlib import Path

from ..errors import BearingLabError
from ._base import ENGINES, RecordingReader


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
        import xarray as xr
        from .. import schema
        from ..errors import RecordingError

        path = Path(path)
        try:
            ds = xr.load_dataset(path, engine="netcdf4")
        except (OSError, ValueError) as exc:
            raise RecordingError(f"{path}: not a readable netCDF4 file ({exc})") from exc
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
