"""Recording import: a rig's file -> the recording Dataset of :mod:`bearing_lab.schema`.

Public API
----------
::

    open_recording(path, format=None, **options) -- file -> xarray.Dataset (format sniffed from content)
    list_engines()                                -- {name: description} of the readers, and what each needs
    to_netcdf(ds, path)                           -- compressed, lossless netCDF4
    to_uff58b(ds, path, channels=None, ...)       -- UFF 58b (binary) for Testlab and other tools
    get_warnings(ds)                              -- the recording's warnings as a list
    speed_problem(rpm)                            -- None for a plausible shaft speed (r/min), else what is wrong
    ENGINES                                       -- name -> reader class, in sniffing order (SNIFF_ORDER,
                                                     then the entry-point group "bearing_lab.readers",
                                                     then FALLBACK_READERS)
    RecordingReader                               -- base class of the readers
    RecordingWarning                              -- category of the non-fatal warnings

Options every reader understands: ``channels``, ``units`` (label or channel ->
label, for unknown or missing unit labels), ``checksum``; most also take ``fs``
(override the rate) and ``sensitivity`` (``"9.91mV/g"`` for voltage channels).
An option a reader does not know is refused with the list of those it knows
(:class:`~bearing_lab.errors.RecordingOptionError`, a ``RecordingError`` whose ``unknown`` and
``accepted`` name the options).
"""
from __future__ import annotations

import errno
import importlib
from importlib.metadata import entry_points
import os
from pathlib import Path
import stat
import warnings

from ..errors import BearingLabError, RecordingError, RecordingOptionError, check_choice
from ._base import (ARRAYS_ONLY, ENGINES, RecordingArrays, RecordingReader,  # noqa: F401
                    RecordingWarning, get_warnings, speed_problem)

#: The built-in readers (one module each, named like the format), in sniffing order: the first
#: reader whose ``guess_can_open`` says yes reads the file.
SNIFF_ORDER = ("uff58", "testlab_mat", "cwru", "mfpt", "ims", "testlab_text", "wav", "tdms", "mdf",
               "netcdf")
#: Readers that accept almost anything (any delimited text): sniffed last.
FALLBACK_READERS = ("csv",)
#: Entry-point group of readers installed by other packages (a lab's private format): each entry
#: names a RecordingReader subclass; they are sniffed after SNIFF_ORDER, before FALLBACK_READERS.
ENTRY_POINT_GROUP = "bearing_lab.readers"


def _load_plugin_readers() -> list[str]:
    """Register the readers of :data:`ENTRY_POINT_GROUP`; a broken one is skipped with a warning."""
    added = []
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        why = None
        if ep.name in ENGINES or ep.name in FALLBACK_READERS:
            why = "the name is taken by a built-in reader"
        else:
            try:
                cls = ep.load()
            except Exception as exc:  # noqa: BLE001 - another package's import error must not stop ours
                why = f"it cannot be imported ({type(exc).__name__}: {exc})"
            else:
                if not (isinstance(cls, type) and issubclass(cls, RecordingReader)):
                    why = f"{ep.value} is not a bearing_lab.io.RecordingReader subclass"
        if why:
            warnings.warn(f"reader {ep.name!r} of the {ENTRY_POINT_GROUP!r} entry points ({ep.value}) "
                          f"is not used: {why}", RecordingWarning, stacklevel=2)
            continue
        ENGINES[ep.name] = cls
        added.append(ep.name)
    return added


def _register_readers():
    for name in SNIFF_ORDER:
        importlib.import_module(f".{name}", __name__)
    _load_plugin_readers()
    for name in FALLBACK_READERS:
        importlib.import_module(f".{name}", __name__)


_register_readers()
from .export import to_netcdf, to_uff58b  # noqa: E402

__all__ = ["open_recording", "read_arrays", "list_engines", "to_netcdf", "to_uff58b", "get_warnings",
           "speed_problem", "ENGINES", "RecordingReader", "RecordingWarning"]


