"""xarray backend: ``xr.open_dataset(path, engine="bearing_lab")`` reads any supported recording.

Why: a notebook user who already works with xarray should not need a second way in.  The
entry point (``xarray.backends`` group, declared in ``pyproject.toml``) forwards to
:func:`bearing_lab.io.open_recording`, so the Dataset is exactly the one the readers build:
SI units, ``units``/``original_units``/``quantity`` per channel, provenance attributes.

Every reader keyword passes through (xarray's plugin loader needs them spelled out, so
:data:`READER_OPTIONS` lists them and a test checks it against the readers): ``format`` (the
reader's name; sniffed from the content when omitted), ``channels``, ``fs``, ``sensitivity``,
``units``, ``allow_truncated``, ``full_scale``, ``record``, ``time_column``, ``allow_uneven``,
``byte_order``, ``snap_rate``, ``checksum``; a reader refuses a keyword it does not use, by name.
``drop_variables`` drops channels after reading.  Without ``engine=``, xarray asks
:meth:`guess_can_open`, which claims only the file types no other xarray backend reads (UFF,
MATLAB, TDMS, MDF4, WAV), so ``.nc`` files keep going to xarray's own netCDF engines.
Documented for users in docs/xarray.md.
"""
from __future__ import annotations

import os
from pathlib import Path

from xarray.backends import BackendEntrypoint

from ..errors import RecordingError
from . import open_recording

#: every keyword a reader takes (the union of the readers' option_names(); a test keeps it so)
READER_OPTIONS = ("channels", "fs", "sensitivity", "units", "allow_truncated", "full_scale", "record",
                  "time_column", "allow_uneven", "byte_order", "snap_rate", "checksum")

#: file types claimed when xarray guesses the engine (no other backend reads them)
_SUFFIXES = (".uff", ".unv", ".mat", ".tdms", ".mf4", ".mdf", ".wav")


class BearingLabBackendEntrypoint(BackendEntrypoint):
    """Read a rig recording with bearing_lab's readers (see :func:`bearing_lab.io.open_recording`)."""

    description = "Rolling-bearing rig recordings (UFF 58/58b, Testlab MAT/text, CWRU, IMS, MFPT, TDMS, MDF4, WAV)"
    open_dataset_parameters = ("filename_or_obj", "drop_variables", "format", *READER_OPTIONS)

    def open_dataset(self, filename_or_obj, *, drop_variables=None, format=None, **options):
        if not isinstance(filename_or_obj, (str, os.PathLike)):
            msg = (f"engine='bearing_lab' reads files by path; got a {type(filename_or_obj).__name__} "
                   "(save it to a file first)")
            raise RecordingError(msg)
        unknown = sorted(set(options) - set(READER_OPTIONS))
        if unknown:
            raise RecordingError(f"{filename_or_obj}: engine='bearing_lab' takes no keyword {unknown[0]!r}; the "
                                 f"reader keywords are {', '.join(READER_OPTIONS)}")
        ds = open_recording(filename_or_obj, format=format, **{k: v for k, v in options.items() if v is not None})
        if drop_variables is not None:
            names = [drop_variables] if isinstance(drop_variables, str) else list(drop_variables)
            ds = ds.drop_vars([n for n in names if n in ds.variables])
        return ds

    def guess_can_open(self, filename_or_obj) -> bool:
        if not isinstance(filename_or_obj, (str, os.PathLike)):
            return False
        return Path(filename_or_obj).suffix.lower() in _SUFFIXES
