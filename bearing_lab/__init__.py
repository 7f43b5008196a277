"""bearing_lab: import rig recordings, simulate defective ball bearings, analyse
both the same way, and write validation reports.

Public API
----------
simulate            -- scene -> xarray.Dataset (bearing_lab.sim)
load_scene          -- TOML file / built-in name / dict -> Scene
open_recording      -- file -> xarray.Dataset (bearing_lab.io)
get_bearing         -- catalog geometry and kinematic fault frequencies
check_dataset       -- the Dataset contract shared by recordings and simulations
BearingLabError     -- base of every error raised on purpose
"""
__version__ = "0.1.0"

from .errors import (AnalysisError, BearingLabError, RecordingError, SceneError,  # noqa: E402
                     SolverError, ValidationCaseError)
from .bearings import get_bearing, BearingGeometry, CATALOG  # noqa: E402
from .schema import check_dataset  # noqa: E402


def __getattr__(name):
    # lazy entry points keep `import bearing_lab` fast (numba compiles on first use)
    if name in ("simulate", "load_scene", "Scene", "list_scenes"):
        from . import sim
        return getattr(sim, name)
    if name in ("open_recording", "list_engines", "to_netcdf", "to_uff58b"):
        from . import io
        return getattr(io, name)
    if name == "sweep":
        from .sweeps import sweep
        return sweep
    if name == "identify":
        from .validation.identify import identify
        return identify
    raise AttributeError(f"module 'bearing_lab' has no attribute {name!r}")


__all__ = ["simulate", "load_scene", "open_recording", "get_bearing", "check_dataset",
           "BearingLabError", "SceneError", "RecordingError", "AnalysisError", "SolverError",
           "ValidationCaseError", "BearingGeometry", "CATALOG", "__version__"]
