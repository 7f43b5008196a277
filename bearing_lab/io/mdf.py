"""ASAM MDF 3/4 measurement files (optional extra: asammdf).

Why optional: asammdf is large and only automotive rigs need it.  Every non-master
channel with numeric samples becomes a variable (unit from the channel's
``unit``); time comes from the channel's timestamps, which must be uniform and
shared by the selected channels, else the file is refused with a request for
``channels=[...]`` (MDF groups often run at different rates).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ._base import ENGINES, RecordingBuilder, RecordingReader, clean_name


class MdfReader(RecordingReader):
    """Read ASAM MDF channels through asammdf."""

    name = "mdf"
    description = "ASAM MDF 3/4 (.mf4, .mdf, .dat) channels (needs asammdf)"
    extensions = (".mf4", ".mdf", ".dat")
    libraries = ("asammdf",)

    def guess_can_open(self, path, head):
        return head[:8] in (b"MDF     ", b"UnFinMF ")

    def open_dataset(self, path, *, channels=None, units=None, sensitivity=None, checksum=True):
        """Read MDF channels that share one uniform time base.

        Parameters
        ----------
        path : str or Path
        channels : str or list of str, optional
        units, sensitivity : see :func:`bearing_lab.io.open_recording`
        checksum : bool

        Returns
        -------
        xarray.Dataset
        """
        from asammdf import MDF  # loads when it reads (every reader is imported to sniff)

        path = Path(path)
        b = RecordingBuilder(path, self, units=units, sensitivity=sensitivity, checksum=checksum)
        try:
            mdf = MDF(str(path))
        except Exception as exc:
            b.fail(f"not a readable MDF file ({type(exc).__name__}: {exc})")
        want = None if channels is None else ([channels] if isinstance(channels, str) else
                                              list(channels))
        sigs = []
        try:
            for sig in mdf.iter_channels(skip_master=True):
                nm = clean_name(sig.name, f"ch{len(sigs) + 1}")
                if want is not None and nm not in want and sig.name not in want:
                    continue
                s = np.asarray(sig.samples)
                if s.dtype.kind not in "iuf" or s.ndim != 1 or s.size < 2:
                    continue
                sigs.append((nm, s, sig.unit, np.asarray(sig.timestamps, dtype=np.float64),
                             sig.name))
        finally:
            mdf.close()
        if not sigs:
            b.fail("no numeric channels" + (f" named {want}" if want else ""))
        t = sigs[0][3]
        for nm, s, _, ts, _ in sigs[1:]:
            if ts.size != t.size or not np.array_equal(ts, t):
                b.fail(f"channels {sigs[0][0]!r} and {nm!r} have different time bases; read them "
                       "separately with channels=[...]")
        dt = np.diff(t)
        med = float(np.median(dt))
        if not np.all(dt > 0) or np.max(np.abs(dt - med)) > 1e-3 * med:
            b.fail("the time base is not uniform; resample in the acquisition software")
        for nm, s, unit, _, orig in sigs:
            b.add_channel(nm, s, unit, file_name=orig)
        return b.build(fs=(t.size - 1) / (t[-1] - t[0]), t0=float(t[0]))


ENGINES["mdf"] = MdfReader
