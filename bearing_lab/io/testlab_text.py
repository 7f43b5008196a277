"""Simcenter/LMS Testlab text export: ``key<TAB>value`` header, names, units and format rows, numbers.

No official specification was found, so the reader is lenient and fails clearly:
UTF-8 or latin-1; decimal comma or point; the header's key/value lines go into
attributes (``testlab_<key>``); the last rows before the numbers whose column
count matches the data are the channel names, the units (recognised through
:mod:`bearing_lab.units`) and an optional format row (``Real``, ``float`` ...).
The time base is, in order: ``fs=``; a first column whose unit is a time unit
(must be uniform); header keys such as ``Increment``/``dt``/``Sampling
frequency`` with ``Start``; else the file is refused with a request for ``fs=``.
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ._base import ENGINES, RecordingBuilder, RecordingReader, clean_name
from ._text import (column_rate, decode, first_non_increasing, is_number, is_uniform, known_unit,
                    looks_binary, parse_table, read_text)

_INC_KEYS = ("increment", "x increment", "delta t", "dt", "time increment", "abscissa increment",
             "sampling interval")
_FS_KEYS = ("sampling frequency", "sample rate", "sampling rate", "fs", "bandwidth sampling rate")
_START_KEYS = ("start", "x start", "start time", "abscissa start", "x_start", "start value")
_FORMAT_WORDS = {"real", "float", "double", "complex", "single", "integer", "int", "%f", "%g", "%e"}


def _kv(lines):
    out = 0
    for ln in lines:
        f = ln.split("\t")
        if len(f) == 2 and f[0].strip() and not is_number(f[0]):
            out += 1
    return out


class TestlabTextReader(RecordingReader):
    """Read Testlab text (tab-separated) exports of time signals."""

    name = "testlab_text"
    description = "Simcenter/LMS Testlab text export (tab-separated key/value header, units row)"
    extensions = (".txt", ".tsv")
    libraries = ("numpy",)

    def guess_can_open(self, path, head):
        if looks_binary(head):
            return False
        text, _ = decode(head)
        lines = [ln for ln in text.splitlines()[:40] if ln.strip()]
        return len(lines) >= 4 and "\t" in lines[0] and _kv(lines[:3]) >= 3

    def open_dataset(self, path, *, channels=None, units=None, sensitivity=None, fs=None,
                     checksum=True):
        """Read a Testlab text export.

        Parameters
        ----------
        path : str or Path
        channels : str or list of str, optional
        units : str or dict, optional
            Unit label(s) replacing or supplying the units row.
        sensitivity : str, dict or False, optional
            For voltage channels.
        fs : float, optional
            Sampling rate, Hz (replaces the file's time base).
        checksum : bool

        Returns
        -------
        xarray.Dataset
        """
        path = Path(path)
        b = RecordingBuilder(path, self, units=units, sensitivity=sensitivity, checksum=checksum)
        _, text, enc = read_text(path, b.fail, "not a Testlab text export")
        start, data_rows, meta, table = _split(text.splitlines(), b)
        ncol = len(data_rows[0])
        decimal_comma = any("," in c for c in data_rows[0]) and not any(
            "." in c for c in data_rows[0])
        vals = parse_table(data_rows, start + 1, b.fail, decimal_comma)
        names, unit_row = _names_and_units(table, ncol)
        rate, start_t, tcol = _time_base(b, vals, names, unit_row, meta, fs)
        for j in range(ncol):
            if j == tcol:
                continue
            nm = clean_name(names[j] if j < len(names) else "", f"ch{j + 1}")
            b.add_channel(nm, vals[:, j], unit_row[j], file_name=names[j] if j < len(names) else nm)
        for k, v in list(meta.items())[:40]:
            b.attrs["testlab_" + re.sub(r"\W+", "_", k).strip("_")[:40]] = v
        b.attrs["text_encoding"] = enc
        if decimal_comma:
            b.attrs["decimal_comma"] = 1
        return b.build(fs=rate, t0=start_t, channels=channels)


def _split(lines, b):
    """(index of the first numeric line, the data rows' cells, the header's key -> value, the
    rows right above the numbers with as many fields as the data: names, units, format)."""
    start = None
    for i, ln in enumerate(lines):
        f = [c for c in ln.split("\t")]
        if ln.strip() and all(is_number(c) for c in f if c.strip()) and \
                sum(1 for c in f if c.strip()) >= 1 and i > 0:
            start = i
            break
    if start is None:
        b.fail("no numeric data rows after the header")
    data_rows = [ln.split("\t") for ln in lines[start:] if ln.strip()]
    ncol = len(data_rows[0])
    while ncol > 1 and all(not r[-1].strip() for r in data_rows[:5]):
        data_rows = [r[:-1] if len(r) == ncol else r for r in data_rows]
        ncol -= 1
    hdr = []
    for ln in lines[:start]:
        f = [c.strip() for c in ln.split("\t")]
        while f and not f[-1]:
            f.pop()
        if f:
            hdr.append(f)
    k, table = len(hdr), []
    while k > 0 and len(hdr[k - 1]) == ncol and len(table) < 3:
        table.insert(0, hdr[k - 1])
        k -= 1
    meta = {}
    for f in hdr[:k]:
        meta[f[0].rstrip(":").lower()] = "\t".join(f[1:])
    return start, data_rows, meta, table


def _names_and_units(table, ncol):
    """The names row and the units row among the rows above the numbers (a format row skipped)."""
    names, unit_row = None, None
    for row in table:
        low = {c.lower() for c in row if c}
        if low and low <= _FORMAT_WORDS:
            continue
        known = sum(1 for c in row if known_unit(c) is not None)
        if known >= max(1, (ncol + 1) // 2) and unit_row is None:
            unit_row = row
        elif names is None:
            names = row
    if names is None:
        names = [f"ch{j + 1}" for j in range(ncol)]
    if unit_row is None:
        unit_row = [""] * ncol
    return names, unit_row


def _meta_float(meta, keys):
    for k in keys:
        if k in meta:
            m = re.search(r"[-+]?\d+(?:[.,]\d*)?(?:[eE][-+]?\d+)?", meta[k])
            if m:
                return float(m.group(0).replace(",", "."))
    return None


def _time_base(b, vals, names, unit_row, meta, fs):
    """(rate, start time, index of the time column or None), in order: ``fs``; a uniform time
    column; the header's increment or sampling frequency."""
    t = None
    tcol = None
    u0 = known_unit(unit_row[0])
    if (u0 is not None and u0.quantity == "time") or names[0].lower() in ("time", "x", "t"):
        tcol = 0
        t = vals[:, 0] * (u0.factor if u0 is not None else 1.0)
    inc, mfs, t0 = _meta_float(meta, _INC_KEYS), _meta_float(meta, _FS_KEYS), _meta_float(meta, _START_KEYS)
    if fs is not None:
        return float(fs), (t[0] if t is not None else (t0 or 0.0)), tcol
    if t is not None:
        if first_non_increasing(t) is not None:
            b.fail("the time column is not strictly increasing; repair it or pass fs=")
        dt = np.diff(t)
        if not is_uniform(dt):
            b.fail(f"the time column is not uniformly sampled (steps from {dt.min():.6g} to "
                   f"{dt.max():.6g} s); pass fs=<Hz> to use the nominal rate")
        rate = 1.0 / inc if inc else column_rate(t)
        return rate, float(t[0]), tcol
    if inc or mfs:
        return (1.0 / inc if inc else mfs), t0 or 0.0, tcol
    b.fail("no time column and no increment/sampling frequency in the header; pass "
           "fs=<Hz>")


ENGINES["testlab_text"] = TestlabTextReader
