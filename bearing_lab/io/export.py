"""Writers: netCDF4 (lossless, atomic, checksummed) and UFF 58b (back into Testlab and friends).

Why one netCDF writer (:func:`to_netcdf`, for recordings, simulations, reports and the sweep
cache): every ``.nc`` bearing_lab writes must survive a failure, a kill or a second process
writing the same name (the file is written beside the target and renamed over it in one step,
:func:`bearing_lab.utils._files.atomic_path`), must carry checksums (HDF5's Fletcher-32 on every
numeric chunk, so a damaged chunk cannot be read as data), and must read back bit for bit.

Why a hand-written 58b writer: ``pyuff.UFF.write_sets(binary=1)`` packs one value
per ``struct.pack`` call and its ``mode='overwrite'`` leaves a 7-byte file; ours
writes the same header layout (the field widths of pyuff's ``_write58``) and the
payload with one ``tobytes``.  The tests read every export back with pyuff and
with our reader.  Values are written as float64 little-endian, in SI (or in the
channel's original unit with ``units="original"``), one set per channel, after
a dataset 164 that declares SI units.
"""
from __future__ import annotations

import errno
import os
from datetime import datetime
from pathlib import Path
import shutil

import numpy as np

from .. import units as _units
from ..errors import RecordingError, check_choice
from ..utils._files import atomic_open, atomic_path, sha256_file

# quantity -> (UFF specific data type, length exponent, force exponent)
_SPEC = {"acceleration": (12, 1, 0), "velocity": (11, 1, 0), "displacement": (8, 1, 0),
         "pressure": (15, -2, 1), "force": (13, 0, 1), "voltage": (1, 0, 0)}
_DIR_CODES = {"+X": 1, "+Y": 2, "+Z": 3, "-X": -1, "-Y": -2, "-Z": -3}


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


def to_netcdf(ds, path, *, complevel: int = 4, checksum_file: bool = False, error=RecordingError) -> Path:
    """Write a Dataset to netCDF4 (zlib + shuffle + Fletcher-32), atomically; reading it back is
    bit-for-bit equal.

    Floats keep their dtype and get no fill value (a NaN-free Dataset stays NaN-free);
    attributes netCDF cannot store (bools, lists, None, undecodable file names) are
    written as ints / "; "-joined strings / "" / repaired text.  The target is replaced
    only once the new file is complete and on disk; a failure leaves an existing file
    untouched and raises ``error`` naming the path.

    Parameters
    ----------
    ds : xarray.Dataset
        A recording, simulation or result Dataset.
    path : str or Path
        Output file (``.nc``).
    complevel : int
        zlib level 1..9; 0 writes the values uncompressed (still with Fletcher-32).
    checksum_file : bool
        Also write ``<path>.sha256`` (``sha256sum -c`` format, the digest of the bytes written)
        once the file is in place.
    error : exception class
        Raised when the file cannot be written (a :class:`~bearing_lab.errors.BearingLabError`).

    Returns
    -------
    Path

    See Also
    --------
    to_uff58b, open_recording

    Examples
    --------
    >>> to_netcdf(ds, "out.nc")   # doctest: +SKIP
    >>> xr.load_dataset("out.nc").identical(ds)   # doctest: +SKIP
    True
    """
    from .. import _xarray  # noqa: F401  (xarray writes without dask; `info` imports this module)
    path = Path(path)
    enc = {}
    for name, var in ds.variables.items():
        if var.dtype.kind in "iufc":
            enc[name] = {"fletcher32": True}
            if complevel:
                enc[name].update(zlib=True, complevel=int(complevel), shuffle=True)
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
            digest = sha256_file(tmp) if checksum_file else None
        if checksum_file:
            with atomic_open(checksum_path(path), "w") as fh:
                fh.write(f"{digest}  {path.name}\n")
    except (OSError, ValueError, TypeError, RuntimeError, UnicodeError) as exc:
        raise error(f"{path}: cannot write netCDF4 ({_write_failure(path, exc, out)}); an existing "
                    "file of that name is left as it was") from exc
    return path


