"""xarray backend: ``xr.open_dataset(path, engine="bearing_lab")`` reads any supported recording.

Why: a notebook user who already works with xarray should not need a second way in.  The
entry point (``xarray.backends`` group, declared in ``pyproject.toml``) forwards to
:func:`bearing_lab.io.open_recording`, so the Dataset is exactly the one the readers build:
SI units, ``units``/``original_units``/``quantity`` per channel, provenance attributes.

Only the options every reader understands are exposed (xarray's plugin loader needs them
spelled out): ``format`` (the reader's name; sniffed from the content when omitted),
``channels``, ``fs``, ``sensitivity``, ``units``.  ``drop_variables`` drops channels after
reading.  Without ``engine=``, xarray asks :meth:`guess_can_open`, which claims only the file
types no other xarray backend reads (UFF, MATLAB, TDMS, MDF4, WAV), so ``.nc`` files keep
going to xarray's own netCDF engines.
"""
from __future__ import annotations

import os
from pathlib import Path

from xarray.backends import BackendEntrypoint

#: file types claimed when xarray guesses the engine (no other backend reads them)
_SUFFIXES = (".uff", ".unv", ".mat", ".tdms", ".mf4", ".mdf", ".wav")


class BearingLabBackendEntrypoint(BackendEntrypoint):
    """Read a rig recording with bearing_lab's readers (see :func:`bearing_lab.io.open_recording`)."""

    description = "Rolling-bearing rig recordings (UFF 58/58b, Testlab MAT/text, CWRU, IMS, MFPT, TDMS, MDF4, WAV)"
    open_dataset_parameters = ("filename_or_obj", "drop_variables", "format", "channels", "fs",
                               "sensitivity", "units")

    def open_dataset(self, filename_or_obj, *, drop_variables=None, format=None, channels=None,
                     fs=None, sensitivity=None, units=None):
        from . import open_recording
        if not isinstance(filename_or_obj, (str, os.PathLike)):
            from ..errors import RecordingError
            msg = (f"engine='bearing_lab' reads files by path; got a {type(filename_or_obj).__name__} "
                   "(save it to a file first)")
            raise RecordingError(msg)
        options = {k: v for k, v in (("channels", channels), ("fs", fs), ("sensitivity", sensitivity),
                                     ("units", units)) if v is not None}
        ds = open_recording(filename_or_obj, format=format, **options)
        if drop_variables is not None:
            names = [drop_variables] if isinstance(drop_variables, str) else list(drop_variables)
            ds = ds.drop_vars([n for n in names if n in ds.variables])
        return ds

    def guess_can_open(self, filename_or_obj) -> bool:
        if not isinstance(filename_or_obj, (str, os.PathLike)):
            return False
        return Path(filename_or_obj).suffix.lower() in _SUFFIXES
