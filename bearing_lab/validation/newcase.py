"""``bearing-lab case new RECORDING``: a commented starting case from what the recording tells.

The file tells the channels, their units, the sampling rate, the duration and (for
some formats, or after ``bearing-lab import --rpm``) the shaft speed.  It cannot tell
the bearing, the load or the defect: those lines are written as commented
placeholders, and the case refuses to run until they are given (naming what is missing).

Public API
----------
new_case_text(recording, *, name=None, bearing=None, speed=None, channel=None, fmt=None, case_dir=None) -> str
compared_duration(record_s) -> float          -- the compared duration: the whole record, up to 10 s
resolution_limits(bearing, rpm, duration_s)   -- fault lines a record that short cannot tell from shaft harmonics
"""
from __future__ import annotations

import math
import os
from pathlib import Path

from .._version import __version__
from ..analysis import coincidences
from ..bearings import get_bearing
from ..errors import BearingLabError
from ..io import open_recording
from ..units import lookup_unit
from .quantities import QUANTITIES

__all__ = ["new_case_text", "resolution_limits", "compared_duration", "DEFAULT_ROWS"]

#: rows a new recording case compares (each with the quantity table's default tolerance and reason)
DEFAULT_ROWS = ("shaft_hz", "bpfo", "excitation_period", "rms", "peak", "crest_factor", "kurtosis",
                "impulse_strength", "impulse_duration")


def _relative(path, case_dir) -> str:
    """The recording relative to the case's folder (as docs/case-format.md reads it), symlinks kept as named;
    absolute only when no relative path exists (another drive)."""
    p = Path(os.path.abspath(path))
    if case_dir is None:
        return p.as_posix()
    try:
        return Path(os.path.relpath(p, os.path.abspath(case_dir))).as_posix()
    except ValueError:
        return p.as_posix()


def _channels(ds) -> list:
    out = []
    for k, v in ds.data_vars.items():
        units = v.attrs.get("units", "?")
        quantity = v.attrs.get("quantity")
        if not quantity:
            try:
                quantity = lookup_unit(units).quantity
            except BearingLabError:
                quantity = "?"
        stored = v.attrs.get("original_units")
        out.append(f"#   {k:14s} {quantity:13s} " + (f"stored as {stored} (read as {units})" if stored else
                                                       f"in {units}"))
    return out


def _source(ds) -> str:
    """What wrote the file: the reader of an imported recording, or the simulator."""
    if ds.attrs.get("reader"):
        return f"reader {ds.attrs['reader']}"
    if ds.attrs.get("scene_name") or ds.attrs.get("fidelity"):
        return f"a bearing_lab simulation of scene {ds.attrs.get('scene_name', '?')!r}"
    return "a bearing_lab netCDF file"


#: longest compared (and simulated) duration ``case new`` writes, s: beyond it, the line search is
#: finer than any slip holds and the simulation only costs time
MAX_COMPARED_S = 10.0


def compared_duration(record_s: float) -> float:
    """The duration ``case new`` compares: the whole record (up to :data:`MAX_COMPARED_S`), so the
    recording's line search (over its whole record) and the simulation's see the same resolution."""
    return float(min(record_s, MAX_COMPARED_S))


def _speed_lines(ds, speed) -> list:
    stored = ds.attrs.get("shaft_speed_rpm")
    if speed is not None:
        return [f"speed = {float(speed):.1f}                 # r/min, given (the file stores "
                + (f"{float(stored):g} r/min)" if stored else "no speed)")]
    if stored:
        return [f"speed = \"file\"                # the file stores {float(stored):g} r/min "
                f"({ds.attrs.get('shaft_speed_source', 'as recorded')})"]
    return ["# speed = 1800.0               # the file stores no shaft speed: give it in r/min (or store it with",
            "                               # `bearing-lab import --rpm`); \"estimate\" takes it from the signal and",
            "                               # stops when the shaft and a fault family cannot be told apart",
            "speed = \"estimate\""]


def resolution_limits(bearing, rpm, duration_s) -> list:
    """What a record of ``duration_s`` s cannot resolve at ``rpm`` r/min: the fault fundamentals (BPFO, BPFI)
    that lie within two bins (1 / duration) of a shaft harmonic, where the line search cannot tell them apart
    (:func:`bearing_lab.analysis.coincidences`).  Each entry: ``family``, ``text`` and
    ``min_duration_s``, the shortest record that separates the two lines by two bins."""
    geo = get_bearing(bearing) if isinstance(bearing, str) else bearing
    fr = float(rpm) / 60.0
    out = []
    for c in coincidences(geo.fault_frequencies(fr), fr, 1.0 / float(duration_s)):
        if c["family"] in ("bpfo", "bpfi") and c["harmonic"] == 1 and c["near"] == "shaft" and "bins from" in c["text"]:
            gap = abs(c["frequency_hz"] - c["order"] * fr)
            out.append({"family": c["family"], "text": c["text"],
                        "min_duration_s": 2.0 / gap if gap > 0 else float("inf")})
    return out


def _limit_lines(bearing, rpm, dur) -> list:
    if not bearing or not rpm:
        return []
    try:
        limits = resolution_limits(bearing, rpm, dur)
    except Exception:        # an unknown catalog name is reported when the case loads
        return []
    lines = []
    for lim in limits:
        need = lim["min_duration_s"]
        lines += [f"# NOTE: at {float(rpm):g} r/min this {dur:.4g} s record cannot resolve {lim['family'].upper()}: "
                  f"{lim['text']}.", f"#   The {lim['family']} line, the excitation period and the impact rows "
                  f"need a record of at least {need:.2g} s" + (" (the path fit needs the impact train too)."
                                                             if lim["family"] == "bpfo" else ".")]
    return lines


