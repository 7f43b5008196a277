"""NI TDMS files (optional extra: ``pip install bearing_lab[formats]`` for npTDMS).

Why optional: npTDMS is only needed by labs with NI hardware.  Rate and start
come from the waveform properties ``wf_increment`` and ``wf_start_offset``; the
unit from ``unit_string`` (NI's property), refused if unknown unless ``units=``.
Channel names are the TDMS channel names (``group_channel`` when names repeat
across groups).  Channels of different rates or lengths are refused with a
request for ``channels=[...]``.

Integrity: npTDMS reads a truncated or damaged file as far as it can and only logs a
warning, so a cut file came back with 11 973 of 20 000 samples and one channel
gone.  Before npTDMS sees the file, :func:`_walk_segments` checks the chain of
segment lead-ins (each ``TDSm`` tag, the declared segment length, the last segment
ending exactly at the end of the file); warnings npTDMS logs while reading are
collected; either refuses the file (or, with ``allow_truncated=True``, keeps what
npTDMS read and says so).  Numeric channels are never dropped; non-numeric ones
(strings, timestamps) are named in a warning.
"""
from __future__ import annotations

import logging
from pathlib import Path
import struct

import numpy as np

from ._base import ENGINES, RecordingBuilder, RecordingReader, clean_name


_LEAD_IN = 28
_INCOMPLETE = 0xFFFFFFFFFFFFFFFF  # next-segment offset of a segment the writer never finished


def _walk_segments(data: bytes) -> str | None:
    """Return None if the segment chain covers the file exactly, else what is wrong."""
    pos, n, size = 0, 0, len(data)
    while pos < size:
        if size - pos < _LEAD_IN:
            return f"{size - pos} stray bytes after segment {n} (byte {pos}): truncated"
        if data[pos:pos + 4] != b"TDSm":
            return f"segment {n + 1} at byte {pos} does not start with 'TDSm'"
        toc = struct.unpack_from("<I", data, pos + 4)[0]
        order = ">" if toc & (1 << 6) else "<"
        nxt, raw = struct.unpack_from(order + "QQ", data, pos + 12)
        if nxt == _INCOMPLETE:
            return f"segment {n + 1} at byte {pos} was never finished by its writer"
        if raw > nxt:
            return f"segment {n + 1} at byte {pos}: data offset {raw} beyond its length {nxt}"
        end = pos + _LEAD_IN + nxt
        if end > size:
            return (f"segment {n + 1} at byte {pos} declares {nxt} bytes, {size - pos - _LEAD_IN} "
                    "present: truncated")
        pos, n = end, n + 1
    return None if n else "no segments"


class _Collect(logging.Handler):
    def __init__(self):
        super().__init__(logging.WARNING)
        self.messages = []

    def emit(self, record):
        self.messages.append(record.getMessage())


class TdmsReader(RecordingReader):
    """Read NI TDMS waveform channels through npTDMS."""

    name = "tdms"
    description = "NI TDMS (.tdms) waveform channels (needs npTDMS)"
    extensions = (".tdms",)
    libraries = ("nptdms",)

    def guess_can_open(self, path, head):
        return head[:4] == b"TDSm"

    def open_dataset(self, path, *, channels=None, units=None, sensitivity=None, fs=None,
                     allow_truncated=False, checksum=True):
        """Read the waveform channels of a TDMS file.

        Parameters
        ----------
        path : str or Path
        channels : str or list of str, optional
        units, sensitivity : see :func:`bearing_lab.io.open_recording`
        fs : float, optional
            Sampling rate, Hz, when the file has no ``wf_increment``.
        allow_truncated : bool
            Keep what a truncated or damaged file still holds (warning) instead of refusing it.
        checksum : bool

        Returns
        -------
        xarray.Dataset
        """
        from nptdms import TdmsFile  # loads when it reads (every reader is imported to sniff)

        path = Path(path)
        b = RecordingBuilder(path, self, units=units, sensitivity=sensitivity, checksum=checksum)
        problem = _walk_segments(path.read_bytes())
        if problem is not None and not allow_truncated:
            b.fail(f"{problem}; pass allow_truncated=True (CLI --allow-truncated) to keep what "
                   "can be read")
        log, handler = logging.getLogger("nptdms"), _Collect()
        log.addHandler(handler)
        try:
            f = TdmsFile.read(path)
        except Exception as exc:  # npTDMS raises ValueError/KeyError/struct.error on bad files
            b.fail(f"not a readable TDMS file ({type(exc).__name__}: {exc})")
        finally:
            log.removeHandler(handler)
        problem = problem or ("; ".join(handler.messages) if handler.messages else None)
        if problem is not None:
            if not allow_truncated:
                b.fail(f"npTDMS: {problem}: damaged file; pass allow_truncated=True to keep what "
                       "can be read")
            b.warn(f"truncated or damaged file read as far as possible ({problem})")
            b.attrs["truncated"] = 1
        found, skipped = [], []
        names = [c.name for g in f.groups() for c in g.channels()]
        for g in f.groups():
            for c in g.channels():
                data = np.asarray(c[:])
                if data.dtype.kind not in "iuf":
                    skipped.append(f"{g.name}/{c.name} ({data.dtype})")
                    continue
                p = c.properties
                inc = p.get("wf_increment")
                rate = 1.0 / float(inc) if inc else (float(fs) if fs else None)
                nm = c.name if names.count(c.name) == 1 else f"{g.name}_{c.name}"
                found.append((clean_name(nm, f"ch{len(found) + 1}"), data, p.get("unit_string"),
                              rate, float(p.get("wf_start_offset", 0.0)), g.name, c.name))
        if skipped:
            b.warn(f"non-numeric channels not read: {', '.join(skipped)}")
        if not found:
            b.fail("no numeric waveform channels")
        if channels is not None:
            want = [channels] if isinstance(channels, str) else list(channels)
            have = [x[0] for x in found]
            for w in want:
                if w not in have:
                    b.fail(f"no channel {w!r}; the file has {', '.join(have)}")
            found = [x for x in found if x[0] in want]
        sizes = [x[1].size for x in found]
        if problem is not None and len(set(sizes)) > 1 and len({(x[3], x[4]) for x in found}) == 1:
            n = min(sizes)  # allow_truncated: keep the samples every channel still has
            b.warn(f"channels cut to the {n} samples all of them still have (up to {max(sizes)} read)")
            b.attrs["declared_samples"] = max(sizes)
            found = [(x[0], x[1][:n], *x[2:]) for x in found]
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
