"""What to analyse in a Dataset: the signal channel, its rate, the tacho channel, the speed and the bearing.

A recording or a simulation Dataset holds several variables; :func:`bearing_lab.analysis.analyze`
takes one signal and its sampling rate, an optional tacho signal, a speed prior and a bearing name.
These functions choose them from the file and the Dataset the same way for every caller
(``bearing-lab analyze`` among them), and say what is missing with the input named.

Public API
----------
::

    open_at_rate(path, fs=None, *, name="fs")  -- (Dataset, rate given or None, note): a file read at a given rate
    signal_rate(ds, channel)                   -- the channel's sampling rate, Hz (the file's, else its time axis)
    shaft_rpm(ds, value=None, *, source="", name="rpm") -- (r/min or None, speed source) from a value or the file
    time_channels(ds)                          -- names of the 1-D variables along ``time``
    pick_channel(ds, name=None, *, source="")  -- the channel to analyse (given, the default one, else the first)
    pick_tacho(ds, name=None, *, channel=None, source="") -- the tacho channel (given, found by name, or None)
    bearing_name(ds, given=None, *, source="") -- the catalog bearing the Dataset names
    not_an_acceleration(da, name, units)       -- a warning when the channel is not an acceleration ("" if it is)
    TACHO_NAME                                 -- the channel names taken for a tacho
    QUANTITY_WORDS                             -- what a channel in a unit other than acceleration is, in words
"""
from __future__ import annotations

import re

from pathlib import Path

from ..bearings import CATALOG
from ..errors import AnalysisError, RecordingError, RecordingOptionError
from ..io import open_recording
from .xr import sampling_rate

__all__ = ["open_at_rate", "signal_rate", "shaft_rpm", "time_channels", "pick_channel", "pick_tacho",
           "bearing_name", "not_an_acceleration", "TACHO_NAME", "QUANTITY_WORDS"]

#: channel names taken for a once-per-rev tacho (tacho, tach, keyphasor, once-per-rev, 1/rev ...)
TACHO_NAME = re.compile(r"^(tacho?|tach|tachometer|keyphasor|key_phasor|kph|once[-_ ]?per[-_ ]?rev|1/rev)\d*$",
                        re.IGNORECASE)


def open_at_rate(path, fs=None, *, name="fs"):
    """A recording read at a sampling rate the caller gives, for a file that stores none or to override it.

    Parameters
    ----------
    path : str or path
        Any file :func:`bearing_lab.io.open_recording` reads.
    fs : float, optional
        Sampling rate, Hz.  Passed to the reader when it takes an ``fs`` option (bare text, a CWRU
        record outside the registry); a reader that takes none (it reads the rate from the file, as
        bearing_lab's netCDF) reads the file as it is, and ``fs`` then overrides the stored rate.
    name : str
        How the caller calls ``fs`` in its messages (``"--fs"`` on the command line).

    Returns
    -------
    ds : xarray.Dataset
        The recording.
    fs : float or None
        ``fs`` as given (None when not given: see :func:`signal_rate`).
    note : str
        ``""``, or the override in words when ``fs`` replaces the file's rate.

    Raises
    ------
    RecordingError
        No such file, or the reader refuses it.
    AnalysisError
        ``fs`` is not a positive number.

    See Also
    --------
    signal_rate : the rate when none is given.
    bearing_lab.io.open_recording : the readers and their options.
    """
    path = Path(path)
    if not path.is_file():
        raise RecordingError(f"{path}: no such file")
    if fs is None:
        return open_recording(path), None, ""
    if not fs > 0:
        raise AnalysisError(f"{name} {fs!r} must be a positive sampling rate in Hz")
    try:
        return open_recording(path, fs=fs), fs, ""
    except RecordingOptionError as exc:   # a reader without an fs option: the rate is set after reading
        if "fs" not in exc.unknown:
            raise
    ds = open_recording(path)
    return ds, fs, f"{name} {fs:g} Hz overrides the file's {ds.attrs.get('sampling_rate_hz')} Hz"


def signal_rate(ds, channel) -> float:
    """The sampling rate of ``ds[channel]``, Hz: the Dataset's ``sampling_rate_hz``, else the
    channel's own attribute or time axis (:func:`bearing_lab.analysis.xr.sampling_rate`).

    See Also
    --------
    open_at_rate : a rate the caller gives instead.

    Examples
    --------
    >>> import numpy as np, xarray as xr
    >>> ds = xr.Dataset({"acc": ("time", np.zeros(5))}, coords={"time": np.arange(5) / 2000.0})
    >>> signal_rate(ds, "acc"), signal_rate(ds.assign_attrs(sampling_rate_hz=48000.0), "acc")
    (2000.0, 48000.0)
    """
    if "sampling_rate_hz" in ds.attrs:
        return float(ds.attrs["sampling_rate_hz"])
    return sampling_rate(ds[channel])


