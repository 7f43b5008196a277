"""IMS / NASA bearing run-to-failure ASCII files (one file per snapshot, named by timestamp).

Rate decision: the IMS documentation says "20 kHz", but every file holds 20 480
rows and the documented fault lines (set 2, bearing 1 outer race, BPFO 236.4 Hz
at 2000 rpm) land where they should only with 20 480 Hz (one second a file);
with 20 000 Hz they would sit 2.4 % low.  We therefore default to
``fs=20480`` and let the user override with ``fs=20000``; the attribute
``sampling_rate_source`` says which.  Units: the set's documentation gives none;
the values are taken as g (``units=`` overrides), stated in ``unit_source``.

Channels: 4 columns (sets 2, 3) -> ``b1`` .. ``b4``; 8 columns (set 1, two
accelerometers a bearing) -> ``b1x``, ``b1y`` .. ``b4y``.  Shaft speed 2000 rpm.

Length: every snapshot of the three IMS test sets holds 20 480 rows, each ended by a
line break.  A file with fewer rows, or whose last row has no line break (its last
number may be cut short), is truncated: refused, or kept with ``allow_truncated=True``
(the incomplete last row dropped; ``truncated`` and ``declared_samples`` say so).
"""
from __future__ import annotations

import io
import re
import warnings
from datetime import datetime
from pathlib import Path

import numpy as np

from ._base import ENGINES, RecordingBuilder, RecordingReader

IMS_FS = 20480.0
IMS_ROWS = 20480
_NAME = re.compile(r"^(\d{4})\.(\d{2})\.(\d{2})\.(\d{2})\.(\d{2})\.(\d{2})$")
_NUMLINE = re.compile(rb"^\s*[-+0-9.eE]+(?:[\t ]+[-+0-9.eE]+){3,7}\s*$")


class ImsReader(RecordingReader):
    """Read IMS/NASA bearing snapshots (tab-separated ASCII, 4 or 8 columns)."""

    name = "ims"
    description = "IMS/NASA bearing run-to-failure ASCII snapshot (file named YYYY.MM.DD.hh.mm.ss)"
    extensions = ("",)
    libraries = ("numpy",)

    def guess_can_open(self, path, head):
        lines = head.splitlines()
        return bool(_NAME.match(Path(path).name)) and bool(lines) and \
            _NUMLINE.match(lines[0]) is not None

    @staticmethod
    def _slow_parse(raw, lines, ncol, b):
        """Token by token, to name the first bad row (only for files loadtxt refused)."""
        toks = raw.split()
        try:
            vals = np.array(toks, dtype=np.float64)
        except ValueError:
            for i, ln in enumerate(lines):
                for t in ln.split():
                    try:
                        float(t)
                    except ValueError:
                        b.fail(f"corrupt number {bytes(t[:30])!r} in row {i + 1}")
            raise  # pragma: no cover
        if vals.size != len(lines) * ncol:
            bad = next((i for i, ln in enumerate(lines) if len(ln.split()) != ncol), None)
            b.fail(f"row {bad + 1 if bad is not None else '?'} does not have {ncol} columns: "
                   "truncated or corrupt file")
        return vals.reshape(-1, ncol)

    def open_dataset(self, path, *, channels=None, fs=None, units="g", allow_truncated=False,
                     checksum=True):
        """Read one IMS snapshot.

        Parameters
        ----------
        path : str or Path
        channels : str or list of str, optional
        fs : float, optional
            Sampling rate, Hz; default 20 480 (see the module docstring).
        units : str
            Unit of the values (default ``"g"``).
        allow_truncated : bool
            Keep the complete rows of a snapshot with fewer than 20 480 (warning).
        checksum : bool
            Compute ``source_sha256``.

        Returns
        -------
        xarray.Dataset
        """
        path = Path(path)
        b = RecordingBuilder(path, self, units=units, checksum=checksum)
        raw = path.read_bytes()
        body = raw.strip()
        if not body:
            b.fail("no data rows")
        cut_row = not raw.endswith((b"\n", b"\r"))
        if cut_row:  # the last row may have lost digits: never read it as data
            raw = raw[:raw.rfind(b"\n") + 1]
            body = raw.strip()
            if not body:
                b.fail("no complete data row (no line break)")
        nl = body.find(b"\n")
        ncol = len((body if nl < 0 else body[:nl]).split())
        if ncol not in (4, 8):
            b.fail(f"first row has {ncol} columns; IMS files have 4 or 8")
        try:  # numpy's C parser: fast path for a well-formed file
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                vals = np.loadtxt(io.BytesIO(raw), dtype=np.float64, ndmin=2)
            if vals.shape[1] != ncol:
                raise ValueError("column count")
        except ValueError:
            vals = self._slow_parse(body, body.splitlines(), ncol, b)
        rows = vals.shape[0]
        if rows < IMS_ROWS or cut_row:
            what = "the last row has no line break (cut short)" if cut_row else "rows"
            b.shortfall(f"IMS snapshot ({what})", IMS_ROWS, rows, allow_truncated, unit="rows",
                        declares="snapshots hold")
        elif rows > IMS_ROWS:
            b.warn(f"{rows} rows (IMS snapshots have {IMS_ROWS}): not a plain IMS snapshot")
        names = [f"b{i + 1}" for i in range(4)] if ncol == 4 else \
            [f"b{i // 2 + 1}{'xy'[i % 2]}" for i in range(8)]
        for j, nm in enumerate(names):
            b.add_channel(nm, vals[:, j], None, file_name=f"column {j + 1}", inplace=True,
                          attrs={"bearing_number": j + 1 if ncol == 4 else j // 2 + 1})
        b.attrs["sampling_rate_source"] = "user" if fs is not None else \
            "bearing_lab default 20480 Hz (20480 rows = 1 s; fits the fault lines)"
        b.attrs["unit_source"] = "user" if units != "g" else "assumed g (IMS documentation gives none)"
        m = _NAME.match(path.name)
        if m:
            try:
                b.attrs["acquisition_time"] = datetime(*map(int, m.groups())).isoformat()
            except ValueError:
                pass
        b.attrs["bearing"] = "Rexnord ZA-2115"
        return b.build(fs=fs if fs is not None else IMS_FS, shaft_speed_rpm=2000.0,
                       default_channel=names[0], channels=channels)


ENGINES["ims"] = ImsReader
