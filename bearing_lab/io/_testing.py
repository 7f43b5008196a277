"""``check_reader``: the one test every reader passes (as MNE's ``_test_raw_reader``).

Why in the package: a new format module's test calls ``check_reader(path)``
and adds only what is specific to its format; living here, it is importable
from any test directory without path tricks.
"""
from __future__ import annotations

import lazy_loader as lazy
import numpy as np

from .. import schema
from . import get_warnings, guess_format, open_recording, to_netcdf

# loaded when a check runs (the fuzz workers import this module for its UFF writer)
netCDF4 = lazy.load("netCDF4")
xr = lazy.load("xarray")


def check_reader(path, *, format=None, tmp_path=None, **options):
    """Open ``path`` and check everything all readers promise; return the Dataset.

    Checks: the recording contract (``schema.check_dataset``), SI ``units`` on
    every channel, unique names, ``default_channel`` present, provenance
    attributes, sniffing finds the same reader as ``format``, a second open gives
    identical data (no state kept between calls), and, with ``tmp_path``, the
    netCDF4 round trip is bit-for-bit and the file is compressed.
    """

    ds = open_recording(path, format=format, **options)
    schema.check_dataset(ds, kind="recording")
    assert ds.attrs["reader"] == (format or guess_format(path))
    if format is not None:
        assert guess_format(path) == format, f"sniffing picked {guess_format(path)!r}"
    assert ds.attrs["default_channel"] in ds.data_vars
    assert len(set(ds.data_vars)) == len(ds.data_vars)
    assert ds["time"].attrs["units"] == "s"
    assert ds.attrs["sampling_rate_hz"] > 0
    for name, v in ds.data_vars.items():
        assert v.attrs["units"] in schema.SI_UNITS, (name, v.attrs["units"])
        assert v.dtype == np.float64
        assert "original_units" in v.attrs and "quantity" in v.attrs
    assert ds.attrs["source_file"].endswith(str(path).split("/")[-1])
    assert len(ds.attrs["source_sha256"]) in (0, 64)
    assert isinstance(ds.attrs["warnings"], str)
    assert isinstance(get_warnings(ds), list)
    t = ds["time"].values
    if "uneven_time" not in ds.attrs and t.size > 2:
        np.testing.assert_allclose(np.diff(t), 1.0 / ds.attrs["sampling_rate_hz"], rtol=1e-6)
    again = open_recording(path, format=format, **options)
    assert again.identical(ds)
    if tmp_path is not None:
        out = to_netcdf(ds, tmp_path / "roundtrip.nc")
        back = xr.load_dataset(out)
        assert back.identical(ds), "netCDF round trip is not bit-for-bit"
        with netCDF4.Dataset(out) as nc:
            for name in ds.data_vars:
                assert nc[name].filters()["zlib"], f"{name} not compressed"
    return ds


def uff58_block(values, *, binary=False, bo=1, double=True, num_pts=None, inc="1.00000E-03",
                t0="0.00000E+00", unit="m/s2", ent="acc", node=1, direction=3, spacing=1,
                x=None, func_type=1, nbytes=None, spec=12, abscissa_spec=17):
    """Return the bytes of one UFF 58/58b set (header widths as pyuff writes them)."""
    v = np.asarray(values, dtype=float)
    if spacing == 0:
        inter = np.empty(2 * v.size)
        inter[0::2], inter[1::2] = x, v
        payload = inter
    else:
        payload = v
    n = v.size if num_pts is None else num_pts
    odt = 4 if double else 2
    item = 8 if double else 4
    out = b"    -1\n"
    if binary:
        nb = payload.size * item if nbytes is None else nbytes
        out += b"    58b%6i%6i%12i%12i%6i%6i%12i%12i\n" % (bo, 2, 11, nb, 0, 0, 0, 0)
    else:
        out += b"    58\n"
    hdr = ("%-80s\n" % "test set" + "%-80s\n" % "NONE" + "%-80s\n" % "01-Jan-26 00:00:00"
           + "%-80s\n" % "NONE" + "%-80s\n" % "NONE"
           + "%5i%10i%5i%10i %10s%10i%4i %10s%10i%4i\n" % (func_type, 0, 0, 0, ent, node,
                                                          direction, "NONE", 0, 0)
           + "%10i%10i%10i%13s%13s%13s\n" % (odt, n, spacing, t0, inc, "0.00000E+00")
           + "%10i%5i%5i%5i %-20s %-20s\n" % (abscissa_spec, 0, 0, 0, "Time", "s")
           + "%10i%5i%5i%5i %-20s %-20s\n" % (spec, 1, 0, 0, "Acceleration", unit)
           + "%10i%5i%5i%5i %-20s %-20s\n" % (0, 0, 0, 0, "NONE", "NONE")
           + "%10i%5i%5i%5i %-20s %-20s\n" % (0, 0, 0, 0, "NONE", "NONE"))
    out += hdr.encode("utf-8")
    if binary:
        dt = ("<" if bo == 1 else ">") + ("f8" if double else "f4")
        out += payload.astype(dt).tobytes() + b"    -1\n"
    else:
        fmt, per = ("%20.11E", 4) if double else ("%13.5E", 6)
        lines = []
        for i in range(0, payload.size, per):
            lines.append("".join(fmt % val for val in payload[i:i + per]))
        out += ("\n".join(lines) + "\n").encode() + b"    -1\n"
    return out