def shaft_rpm(ds, value=None, *, source="", name="rpm"):
    """The shaft speed prior of an analysis and where it comes from: ``(r/min or None, rpm_source)``.

    ``value`` None: the Dataset's ``shaft_speed_rpm`` ("file"), else none ("given": a blind
    estimate).  ``"none"`` (any case): none, whatever the file stores.  ``"file"``: the stored speed,
    an :class:`~bearing_lab.errors.AnalysisError` when there is none.  A number: that speed
    ("given"), which must be positive.  ``source`` (the file) and ``name`` (how the caller calls
    ``value``, ``"--rpm"`` on the command line) start the messages.

    See Also
    --------
    bearing_lab.analysis.analyze : takes the two as ``rpm`` and ``rpm_source``.

    Examples
    --------
    >>> import xarray as xr
    >>> ds = xr.Dataset(attrs={"shaft_speed_rpm": 1797.0})
    >>> shaft_rpm(ds), shaft_rpm(ds, "none"), shaft_rpm(ds, 1750)
    ((1797.0, 'file'), (None, 'given'), (1750.0, 'given'))
    """
    stored = ds.attrs.get("shaft_speed_rpm")
    if value is None:
        return (float(stored), "file") if stored else (None, "given")
    text = str(value).lower()
    if text == "none":
        return None, "given"
    if text == "file":
        if not stored:
            raise AnalysisError(f"{source}: {name} file given but the file stores no shaft_speed_rpm")
        return float(stored), "file"
    try:
        rpm = float(value)
    except ValueError:
        raise AnalysisError(f"{name} {value!r} is not a number (r/min), 'file' nor 'none'") from None
    if not rpm > 0:
        raise AnalysisError(f"{name} {value!r} must be a positive speed in r/min")
    return rpm, "given"


def time_channels(ds) -> list:
    """Names of the Dataset's one-dimensional variables along ``time`` (the signals)."""
    return [v for v, da in ds.data_vars.items() if "time" in da.dims and da.ndim == 1]


def pick_channel(ds, name=None, *, source="") -> str:
    """The channel to analyse.

    ``name`` given: it must be a 1-D time signal of the Dataset.  Otherwise the Dataset's
    ``default_channel`` attribute, else its first time signal that is not named like a tacho.
    ``source`` (the file) starts the message of the :class:`~bearing_lab.errors.AnalysisError`
    raised when there is no such channel.
    """
    candidates = time_channels(ds)
    if name is not None:
        if name not in ds.data_vars:
            raise AnalysisError(f"{source}: no channel {name!r}; the file has {', '.join(map(str, ds.data_vars))}")
        if name not in candidates:
            raise AnalysisError(f"{source}: channel {name!r} is not a 1-D time signal "
                                f"(dims {ds[name].dims}); pick one of {', '.join(candidates)}")
        return name
    default = ds.attrs.get("default_channel")
    if default in candidates:
        return default
    candidates = [c for c in candidates if not TACHO_NAME.match(str(c))]
    if not candidates:
        raise AnalysisError(f"{source}: no 1-D time signal to analyse")
    return candidates[0]


def pick_tacho(ds, name=None, *, channel=None, source=""):
    """The tacho channel's name, or None.

    ``name`` "none" (any case): no tacho.  ``name`` given: that channel (checked as in
    :func:`pick_channel`).  Otherwise the first time signal named like a tacho (:data:`TACHO_NAME`)
    other than ``channel`` (the one analysed), or None.
    """
    if name is not None and name.lower() == "none":
        return None
    if name is not None:
        return pick_channel(ds, name, source=source)
    hits = [c for c in time_channels(ds) if TACHO_NAME.match(str(c)) and c != channel]
    return hits[0] if hits else None


def bearing_name(ds, given=None, *, source="") -> str:
    """The catalog bearing (:data:`bearing_lab.bearings.CATALOG` key) of a Dataset.

    ``given`` wins.  Otherwise the ``bearing`` attribute when it is a catalog name or contains
    exactly one, else the ``reader`` attribute when it is one (the MFPT reader's rig bearing).
    Raises :class:`~bearing_lab.errors.AnalysisError` naming ``source`` and the catalog when the
    Dataset names none.
    """
    if given is not None:
        return given
    attr = str(ds.attrs.get("bearing", ""))
    if attr in CATALOG:
        return attr
    hits = [k for k in CATALOG if k.lower() in attr.lower()]
    if attr and len(hits) == 1:
        return hits[0]
    reader = str(ds.attrs.get("reader", ""))
    if reader.upper() in CATALOG:
        return reader.upper()
    raise AnalysisError(f"{source}: the file names no catalog bearing (bearing attribute {attr!r}); "
                        f"give the bearing (--bearing), one of {', '.join(sorted(CATALOG))}")


#: what a channel in these units is, in words (for the warning of :func:`not_an_acceleration`)
QUANTITY_WORDS = {"Pa": "a sound pressure (a microphone)", "V": "a voltage (no sensor sensitivity applied)",
                  "m": "a displacement", "m s-1": "a velocity", "N": "a force", "rad s-1": "an angular speed"}


def not_an_acceleration(da, name, units) -> str:
    """A warning when the channel analysed is not an acceleration ("" when it is, or says nothing).

    ``da``: the channel (its ``quantity`` attribute is read), ``name`` its name, ``units`` its unit.
    The analysis still runs on such a channel; the warning says which of its numbers keep their meaning.
    """
    if units in ("m s-2", "g", "m/s^2", "m/s2"):
        return ""
    what = QUANTITY_WORDS.get(str(units)) or (f"a quantity in {units!r}" if units not in (None, "", "1") else "")
    quantity = da.attrs.get("quantity")
    if quantity and quantity != "acceleration":
        what = what or f"a {quantity}"
    if not what:
        return ""
    return (f"channel {name!r} is {what}, not an acceleration: the fault frequencies and the diagnosis read "
            f"the signal's periodicity, but the thresholds were set on accelerometer signals, and rms, peak and "
            f"the band levels are in {units}, not vibration levels")