def checksum_path(path) -> Path:
    """The checksum file :func:`to_netcdf` writes beside ``path`` with ``checksum_file=True``."""
    path = Path(path)
    return path.with_name(path.name + ".sha256")


def _write_failure(path: Path, exc, ds) -> str:
    """The true cause of a failed write.  netCDF-C/HDF5 report a full disk as "HDF error" or
    as "Permission denied"; the free space and the directory's permissions tell them apart."""
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


def _label_for(si: str, quantity: str) -> str:
    return _units.UFF_LABELS.get(si, si)


def to_uff58b(ds, path, *, channels=None, units: str = "si", id1=None, id2=None, id4=None,
              byte_order: str = "little"):
    """Write channels of a Dataset as UFF dataset 58b (binary, float64), one set per channel.

    Parameters
    ----------
    ds : xarray.Dataset
        Recording or simulation Dataset (uniform ``time`` coordinate).
    path : str or Path
        Output ``.uff`` file (replaced atomically: complete or not at all).
    channels : list of str, optional
        Variables to write (default: every variable with dimension ``time`` only).
    units : "si" or "original"
        Write SI values (label ``m/s2`` ...) or convert back to each channel's
        ``original_units`` (e.g. ``g``) where that unit is known.
    id1, id2, id4 : str, optional
        Free-text header records (default: channel description, source, reader).
    byte_order : "little" or "big"

    Returns
    -------
    Path

    See Also
    --------
    to_netcdf, open_recording

    Notes
    -----
    Node and direction come from the variable attributes ``uff_rsp_node`` and
    ``uff_rsp_dir`` when present (a round trip of a UFF import keeps them), else
    node = channel index + 1 and direction 0 (scalar); the channel name goes into
    the response entity name (10 characters) and ``id1``.
    """
    path = Path(path)
    t, dt, channels = _uff_time_and_channels(ds, path, channels)
    check_choice(units, ("si", "original"), f"{path}: units", RecordingError)
    bo_code, bo_char = (1, "<") if byte_order == "little" else (2, ">")
    date = datetime.now().strftime("%d-%b-%y %H:%M:%S")
    src = Path(str(ds.attrs.get("source_file", ""))).name or "bearing_lab"
    out = []
    out.append(b"%6i\n%6i%74s\n" % (-1, 164, b" "))
    out.append(b"%10i%20s%10i\n" % (1, b"SI - mks (Newton)".rjust(20), 2))
    out.append(b"%25.16e%25.16e%25.16e\n%25.16e\n" % (1.0, 1.0, 1.0, 273.15))
    out.append(b"%6i\n" % -1)
    for k, name in enumerate(channels):
        var = ds[name]
        y, label, quantity = _uff_values(path, name, var, units)
        i1 = (id1 if id1 is not None else str(var.attrs.get("id1", name)))[:80]
        i2 = (id2 if id2 is not None else f"bearing_lab {ds.attrs.get('bearing_lab_version', '')} "
              f"from {src}")[:80]
        i4 = (id4 if id4 is not None else str(ds.attrs.get("reader", "simulation")))[:80]
        out.extend(_uff58b_set(name, k, var.attrs, y, label, quantity, (i1, i2, date, i4), float(t[0]), dt,
                               bo_code, bo_char))
    try:
        with atomic_open(path, "wb") as fh:  # an existing file survives any failure
            for chunk in out:
                fh.write(chunk)
    except OSError as exc:
        raise RecordingError(f"{path}: cannot write ({exc.strerror or exc}); an existing file of "
                             "that name is left as it was") from exc
    return path


