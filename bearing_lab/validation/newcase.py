"""``bearing-lab case new RECORDING``: a commented starting case from what the recording tells.

The file tells the channels, their units, the sampling rate, the duration and (for
some formats, or after ``bearing-lab import --rpm``) the shaft speed.  It cannot tell
the bearing, the load or the defect: those lines are written as commented
placeholders, and the case refuses to run until they are given (naming what is missing).

Public API
----------
new_case_text(recording, *, name=None, bearing=None, speed=None, channel=None, fmt=None, case_dir=None) -> str
"""
from __future__ import annotations

from pathlib import Path

from .quantities import QUANTITIES

__all__ = ["new_case_text", "DEFAULT_ROWS"]

#: rows a new recording case compares (each with the quantity table's default tolerance and reason)
DEFAULT_ROWS = ("shaft_hz", "bpfo", "excitation_period", "rms", "peak", "crest_factor", "kurtosis",
                "impulse_strength", "impulse_duration")


def _relative(path, case_dir) -> str:
    """The recording relative to the case's folder when it lies inside it, else absolute."""
    p = Path(path).resolve()
    if case_dir is not None:
        try:
            return p.relative_to(Path(case_dir).resolve()).as_posix()
        except ValueError:
            pass
    return p.as_posix()


def _channels(ds) -> list:
    out = []
    for k, v in ds.data_vars.items():
        out.append(f"#   {k:14s} {v.attrs.get('quantity', '?'):13s} stored as {v.attrs.get('original_units') or '?'}"
                   f" (read as {v.attrs.get('units', '?')})")
    return out


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


def new_case_text(recording, *, name=None, bearing=None, speed=None, channel=None, fmt=None, case_dir=None) -> str:
    """The text of a starting case for ``recording`` (see the module docstring).

    ``case_dir``: where the case will be written; the recording is then named relative to it.
    """
    from .. import __version__
    from ..io import open_recording
    path = Path(recording)
    ds = open_recording(path, **({"format": fmt} if fmt else {}))
    ch = channel or ds.attrs.get("default_channel") or next(iter(ds.data_vars))
    fs = float(ds.attrs["sampling_rate_hz"])
    dur = ds.sizes["time"] / fs
    compared = min(1.0, round(dur / 2, 3)) if dur < 2 else 1.0
    name = name or path.stem
    lines = [f"# Validation case for {path.name}, written by bearing_lab {__version__} `case new`.",
             "# Every key is explained in docs/case-format.md.  What the file tells:",
             f"#   reader {ds.attrs.get('reader')}, {fs:g} Hz, {ds.sizes['time']} samples ({dur:.4g} s)",
             "#   channels:", *_channels(ds),
             "# What it cannot tell (bearing, load, defect) is left for you below.",
             f"name = \"{name}\"", f"title = \"{path.name}: simulation against the recording\"",
             (f"bearing = \"{bearing}\"" if bearing else
              "# bearing = \"6308\"             # a catalog name, or a [bearing] table with the geometry"),
             *_speed_lines(ds, speed), "", "[recording]",
             f"file = \"{_relative(path, case_dir)}\"",
             f"channel = \"{ch}\"", *( [f"format = \"{fmt}\""] if fmt else []),
             "scale = 1.0                    # calibration factor on the SI values (1: the file is calibrated)",
             "start_s = 0.0                  # start of the compared segment, s",
             f"duration_s = {float(compared):.1f}               # compared and simulated duration, s", "",
             "# [reference]                  # a healthy recording of the same rig (optional): background, healthy rows",
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
             "method = \"fit\"", "frequency_hz = [500.0, %g]" % (0.45 * fs), "damping_ratio = [0.005, 0.5]",
             "gain = [0.001, 1000.0]", "",
             "[background]                   # the rig's tones and noise, measured, added to the simulation",
             "enabled = true", "",
             "[tolerances]                   # {} = the quantity's default tolerance and reason"]
    for q in DEFAULT_ROWS:
        lines.append(f"{q} = {{}}{' ' * max(1, 26 - len(q))}# {QUANTITIES[q].tolerance.text()}: {QUANTITIES[q].label}")
    lines += ["# bpfo is the outer-race family; for an inner-race defect compare bpfi instead (a line neither",
              "# signal shows is a missing value, and a missing value fails):",
              "# bpfi = {}"]
    return "\n".join(lines) + "\n"
