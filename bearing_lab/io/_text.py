"""Helpers for the text readers (Testlab text export, CSV/TSV): decoding and numbers.

Why: rig software writes latin-1 and decimal commas; one place decides how a
text file is decoded and how a column of numbers is parsed, and reports the
first bad cell by row and column instead of a bare ``ValueError``.
"""
from __future__ import annotations

import re

import numpy as np

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
