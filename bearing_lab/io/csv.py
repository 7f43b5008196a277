"""Generic CSV/TSV: a header row of names, an optional units row, a time column or a given rate.

Why strict about units and time: a CSV says nothing reliable about either, so
the unit of every channel must come from the file (a units row, or ``name
[unit]`` / ``name (unit)`` headers) or from ``units=``, and the rate from a
uniform time column or ``fs=``.  A non-uniform time column is refused unless
``allow_uneven=True`` keeps it as the time coordinate.  Delimiter (``,`` ``;``
tab or blanks) and decimal comma are detected.
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from .. import units as _units
from ..errors import RecordingError
from ._base import ENGINES, RecordingBuilder, RecordingReader, clean_name
from ._text import (column_rate, decode, first_non_increasing, is_number, is_uniform, known_unit,
                    looks_binary, parse_table, read_text)

_UNIT_IN_NAME = re.compile(r"^(.*?)\s*[\[(]\s*([^\])]+?)\s*[\])]\s*$")
_TIME_NAMES = {"time", "t", "zeit", "x", "time_s", "timestamp", "seconds", "sec", "s"}


def _split(line, delim):
    return line.split() if delim is None else line.split(delim)


def _delimiter(lines):
    """The delimiter most lines agree on (tab, semicolon, comma), else None (blanks)."""
    lines = [ln for ln in lines if ln.strip()]
    for d in ("\t", ";", ","):
        counts = [ln.count(d) for ln in lines]
        if not counts:
            continue
        mode = max(set(counts), key=counts.count)
        if mode > 0 and counts.count(mode) >= 0.9 * len(counts):
            return d
    return None


class CsvReader(RecordingReader):
    """Read delimited text (CSV, TSV, blank-separated)."""

    name = "csv"
    description = "CSV/TSV text: header of names, optional units row, time column or fs="
    extensions = (".csv", ".tsv", ".txt", ".dat")
    libraries = ("numpy",)

    def guess_can_open(self, path, head):
        if looks_binary(head):
            return False
        text, _ = decode(head)
        lines = [ln for ln in text.splitlines()[:20] if ln.strip()]
        if len(lines) < 2:
            return False
        d = _delimiter(lines[:-1] if len(lines) > 2 else lines)
        last = [c for c in _split(lines[-2], d) if c.strip()]
        return bool(last) and all(is_number(c) or is_number(c.replace(",", ".")) for c in last)

    def open_dataset(self, path, *, channels=None, units=None, sensitivity=None, fs=None,
                     time_column=None, allow_uneven=False, checksum=True):
        """Read a delimited text file.

        Parameters
        ----------
        path : str or Path
        channels : str or list of str, optional
        units : str or dict, optional
            Unit for every channel, or column name -> unit (required where the
            file has none).
        sensitivity : str, dict or False, optional
            For voltage channels.
        fs : float, optional
            Sampling rate, Hz; required when there is no time column (a time
            column is then ignored).
        time_column : str or int, optional
            Name or 0-based index of the time column (default: a column named
            time/t/zeit/x or with a time unit).
        allow_uneven : bool
            Keep a non-uniform time column as the time coordinate (warning).
        checksum : bool

        Returns
        -------
        xarray.Dataset
        """
        path = Path(path)
        b = RecordingBuilder(path, self, units=units, sensitivity=sensitivity, checksum=checksum)
        raw, text, enc = read_text(path, b.fail, "not a delimited text file (pass format= if you know it)")
        if not raw.endswith((b"\n", b"\r")):
            b.warn("the last line has no line break: if the file was cut short, its last row is "
                   "incomplete (a CSV declares no length, so this cannot be checked)")
        lines = [ln for ln in text.splitlines()]
        delim, header_rows, first = _header_and_first_row(lines, b)
        rows = [[c.strip().strip('"') for c in _split(ln, delim)] for ln in lines[first:] if ln.strip()]
        ncol = len(rows[0])
        decimal_comma = delim != "," and any("," in c for c in rows[0])
        vals = parse_table(rows, first + 1, b.fail, decimal_comma)
        names, col_units = _names_and_units(header_rows, ncol, b)
        tcol = _time_column(names, col_units, time_column, b)
        fs, t0, time = _time_base(b, vals, names, col_units, tcol, first, fs, allow_uneven)
        for j in range(ncol):
            if j == tcol:
                continue
            nm = clean_name(names[j], f"ch{j + 1}")
            b.add_channel(nm, vals[:, j], col_units[j] or None, file_name=names[j] or nm)
        b.attrs["text_encoding"] = enc
        b.attrs["csv_delimiter"] = {None: "blank", "\t": "tab"}.get(delim, delim)
        return b.build(fs=fs if time is None else None, t0=t0, time=time, channels=channels)


def _header_and_first_row(lines, b):
    """The delimiter, the header rows (cells) and the index of the first numeric line."""
    nonblank = [(i, ln) for i, ln in enumerate(lines) if ln.strip()]
    if not nonblank:
        b.fail("no text lines")
    delim = _delimiter([ln for _, ln in nonblank[:50]])
    header_rows = []
    first = None
    for i, ln in nonblank:
        cells = [c.strip().strip('"') for c in _split(ln, delim)]
        if all(is_number(c) or (delim != "," and is_number(c.replace(",", "."))) for c in cells
               if c) and any(cells):
            first = i
            break
        header_rows.append(cells)
        if len(header_rows) > 3:
            b.fail("more than 3 non-numeric lines before the data: not a plain CSV/TSV "
                   "(a header of names and an optional units row are understood)")
    if first is None:
        b.fail("no numeric data rows")
    return delim, header_rows, first


def _names_and_units(header_rows, ncol, b):
    """Column names and units: ``name [unit]`` / ``name (unit)`` headers, then a units row."""
    names = header_rows[0] if header_rows else [f"ch{j + 1}" for j in range(ncol)]
    if len(names) != ncol:
        b.fail(f"header has {len(names)} names for {ncol} data columns")
    col_units = [""] * ncol
    for j, nm in enumerate(names):
        m = _UNIT_IN_NAME.match(nm)
        if m:
            names[j], col_units[j] = m.group(1).strip(), m.group(2)
    if len(header_rows) >= 2:
        row = header_rows[1]
        if len(row) != ncol:
            b.fail(f"units row has {len(row)} entries for {ncol} data columns")
        col_units = [u or cu for u, cu in zip(row, col_units)]
    return names, col_units


def _time_column(names, col_units, time_column, b):
    """Index of the time column: the one asked for, else the first named like time or in a
    time unit, else None."""
    if time_column is not None:
        if isinstance(time_column, int) or str(time_column).isdigit():
            return int(time_column)
        if time_column in names:
            return names.index(time_column)
        b.fail(f"time_column={time_column!r} not among the columns {names}")
    for j, nm in enumerate(names):
        unit = known_unit(col_units[j])
        if nm.lower() in _TIME_NAMES or (unit is not None and unit.quantity == "time"):
            return j
    return None


def _time_base(b, vals, names, col_units, tcol, first, fs, allow_uneven):
    """(fs, t0, time): the rate from ``fs`` or a uniform time column, or an uneven time column
    kept as the time coordinate (``allow_uneven``)."""
    time = None
    t0 = 0.0
    if tcol is None:
        if fs is None:
            b.fail("no time column (time, t, or a column in s) and no rate; pass fs=<Hz> "
                   "(CLI --fs)")
        return fs, t0, time
    tu = col_units[tcol] or "s"
    try:
        tu = _units.lookup_unit(tu)
    except RecordingError as exc:
        b.fail(f"time column {names[tcol]!r}: {exc}")
    t = vals[:, tcol] * tu.factor
    if fs is not None:
        b.attrs["time_column_ignored"] = names[tcol]
        return fs, float(t[0]), time
    bad = first_non_increasing(t)
    if bad is not None:
        b.fail(f"time column {names[tcol]!r} is not strictly increasing (line "
               f"{first + bad + 2}); repair it, or pass fs= to ignore it")
    dt = np.diff(t)
    if not is_uniform(dt):
        if not allow_uneven:
            b.fail(f"time column {names[tcol]!r} is not uniformly sampled (steps "
                   f"{dt.min():.6g} to {dt.max():.6g} s); pass fs=<Hz> to use a "
                   "nominal rate, or allow_uneven=True to keep the times")
        b.warn("uneven time column kept as the time coordinate")
        b.attrs["uneven_time"] = 1
        return fs, t0, t
    return column_rate(t), float(t[0]), time


ENGINES["csv"] = CsvReader