def list_engines() -> dict[str, str]:
    """Return ``{name: description}`` for every registered reader.

    A reader whose optional library is missing says what to install.

    See Also
    --------
    open_recording

    Examples
    --------
    >>> "uff58" in list_engines()
    True
    """
    out = {}
    for name, cls in ENGINES.items():
        r = cls()
        missing = r.available()
        out[name] = r.description + (f" [{missing}]" if missing else "")
    return out


def _engine_list() -> str:
    return ", ".join(f"{n}" + ("" if ENGINES[n]().available() is None else " (not installed)")
                     for n in ENGINES)


def guess_format(path) -> str:
    """Return the name of the first reader that recognises the file's content.

    Raises
    ------
    RecordingError
        If no reader claims the file.
    """
    path = Path(path)
    with open(path, "rb") as fh:
        head = fh.read(8192)
    corrupt = None
    sniff_errors = []
    for name, cls in ENGINES.items():
        try:
            if cls().guess_can_open(path, head):
                return name
        except RecordingError as exc:  # looks like the format but is damaged
            corrupt = corrupt or exc
        except Exception as exc:  # noqa: BLE001 - a reader's sniffing failed: not its format,
            sniff_errors.append(f"{name}: {type(exc).__name__}: {exc}")  # but say so below
            continue
    if corrupt is not None:
        raise corrupt
    msg = (f"{path}: no reader recognises this file (it starts with {head[:16]!r}); installed "
           f"engines: {_engine_list()}; if you know the format, pass format='<engine>' "
           "(bearing-lab import --format)")
    if sniff_errors:
        msg += "; readers that failed while sniffing: " + " | ".join(sniff_errors)
    raise RecordingError(msg)


