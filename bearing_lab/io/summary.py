"""What a Dataset holds, as plain values: the summary ``bearing-lab info`` prints and ``--json`` gives.

Works on a recording, a simulation output or a sweep, and on the plain arrays
:func:`bearing_lab.io.read_arrays` returns (no xarray or pandas is imported here).

Public API
----------
::

    describe(ds, path=None)  -- dict: file, kind, reader, rate, samples, duration, speed, bearing,
                                default channel, per channel its units, quantity, dims and RMS, warnings
    dataset_kind(ds)         -- "recording", "simulation", "sweep" or "dataset"
    channel_rms(values)      -- RMS of any array without overflow (None when empty)
    QUANTITY_OF_UNITS        -- the quantity a channel's SI unit implies, where it says none
"""
from __future__ import annotations

import numpy as np

from ._base import get_warnings

__all__ = ["describe", "dataset_kind", "channel_rms", "QUANTITY_OF_UNITS"]

#: the quantity a channel's unit implies, for a Dataset whose variables do not say
QUANTITY_OF_UNITS = {"m s-2": "acceleration", "m": "displacement", "N": "force",
                     "rad s-1": "angular speed", "m s-1": "velocity", "Pa": "pressure", "V": "voltage"}


def dataset_kind(ds) -> str:
    """What made the Dataset: ``"recording"`` (a reader), ``"simulation"``, ``"sweep"``, else ``"dataset"``."""
    if "reader" in ds.attrs:
        return "recording"
    if "scene_toml" in ds.attrs or "fidelity" in ds.attrs:
        return "sweep" if "sweep_n_scenes" in ds.attrs else "simulation"
    return "dataset"


def channel_rms(values) -> float | None:
    """Root mean square of every value of ``values`` (any shape), in the values' unit.

    Scaled by the largest magnitude before squaring, so values near the float limit do not
    overflow.  None for an empty array or one holding NaN or inf; 0 for zeros.
    """
    x = np.asarray(values, dtype=float).ravel()
    if not x.size:
        return None
    scale = float(np.max(np.abs(x)))
    if not np.isfinite(scale) or scale == 0.0:
        return scale if np.isfinite(scale) else None
    return float(scale * np.sqrt(np.mean(np.square(x / scale))))  # no overflow for huge values


def describe(ds, path=None) -> dict:
    """Return the summary ``bearing-lab info`` prints (also used for ``--json``).

    Works for recordings, simulation outputs and sweeps (``kind``); fields a Dataset
    does not have are None.  ``path`` names the file where the Dataset does not
    (``source_file``).
    """
    n = ds.sizes.get("time", 0)
    fs = float(ds.attrs.get("sampling_rate_hz", 0.0) or 0.0)
    kind = dataset_kind(ds)
    default = ds.attrs.get("default_channel")
    if default is None and "outer_ring_acc_y" in ds.data_vars:
        default = "outer_ring_acc_y"
    channels = {}
    for k, v in ds.data_vars.items():
        units = v.attrs.get("units")
        channels[str(k)] = {
            "units": units, "original_units": v.attrs.get("original_units"),
            "quantity": v.attrs.get("quantity") or QUANTITY_OF_UNITS.get(str(units)),
            "dims": [str(d) for d in v.dims],
            "rms": channel_rms(v.values) if v.dtype.kind in "iuf" else None}
    return {
        "file": ds.attrs.get("source_file") or (str(path) if path is not None else None),
        "kind": kind,
        "reader": ds.attrs.get("reader") or kind,
        "sampling_rate_hz": fs,
        "samples": int(n),
        "duration_s": (n / fs) if fs else None,
        "start_time_s": float(ds["time"].values[0]) if n else None,
        "shaft_speed_rpm": ds.attrs.get("shaft_speed_rpm"),
        "bearing": ds.attrs.get("bearing"),
        "scene": ds.attrs.get("scene_name"),
        "default_channel": default,
        "channels": channels,
        "sha256": ds.attrs.get("source_sha256"),
        "warnings": get_warnings(ds),
    }
