"""Helpers for the text readers (Testlab text export, CSV/TSV): decoding and numbers.

Why: rig software writes latin-1 and decimal commas; one place decides how a
text file is decoded and how a column of numbers is parsed, and reports the
first bad cell by row and column instead of a bare ``ValueError``.
"""
from __future__ import annotations

from pathlib import Path
import re

import numpy as np

from .. import units as _units
from ..errors import RecordingError

_NUM = re.compile(r"^\s*[-+]?(?:\d+(?:[.,]\d*)?|[.,]\d+)(?:[eEdD][-+]?\d+)?\s*$")


def decode(raw: bytes) -> tuple[str, str]:
    """Return (text, encoding): UTF-8 (with or without BOM), else latin-1."""
    if raw.startswith(b"\xef\xbb\xbf"):
        return raw[3:].decode("utf-8", errors="replace"), "utf-8-sig"
    try:
        return raw.decode("utf-8"), "utf-8"
    except UnicodeDecodeError:
        return raw.decode("latin-1"), "latin-1"


def looks_binary(raw: bytes) -> bool:
    """True if the bytes are not text (NUL bytes or many control characters)."""
    if b"\x00" in raw:
        return True
    ctrl = sum(1 for c in raw[:4096] if c < 32 and c not in (9, 10, 13))
    return ctrl > 0.01 * max(len(raw[:4096]), 1)


def read_text(path, fail, not_what: str) -> tuple[bytes, str, str]:
    """Return (bytes, text, encoding) of a text file; ``fail("binary content: " + not_what)``
    when its first 64 KiB are not text."""
    raw = Path(path).read_bytes()
    if looks_binary(raw[:65536]):
        fail(f"binary content: {not_what}")
    text, enc = decode(raw)
    return raw, text, enc


def known_unit(label):
    """The :class:`bearing_lab.units.Unit` of a unit label, or None (no label, or an unknown one)."""
    if not label:
        return None
    try:
        return _units.lookup_unit(label)
    except RecordingError:
        return None


def first_non_increasing(t) -> int | None:
    """Index ``k`` of the first step ``t[k + 1] - t[k]`` that is not positive (0 when ``t`` has
    fewer than two values), or None when the times strictly increase."""
    dt = np.diff(t)
    if dt.size and np.all(dt > 0):
        return None
    return int(np.flatnonzero(~(dt > 0))[0]) if dt.size else 0


def is_uniform(dt) -> bool:
    """True when every time step is within 0.1 % of the median step."""
    med = float(np.median(dt))
    return not np.max(np.abs(dt - med)) > 1e-3 * med + 1e-12


def column_rate(t) -> float:
    """The rate of a uniform time column, Hz, snapped to a whole number within 1 ppm."""
    rate = (t.size - 1) / (t[-1] - t[0])
    if abs(rate - round(rate)) < 1e-6 * rate:
        rate = float(round(rate))
    return rate


def is_number(s: str) -> bool:
    return bool(_NUM.match(s))


def parse_table(rows, first_row: int, fail, decimal_comma: bool):
    """Parse a list of lists of strings into a float array (rows × columns).

    ``fail(msg)`` raises; ``first_row`` is the file line number of ``rows[0]``.
    """
    ncol = len(rows[0])
    for i, r in enumerate(rows):
        if len(r) != ncol:
            fail(f"line {first_row + i}: {len(r)} columns, expected {ncol} (truncated or corrupt)")
    flat = [c.strip() for r in rows for c in r]
    if decimal_comma:
        flat = [c.replace(",", ".") for c in flat]
    try:
        return np.array(flat, dtype=np.float64).reshape(len(rows), ncol)
    except ValueError:
        for k, c in enumerate(flat):
            try:
                float(c)
            except ValueError:
                fail(f"line {first_row + k // ncol}, column {k % ncol + 1}: {c[:30]!r} is not a "
                     "number")
        raise  # pragma: no cover
