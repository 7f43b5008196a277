"""What to analyse in a Dataset: the signal channel, the tacho channel and the catalog bearing.

A recording or a simulation Dataset holds several variables; :func:`bearing_lab.analysis.analyze`
takes one signal, an optional tacho signal and a bearing name.  These functions choose them
from the Dataset the same way for every caller (``bearing-lab analyze`` among them), and say
what is missing with the input named.

Public API
----------
time_channels(ds)                          -- names of the 1-D variables along ``time``
pick_channel(ds, name=None, *, source="")  -- the channel to analyse (given, the default one, else the first)
pick_tacho(ds, name=None, *, channel=None, source="") -- the tacho channel (given, found by name, or None)
bearing_name(ds, given=None, *, source="") -- the catalog bearing the Dataset names
not_an_acceleration(da, name, units)       -- a warning when the channel is not an acceleration ("" if it is)
TACHO_NAME                                 -- the channel names taken for a tacho
"""
from __future__ import annotations

import re

from ..bearings import CATALOG
from ..errors import AnalysisError

__all__ = ["time_channels", "pick_channel", "pick_tacho", "bearing_name", "not_an_acceleration", "TACHO_NAME",
           "QUANTITY_WORDS"]

#: channel names taken for a once-per-rev tacho (tacho, tach, keyphasor, once-per-rev, 1/rev ...)
TACHO_NAME = re.compile(r"^(tacho?|tach|tachometer|keyphasor|key_phasor|kph|once[-_ ]?per[-_ ]?rev|1/rev)\d*$",
                        re.IGNORECASE)


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