_NOT_REGULAR = ((stat.S_ISFIFO, "a named pipe (FIFO)"), (stat.S_ISCHR, "a character device"),
                (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def check_input_file(path) -> int:
    """Return the size of ``path`` after checking it is a regular, readable file.

    Checked with ``stat`` before anything opens the file: opening a named pipe blocks until
    another program writes to it, and a device or a ``/proc`` file reports no size (or an
    endless one).  Each case is its own message: a missing file, a dangling link, a loop of
    symbolic links, a directory, a pipe or a device, a pseudo-file, a file without read
    permission.

    Raises
    ------
    RecordingError
        Naming the path and what it is instead of a recording file.
    """
    path = Path(path)
    try:
        st = os.stat(path)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise RecordingError(f"{path}: symbolic links form a loop (or a chain too long to "
                                 "follow); point the link at the recording file") from None
        if exc.errno == errno.ENOENT:
            if os.path.islink(path):
                raise RecordingError(f"{path}: symbolic link to {os.readlink(path)}, which does "
                                     "not exist") from None
            raise RecordingError(f"{path}: file not found") from None
        if exc.errno == errno.ENAMETOOLONG:
            raise RecordingError(f"{path}: file name too long") from None
        raise RecordingError(f"{path}: cannot read the file ({exc.strerror or exc})") from None
    if stat.S_ISDIR(st.st_mode):
        raise RecordingError(f"{path}: is a directory, not a recording file")
    if not stat.S_ISREG(st.st_mode):
        kind = next((k for test, k in _NOT_REGULAR if test(st.st_mode)), "not a regular file")
        raise RecordingError(f"{path}: is {kind}, not a regular file; a recording is read from a "
                             "file (save the stream to a file first)")
    try:
        with open(path, "rb") as fh:  # unreadable (permissions): one clear line, here
            first = fh.read(1) if st.st_size == 0 else b""
    except OSError as exc:
        raise RecordingError(f"{path}: cannot read the file ({exc.strerror or exc})") from None
    if first:
        raise RecordingError(f"{path}: reports a size of 0 bytes but has content: a pseudo-file "
                             "(such as those under /proc or /sys), not a recording file")
    return st.st_size


def open_recording(path, format=None, **options):
    """Open a recording file as a Dataset in SI units with provenance.

    Parameters
    ----------
    path : str or Path
        The recording (UFF 58/58b, Testlab MAT or text, CSV/TSV, WAV, CWRU/MFPT
        ``.mat``, IMS ASCII, TDMS, MDF4, or a bearing_lab ``.nc``).
    format : str, optional
        Reader name (see :func:`list_engines`); sniffed from the content if None.
        ``engine=`` is accepted as an alias (xarray's spelling).
    **options
        Passed to the reader's ``open_dataset`` (e.g. ``fs=12000``,
        ``sensitivity="9.91mV/g"``, ``channels=["DE"]``, ``units="g"``).

    Returns
    -------
    xarray.Dataset
        Coordinate ``time`` (s), one variable per channel (attrs ``units`` SI,
        ``original_units``, ``quantity``), global attrs ``sampling_rate_hz``,
        ``bearing_lab_version``, ``source_file``, ``source_sha256``, ``reader``,
        ``reader_libraries``, ``warnings`` (``"; "``-joined), ``default_channel``
        and ``shaft_speed_rpm`` where known.

    Raises
    ------
    RecordingError
        For any unreadable, corrupt or ambiguous input; the message names the file.

    See Also
    --------
    list_engines : the readers and the options each takes.
    to_netcdf, to_uff58b : write a Dataset.
    bearing_lab.analysis.analyze : analyse a channel.

    Examples
    --------
    >>> ds = open_recording("130_OR007@6_0.mat")          # doctest: +SKIP
    >>> ds["DE"].attrs["units"], ds.attrs["sampling_rate_hz"]  # doctest: +SKIP
    ('m s-2', 12000.0)
    """
    path = Path(path)
    if "engine" in options:  # xarray's spelling, accepted as an alias of format=
        engine = options.pop("engine")
        if format is not None and engine != format:
            raise RecordingError(f"{path}: format={format!r} and engine={engine!r} disagree")
        format = engine
    size = check_input_file(path)
    if size == 0:
        raise RecordingError(f"{path}: file is empty (0 bytes)")
    if format is None:
        try:
            format = guess_format(path)
        except OSError as exc:
            raise RecordingError(f"{path}: cannot read the file ({exc.strerror or exc})") from None
    check_choice(format, ENGINES, f"{path}: format", RecordingError)
    if not ARRAYS_ONLY.get():
        from .. import _accessor  # noqa: F401  (registers da.bearing on the recordings; imports xarray)
    reader = ENGINES[format]()
    missing = reader.available()
    if missing:
        raise RecordingError(f"{path}: the {format!r} reader {missing}")
    known = reader.option_names()
    unknown = [k for k in options if k not in known]
    if unknown:
        msg = (f"{path}: the {format!r} reader does not understand option(s) "
               f"{', '.join(unknown)}; it accepts {', '.join(known)}")
        raise RecordingOptionError(msg, unknown=unknown, accepted=known)
    try:
        return reader.open_dataset(path, **options)
    except RecordingError as exc:
        if str(path) in str(exc) or path.name in str(exc):
            raise
        raise RecordingError(f"{path}: {exc}") from exc
    except BearingLabError as exc:
        raise RecordingError(f"{path}: {exc}") from exc
    except MemoryError as exc:
        raise RecordingError(f"{path}: corrupt sizes in the file ask for more memory than "
                             "there is") from exc
    except OSError as exc:
        raise RecordingError(f"{path}: cannot read the file ({exc.strerror or exc})") from exc
    except Exception as exc:  # the safety net: no library exception escapes
        msg = (f"{path}: the {format!r} reader failed on unexpected or corrupt content "
               f"({type(exc).__name__}: {exc})")
        raise RecordingError(msg) from exc


def read_arrays(path, format=None, **options):
    """Read a recording like :func:`open_recording`, without making the Dataset.

    Returns a :class:`RecordingArrays` (time, channels and attributes, every check made;
    ``.to_dataset()`` gives what :func:`open_recording` gives) for the readers that assemble
    their channels (all but ``netcdf``, which returns its Dataset).  For a quick summary
    (``bearing-lab info``): xarray and pandas are not imported.
    """
    token = ARRAYS_ONLY.set(True)
    try:
        return open_recording(path, format=format, **options)
    finally:
        ARRAYS_ONLY.reset(token)
