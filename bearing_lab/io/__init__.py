"""Recording import: a rig's file -> the recording Dataset of :mod:`bearing_lab.schema`.

Public API
----------
open_recording(path, format=None, **options) -- file -> xarray.Dataset (format sniffed from content)
list_engines()                                -- {name: description} of the readers, and what each needs
to_netcdf(ds, path)                           -- compressed, lossless netCDF4
to_uff58b(ds, path, channels=None, ...)       -- UFF 58b (binary) for Testlab and other tools
get_warnings(ds)                              -- the recording's warnings as a list
ENGINES                                       -- name -> reader class (one module per format)
RecordingReader                               -- base class of the readers
RecordingWarning                              -- category of the non-fatal warnings

Options every reader understands: ``channels``, ``units`` (label or channel ->
label, for unknown or missing unit labels), ``checksum``; most also take ``fs``
(override the rate) and ``sensitivity`` (``"9.91mV/g"`` for voltage channels).
An option a reader does not know is refused with the list of those it knows.
"""
from __future__ import annotations

from pathlib import Path

from ..errors import BearingLabError, RecordingError, check_choice
from ._base import ENGINES, RecordingReader, RecordingWarning, get_warnings  # noqa: F401

# one import line per format: the order is the sniffing order
from . import uff58  # noqa: F401,E402
from . import testlab_mat  # noqa: F401,E402
from . import cwru  # noqa: F401,E402
from . import mfpt  # noqa: F401,E402
from . import ims  # noqa: F401,E402
from . import testlab_text  # noqa: F401,E402
from . import wav  # noqa: F401,E402
from . import tdms  # noqa: F401,E402
from . import mdf  # noqa: F401,E402
from . import netcdf  # noqa: F401,E402
from . import csv  # noqa: F401,E402  (last: it accepts any delimited text)
from .export import to_netcdf, to_uff58b  # noqa: E402

__all__ = ["open_recording", "list_engines", "to_netcdf", "to_uff58b", "get_warnings",
           "ENGINES", "RecordingReader", "RecordingWarning"]


def list_engines() -> dict[str, str]:
    """Return ``{name: description}`` for every registered reader.

    A reader whose optional library is missing says what to install.

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
    if not path.exists():
        raise RecordingError(f"{path}: file not found")
    if path.is_dir():
        raise RecordingError(f"{path}: is a directory, not a recording file")
    try:
        size = path.stat().st_size
        with open(path, "rb"):  # unreadable (permissions, a device): one clear line, here
            pass
    except OSError as exc:
        raise RecordingError(f"{path}: cannot read the file ({exc.strerror or exc})") from None
    if size == 0:
        raise RecordingError(f"{path}: file is empty (0 bytes)")
    if format is None:
        try:
            format = guess_format(path)
        except OSError as exc:
            raise RecordingError(f"{path}: cannot read the file ({exc.strerror or exc})") from None
    check_choice(format, ENGINES, f"{path}: format", RecordingError)
    reader = ENGINES[format]()
    missing = reader.available()
    if missing:
        raise RecordingError(f"{path}: the {format!r} reader {missing}")
    known = reader.option_names()
    unknown = [k for k in options if k not in known]
    if unknown:
        msg = (f"{path}: the {format!r} reader does not understand option(s) "
               f"{', '.join(unknown)}; it accepts {', '.join(known)}")
        raise RecordingError(msg)
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