def _uff_time_and_channels(ds, path, channels):
    """(time values, increment s, channel names) of a UFF 58b export, checked: an even time
    base of at least 2 samples and named variables of the Dataset."""
    if "time" not in ds.coords:
        raise RecordingError(f"{path}: the Dataset has no 'time' coordinate to export")
    t = np.asarray(ds["time"].values, dtype=np.float64)
    if t.size < 2:
        raise RecordingError(f"{path}: need at least 2 samples to export, got {t.size}")
    fs = float(ds.attrs.get("sampling_rate_hz", 1.0 / np.median(np.diff(t))))
    dt = 1.0 / fs
    if not np.allclose(np.diff(t), dt, rtol=1e-6, atol=0):
        raise RecordingError(f"{path}: the time base is uneven; UFF 58b export writes even "
                             "abscissa only: resample first")
    if channels is None:
        channels = [n for n, v in ds.data_vars.items() if v.dims == ("time",)]
    elif isinstance(channels, str):
        channels = [channels]
    missing = [c for c in channels if c not in ds.data_vars]
    if missing:
        raise RecordingError(f"{path}: no variable {missing[0]!r} in the Dataset; it has "
                             f"{', '.join(ds.data_vars)}")
    if not channels:
        raise RecordingError(f"{path}: no time-series variables to export")
    return t, dt, channels


def _uff_values(path, name, var, units):
    """(values, unit label, quantity) of one exported variable: SI, or its original unit."""
    if var.dims != ("time",):
        raise RecordingError(f"{path}: variable {name!r} has dims {var.dims}; only (time,) "
                             "variables can be exported")
    y = np.asarray(var.values, dtype=np.float64)
    if not np.all(np.isfinite(y)):
        raise RecordingError(f"{path}: variable {name!r} holds NaN/Inf; UFF cannot carry them")
    si = str(var.attrs.get("units", "1"))
    quantity = str(var.attrs.get("quantity", "")) or {"m s-2": "acceleration", "m": "displacement",
                                                      "Pa": "pressure", "N": "force",
                                                      "V": "voltage"}.get(si, "")
    label = _label_for(si, quantity)
    if units == "original" and var.attrs.get("original_units"):
        try:
            u = _units.lookup_unit(var.attrs["original_units"])
            if u.si == si and (u.factor != 1.0 or u.offset != 0.0):
                y = (y - u.offset) / u.factor
                label = u.label
        except RecordingError:
            pass
    return y, label, quantity


def _uff58b_set(name, k, attrs, y, label, quantity, ids, t0, dt, bo_code, bo_char):
    """The byte chunks of one dataset 58b: delimiter, binary header line, the 11 header records
    (``ids``: records 1-4), the float64 payload and the closing delimiter."""
    spec, lexp, fexp = _SPEC.get(quantity, (1, 0, 0))
    node = int(attrs.get("uff_rsp_node", k + 1))
    rdir = int(attrs.get("uff_rsp_dir", 0))
    ent = str(attrs.get("rsp_ent_name", name))[:10]
    n = y.size
    nbytes = n * 8
    head = [
        b"%6i\n" % -1,
        b"%6i%c%6i%6i%12i%12i%6i%6i%12i%12i\n" % (58, ord("b"), bo_code, 2, 11, nbytes,
                                                0, 0, 0, 0),
    ]
    text = [
        *("%-80s\n" % i for i in ids), "%-80s\n" % "NONE",
        "%5i%10i%5i%10i %10s%10i%4i %10s%10i%4i\n" % (1, 0, 0, 0, ent, node, rdir, "NONE", 0, 0),
        "%10i%10i%10i%13.5e%13.5e%13.5e\n" % (4, n, 1, t0, dt, 0.0),
        "%10i%5i%5i%5i %-20s %-20s\n" % (17, 0, 0, 0, "Time", "s"),
        "%10i%5i%5i%5i %-20s %-20s\n" % (spec, lexp, fexp, 0, (quantity or name)[:20],
                                        label[:20]),
        "%10i%5i%5i%5i %-20s %-20s\n" % (0, 0, 0, 0, "NONE", "NONE"),
        "%10i%5i%5i%5i %-20s %-20s\n" % (0, 0, 0, 0, "NONE", "NONE"),
    ]
    return [*head, "".join(text).encode("utf-8"), y.astype(bo_char + "f8").tobytes(), b"%6i\n" % -1]
