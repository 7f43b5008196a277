"""bearing_lab: import rig recordings, simulate defective ball bearings, analyse
both the same way, and write validation reports.

Public API
----------
simulate            -- scene -> xarray.Dataset (bearing_lab.sim)
load_scene          -- TOML file / built-in name / dict -> Scene
open_recording      -- file -> xarray.Dataset (bearing_lab.io)
analyze             -- signal -> speed, band, envelope spectrum, diagnosis (bearing_lab.analysis)
get_bearing         -- catalog geometry and kinematic fault frequencies
check_dataset       -- the Dataset contract shared by recordings and simulations
sweep, identify     -- many scenes on Dask; defect geometry from a recording
BearingLabError     -- base of every error raised on purpose

Imports are lazy (SPEC 1, ``lazy_loader.attach``): ``import bearing_lab`` loads no
numpy, xarray, scipy, numba or matplotlib; a name above, or a subpackage
(``bearing_lab.analysis`` ...), is imported the first time it is used.  Each
subpackage face does the same, so a command pays only for the libraries it uses
(``docs/architecture.md``, "Imports").  ``EAGER_IMPORT=1`` resolves every lazy
name at import (a check that they all exist).
"""
import lazy_loader as _lazy

from ._version import __version__

_SUBPACKAGES = ["analysis", "datasets", "io", "report", "sim", "validation"]
__getattr__, __dir__, __all__ = _lazy.attach(
    __name__,
    submodules=_SUBPACKAGES,
    submod_attrs={
        "errors": ["AnalysisError", "BearingLabError", "RecordingError", "SceneError",
                   "SolverError", "ValidationCaseError"],
        "bearings": ["get_bearing", "BearingGeometry", "CATALOG"],
        "schema": ["check_dataset"],
        "sim": ["simulate", "load_scene", "Scene", "list_scenes"],
        "io": ["open_recording", "list_engines", "to_netcdf", "to_uff58b"],
        "analysis": ["analyze"],
        "sweeps": ["sweep"],
        "validation.identify": ["identify"],
    })
# ``from bearing_lab import *`` gives the names above, not the subpackages
__all__ = [n for n in __all__ if n not in _SUBPACKAGES] + ["__version__"]
