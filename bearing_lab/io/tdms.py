"""NI TDMS files (optional extra: ``pip install bearing_lab[formats]`` for npTDMS).

Why optional: npTDMS is only needed by labs with NI hardware.  Rate and start
come from the waveform properties ``wf_increment`` and ``wf_start_offset``; the
unit from ``unit_string`` (NI's property), refused if unknown unless ``units=``.
Channel names are the TDMS channel names (``group_channel`` when names repeat
across groups).  Channels of different rates or lengths are refused with a
request for ``channels=[...]``.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ._base import ENGINES, RecordingBuilder, RecordingReader, clean_name


class TdmsReader(RecordingReader):
    """Read NI TDMS waveform channels through npTDMS."""

    name = "tdms"
    description = "NI TDMS (.tdms) waveform channels (needs npTDMS)"
    extensions = (".tdms",)
    libraries = ("nptdms",)

    def guess_can_open(self, path, head):
        return head[:4] == b"TDSm"

    def open_dataset(self, path, *, channels=None, units=None, sensitivity=None, fs=None,
                     checksum=True):
        """Read the waveform channels of a TDMS file.

        Parameters
        ----------
        path : str or Path
        channels : str or list of str, optional
        units, sensitivity : see :func:`bearing_lab.io.open_recording`
        fs : float, optional
            Sampling rate, Hz, when the file has no ``wf_increment``.
        checksum : bool

        Returns
        -------
        xarray.Dataset
        """
        from nptdms import TdmsFile

        path = Path(path)
        b = RecordingBuilder(path, self, units=units, sensitivity=sensitivity, checksum=checksum)
        try:
            f = TdmsFile.read(path)
        except Exception as exc:  # npTDMS raises ValueError/KeyError/struct.error on bad files
            b.fail(f"not a readable TDMS file ({type(exc).__name__}: {exc})")
        found = []
        names = [c.name for g in f.groups() for c in g.channels()]
        for g in f.groups():
            for c in g.channels():
                data = np.asarray(c[:])
                if data.dtype.kind not in "iuf" or data.size < 2:
                    continue
                p = c.properties
                inc = p.get("wf_increment")
                rate = 1.0 / float(inc) if inc else (float(fs) if fs else None)
                nm = c.name if names.count(c.name) == 1 else f"{g.name}_{c.name}"
                found.append((clean_name(nm, f"ch{len(found) + 1}"), data, p.get("unit_string"),
                              rate, float(p.get("wf_start_offset", 0.0)), g.name, c.name))
        if not found:
            b.fail("no numeric waveform channels")
        if channels is not None:
            want = [channels] if isinstance(channels, str) else list(channels)
            have = [x[0] for x in found]
            for w in want:
                if w not in have:
                    b.fail(f"no channel {w!r}; the file has {', '.join(have)}")
            found = [x for x in found if x[0] in want]
        keys = {(x[1].size, x[3], x[4]) for x in found}
        if len(keys) > 1:
            desc = ", ".join(f"{x[0]}: {x[1].size} samples at {x[3]} Hz" for x in found)
            b.fail(f"channels differ in rate, length or start ({desc}); read one group at a time "
                   "with channels=[...]")
        rate = float(fs) if fs else found[0][3]
        if rate is None:
            b.fail("no wf_increment property: the rate is unknown; pass fs=<Hz>")
        for nm, data, unit, _, _, gname, cname in found:
            b.add_channel(nm, data, unit, file_name=cname,
                          attrs={"tdms_group": gname, "tdms_channel": cname})
        return b.build(fs=rate, t0=found[0][4])


ENGINES["tdms"] = TdmsReader