def _seconds(v: float) -> str:
    """``v`` s written so that it never rounds up past the record (4 decimals, floored)."""
    return repr(math.floor(v * 1e4) / 1e4)


def new_case_text(recording, *, name=None, bearing=None, speed=None, channel=None, fmt=None, sensitivity=None,
                  case_dir=None) -> str:
    """The text of a starting case for ``recording`` (see the module docstring).

    What the file tells (rate, length, channels, speed) is filled in; what it cannot tell (bearing,
    load, defect) is left commented for the user, with the rows a short record cannot support.

    Parameters
    ----------
    recording : str or path
        The recording file (any format :func:`~bearing_lab.io.open_recording` reads).
    name : str, optional
        Case name (default: the file's stem).
    bearing : str, optional
        Catalog bearing (``6308``, ``6205`` ...).
    speed : float, optional
        Shaft speed, r/min (default: the one the file stores).
    channel, fmt : str, optional
        Channel to compare and reader name (default: the file's default channel, sniffed format).
    sensitivity : str, optional
        Sensor sensitivity for channels stored in volts, e.g. ``"9.91mV/g"``; written to the case's
        ``[recording]`` table so that ``validate`` reads the file the same way.
    case_dir : str or path, optional
        Where the case will be written; the recording is then named relative to it.

    Returns
    -------
    str
        TOML text; every key is explained in ``docs/case-format.md``.

    See Also
    --------
    load_case : reads the case once it is written.
    make_standin_recording

    Examples
    --------
    >>> from bearing_lab.sim import simulate
    >>> from bearing_lab.io import to_uff58b
    >>> path = to_uff58b(simulate("paper-healthy", duration=0.05, progress=False), "rig.uff")
    >>> text = new_case_text("rig.uff", bearing="6308", speed=1800)
    >>> [line for line in text.splitlines() if line.startswith(("bearing", "speed"))]
    ['bearing = "6308"', 'speed = 1800.0                 # r/min, given (the file stores no speed)']
    """
    path = Path(recording)
    opts = {k: v for k, v in (("format", fmt), ("sensitivity", sensitivity)) if v}
    ds = open_recording(path, **opts)
    ch = channel or ds.attrs.get("default_channel") or next(iter(ds.data_vars))
    fs = float(ds.attrs["sampling_rate_hz"])
    dur = ds.sizes["time"] / fs
    compared = compared_duration(dur)
    name = name or path.stem
    rpm = float(speed) if speed is not None else ds.attrs.get("shaft_speed_rpm")
    limits = _limit_lines(bearing, rpm, compared)
    lines = [f"# Validation case for {path.name}, written by bearing_lab {__version__} `case new`.",
             "# Every key is explained in docs/case-format.md.  What the file tells:",
             f"#   {_source(ds)}, {fs:g} Hz, {ds.sizes['time']} samples ({dur:.4g} s)",
             "#   channels:", *_channels(ds),
             *limits,
             "# What it cannot tell (bearing, load, defect) is left for you below.",
             f"name = \"{name}\"", f"title = \"{path.name}: simulation against the recording\"",
             (f"bearing = \"{bearing}\"" if bearing else
              "# bearing = \"6308\"             # a catalog name, or a [bearing] table with the geometry"),
             *_speed_lines(ds, speed), "", "[recording]",
             f"file = \"{_relative(path, case_dir)}\"",
             f"channel = \"{ch}\"", *( [f"format = \"{fmt}\""] if fmt else []),
             *([f"sensitivity = \"{sensitivity}\"       # the sensor's, for the channels stored in volts"]
               if sensitivity else []),
             "scale = 1.0                    # calibration factor on the SI values (1: the file is calibrated)",
             "start_s = 0.0                  # start of the compared segment, s",
             f"duration_s = {_seconds(compared)}{' ' * max(1, 17 - len(_seconds(compared)))}# compared and simulated "
             f"duration, s: {'the whole record' if compared >= dur else 'the first %g s of the record' % compared}",
             "",
             "# [reference]                  # a healthy recording of the same rig (optional): "
             "background, healthy rows",
             "# file = \"healthy.uff\"", "",
             "# [load]                       # the radial load you applied",
             "# radial_n = 300.0",
             "# on = \"inner\"                 # the ring it acts on", "",
             "# [[defect]]                   # the defect you made (none: a healthy bearing)",
             "# race = \"outer\"", "# shape = \"rectangle\"", "# length_mm = 3.0              # along the track",
             "# width_mm = 1.0               # across the track", "# depth_mm = 0.5",
             "# offset_mm = 0.0              # axial offset H from the track centre line",
             "# skew_deg = 0.0               # skew θ against the centre line",
             "# angle_deg = 0.0              # from the load-zone centre", "",
             "[structural_path]              # housing and sensor: fitted once on the impacts, then held fixed",
             "method = \"fit\"                 # a resonance, or the gain alone when the recording shows none;",
             "                               # \"none\": the bare model; \"fixed\": give the three values below",
             "# frequency_hz = [500.0, %.1f]  # fit: search bounds (these are the defaults)" % (0.45 * fs),
             "# damping_ratio = [0.005, 0.5]", "# gain = [0.001, 1000.0]", "",
             "[background]                   # the rig's tones and noise, measured, added to the simulation",
             "enabled = true", "",
             "[tolerances]                   # {} = the quantity's default tolerance and reason"]
    for q in DEFAULT_ROWS:
        lines.append(f"{q} = {{}}{' ' * max(1, 26 - len(q))}# {QUANTITIES[q].tolerance.text()}: {QUANTITIES[q].label}")
    lines += ["# bpfo is the outer-race family; for an inner-race defect compare bpfi instead (a line neither",
              "# signal shows is a missing value, and a missing value fails):",
              "# bpfi = {}"]
    return "\n".join(lines) + "\n"
