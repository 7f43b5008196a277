"""Writers: compressed netCDF4 (lossless) and UFF 58b (back into Testlab and friends).

Why a hand-written 58b writer: ``pyuff.UFF.write_sets(binary=1)`` packs one value
per ``struct.pack`` call and its ``mode='overwrite'`` leaves a 7-byte file; ours
writes the same header layout (the field widths of pyuff's ``_write58``) and the
payload with one ``tobytes``.  The tests read every export back with pyuff and
with our reader.  Values are written as float64 little-endian, in SI (or in the
channel's original unit with ``units="original"``), one set per channel, after
a dataset 164 that declares SI units.
"""
from __future__ import annotations

from datetime import datetime
from pathlib import Path

import numpy as np

from ..errors import RecordingError, check_choice
from .. import units as _units

# quantity -> (UFF specific data type, length exponent, force exponent)
_SPEC = {"acceleration": (12, 1, 0), "velocity": (11, 1, 0), "displacement": (8, 1, 0),
         "pressure": (15, -2, 1), "force": (13, 0, 1), "voltage": (1, 0, 0)}
_DIR_CODES = {"+X": 1, "+Y": 2, "+Z": 3, "-X": -1, "-Y": -2, "-Z": -3}


def to_netcdf(ds, path, *, complevel: int = 4):
    """Write a Dataset to netCDF4 with zlib compression; reading it back is bit-for-bit equal.

    Parameters
    ----------
    ds : xarray.Dataset
        A recording or simulation Dataset.
    path : str or Path
        Output file (``.nc``).
    complevel : int
        zlib level 1..9.

    Returns
    -------
    Path

    Examples
    --------
    >>> to_netcdf(ds, "out.nc")   # doctest: +SKIP
    >>> xr.load_dataset("out.nc").identical(ds)   # doctest: +SKIP
    True
    """
    from ..io_netcdf import write_netcdf
    return write_netcdf(ds, path, complevel=complevel, error=RecordingError)


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

    Notes
    -----
    Node and direction come from the variable attributes ``uff_rsp_node`` and
    ``uff_rsp_dir`` when present (a round trip of a UFF import keeps them), else
    node = channel index + 1 and direction 0 (scalar); the channel name goes into
    the response entity name (10 characters) and ``id1``.
    """
    path = Path(path)
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
        spec, lexp, fexp = _SPEC.get(quantity, (1, 0, 0))
        node = int(var.attrs.get("uff_rsp_node", k + 1))
        rdir = int(var.attrs.get("uff_rsp_dir", 0))
        ent = str(var.attrs.get("rsp_ent_name", name))[:10]
        i1 = (id1 if id1 is not None else str(var.attrs.get("id1", name)))[:80]
        i2 = (id2 if id2 is not None else f"bearing_lab {ds.attrs.get('bearing_lab_version', '')} "
              f"from {src}")[:80]
        i4 = (id4 if id4 is not None else str(ds.attrs.get("reader", "simulation")))[:80]
        n = y.size
        nbytes = n * 8
        head = [
            b"%6i\n" % -1,
            b"%6i%c%6i%6i%12i%12i%6i%6i%12i%12i\n" % (58, ord("b"), bo_code, 2, 11, nbytes,
                                                    0, 0, 0, 0),
        ]
        text = [
            "%-80s\n" % i1, "%-80s\n" % i2, "%-80s\n" % date, "%-80s\n" % i4, "%-80s\n" % "NONE",
            "%5i%10i%5i%10i %10s%10i%4i %10s%10i%4i\n" % (1, 0, 0, 0, ent, node, rdir, "NONE", 0, 0),
            "%10i%10i%10i%13.5e%13.5e%13.5e\n" % (4, n, 1, float(t[0]), dt, 0.0),
            "%10i%5i%5i%5i %-20s %-20s\n" % (17, 0, 0, 0, "Time", "s"),
            "%10i%5i%5i%5i %-20s %-20s\n" % (spec, lexp, fexp, 0, (quantity or name)[:20],
                                            label[:20]),
            "%10i%5i%5i%5i %-20s %-20s\n" % (0, 0, 0, 0, "NONE", "NONE"),
            "%10i%5i%5i%5i %-20s %-20s\n" % (0, 0, 0, 0, "NONE", "NONE"),
        ]
        out.extend(head)
        out.append("".join(text).encode("utf-8"))
        out.append(y.astype(bo_char + "f8").tobytes())
        out.append(b"%6i\n" % -1)
    from ..utils._files import atomic_open
    try:
        with atomic_open(path, "wb") as fh:  # an existing file survives any failure
            for chunk in out:
                fh.write(chunk)
    except OSError as exc:
        raise RecordingError(f"{path}: cannot write ({exc.strerror or exc}); an existing file of "
                             "that name is left as it was") from exc
    return path
