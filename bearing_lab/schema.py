"""The Dataset contract shared by recordings and simulations.

Measured and simulated data meet here: every reader and the simulator return a
Dataset that passes :func:`check_dataset`, so analysis, comparison and report
never ask where the data came from.

- coordinate ``time`` in s, uniformly sampled (or flagged as uneven);
- global attributes ``sampling_rate_hz``, ``bearing_lab_version`` and, where
  known, ``shaft_speed_rpm``;
- every data variable carries a CF-style ``units`` attribute in SI and a
  ``quantity`` ("acceleration", "displacement", "force", ...);
- the global attribute ``default_channel`` names the accelerometer signal, so code
  above the analysis layer asks the Dataset which variable to use instead of naming
  a reader's or the simulator's variable.
"""
from __future__ import annotations

import numpy as np

from .errors import BearingLabError

SI_UNITS = {"m s-2", "m", "N", "Pa", "V", "m s-1", "1", "rad", "rad s-1", "K", "s",
            "degree"}  # contact angles are named and given in degrees, as bearing catalogues give them

#: the simulator's accelerometer signal (its Datasets' ``default_channel``)
DEFAULT_CHANNEL = "outer_ring_acc_y"
#: the ``quantity`` attribute of a simulated variable, from its SI unit
QUANTITY_OF_UNITS = {"m s-2": "acceleration", "m": "displacement", "N": "force", "rad s-1": "angular velocity"}

SIMULATION_VARIABLES = {
    "outer_ring_acc_y": "m s-2",
    "outer_ring_acc_x": "m s-2",
    "outer_ring_disp_y": "m",
    "outer_ring_disp_x": "m",
    "inner_ring_disp_y": "m",
    "inner_ring_disp_x": "m",
    "ball_load_outer": "N",
    "ball_load_inner": "N",
}

#: the 3-D bearing's extra variables (a scene with an axial load), checked where present
SIMULATION_3D_VARIABLES = {
    "outer_ring_acc_z": "m s-2",
    "outer_ring_disp_z": "m",
    "contact_angle_outer_deg": "degree",
    "contact_angle_inner_deg": "degree",
}


def check_dataset(ds, *, kind: str | None = None) -> None:
    """Raise :class:`BearingLabError` if ``ds`` breaks the contract.

    Parameters
    ----------
    ds : xarray.Dataset
    kind : "simulation", "recording" or None (common checks only).

    See Also
    --------
    bearing_lab.io.open_recording, bearing_lab.sim.simulate : make Datasets that pass it.
    """
    problems = []
    if "time" not in ds.coords:
        problems.append("no 'time' coordinate")
    else:
        if ds["time"].attrs.get("units") != "s":
            problems.append("coordinate 'time' has no units='s'")
        t = np.asarray(ds["time"].values, dtype=float)
        if t.size > 1 and not np.all(np.diff(t) > 0):
            problems.append("time is not strictly increasing")
    for key in ("sampling_rate_hz", "bearing_lab_version"):
        if key not in ds.attrs:
            problems.append(f"global attribute {key!r} missing")
    for name, var in ds.data_vars.items():
        if "units" not in var.attrs:
            problems.append(f"variable {name!r} has no 'units' attribute")
        if var.dtype.kind == "f" and var.size and not np.all(np.isfinite(var.values)):
            problems.append(f"variable {name!r} holds NaN or Inf")
    if ds.data_vars and "default_channel" in ds.attrs and ds.attrs["default_channel"] not in ds.data_vars:
        problems.append(f"default_channel {ds.attrs['default_channel']!r} is not a variable")
    if kind == "simulation":
        if "default_channel" not in ds.attrs:
            problems.append("simulation attribute 'default_channel' missing")
        for name, var in ds.data_vars.items():
            if "quantity" not in var.attrs:
                problems.append(f"variable {name!r} has no 'quantity' attribute")
        for name, units in SIMULATION_3D_VARIABLES.items():
            if name in ds and ds[name].attrs.get("units") != units:
                problems.append(f"{name!r} has units {ds[name].attrs.get('units')!r}, expected {units!r}")
        for name, units in SIMULATION_VARIABLES.items():
            if name not in ds:
                problems.append(f"simulation variable {name!r} missing")
            elif ds[name].attrs.get("units") != units:
                problems.append(f"{name!r} has units {ds[name].attrs.get('units')!r}, expected {units!r}")
        for key in ("bearing", "fidelity", "scene_toml", "wall_time_s"):
            if key not in ds.attrs:
                problems.append(f"simulation attribute {key!r} missing")
    elif kind == "recording":
        for key in ("source_file", "source_sha256", "reader", "warnings"):
            if key not in ds.attrs:
                problems.append(f"recording attribute {key!r} missing")
        for name, var in ds.data_vars.items():
            for key in ("original_units", "quantity"):
                if key not in var.attrs:
                    problems.append(f"variable {name!r} has no {key!r} attribute")
    if problems:
        raise BearingLabError("Dataset breaks the bearing_lab contract: " + "; ".join(problems))
